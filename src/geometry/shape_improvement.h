// Better-shaped triangles for a coarse mesh that approximates a reference surface: edge flips and
// tangential relaxation with projection back onto the reference. The surface remesher runs it on
// the simplifier's base mesh, whose slivers would otherwise be subdivided into thousands of
// slivers that the smallest projection offset flips over (docs/REMESHER.md).
#pragma once

#include <cstdint>
#include <vector>

#include "amc/mesh.h"
#include "geometry/reference_surface.h"

namespace amc {

struct ShapeImprovementStats {
    double min_quality_before = 0, min_quality_after = 0;  // triangle_quality
    uint32_t fold_overs_before = 0, fold_overs_after = 0;
    uint32_t flips = 0, moves = 0;
};

// Improves `mesh` (whose vertices lie on `surface`, the surface of `reference`) in place, in
// rounds of (a) edge flips where the two triangles are nearly planar and the flip raises the
// smaller quality, or where they fold over, and (b) moves of every vertex that is not locked (nor
// on the boundary) halfway to the centroid of its triangles, in their tangent plane, projected
// onto the surface. A step is kept only if it removes a fold-over or raises the worst quality it
// touches, adds no fold-over, and moves neither the changed triangles farther from the
// reference vertices nearest to them nor their chords farther from the surface than they were
// or than the largest such distance of the mesh as it came: the mesh's one-sided distances to
// the reference (at the reference vertices, and at the chords' midpoints and centroids) do not
// grow, so no thin part is lost. With mesh.single_precision moved vertices are rounded to float.
// The connectivity stays edge-manifold and consistently oriented; the vertex count stays.
ShapeImprovementStats improve_shapes(TriangleMesh& mesh, const ReferenceSurface& surface, const TriangleMesh& reference,
                                     const std::vector<uint8_t>& locked, int rounds = 3);

// Moves vertices of fold-overs of `mesh` (not on its boundary) towards the centroid of their neighbours (off the
// surface: a fold-over of a coarse mesh is a defect of its reference or a part too thin for it),
// each by the least of 1/16, 1/8, 1/4, 1/2, 3/4 or all of the way that lowers the
// fold-overs around it and leaves its triangles a quality of at least `min_quality` (or what they
// had). Rounds until no fold-over is left or none moves; returns the fold-overs left. With
// mesh.single_precision moved vertices are rounded to float.
uint32_t unfold(TriangleMesh& mesh, double min_quality, int rounds = 16);

// Per vertex of `mesh`: 1 where two of its incident triangles meet at an edge at more than
// `degrees` (between their normals): a crease or corner that relaxation must not smooth away.
std::vector<uint8_t> sharp_vertices(const TriangleMesh& mesh, double degrees);

}  // namespace amc
