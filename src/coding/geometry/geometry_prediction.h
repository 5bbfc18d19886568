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
#include "common/exact_float.h"

#include <amc/hierarchy.h>

#include <array>
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
Vec3 predict_midpoint(const Hierarchy& h, NodeId n, int e);

// The 8-point butterfly stencil (Dyn, Levin, Gregory 1990) for edge e of node n on n's level:
//   1/2 (a + b) + 1/8 (c + d) - 1/16 (w_bc + w_ca + w_ad + w_db)
// with a, b the edge's end points, c the vertex of n opposite the edge, d the vertex opposite
// the edge in the same-level neighbour q across e, and w_xy the vertex opposite edge xy in the
// same-level neighbour across xy (of n for bc, ca; of q for ad, db).
// A missing wing (boundary or coarser region) is replaced by its parallelogram reflection
// (w_bc = b + c - a, and so on), which keeps the stencil affine and exact for planar data; when
// q is missing (boundary edge) the prediction is the midpoint. Rounded to float for
// single-precision hierarchies.
Vec3 predict_butterfly(const Hierarchy& h, NodeId n, int e);

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
// unit_normals (geometry mode 4, FORMAT.md 5.7): N is the sum of the two triangles' unit normals
// instead, the direction along which the surface remesher places the vertex.
NormalFrame normal_frame(const Hierarchy& h, NodeId n, int e, bool unit_normals = false);
// normal_frame in two steps, for decoders that gather many vertices' corners (and prefetch their
// positions) before computing their frames: the corners a frame reads, a, b, c of node n (edge e
// runs a -> b) and d, the vertex opposite the edge in the same-level neighbour (kNoVertex at a
// boundary); then the frame from their positions.
struct FrameCorners {
    VertexId a, b, c, d;
};
FrameCorners frame_corners(const Hierarchy& h, NodeId n, int e);
NormalFrame frame_of(const Hierarchy& h, const FrameCorners& corners, bool unit_normals);

// Parallelogram rule over already decoded positions: a + b - c when all three indices are valid
// (>= 0 and < decoded.size()), else a when a is valid, else the zero vector.
Vec3 predict_parallelogram(const std::vector<Vec3>& decoded, std::array<int32_t, 3> stencil);

}  // namespace amc
