// How good a triangle mesh is as an approximation of another: the measures the surface remesher
// promises to keep bounded (fold-overs, triangle quality, coincident vertices) and the two-sided
// distance between two surfaces. Used by remesh_adaptively, its tests and bench/remesh_quality.
#pragma once

#include <cstdint>
#include <vector>

#include "amc/mesh.h"

namespace amc {

// A fold-over: two triangles sharing an edge whose normals are more than this far apart (the
// surface turns back on itself at that edge; 180 degrees is a flat double sheet).
constexpr double kFoldOverDegrees = 150.0;

// Triangle quality 4 sqrt(3) area / (l0^2 + l1^2 + l2^2): 1 for an equilateral triangle, 0 for a
// degenerate one; never above sqrt(3) sin(smallest angle) (so quality q guarantees a smallest
// angle of at least asin(q / sqrt(3))). Scale invariant.
double triangle_quality(Vec3 a, Vec3 b, Vec3 c);

// Two triangles with these (unnormalized) normals, adjacent, make a fold-over; never for a zero
// normal (a degenerate triangle has none: it is counted by its quality instead).
bool is_fold_over(Vec3 normal_a, Vec3 normal_b);

struct MeshShape {
    uint32_t fold_overs = 0;           // interior edges whose triangles make a fold-over
    uint32_t degenerate_triangles = 0; // zero area (no normal)
    uint32_t coincident_vertices = 0;  // vertices at the exact position of another vertex
    double min_quality = 1;            // smallest triangle_quality (1 for a mesh without triangles)
    double mean_quality = 0;
};
// Edges are matched by their vertex ids (an edge-manifold mesh: validate_triangle_mesh).
MeshShape measure_shape(const TriangleMesh& mesh);

// The distance from surface A to surface B, one direction: sup and root mean square over the
// points of A of their distance to B.
//
// The maximum is certified: distance-to-B is 1-Lipschitz, so over a triangle with centroid g it
// is at most d(g) + (largest distance from g to a corner). A branch and bound splits (1-to-4) the
// triangles whose bound exceeds the largest distance found so far, until no bound exceeds it by
// more than max(`tolerance`, 1% of it): then max_found <= sup <= max_upper <= max_found +
// max(tolerance, 0.01 max_found) (a budget of evaluations stops it earlier: max_upper still
// bounds it). The mean square is the integral of
// d^2 by the 7-point rule on every triangle (corners, edge midpoints, centroid; exact for cubics).
struct OneSidedDistance {
    double max = 0;        // largest distance found at a sample point (a lower bound of the sup)
    Vec3 max_point;        // that sample point, on A
    double max_upper = 0;  // an upper bound of the sup
    double rms = 0;        // sqrt(integral of d^2 / area)
    double area = 0;       // area of A
    uint64_t evaluations = 0;
    uint64_t tested = 0;    // boxes and triangles of B the closest-point queries tested
    // False when the queries tested more than the evaluations warrant (a reference of long thin
    // triangles around one vertex, whose boxes all overlap there): nothing is measured.
    bool complete = true;
};
OneSidedDistance one_sided_distance(const TriangleMesh& from, const TriangleMesh& to, double tolerance);

// Both directions, relative to the bounding-box diagonal of `reference` (the measures a user
// reads: 1e-3 is a thousandth of the model's size).
struct SurfaceDistance {
    double max = 0;        // Hausdorff distance: the larger of the two one-sided maxima
    double max_upper = 0;  // its certified upper bound
    double rms = 0;        // sqrt of (integral of d^2 over both surfaces) / (both areas)
    double diagonal = 0;   // bounding-box diagonal of the reference, the unit of the three above
    OneSidedDistance to_reference, from_reference;  // absolute units
    bool complete() const { return to_reference.complete && from_reference.complete; }
};
// `tolerance` is relative to the diagonal.
SurfaceDistance surface_distance(const TriangleMesh& reference, const TriangleMesh& approximation,
                                 double tolerance = 1e-5);

double bounding_box_diagonal(const TriangleMesh& mesh);

}  // namespace amc
