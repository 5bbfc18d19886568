// How far a candidate lies off the shortest paths between an edge's ends in the leaf mesh
// (src/import/leaf_detour.h): known answers on a strip of six triangles; and the neighbour lists
// of the directed-edge index (src/import/leaf_halfedges.h) both search it with.
#include "import/leaf_detour.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

namespace {

//  0 - 1 - 2 - 6
//  | / | / | /
//  3 - 4 - 5
amc::TriangleMesh strip() {
    amc::TriangleMesh m;
    for (int i = 0; i < 7; ++i) m.positions.push_back({double(i), 0, 0});
    m.triangles = {{0, 3, 1}, {1, 3, 4}, {1, 4, 2}, {2, 4, 5}, {2, 5, 6}};
    return m;
}

TEST(LeafDetour, CountsTheHopsOffTheShortestPaths) {
    const amc::TriangleMesh mesh = strip();
    const amc::LeafHalfedges halfedges(mesh);
    amc::LeafDetour detour(halfedges);
    ASSERT_TRUE(detour.measure(0, 2, 4));
    EXPECT_EQ(detour.detour(1), 0);  // on the path 0-1-2
    EXPECT_EQ(detour.detour(3), 1);  // 0-3, 3-1-2
    EXPECT_EQ(detour.detour(4), 1);  // 0-1-4, 4-2
    EXPECT_EQ(detour.detour(5), 2);  // 0-1-4-5 or 0-1-2-5, 5-2
    EXPECT_EQ(detour.detour(6), 2);  // 0-1-2-6, 6-2
    // A second measure forgets the first.
    ASSERT_TRUE(detour.measure(3, 5, 4));
    EXPECT_EQ(detour.detour(4), 0);
    EXPECT_EQ(detour.detour(1), 1);  // 3-1, 1-2-5 or 1-4-5
}

TEST(LeafDetour, TargetsAloneGetTheFullSearchesDetours) {
    const amc::TriangleMesh mesh = strip();
    const amc::LeafHalfedges halfedges(mesh);
    amc::LeafDetour full(halfedges), targeted(halfedges);
    for (uint32_t a = 0; a < 7; ++a) {
        for (uint32_t b = 0; b < 7; ++b) {
            for (uint32_t c = 0; c < 7; ++c) {
                const uint32_t targets[2] = {c, (c + 3) % 7};
                for (int hops = 1; hops <= 4; ++hops) {
                    const bool measured = full.measure(a, b, hops);
                    ASSERT_EQ(targeted.measure(a, b, hops, targets, 2), measured) << a << " " << b << " " << hops;
                    if (!measured) continue;
                    EXPECT_EQ(targeted.detour(targets[0]), full.detour(targets[0])) << a << " " << b << " " << c;
                    EXPECT_EQ(targeted.detour(targets[1]), full.detour(targets[1])) << a << " " << b << " " << c;
                }
            }
        }
    }
    // Stopped early: 6 is three hops from 0 and not asked for, so not reached.
    const uint32_t near[1] = {3};
    ASSERT_TRUE(targeted.measure(0, 1, 4, near, 1));
    EXPECT_EQ(targeted.detour(3), 1);  // 0-3-1 against 0-1
    EXPECT_EQ(targeted.detour(6), amc::LeafDetour::kFar);
}

// A hexagon of six triangles around 0 (ring 1-2-3-4-5-6): 0's fan is closed, the ring's open.
amc::TriangleMesh hexagon() {
    amc::TriangleMesh m;
    for (int i = 0; i < 7; ++i) m.positions.push_back({double(i), 0, 0});
    for (uint32_t i = 1; i <= 6; ++i) m.triangles.push_back({0, i, i % 6 + 1});
    return m;
}

TEST(LeafDetour, AClosedFansCenterReachesEveryNeighbour) {
    const amc::TriangleMesh mesh = hexagon();
    const amc::LeafHalfedges halfedges(mesh);
    amc::LeafDetour detour(halfedges);
    for (uint32_t a = 1; a <= 6; ++a) {
        const uint32_t b = (a + 2) % 6 + 1;  // across the center
        ASSERT_TRUE(detour.measure(a, b, 2)) << a;
        EXPECT_EQ(detour.detour(0), 0) << a;
        EXPECT_EQ(detour.detour(a % 6 + 1), 1) << a;  // a-x, x-0-b
        ASSERT_TRUE(detour.measure(0, a, 2)) << a;
        EXPECT_EQ(detour.detour(b), 2) << a;  // 0-b, b-0-a
    }
}

TEST(LeafDetour, TargetsAloneGetTheFullSearchesDetoursInAClosedMesh) {
    amc::TriangleMesh mesh;  // an octahedron: every fan closed
    for (int i = 0; i < 6; ++i) mesh.positions.push_back({double(i), 0, 0});
    mesh.triangles = {{0, 1, 2}, {0, 2, 3}, {0, 3, 4}, {0, 4, 1}, {5, 2, 1}, {5, 3, 2}, {5, 4, 3}, {5, 1, 4}};
    const amc::LeafHalfedges halfedges(mesh);
    amc::LeafDetour full(halfedges), targeted(halfedges);
    for (uint32_t a = 0; a < 6; ++a) {
        for (uint32_t b = 0; b < 6; ++b) {
            for (uint32_t c = 0; c < 6; ++c) {
                const uint32_t targets[1] = {c};
                ASSERT_TRUE(full.measure(a, b, 2));
                ASSERT_TRUE(targeted.measure(a, b, 2, targets, 1));
                EXPECT_EQ(targeted.detour(c), full.detour(c)) << a << " " << b << " " << c;
            }
        }
    }
    ASSERT_TRUE(full.measure(0, 5, 2));  // opposite poles: every other vertex is on a shortest path
    for (uint32_t c = 1; c <= 4; ++c) EXPECT_EQ(full.detour(c), 0) << c;
}

// LeafHalfedges::for_each_neighbor_once, which the reconstruction's order-free tests use: every
// neighbour once, in closed fans (the ends alone) and open ones (an apex that is no end too).
TEST(LeafHalfedges, ListEachNeighbourOnce) {
    const amc::TriangleMesh meshes[2] = {hexagon(), strip()};
    for (const amc::TriangleMesh& mesh : meshes) {
        const amc::LeafHalfedges halfedges(mesh);
        for (uint32_t u = 0; u < mesh.positions.size(); ++u) {
            std::vector<uint32_t> expected, listed;
            for (const amc::Triangle& t : mesh.triangles) {
                for (int k = 0; k < 3; ++k) {
                    if (t[k] != u) continue;
                    expected.push_back(t[(k + 1) % 3]);
                    expected.push_back(t[(k + 2) % 3]);
                }
            }
            std::sort(expected.begin(), expected.end());
            expected.erase(std::unique(expected.begin(), expected.end()), expected.end());
            halfedges.for_each_neighbor_once(u, [&](uint32_t x) { listed.push_back(x); });
            std::sort(listed.begin(), listed.end());
            EXPECT_EQ(listed, expected) << u;  // sorted with its repeats: each exactly once
            EXPECT_EQ(halfedges.face(u, u), amc::kNoIndex);
        }
        // The flag bit kept out of the faces the index reports.
        for (uint32_t f = 0; f < mesh.triangles.size(); ++f) {
            const amc::Triangle& t = mesh.triangles[f];
            EXPECT_EQ(halfedges.face(t[0], t[1]), f);
            EXPECT_EQ(halfedges.edge(t[1], t[2]).face, f);
            EXPECT_EQ(halfedges.edge(t[1], t[2]).apex, t[0]);
        }
    }
}

TEST(LeafDetour, EndsFartherThanTheBoundAreNotMeasured) {
    const amc::TriangleMesh mesh = strip();
    const amc::LeafHalfedges halfedges(mesh);
    amc::LeafDetour detour(halfedges);
    EXPECT_FALSE(detour.measure(0, 6, 2));  // three hops apart
    ASSERT_TRUE(detour.measure(0, 6, 3));
    EXPECT_EQ(detour.detour(2), 0);
    EXPECT_EQ(detour.detour(3), 1);  // 0-3, 3-1-2-6
    ASSERT_TRUE(detour.measure(0, 2, 2));
    EXPECT_EQ(detour.detour(1), 0);
    EXPECT_EQ(detour.detour(6), amc::LeafDetour::kFar);  // three hops from 0, beyond the bound
}

}  // namespace
