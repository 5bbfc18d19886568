// Position predictions for the geometry coder (paper III, "geometry prediction schemes"): the
// vertices a red refinement creates are predicted level by level from vertices the decoder
// already has (corners of the nodes of that level), base vertices by the parallelogram rule.
//
// Order: the new vertices of level l are those created by splitting the refined nodes of level
// l; they are visited in canonical order (refined nodes of level l in breadth-first order, edges
// 0, 1, 2, each vertex at its first appearance), which is exactly the slice of
// canonical_vertex_order() (include/amc/hierarchy.h) belonging to level l. Every prediction for a
// vertex of level l reads only corners of level-l nodes, which exist before level l is refined.
#pragma once

#include "coding/geometry/float_coder.h"
#include "common/compiler.h"
#include "common/exact_float.h"
#include "common/simd.h"
#include "hierarchy/hierarchy_builder.h"

#include <amc/hierarchy.h>

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace amc {

// The live nodes grouped by level, each level in canonical breadth-first order.
std::vector<std::vector<NodeId>> nodes_by_level(const Hierarchy& h);

// The vertices created by splitting the refined nodes among `level_nodes` (the nodes of one
// level in canonical order), as (node, edge) at their first appearance, in canonical order.
std::vector<std::pair<NodeId, int>> new_vertices_of_level(const Hierarchy& h,
                                                          const std::vector<NodeId>& level_nodes);

// Midpoint of edge e of node n, 0.5 * (a + b) (rounded to float for single-precision
// hierarchies), as FORMAT.md 5.5 fixes it: the hierarchy's default vertex placer wherever a + b
// does not overflow, so exact finite-element midpoints predict with residual 0.
// Mesh: Hierarchy or HierarchyOnGrid (the encoder's grid points), here and below.
template <class Mesh>
Vec3 predict_midpoint(const Mesh& h, NodeId n, int e);

// The 8-point butterfly stencil (Dyn, Levin, Gregory 1990) for edge e of node n on n's level:
//   1/2 (a + b) + 1/8 (c + d) - 1/16 (w_bc + w_ca + w_ad + w_db)
// with a, b the edge's end points, c the vertex of n opposite the edge, d the vertex opposite
// the edge in the same-level neighbour q across e, and w_xy the vertex opposite edge xy in the
// same-level neighbour across xy (of n for bc, ca; of q for ad, db).
// A missing wing (boundary or coarser region) is replaced by its parallelogram reflection
// (w_bc = b + c - a, and so on), which keeps the stencil affine and exact for planar data; when
// q is missing (boundary edge) the prediction is the midpoint. Rounded to float for
// single-precision hierarchies.
template <class Mesh>
Vec3 predict_butterfly(const Mesh& h, NodeId n, int e);

// The frame of the normal-frame predictor (FORMAT.md 5.5): the midpoint of edge e of node n, the
// summed normals N of n and of its same-level neighbour across e (cross products of edge vectors,
// n's alone at a boundary), and the axis where |N| is largest. The vertex's coordinate on that
// axis is coded first against the midpoint; the offset it shows, taken along N, predicts the
// other two: surface remeshes place new vertices on the surface near the edge's midpoint, so the
// residual lies mostly along the normal. has_normal is false when N is zero or not finite (then
// all three coordinates are predicted by the midpoint, x first).
struct NormalFrame {
    Vec3 midpoint;
    Vec3 normal;
    int axis = 0;
    bool has_normal = false;
    // The other coordinates' prediction once the first axis's value is known.
    Vec3 predict(double first_axis_value) const {
        if (!has_normal) return midpoint;
        const double t = rounded((first_axis_value - axis_coordinate(midpoint, axis)) / axis_coordinate(normal, axis));
        Vec3 p = midpoint + rounded_scaled(t, normal);
        (axis == 0 ? p.x : axis == 1 ? p.y : p.z) = first_axis_value;
        return p;
    }
};
// unit_normals (geometry modes 4 and 5, FORMAT.md 5.7, 5.8): N is the sum of the two triangles' unit normals
// instead, the direction along which the surface remesher places the vertex.
NormalFrame normal_frame(const Hierarchy& h, NodeId n, int e, bool unit_normals = false);
// normal_frame in two steps, for decoders that gather many vertices' corners (and prefetch their
// positions) before computing their frames: the corners a frame reads, a, b, c of node n (edge e
// runs a -> b) and d, the vertex opposite the edge in the same-level neighbour (kNoVertex at a
// boundary); then the frame from their positions.
// (FrameCorners: hierarchy_builder.h, where split_level lists them for the decoders.)
// Inline: the static coders ask it once a vertex.
template <class Mesh>
inline FrameCorners frame_corners(const Mesh& h, NodeId n, int e) {
    static constexpr int kNext[5] = {1, 2, 0, 1, 2};  // (i + 1) % 3 at i, (i + 2) % 3 at i + 1, for i in 0..2
    const NodeId q = h.neighbor(n, e);
    return {h.vertex(n, e), h.vertex(n, kNext[e]), h.vertex(n, kNext[e + 1]),
            q == kNoNode ? kNoVertex : h.vertex(q, kNext[h.neighbor_edge(n, e) + 1])};
}
// frame_of<UnitNormals>(h, corners): below, inline.

// Parallelogram rule over already decoded positions: a + b - c when all three indices are valid
// (>= 0 and < decoded.size()), else a when a is valid, else the zero vector.
Vec3 predict_parallelogram(const std::vector<Vec3>& decoded, std::array<int32_t, 3> stencil);

// ---- the frame, inline: the static decoders compute one per vertex ---------------------------------

namespace frame_detail {

// 1 / L for the lengths L = sqrt(squared) of two vectors, each correctly rounded, and whether L is
// positive and finite (else the unit vector is the zero vector). With SSE2 both square roots and
// both divisions are one instruction each: they are most of the unit-normal frame.
struct InverseLengths {
    double r[2];
    bool valid[2];
};
AMC_ALWAYS_INLINE InverseLengths inverse_lengths(double squared0, double squared1) {
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

// v scaled to unit length: each coordinate times 1 / L, each product rounded; the zero vector when
// L is 0 or not finite.
AMC_ALWAYS_INLINE Vec3 scaled_unit(Vec3 v, double r, bool valid) { return valid ? rounded_scaled(r, v) : Vec3{0, 0, 0}; }

// The first axis of largest |N_i|, without branches (the axis is a coin flip on curved surfaces),
// and whether the normal is usable.
AMC_ALWAYS_INLINE void set_axis(NormalFrame& f) {
    const double x = std::fabs(f.normal.x), y = std::fabs(f.normal.y), z = std::fabs(f.normal.z);
    const bool y_wins = y > x;
    const double best = y_wins ? y : x;
    const bool z_wins = z > best;
    f.axis = z_wins ? 2 : int(y_wins);
    const double largest = z_wins ? z : best;
    f.has_normal = largest > 0 && std::isfinite(largest);
}

}  // namespace frame_detail

template <bool UnitNormals, class Mesh>
AMC_ALWAYS_INLINE NormalFrame frame_of(const Mesh& h, const FrameCorners& corners) {
    NormalFrame f;
    const Vec3 a = h.position(corners.a), b = h.position(corners.b), c = h.position(corners.c);
    f.midpoint = rounded_scaled(0.5, a + b);  // predict_midpoint's
    if (h.single_precision()) f.midpoint = rounded_to_float(f.midpoint);
    const bool has_d = corners.d != kNoVertex;
    const Vec3 n1 = exact_cross(b - a, c - a);
    const Vec3 n2 = has_d ? exact_cross(a - b, h.position(corners.d) - b) : Vec3{};
    if (UnitNormals) {
        // Modes 4 and 5 sum unit normals (the remesher's direction, vertex_placement.cpp).
        const frame_detail::InverseLengths r = frame_detail::inverse_lengths(exact_dot(n1, n1), exact_dot(n2, n2));
        f.normal = frame_detail::scaled_unit(n1, r.r[0], r.valid[0]);
        if (has_d) f.normal = f.normal + frame_detail::scaled_unit(n2, r.r[1], r.valid[1]);
    } else {
        // Mode 3 sums the cross products themselves (each weighted by its triangle's area).
        f.normal = has_d ? n1 + n2 : n1;
    }
    frame_detail::set_axis(f);
    return f;
}

#if AMC_SSE2
// Two vertices' frames before their axes, each vertex in one lane: the midpoints' and the
// normals' coordinates (frame_pair_lanes).
struct FramePairLanes {
    __m128d mx, my, mz, nx, ny, nz;
};

// frame_of for two vertices at once, each in one lane of every SSE2 operation: the same IEEE
// operations in the same order, so the same bits. Half the arithmetic instructions of two
// frame_of calls. Not for single-precision hierarchies (their midpoints are rounded to float).
// The midpoints and normals in lanes; frame_pair_of below makes the two frames of them.
template <bool UnitNormals, class Mesh>
AMC_ALWAYS_INLINE FramePairLanes frame_pair_lanes(const Mesh& h, const FrameCorners& k0, const FrameCorners& k1) {
    struct Lanes {  // a Vec3 of each vertex: x, y, z, each holding (first vertex, second vertex)
        __m128d x, y, z;
    };
    const Vec3* positions = h.positions().data();
    auto load = [positions](VertexId v0, VertexId v1) {
        const Vec3& p = positions[v0];
        const Vec3& q = positions[v1];
        const __m128d xy0 = _mm_loadu_pd(&p.x), xy1 = _mm_loadu_pd(&q.x);
        return Lanes{_mm_unpacklo_pd(xy0, xy1), _mm_unpackhi_pd(xy0, xy1), _mm_loadh_pd(_mm_load_sd(&p.z), &q.z)};
    };
    auto sub = [](const Lanes& u, const Lanes& v) { return Lanes{_mm_sub_pd(u.x, v.x), _mm_sub_pd(u.y, v.y), _mm_sub_pd(u.z, v.z)}; };
    // GCC's intrinsics are vector arithmetic: a product fed to an add fuses into an FMA under
    // -ffp-contract=fast unless it goes through `rounded`, as in the scalar frame_of.
    auto mul = [](__m128d u, __m128d v) { return rounded(_mm_mul_pd(u, v)); };
    auto cross = [mul](const Lanes& u, const Lanes& v) {  // exact_cross (exact_float.h)
        return Lanes{_mm_sub_pd(mul(u.y, v.z), mul(u.z, v.y)), _mm_sub_pd(mul(u.z, v.x), mul(u.x, v.z)),
                     _mm_sub_pd(mul(u.x, v.y), mul(u.y, v.x))};
    };
    auto dot = [mul](const Lanes& u) {  // exact_dot(u, u)
        return _mm_add_pd(_mm_add_pd(mul(u.x, u.x), mul(u.y, u.y)), mul(u.z, u.z));
    };
    const bool has_d0 = k0.d != kNoVertex, has_d1 = k1.d != kNoVertex;
    const Lanes a = load(k0.a, k1.a), b = load(k0.b, k1.b), c = load(k0.c, k1.c);
    // A missing d reads a's position: its lane's n2 is computed and then not used.
    const Lanes d = load(has_d0 ? k0.d : k0.a, has_d1 ? k1.d : k1.a);
    const __m128d half = _mm_set1_pd(0.5);
    const Lanes mid{mul(_mm_add_pd(a.x, b.x), half), mul(_mm_add_pd(a.y, b.y), half), mul(_mm_add_pd(a.z, b.z), half)};
    const Lanes n1 = cross(sub(b, a), sub(c, a));
    const Lanes n2 = cross(sub(a, b), sub(d, b));
    const __m128d has_d = _mm_castsi128_pd(_mm_set_epi64x(-int64_t(has_d1), -int64_t(has_d0)));
    // u + v in the lanes that have a d, u alone in the others.
    auto pick = [has_d](__m128d u, __m128d v) { return _mm_or_pd(_mm_and_pd(has_d, _mm_add_pd(u, v)), _mm_andnot_pd(has_d, u)); };
    Lanes n;
    if (UnitNormals) {
        const __m128d zero = _mm_setzero_pd(), infinity = _mm_set1_pd(HUGE_VAL), one = _mm_set1_pd(1.0);
        const __m128d l1 = _mm_sqrt_pd(dot(n1)), l2 = _mm_sqrt_pd(dot(n2));
        const __m128d r1 = _mm_div_pd(one, l1), r2 = _mm_div_pd(one, l2);
        // inverse_lengths' validity: L > 0 and finite (false for NaN); an invalid unit vector is +0.
        const __m128d v1 = _mm_and_pd(_mm_cmpgt_pd(l1, zero), _mm_cmplt_pd(l1, infinity));
        const __m128d v2 = _mm_and_pd(_mm_cmpgt_pd(l2, zero), _mm_cmplt_pd(l2, infinity));
        auto unit = [mul](const Lanes& u, __m128d r, __m128d valid) {
            return Lanes{_mm_and_pd(valid, mul(r, u.x)), _mm_and_pd(valid, mul(r, u.y)), _mm_and_pd(valid, mul(r, u.z))};
        };
        const Lanes u1 = unit(n1, r1, v1), u2 = unit(n2, r2, v2);
        // frame_of adds even an invalid u2's +0 where there is a d.
        n = Lanes{pick(u1.x, u2.x), pick(u1.y, u2.y), pick(u1.z, u2.z)};
    } else {
        n = Lanes{pick(n1.x, n2.x), pick(n1.y, n2.y), pick(n1.z, n2.z)};
    }
    return {mid.x, mid.y, mid.z, n.x, n.y, n.z};
}

template <bool UnitNormals, class Mesh>
AMC_ALWAYS_INLINE void frame_pair_of(const Mesh& h, const FrameCorners& k0, const FrameCorners& k1, NormalFrame& f0,
                                     NormalFrame& f1) {
    const FramePairLanes l = frame_pair_lanes<UnitNormals>(h, k0, k1);
    double mx[2], my[2], mz[2], nx[2], ny[2], nz[2];
    _mm_storeu_pd(mx, l.mx);
    _mm_storeu_pd(my, l.my);
    _mm_storeu_pd(mz, l.mz);
    _mm_storeu_pd(nx, l.nx);
    _mm_storeu_pd(ny, l.ny);
    _mm_storeu_pd(nz, l.nz);
    NormalFrame* out[2] = {&f0, &f1};
    for (int k = 0; k < 2; ++k) {
        NormalFrame& f = *out[k];
        f.midpoint = {mx[k], my[k], mz[k]};
        f.normal = {nx[k], ny[k], nz[k]};
        frame_detail::set_axis(f);
    }
}
#endif

}  // namespace amc
