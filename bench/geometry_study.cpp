// Prediction and residual coding of refinement vertices, measured (issues 29 and 30; docs/CODEC.md,
// "Geometry: predictors and static tables"). For every level of each model, the positions the
// level creates are predicted with several stencils from the corners of the level's nodes (what a
// decoder has), and their residuals are costed two ways:
//   today   the .amc coder's adaptive binary models (FORMAT.md 5.2), the predictor of each level
//           picked between midpoint and butterfly as the encoder does (bytes of a real coder);
//   static  a token per coordinate (the magnitude class of the residual, see token_of) coded with a
//           static table per level, axis and context, as an rANS coder would, plus raw bits below the
//           token and the table's own cost: sum of -log2(normalised frequency) over the tokens, the
//           tables' bits as coded (gap and frequency with Elias-gamma lengths), the raw bits.
// Contexts (per level and axis, each a separate table): none; "parent", the magnitude class of the
// residuals of the edge's two end points on the same axis (decoded at coarser levels: a zerotree
// view); "axis", the class of the same vertex's residuals on the axes coded before; both.
//   geometry_study [--levels] model.amh ...
#include <amc/codec.h>
#include <amc/hierarchy.h>

#include "coding/entropy/arithmetic_coder.h"
#include "coding/geometry/float_coder.h"
#include "coding/geometry/geometry_prediction.h"
#include "common/bits.h"
#include "common/exact_float.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace {

using namespace amc;

constexpr int kScaleBits = 12;  // frequencies sum to 2^12
constexpr int kDirect = 8;      // magnitudes below this are their own token

// Token of a residual (sign, magnitude): 0 for 0; 2m - 1 + sign for m < kDirect; above, the bit
// length k and the two bits below the leading one, the sign and k - 3 bits raw.
int token_of(uint64_t m, bool negative, int& raw_bits) {
    raw_bits = 0;
    if (m == 0) return 0;
    if (m < uint64_t(kDirect)) return int(2 * m - 1 + (negative ? 1 : 0));
    const int k = bit_length(m);
    raw_bits = k - 3 + 1;
    return 2 * kDirect - 1 + (k - 4) * 4 + int((m >> (k - 3)) & 3);
}

int class_of(uint64_t m, int shift) { return std::clamp(bit_length(m) - shift, 0, 3); }

// Frequencies scaled to 2^kScaleBits, every seen token at least 1.
std::map<int, uint32_t> normalise(const std::map<int, uint64_t>& counts) {
    uint64_t total = 0;
    for (auto& kv : counts) total += kv.second;
    std::map<int, uint32_t> f;
    if (total == 0) return f;
    int64_t sum = 0;
    int largest = counts.begin()->first;
    for (auto& kv : counts) {
        const uint32_t v = std::max<uint32_t>(1, uint32_t((kv.second << kScaleBits) / total));
        f[kv.first] = v;
        sum += v;
        if (kv.second > counts.at(largest)) largest = kv.first;
    }
    const int64_t target = int64_t(1) << kScaleBits;
    // Fix the sum on the largest (and, should it be too small, on any token above 1).
    f[largest] = uint32_t(int64_t(f[largest]) + target - sum);
    if (int64_t(f[largest]) < 1) {
        // Many rare tokens: take from the biggest until the sum fits.
        int64_t excess = 1 - int64_t(f[largest]);
        f[largest] = 1;
        for (auto& kv : f) {
            while (excess > 0 && kv.second > 1) { --kv.second; --excess; }
        }
    }
    return f;
}

double elias_gamma_bits(uint64_t v) { return 2.0 * bit_length(v) - 1; }  // v >= 1

// Bits of one static table coded as (gap, frequency) pairs and the token count.
double table_bits(const std::map<int, uint32_t>& f) {
    double bits = elias_gamma_bits(f.size() + 1);
    int previous = -1;
    for (auto& kv : f) {
        bits += elias_gamma_bits(uint64_t(kv.first - previous));
        bits += elias_gamma_bits(kv.second);
        previous = kv.first;
    }
    return bits;
}

struct Residual {
    std::array<uint64_t, 3> m;
    std::array<bool, 3> negative;
};

struct Coded {  // one table's tokens
    std::map<int, uint64_t> counts;
    double raw = 0;
};

double static_bits(const std::map<int, Coded>& tables) {
    double bits = 0;
    for (auto& kv : tables) {
        const std::map<int, uint32_t> f = normalise(kv.second.counts);
        bits += table_bits(f) + kv.second.raw;
        for (auto& c : kv.second.counts) bits += double(c.second) * (kScaleBits - std::log2(double(f.at(c.first))));
    }
    return bits;
}

enum Predictor { kMidpoint, kButterfly, kLoop, kHalfButterfly, kNormalMidpoint, kNormalHalfButterfly, kPredictors };
const char* kPredictorNames[] = {"midpoint", "butterfly", "loop", "butterfly/2", "midpoint+normal", "butterfly/2+normal"};

Vec3 opposite_of(const Hierarchy& h, NodeId m, int f) { return h.position(h.vertex(m, (f + 2) % 3)); }
Vec3 wing_of(const Hierarchy& h, NodeId m, int f, Vec3 fallback) {
    const NodeId r = h.neighbor(m, f);
    return r == kNoNode ? fallback : opposite_of(h, r, h.neighbor_edge(m, f));
}

Vec3 predict(const Hierarchy& h, Predictor p, NodeId n, int e) {
    if (p == kNormalMidpoint) p = kMidpoint;
    if (p == kNormalHalfButterfly) p = kHalfButterfly;
    if (p == kMidpoint) return predict_midpoint(h, n, e);
    if (p == kButterfly) return predict_butterfly(h, n, e);
    const NodeId q = h.neighbor(n, e);
    if (q == kNoNode) return predict_midpoint(h, n, e);
    const int e1 = (e + 1) % 3, e2 = (e + 2) % 3, eq = h.neighbor_edge(n, e);
    const Vec3 a = h.position(h.vertex(n, e)), b = h.position(h.vertex(n, e1)), c = h.position(h.vertex(n, e2));
    const Vec3 d = opposite_of(h, q, eq);
    if (p == kLoop) return rounded_scaled(0.375, a + b) + rounded_scaled(0.125, c + d);
    const Vec3 w = (wing_of(h, n, e1, b + c - a) + wing_of(h, n, e2, c + a - b)) +
                   (wing_of(h, q, (eq + 1) % 3, a + d - b) + wing_of(h, q, (eq + 2) % 3, d + b - a));
    return rounded_scaled(0.5, a + b) + rounded_scaled(0.0625, c + d) - rounded_scaled(0.03125, w);
}

// The summed normals of n and of its neighbour across e (n's alone at a boundary).
Vec3 edge_normal(const Hierarchy& h, NodeId n, int e) {
    const Vec3 a = h.position(h.vertex(n, e)), b = h.position(h.vertex(n, (e + 1) % 3)), c = h.position(h.vertex(n, (e + 2) % 3));
    Vec3 normal = cross(b - a, c - a);
    const NodeId q = h.neighbor(n, e);
    if (q != kNoNode) normal = normal + cross(a - b, opposite_of(h, q, h.neighbor_edge(n, e)) - b);
    return normal;
}

double axis(Vec3 p, int a) { return a == 0 ? p.x : a == 1 ? p.y : p.z; }

struct Mode {
    const char* name;
    int bits;  // 0: bit-exact float64
};

// The residual of `actual` against `predicted`, as the .amc coder forms it.
Residual residual_of(const Quantizer* quantizer, Vec3 actual, Vec3 predicted) {
    Residual r{};
    for (int a = 0; a < 3; ++a) {
        if (quantizer != nullptr) {
            const int64_t qa = quantize_coordinate(*quantizer, a, axis(actual, a));
            const int64_t qp = quantize_coordinate(*quantizer, a, axis(predicted, a));
            r.negative[size_t(a)] = qa < qp;
            r.m[size_t(a)] = uint64_t(qa < qp ? qp - qa : qa - qp);
        } else {
            const uint64_t x = ordered_bits(axis(actual, a), Precision::float64);
            const uint64_t p = ordered_bits(coder_prediction(axis(predicted, a), Precision::float64), Precision::float64);
            const uint64_t d = x - p;
            r.negative[size_t(a)] = (d >> 63) != 0;
            r.m[size_t(a)] = r.negative[size_t(a)] ? uint64_t(0) - d : d;
        }
    }
    return r;
}

// Re-expresses a quantized residual along the normal: the axis where the normal is largest
// first, the two others as differences from what a residual along the normal would give them.
Residual along_normal(const Residual& r, Vec3 normal) {
    std::array<double, 3> n{std::fabs(normal.x), std::fabs(normal.y), std::fabs(normal.z)};
    const std::array<double, 3> signed_n{normal.x, normal.y, normal.z};
    const int k = int(std::max_element(n.begin(), n.end()) - n.begin());
    if (n[size_t(k)] == 0) return r;
    const double rk = r.negative[size_t(k)] ? -double(r.m[size_t(k)]) : double(r.m[size_t(k)]);
    Residual out{};
    out.m[0] = r.m[size_t(k)];
    out.negative[0] = r.negative[size_t(k)];
    int slot = 1;
    for (int a = 0; a < 3; ++a) {
        if (a == k) continue;
        const double ra = r.negative[size_t(a)] ? -double(r.m[size_t(a)]) : double(r.m[size_t(a)]);
        const double d = ra - std::nearbyint(rk * signed_n[size_t(a)] / signed_n[size_t(k)]);
        out.negative[size_t(slot)] = d < 0;
        out.m[size_t(slot)] = uint64_t(std::fabs(d));
        ++slot;
    }
    return out;
}

struct LevelCost {
    double today = 0;                 // bytes
    std::array<double, 4> designs{};  // bytes: no context, parent, axis, parent x axis
    int predictor = 0;
    std::array<double, kPredictors> by_predictor{};  // bytes without contexts
    size_t vertices = 0;
};

constexpr int kDesigns = 4;
const char* kDesignNames[kDesigns] = {"static", "static+parent", "static+axis", "static+parent+axis"};

// Bytes of the level's residuals under each design; `magnitude` holds the residual magnitudes of
// the vertices decoded so far (coarser levels).
std::array<double, kDesigns> level_designs(const Hierarchy& h, const std::vector<std::pair<NodeId, int>>& created,
                                           const std::vector<Residual>& residuals,
                                           const std::vector<std::array<uint64_t, 3>>& magnitude) {
    // Shifts: the median bit length of the context quantity over the level (signalled per level).
    std::array<int, 3> parent_shift{}, axis_shift{};
    for (int a = 0; a < 3; ++a) {
        std::vector<int> ps, as;
        for (size_t i = 0; i < created.size(); ++i) {
            const auto [n, e] = created[i];
            const uint64_t s = magnitude[h.vertex(n, e)][size_t(a)] + magnitude[h.vertex(n, (e + 1) % 3)][size_t(a)];
            ps.push_back(bit_length(s));
            as.push_back(bit_length(residuals[i].m[size_t(a)]));
        }
        if (ps.empty()) continue;
        std::nth_element(ps.begin(), ps.begin() + long(ps.size() / 2), ps.end());
        std::nth_element(as.begin(), as.begin() + long(as.size() / 2), as.end());
        parent_shift[size_t(a)] = std::max(0, ps[ps.size() / 2] - 1);
        axis_shift[size_t(a)] = std::max(0, as[as.size() / 2] - 1);
    }
    std::array<std::map<int, Coded>, kDesigns> tables;
    for (size_t i = 0; i < created.size(); ++i) {
        const auto [n, e] = created[i];
        const Residual& r = residuals[i];
        uint64_t previous_axes = 0;
        for (int a = 0; a < 3; ++a) {
            int raw = 0;
            const int token = token_of(r.m[size_t(a)], r.negative[size_t(a)], raw);
            const uint64_t s = magnitude[h.vertex(n, e)][size_t(a)] + magnitude[h.vertex(n, (e + 1) % 3)][size_t(a)];
            const int parent = class_of(s, parent_shift[size_t(a)]);
            const int across = a == 0 ? 0 : class_of(previous_axes, axis_shift[size_t(a - 1)]);
            const int keys[kDesigns] = {a, a * 4 + parent, a * 4 + across, (a * 4 + parent) * 4 + across};
            for (int d = 0; d < kDesigns; ++d) {
                Coded& c = tables[size_t(d)][keys[d]];
                ++c.counts[token];
                c.raw += raw;
            }
            previous_axes = std::max(previous_axes, r.m[size_t(a)]);
        }
    }
    std::array<double, kDesigns> bytes{};
    for (int d = 0; d < kDesigns; ++d) bytes[size_t(d)] = static_bits(tables[size_t(d)]) / 8 + (d == 0 ? 0 : 3);
    return bytes;
}

std::vector<LevelCost> study(Hierarchy h, const Mode& mode) {
    std::unique_ptr<Quantizer> quantizer;
    if (mode.bits != 0) {
        std::vector<Vec3> points;
        for (VertexId v = 0; v < h.positions().size(); ++v) points.push_back(h.position(v));
        quantizer = std::make_unique<Quantizer>(make_quantizer(points, mode.bits));
        h.set_single_precision(false);
        for (VertexId v = 0; v < h.positions().size(); ++v)
            h.set_position(v, dequantize(*quantizer, snap_to_grid(*quantizer, h.position(v))));
    }
    const Precision precision = h.single_precision() ? Precision::float32 : Precision::float64;
    // Base vertices: their context class is "large" (the parallelogram residuals are not known here).
    std::vector<std::array<uint64_t, 3>> magnitude(h.positions().size(), {~uint64_t(0) >> 2, ~uint64_t(0) >> 2, ~uint64_t(0) >> 2});
    FloatResidualModels models(51);
    std::vector<LevelCost> out;
    const std::vector<std::vector<NodeId>> levels = nodes_by_level(h);
    for (size_t l = 0; l < levels.size(); ++l) {
        const auto created = new_vertices_of_level(h, levels[l]);
        if (created.empty()) break;
        LevelCost cost;
        cost.vertices = created.size();
        const int context = 3 * (1 + std::min(int(l), 15));
        // Today: the better of midpoint and butterfly on a copy of the adaptive models.
        size_t best = SIZE_MAX;
        FloatResidualModels best_models = models;
        for (Predictor p : {kMidpoint, kButterfly}) {
            FloatResidualModels trial = models;
            ArithmeticEncoder encoder;
            for (auto [n, e] : created) {
                const Vec3 actual = h.position(h.midpoint(n, e)), predicted = predict(h, p, n, e);
                for (int a = 0; a < 3; ++a) {
                    if (quantizer)
                        encode_quantized(encoder, trial, context + a, quantizer->bits,
                                         quantize_coordinate(*quantizer, a, axis(actual, a)),
                                         quantize_coordinate(*quantizer, a, axis(predicted, a)));
                    else
                        encode_coordinate(encoder, trial, context + a, precision, axis(actual, a), axis(predicted, a));
                }
            }
            const size_t size = encoder.finish().size();
            if (size < best) {
                best = size;
                best_models = trial;
            }
        }
        models = best_models;
        cost.today = double(best);
        // Static designs for every predictor; the level keeps the predictor best without contexts.
        std::vector<Residual> chosen;
        double chosen_bytes = 1e300;
        for (int p = 0; p < kPredictors; ++p) {
            std::vector<Residual> residuals;
            for (auto [n, e] : created) {
                if ((p == kNormalMidpoint || p == kNormalHalfButterfly) && !quantizer) {
                    // Bit-exact: the dominant axis against the prediction, the others against the
                    // prediction moved along the normal by the dominant axis's offset.
                    const Vec3 actual = h.position(h.midpoint(n, e)), predicted = predict(h, Predictor(p), n, e);
                    const Vec3 normal = edge_normal(h, n, e);
                    const std::array<double, 3> an{std::fabs(normal.x), std::fabs(normal.y), std::fabs(normal.z)};
                    const int k = int(std::max_element(an.begin(), an.end()) - an.begin());
                    Vec3 moved = predicted;
                    if (an[size_t(k)] > 0) {
                        const double t = (axis(actual, k) - axis(predicted, k)) / axis(normal, k);
                        moved = predicted + t * normal;
                        if (k == 0) moved.x = predicted.x;
                        if (k == 1) moved.y = predicted.y;
                        if (k == 2) moved.z = predicted.z;
                    }
                    const Residual r = residual_of(nullptr, actual, moved);
                    Residual out{};
                    out.m[0] = r.m[size_t(k)];
                    out.negative[0] = r.negative[size_t(k)];
                    int slot = 1;
                    for (int a = 0; a < 3; ++a)
                        if (a != k) {
                            out.m[size_t(slot)] = r.m[size_t(a)];
                            out.negative[size_t(slot)] = r.negative[size_t(a)];
                            ++slot;
                        }
                    residuals.push_back(out);
                    continue;
                }
                residuals.push_back(residual_of(quantizer.get(), h.position(h.midpoint(n, e)), predict(h, Predictor(p), n, e)));
                if (p == kNormalMidpoint || p == kNormalHalfButterfly) residuals.back() = along_normal(residuals.back(), edge_normal(h, n, e));
            }
            const std::array<double, kDesigns> bytes = level_designs(h, created, residuals, magnitude);
            cost.by_predictor[size_t(p)] = bytes[0];
            const double smallest = *std::min_element(bytes.begin(), bytes.end());
            if (smallest < chosen_bytes) {
                chosen_bytes = smallest;
                chosen = residuals;
                cost.predictor = p;
                cost.designs = bytes;
            }
        }
        for (size_t i = 0; i < created.size(); ++i) magnitude[h.midpoint(created[i].first, created[i].second)] = chosen[i].m;
        out.push_back(cost);
    }
    return out;
}

}  // namespace

int main(int argc, char** argv) {
    bool per_level = false;
    std::vector<std::string> files;
    for (int a = 1; a < argc; ++a) {
        if (std::strcmp(argv[a], "--levels") == 0) per_level = true;
        else files.emplace_back(argv[a]);
    }
    const Mode modes[] = {{"12 bits", 12}, {"16 bits", 16}, {"lossless", 0}};
    std::printf("| model | coordinates | vertices | today bytes | %s | %s | %s | %s | best / today |\n",
                kDesignNames[0], kDesignNames[1], kDesignNames[2], kDesignNames[3]);
    std::printf("|---|---|---:|---:|---:|---:|---:|---:|---:|\n");
    for (const std::string& file : files) {
        const Hierarchy h = read_hierarchy(file);
        const std::string name = std::filesystem::path(file).stem().string();
        for (const Mode& mode : modes) {
            const std::vector<LevelCost> levels = study(h, mode);
            double today = 0, vertices = 0;
            std::array<double, kDesigns> designs{};
            std::array<double, kPredictors> by_predictor{};
            for (const LevelCost& c : levels) {
                today += c.today;
                vertices += double(c.vertices);
                for (int d = 0; d < kDesigns; ++d) designs[size_t(d)] += c.designs[size_t(d)];
                for (int p = 0; p < kPredictors; ++p) by_predictor[size_t(p)] += c.by_predictor[size_t(p)];
            }
            const double best = *std::min_element(designs.begin(), designs.end());
            std::printf("| %s | %s | %.0f | %.0f | %.0f | %.0f | %.0f | %.0f | %.3f |\n", name.c_str(), mode.name, vertices,
                        today, designs[0], designs[1], designs[2], designs[3], best / today);
            if (per_level) {
                std::printf("\n| level | vertices | today | %s | %s | %s | %s | chosen | %s | %s | %s | %s |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|---|---:|---:|---:|---:|\n",
                            kPredictorNames[0], kPredictorNames[1], kPredictorNames[2], kPredictorNames[3], kDesignNames[0],
                            kDesignNames[1], kDesignNames[2], kDesignNames[3]);
                for (size_t l = 0; l < levels.size(); ++l) {
                    const LevelCost& c = levels[l];
                    std::printf("| %zu | %zu | %.0f | %.0f | %.0f | %.0f | %.0f | %.0f | %.0f | %s | %.0f | %.0f | %.0f | %.0f |\n", l, c.vertices,
                                c.today, c.by_predictor[0], c.by_predictor[1], c.by_predictor[2], c.by_predictor[3], c.by_predictor[4], c.by_predictor[5],
                                kPredictorNames[c.predictor], c.designs[0], c.designs[1], c.designs[2], c.designs[3]);
                }
                std::printf("\n");
            }
        }
    }
    return 0;
}
