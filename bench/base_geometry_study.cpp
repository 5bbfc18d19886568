// Contexts for the base mesh's position residuals (issue 30 item 2; the base coder is the whole
// coder of a plain irregular mesh, issue 23; docs/BASE_CODER.md, "The base positions"). The file
// codes every base coordinate against the parallelogram prediction with one context per axis
// (FORMAT.md 3.5). The designs choose each axis's context from what a decoder knows when the
// vertex comes: the stencil triangle's extent along that axis (grid steps when quantized,
// ordered-bit units when bit-exact), the residuals the stencil's vertices had, the axes already
// coded at this vertex. Each design is coded for real (the library's arithmetic coder and
// residual models) in mode 2's vertex order; the table gives bytes of the positions' code (raw
// side bits included) and the ratio to today's.
//   base_geometry_study [--bits 12,16,0] [--shrink L] [--dihedral S] mesh ...
// --shrink L predicts m + L (m - c) instead of the parallelogram's m + (m - c) (m the gate edge's
// middle, c the stencil's opposite vertex). --dihedral S turns the parallelogram about the gate edge
// by S times the bend between the gate triangle and its decoded neighbour across another edge (the
// surface assumed to keep bending as it did; S < 0 bends the other way).
#include <amc/mesh_io.h>

#include "coding/base/base_mesh_coder.h"
#include "coding/entropy/rans_coder.h"
#include "coding/geometry/float_coder.h"
#include "coding/geometry/geometry_prediction.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

namespace {

using namespace amc;

// The mesh's triangles in decoder vertex ids, and each vertex's triangles.
struct DecoderTriangles {
    std::vector<Triangle> triangles;
    std::vector<std::vector<uint32_t>> of_vertex;
};

// The third vertex of a triangle on edge (u, w) other than `not_v`, decoded before `limit`; -1 if
// none. (A triangle whose corners are decoded is taken as known: mode 2 may not have closed it yet,
// so this favours the predictor that uses it.)
int64_t third_decoded(const DecoderTriangles& mesh, uint32_t u, uint32_t w, uint32_t not_v, uint32_t limit) {
    for (uint32_t t : mesh.of_vertex[u]) {
        const Triangle& tr = mesh.triangles[t];
        bool has_w = false;
        uint32_t other = UINT32_MAX;
        for (int j = 0; j < 3; ++j) {
            if (tr[j] == w) has_w = true;
            else if (tr[j] != u) other = tr[j];
        }
        if (has_w && other != not_v && other < limit) return other;
    }
    return -1;
}

Vec3 rotate_about(Vec3 p, Vec3 origin, Vec3 axis, double angle) {
    const Vec3 v = p - origin;
    const double c = std::cos(angle), s = std::sin(angle);
    return origin + (c * v) + (s * cross(axis, v)) + ((1 - c) * dot(axis, v)) * axis;
}

Vec3 unit(Vec3 v) {
    const double n = std::sqrt(dot(v, v));
    return n > 0 ? (1.0 / n) * v : v;
}

int bit_length64(uint64_t v) {
    int k = 0;
    for (; v != 0; v >>= 1) ++k;
    return k;
}

// What the decoder knows when it comes to axis `axis` of a base vertex.
struct Known {
    bool full_stencil = false;
    uint64_t extent[3] = {0, 0, 0};  // |p0 - p2| + |p1 - p2| per axis over the stencil (s0, s1, s2)
    int coded_k[3] = {0, 0, 0};      // bit lengths of the residuals of the axes already coded here
    int stencil_k = 0;               // mean over the stencil's vertices of their largest residual bit length
};

constexpr int kExtentClasses = 68;  // bit lengths 0..66, and "no full stencil"

int extent_class(const Known& known, int axis) {
    return known.full_stencil ? std::min(bit_length64(known.extent[axis]), kExtentClasses - 2) : kExtentClasses - 1;
}

struct Design {
    const char* name;
    int contexts;
    std::function<int(int axis, const Known&)> context;
};

const std::vector<Design>& designs() {
    static const std::vector<Design> list = {
        {"today: axis", 3, [](int a, const Known&) { return a; }},
        {"axis x own extent", 3 * kExtentClasses, [](int a, const Known& k) { return 3 * extent_class(k, a) + a; }},
        {"axis x largest extent", 3 * kExtentClasses,
         [](int a, const Known& k) {
             int largest = 0;
             for (int i = 1; i < 3; ++i)
                 if (k.extent[i] > k.extent[largest]) largest = i;
             return 3 * extent_class(k, largest) + a;
         }},
        {"axis x own extent x previous axis's surprise", 3 * kExtentClasses * 4,
         [](int a, const Known& k) {
             int surprise = 0;
             if (a > 0) {
                 const int expected = k.full_stencil ? bit_length64(k.extent[a - 1]) : 0;
                 const int d = k.coded_k[a - 1] - expected;
                 surprise = d < -1 ? 1 : d <= 0 ? 2 : 3;
             }
             return (3 * extent_class(k, a) + a) * 4 + surprise;
         }},
        {"axis x stencil's residuals", 3 * kExtentClasses, [](int a, const Known& k) { return 3 * k.stencil_k + a; }},
        {"axis x own extent x stencil's residuals (3)", 3 * kExtentClasses * 3,
         [](int a, const Known& k) {
             return (3 * extent_class(k, a) + a) * 3 + (k.stencil_k < 6 ? 0 : k.stencil_k < 10 ? 1 : 2);
         }},
    };
    return list;
}

int residual_bit_length(double actual, double predicted, Precision precision) {
    const uint64_t mask = precision == Precision::float32 ? 0xffffffffull : ~0ull;
    const uint64_t half = mask / 2 + 1;
    const uint64_t r = (ordered_bits(actual, precision) - ordered_bits(predicted, precision)) & mask;
    return bit_length64(r >= half ? (mask - r + 1) & mask : r);
}

// Bytes of the base positions of `mesh` (decoder order of `code`) under each design.
std::vector<uint64_t> code_sizes(const TriangleMesh& mesh, const BaseMeshCode& code, const Quantizer* quantizer,
                                 Precision precision, double shrink, double bend_share) {
    DecoderTriangles by_id;
    {
        std::vector<uint32_t> decoder_id(mesh.positions.size());
        for (size_t i = 0; i < code.vertex_order.size(); ++i) decoder_id[code.vertex_order[i]] = uint32_t(i);
        by_id.of_vertex.assign(mesh.positions.size(), {});
        for (const Triangle& t : mesh.triangles) {
            const Triangle d = {decoder_id[t[0]], decoder_id[t[1]], decoder_id[t[2]]};
            for (int j = 0; j < 3; ++j) by_id.of_vertex[d[j]].push_back(uint32_t(by_id.triangles.size()));
            by_id.triangles.push_back(d);
        }
    }
    std::vector<uint64_t> sizes;
    for (const Design& design : designs()) {
        ArithmeticEncoder encoder;
        RawBitWriter raw;
        FloatResidualModels models(design.contexts);
        std::vector<Vec3> decoded;
        std::vector<int> vertex_k;  // largest residual bit length of each decoded vertex
        decoded.reserve(mesh.positions.size());
        for (size_t i = 0; i < code.vertex_order.size(); ++i) {
            const Vec3 p = mesh.positions[code.vertex_order[i]];
            const BaseStencil st = code.stencils[i];
            const auto valid = [&](int32_t s) { return s >= 0 && size_t(s) < decoded.size(); };
            Known known;
            known.full_stencil = valid(st[0]) && valid(st[1]) && valid(st[2]);
            Vec3 predicted = predict_parallelogram(decoded, st);
            if (known.full_stencil) {
                const Vec3 a = decoded[size_t(st[0])], b = decoded[size_t(st[1])], c = decoded[size_t(st[2])];
                if (bend_share != 0.0) {
                    // The bend across (c, a) or (c, b) from the triangle before, carried across the gate (a, b).
                    const uint32_t ia = uint32_t(st[0]), ib = uint32_t(st[1]), ic = uint32_t(st[2]);
                    int64_t x = third_decoded(by_id, ic, ia, ib, uint32_t(i));
                    Vec3 e0 = a, e1 = c;
                    if (x < 0) {
                        x = third_decoded(by_id, ic, ib, ia, uint32_t(i));
                        e0 = b;
                    }
                    if (x >= 0) {
                        const Vec3 xp = decoded[size_t(x)];
                        const Vec3 n = unit(cross(b - a, c - a));
                        // bend angle across edge (e0, e1): between T's plane and the triangle (e0, e1, x)
                        const Vec3 edge = unit(e1 - e0);
                        const Vec3 in_t = unit((c + a + b - (3.0 * e0)) - dot(c + a + b - (3.0 * e0), edge) * edge);  // into T, perpendicular to the edge
                        const Vec3 to_x = (xp - e0) - dot(xp - e0, edge) * edge;
                        const double along = dot(to_x, -1.0 * in_t), up = dot(to_x, n);
                        const double bend = std::atan2(up, along);  // 0 when flat
                        const Vec3 gate = unit(b - a);
                        const Vec3 q1 = rotate_about(predicted, a, gate, std::fabs(bend_share) * bend);
                        const Vec3 q2 = rotate_about(predicted, a, gate, -std::fabs(bend_share) * bend);
                        // The rotation that bends the way x lies (above or below T's plane), or with a
                        // negative share the other way.
                        predicted = (((dot(q1 - a, n) > 0) == (up > 0)) == (bend_share > 0)) ? q1 : q2;
                    }
                }
                if (shrink != 1.0) {
                    const Vec3 m = {0.5 * (a.x + b.x), 0.5 * (a.y + b.y), 0.5 * (a.z + b.z)};
                    predicted = {m.x + shrink * (m.x - c.x), m.y + shrink * (m.y - c.y), m.z + shrink * (m.z - c.z)};
                }
                for (int axis = 0; axis < 3; ++axis) {
                    const auto unit = [&](Vec3 v) {
                        return quantizer ? int64_t(quantize(*quantizer, v)[axis])
                                         : int64_t(ordered_bits(axis_coordinate(v, axis), precision) >> 1);
                    };
                    known.extent[axis] = uint64_t(std::llabs(unit(a) - unit(c))) + uint64_t(std::llabs(unit(b) - unit(c)));
                }
                known.stencil_k = (vertex_k[size_t(st[0])] + vertex_k[size_t(st[1])] + vertex_k[size_t(st[2])] + 1) / 3;
            } else {
                known.stencil_k = kExtentClasses - 1;
            }
            for (int axis = 0; axis < 3; ++axis) {
                const int context = design.context(axis, known);
                if (quantizer) {
                    const uint32_t qa = quantize(*quantizer, p)[axis], qp = quantize(*quantizer, predicted)[axis];
                    encode_quantized(encoder, models, context, quantizer->bits, qa, qp);
                    known.coded_k[axis] = bit_length64(qa > qp ? qa - qp : qp - qa);
                } else {
                    const double pa = coder_prediction(axis_coordinate(predicted, axis), precision);
                    encode_coordinate(encoder, models, context, precision, axis_coordinate(p, axis), pa, &raw);
                    known.coded_k[axis] = residual_bit_length(axis_coordinate(p, axis), pa, precision);
                }
            }
            decoded.push_back(p);
            vertex_k.push_back(std::max({known.coded_k[0], known.coded_k[1], known.coded_k[2]}));
        }
        sizes.push_back(encoder.finish().size() + raw.finish().size());
    }
    return sizes;
}

std::vector<int> parse_list(const std::string& s) {
    std::vector<int> out;
    size_t pos = 0;
    while (true) {
        const size_t comma = s.find(',', pos);
        out.push_back(std::atoi(s.substr(pos, comma - pos).c_str()));
        if (comma == std::string::npos) return out;
        pos = comma + 1;
    }
}

}  // namespace

int main(int argc, char** argv) {
    std::vector<int> bit_list = {12, 16, 0};
    double shrink = 1.0, bend_share = 0.0;
    std::vector<std::string> paths;
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        if (arg == "--bits" && i + 1 < argc) {
            bit_list = parse_list(argv[++i]);
        } else if (arg == "--dihedral" && i + 1 < argc) {
            bend_share = std::atof(argv[++i]);
        } else if (arg == "--shrink" && i + 1 < argc) {
            shrink = std::atof(argv[++i]);
        } else if (!arg.empty() && arg[0] == '-') {
            std::fprintf(stderr, "usage: base_geometry_study [--bits 12,16,0] [--shrink L] [--dihedral S] mesh ...\n");
            return 2;
        } else {
            paths.push_back(arg);
        }
    }
    std::printf("| mesh | bits | V |");
    for (const Design& d : designs()) std::printf(" %s |", d.name);
    std::printf("\n|---|--:|--:|");
    for (size_t i = 0; i < designs().size(); ++i) std::printf("--:|");
    std::printf("\n");
    for (const std::string& path : paths) {
        const TriangleMesh input = read_mesh(path);
        for (int bits : bit_list) {
            TriangleMesh mesh = input;
            Quantizer quantizer;
            const Quantizer* grid = nullptr;
            if (bits > 0) {
                // As the encoder: positions snapped to the grid before mode 2 codes the connectivity.
                quantizer = make_quantizer(mesh.positions, bits);
                grid = &quantizer;
                for (Vec3& p : mesh.positions) p = dequantize(quantizer, snap_to_grid(quantizer, p));
            }
            const BaseMeshCode code = encode_base_connectivity(mesh, 1, kFullBaseSearch);
            const Precision precision = mesh.single_precision && !grid ? Precision::float32 : Precision::float64;
            const std::vector<uint64_t> sizes = code_sizes(mesh, code, grid, precision, shrink, bend_share);
            const std::string stem = path.substr(path.find_last_of('/') + 1);
            std::printf("| %s | %d | %zu |", stem.c_str(), bits, mesh.positions.size());
            for (uint64_t size : sizes)
                std::printf(" %llu (%.3f) |", static_cast<unsigned long long>(size), double(size) / double(sizes[0]));
            std::printf("\n");
            std::fflush(stdout);
        }
    }
}
