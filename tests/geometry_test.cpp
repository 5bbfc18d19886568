// Geometric queries of the refinement driver: closest point on a mesh (against brute force) and
// discrete curvature (against the smooth surfaces the meshes sample).
#include "random_hierarchies.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <utility>
#include <vector>

#include "geometry/closest_point.h"
#include "geometry/curvature.h"

namespace amc {
namespace {

constexpr double kPi = 3.14159265358979323846;

double length(Vec3 v) { return std::sqrt(dot(v, v)); }
Vec3 normalized(Vec3 v) { return (1 / length(v)) * v; }

// --- Procedural meshes ---------------------------------------------------------------------

// Icosahedron subdivided `levels` times (each triangle into four), projected onto the sphere.
TriangleMesh icosphere(int levels, double radius) {
    const double g = (1 + std::sqrt(5.0)) / 2;
    TriangleMesh mesh;
    mesh.positions = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0}, {0, -1, g}, {0, 1, g},
                      {0, -1, -g}, {0, 1, -g}, {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
    mesh.triangles = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                      {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                      {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                      {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
    for (Vec3& p : mesh.positions) p = normalized(p);
    for (int level = 0; level < levels; ++level) {
        std::map<std::pair<uint32_t, uint32_t>, uint32_t> midpoints;
        auto midpoint = [&](uint32_t a, uint32_t b) {
            auto key = std::minmax(a, b);
            auto it = midpoints.find(key);
            if (it != midpoints.end()) return it->second;
            uint32_t index = static_cast<uint32_t>(mesh.positions.size());
            mesh.positions.push_back(normalized(mesh.positions[a] + mesh.positions[b]));
            midpoints.emplace(key, index);
            return index;
        };
        std::vector<Triangle> finer;
        for (const Triangle& t : mesh.triangles) {
            uint32_t ab = midpoint(t[0], t[1]), bc = midpoint(t[1], t[2]),
                     ca = midpoint(t[2], t[0]);
            finer.push_back({t[0], ab, ca});
            finer.push_back({t[1], bc, ab});
            finer.push_back({t[2], ca, bc});
            finer.push_back({ab, bc, ca});
        }
        mesh.triangles = std::move(finer);
    }
    for (Vec3& p : mesh.positions) p = radius * p;
    return mesh;
}

// Regular grid over [0, 1]^2 in the plane z = 0, interior vertices jittered within the plane.
TriangleMesh jittered_grid(int n, uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> jitter(-0.3 / n, 0.3 / n);
    TriangleMesh mesh;
    for (int j = 0; j <= n; ++j) {
        for (int i = 0; i <= n; ++i) {
            Vec3 p{double(i) / n, double(j) / n, 0};
            if (i > 0 && i < n && j > 0 && j < n) {
                p.x += jitter(rng);
                p.y += jitter(rng);
            }
            mesh.positions.push_back(p);
        }
    }
    auto id = [n](int i, int j) { return static_cast<uint32_t>(j * (n + 1) + i); };
    for (int j = 0; j < n; ++j) {
        for (int i = 0; i < n; ++i) {
            mesh.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
            mesh.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
        }
    }
    return mesh;
}

// Torus with tube radius r around a circle of radius R, nu x nv quads split into triangles.
TriangleMesh torus(double R, double r, int nu, int nv) {
    TriangleMesh mesh;
    for (int j = 0; j < nv; ++j) {
        for (int i = 0; i < nu; ++i) {
            double u = 2 * kPi * i / nu, v = 2 * kPi * j / nv;
            mesh.positions.push_back({(R + r * std::cos(v)) * std::cos(u),
                                      (R + r * std::cos(v)) * std::sin(u), r * std::sin(v)});
        }
    }
    auto id = [nu, nv](int i, int j) { return static_cast<uint32_t>((j % nv) * nu + i % nu); };
    for (int j = 0; j < nv; ++j) {
        for (int i = 0; i < nu; ++i) {
            mesh.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
            mesh.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
        }
    }
    return mesh;
}

// Upper hemisphere z >= 0 of radius `radius`: a pole and `rings` latitude rings of `segments`
// vertices, the last ring on the equator (the boundary).
TriangleMesh hemisphere(double radius, int rings, int segments) {
    TriangleMesh mesh;
    mesh.positions.push_back({0, 0, radius});
    for (int k = 1; k <= rings; ++k) {
        double polar = 0.5 * kPi * k / rings;
        for (int s = 0; s < segments; ++s) {
            double azimuth = 2 * kPi * (s + 0.5 * k) / segments;  // staggered rings
            mesh.positions.push_back({radius * std::sin(polar) * std::cos(azimuth),
                                      radius * std::sin(polar) * std::sin(azimuth),
                                      radius * std::cos(polar)});
        }
    }
    auto id = [segments](int k, int s) {
        return static_cast<uint32_t>(1 + (k - 1) * segments + (s % segments));
    };
    for (int s = 0; s < segments; ++s) mesh.triangles.push_back({0, id(1, s), id(1, s + 1)});
    for (int k = 1; k < rings; ++k) {
        for (int s = 0; s < segments; ++s) {
            mesh.triangles.push_back({id(k, s), id(k + 1, s), id(k + 1, s + 1)});
            mesh.triangles.push_back({id(k, s), id(k + 1, s + 1), id(k, s + 1)});
        }
    }
    return mesh;
}

// Random triangle soup in [0, 1]^3: small and large triangles, some degenerate, some repeated.
TriangleMesh random_soup(int triangle_count, uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> unit(0, 1);
    std::uniform_real_distribution<double> offset(-0.05, 0.05);
    TriangleMesh mesh;
    for (int t = 0; t < triangle_count; ++t) {
        Vec3 a{unit(rng), unit(rng), unit(rng)};
        Vec3 b = a + Vec3{offset(rng), offset(rng), offset(rng)};
        Vec3 c = a + Vec3{offset(rng), offset(rng), offset(rng)};
        if (t % 50 == 7) c = a + 0.37 * (b - a);  // collinear
        if (t % 50 == 13) b = c = a;              // a point
        if (t % 10 == 3) b = a + 10.0 * (b - a);  // a long sliver
        uint32_t base = static_cast<uint32_t>(mesh.positions.size());
        mesh.positions.insert(mesh.positions.end(), {a, b, c});
        mesh.triangles.push_back({base, base + 1, base + 2});
        if (t % 25 == 5) mesh.triangles.push_back({base + 1, base + 2, base});  // a repeat
    }
    return mesh;
}

// --- Closest point -------------------------------------------------------------------------

ClosestPointQuery::Hit brute_force_closest(const TriangleMesh& mesh, Vec3 p) {
    ClosestPointQuery::Hit best;
    best.distance_squared = std::numeric_limits<double>::infinity();
    best.triangle = std::numeric_limits<uint32_t>::max();
    for (uint32_t t = 0; t < mesh.triangles.size(); ++t) {
        const Triangle& tri = mesh.triangles[t];
        Vec3 barycentric;
        Vec3 q = closest_point_on_triangle(p, mesh.positions[tri[0]], mesh.positions[tri[1]],
                                           mesh.positions[tri[2]], barycentric);
        double d = dot(p - q, p - q);
        if (d < best.distance_squared) best = {q, t, d, barycentric};
    }
    return best;
}

double segment_distance_squared(Vec3 p, Vec3 a, Vec3 b) {
    Vec3 ab = b - a;
    double len2 = dot(ab, ab);
    double t = len2 > 0 ? std::clamp(dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
    Vec3 q = a + t * ab;
    return dot(p - q, p - q);
}

// An independent formulation: project onto the plane; inside the triangle that is the answer,
// otherwise the nearest of the three edges.
double reference_triangle_distance_squared(Vec3 p, Vec3 a, Vec3 b, Vec3 c) {
    Vec3 n = cross(b - a, c - a);
    double n2 = dot(n, n);
    double best = std::min({segment_distance_squared(p, a, b), segment_distance_squared(p, b, c),
                            segment_distance_squared(p, c, a)});
    if (n2 > 0) {
        Vec3 q = p - (dot(p - a, n) / n2) * n;
        double u = dot(cross(c - b, q - b), n) / n2;
        double v = dot(cross(a - c, q - c), n) / n2;
        double w = dot(cross(b - a, q - a), n) / n2;
        if (u >= 0 && v >= 0 && w >= 0) best = std::min(best, dot(p - q, p - q));
    }
    return best;
}

TEST(ClosestPointOnTriangle, MatchesIndependentFormulation) {
    std::mt19937 rng(1);
    std::uniform_real_distribution<double> coordinate(-1, 1);
    auto random_point = [&] { return Vec3{coordinate(rng), coordinate(rng), coordinate(rng)}; };
    for (int i = 0; i < 20000; ++i) {
        Vec3 a = random_point(), b = random_point(), c = random_point();
        Vec3 p = 2.0 * random_point();
        Vec3 barycentric;
        Vec3 q = closest_point_on_triangle(p, a, b, c, barycentric);
        double expected = reference_triangle_distance_squared(p, a, b, c);
        ASSERT_NEAR(dot(p - q, p - q), expected, 1e-12 * (1 + expected)) << i;
        EXPECT_GE(barycentric.x, 0);
        EXPECT_GE(barycentric.y, 0);
        EXPECT_GE(barycentric.z, 0);
        EXPECT_NEAR(barycentric.x + barycentric.y + barycentric.z, 1, 1e-12);
        Vec3 from_weights = barycentric.x * a + barycentric.y * b + barycentric.z * c;
        EXPECT_NEAR(length(from_weights - q), 0, 1e-12);
    }
}

TEST(ClosestPointOnTriangle, DegenerateTrianglesGiveFiniteExactAnswers) {
    Vec3 a{0, 0, 0}, b{1, 0, 0}, mid{0.25, 0, 0};
    Vec3 barycentric;
    // Collinear: the segment [a, b].
    for (Vec3 p : {Vec3{0.5, 1, 0}, Vec3{-1, 0.5, 0.5}, Vec3{2, 0, 0}, Vec3{0.3, 0, 0}}) {
        Vec3 q = closest_point_on_triangle(p, a, b, mid, barycentric);
        EXPECT_NEAR(dot(p - q, p - q), segment_distance_squared(p, a, b), 1e-15);
        EXPECT_TRUE(std::isfinite(barycentric.x + barycentric.y + barycentric.z));
    }
    // A point.
    Vec3 q = closest_point_on_triangle({1, 2, 3}, a, a, a, barycentric);
    EXPECT_EQ(q, a);
    EXPECT_NEAR(barycentric.x + barycentric.y + barycentric.z, 1, 0);
    // Nearly collinear (rounding noise in the face region).
    Vec3 c{0.5, 1e-300, 0};
    q = closest_point_on_triangle({0.5, 0, 0}, a, b, c, barycentric);
    EXPECT_TRUE(std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z));
    EXPECT_NEAR(q.x, 0.5, 1e-15);
}

void expect_same_as_brute_force(const TriangleMesh& mesh, const std::vector<Vec3>& queries) {
    ClosestPointQuery query(mesh);
    for (std::size_t i = 0; i < queries.size(); ++i) {
        ClosestPointQuery::Hit hit = query.closest(queries[i]);
        ClosestPointQuery::Hit expected = brute_force_closest(mesh, queries[i]);
        ASSERT_EQ(hit.distance_squared, expected.distance_squared) << "query " << i;
        ASSERT_EQ(hit.triangle, expected.triangle) << "query " << i;
        ASSERT_EQ(hit.point, expected.point) << "query " << i;
        ASSERT_EQ(hit.barycentric, expected.barycentric) << "query " << i;
    }
}

TEST(ClosestPointQuery, MatchesBruteForceOnRandomSoups) {
    for (uint32_t seed : {1u, 2u, 3u}) {
        TriangleMesh mesh = random_soup(seed == 1 ? 3 : 1500, seed);
        std::mt19937 rng(seed + 100);
        std::uniform_real_distribution<double> coordinate(-0.5, 1.5);
        std::vector<Vec3> queries;
        for (int i = 0; i < 3000; ++i) queries.push_back({coordinate(rng), coordinate(rng), coordinate(rng)});
        // Far away, and exactly on vertices (shared by the repeated triangles: ties).
        queries.push_back({100, -50, 7});
        for (int i = 0; i < 200; ++i) queries.push_back(mesh.positions[i % mesh.positions.size()]);
        expect_same_as_brute_force(mesh, queries);
    }
}

TEST(ClosestPointQuery, MatchesBruteForceNearASphere) {
    TriangleMesh mesh = icosphere(4, 1.0);  // 5120 triangles
    std::mt19937 rng(7);
    std::normal_distribution<double> gaussian;
    std::uniform_real_distribution<double> radius(0.8, 1.2);
    std::vector<Vec3> queries;
    for (int i = 0; i < 3000; ++i) {
        Vec3 direction = normalized({gaussian(rng), gaussian(rng), gaussian(rng)});
        queries.push_back(radius(rng) * direction);
    }
    queries.push_back({0, 0, 0});  // equidistant from many triangles
    // Midpoints of edges: on two triangles at once.
    for (int t = 0; t < 200; ++t) {
        const Triangle& tri = mesh.triangles[t];
        queries.push_back(0.5 * (mesh.positions[tri[0]] + mesh.positions[tri[1]]));
    }
    expect_same_as_brute_force(mesh, queries);
}

TEST(ClosestPointQuery, MatchesBruteForceBeyondFloatRange) {
    // Node bounds are floats rounded outward; coordinates beyond float range must still work.
    for (double scale : {1e-30, 1e60, 1e100}) {
        TriangleMesh mesh = random_soup(300, 21);
        for (Vec3& p : mesh.positions) p = scale * p + Vec3{scale, -2 * scale, 0};
        std::mt19937 rng(22);
        std::uniform_real_distribution<double> coordinate(-0.5, 1.5);
        std::vector<Vec3> queries;
        for (int i = 0; i < 300; ++i) {
            queries.push_back(scale * Vec3{coordinate(rng), coordinate(rng), coordinate(rng)} +
                              Vec3{scale, -2 * scale, 0});
        }
        expect_same_as_brute_force(mesh, queries);
    }
}

TEST(ClosestPointQuery, PointsOnTheSurfaceMapToThemselves) {
    TriangleMesh mesh = icosphere(4, 3.0);
    ClosestPointQuery query(mesh);
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> weight(0.05, 1.0);
    for (uint32_t t = 0; t < mesh.triangles.size(); t += 3) {
        double u = weight(rng), v = weight(rng), w = weight(rng);
        double sum = u + v + w;
        Vec3 barycentric{u / sum, v / sum, w / sum};
        const Triangle& tri = mesh.triangles[t];
        Vec3 p = barycentric.x * mesh.positions[tri[0]] + barycentric.y * mesh.positions[tri[1]] +
                 barycentric.z * mesh.positions[tri[2]];
        ClosestPointQuery::Hit hit = query.closest(p);
        ASSERT_EQ(hit.triangle, t);
        EXPECT_LE(hit.distance_squared, 1e-28);
        EXPECT_NEAR(length(hit.point - p), 0, 1e-14);
        EXPECT_NEAR(hit.barycentric.x, barycentric.x, 1e-12);
        EXPECT_NEAR(hit.barycentric.y, barycentric.y, 1e-12);
        EXPECT_NEAR(hit.barycentric.z, barycentric.z, 1e-12);
    }
    // Vertices map to themselves exactly.
    for (const Vec3& p : mesh.positions) {
        ClosestPointQuery::Hit hit = query.closest(p);
        EXPECT_EQ(hit.point, p);
        EXPECT_EQ(hit.distance_squared, 0);
    }
}

TEST(ClosestPointQuery, BoundedQueryAgreesWithUnbounded) {
    TriangleMesh mesh = random_soup(800, 11);
    ClosestPointQuery query(mesh);
    std::mt19937 rng(12);
    std::uniform_real_distribution<double> coordinate(-0.5, 1.5);
    std::uniform_real_distribution<double> bound(0, 0.2);
    int found = 0, missed = 0;
    for (int i = 0; i < 3000; ++i) {
        Vec3 p{coordinate(rng), coordinate(rng), coordinate(rng)};
        double max_distance = bound(rng);
        ClosestPointQuery::Hit full = query.closest(p);
        std::optional<ClosestPointQuery::Hit> hit = query.closest(p, max_distance);
        if (full.distance_squared <= max_distance * max_distance) {
            ASSERT_TRUE(hit.has_value()) << i;
            EXPECT_EQ(hit->triangle, full.triangle);
            EXPECT_EQ(hit->distance_squared, full.distance_squared);
            ++found;
        } else {
            EXPECT_FALSE(hit.has_value()) << i;
            ++missed;
        }
    }
    EXPECT_GT(found, 100);
    EXPECT_GT(missed, 100);
    // The bound is inclusive: a vertex at distance 0 is found with bound 0.
    EXPECT_TRUE(query.closest(mesh.positions[0], 0.0).has_value());
    EXPECT_FALSE(query.closest({5, 5, 5}, -1.0).has_value());
}

// A bipyramid of `sides` long triangles around two apexes off its axis (the remesher's case of
// docs/REMESHER.md, "Fans of long triangles"), with repeats of some triangles (ties, the repeat
// turned over for closest_facing) and zero-area triangles at the upper apex: a segment and a
// triangle with the apex twice.
TriangleMesh bipyramid_with_ties(uint32_t sides) {
    TriangleMesh mesh;
    for (uint32_t i = 0; i < sides; ++i) {
        const double angle = 2 * kPi * double(i) / double(sides);
        mesh.positions.push_back({std::cos(angle), std::sin(angle), 0});
    }
    const uint32_t top = sides, bottom = sides + 1;
    mesh.positions.push_back({0.3, 0.1, 1});
    mesh.positions.push_back({-0.2, 0.1, -1});
    for (uint32_t i = 0; i < sides; ++i) {
        mesh.triangles.push_back({i, (i + 1) % sides, top});
        mesh.triangles.push_back({(i + 1) % sides, i, bottom});
        if (i % 7 == 3) mesh.triangles.push_back({top, i, (i + 1) % sides});
        if (i % 11 == 5) mesh.triangles.push_back({i, bottom, (i + 1) % sides});
    }
    mesh.triangles.push_back({top, 5, 5});
    mesh.triangles.push_back({top, top, 9});
    return mesh;
}

// Points near the bipyramid's upper apex (1e-7 to 1 away, in every direction), near its surface
// (a point of a triangle moved off it by 0 to 1e-2), on its vertices, far away.
std::vector<Vec3> queries_near_a_fan(const TriangleMesh& mesh, uint32_t seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> gaussian;
    std::uniform_real_distribution<double> unit(0, 1);
    const Vec3 apex = mesh.positions[mesh.positions.size() - 2];
    std::vector<Vec3> queries{apex, {0, 0, 0}, {100, -50, 7}};
    for (int i = 0; i < 2000; ++i) {
        const Vec3 direction = normalized({gaussian(rng), gaussian(rng), gaussian(rng)});
        queries.push_back(apex + std::pow(10.0, -7 * unit(rng)) * direction);
    }
    for (int i = 0; i < 2000; ++i) {
        const Triangle& t = mesh.triangles[std::uniform_int_distribution<size_t>(0, mesh.triangles.size() - 1)(rng)];
        double u = unit(rng), v = unit(rng);
        if (u + v > 1) u = 1 - u, v = 1 - v;
        const Vec3 a = mesh.positions[t[0]], b = mesh.positions[t[1]], c = mesh.positions[t[2]];
        const Vec3 on = a + u * (b - a) + v * (c - a);
        const double off = i % 4 == 0 ? 0.0 : std::pow(10.0, -2 - 6 * unit(rng));
        queries.push_back(on + off * Vec3{gaussian(rng), gaussian(rng), gaussian(rng)});
    }
    for (const Vec3& p : mesh.positions) queries.push_back(p);
    return queries;
}

TEST(ClosestPointQuery, FanOfHighValenceMatchesBruteForce) {
    const TriangleMesh mesh = bipyramid_with_ties(1024);
    ASSERT_EQ(ClosestPointQuery(mesh).fan_count(), 2u);  // the apexes' fans, out of the box tree
    expect_same_as_brute_force(mesh, queries_near_a_fan(mesh, 5));
    // Far from the origin (the margins scale with the coordinates), and beyond float range.
    for (double scale : {1e-30, 1e3, 1e60}) {
        TriangleMesh scaled = mesh;
        for (Vec3& p : scaled.positions) p = scale * p + Vec3{scale, -2 * scale, 0};
        std::vector<Vec3> queries = queries_near_a_fan(mesh, 6);
        queries.resize(800);
        for (Vec3& p : queries) p = scale * p + Vec3{scale, -2 * scale, 0};
        expect_same_as_brute_force(scaled, queries);
    }
}

// The fans change no answer of the other queries either: each equals the box tree's alone.
TEST(ClosestPointQuery, FanOfHighValenceAnswersAsTheBoxTree) {
    const TriangleMesh mesh = bipyramid_with_ties(1024);
    const ClosestPointQuery fans(mesh), boxes(testing::without_shared_vertices(mesh));
    ASSERT_EQ(fans.fan_count(), 2u);
    ASSERT_EQ(boxes.fan_count(), 0u);
    std::mt19937 rng(8);
    std::normal_distribution<double> gaussian;
    std::uniform_real_distribution<double> unit(0, 1);
    auto same = [](const std::optional<ClosestPointQuery::Hit>& a, const std::optional<ClosestPointQuery::Hit>& b) {
        if (a.has_value() != b.has_value()) return false;
        return !a || (a->triangle == b->triangle && a->point == b->point && a->distance_squared == b->distance_squared &&
                      a->barycentric == b->barycentric);
    };
    int lines_hit = 0, normals_hit = 0;
    for (const Vec3& p : queries_near_a_fan(mesh, 9)) {
        const double reach = std::pow(10.0, -4 * unit(rng));
        ASSERT_TRUE(same(fans.closest(p, reach), boxes.closest(p, reach)));
        const Vec3 direction{gaussian(rng), gaussian(rng), gaussian(rng)};
        ASSERT_TRUE(same(fans.closest_facing(p, direction, 0.3, reach), boxes.closest_facing(p, direction, 0.3, reach)));
        const std::optional<ClosestPointQuery::Hit> line = fans.intersect_line(p, direction, reach);
        ASSERT_TRUE(same(line, boxes.intersect_line(p, direction, reach)));
        lines_hit += line.has_value();
        // Along the normal of the nearest triangle, as the remesher projects, and widened.
        const Triangle& t = mesh.triangles[fans.closest(p).triangle];
        const Vec3 normal = cross(mesh.positions[t[1]] - mesh.positions[t[0]], mesh.positions[t[2]] - mesh.positions[t[0]]);
        const std::optional<ClosestPointQuery::Hit> along = fans.intersect_line(p, normal, reach);
        ASSERT_TRUE(same(along, boxes.intersect_line(p, normal, reach)));
        ASSERT_TRUE(same(fans.intersect_line(p, normal, reach, 1e-9), boxes.intersect_line(p, normal, reach, 1e-9)));
        normals_hit += along.has_value();
    }
    EXPECT_GT(lines_hit, 1000);
    EXPECT_GT(normals_hit, 3000);
}

TEST(ClosestPointQuery, RejectsUnusableMeshesAndPoints) {
    TriangleMesh empty;
    EXPECT_THROW(ClosestPointQuery{empty}, Error);
    TriangleMesh bad;
    bad.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    bad.triangles = {{0, 1, 3}};
    EXPECT_THROW(ClosestPointQuery{bad}, Error);
    bad.triangles = {{0, 1, 2}};
    ClosestPointQuery query(bad);
    double nan = std::numeric_limits<double>::quiet_NaN();
    EXPECT_THROW(query.closest({nan, 0, 0}), Error);
    EXPECT_EQ(query.triangle_count(), 1u);
}

TEST(ClosestPointQuery, SurvivesTheDroppedMesh) {
    std::unique_ptr<ClosestPointQuery> query;
    ClosestPointQuery::Hit expected;
    const Vec3 p{0.3, -1.7, 0.4};
    {
        TriangleMesh mesh = icosphere(2, 1.0);
        query = std::make_unique<ClosestPointQuery>(mesh);
        expected = brute_force_closest(mesh, p);
        mesh.positions.assign(mesh.positions.size(), Vec3{9, 9, 9});
    }
    ClosestPointQuery::Hit hit = query->closest(p);
    EXPECT_EQ(hit.triangle, expected.triangle);
    EXPECT_EQ(hit.point, expected.point);
}

// --- Curvature -----------------------------------------------------------------------------

double sum_of(const std::vector<double>& values) {
    double sum = 0;
    for (double v : values) sum += v;
    return sum;
}

double total_area(const TriangleMesh& mesh) {
    double area = 0;
    for (const Triangle& t : mesh.triangles) {
        area += triangle_area(mesh.positions[t[0]], mesh.positions[t[1]], mesh.positions[t[2]]);
    }
    return area;
}

double integrated_gauss(const TriangleMesh& mesh) {
    std::vector<double> k = gauss_curvature(mesh);
    std::vector<double> area = mixed_areas(mesh);
    double sum = 0;
    for (std::size_t v = 0; v < k.size(); ++v) sum += k[v] * area[v];
    return sum;
}

TEST(Curvature, SphereHasMeanOneOverRAndGaussOneOverRSquared) {
    const double r = 2.5;
    TriangleMesh mesh = icosphere(5, r);  // 10242 vertices
    std::vector<double> h = mean_curvature(mesh);
    std::vector<double> k = gauss_curvature(mesh);
    ASSERT_EQ(h.size(), mesh.positions.size());
    for (std::size_t v = 0; v < h.size(); ++v) {
        ASSERT_NEAR(h[v] * r, 1, 0.02) << v;
        ASSERT_NEAR(k[v] * r * r, 1, 0.05) << v;
    }
    EXPECT_NEAR(sum_of(h) / h.size() * r, 1, 0.005);
}

TEST(Curvature, GaussBonnetHoldsForSphereTorusAndDisk) {
    EXPECT_NEAR(integrated_gauss(icosphere(3, 0.7)), 4 * kPi, 1e-10);  // chi = 2
    EXPECT_NEAR(integrated_gauss(torus(2, 0.5, 48, 24)), 0, 1e-10);    // chi = 0
    EXPECT_NEAR(integrated_gauss(jittered_grid(20, 5)), 2 * kPi, 1e-10);  // chi = 1
    EXPECT_NEAR(integrated_gauss(hemisphere(1.3, 12, 40)), 2 * kPi, 1e-10);
}

TEST(Curvature, MixedAreasPartitionTheSurface) {
    for (const TriangleMesh& mesh :
         {icosphere(3, 1.0), torus(2, 0.5, 30, 12), jittered_grid(15, 2), random_soup(200, 4)}) {
        EXPECT_NEAR(sum_of(mixed_areas(mesh)), total_area(mesh), 1e-12 * (1 + total_area(mesh)));
    }
}

TEST(Curvature, PlaneIsFlat) {
    TriangleMesh mesh = jittered_grid(30, 9);
    std::vector<double> h = mean_curvature(mesh);
    std::vector<double> k = gauss_curvature(mesh);
    const int n = 30;
    for (int j = 0; j <= n; ++j) {
        for (int i = 0; i <= n; ++i) {
            std::size_t v = j * (n + 1) + i;
            EXPECT_NEAR(h[v], 0, 1e-9) << v;  // boundary included: normal component only
            bool corner = (i == 0 || i == n) && (j == 0 || j == n);
            if (!corner) {
                EXPECT_NEAR(k[v], 0, 1e-9) << v;  // straight boundary: angle sum pi
            }
        }
    }
}

TEST(Curvature, TorusMatchesTheSmoothSurface) {
    const double R = 2, r = 0.5;
    const int nu = 160, nv = 60;
    TriangleMesh mesh = torus(R, r, nu, nv);
    std::vector<double> h = mean_curvature(mesh);
    std::vector<double> k = gauss_curvature(mesh);
    for (int j = 0; j < nv; ++j) {
        double c = std::cos(2 * kPi * j / nv);
        double expected_h = std::abs((R + 2 * r * c) / (2 * r * (R + r * c)));
        double expected_k = c / (r * (R + r * c));
        for (int i = 0; i < nu; i += 17) {
            std::size_t v = j * nu + i;
            EXPECT_NEAR(h[v], expected_h, 0.02 * expected_h + 1e-3) << j;
            EXPECT_NEAR(k[v], expected_k, 0.03 * std::abs(expected_k) + 0.02) << j;
        }
    }
}

TEST(Curvature, OpenHemisphereBoundaryIsClose) {
    const double radius = 2;
    const int rings = 30, segments = 120;
    TriangleMesh mesh = hemisphere(radius, rings, segments);
    std::vector<double> h = mean_curvature(mesh);
    std::vector<double> k = gauss_curvature(mesh);
    std::vector<uint8_t> boundary = boundary_vertices(mesh);
    for (int s = 0; s < segments; ++s) {
        std::size_t interior = 1 + (rings - 2) * segments + s;
        std::size_t rim = 1 + (rings - 1) * segments + s;
        EXPECT_EQ(boundary[interior], 0);
        EXPECT_EQ(boundary[rim], 1);
        EXPECT_NEAR(h[interior] * radius, 1, 0.03) << s;
        EXPECT_NEAR(h[rim] * radius, 1, 0.03) << s;  // the interior neighbours' mean
        EXPECT_NEAR(k[interior] * radius * radius, 1, 0.05) << s;
        // The equator is a geodesic: the boundary convention sees only the Gauss curvature.
        EXPECT_NEAR(k[rim] * radius * radius, 1, 0.1) << s;
    }
}

TEST(Curvature, DegenerateTrianglesGiveFiniteValues) {
    TriangleMesh mesh = icosphere(2, 1.0);
    uint32_t n = static_cast<uint32_t>(mesh.positions.size());
    // A collinear triangle, a triangle on one repeated point, a sliver, an isolated vertex.
    mesh.positions.insert(mesh.positions.end(),
                          {{3, 0, 0}, {4, 0, 0}, {3.5, 0, 0}, {5, 5, 5}, {6, 0, 0}, {7, 0, 0},
                           {6.5, 1e-13, 0}, {9, 9, 9}});
    mesh.triangles.push_back({n, n + 1, n + 2});
    mesh.triangles.push_back({n + 3, n + 3, n + 3});
    mesh.triangles.push_back({n + 4, n + 5, n + 6});
    mesh.triangles.push_back({0, 1, 0});  // repeated vertex inside the sphere's data
    for (const std::vector<double>& field :
         {mean_curvature(mesh), gauss_curvature(mesh), mixed_areas(mesh)}) {
        ASSERT_EQ(field.size(), mesh.positions.size());
        for (double value : field) EXPECT_TRUE(std::isfinite(value));
    }
    EXPECT_EQ(mean_curvature(mesh)[n + 7], 0);
    EXPECT_EQ(gauss_curvature(mesh)[n + 7], 0);

    TriangleMesh bad;
    bad.positions = {{0, 0, 0}};
    bad.triangles = {{0, 0, 1}};
    EXPECT_THROW(mean_curvature(bad), Error);
    EXPECT_THROW(gauss_curvature(bad), Error);
}

TEST(Curvature, InterpolateAtReproducesLinearFields) {
    TriangleMesh mesh = torus(2, 0.7, 40, 20);
    std::vector<double> field;
    auto linear = [](Vec3 p) { return 0.5 + p.x - 2 * p.y + 3 * p.z; };
    for (const Vec3& p : mesh.positions) field.push_back(linear(p));
    ClosestPointQuery query(mesh);
    std::mt19937 rng(8);
    std::uniform_real_distribution<double> coordinate(-3, 3);
    for (int i = 0; i < 1000; ++i) {
        ClosestPointQuery::Hit hit = query.closest({coordinate(rng), coordinate(rng), coordinate(rng)});
        EXPECT_NEAR(interpolate_at(mesh, field, hit), linear(hit.point), 1e-12);
    }
    ClosestPointQuery::Hit hit = query.closest({0, 0, 0});
    std::vector<double> short_field(field.begin(), field.end() - 1);
    EXPECT_THROW(interpolate_at(mesh, short_field, hit), Error);
    hit.triangle = static_cast<uint32_t>(mesh.triangles.size());
    EXPECT_THROW(interpolate_at(mesh, field, hit), Error);
}

TEST(Curvature, TriangleArea) {
    EXPECT_DOUBLE_EQ(triangle_area({0, 0, 0}, {2, 0, 0}, {0, 3, 0}), 3);
    EXPECT_EQ(triangle_area({0, 0, 0}, {1, 1, 1}, {2, 2, 2}), 0);
}

}  // namespace
}  // namespace amc
