// Discrete curvature of a triangle mesh, per vertex (Meyer, Desbrun, Schroeder, Barr: "Discrete
// Differential-Geometry Operators for Triangulated 2-Manifolds", 2003), and evaluation of a
// per-vertex field at a closest-point hit. The adaptive refinement driver refines where the
// reference surface bends.
//
// Conventions shared by every function here:
// - Areas are Meyer's mixed Voronoi areas (section 3.3): the Voronoi area of the vertex inside
//   each non-obtuse incident triangle, half the triangle's area at an obtuse corner, a quarter at
//   the other two corners of an obtuse triangle. They partition the surface area exactly.
// - Degenerate triangles (area at most 1e-12 times the squared longest edge, or non-finite) are
//   skipped: they add no area, angle or Laplacian term. Cotangents are clamped to +-1e6. A vertex
//   with no area left (isolated, or only degenerate triangles around it) gets curvature 0.
//   Outputs are always finite.
// - A boundary vertex is one on an edge used by exactly one triangle; other vertices are
//   interior (meshes are expected to be edge-manifold, see validate_triangle_mesh).
#pragma once

#include <cstdint>
#include <vector>

#include "amc/mesh.h"
#include "geometry/closest_point.h"

namespace amc {

double triangle_area(Vec3 a, Vec3 b, Vec3 c);

// 1 for every vertex on an edge used by exactly one triangle, else 0.
std::vector<uint8_t> boundary_vertices(const TriangleMesh& mesh);

// Meyer's mixed area of every vertex (0 for vertices in no non-degenerate triangle).
std::vector<double> mixed_areas(const TriangleMesh& mesh);

// Absolute mean curvature |H| per vertex, from the cotangent Laplacian (Meyer et al. eq. 8):
// K(x_i) = 1/(2 A_mixed) sum_j (cot alpha_ij + cot beta_ij)(x_i - x_j) = 2 H n, |H| = |K| / 2.
// A sphere of radius r gives 1/r.
// Boundary vertices get the mean |H| of their interior neighbours (0 if they have none). The
// cotangent formula itself does not work there: over an open fan it is the area gradient, which
// pulls across the boundary with a force of order h against a curvature signal of order h^2, and
// neither projecting it on a one-sided vertex normal nor adding the boundary conormal term of
// Meyer's line integral recovers the curvature (both are off by O(1) on a hemisphere's rim,
// because one-sided normals are only first-order accurate). A flat patch gives 0 everywhere.
std::vector<double> mean_curvature(const TriangleMesh& mesh);

// Gauss curvature K per vertex, the angle defect over the mixed area (Meyer et al. eq. 9):
// interior (2 pi - sum of angles) / A_mixed, boundary (pi - sum of angles) / A_mixed.
// The boundary convention counts the boundary's turning angle (its geodesic curvature) as defect:
// a geodesic rim such as a hemisphere's equator shows the Gauss curvature, the corner of a flat
// square shows (pi/2) / A_mixed. (boundary_vertices() lets a caller mask the rim instead.) With
// it the discrete Gauss-Bonnet theorem holds to rounding: sum_i K_i A_mixed,i = 2 pi chi
// (chi = V - E + F) for any mesh with or without boundary, provided no triangle is degenerate
// and every vertex is in a triangle. A sphere of radius r gives about 1/r^2 at every vertex.
std::vector<double> gauss_curvature(const TriangleMesh& mesh);

// A per-vertex field (e.g. a curvature) at a hit on `mesh`, interpolated linearly with the hit's
// barycentric weights. Throws Error if the field or the hit does not belong to the mesh.
double interpolate_at(const TriangleMesh& mesh, const std::vector<double>& per_vertex,
                      const ClosestPointQuery::Hit& hit);

}  // namespace amc
