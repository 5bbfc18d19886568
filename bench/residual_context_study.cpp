// Contexts for the quantized residuals of the normal-frame predictor (issue 30 item 2;
// docs/CODEC.md, "Geometry mode 4"). The static mode (FORMAT.md 5.6) codes q - round(t), t the
// prediction in grid steps, with one table per level and role. Where the surface is flat at the
// grid's scale (remeshes of piecewise-flat inputs) the residual is the grid's rounding noise, and how
// it falls depends on where t lies between two grid points: t on a grid point (the midpoint of an
// even sum) gives 0, t half-way gives 0 or the far neighbour with equal odds. Designs, per level and
// role, costed in static tables (their own bits included, as geometry_study costs them) and as
// adaptive counts (no table):
//   none        today's tables (mode 3);
//   fracB       the distance of t from round(t) in B bins over [0, 1/2], the residual's sign turned
//               so that positive points away from round(t) towards the second-nearest grid point
//               (frac2 is mode 4's split);
//   fracB+r0    the same, and for roles 1 and 2 the class of role 0's residual (0, 1, more);
//   frac2+ends  frac2 and the class (0-1, 2-8, more, a base vertex) of the summed role-0
//               residuals of the edge's end points (zerotree-style), for every role or role 0 only.
// UNIT=1: the frame's normal is the sum of the two triangles' unit normals (mode 4's frame, the
// remesher's direction) instead of the summed cross products (mode 3's).
//   [UNIT=1] residual_context_study model.amh ...
#include <amc/codec.h>
#include <amc/hierarchy.h>

#include "coding/geometry/float_coder.h"
#include "coding/geometry/geometry_prediction.h"
#include "common/bits.h"
#include "common/exact_float.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace {

using namespace amc;

constexpr int kScaleBits = 12;

int token_of(uint64_t m, bool negative, int& raw_bits) {
    raw_bits = 0;
    if (m == 0) return 0;
    if (m < 8) return int(2 * m - 1 + (negative ? 1 : 0));
    const int k = bit_length(m);
    raw_bits = k - 3 + 1;
    return 15 + (k - 4) * 4 + int((m >> (k - 3)) & 3);
}

double elias_gamma_bits(uint64_t v) { return 2.0 * bit_length(v) - 1; }

struct Table {
    std::map<int, uint64_t> counts;
    double raw = 0;
    double adaptive = 0;  // bits of an adaptive frequency count (KT-like, 40-token alphabet)
    uint64_t total = 0;
    void add(int token, int raw_bits) {
        const uint64_t c = counts[token];
        adaptive += -std::log2((double(c) + 0.4) / (double(total) + 0.4 * 40));
        ++counts[token];
        ++total;
        raw += raw_bits;
    }
};

double static_bits(const Table& t) {
    uint64_t total = 0;
    for (auto& kv : t.counts) total += kv.second;
    if (total == 0) return 0;
    double bits = elias_gamma_bits(t.counts.size() + 1) + t.raw;
    int previous = -1;
    for (auto& kv : t.counts) {
        const double f = std::max(1.0, std::floor(double(kv.second << kScaleBits) / double(total)));
        bits += elias_gamma_bits(uint64_t(kv.first - previous)) + elias_gamma_bits(uint64_t(f));
        previous = kv.first;
        bits += double(kv.second) * (kScaleBits - std::log2(f));
    }
    return bits;
}

double component(Vec3 p, int a) { return a == 0 ? p.x : a == 1 ? p.y : p.z; }

constexpr int kDesigns = 8;
const char* kNames[kDesigns] = {"none", "frac2", "frac4", "frac8", "frac4+r0", "frac8+r0", "frac2+ends", "frac2+ends(role 0)"};

}  // namespace

int main(int argc, char** argv) {
    std::printf("| model | bits | vertices | design | static bytes | adaptive bytes |\n|---|---:|---:|---|---:|---:|\n");
    for (int i = 1; i < argc; ++i) {
        const std::string name = std::filesystem::path(argv[i]).stem().string();
        for (int bits : {12, 16}) {
            Hierarchy h = read_hierarchy(argv[i]);
            std::vector<Vec3> points;
            for (VertexId v = 0; v < h.positions().size(); ++v) points.push_back(h.position(v));
            const Quantizer quantizer = make_quantizer(points, bits);
            h.set_single_precision(false);
            for (VertexId v = 0; v < h.positions().size(); ++v)
                h.set_position(v, dequantize(quantizer, snap_to_grid(quantizer, h.position(v))));
            std::array<double, kDesigns> stat{}, adapt{};
            size_t vertices = 0;
            const std::vector<std::vector<NodeId>> levels = nodes_by_level(h);
            std::vector<int64_t> r0mag(h.positions().size(), -1);
            for (size_t l = 0; l < levels.size(); ++l) {
                const auto created = new_vertices_of_level(h, levels[l]);
                if (created.empty()) break;
                vertices += created.size();
                std::array<std::map<int, Table>, kDesigns> tables;
                for (auto [n, e] : created) {
                    NormalFrame frame = normal_frame(h, n, e);
                    if (std::getenv("UNIT") != nullptr && frame.has_normal) {
                        // The remesher's direction: the sum of the two elements' unit normals.
                        const Vec3 a = h.position(h.vertex(n, e)), b = h.position(h.vertex(n, (e + 1) % 3)),
                                   c = h.position(h.vertex(n, (e + 2) % 3));
                        auto unit_of = [](Vec3 v) { const double l = std::sqrt(exact_dot(v, v)); return l > 0 ? rounded_scaled(1.0 / l, v) : v; };
                        Vec3 nn = unit_of(exact_cross(b - a, c - a));
                        const NodeId q = h.neighbor(n, e);
                        if (q != kNoNode) {
                            const Vec3 d = h.position(h.vertex(q, (h.neighbor_edge(n, e) + 2) % 3));
                            nn = nn + unit_of(exact_cross(a - b, d - b));
                        }
                        frame.normal = nn;
                        frame.axis = 0;
                        for (int i = 1; i < 3; ++i)
                            if (std::fabs(component(nn, i)) > std::fabs(component(nn, frame.axis))) frame.axis = i;
                        frame.has_normal = std::fabs(component(nn, frame.axis)) > 0;
                    }
                    const std::array<int, 3> axes =
                        frame.has_normal ? std::array<int, 3>{frame.axis, frame.axis == 0 ? 1 : 0, frame.axis == 2 ? 1 : 2}
                                         : std::array<int, 3>{0, 1, 2};
                    const Vec3 actual = h.position(h.midpoint(n, e));
                    const Vec3 others = frame.predict(component(actual, axes[0]));
                    int r0class = 0;
                    const int64_t ma = r0mag[h.vertex(n, e)], mb = r0mag[h.vertex(n, (e + 1) % 3)];
                    const int ends = ma < 0 || mb < 0 ? 3 : ma + mb <= 1 ? 0 : ma + mb <= 8 ? 1 : 2;
                    for (int role = 0; role < 3; ++role) {
                        const int a = axes[size_t(role)];
                        const double predicted = role == 0 ? component(frame.midpoint, a) : component(others, a);
                        const double t = (predicted - component(quantizer.origin, a)) / quantizer.step;
                        const int64_t q = quantize_coordinate(quantizer, a, component(actual, a));
                        const int64_t p = quantize_coordinate(quantizer, a, predicted);
                        int64_t r = q - p;
                        double f = t - double(p);  // in [-1/2, 1/2] (up to clamping)
                        if (f < 0) {
                            r = -r;
                            f = -f;
                        }
                        f = std::min(f, 0.5);
                        int raw = 0;
                        const int token = token_of(uint64_t(r < 0 ? -r : r), r < 0, raw);
                        int raw_plain = 0;
                        const int64_t rp = q - p;
                        const int token_plain = token_of(uint64_t(rp < 0 ? -rp : rp), rp < 0, raw_plain);
                        const int b2 = std::min(1, int(f * 4)), b4 = std::min(3, int(f * 8)), b8 = std::min(7, int(f * 16));
                        // Role 0 oriented by the normal: r' = sign(N_k) (q - p), f' = sign(N_k) (t - p).
                        const double sn = frame.has_normal && component(frame.normal, a) < 0 ? -1.0 : 1.0;
                        const double fs = std::clamp(sn * (t - double(p)), -0.5, 0.5);
                        const int64_t rs = sn < 0 ? -rp : rp;
                        int raw_s = 0;
                        const int token_s = token_of(uint64_t(rs < 0 ? -rs : rs), rs < 0, raw_s);
                        (void)fs; (void)token_s;
                        const int keys[kDesigns] = {role, role * 2 + b2, role * 4 + b4, role * 8 + b8,
                                                    (role * 4 + b4) * 3 + (role == 0 ? 0 : r0class),
                                                    (role * 8 + b8) * 3 + (role == 0 ? 0 : r0class),
                                                    (role * 2 + b2) * 4 + ends,
                                                    role == 0 ? 100 + b2 * 4 + ends : role * 2 + b2};
                        for (int d = 0; d < kDesigns; ++d) {
                            tables[size_t(d)][keys[d]].add(d == 0 ? token_plain : token, d == 0 ? raw_plain : raw);
                        }
                        if (role == 0) r0class = std::min<int64_t>(2, rp < 0 ? -rp : rp);
                        if (role == 0) r0mag[h.midpoint(n, e)] = rp < 0 ? -rp : rp;
                    }
                }
                std::array<double, kDesigns> level_bytes{};
                for (int d = 0; d < kDesigns; ++d)
                    for (auto& kv : tables[size_t(d)]) {
                        stat[size_t(d)] += static_bits(kv.second) / 8;
                        level_bytes[size_t(d)] += static_bits(kv.second) / 8;
                        adapt[size_t(d)] += (kv.second.adaptive + kv.second.raw) / 8;
                    }
                if (std::getenv("LEVELS") != nullptr) {
                    std::printf("level %zu: %zu vertices, none %.0f, frac2 %.0f; role tables (none):", l, created.size(), level_bytes[0], level_bytes[1]);
                    for (auto& kv : tables[0]) {
                        std::printf(" [role %d: %.0f B;", kv.first, static_bits(kv.second) / 8);
                        for (auto& c : kv.second.counts) if (c.first < 9) std::printf(" %d:%.2f", c.first, double(c.second) / double(kv.second.total));
                        std::printf("]");
                    }
                    std::printf("\n");
                }
            }
            for (int d = 0; d < kDesigns; ++d)
                std::printf("| %s | %d | %zu | %s | %.0f (%.3f) | %.0f (%.3f) |\n", name.c_str(), bits, vertices, kNames[d], stat[size_t(d)],
                            stat[size_t(d)] / stat[0], adapt[size_t(d)], adapt[size_t(d)] / stat[0]);
        }
    }
    return 0;
}
