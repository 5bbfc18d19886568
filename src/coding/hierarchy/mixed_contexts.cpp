// The mixing mode's features and model (mixed_contexts.h; docs/FORMAT.md section 2.1). The
// geometric features are decisions both sides take on positions: every product is rounded on its
// own (exact_float.h) and logarithms are taken exactly, from the binary exponent and mantissa.
#include "coding/hierarchy/mixed_contexts.h"

#include "coding/hierarchy/context_groups.h"
#include "common/exact_float.h"

#include <algorithm>
#include <cmath>

namespace amc {

namespace {

Vec3 exact_cross(Vec3 a, Vec3 b) {
    return {rounded(a.y * b.z) - rounded(a.z * b.y), rounded(a.z * b.x) - rounded(a.x * b.z),
            rounded(a.x * b.y) - rounded(a.y * b.x)};
}

double exact_length(Vec3 a) { return std::sqrt(exact_dot(a, a)); }

// The unit normal of node n (zero for a degenerate triangle).
Vec3 unit_normal(const Hierarchy& h, NodeId n) {
    const Vec3 a = h.position(h.vertex(n, 0));
    const Vec3 x = exact_cross(h.position(h.vertex(n, 1)) - a, h.position(h.vertex(n, 2)) - a);
    const double len = exact_length(x);
    if (!(len > 0)) return {0, 0, 0};
    return {x.x / len, x.y / len, x.z / len};
}

// floor(2 log2 x) + offset for x > 0 (half octaves), clamped to [1, top]; 0 for x <= 0 or NaN.
int half_octave_bin(double x, int offset, int top) {
    if (!(x > 0) || !std::isfinite(x)) return 0;
    int e = 0;
    const double m = std::frexp(x, &e);  // x = m 2^e, m in [0.5, 1)
    return std::clamp(2 * e + (m >= 0.70710678118654752) + offset, 1, top);
}

// floor(4 log2 x) + offset (quarter octaves), as half_octave_bin.
int quarter_octave_bin(double x, int offset, int top) {
    if (!(x > 0) || !std::isfinite(x)) return 0;
    int e = 0;
    const double m = std::frexp(x, &e);
    const int q = (m >= 0.59460355750136054) + (m >= 0.70710678118654752) + (m >= 0.84089641525371454);
    return std::clamp(4 * e + q + offset, 1, top);
}

// |m - (a + b) / 2|^2 / |b - a|^2 for parent p's edge e and its midpoint vertex m.
double relative_displacement2(const Hierarchy& h, NodeId p, int e) {
    const Vec3 a = h.position(h.vertex(p, e)), b = h.position(h.vertex(p, (e + 1) % 3));
    const Vec3 m = h.position(h.midpoint(p, e));
    const Vec3 middle{rounded(a.x + b.x) * 0.5, rounded(a.y + b.y) * 0.5, rounded(a.z + b.z) * 0.5};
    const double l2 = exact_dot(b - a, b - a);
    return l2 > 0 ? exact_dot(m - middle, m - middle) / l2 : 0;
}

}  // namespace

void LevelNormals::start_level(size_t nodes) {
    if (++current_ == 0) {  // wrapped: no stamp may look current
        std::fill(stamp_.begin(), stamp_.end(), 0u);
        current_ = 1;
    }
    if (normal_.size() < nodes) {
        normal_.resize(nodes);
        stamp_.resize(nodes, 0u);
    }
}

Vec3 LevelNormals::get(const Hierarchy& h, NodeId node, uint32_t local) {
    if (local >= normal_.size()) return unit_normal(h, node);
    if (stamp_[local] != current_) {
        normal_[local] = unit_normal(h, node);
        stamp_[local] = current_;
    }
    return normal_[local];
}

MixedFeatures mixed_features(const Hierarchy& h, NodeId n, const Level& level, uint32_t i, int group, LevelNormals& normals) {
    MixedFeatures f{};
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
    for (int e = 0; e < 3; ++e) {
        const uint32_t q = nbr.nbr[e];
        if (q == kNoLocal) continue;
        const Neighbors qn = with_links(level, [q](auto links) { return links.neighbors(q); });
        for (int eq = 0; eq < 3; ++eq) {
            const uint32_t r = qn.nbr[eq];
            if (r == i || r == kNoLocal) continue;
            const uint8_t s = state[r];
            ring2 += (s & kDecided) && (s & kRefined);
        }
    }
    f.ring2 = uint8_t(std::min(ring2, 4));
    if (p != kNoNode) {
        for (int e = 0; e < 3; ++e) {
            const NodeId q = h.neighbor(p, e);
            f.parent_nbrs = uint8_t(f.parent_nbrs + (q != kNoNode && !h.is_leaf(q)));
        }
        const NodeId g = h.parent(p);
        if (g != kNoNode) {
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
        f.disp = uint8_t(half_octave_bin(near, 34, 23));
        f.disp_parent = uint8_t(half_octave_bin(all, 34, 23));
    }
    // Bending towards the same-level neighbours: chords between unit normals (2 sin of half the
    // angle), summed; and a discrete mean curvature, sum of chord * edge length / (4 area), times
    // the longest edge.
    const Vec3 normal = normals.get(h, n, i);
    const Vec3 a = h.position(h.vertex(n, 0)), b = h.position(h.vertex(n, 1)), c = h.position(h.vertex(n, 2));
    const double twice_area = exact_length(exact_cross(b - a, c - a));
    const Vec3 corner[3] = {a, b, c};
    double chord_sum = 0, weighted = 0, longest = 0;
    for (int e = 0; e < 3; ++e) {
        const double len = exact_length(corner[(e + 1) % 3] - corner[e]);
        longest = std::max(longest, len);
        const NodeId q = h.neighbor(n, e);
        if (q == kNoNode) continue;
        // nbr.nbr[e] is q's local index (the level's neighbour across e, as h's).
        const double chord = exact_length(normal - (nbr.nbr[e] != kNoLocal ? normals.get(h, q, nbr.nbr[e]) : unit_normal(h, q)));
        chord_sum += chord;
        weighted += rounded(chord * len);
    }
    f.bend_sum = uint8_t(half_octave_bin(chord_sum, 30, 31));
    f.mean_curv = twice_area > 0 ? uint8_t(quarter_octave_bin(rounded(weighted * longest) / (2 * twice_area), 40, 63)) : 0;
    return f;
}

namespace {

constexpr int kModelWindowLog2 = 8;
constexpr int kMixerRate = 24;
constexpr int kMapRate = 7;
constexpr uint32_t kContextSizes[MixedHierarchyModel::kInputs] = {10,  40,   40,   80,   50,  120,
                                                                    240, 960, 1920, 2560, 640, 10240, 3840, 200, 400, 480};

}  // namespace

MixedHierarchyModel::MixedHierarchyModel()
    : mixer_(kInputs + 1, kContextGroupCount, kMixerRate),
      by_level_(kInputs + 1, 16, kMixerRate),
      by_displacement_(kInputs + 1, 24, kMixerRate),
      apm_(kContextGroupCount * 4, kMapRate) {
    for (int j = 0; j < kInputs; ++j) models_[size_t(j)].assign(kContextSizes[j], BitModel(kModelWindowLog2));
}

uint32_t MixedHierarchyModel::p16(const MixedFeatures& f) {
    const uint32_t g = f.group;
    slot_ = {g,
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
    for (int j = 0; j < kInputs; ++j) st_[size_t(j)] = mixing::stretch(mixing::p12_of(models_[size_t(j)][slot_[size_t(j)]]));
    st_[kInputs] = 256;  // bias
    // Three weight sets chosen by different contexts, averaged in the stretched domain.
    const int s1 = mixing::stretch(mixer_.mix(st_.data(), int(g)));
    const int s2 = mixing::stretch(by_level_.mix(st_.data(), f.level * 2 + f.center));
    const int s3 = mixing::stretch(by_displacement_.mix(st_.data(), f.disp));
    p_mix_ = mixing::squash((s1 + s2 + s3) / 3);
    const int refined = apm_.refine(p_mix_, int(g * 4 + f.inner));
    const int p = std::clamp((p_mix_ * 2 + refined * 2 + 2) >> 2, 1, 4095);
    return uint32_t(p) << 4;
}

void MixedHierarchyModel::update(bool bit) {
    mixer_.update(st_.data(), bit);
    by_level_.update(st_.data(), bit);
    by_displacement_.update(st_.data(), bit);
    apm_.update(bit);
    for (int j = 0; j < kInputs; ++j) models_[size_t(j)][slot_[size_t(j)]].update(bit);
}

}  // namespace amc
