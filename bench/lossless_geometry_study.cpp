// Bit-exact (float64) refinement positions, measured (issue 30 item 2; docs/CODEC.md, "Lossless
// geometry"). Geometry mode 3 codes each coordinate's ordered-bits residual as a token under a static
// table per level and role plus raw bits below it (FORMAT.md 5.6). For every level, designs of the
// frame and of the tables are costed as static tables would code them: the tokens' empirical
// entropy per table, an estimate of the tables' own bits (gamma codes of gaps and frequencies) and
// the raw bits.
//   area       mode 3: the frame's normal sums the two triangles' cross products;
//   unit       the normal sums their unit normals (mode 4's frame, the remesher's direction);
//   unit+bfly  unit, role 0 predicted by the butterfly's coordinate instead of the midpoint's;
//   unit+r0class  unit, roles 1 and 2 split by the bit length of role 0's residual (3 classes);
//   unit+near  unit, role 0 predicted by the midpoint moved along N by the mean offset of the level's
//              vertices coded before in the same node and in its neighbour across the edge, each
//              offset t (FORMAT.md 5.5) divided by its edge's squared length and scaled by this one's.
// Residuals in the hierarchy's precision (float32 remeshes of float32 references, else float64).
//   lossless_geometry_study model.amh ...
#include <amc/codec.h>
#include <amc/hierarchy.h>

#include "coding/geometry/float_coder.h"
#include "coding/geometry/geometry_prediction.h"
#include "coding/geometry/static_position_coder.h"
#include "common/bits.h"
#include "common/exact_float.h"

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace {

using namespace amc;

constexpr int kDesigns = 5;
const char* const kDesignNames[kDesigns] = {"area", "unit", "unit+bfly", "unit+r0class", "unit+near"};
constexpr int kTablesPerDesign = 12;

double gamma_bits(double v) { return 2.0 * std::floor(std::log2(v)) + 1; }

struct Table {
    std::map<int, uint64_t> counts;
    double raw = 0;
    void add(int token, int raw_bits) {
        ++counts[token];
        raw += raw_bits;
    }
    double bits() const {
        uint64_t total = 0;
        for (auto& kv : counts) total += kv.second;
        if (total == 0) return 0;
        double b = raw + gamma_bits(double(counts.size()) + 1);
        int previous = -1;
        for (auto& kv : counts) {
            const double f = std::max(1.0, std::floor(double(kv.second) * 4096.0 / double(total)));
            b += gamma_bits(kv.first - previous) + gamma_bits(f) + double(kv.second) * (12 - std::log2(f));
            previous = kv.first;
        }
        return b;
    }
};

struct Residual {
    bool negative;
    uint64_t magnitude;
};
// FORMAT.md 5.3: the ordered-bits difference in the hierarchy's precision.
Residual residual_of(Precision precision, double actual, double predicted) {
    const int width = precision == Precision::float32 ? 32 : 64;
    const uint64_t mask = width == 64 ? ~uint64_t{0} : 0xFFFFFFFFull;
    const uint64_t r = (ordered_bits(actual, precision) - ordered_bits(coder_prediction(predicted, precision), precision)) & mask;
    const bool negative = (r >> (width - 1)) & 1;
    return {negative, negative ? (uint64_t{0} - r) & mask : r};
}

std::array<int, 3> role_axes(const NormalFrame& f) {
    static constexpr std::array<std::array<int, 3>, 3> kByAxis{{{0, 1, 2}, {1, 0, 2}, {2, 0, 1}}};
    return kByAxis[f.has_normal ? size_t(f.axis) : 0];
}

struct Totals {
    std::array<double, kDesigns> bits{};
    std::array<std::array<double, 3>, kDesigns> raw_by_role{}, all_by_role{};
};

void study_level(const Hierarchy& h, const std::vector<std::pair<NodeId, int>>& created, Totals& totals) {
    std::array<std::array<Table, kTablesPerDesign>, kDesigns> tables;
    const Precision precision = h.single_precision() ? Precision::float32 : Precision::float64;
    const int width = precision == Precision::float32 ? 32 : 64;
    std::map<NodeId, std::pair<double, int>> offsets;  // unit+near: per node, sum and count of t / |ab|^2
    for (auto [n, e] : created) {
        const Vec3 actual = h.position(h.midpoint(n, e));
        const NodeId across = h.neighbor(n, e);
        const Vec3 edge = h.position(h.vertex(n, (e + 1) % 3)) - h.position(h.vertex(n, e));
        const double squared_length = exact_dot(edge, edge);
        for (int d = 0; d < kDesigns; ++d) {
            const NormalFrame frame = normal_frame(h, n, e, d != 0);
            const std::array<int, 3> axes = role_axes(frame);
            Vec3 first_prediction = d == 2 ? predict_butterfly(h, n, e) : frame.midpoint;
            if (d == 4 && frame.has_normal) {
                double sum = 0;
                int count = 0;
                for (NodeId m : {n, across}) {
                    const auto it = offsets.find(m);
                    if (it != offsets.end()) sum += it->second.first, count += it->second.second;
                }
                if (count > 0) first_prediction = frame.midpoint + rounded_scaled(sum / count * squared_length, frame.normal);
                const double t = (axis_coordinate(actual, frame.axis) - axis_coordinate(frame.midpoint, frame.axis)) /
                                 axis_coordinate(frame.normal, frame.axis);
                for (NodeId m : {n, across}) {
                    if (m == kNoNode || !(squared_length > 0)) continue;
                    offsets[m].first += t / squared_length;
                    ++offsets[m].second;
                }
            }
            const Vec3 others = frame.predict(axis_coordinate(actual, axes[0]));
            int r0_class = 0;
            for (int role = 0; role < 3; ++role) {
                const int axis = axes[size_t(role)];
                const double predicted = role == 0 ? axis_coordinate(first_prediction, axis) : axis_coordinate(others, axis);
                const Residual r = residual_of(precision, axis_coordinate(actual, axis), predicted);
                const int raw = static_raw_bit_count(r.magnitude);
                const int token = static_token(r.negative, r.magnitude);
                int table = role;
                if (role == 0) r0_class = bit_length(r.magnitude) < width - 24 ? 0 : bit_length(r.magnitude) < width - 18 ? 1 : 2;
                if (d == 3 && role > 0) table = 3 * r0_class + role;
                tables[size_t(d)][size_t(table)].add(token, raw);
                totals.raw_by_role[size_t(d)][size_t(role)] += raw;
            }
        }
    }
    for (int d = 0; d < kDesigns; ++d)
        for (int t = 0; t < kTablesPerDesign; ++t) {
            const double b = tables[size_t(d)][size_t(t)].bits();
            totals.bits[size_t(d)] += b;
            totals.all_by_role[size_t(d)][size_t(t % 3)] += b;
        }
}

}  // namespace

int main(int argc, char** argv) {
    std::printf("| model | precision | vertices |");
    for (const char* name : kDesignNames) std::printf(" %s bytes (role 0 / 1 / 2 bits per coordinate) |", name);
    std::printf("\n|---|---|---:|");
    for (int d = 0; d < kDesigns; ++d) std::printf("---:|");
    std::printf("\n");
    for (int a = 1; a < argc; ++a) {
        const Hierarchy h = read_hierarchy(argv[a]);
        Totals totals;
        size_t vertices = 0;
        for (const std::vector<NodeId>& level : nodes_by_level(h)) {
            const auto created = new_vertices_of_level(h, level);
            vertices += created.size();
            study_level(h, created, totals);
        }
        std::printf("| %s | %s | %zu |", std::filesystem::path(argv[a]).stem().string().c_str(),
                    h.single_precision() ? "float32" : "float64", vertices);
        for (int d = 0; d < kDesigns; ++d) {
            const auto& r = totals.all_by_role[size_t(d)];
            std::printf(" %.0f (%.1f / %.1f / %.1f) |", totals.bits[size_t(d)] / 8, r[0] / double(vertices), r[1] / double(vertices),
                        r[2] / double(vertices));
        }
        std::printf("\n");
        std::fflush(stdout);
    }
    return 0;
}
