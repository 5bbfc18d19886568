// How far a candidate lies off the shortest paths between an edge's ends in the leaf mesh
// (src/import/leaf_detour.h): known answers on a strip of six triangles.
#include "import/leaf_detour.h"

#include <gtest/gtest.h>

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
