// The remesher's geometric helpers: triangle quality, fold-overs, coincident vertices, the
// certified two-sided distance, the line and facing queries of the closest-point tree, and the
// base mesh's shape improvement.
#include <gtest/gtest.h>

#include <amc/refinement.h>

#include "geometry/closest_point.h"
#include "geometry/reference_surface.h"
#include "geometry/shape_improvement.h"
#include "geometry/surface_quality.h"

#include <algorithm>
#include <cmath>

namespace amc {
namespace {

TEST(SurfaceQuality, TriangleQualityKnownValues) {
    EXPECT_NEAR(triangle_quality({0, 0, 0}, {1, 0, 0}, {0.5, std::sqrt(3.0) / 2, 0}), 1.0, 1e-15);
    // Right isosceles: area 1/2, squared edges 1 + 1 + 2.
    EXPECT_NEAR(triangle_quality({0, 0, 0}, {1, 0, 0}, {0, 1, 0}), 4 * std::sqrt(3.0) * 0.5 / 4, 1e-15);
    EXPECT_EQ(triangle_quality({0, 0, 0}, {1, 0, 0}, {2, 0, 0}), 0.0);
    EXPECT_EQ(triangle_quality({1, 1, 1}, {1, 1, 1}, {1, 1, 1}), 0.0);
    // Scale and orientation do not matter.
    EXPECT_NEAR(triangle_quality({0, 0, 0}, {0, 1e3, 0}, {0, 0, 2e3}), triangle_quality({0, 0, 0}, {2, 0, 0}, {0, 1, 0}),
                1e-12);
}

TEST(SurfaceQuality, FoldOversCoincidenceAndDegenerates) {
    // Two triangles on the edge (0,0,0)-(1,0,0); the second one's far corner at angle phi.
    auto pair = [](double phi) {
        TriangleMesh m;
        m.positions = {{0, 0, 0}, {1, 0, 0}, {0.5, 1, 0}, {0.5, std::cos(phi), std::sin(phi)}};
        m.triangles = {{0, 1, 2}, {1, 0, 3}};
        return m;
    };
    const double degree = 3.14159265358979323846 / 180;
    // phi is the dihedral opening: the normals are 180 - phi degrees apart.
    EXPECT_EQ(measure_shape(pair(180 * degree)).fold_overs, 0u);  // flat
    EXPECT_EQ(measure_shape(pair(31 * degree)).fold_overs, 0u);   // 149 degrees
    EXPECT_EQ(measure_shape(pair(29 * degree)).fold_overs, 1u);   // 151 degrees
    TriangleMesh m = pair(90 * degree);
    m.positions.push_back(m.positions[2]);
    m.triangles.push_back({1, 4, 3});
    const MeshShape shape = measure_shape(m);
    EXPECT_EQ(shape.coincident_vertices, 2u);
    m.positions[3] = {2, 0, 0};
    EXPECT_EQ(measure_shape(m).degenerate_triangles, 1u);
    EXPECT_EQ(measure_shape(m).min_quality, 0.0);
}

// Two squares of side 1, the second lifted by h and shifted by s along x.
TriangleMesh square(double z, double shift) {
    TriangleMesh m;
    m.positions = {{shift, 0, z}, {1 + shift, 0, z}, {1 + shift, 1, z}, {shift, 1, z}};
    m.triangles = {{0, 1, 2}, {0, 2, 3}};
    return m;
}

TEST(SurfaceDistance, ParallelAndShiftedSquares) {
    // A constant distance is the branch and bound's worst case: the bound d(centroid) + radius
    // only meets it once the pieces are smaller than the tolerance (7 levels of splits for 1e-2).
    const OneSidedDistance parallel = one_sided_distance(square(0.25, 0), square(0, 0), 1e-2);
    EXPECT_NEAR(parallel.max, 0.25, 1e-12);
    EXPECT_NEAR(parallel.rms, 0.25, 1e-12);
    EXPECT_NEAR(parallel.area, 1.0, 1e-12);
    EXPECT_GE(parallel.max_upper, 0.25);
    EXPECT_LE(parallel.max_upper, 0.25 + 1e-2);
    // Shifted by 0.5 in the plane: half of A is over B (distance 0), the rest at distance x - 1
    // for x in (1, 1.5]: max 0.5 on the far edge, mean square the integral of t^2 over [0, 0.5].
    const OneSidedDistance shifted = one_sided_distance(square(0, 0.5), square(0, 0), 1e-2);
    EXPECT_NEAR(shifted.max, 0.5, 1e-12);
    EXPECT_NEAR(shifted.rms, std::sqrt(0.125 / 3), 1e-3);
    // The sup lies on an edge the first pass samples only at its ends and middle: a square
    // tilted so that the farthest point is inside a triangle needs the branch and bound.
    TriangleMesh tent = square(0, 0);
    tent.positions.push_back({0.37, 0.61, 0.3});
    tent.triangles = {{0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}};
    const OneSidedDistance peak = one_sided_distance(tent, square(0, 0), 1e-7);
    EXPECT_NEAR(peak.max, 0.3, 1e-12);
    const OneSidedDistance coarse = one_sided_distance(square(0, 0), tent, 1e-4);
    EXPECT_LE(coarse.max, coarse.max_upper);
    EXPECT_LE(coarse.max_upper - coarse.max, std::max(1e-4, 0.01 * coarse.max) + 1e-12);
    const SurfaceDistance both = surface_distance(square(0, 0), square(0.25, 0), 1e-2);
    EXPECT_NEAR(both.diagonal, std::sqrt(2.0), 1e-15);
    EXPECT_NEAR(both.max, 0.25 / std::sqrt(2.0), 1e-12);
    EXPECT_NEAR(both.rms, 0.25 / std::sqrt(2.0), 1e-12);
}

TEST(SurfaceDistance, MaxIsCertifiedOnASphere) {
    // A coarse sphere against a fine one: the largest distance is inside the coarse triangles,
    // where no vertex, edge midpoint or centroid sits; a dense brute-force sampling must not
    // find more than the certified bound.
    const TriangleMesh fine = make_bumpy_sphere(4);
    const TriangleMesh coarse = make_bumpy_sphere(1);
    const OneSidedDistance d = one_sided_distance(coarse, fine, 1e-6);
    const ClosestPointQuery query(fine);
    double brute = 0;
    const int n = 24;
    for (const Triangle& t : coarse.triangles) {
        for (int i = 0; i <= n; ++i) {
            for (int j = 0; i + j <= n; ++j) {
                const double u = double(i) / n, v = double(j) / n;
                const Vec3 p = (1 - u - v) * coarse.positions[t[0]] + u * coarse.positions[t[1]] + v * coarse.positions[t[2]];
                brute = std::max(brute, std::sqrt(query.closest(p).distance_squared));
            }
        }
    }
    EXPECT_LE(brute, d.max_upper);
    // Within the bound's slack (1% of the maximum) of brute force.
    EXPECT_GE(d.max, brute - std::max(1e-6, 0.01 * d.max)) << "the branch and bound found less than brute force";
}

TEST(ClosestPointQuery, LineAndFacingQueriesMatchBruteForce) {
    const TriangleMesh mesh = make_bumpy_sphere(3);
    const ClosestPointQuery query(mesh);
    uint64_t state = 7;
    auto uniform = [&]() {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        return double(state >> 11) / double(1ull << 53) * 2 - 1;
    };
    for (int i = 0; i < 300; ++i) {
        const Vec3 p{0.8 * uniform(), 0.8 * uniform(), 0.8 * uniform()};
        const Vec3 d{uniform(), uniform(), uniform()};
        // Brute force: the facing triangle hit at least |t|.
        double best = 1e300;
        uint32_t best_t = 0;
        double best_facing = 1e300;
        for (uint32_t t = 0; t < mesh.triangles.size(); ++t) {
            const Vec3 a = mesh.positions[mesh.triangles[t][0]], b = mesh.positions[mesh.triangles[t][1]],
                       c = mesh.positions[mesh.triangles[t][2]];
            const Vec3 n = cross(b - a, c - a);
            if (!(dot(n, d) > 0)) continue;
            Vec3 w;
            const Vec3 q = closest_point_on_triangle(p, a, b, c, w);
            best_facing = std::min(best_facing, std::sqrt(dot(q - p, q - p)));
            // Line-plane intersection inside the triangle.
            const double s = dot(n, a - p) / dot(n, d);
            const Vec3 x = p + s * d;
            const double area = std::sqrt(dot(n, n));
            const double u = dot(cross(c - b, x - b), n) / (area * area), v = dot(cross(a - c, x - c), n) / (area * area);
            if (u < -1e-12 || v < -1e-12 || u + v > 1 + 1e-12) continue;
            const double distance = std::fabs(s) * std::sqrt(dot(d, d));
            if (distance < best) {
                best = distance;
                best_t = t;
            }
        }
        const auto hit = query.intersect_line(p, d, 10.0);
        ASSERT_EQ(hit.has_value(), best < 1e300);
        if (hit) {
            EXPECT_NEAR(std::sqrt(hit->distance_squared), best, 1e-9);
            (void)best_t;
        }
        const auto facing = query.closest_facing(p, d, 0.0, 10.0);
        ASSERT_TRUE(facing.has_value());
        EXPECT_NEAR(std::sqrt(facing->distance_squared), best_facing, 1e-12);
        // Beyond the reach there is nothing.
        EXPECT_FALSE(query.intersect_line(p, d, 0.5 * best).has_value() && best < 1e300);
    }
}

TEST(ShapeImprovement, RaisesTheWorstQualityAndStaysOnTheSurface) {
    // The reference: a fine flat grid. The coarse mesh: the same square with slivers (the
    // interior vertex (0.25, 0.25) squeezed near the boundary edge below it, still inside its
    // star, the square [0, 0.5]^2), its boundary as is.
    const TriangleMesh reference = make_square(20);
    TriangleMesh coarse = make_square(4);
    int squeezed = 0;
    for (Vec3& p : coarse.positions) {
        if (p.x == 0.25 && p.y == 0.25) {
            p = {0.22, 0.01, 0};
            ++squeezed;
        }
    }
    ASSERT_EQ(squeezed, 1);
    const double before = measure_shape(coarse).min_quality;
    const ReferenceSurface surface(reference);
    const ShapeImprovementStats stats = improve_shapes(coarse, surface, reference, {});
    EXPECT_EQ(stats.min_quality_before, before);
    EXPECT_GT(stats.min_quality_after, before + 0.1);
    EXPECT_EQ(measure_shape(coarse).min_quality, stats.min_quality_after);
    EXPECT_EQ(stats.fold_overs_after, 0u);
    for (const Vec3& p : coarse.positions) EXPECT_NEAR(p.z, 0.0, 1e-15);
    // Boundary vertices do not move.
    const TriangleMesh original = make_square(4);
    for (size_t v = 0; v < coarse.positions.size(); ++v) {
        const Vec3 p = original.positions[v];
        if (p.x == 0 || p.y == 0 || p.x == 1 || p.y == 1) {
            EXPECT_TRUE(coarse.positions[v] == p);
        }
    }
    EXPECT_NO_THROW(validate_triangle_mesh(coarse, "improved"));
}

TEST(ShapeImprovement, UnfoldRemovesFoldOversByTheLeastMove) {
    // The centre vertex of a flat 4x4 grid dragged across its neighbour at (0.75, 0.5): some of
    // its triangles turn over (normals opposite to their neighbours', fold-overs).
    TriangleMesh mesh = make_square(4);
    uint32_t dragged = 0;
    for (uint32_t v = 0; v < mesh.positions.size(); ++v)
        if (mesh.positions[v] == Vec3{0.5, 0.5, 0}) dragged = v;
    mesh.positions[dragged] = {0.9, 0.55, 0};
    const TriangleMesh folded = mesh;
    ASSERT_GT(measure_shape(mesh).fold_overs, 0u);
    EXPECT_EQ(unfold(mesh, 0.1), 0u);
    const MeshShape shape = measure_shape(mesh);
    EXPECT_EQ(shape.fold_overs, 0u);
    EXPECT_EQ(shape.degenerate_triangles, 0u);
    EXPECT_EQ(shape.coincident_vertices, 0u);
    EXPECT_GT(shape.min_quality, 0.0);
    // Only vertices of fold-overs move, within the plane; the boundary stays.
    for (size_t v = 0; v < mesh.positions.size(); ++v) {
        const Vec3 p = folded.positions[v];
        EXPECT_EQ(mesh.positions[v].z, 0.0);
        if (p.x == 0 || p.y == 0 || p.x == 1 || p.y == 1) {
            EXPECT_TRUE(mesh.positions[v] == p);
        }
    }
    // A mesh without fold-overs is left as it is.
    TriangleMesh flat = make_square(4);
    EXPECT_EQ(unfold(flat, 0.1), 0u);
    for (size_t v = 0; v < flat.positions.size(); ++v) EXPECT_TRUE(flat.positions[v] == make_square(4).positions[v]);
}

}  // namespace
}  // namespace amc
