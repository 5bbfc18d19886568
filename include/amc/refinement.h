// Making hierarchies: procedural base meshes and the adaptive refinement drivers that produce
// realistic red-green hierarchies (curvature-adaptive surface remeshing, planar finite-element
// style refinement, uniform and random refinement for tests).
#pragma once

#include <amc/hierarchy.h>

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace amc {

// ---- procedural base meshes ------------------------------------------------------------------
TriangleMesh make_icosahedron();                  // 12 vertices, 20 triangles, closed, genus 0
TriangleMesh make_torus(int rings, int segments, double major_radius, double minor_radius);  // genus 1
// An irregular mesh of any size: the torus above (radii 3 and 1) with every vertex jittered by up
// to 0.3 of a cell and every cell cut along a random diagonal (valences 3 to 9), coordinates
// rounded to float32; 2 * rings * segments triangles, deterministic per seed.
TriangleMesh make_irregular_torus(int rings, int segments, uint32_t seed);
// A long open strip of `length` x `width` cells, jittered, gently bumped out of the plane and cut
// along random diagonals like the torus above: its conquest keeps a border loop as long as the strip.
TriangleMesh make_irregular_strip(int length, int width, uint32_t seed);
TriangleMesh make_square(int cells);             // [0,1]^2 in z=0, 2*cells^2 triangles, boundary
// L-shaped domain [-1,1]^2 without (0,1]x[-1,0): re-entrant corner at the origin.
TriangleMesh make_l_shape(int cells_per_unit);
// A closed, fine procedural surface: an icosphere subdivided `subdivisions` times and displaced
// radially by smooth bumps, for the embedded default (20 * 4^subdivisions triangles).
TriangleMesh make_bumpy_sphere(int subdivisions);

// ---- simple drivers ------------------------------------------------------------------------
void refine_uniformly(Hierarchy& h, int levels);
// Refines random leaves (below max_level) until the hierarchy has at least `target_leaves`
// leaves; with coarsen_ratio > 0 it also coarsens random nodes on the way. Deterministic per seed.
void refine_randomly(Hierarchy& h, uint32_t target_leaves, int max_level, uint64_t seed,
                     double coarsen_ratio = 0.0);
// Refines every leaf whose size exceeds the local target size given by `size_at(centroid)`,
// until none does or max_level is reached (the classic a-priori adaptive FE loop). Throws
// Error(limit_exceeded) once the hierarchy holds more than `max_nodes` nodes.
void refine_to_size(Hierarchy& h, const std::function<double(Vec3)>& size_at, int max_level,
                    uint64_t max_nodes = ~uint64_t{0});

// ---- surface remeshing -----------------------------------------------------------------------
enum class RefinementCriterion { mean_curvature, gauss_curvature, approximation_error };
// Coordinates of the remesh: float32 when the reference is single precision (the default), or
// as asked.
enum class SurfacePrecision { as_reference, float32, float64 };

struct SurfaceRemeshOptions {
    RefinementCriterion criterion = RefinementCriterion::mean_curvature;
    uint32_t base_triangles = 500;    // target size of the simplified base (others tried if it folds over or misses a thin part)
    uint32_t target_faces = 150000;   // triangles of the conforming leaf mesh to stop at (or just past)
    int max_level = 7;                // 0 .. kMaxLevel
    // Every leaf-mesh triangle gets at least this quality (4 sqrt(3) area / sum of squared
    // edges: 1 equilateral, 0 degenerate), or a third of its base triangle's if that is lower.
    double min_quality = 0.1;
    SurfacePrecision precision = SurfacePrecision::as_reference;
    bool measure = false;             // fill the measures of SurfaceRemeshStats (about 2 s per 10^5 faces)
    // Error(limit_exceeded) once the hierarchy holds more nodes (target_faces up to 2^30 and
    // max_level up to 30 would fill any memory).
    uint64_t max_nodes = ~uint64_t{0};
};

struct SurfaceRemeshStats {
    uint32_t base_triangles = 0;
    uint32_t base_attempts = 0;        // simplifications tried (sizes B, 2B, 4B, 8B, B/2, B/4)
    double base_min_quality = 0;       // of the base after shape improvement
    uint32_t base_fold_overs = 0;      // left in the base (thin parts it cannot show)
    // Largest distance between the base and the reference, both ways (at the reference's vertices
    // and the base's edge midpoints and centroids), relative to the diagonal.
    double base_distance = 0;
    uint32_t faces = 0;                // triangles of the conforming leaf mesh
    uint32_t corrected_vertices = 0;   // new vertices moved by the correction
    uint32_t inherited_fold_overs = 0; // fold-overs left where the flat subdivision of the base folds
    // With options.measure, the leaf mesh against the reference: fold-overs (adjacent triangles
    // whose normals are more than 150 degrees apart), vertices at the position of another vertex,
    // the smallest triangle quality, and the two-sided (Hausdorff) distance relative to the
    // reference's bounding-box diagonal: the largest found, a certified upper bound of it, and the
    // root mean square over both surfaces (docs/REMESHER.md says how they are sampled).
    uint32_t reference_fold_overs = 0; // always filled
    uint32_t fold_overs = 0;
    uint32_t coincident_vertices = 0;
    double min_quality = 0;
    double max_distance = 0, max_distance_bound = 0, rms_distance = 0;
    // False when the distance was not measured: the reference's closest-point queries tested too
    // many triangles each (long thin triangles around one vertex); the three above are then 0.
    bool distance_measured = true;
    double simplify_seconds = 0, refine_seconds = 0, correct_seconds = 0, measure_seconds = 0;
};

// Simplifies `reference` to a coarse base (meshoptimizer; the reference's own triangles kept where
// the simplified base strays from it by more than 1% of the diagonal, a thin part), improves its
// triangles (flips and relaxation on the surface that never move it away from the reference) and
// moves the vertices of any fold-over left until it has none, refines first where the
// base folds over and then greedily where the criterion is largest (curvature of the reference
// times element size, or distance of the element's centroid from the reference) until the leaf
// mesh has `target_faces` triangles, placing every new vertex on the reference (along the
// elements' normal, boundary vertices on the reference's boundary), and finally corrects the
// vertices of fold-overs, triangles below the quality bound and coincident vertices: slid along
// the surface, or stepped back towards their edge midpoints (docs/REMESHER.md). The result has
// no coincident vertices, no triangle below min(min_quality, a third of its base triangle's
// quality), and fold-overs only where the base folds over (none on every mesh measured;
// SurfaceRemeshStats::base_fold_overs says how many the base kept).
// Throws Error if max_level is outside 0..kMaxLevel.
Hierarchy remesh_adaptively(const TriangleMesh& reference, const SurfaceRemeshOptions& options,
                            SurfaceRemeshStats* stats = nullptr);

// ---- planar finite-element style models -------------------------------------------------------
// L-shaped domain graded towards the re-entrant corner: element size size_scale * r^0.6 at
// distance r from it. The default gives 1.2 * 10^5 nodes at max_level 10; the node count grows
// about as 1 / size_scale^2.
Hierarchy make_l_shape_model(int max_level, double size_scale = 0.025);
// A front (a circular arc) sweeping across the unit square: one hierarchy per time step, each
// obtained from the previous one by coarsening behind the front and refining ahead of it. Throws
// Error(limit_exceeded) once the steps' hierarchies, all kept, hold more than `max_nodes` nodes
// together (the front is refined to max_level along its length: 2^max_level nodes and more).
std::vector<Hierarchy> make_moving_front_sequence(int steps, int max_level, uint64_t max_nodes = ~uint64_t{0});

// ---- statistics ------------------------------------------------------------------------------
struct HierarchyStats {
    uint32_t base_triangles = 0, base_vertices = 0;
    uint32_t nodes = 0, leaves = 0, levels = 0, vertices = 0;
    uint32_t faces = 0, red_faces = 0, green_faces = 0;
    uint32_t one_hanging = 0, two_hanging = 0;  // leaves closed by one / two hanging nodes
    std::vector<uint32_t> nodes_per_level;
};
HierarchyStats compute_stats(const Hierarchy& h);

}  // namespace amc
