// The red split (include/amc/red_split.h): the children a split makes, checked by geometry rather
// than against a second copy of the table, and the SSE2 kernels against their scalar twins.
#include "hierarchy_checks.h"
#include "hierarchy/red_split_kernels.h"

#include <amc/red_split.h>

#include <random>

namespace amc {
namespace {

// One triangle, split once: every child keeps the parent's orientation, its edge e is parallel
// to the parent's edge e and half as long (the center's, turned by half a turn, runs the other
// way), and corner child k holds the parent's corner k.
TEST(RedSplit, ChildrenHaveTheParentsOrientationAndParallelEdges) {
    TriangleMesh mesh;
    mesh.positions = {{0, 0, 0}, {4, 0, 0}, {1, 3, 0}};
    mesh.triangles = {{0, 1, 2}};
    Hierarchy h(mesh);
    h.split(0);
    ASSERT_TRUE(testing::hierarchy_is_valid(h));
    auto edge = [&](NodeId n, int e) { return h.position(h.vertex(n, (e + 1) % 3)) - h.position(h.vertex(n, e)); };
    for (int k = 0; k < 4; ++k) {
        const NodeId c = h.child(0, k);
        const double sign = k == red_split::kCenter ? -2 : 2;
        for (int e = 0; e < 3; ++e) {
            const Vec3 parent = edge(0, e), child = edge(c, e);
            EXPECT_EQ(child.x * sign, parent.x) << "child " << k << " edge " << e;
            EXPECT_EQ(child.y * sign, parent.y) << "child " << k << " edge " << e;
        }
        const Vec3 a = edge(c, 0), b = edge(c, 1);
        EXPECT_GT(a.x * b.y - a.y * b.x, 0) << "child " << k;
    }
    for (int i = 0; i < 3; ++i) {
        const NodeId corner = h.child(0, i);
        bool holds = false;
        for (int j = 0; j < 3; ++j) holds = holds || h.vertex(corner, j) == h.vertex(0, i);
        EXPECT_TRUE(holds) << "corner child " << i;
    }
    for (int e = 0; e < 3; ++e) {
        const Vec3 m = h.position(h.midpoint(0, e));
        const Vec3 expected = 0.5 * (h.position(h.vertex(0, e)) + h.position(h.vertex(0, (e + 1) % 3)));
        EXPECT_EQ(m.x, expected.x);
        EXPECT_EQ(m.y, expected.y);
    }
    static_assert(red_split::well_formed(), "");
}

// Two triangles sharing an edge, both split: the halves of the shared edge meet the right
// children of the other side (Hierarchy::split links them by red_split's half-edge children).
TEST(RedSplit, HalvesOfASharedEdgeMeetAcrossIt) {
    TriangleMesh mesh;
    mesh.positions = {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}, {2, 2, 0}};
    mesh.triangles = {{0, 1, 2}, {3, 2, 1}};
    Hierarchy h(mesh);
    h.split(0);
    h.split(1);
    ASSERT_TRUE(testing::hierarchy_is_valid(h));
    for (NodeId n = 0; n < 2; ++n) {
        for (int k = 0; k < 4; ++k) {
            const NodeId c = h.child(n, k);
            for (int e = 0; e < 3; ++e) {
                const NodeId q = h.neighbor(c, e);
                if (q == kNoNode) continue;
                const int eq = h.neighbor_edge(c, e);
                // The same segment, run the other way.
                EXPECT_EQ(h.vertex(q, eq), h.vertex(c, (e + 1) % 3));
                EXPECT_EQ(h.vertex(q, (eq + 1) % 3), h.vertex(c, e));
            }
        }
    }
}

#if AMC_SSE2
struct FakeNode {
    uint32_t v[3];
    uint32_t fourth;
    uint32_t after[4];
};
struct FakeLinks {
    uint32_t nbr[3];
};

TEST(RedSplit, Sse2ChildVerticesEqualScalar) {
    std::mt19937 rng(25);
    for (int round = 0; round < 1000; ++round) {
        uint32_t corner[3], mid[3];
        for (int i = 0; i < 3; ++i) {
            corner[i] = uint32_t(rng());
            mid[i] = uint32_t(rng());
        }
        FakeNode a[4], b[4];
        for (int k = 0; k < 4; ++k) {
            for (int i = 0; i < 4; ++i) a[k].after[i] = b[k].after[i] = uint32_t(k * 4 + i);
        }
        red_split_scalar::write_child_vertices(a, corner, mid);
        red_split_sse2::write_child_vertices(b, corner, mid);
        for (int k = 0; k < 4; ++k) {
            for (int i = 0; i < 3; ++i) EXPECT_EQ(a[k].v[i], b[k].v[i]) << "child " << k << " vertex " << i;
            EXPECT_EQ(a[k].fourth, 0xffffffffu);
            EXPECT_EQ(b[k].fourth, 0xffffffffu);
            for (int i = 0; i < 4; ++i) EXPECT_EQ(b[k].after[i], uint32_t(k * 4 + i));
        }
    }
}

TEST(RedSplit, Sse2ChildLinksEqualScalar) {
    std::mt19937 rng(25);
    for (unsigned code = 0; code < 64; ++code) {
        for (unsigned present = 0; present < 8; ++present) {
            const uint32_t b = rng() % (1u << 28);
            uint32_t q[3];
            for (int e = 0; e < 3; ++e) q[e] = (present >> e) & 1 ? rng() % (1u << 28) : 0xffffffffu;
            FakeLinks x[4], y[4];
            const unsigned lx = red_split_scalar::write_child_links(x, b, q[0], q[1], q[2], uint8_t(code));
            const unsigned ly = red_split_sse2::write_child_links(y, b, q[0], q[1], q[2], uint8_t(code));
            EXPECT_EQ(lx, ly);
            EXPECT_EQ(lx, present);
            for (int w = 0; w < 12; ++w) EXPECT_EQ(x[w / 3].nbr[w % 3], y[w / 3].nbr[w % 3]) << "code " << code << " word " << w;
        }
    }
}
#else
TEST(RedSplit, Sse2ChildVerticesEqualScalar) { GTEST_SKIP() << "scalar build (AMC_SCALAR or no SSE2): one form only"; }
#endif

}  // namespace
}  // namespace amc
