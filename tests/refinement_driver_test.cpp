// The refinement drivers: surface remeshing onto a reference, finite-element style models.
#include "hierarchy_checks.h"

#include <cmath>

namespace amc {
namespace {

TEST(RefinementDrivers, SurfaceRemeshingProjectsOntoTheReference) {
    const TriangleMesh reference = make_bumpy_sphere(4);
    for (RefinementCriterion criterion : {RefinementCriterion::mean_curvature, RefinementCriterion::gauss_curvature,
                                          RefinementCriterion::approximation_error}) {
        SurfaceRemeshOptions options;
        options.criterion = criterion;
        options.base_triangles = 200;
        options.target_faces = 8000;
        options.max_level = 5;
        const Hierarchy h = remesh_adaptively(reference, options);
        EXPECT_GE(extract_leaf_mesh(h).mesh.triangles.size(), 8000u);  // target_faces counts triangles
        EXPECT_LE(h.depth(), 5);
        EXPECT_GT(h.depth(), 2);
        EXPECT_TRUE(h.single_precision());
        EXPECT_TRUE(testing::hierarchy_is_valid(h));
        EXPECT_EQ(testing::euler_characteristic(h.base()), 2);
        // New vertices lie on the bumpy surface: radius within the bump range.
        for (uint32_t v = 0; v < h.positions().size(); ++v) {
            const Vec3 p = h.position(v);
            const double r = std::sqrt(dot(p, p));
            EXPECT_GT(r, 0.7);
            EXPECT_LT(r, 1.35);
        }
        // Adaptive: several levels carry leaves.
        const HierarchyStats s = compute_stats(h);
        EXPECT_GT(s.green_faces, 0u);
    }
}

TEST(RefinementDrivers, LShapeIsGradedTowardsTheCorner) {
    const Hierarchy h = make_l_shape_model(8);
    EXPECT_TRUE(testing::hierarchy_is_valid(h));
    EXPECT_EQ(h.depth(), 8);
    // The finest leaves touch the re-entrant corner; the far corner stays coarse.
    double finest_distance = 1e9;
    for (NodeId n : h.leaves()) {
        if (h.level(n) != 8) continue;
        for (int i = 0; i < 3; ++i) {
            const Vec3 p = h.position(h.vertex(n, i));
            finest_distance = std::min(finest_distance, std::sqrt(p.x * p.x + p.y * p.y));
        }
    }
    EXPECT_EQ(finest_distance, 0.0);
}

TEST(RefinementDrivers, MovingFrontMovesAndStaysValid) {
    const std::vector<Hierarchy> steps = make_moving_front_sequence(4, 7);
    ASSERT_EQ(steps.size(), 4u);
    for (const Hierarchy& h : steps) {
        EXPECT_TRUE(testing::hierarchy_is_valid(h));
        EXPECT_EQ(h.depth(), 7);
    }
    EXPECT_FALSE(identical(steps[0], steps[1]));
    EXPECT_EQ(steps[0].root_count(), steps[3].root_count()) << "one base mesh for all time steps";
}

}  // namespace
}  // namespace amc
