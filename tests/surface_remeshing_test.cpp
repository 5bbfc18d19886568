// The surface remesher's guarantees (docs/REMESHER.md) on procedural surfaces: no fold-overs
// (even where the reference has its own), no coincident vertices, the quality bound, the face count, the
// precision, and thin parts kept.
#include "hierarchy_checks.h"

#include "geometry/surface_quality.h"

#include <cmath>

namespace amc {
namespace {

// A thin shape: the bumpy sphere flattened to a wavy disk 1/25 as thick as it is wide, whose two
// sheets a projection onto the nearest point would mix up.
TriangleMesh thin_disk() {
    TriangleMesh mesh = make_bumpy_sphere(4);
    for (Vec3& p : mesh.positions) p.z = double(float(0.04 * p.z));
    return mesh;
}

// A reference with fold-overs of its own, as scanned meshes have (femur, horse, venus): one vertex
// of the bumpy sphere dragged across a neighbour, turning some of its triangles over.
TriangleMesh dragged_vertex() {
    TriangleMesh mesh = make_bumpy_sphere(4);
    const uint32_t v = mesh.triangles[100][0], w = mesh.triangles[100][1];
    mesh.positions[v] = mesh.positions[v] + 1.6 * (mesh.positions[w] - mesh.positions[v]);
    return mesh;
}

// A thin tube: a torus whose tube is 1/50 of its size, which a simplifier collapses into
// "pillows" (two triangles on three vertices) or drops where the base is too coarse for it.
TriangleMesh thin_tube() { return make_torus(96, 12, 1.0, 0.04); }

struct Case {
    const char* name;
    TriangleMesh reference;
    uint32_t base_triangles, target_faces;
    int max_level;
    // The reference has fold-overs of its own (the thin disk's rim, from its float32 z rounding;
    // the dragged vertex): the remesh has none all the same.
    bool reference_folds;
    // Bound of the Hausdorff distance relative to the diagonal. The thin disk is 0.04 thick, 1.4%
    // of its diagonal: a lost sheet would put the other at that distance.
    double max_distance;
};

std::vector<Case> cases() {
    return {{"bumpy sphere", make_bumpy_sphere(4), 200, 12000, 6, false, 0.015},
            {"torus", make_torus(24, 48, 1.0, 0.3), 300, 12000, 6, false, 0.015},
            {"thin disk", thin_disk(), 300, 12000, 6, true, 0.007},
            {"dragged vertex", dragged_vertex(), 200, 12000, 6, true, 0.015},
            {"thin tube", thin_tube(), 60, 12000, 6, false, 0.007}};
}

// Every leaf triangle's quality against its bound: min(min_quality, a third of its base
// triangle's quality).
double worst_quality_margin(const Hierarchy& h, const LeafMesh& leaf, double min_quality) {
    double worst = 1e300;
    for (size_t t = 0; t < leaf.mesh.triangles.size(); ++t) {
        const Triangle& c = leaf.mesh.triangles[t];
        NodeId root = leaf.source[t];
        while (h.parent(root) != kNoNode) root = h.parent(root);
        const Triangle& b = h.base().triangles[root];
        const auto& bp = h.base().positions;
        const double bound = std::min(min_quality, triangle_quality(bp[b[0]], bp[b[1]], bp[b[2]]) / 3);
        const auto& p = leaf.mesh.positions;
        worst = std::min(worst, triangle_quality(p[c[0]], p[c[1]], p[c[2]]) - 0.999 * bound);
    }
    return worst;
}

TEST(SurfaceRemeshing, KeepsItsGuarantees) {
    for (const Case& c : cases()) {
        SCOPED_TRACE(c.name);
        SurfaceRemeshOptions options;
        options.base_triangles = c.base_triangles;
        options.target_faces = c.target_faces;
        options.max_level = c.max_level;
        options.measure = true;
        SurfaceRemeshStats stats;
        const Hierarchy h = remesh_adaptively(c.reference, options, &stats);
        ASSERT_TRUE(testing::hierarchy_is_valid(h));
        const LeafMesh leaf = extract_leaf_mesh(h);
        const MeshShape shape = measure_shape(leaf.mesh);
        // No fold-over at all (so none added to the reference's own), none left in the base.
        EXPECT_EQ(shape.fold_overs, 0u);
        EXPECT_LE(shape.fold_overs, stats.reference_fold_overs);
        EXPECT_EQ(stats.base_fold_overs, 0u);
        EXPECT_EQ(stats.inherited_fold_overs, 0u);
        EXPECT_EQ(shape.coincident_vertices, 0u);
        EXPECT_EQ(shape.degenerate_triangles, 0u);
        EXPECT_GE(worst_quality_margin(h, leaf, options.min_quality), 0.0);
        EXPECT_GE(shape.min_quality, 0.01);
        EXPECT_EQ(stats.reference_fold_overs > 0, c.reference_folds);
        EXPECT_LE(stats.base_distance, 0.01) << "the base misses a part of the reference";
        // --faces counts the conforming leaf mesh's triangles; the last refinement overshoots by
        // a handful.
        EXPECT_EQ(stats.faces, leaf.mesh.triangles.size());
        EXPECT_GE(stats.faces, c.target_faces);
        EXPECT_LE(stats.faces, c.target_faces + c.target_faces / 100);
        // The measures agree with an independent measurement, and the remesh is close: the thin
        // disk keeps both its sheets (one lost would put the other at the disk's thickness, 0.04,
        // about 1.4% of its diagonal).
        EXPECT_EQ(stats.fold_overs, shape.fold_overs);
        EXPECT_EQ(stats.min_quality, shape.min_quality);
        const SurfaceDistance d = surface_distance(c.reference, leaf.mesh);
        EXPECT_EQ(stats.max_distance, d.max);
        EXPECT_LE(stats.max_distance, stats.max_distance_bound);
        EXPECT_LT(stats.max_distance_bound, c.max_distance);
        EXPECT_LT(stats.rms_distance, 0.001);
    }
}

TEST(SurfaceRemeshing, CriteriaAllKeepTheGuarantees) {
    const TriangleMesh reference = make_bumpy_sphere(4);
    for (RefinementCriterion criterion : {RefinementCriterion::mean_curvature, RefinementCriterion::gauss_curvature,
                                          RefinementCriterion::approximation_error}) {
        SurfaceRemeshOptions options;
        options.criterion = criterion;
        options.base_triangles = 200;
        options.target_faces = 8000;
        options.max_level = 5;
        SurfaceRemeshStats stats;
        const Hierarchy h = remesh_adaptively(reference, options, &stats);
        EXPECT_TRUE(testing::hierarchy_is_valid(h));
        EXPECT_LE(h.depth(), 5);
        EXPECT_GT(h.depth(), 2);
        const LeafMesh leaf = extract_leaf_mesh(h);
        const MeshShape shape = measure_shape(leaf.mesh);
        EXPECT_EQ(shape.fold_overs, 0u);
        EXPECT_EQ(shape.coincident_vertices, 0u);
        EXPECT_GE(worst_quality_margin(h, leaf, options.min_quality), 0.0);
        EXPECT_EQ(stats.faces, leaf.mesh.triangles.size());
        EXPECT_NEAR(double(stats.faces), 8000.0, 80.0);
        EXPECT_GT(compute_stats(h).green_faces, 0u) << "adaptive: several levels carry leaves";
    }
}

TEST(SurfaceRemeshing, KeepsFloat32UnlessAsked) {
    const TriangleMesh reference = make_bumpy_sphere(3);  // single precision
    ASSERT_TRUE(reference.single_precision);
    SurfaceRemeshOptions options;
    options.base_triangles = 100;
    options.target_faces = 3000;
    options.max_level = 5;
    auto all_float = [](const Hierarchy& h) {
        for (const Vec3& p : h.positions())
            if (double(float(p.x)) != p.x || double(float(p.y)) != p.y || double(float(p.z)) != p.z) return false;
        return true;
    };
    const Hierarchy kept = remesh_adaptively(reference, options);
    EXPECT_TRUE(kept.single_precision());
    EXPECT_TRUE(all_float(kept));
    options.precision = SurfacePrecision::float64;
    const Hierarchy wide = remesh_adaptively(reference, options);
    EXPECT_FALSE(wide.single_precision());
    EXPECT_FALSE(all_float(wide)) << "projected points are not float32 values";
    TriangleMesh double_reference = reference;
    double_reference.single_precision = false;
    options.precision = SurfacePrecision::float32;
    const Hierarchy narrowed = remesh_adaptively(double_reference, options);
    EXPECT_TRUE(narrowed.single_precision());
    EXPECT_TRUE(all_float(narrowed));
}

TEST(SurfaceRemeshing, SmallReferencesAndBadOptions) {
    // A reference smaller than the base asked for is its own base (meshoptimizer asserts on it).
    SurfaceRemeshOptions options;
    options.base_triangles = 500;
    options.target_faces = 2000;
    options.max_level = 4;
    SurfaceRemeshStats stats;
    const Hierarchy h = remesh_adaptively(make_icosahedron(), options, &stats);
    EXPECT_EQ(stats.base_triangles, 20u);
    EXPECT_TRUE(testing::hierarchy_is_valid(h));
    options.max_level = kMaxLevel + 1;
    EXPECT_THROW(remesh_adaptively(make_icosahedron(), options), Error);
    options.max_level = -1;
    EXPECT_THROW(remesh_adaptively(make_icosahedron(), options), Error);
}

}  // namespace
}  // namespace amc
