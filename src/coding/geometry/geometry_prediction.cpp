// Predictions of refinement vertices (midpoint, butterfly) and of base vertices (parallelogram);
// see geometry_prediction.h.
#include "coding/geometry/geometry_prediction.h"

#include "common/exact_float.h"
#include "common/simd.h"

#include <algorithm>
#include <cmath>

namespace amc {

namespace {

Vec3 round_if_single(const Hierarchy& h, Vec3 p) { return h.single_precision() ? rounded_to_float(p) : p; }

// The vertex of node m opposite its edge f.
Vec3 opposite(const Hierarchy& h, NodeId m, int f) { return h.position(h.vertex(m, (f + 2) % 3)); }

// Vertex opposite edge f of node m in the same-level neighbour across f, or `fallback`.
Vec3 wing(const Hierarchy& h, NodeId m, int f, Vec3 fallback) {
    const NodeId r = h.neighbor(m, f);
    return r == kNoNode ? fallback : opposite(h, r, h.neighbor_edge(m, f));
}

}  // namespace

std::vector<std::vector<NodeId>> nodes_by_level(const Hierarchy& h) {
    std::vector<std::vector<NodeId>> levels;
    for (NodeId n : h.breadth_first_order()) {
        const size_t l = static_cast<size_t>(h.level(n));
        if (levels.size() <= l) levels.resize(l + 1);
        levels[l].push_back(n);
    }
    return levels;
}

std::vector<std::pair<NodeId, int>> new_vertices_of_level(const Hierarchy& h,
                                                          const std::vector<NodeId>& level_nodes) {
    // A midpoint is shared only with the same-level neighbour across the edge; it was listed
    // before iff that neighbour is refined and comes earlier in level order. A vertex flag is
    // the simplest exact test of that.
    std::vector<bool> seen(h.positions().size(), false);
    std::vector<std::pair<NodeId, int>> out;
    for (NodeId n : level_nodes) {
        if (h.is_leaf(n)) continue;
        for (int e = 0; e < 3; ++e) {
            const VertexId m = h.midpoint(n, e);
            if (seen[m]) continue;
            seen[m] = true;
            out.emplace_back(n, e);
        }
    }
    return out;
}

Vec3 predict_midpoint(const Hierarchy& h, NodeId n, int e) {
    const Vec3 a = h.position(h.vertex(n, e));
    const Vec3 b = h.position(h.vertex(n, (e + 1) % 3));
    return round_if_single(h, rounded_scaled(0.5, a + b));  // FORMAT.md 5.5 (forest.cpp's placer where a + b is finite)
}

Vec3 predict_butterfly(const Hierarchy& h, NodeId n, int e) {
    const NodeId q = h.neighbor(n, e);
    if (q == kNoNode) return predict_midpoint(h, n, e);
    const int e1 = (e + 1) % 3, e2 = (e + 2) % 3;
    const Vec3 a = h.position(h.vertex(n, e));
    const Vec3 b = h.position(h.vertex(n, e1));
    const Vec3 c = h.position(h.vertex(n, e2));
    const int eq = h.neighbor_edge(n, e);  // q's edge eq runs b -> a
    const Vec3 d = opposite(h, q, eq);
    const Vec3 w_bc = wing(h, n, e1, b + c - a);
    const Vec3 w_ca = wing(h, n, e2, c + a - b);
    const Vec3 w_ad = wing(h, q, (eq + 1) % 3, a + d - b);
    const Vec3 w_db = wing(h, q, (eq + 2) % 3, d + b - a);
    // Every product rounded before it is added (common/exact_float.h): the decoder computes the same.
    const Vec3 p = rounded_scaled(0.5, a + b) + rounded_scaled(0.125, c + d) -
                   rounded_scaled(0.0625, (w_bc + w_ca) + (w_ad + w_db));
    return round_if_single(h, p);
}

namespace {

// u x v with every product rounded before the subtraction (no fused multiply-add).
Vec3 exact_cross(Vec3 u, Vec3 v) {
    return {rounded(u.y * v.z) - rounded(u.z * v.y), rounded(u.z * v.x) - rounded(u.x * v.z),
            rounded(u.x * v.y) - rounded(u.y * v.x)};
}

// 1 / L for the lengths L = sqrt(squared) of two vectors, each correctly rounded, and whether L is
// positive and finite (else the unit vector is the zero vector). With SSE2 both square roots and
// both divisions are one instruction each: they are most of mode 4's frame.
struct InverseLengths {
    double r[2];
    bool valid[2];
};
InverseLengths inverse_lengths(double squared0, double squared1) {
    double length[2];
    InverseLengths out;
#if AMC_SSE2
    const __m128d l = _mm_sqrt_pd(_mm_set_pd(squared1, squared0));
    _mm_storeu_pd(length, l);
    _mm_storeu_pd(out.r, _mm_div_pd(_mm_set1_pd(1.0), l));
#else
    for (int k = 0; k < 2; ++k) {
        length[k] = std::sqrt(k == 0 ? squared0 : squared1);
        out.r[k] = 1.0 / length[k];
    }
#endif
    for (int k = 0; k < 2; ++k) out.valid[k] = length[k] > 0 && std::isfinite(length[k]);
    return out;
}

// v scaled to unit length: each coordinate times 1 / L, L the correctly rounded square root of
// exact_dot(v, v), each product rounded; the zero vector when L is 0 or not finite.
Vec3 scaled_unit(Vec3 v, double r, bool valid) { return valid ? rounded_scaled(r, v) : Vec3{0, 0, 0}; }

}  // namespace

FrameCorners frame_corners(const Hierarchy& h, NodeId n, int e) {
    const NodeId q = h.neighbor(n, e);
    return {h.vertex(n, e), h.vertex(n, (e + 1) % 3), h.vertex(n, (e + 2) % 3),
            q == kNoNode ? kNoVertex : h.vertex(q, (h.neighbor_edge(n, e) + 2) % 3)};
}

NormalFrame frame_of(const Hierarchy& h, const FrameCorners& corners, bool unit_normals) {
    NormalFrame f;
    const Vec3 a = h.position(corners.a), b = h.position(corners.b), c = h.position(corners.c);
    f.midpoint = round_if_single(h, rounded_scaled(0.5, a + b));  // predict_midpoint's
    const bool has_d = corners.d != kNoVertex;
    const Vec3 n1 = exact_cross(b - a, c - a);
    const Vec3 n2 = has_d ? exact_cross(a - b, h.position(corners.d) - b) : Vec3{};
    if (unit_normals) {
        // Mode 4 sums unit normals (the remesher's direction, vertex_placement.cpp).
        const InverseLengths r = inverse_lengths(exact_dot(n1, n1), exact_dot(n2, n2));
        f.normal = scaled_unit(n1, r.r[0], r.valid[0]);
        if (has_d) f.normal = f.normal + scaled_unit(n2, r.r[1], r.valid[1]);
    } else {
        // Mode 3 sums the cross products themselves (each weighted by its triangle's area).
        f.normal = has_d ? n1 + n2 : n1;
    }
    // The first axis of largest |N_i|, without branches (the axis is a coin flip on curved surfaces).
    const double x = std::fabs(f.normal.x), y = std::fabs(f.normal.y), z = std::fabs(f.normal.z);
    const bool y_wins = y > x;
    const double best = y_wins ? y : x;
    const bool z_wins = z > best;
    f.axis = z_wins ? 2 : int(y_wins);
    const double largest = z_wins ? z : best;
    f.has_normal = largest > 0 && std::isfinite(largest);
    return f;
}

NormalFrame normal_frame(const Hierarchy& h, NodeId n, int e, bool unit_normals) {
    return frame_of(h, frame_corners(h, n, e), unit_normals);
}

Vec3 predict_parallelogram(const std::vector<Vec3>& decoded, std::array<int32_t, 3> stencil) {
    const auto valid = [&](int32_t i) { return i >= 0 && static_cast<size_t>(i) < decoded.size(); };
    if (valid(stencil[0]) && valid(stencil[1]) && valid(stencil[2])) {
        return decoded[size_t(stencil[0])] + decoded[size_t(stencil[1])] - decoded[size_t(stencil[2])];
    }
    if (valid(stencil[0])) return decoded[size_t(stencil[0])];
    return Vec3{};
}

}  // namespace amc
