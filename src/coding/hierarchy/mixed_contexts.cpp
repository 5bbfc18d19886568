// The mixing mode's features and model (mixed_contexts.h; docs/FORMAT.md section 2.1). The
// geometric features are decisions both sides take on positions: every product is rounded on its
// own (exact_float.h) and logarithms are taken exactly, from the binary exponent and mantissa.
#include "coding/hierarchy/mixed_contexts.h"

#include "coding/hierarchy/context_groups.h"
#include "common/exact_float.h"
#include "common/little_endian.h"

#include <algorithm>
#include <cmath>

namespace amc {

namespace {

double exact_length(Vec3 a) { return std::sqrt(exact_dot(a, a)); }

// The longest edge of node n, as LevelShapes::bending measures it (a correctly rounded root keeps
// the order of the squares, so one root of the largest is the largest root).
double longest_edge(const Hierarchy& h, NodeId n) {
    const Vec3 a = h.position(h.vertex(n, 0)), b = h.position(h.vertex(n, 1)), c = h.position(h.vertex(n, 2));
    return std::sqrt(std::max(std::max(exact_dot(b - a, b - a), exact_dot(c - b, c - b)), exact_dot(a - c, a - c)));
}

// The unit normal of node n (zero for a degenerate triangle).
Vec3 unit_normal(const Hierarchy& h, NodeId n) {
    const Vec3 a = h.position(h.vertex(n, 0));
    const Vec3 x = exact_cross(h.position(h.vertex(n, 1)) - a, h.position(h.vertex(n, 2)) - a);
    const double len = exact_length(x);
    if (!(len > 0)) return {0, 0, 0};
    return {x.x / len, x.y / len, x.z / len};
}

// std::frexp for finite x > 0: x = m 2^e with m in [0.5, 1); read from the bits where x is normal.
double mantissa_exponent(double x, int* e) {
    const uint64_t bits = bit_cast<uint64_t>(x);
    const int biased = int(bits >> 52);  // the sign bit is 0
    if (biased == 0) return std::frexp(x, e);
    *e = biased - 1022;
    return bit_cast<double>((bits & ((uint64_t{1} << 52) - 1)) | (uint64_t{1022} << 52));
}

// floor(2 log2 x) + offset for x > 0 (half octaves), clamped to [1, top]; 0 for x <= 0 or NaN.
int half_octave_bin(double x, int offset, int top) {
    if (!(x > 0) || !std::isfinite(x)) return 0;
    int e = 0;
    const double m = mantissa_exponent(x, &e);
    return std::clamp(2 * e + (m >= 0.70710678118654752) + offset, 1, top);
}

// The fifth model's local threshold: half octaves of own / other around 16, 1..31; 0 when other is
// not > 0 (no such node), 1 when own is not > 0.
int threshold_bin(double own, double other) {
    if (!(other > 0)) return 0;
    if (!(own > 0)) return 1;
    const double ratio = own / other;
    return std::isfinite(ratio) ? half_octave_bin(ratio, 16, 31) : 31;
}

// floor(4 log2 x) + offset (quarter octaves), as half_octave_bin.
int quarter_octave_bin(double x, int offset, int top) {
    if (!(x > 0) || !std::isfinite(x)) return 0;
    int e = 0;
    const double m = mantissa_exponent(x, &e);
    const int q = (m >= 0.59460355750136054) + (m >= 0.70710678118654752) + (m >= 0.84089641525371454);
    return std::clamp(4 * e + q + offset, 1, top);
}

// |m - (a + b) / 2|^2 / |b - a|^2 for parent p's edge e and its midpoint vertex m.
double relative_displacement2(const Hierarchy& h, NodeId p, int e) {
    const Vec3 a = h.position(h.vertex(p, e)), b = h.position(h.vertex(p, (e + 1) % 3));
    const Vec3 m = h.position(h.midpoint(p, e));
    const Vec3 middle{rounded(rounded(a.x + b.x) * 0.5), rounded(rounded(a.y + b.y) * 0.5), rounded(rounded(a.z + b.z) * 0.5)};
    const double l2 = exact_dot(b - a, b - a);
    return l2 > 0 ? exact_dot(m - middle, m - middle) / l2 : 0;
}

}  // namespace

// The remesher ranks by the input's |mean| or root |Gauss| curvature times size, which this signed
// fit estimates where the dihedral angles (curv) cannot tell a saddle from a bump.
std::array<double, 2> quadric_curvatures(const Hierarchy& h, NodeId n, double longest) {
    const Vec3 v0 = h.position(h.vertex(n, 0));
    const Vec3 e1 = h.position(h.vertex(n, 1)) - v0, e2 = h.position(h.vertex(n, 2)) - v0;
    const Vec3 x = exact_cross(e1, e2);
    const double a2 = exact_dot(x, x);
    if (!(a2 > 0)) return {0, 0};
    // The gradients of b_1 and b_2 in n's plane (b_0's is minus their sum) and the unit normal.
    const Vec3 c1 = exact_cross(e2, x), c2 = exact_cross(x, e1);
    const Vec3 g1{c1.x / a2, c1.y / a2, c1.z / a2}, g2{c2.x / a2, c2.y / a2, c2.z / a2};
    const double area = std::sqrt(a2);
    const Vec3 unit{x.x / area, x.y / area, x.z / area};
    double m[3][3], t[3];
    for (int e = 0; e < 3; ++e) {
        const NodeId q = h.neighbor(n, e);
        if (q == kNoNode) return {0, 0};
        const Vec3 r = h.position(h.vertex(q, (h.neighbor_edge(n, e) + 2) % 3)) - v0;
        const double b1 = exact_dot(r, g1), b2 = exact_dot(r, g2);
        const double b0 = (1 - b1) - b2;
        m[e][0] = rounded(b0 * b1), m[e][1] = rounded(b1 * b2), m[e][2] = rounded(b2 * b0);
        t[e] = exact_dot(r, unit);
    }
    // a = m^-1 t by the cofactors c[i][j] of m.
    auto minor = [&m](int i0, int j0, int i1, int j1) { return rounded(m[i0][j0] * m[i1][j1]) - rounded(m[i0][j1] * m[i1][j0]); };
    const double c[3][3] = {{minor(1, 1, 2, 2), -minor(1, 0, 2, 2), minor(1, 0, 2, 1)},
                            {-minor(0, 1, 2, 2), minor(0, 0, 2, 2), -minor(0, 0, 2, 1)},
                            {minor(0, 1, 1, 2), -minor(0, 0, 1, 2), minor(0, 0, 1, 1)}};
    const double det = (rounded(m[0][0] * c[0][0]) + rounded(m[0][1] * c[0][1])) + rounded(m[0][2] * c[0][2]);
    if (!(det != 0) || !std::isfinite(det)) return {0, 0};
    double a[3];
    for (int k = 0; k < 3; ++k) a[k] = ((rounded(c[0][k] * t[0]) + rounded(c[1][k] * t[1])) + rounded(c[2][k] * t[2])) / det;
    // The Hessian: P g1 g1' + Q (g1 g2' + g2 g1') + R g2 g2'. Mean curvature: half its trace;
    // Gauss: its determinant in the plane, (P R - Q^2) times |g1 x g2|^2 = 1 / a2.
    const double p = -2 * a[0], r = -2 * a[2], qq = (a[1] - a[0]) - a[2];
    // Doubled apart from the sum: compilers turn x + x into 2 x, which would meet the sum as an FMA.
    const double twice_cross_term = rounded(2 * rounded(qq * exact_dot(g1, g2)));
    const double mean = ((rounded(p * exact_dot(g1, g1)) + twice_cross_term) + rounded(r * exact_dot(g2, g2))) * 0.5;
    const double gauss = (rounded(p * r) - rounded(qq * qq)) / a2;
    return {rounded(std::fabs(mean) * longest), rounded(std::sqrt(std::fabs(gauss)) * longest)};
}

void LevelShapes::start_level(size_t nodes) {
    if (++current_ == 0) {  // wrapped: no stamp may look current
        std::fill(stamp_.begin(), stamp_.end(), 0u);
        std::fill(bending_stamp_.begin(), bending_stamp_.end(), 0u);
        std::fill(quadric_stamp_.begin(), quadric_stamp_.end(), 0u);
        current_ = 1;
    }
    if (normal_.size() < nodes) {
        normal_.resize(nodes);
        bending_.resize(nodes);
        quadric_.resize(nodes);
        stamp_.resize(nodes, 0u);
        bending_stamp_.resize(nodes, 0u);
        quadric_stamp_.resize(nodes, 0u);
    }
    coded_curvature_.assign(nodes, kUncoded);
    coded_quad_.assign(nodes, 0.0);
}

Vec3 LevelShapes::normal(const Hierarchy& h, NodeId node, uint32_t local) {
    if (local >= normal_.size()) return unit_normal(h, node);
    if (stamp_[local] != current_) {
        normal_[local] = unit_normal(h, node);
        stamp_[local] = current_;
    }
    return normal_[local];
}

LevelShapes::Bending LevelShapes::bending(const Hierarchy& h, NodeId n, uint32_t local, const Level& level) {
    if (local < bending_.size() && bending_stamp_[local] == current_) return bending_[local];
    // Chords between unit normals (2 sin of half the angle) times the edge lengths, over 4 times
    // the area: a discrete mean curvature; times the longest edge.
    const Neighbors nbr = with_links(level, [local](auto links) { return links.neighbors(local); });
    const Vec3 own = normal(h, n, local);
    const Vec3 a = h.position(h.vertex(n, 0)), b = h.position(h.vertex(n, 1)), c = h.position(h.vertex(n, 2));
    const double twice_area = exact_length(exact_cross(b - a, c - a));
    const Vec3 corner[3] = {a, b, c};
    double chord_sum = 0, weighted = 0, longest = 0;
    Vec3 around[3];
    int neighbours = 0;
    for (int e = 0; e < 3; ++e) {
        const double len = exact_length(corner[(e + 1) % 3] - corner[e]);
        longest = std::max(longest, len);
        const NodeId q = h.neighbor(n, e);
        if (q == kNoNode) continue;
        // nbr.nbr[e] is q's local index (the level's neighbour across e, as h's).
        around[e] = nbr.nbr[e] != kNoLocal ? normal(h, q, nbr.nbr[e]) : unit_normal(h, q);
        ++neighbours;
        const double chord = exact_length(own - around[e]);
        chord_sum += chord;
        weighted += rounded(chord * len);
    }
    // The neighbours' normals span a solid angle about the Gauss curvature times the area.
    double gauss = 0;
    if (neighbours == 3 && twice_area > 0)
        gauss = rounded(std::fabs(exact_dot(around[0], exact_cross(around[1], around[2]))) * rounded(longest * longest)) / twice_area;
    const Bending value{chord_sum, twice_area > 0 ? rounded(weighted * longest) / (2 * twice_area) : 0, longest, gauss};
    if (local < bending_.size()) {
        bending_[local] = value;
        bending_stamp_[local] = current_;
    }
    return value;
}

std::array<double, 2> LevelShapes::new_quadric(const Hierarchy& h, NodeId node, uint32_t local, double longest) {
    const std::array<double, 2> value = quadric_curvatures(h, node, longest >= 0 ? longest : longest_edge(h, node));
    if (local < quadric_.size()) {
        quadric_[local] = value;
        quadric_stamp_[local] = current_;
    }
    return value;
}

double LevelShapes::base_edge(const Hierarchy& h) {
    if (base_edge_ < 0) {
        double sum = 0;
        for (NodeId r = 0; r < NodeId(h.root_count()); ++r) {
            const Vec3 c[3] = {h.position(h.vertex(r, 0)), h.position(h.vertex(r, 1)), h.position(h.vertex(r, 2))};
            double longest = 0;
            for (int e = 0; e < 3; ++e) longest = std::max(longest, exact_length(c[(e + 1) % 3] - c[e]));
            sum += longest;
        }
        base_edge_ = h.root_count() > 0 ? sum / double(h.root_count()) : 0;
    }
    return base_edge_;
}

MixedFeatures mixed_features(const Hierarchy& h, NodeId n, const Level& level, uint32_t i, int group, LevelShapes& shapes,
                             MixingModel model, bool older_too) {
    MixedFeatures f{};
    // The sixth and seventh models leave out what only older models read (bend_sum, disp,
    // parent_sibs and the curvature's ring), unless they are wanted too.
    const bool every = model < MixingModel::sixth || older_too;
    f.group = uint8_t(group);
    const int l = h.level(n);
    f.level = uint8_t(std::min(l, 7));
    const int k = h.child_index(n);  // -1 for a root
    f.center = k == red_split::kCenter;
    const Neighbors nbr = with_links(level, [i](auto links) { return links.neighbors(i); });
    const uint8_t* state = level.state();
    f.inner = 3;
    f.parent_far = 2;
    const NodeId p = h.parent(n);
    if (k >= 0 && k != red_split::kCenter) {
        // Outer child k's edge (k + 1) % 3 is its inner edge, to the center sibling; the parent's
        // edge (k + 1) % 3 is the one away from corner k.
        const uint8_t s = neighbor_state(state, nbr.nbr[(k + 1) % 3]);
        f.inner = !(s & kDecided) ? 2 : (s & kRefined) ? 0 : 1;
        const NodeId far = h.neighbor(p, (k + 1) % 3);
        f.parent_far = far != kNoNode && !h.is_leaf(far) ? 0 : 1;
    }
    int ring2 = 0;
    // Fifth model: the coded nodes one and two edges away (a node as often as it is reached), the
    // least curvature of the refined ones, the largest of the others, and their counts. The
    // remesher refines above one threshold of its priority, so the neighbours' decisions against
    // their estimates place the threshold locally, where the estimates' errors are alike.
    const bool fifth = model >= MixingModel::fifth;
    double least_refined = -1, most_unrefined = -1, least_quad = -1, most_quad = -1;
    int coded_refined = 0, coded_unrefined = 0;
    const double* coded = shapes.coded_curvatures();
    const double* quads = shapes.coded_quads();
    auto take_coded = [&](uint32_t r) {
        const double c = coded[r];
        if (c == LevelShapes::kUncoded) return;
        const double quad = quads[r];
        if (state[r] & kRefined) {
            least_refined = least_refined < 0 ? c : std::min(least_refined, c);
            least_quad = least_quad < 0 ? quad : std::min(least_quad, quad);
            ++coded_refined;
        } else {
            most_unrefined = std::max(most_unrefined, c);
            most_quad = std::max(most_quad, quad);
            ++coded_unrefined;
        }
    };
    for (int e = 0; e < 3; ++e) {
        const uint32_t q = nbr.nbr[e];
        if (q == kNoLocal) continue;
        if (fifth) take_coded(q);
        const Neighbors qn = with_links(level, [q](auto links) { return links.neighbors(q); });
        for (int eq = 0; eq < 3; ++eq) {
            const uint32_t r = qn.nbr[eq];
            if (r == i || r == kNoLocal) continue;
            const uint8_t s = state[r];
            ring2 += (s & kDecided) && (s & kRefined);
            if (fifth) take_coded(r);
        }
    }
    f.ring2 = uint8_t(std::min(ring2, 4));
    if (p != kNoNode) {
        for (int e = 0; e < 3; ++e) {
            const NodeId q = h.neighbor(p, e);
            f.parent_nbrs = uint8_t(f.parent_nbrs + (q != kNoNode && !h.is_leaf(q)));
        }
        const NodeId g = h.parent(p);
        if (g != kNoNode && every) {  // parent_sibs: not the sixth model's
            for (int c = 0; c < 4; ++c) {
                const NodeId s = h.child(g, c);
                f.parent_sibs = uint8_t(f.parent_sibs + (s != p && !h.is_leaf(s)));
            }
        }
        double near = 0, all = 0;
        for (int e = 0; e < 3; ++e) {
            const double r2 = relative_displacement2(h, p, e);
            all = std::max(all, r2);
            // Outer child k lies on the parent's edges k and k + 2; the center child on none, but
            // its corners are all three midpoints.
            if (k == red_split::kCenter || e == k || e == (k + 2) % 3) near = std::max(near, r2);
        }
        if (every) f.disp = uint8_t(half_octave_bin(near, 34, 23));
        f.disp_parent = uint8_t(half_octave_bin(all, 34, 23));
    }
    // Bending towards the same-level neighbours (LevelShapes::bending).
    const LevelShapes::Bending bending = shapes.bending(h, n, i, level);
    if (every) f.bend_sum = uint8_t(half_octave_bin(bending.chord_sum, 30, 31));
    const double curvature = bending.curvature;
    f.mean_curv = uint8_t(quarter_octave_bin(curvature, 40, 63));
    if (model != MixingModel::first && every) {
        // The same over the node and its same-level neighbours in the level: largest and mean.
        double largest = curvature, sum = curvature;
        int count = 1;
        for (int e = 0; e < 3; ++e) {
            const NodeId q = h.neighbor(n, e);
            if (q == kNoNode || nbr.nbr[e] == kNoLocal) continue;
            const double c = shapes.bending(h, q, nbr.nbr[e], level).curvature;
            largest = std::max(largest, c);
            sum += c;
            ++count;
        }
        f.ring_max = uint8_t(quarter_octave_bin(largest, 40, 63));
        f.ring_mean = uint8_t(quarter_octave_bin(sum / count, 40, 63));
    }
    if (model >= MixingModel::third) {
        const double unit = shapes.base_edge(h);
        // Times 2^l as a product (exact, as std::ldexp, for 0 <= l <= kMaxLevel) without libm's call.
        const double scaled = bending.longest * bit_cast<double>(uint64_t(1023 + l) << 52);
        f.size = uint8_t(unit > 0 ? quarter_octave_bin(scaled / unit, 28, 63) : 0);
        f.gauss = uint8_t(quarter_octave_bin(bending.gauss, 46, 63));
    }
    double ring_quad[2] = {0, 0};
    if (model >= MixingModel::fourth) {
        const std::array<double, 2> quadric =
            model >= MixingModel::sixth ? shapes.quadric(h, n, i, bending.longest) : quadric_curvatures(h, n, bending.longest);
        f.quad_mean = uint8_t(quarter_octave_bin(quadric[0], 40, 63));
        f.quad_gauss = uint8_t(quarter_octave_bin(quadric[1], 40, 63));
        if (model >= MixingModel::sixth) {
            // The same over the node and its same-level neighbours, averaged: the remesher's
            // curvature is the input's, smoother at the node's scale than six points tell.
            double sum_mean = quadric[0], sum_gauss = quadric[1];
            int count = 1;
            for (int e = 0; e < 3; ++e) {
                const NodeId q = h.neighbor(n, e);
                if (q == kNoNode || nbr.nbr[e] == kNoLocal) continue;
                const std::array<double, 2> c = shapes.quadric(h, q, nbr.nbr[e]);
                sum_mean += c[0];
                sum_gauss += c[1];
                ++count;
            }
            ring_quad[0] = sum_mean / count;
            ring_quad[1] = sum_gauss / count;
            f.ring_quad_mean = uint8_t(quarter_octave_bin(ring_quad[0], 40, 63));
            f.ring_quad_gauss = uint8_t(quarter_octave_bin(ring_quad[1], 40, 63));
        }
    }
    if (fifth) {
        f.thr_refined = uint8_t(threshold_bin(curvature, least_refined));
        f.thr_unrefined = uint8_t(threshold_bin(curvature, most_unrefined));
        f.coded_refined = uint8_t(std::min(coded_refined, 7));
        f.coded_unrefined = uint8_t(std::min(coded_unrefined, 7));
        if (model >= MixingModel::sixth) {
            f.quad_refined = uint8_t(threshold_bin(ring_quad[0], least_quad));
            f.quad_unrefined = uint8_t(threshold_bin(ring_quad[0], most_quad));
        }
        shapes.mark_coded(i, curvature, ring_quad[0]);
    }
    return f;
}

namespace {

constexpr int kModelWindowLog2 = 8;
constexpr int kMixerRate = 24;
constexpr int kMapRate = 7;
constexpr uint32_t kContextSizes[MixedHierarchyModel::kInputs] = {10,  40,   40,   80,   50,  120,
                                                                    240, 960, 1920, 2560, 640, 10240, 3840, 200, 400, 480};

// The second model's (FORMAT.md 2.2): direct models 16-20 and the bit histories' maps.
constexpr uint32_t kSecondContextSizes[MixedHierarchyModel::kHistoryInputs + MixedHierarchyModel::kRingInputs] = {
    160, 640, 2560, 640, 5120};
constexpr int kIndirectOf[MixedHierarchyModel::kIndirectInputs] = {1, 4, 11};  // the direct contexts with bit histories
constexpr int kHistoryMapLog2 = 6;
// The third model's (FORMAT.md 2.3): direct models 21-24, mixer D's sets, the mixers' rate and
// their start weights, one row a mixer (the weights the corpus's models end with, averaged:
// bench/model_study, docs/HIERARCHY_CODER.md).
constexpr uint32_t kThirdContextSizes[MixedHierarchyModel::kSizeInputs] = {5120, 1024, 1024, 16384};
constexpr int kThirdMixerRate = 16;
constexpr int32_t kThirdStartWeights[4][MixedHierarchyModel::kThirdInputs + 1] = {
    {-7175, 1455, -3168, -7918, 9409, 6132, 4309, 10091, 2515, 5506, 2802, 284, 1641, 14454, 10366,
     5135, 3181, 8408, 3283, 4805, 3267, -10110, -6345, -7740, 13069, 1994, 6224, 10058, 1524},
    {-6364, -1912, -1706, -5835, 8484, 5389, 1223, 7186, -359, 3153, 559, -2070, -252, 12334, 10866,
     4665, 4605, 10099, 2373, 1188, 350, 968, 5894, -830, 11111, -64, 6101, 5962, 4867},
    {-1878, 2409, -77, -2088, 7274, 4270, 4100, 7297, 3311, 4805, 3052, 1554, 2595, 10469, 7575,
     4001, -2448, 2742, 2901, 5320, 4654, -4493, -2988, -3507, 8433, 2874, 5502, 9095, 1997},
    {-2915, 1231, -1166, -3132, 7789, 3497, 3891, 7928, 2948, 5379, 2671, 1048, 2382, 10671, 8498,
     3163, 3379, 6474, 3899, 4952, 4732, -3768, -988, -3442, 1813, 724, 6746, 7379, 1957}};
// The fourth model's (FORMAT.md 2.4): the direct tables of 0-20 it keeps, in input order (the
// others gain nothing beside the quadric's curvatures: docs/HIERARCHY_CODER.md, "The fourth
// model"), direct tables 25-27 and the mixers' start weights, one row a mixer (the weights the
// corpus's models end with, averaged: bench/model_study).
constexpr int kFourthKeptTables[MixedHierarchyModel::kFourthKept] = {0, 2, 3, 4, 5, 7, 9, 13, 14, 15, 16, 17, 19, 20};
constexpr int kFourthLaterTables[MixedHierarchyModel::kFourthLater] = {21, 23, 24, 25, 26, 27};
constexpr int kFourthMaps[2] = {3, 4};  // of the second model's five
constexpr uint32_t kFourthContextSizes[MixedHierarchyModel::kQuadricInputs] = {16384, 16384, 10240};
constexpr int32_t kFourthStartWeights[4][MixedHierarchyModel::kFourthInputs + 1] = {
    {-6926, -3141, -7757, 9242, 5837, 11814, 4996, 14338, 10374, 4572, 4383, 9511, 5815, 4373, -8133, -4389, -6420, 10966, 3231, 7736, 8317, 3532, 6809, 1848},
    {-6996, -2620, -6687, 8506, 4386, 7175, 1322, 12247, 11007, 3546, 5409, 10621, 1060, 957, 1017, 6127, -1110, 9007, 2092, 3740, 5936, 1195, 5596, 6413},
    {-1301, 379, -1544, 7386, 4548, 8698, 5308, 10606, 7666, 4286, -1927, 3141, 6197, 5582, -3374, -1802, -2329, 7563, 4216, 7532, 7133, 3719, 6823, 2024},
    {-2549, -912, -2838, 7924, 3527, 9199, 5298, 10744, 8715, 3049, 4343, 7336, 5730, 5487, -2727, 117, -2427, 1501, 4550, 6302, 6986, 2464, 6740, 2100}};
// The fifth model's (FORMAT.md 2.5): the direct tables of 0-20 it keeps (tables 4, 13 and 14, of the
// decided refined nodes two edges away, gain nothing beside the coded nodes' counts; 2, 9, 15 and 16
// little, and they pay for the walk's instructions), those of 21-30 and the mixers' start weights
// (bench/model_study's design "Y: fifth without 2 9 15 16", averaged).
constexpr int kFifthKeptTables[MixedHierarchyModel::kFifthKept] = {0, 3, 5, 7, 17, 19, 20};
constexpr int kFifthLaterTables[MixedHierarchyModel::kFifthLater] = {21, 23, 24, 25, 26, 27, 28, 29, 30};
constexpr uint32_t kFifthContextSizes[MixedHierarchyModel::kThresholdInputs] = {8192, 640, 2560};
constexpr int32_t kFifthStartWeights[4][MixedHierarchyModel::kFifthInputs + 1] = {
    {-6099, -6636, 6129, 12162, 9007, 5892, 4881, -5277, -2335, -4993, 10713, 3027, 7408, 7761, 3097, 6935, 10325, 13158, 15886, 1774},
    {-5766, -5268, 4345, 7188, 10042, 1418, 969, 2127, 6186, -443, 8905, 1324, 3324, 5320, 708, 5433, 8958, 12558, 16418, 6688},
    {-958, -1085, 4644, 8960, 3058, 6308, 5801, -2061, -907, -1490, 7298, 4163, 7307, 6690, 3322, 6890, 10119, 9277, 11352, 1931},
    {-1595, -1760, 4018, 9631, 7089, 6043, 6041, -1164, 1175, -1313, 1865, 4445, 6044, 6482, 2109, 6964, 10163, 10840, 12650, 1857}};
// The sixth model's (FORMAT.md 2.6): the fifth's tables less the three of the curvature's ring
// (19, 20, 24: the quadric's ring means carry them, and the neighbours' bending is not computed)
// and tables 0 and 5 (0.05 points, for one group of mixer weights fewer), four more of the
// quadric's ring means and the mixers' start weights (bench/model_study's design "C6h: C6d
// without 0 5", averaged).
constexpr int kSixthKeptTables[MixedHierarchyModel::kSixthKept] = {3, 7, 17};
constexpr int kSixthLaterTables[MixedHierarchyModel::kSixthLater] = {21, 23, 25, 26, 27, 28, 29, 30, 31, 32, 33, 34};
constexpr uint32_t kSixthContextSizes[MixedHierarchyModel::kRingQuadricInputs] = {16384, 16384, 10240, 8192};
constexpr int32_t kSixthStartWeights[4][MixedHierarchyModel::kSixthInputs + 1] = {
    {-5060, 10717, 9618, -3972, -1687, -2905, 10571, 4946, 3758, 694, 5492, 6964, 10791, 13757, 6780, 6799, 6622, 8787, 1202},
    {-3180, 5352, 10073, 2318, 5356, 1891, 7416, 4136, 128, -963, 3173, 6363, 9757, 13360, 2608, 6357, 3214, 7938, 2571},
    {247, 8542, 4194, -1056, -309, 223, 7544, 4989, 3318, 1475, 5822, 7197, 7859, 9860, 7145, 6694, 7477, 8633, 1623},
    {-397, 8843, 7362, -228, 1626, 492, 2647, 5534, 2954, 342, 5681, 7106, 9221, 10937, 6266, 5708, 7845, 9042, 1378}};
// The direct tables the fourth, fifth or sixth model reads, of 0-20 and of 21 on.
template <MixingModel kModel>
constexpr const auto& kept_tables() {
    if constexpr (kModel == MixingModel::sixth) return kSixthKeptTables;
    else if constexpr (kModel == MixingModel::fifth) return kFifthKeptTables;
    else return kFourthKeptTables;
}
template <MixingModel kModel>
constexpr const auto& later_tables() {
    if constexpr (kModel == MixingModel::sixth) return kSixthLaterTables;
    else if constexpr (kModel == MixingModel::fifth) return kFifthLaterTables;
    else return kFourthLaterTables;
}
constexpr int kMapContexts[MixedHierarchyModel::kMaps] = {kContextGroupCount * 4, kContextGroupCount * 64, 24 * 8,
                                                          kContextGroupCount * 256, kContextGroupCount * 5 * 4};

// A context's bit history after `bit`: its last bits, at most 7, below a leading 1.
uint8_t next_history(uint8_t history, bool bit) {
    const int shifted = history * 2 + int(bit);
    return uint8_t(history < 128 ? shifted : 128 + (shifted & 127));
}

}  // namespace

namespace {

// A mixer of `model` with `sets` weight sets: the third model's start at row `row` of its trained
// weights, the others' at 1/n each.
mixing::Mixer model_mixer(MixingModel model, int sets, int row) {
    if (model >= MixingModel::sixth)
        return mixing::Mixer(MixedHierarchyModel::kSixthInputs + 1, sets, kThirdMixerRate, kSixthStartWeights[row]);
    if (model == MixingModel::fifth)
        return mixing::Mixer(MixedHierarchyModel::kFifthInputs + 1, sets, kThirdMixerRate, kFifthStartWeights[row]);
    if (model == MixingModel::fourth)
        return mixing::Mixer(MixedHierarchyModel::kFourthInputs + 1, sets, kThirdMixerRate, kFourthStartWeights[row]);
    if (model == MixingModel::third)
        return mixing::Mixer(MixedHierarchyModel::kThirdInputs + 1, sets, kThirdMixerRate, kThirdStartWeights[row]);
    return mixing::Mixer((model == MixingModel::first ? MixedHierarchyModel::kInputs : MixedHierarchyModel::kSecondInputs) + 1, sets,
                         kMixerRate);
}

}  // namespace

MixedHierarchyModel::MixedHierarchyModel(MixingModel model, const TrainedStateTables& trained)
    : model_(model),
      mixer_a_(model_mixer(model, kContextGroupCount, 0)),
      mixer_b_(model_mixer(model, 16, 1)),
      mixer_c_(model_mixer(model, model == MixingModel::first ? 24 : kContextGroupCount * 16, 2)),
      mixer_d_(model_mixer(model, model >= MixingModel::third ? kContextGroupCount * 16 : 1, 3)) {
    const bool fourth = model >= MixingModel::fourth;
    if (fourth) {
        auto assign = [this](const auto& kept, const auto& later) {
            for (int j : kept)
                models_[size_t(j)].assign(j < kInputs ? kContextSizes[j] : kSecondContextSizes[j - kInputs], BitModel(kModelWindowLog2));
            for (int j : later)
                models_[size_t(j)].assign(j < kThirdDirect    ? kThirdContextSizes[j - kDirect]
                                          : j < kFourthDirect ? kFourthContextSizes[j - kThirdDirect]
                                          : j < kFifthDirect  ? kFifthContextSizes[j - kFourthDirect]
                                                              : kSixthContextSizes[j - kFifthDirect],
                                          BitModel(kModelWindowLog2));
        };
        if (model >= MixingModel::sixth) assign(kept_tables<MixingModel::sixth>(), later_tables<MixingModel::sixth>());
        if (model == MixingModel::seventh) {
            // Each character's model once (an ASCII table), then a copy per slot.
            std::array<BitModel, 128> start;
            for (size_t c = 0; c < start.size(); ++c) start[c] = trained_state(char(c), kModelWindowLog2);
            for (size_t k = 0; k < kTrainedTables.size(); ++k) {
                std::vector<BitModel>& table = models_[size_t(kTrainedTables[k])];
                const char* states = trained[k];
                for (size_t slot = 0; slot < table.size() && states[slot] != '\0'; ++slot) table[slot] = start[uint8_t(states[slot]) & 127u];
            }
        }
        else if (model == MixingModel::fifth) assign(kept_tables<MixingModel::fifth>(), later_tables<MixingModel::fifth>());
        else assign(kept_tables<MixingModel::fourth>(), later_tables<MixingModel::fourth>());
    } else {
        for (int j = 0; j < kInputs; ++j) models_[size_t(j)].assign(kContextSizes[j], BitModel(kModelWindowLog2));
    }
    if (model == MixingModel::first) {
        maps_.emplace_back(kContextGroupCount * 4, kMapRate);
        return;
    }
    if (!fourth)
        for (int j = kInputs; j < kDirect; ++j) models_[size_t(j)].assign(kSecondContextSizes[j - kInputs], BitModel(kModelWindowLog2));
    if (model == MixingModel::third)
        for (int j = kDirect; j < kThirdDirect; ++j) models_[size_t(j)].assign(kThirdContextSizes[j - kDirect], BitModel(kModelWindowLog2));
    for (int k = 0; k < kIndirectInputs; ++k) {
        histories_[size_t(k)].assign(kContextSizes[kIndirectOf[k]], uint8_t{1});
        history_maps_[size_t(k)].assign(size_t(kContextGroupCount) * 256, BitModel(kHistoryMapLog2));
    }
    if (fourth) {
        for (int m : kFourthMaps) maps_.emplace_back(kMapContexts[m], kMapRate);
        return;
    }
    for (int m = 0; m < kMaps; ++m) maps_.emplace_back(kMapContexts[m], kMapRate);
}

std::array<uint32_t, MixedHierarchyModel::kInputs> MixedHierarchyModel::direct_slots(const MixedFeatures& f) {
    const uint32_t g = f.group;
    return {g,
            g * 4 + f.inner,
            g * 4 + f.parent_nbrs,
            g * 8 + f.level,
            g * 5 + f.ring2,
            (g * 3 + f.parent_far) * 4 + f.parent_sibs,
            g * 24 + f.disp,
            (g * 24 + f.disp_parent) * 4 + f.inner,
            (g * 24 + f.disp) * 8 + f.level,
            (g * 32 + f.bend_sum) * 8 + f.level,
            g * 64 + f.mean_curv,
            ((g * 64 + f.mean_curv) * 8 + f.level) * 2 + f.center,
            (g * 24 + f.disp) * 16 + f.mean_curv / 4u,
            (g * 5 + f.ring2) * 4 + f.inner,
            (g * 5 + f.ring2) * 8 + f.level,
            ((g * 4 + f.parent_nbrs) * 3 + f.parent_far) * 4 + f.inner};
}

uint32_t MixedHierarchyModel::p16(const MixedFeatures& f) {
    const uint32_t g = f.group;
    if (model_ >= MixingModel::sixth) {
        // Only the slots the sixth model reads of tables 0-15 (3, 7, and 1, 4, 11 for the bit
        // histories), as direct_slots gives them.
        slot_[1] = g * 4 + f.inner;
        slot_[3] = g * 8 + f.level;
        slot_[4] = g * 5 + f.ring2;
        slot_[7] = (g * 24 + f.disp_parent) * 4 + f.inner;
        slot_[11] = ((g * 64 + f.mean_curv) * 8 + f.level) * 2 + f.center;
        return uint32_t(fourth_model_p12<MixingModel::sixth>(f)) << 4;
    }
    const std::array<uint32_t, kInputs> direct = direct_slots(f);
    std::copy_n(direct.begin(), kInputs, slot_.begin());
    if (model_ == MixingModel::fifth) return uint32_t(fourth_model_p12<MixingModel::fifth>(f)) << 4;
    if (model_ == MixingModel::fourth) return uint32_t(fourth_model_p12<MixingModel::fourth>(f)) << 4;
    for (int j = 0; j < kInputs; ++j) st_[size_t(j)] = mixing::stretch(mixing::p12_of(models_[size_t(j)][slot_[size_t(j)]]));
    if (model_ != MixingModel::first) return uint32_t(later_model_p12(f)) << 4;
    st_[kInputs] = 256;  // bias
    // Three weight sets chosen by different contexts, averaged in the stretched domain.
    const int s1 = mixing::stretch(mixer_a_.mix(st_.data(), int(g)));
    const int s2 = mixing::stretch(mixer_b_.mix(st_.data(), f.level * 2 + f.center));
    const int s3 = mixing::stretch(mixer_c_.mix(st_.data(), f.disp));
    p_mix_ = mixing::squash((s1 + s2 + s3) / 3);
    map_context_[0] = int(g * 4 + f.inner);
    const int refined = maps_[0].refine(p_mix_, map_context_[0]);
    const int p = std::clamp((p_mix_ * 2 + refined * 2 + 2) >> 2, 1, 4095);
    return uint32_t(p) << 4;
}

int MixedHierarchyModel::later_model_p12(const MixedFeatures& f) {
    const uint32_t g = f.group;
    const uint32_t last4 = last_bits_ & 15;
    slot_[kInputs] = g * 16 + last4;
    slot_[kInputs + 1] = (g * 4 + f.inner) * 16 + last4;
    slot_[kInputs + 2] = (g * 64 + f.mean_curv) * 4 + (last_bits_ & 3);
    slot_[kInputs + 3] = g * 64 + f.ring_max;
    slot_[kInputs + 4] = (g * 64 + f.ring_mean) * 8 + f.level;
    for (int j = kInputs; j < kDirect; ++j) st_[size_t(j)] = mixing::stretch(mixing::p12_of(models_[size_t(j)][slot_[size_t(j)]]));
    history_inputs(g, kDirect);
    const bool third = model_ == MixingModel::third;
    if (third) {
        slot_[kDirect] = (g * 64 + f.size) * 8 + f.level;
        // Tables 22-24 without the group: shared by all groups, they learn faster.
        slot_[kDirect + 1] = f.mean_curv * 16u + f.size / 4u;
        slot_[kDirect + 2] = f.gauss * 16u + f.mean_curv / 4u;
        slot_[kDirect + 3] = (f.ring_mean * 32u + f.size / 2u) * 8 + f.level;
        for (int j = kDirect; j < kThirdDirect; ++j)
            st_[size_t(j + kIndirectInputs)] = mixing::stretch(mixing::p12_of(models_[size_t(j)][slot_[size_t(j)]]));
    }
    const int inputs = third ? kThirdInputs : kSecondInputs;
    st_[size_t(inputs)] = 256;  // bias
    const int s1 = mixing::stretch(mixer_a_.mix(st_.data(), int(g)));
    const int s2 = mixing::stretch(mixer_b_.mix(st_.data(), f.ring_mean / 4));
    const int s3 = mixing::stretch(mixer_c_.mix(st_.data(), int(g * 16 + last4)));
    p_mix_ = third ? mixing::squash((s1 + s2 + s3 + mixing::stretch(mixer_d_.mix(st_.data(), int(g * 16 + f.size / 4u)))) / 4)
                   : mixing::squash((s1 + s2 + s3) / 3);
    map_context_ = {int(g * 4 + f.inner), int(g * 64 + f.mean_curv), int(f.disp * 8 + f.level), int(g * 256 + (last_bits_ & 255)),
                    int((g * 5 + f.ring2) * 4 + f.parent_nbrs)};
    const int stretched = mixing::stretch(p_mix_);
    int refined = 0;
    for (int m = 0; m < kMaps; ++m) refined += maps_[size_t(m)].refine_stretched(stretched, map_context_[size_t(m)]);
    return std::clamp((p_mix_ + (refined / kMaps) * 3 + 2) >> 2, 1, 4095);
}

void MixedHierarchyModel::history_inputs(uint32_t g, int first) {
    for (int k = 0; k < kIndirectInputs; ++k) {
        history_context_[size_t(k)] = slot_[size_t(kIndirectOf[k])];
        history_map_slot_[size_t(k)] = g * 256 + histories_[size_t(k)][history_context_[size_t(k)]];
        st_[size_t(first + k)] = mixing::stretch(mixing::p12_of(history_maps_[size_t(k)][history_map_slot_[size_t(k)]]));
    }
}

template <MixingModel kModel>
int MixedHierarchyModel::fourth_model_p12(const MixedFeatures& f) {
    const uint32_t g = f.group;
    const uint32_t last4 = last_bits_ & 15;
    slot_[kInputs] = g * 16 + last4;
    slot_[kInputs + 1] = (g * 4 + f.inner) * 16 + last4;
    if constexpr (kModel != MixingModel::sixth) {  // tables 19, 20 and 24: not the sixth's
        slot_[kInputs + 3] = g * 64 + f.ring_max;
        slot_[kInputs + 4] = (g * 64 + f.ring_mean) * 8 + f.level;
        slot_[kDirect + 3] = (f.ring_mean * 32u + f.size / 2u) * 8 + f.level;
    }
    slot_[kDirect] = (g * 64 + f.size) * 8 + f.level;
    slot_[kDirect + 2] = f.gauss * 16u + f.mean_curv / 4u;
    // Tables 25 and 26 without the group, as 23 and 24.
    slot_[kThirdDirect] = (f.quad_mean * 32u + f.size / 2u) * 8 + f.level;
    slot_[kThirdDirect + 1] = (f.quad_gauss * 32u + f.size / 2u) * 8 + f.level;
    slot_[kThirdDirect + 2] = (g * 64 + f.quad_mean) * 16 + f.quad_gauss / 4u;
    if constexpr (kModel >= MixingModel::fifth) {
        // Tables 28-30: the local threshold by level, the coded nodes' counts by group and by
        // group and inner.
        const uint32_t counts = (g * 8 + f.coded_refined) * 8 + f.coded_unrefined;
        slot_[kFourthDirect] = (f.level * 32u + f.thr_refined) * 32 + f.thr_unrefined;
        slot_[kFourthDirect + 1] = counts;
        slot_[kFourthDirect + 2] = counts * 4 + f.inner;
    }
    if constexpr (kModel == MixingModel::sixth) {
        // Tables 31-34: the quadric's ring means by size and level (no group, as 25 and 26), both
        // by group, and the local threshold on the mean by level.
        slot_[kFifthDirect] = (f.ring_quad_mean * 32u + f.size / 2u) * 8 + f.level;
        slot_[kFifthDirect + 1] = (f.ring_quad_gauss * 32u + f.size / 2u) * 8 + f.level;
        slot_[kFifthDirect + 2] = (g * 64 + f.ring_quad_mean) * 16 + f.ring_quad_gauss / 4u;
        slot_[kFifthDirect + 3] = (f.level * 32u + f.quad_refined) * 32 + f.quad_unrefined;
    }
    int input = 0;
    for (int j : kept_tables<kModel>()) st_[size_t(input++)] = mixing::stretch(mixing::p12_of(models_[size_t(j)][slot_[size_t(j)]]));
    history_inputs(g, input);
    input += kIndirectInputs;
    for (int j : later_tables<kModel>()) st_[size_t(input++)] = mixing::stretch(mixing::p12_of(models_[size_t(j)][slot_[size_t(j)]]));
    st_[size_t(input)] = 256;  // bias
    const int s1 = mixing::stretch(mixer_a_.mix(st_.data(), int(g)));
    const int s2 = mixing::stretch(mixer_b_.mix(st_.data(), kModel == MixingModel::sixth ? f.ring_quad_mean / 4 : f.ring_mean / 4));
    const int s3 = mixing::stretch(mixer_c_.mix(st_.data(), int(g * 16 + last4)));
    const int s4 = mixing::stretch(mixer_d_.mix(st_.data(), int(g * 16 + f.size / 4u)));
    p_mix_ = mixing::squash((s1 + s2 + s3 + s4) / 4);
    // The second model's maps 3 and 4 (the others gain nothing here).
    const int stretched = mixing::stretch(p_mix_);
    const int refined = maps_[0].refine_stretched(stretched, int(g * 256 + (last_bits_ & 255))) +
                        maps_[1].refine_stretched(stretched, int((g * 5 + f.ring2) * 4 + f.parent_nbrs));
    return std::clamp((p_mix_ + (refined / 2) * 3 + 2) >> 2, 1, 4095);
}

template <MixingModel kModel>
void MixedHierarchyModel::update_fourth_tables(bool bit) {
    for (int j : kept_tables<kModel>()) models_[size_t(j)][slot_[size_t(j)]].update_with_limit(bit, kModelWindowLog2);
    for (int j : later_tables<kModel>()) models_[size_t(j)][slot_[size_t(j)]].update_with_limit(bit, kModelWindowLog2);
}

void MixedHierarchyModel::update(bool bit) {
    mixer_a_.update(st_.data(), bit);
    mixer_b_.update(st_.data(), bit);
    mixer_c_.update(st_.data(), bit);
    if (model_ >= MixingModel::third) mixer_d_.update(st_.data(), bit);
    for (mixing::ProbabilityMap& map : maps_) map.update(bit);
    if (model_ >= MixingModel::sixth) {
        update_fourth_tables<MixingModel::sixth>(bit);
    } else if (model_ == MixingModel::fifth) {
        update_fourth_tables<MixingModel::fifth>(bit);
    } else if (model_ == MixingModel::fourth) {
        update_fourth_tables<MixingModel::fourth>(bit);
    } else {
        const int direct = model_ == MixingModel::first ? kInputs : model_ == MixingModel::second ? kDirect : kThirdDirect;
        for (int j = 0; j < direct; ++j) models_[size_t(j)][slot_[size_t(j)]].update_with_limit(bit, kModelWindowLog2);
    }
    if (model_ == MixingModel::first) return;
    for (int k = 0; k < kIndirectInputs; ++k) {
        history_maps_[size_t(k)][history_map_slot_[size_t(k)]].update_with_limit(bit, kHistoryMapLog2);
        uint8_t& history = histories_[size_t(k)][history_context_[size_t(k)]];
        history = next_history(history, bit);
    }
    last_bits_ = (last_bits_ << 1) | uint32_t(bit);
}

}  // namespace amc
