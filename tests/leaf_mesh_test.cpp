// Green closure and leaf-mesh extraction: conforming output, diagonal rule and override, levels.
#include "hierarchy_checks.h"

namespace amc {
namespace {

using testing::hierarchy_is_valid;

// A leaf with two hanging nodes: refine two neighbours of one icosahedron triangle.
struct TwoHanging {
    Hierarchy h{make_icosahedron()};
    NodeId leaf = 5;
    TwoHanging() {
        h.refine(h.neighbor(leaf, 0));
        h.refine(h.neighbor(leaf, 1));
    }
};

std::vector<Triangle> triangles_of(const LeafMesh& leaf, NodeId n) {
    std::vector<Triangle> out;
    for (size_t i = 0; i < leaf.source.size(); ++i) {
        if (leaf.source[i] == n) out.push_back(leaf.mesh.triangles[i]);
    }
    return out;
}

TEST(LeafMesh, TwoHangingNodesGiveThreeGreenTriangles) {
    TwoHanging t;
    ASSERT_TRUE(t.h.is_leaf(t.leaf));
    ASSERT_EQ(t.h.hanging_node_count(t.leaf), 2);
    const LeafMesh leaf = extract_leaf_mesh(t.h);
    const auto tris = triangles_of(leaf, t.leaf);
    ASSERT_EQ(tris.size(), 3u);
    for (size_t i = 0; i < leaf.source.size(); ++i) {
        if (leaf.source[i] == t.leaf) {
            EXPECT_EQ(leaf.cells.is_green[i], 1);
        }
    }
    EXPECT_TRUE(hierarchy_is_valid(t.h));
}

// Default rule: unrefined edge u = 2 here; the diagonal joins m_{(u+1)%3} = m_0 and v_u = v_2.
TEST(LeafMesh, DefaultDiagonalRuleAndOverride) {
    TwoHanging t;
    const LeafMesh leaf = extract_leaf_mesh(t.h);
    const std::vector<uint32_t> canonical = canonical_vertex_order(t.h);
    const uint32_t v2 = canonical[t.h.vertex(t.leaf, 2)];
    const uint32_t v0 = canonical[t.h.vertex(t.leaf, 0)];
    const uint32_t m0 = canonical[t.h.midpoint(t.h.neighbor(t.leaf, 0), t.h.neighbor_edge(t.leaf, 0))];
    const uint32_t m1 = canonical[t.h.midpoint(t.h.neighbor(t.leaf, 1), t.h.neighbor_edge(t.leaf, 1))];
    auto has_edge = [](const std::vector<Triangle>& tris, uint32_t a, uint32_t b) {
        for (const Triangle& tri : tris) {
            for (int e = 0; e < 3; ++e) {
                if ((tri[e] == a && tri[(e + 1) % 3] == b) || (tri[e] == b && tri[(e + 1) % 3] == a)) return true;
            }
        }
        return false;
    };
    const auto tris = triangles_of(leaf, t.leaf);
    EXPECT_TRUE(has_edge(tris, m0, v2));
    EXPECT_FALSE(has_edge(tris, m1, v0));

    t.h.set_diagonal_flipped(t.leaf, true);
    const auto flipped = triangles_of(extract_leaf_mesh(t.h), t.leaf);
    EXPECT_FALSE(has_edge(flipped, m0, v2));
    EXPECT_TRUE(has_edge(flipped, m1, v0)) << "the other diagonal: m_{(u+2)%3} -- v_{(u+1)%3}";
    EXPECT_TRUE(hierarchy_is_valid(t.h));
}

TEST(LeafMesh, OneHangingNodeBisects) {
    Hierarchy h(make_icosahedron());
    h.refine(0);
    const LeafMesh leaf = extract_leaf_mesh(h);
    for (int e = 0; e < 3; ++e) {
        const NodeId n = h.neighbor(0, e);
        EXPECT_EQ(triangles_of(leaf, n).size(), 2u);
    }
}

TEST(LeafMesh, LevelMeshesAreConformingAndNested) {
    Hierarchy h(make_torus(6, 5, 2.0, 0.7));
    refine_randomly(h, 3000, 6, 11);
    const int depth = h.depth();
    size_t previous_vertices = 0;
    for (int level = 0; level <= depth; ++level) {
        const LeafMesh cut = extract_leaf_mesh(h, level);
        EXPECT_NO_THROW(validate_triangle_mesh(cut.mesh, "level mesh")) << level;
        EXPECT_EQ(testing::euler_characteristic(cut.mesh), 0) << level;
        EXPECT_GE(cut.mesh.positions.size(), previous_vertices);
        previous_vertices = cut.mesh.positions.size();
        for (uint8_t l : cut.cells.level) EXPECT_LE(int(l), level);
    }
    EXPECT_EQ(extract_leaf_mesh(h, 0).mesh.triangles.size(), h.root_count());
    const LeafMesh finest = extract_leaf_mesh(h, depth);
    EXPECT_EQ(finest.mesh.triangles, extract_leaf_mesh(h).mesh.triangles);
}

TEST(LeafMesh, GreenTrianglesCoverTheirParentArea) {
    Hierarchy h(make_square(2));
    refine_randomly(h, 400, 5, 3);
    const LeafMesh leaf = extract_leaf_mesh(h);
    double area = 0;
    for (const Triangle& t : leaf.mesh.triangles) {
        const Vec3 a = leaf.mesh.positions[t[0]], b = leaf.mesh.positions[t[1]], c = leaf.mesh.positions[t[2]];
        const double z = cross(b - a, c - a).z;
        EXPECT_GT(z, 0) << "every leaf triangle keeps the base orientation";
        area += 0.5 * z;
    }
    EXPECT_NEAR(area, 1.0, 1e-12);
}

}  // namespace
}  // namespace amc
