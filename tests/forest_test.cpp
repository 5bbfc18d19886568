// The red-green forest: known answers for refinement, balance, closure and coarsening.
#include "hierarchy_checks.h"

#include "hierarchy/hierarchy_builder.h"

namespace amc {
namespace {

using testing::fixture_meshes;
using testing::hierarchy_is_valid;

TEST(Forest, RootsMatchTheBaseMesh) {
    for (const auto& [name, mesh] : fixture_meshes()) {
        Hierarchy h(mesh);
        EXPECT_EQ(h.node_count(), mesh.triangles.size()) << name;
        EXPECT_EQ(h.leaf_count(), mesh.triangles.size()) << name;
        EXPECT_EQ(h.vertex_count(), mesh.positions.size()) << name;
        EXPECT_EQ(h.depth(), 0) << name;
        EXPECT_TRUE(hierarchy_is_valid(h)) << name;
    }
}

// Root neighbours by known answers: a strip of two, a boundary elsewhere, and over an edge used
// twice the same way (not a valid base: a Hierarchy still links) the last triangle with (b, a).
TEST(Forest, RootNeighboursAcrossEachEdge) {
    TriangleMesh strip;
    strip.positions.resize(4);
    strip.triangles = {{0, 1, 2}, {2, 1, 3}};
    const Hierarchy h(strip);
    EXPECT_EQ(h.neighbor(0, 1), 1u);
    EXPECT_EQ(h.neighbor_edge(0, 1), 0);
    EXPECT_EQ(h.neighbor(1, 0), 0u);
    EXPECT_EQ(h.neighbor_edge(1, 0), 1);
    for (int e : {0, 2}) {
        EXPECT_TRUE(h.is_boundary_edge(0, e));
        EXPECT_EQ(h.neighbor(0, e), kNoNode);
    }
    EXPECT_FALSE(h.is_boundary_edge(0, 1));
    TriangleMesh twice = strip;  // (2, 1) in triangles 1 and 2
    twice.positions.resize(5);
    twice.triangles.push_back({4, 2, 1});
    const Hierarchy g(twice);
    EXPECT_EQ(g.neighbor(0, 1), 2u);
    EXPECT_EQ(g.neighbor_edge(0, 1), 1);
    EXPECT_EQ(g.neighbor(2, 1), 0u);
    EXPECT_EQ(g.neighbor(1, 0), 0u);
}

TEST(Forest, UniformRefinementGivesFourToTheKTimesFaces) {
    for (const auto& [name, mesh] : fixture_meshes()) {
        for (int k = 0; k <= 4; ++k) {
            Hierarchy h(mesh);
            refine_uniformly(h, k);
            const LeafMesh leaf = extract_leaf_mesh(h);
            uint64_t expected = mesh.triangles.size();
            for (int i = 0; i < k; ++i) expected *= 4;
            EXPECT_EQ(leaf.mesh.triangles.size(), expected) << name << " k=" << k;
            EXPECT_EQ(compute_stats(h).green_faces, 0u) << name;
            EXPECT_EQ(h.depth(), k) << name;
            EXPECT_TRUE(hierarchy_is_valid(h)) << name;
        }
    }
}

// One refined triangle of a closed mesh: its 4 children, each of the 3 neighbours bisected into
// 2 green triangles, every other triangle unchanged: f0 - 4 + 4 + 3 * 2 = f0 + 6 faces and
// 3 new vertices (one per split edge).
TEST(Forest, OneRefinedTriangleInAClosedMesh) {
    Hierarchy h(make_icosahedron());
    EXPECT_EQ(h.refine(7), 1u);
    const LeafMesh leaf = extract_leaf_mesh(h);
    EXPECT_EQ(leaf.mesh.triangles.size(), 20u + 6u);
    EXPECT_EQ(h.vertex_count(), 12u + 3u);
    const HierarchyStats s = compute_stats(h);
    EXPECT_EQ(s.red_faces, 4u + 16u);
    EXPECT_EQ(s.green_faces, 6u);
    EXPECT_EQ(s.one_hanging, 3u);
    EXPECT_TRUE(hierarchy_is_valid(h));
}

// Two refined triangles sharing an edge: 2 * 4 red children; their four other edge neighbours
// (all distinct on the icosahedron) get one hanging node each and become 2 green triangles:
// 20 - 2 - 4 + 8 + 4 * 2 = 30 faces; 5 split edges, so 12 + 5 vertices.
TEST(Forest, TwoAdjacentRefinedTriangles) {
    Hierarchy h(make_icosahedron());
    const NodeId a = 0;
    const NodeId b = h.neighbor(a, 0);
    h.refine(a);
    h.refine(b);
    EXPECT_EQ(h.vertex_count(), 12u + 5u);
    EXPECT_EQ(extract_leaf_mesh(h).mesh.triangles.size(), 30u);
    EXPECT_TRUE(hierarchy_is_valid(h));
}

TEST(Forest, ThreeRefinedNeighboursForceClosure) {
    Hierarchy h(make_icosahedron());
    const NodeId center = 5;
    for (int e = 0; e < 3; ++e) h.refine(h.neighbor(center, e));
    EXPECT_FALSE(h.is_leaf(center)) << "a leaf with three hanging nodes must be red refined";
    EXPECT_TRUE(hierarchy_is_valid(h));
}

TEST(Forest, RefiningDeepKeepsBalance) {
    for (const auto& [name, mesh] : fixture_meshes()) {
        Hierarchy h(mesh);
        NodeId n = 0;
        for (int level = 0; level < 8; ++level) {
            h.refine(n);
            n = h.child(n, level % 4);
        }
        EXPECT_EQ(h.depth(), 8) << name;
        EXPECT_TRUE(hierarchy_is_valid(h)) << name;
        // Balance: every refined node has a same-level neighbour on every inner edge.
        for (NodeId m : h.breadth_first_order()) {
            if (!h.is_leaf(m)) {
                EXPECT_TRUE(h.has_all_neighbors(m)) << name;
            }
        }
    }
}

TEST(Forest, ChildLayoutFollowsThePaper) {
    TriangleMesh mesh;
    mesh.positions = {{0, 0, 0}, {4, 0, 0}, {0, 4, 0}};
    mesh.triangles = {{0, 1, 2}};
    Hierarchy h(mesh);
    h.refine(0);
    auto at = [&](NodeId n, int i) { return h.position(h.vertex(n, i)); };
    // Corner children at the parent's vertices 0, 1, 2 (keeping that vertex's local index), then
    // the center child whose vertex i is the midpoint opposite parent vertex i.
    EXPECT_EQ(at(h.child(0, 0), 0), (Vec3{0, 0, 0}));
    EXPECT_EQ(at(h.child(0, 1), 1), (Vec3{4, 0, 0}));
    EXPECT_EQ(at(h.child(0, 2), 2), (Vec3{0, 4, 0}));
    EXPECT_EQ(at(h.child(0, 3), 0), (Vec3{2, 2, 0}));
    EXPECT_EQ(at(h.child(0, 3), 1), (Vec3{0, 2, 0}));
    EXPECT_EQ(at(h.child(0, 3), 2), (Vec3{2, 0, 0}));
    for (int k = 0; k < 4; ++k) EXPECT_EQ(h.child_index(h.child(0, k)), k);
    EXPECT_TRUE(hierarchy_is_valid(h));
}

TEST(Forest, CoarsenUndoesRefine) {
    for (const auto& [name, mesh] : fixture_meshes()) {
        Hierarchy h(mesh);
        const Hierarchy original = h;
        h.refine(0);
        EXPECT_TRUE(h.coarsen(0)) << name;
        EXPECT_TRUE(identical(h, original)) << name;
        EXPECT_TRUE(hierarchy_is_valid(h)) << name;
    }
}

// A reset hierarchy is the fresh one over the new base, and refines as it does: no node, vertex,
// free id or vertex placer of its past shows.
TEST(Forest, ResetGivesTheFreshHierarchy) {
    const auto meshes = fixture_meshes();
    Hierarchy h(meshes[0].mesh);
    for (const auto& [name, mesh] : meshes) {
        refine_randomly(h, h.root_count() + 200, 4, 3);
        h.coarsen(h.parent(h.leaves().back()));  // leaves free ids behind
        h.set_vertex_placer([](void*, Vec3 a, Vec3) { return a; }, nullptr);
        h.reset(mesh);
        Hierarchy fresh(mesh);
        EXPECT_TRUE(identical(h, fresh)) << name;
        EXPECT_EQ(h.node_capacity(), fresh.node_capacity()) << name;
        refine_randomly(h, h.root_count() + 100, 3, 9);
        refine_randomly(fresh, fresh.root_count() + 100, 3, 9);
        EXPECT_TRUE(identical(h, fresh)) << name;
        EXPECT_TRUE(hierarchy_is_valid(h)) << name;
    }
}

// A base that reset refuses (a triangle past its vertices) leaves the hierarchy as it was: the
// base is checked before anything is cleared.
TEST(Forest, ResetToARefusedBaseKeepsTheHierarchy) {
    const auto meshes = fixture_meshes();
    Hierarchy h(meshes[0].mesh);
    refine_randomly(h, h.root_count() + 200, 4, 3);
    const Hierarchy before = h;
    TriangleMesh bad = meshes[0].mesh;
    bad.triangles[0][1] = uint32_t(bad.positions.size());
    EXPECT_THROW(h.reset(bad), Error);
    EXPECT_TRUE(identical(h, before));
    EXPECT_EQ(h.node_capacity(), before.node_capacity());
    EXPECT_EQ(h.positions().size(), before.positions().size());
}

// The same nodes under the same ids: what the import's trials need of undo_splits, since they go on
// splitting after it as if the undone splits had never been made.
::testing::AssertionResult same_ids(const Hierarchy& a, const Hierarchy& b) {
    if (a.node_capacity() != b.node_capacity() || a.positions().size() != b.positions().size() ||
        a.node_count() != b.node_count() || a.vertex_count() != b.vertex_count())
        return ::testing::AssertionFailure() << "sizes differ";
    for (NodeId n = 0; n < a.node_capacity(); ++n) {
        if (a.is_leaf(n) != b.is_leaf(n) || (!a.is_leaf(n) && a.child(n, 0) != b.child(n, 0)) ||
            a.diagonal_flipped(n) != b.diagonal_flipped(n))
            return ::testing::AssertionFailure() << "node " << n << " differs";
        for (int e = 0; e < 3; ++e) {
            if (a.vertex(n, e) != b.vertex(n, e) || a.neighbor(n, e) != b.neighbor(n, e) ||
                (a.neighbor(n, e) != kNoNode && a.neighbor_edge(n, e) != b.neighbor_edge(n, e)))
                return ::testing::AssertionFailure() << "node " << n << " edge " << e << " differs";
        }
    }
    return ::testing::AssertionSuccess();
}

TEST(Forest, UndoSplitsRestoresTheIdsBeforeThem) {
    for (const auto& [name, mesh] : fixture_meshes()) {
        Hierarchy h(mesh);
        refine_randomly(h, h.root_count() + 120, 4, 5);
        const Hierarchy before = h;
        std::vector<NodeId> splits;
        for (NodeId n : before.leaves()) {
            if (splits.size() >= 40) break;
            if (h.is_leaf(n)) h.refine(n, &splits);
        }
        ASSERT_GT(splits.size(), 0u) << name;
        ASSERT_FALSE(same_ids(h, before)) << name;
        HierarchyBuilder::undo_splits(h, splits, 0);
        EXPECT_TRUE(same_ids(h, before)) << name;
        EXPECT_TRUE(hierarchy_is_valid(h)) << name;
        // Refined again the same way, both give the same ids.
        Hierarchy again = before;
        refine_randomly(h, h.root_count() + 300, 5, 8);
        refine_randomly(again, again.root_count() + 300, 5, 8);
        EXPECT_TRUE(same_ids(h, again)) << name;
    }
}

TEST(Forest, UndoSplitsRefusesIdsFreeForReuse) {
    Hierarchy h(make_icosahedron());
    std::vector<NodeId> splits;
    h.refine(0, &splits);
    h.refine(h.child(0, 0), &splits);
    ASSERT_TRUE(h.coarsen(h.child(0, 0)));
    splits.pop_back();
    EXPECT_THROW(HierarchyBuilder::undo_splits(h, splits, 0), Error);
}

TEST(Forest, CoarsenRefusesWhatBalanceForbids) {
    Hierarchy h(make_icosahedron());
    h.refine(0);
    h.refine(h.child(0, 0));  // balance refines 0's neighbours across edges 0 and 2
    const NodeId neighbour = h.neighbor(0, 0);
    ASSERT_FALSE(h.is_leaf(neighbour));
    // Coarsening the neighbour would put level-2 leaves next to a level-0 leaf.
    const Hierarchy before = h;
    EXPECT_FALSE(h.can_coarsen(neighbour));
    EXPECT_FALSE(h.coarsen(neighbour));
    EXPECT_TRUE(identical(h, before));
    EXPECT_FALSE(h.coarsen(0)) << "node 0 has a refined child";
    EXPECT_TRUE(h.coarsen(h.child(0, 0)));
    EXPECT_TRUE(h.coarsen(neighbour));
    EXPECT_TRUE(hierarchy_is_valid(h));
}

TEST(Forest, CoarsenRefusesWhenClosureWouldRefineAgain) {
    Hierarchy h(make_icosahedron());
    const NodeId center = 5;
    for (int e = 0; e < 3; ++e) h.refine(h.neighbor(center, e));
    ASSERT_FALSE(h.is_leaf(center));
    EXPECT_FALSE(h.can_coarsen(center));
    EXPECT_FALSE(h.coarsen(center));
    EXPECT_TRUE(hierarchy_is_valid(h));
}

TEST(Forest, SingleSplitRequiresNeighbours) {
    Hierarchy h(make_icosahedron());
    h.split(0);
    const NodeId c = h.child(0, 0);
    EXPECT_FALSE(h.can_split(c)) << "its outer neighbours are coarser";
    EXPECT_TRUE(h.can_split(h.child(0, 3))) << "the center's neighbours are its siblings";
}

// Guards the GCC 12 miscompile noted in CMakeLists.txt: rounding all three coordinates to float.
bool is_float(double x) {
    volatile float f = static_cast<float>(x);
    return static_cast<double>(f) == x;
}

TEST(Forest, SinglePrecisionBaseKeepsFloatVertices) {
    const TriangleMesh mesh = make_bumpy_sphere(1);
    for (const Vec3& p : mesh.positions) {
        EXPECT_TRUE(is_float(p.x) && is_float(p.y) && is_float(p.z));
    }
    Hierarchy h(mesh);
    refine_uniformly(h, 2);
    for (uint32_t v = 0; v < h.positions().size(); ++v) {
        const Vec3 p = h.position(v);
        EXPECT_TRUE(is_float(p.x) && is_float(p.y) && is_float(p.z)) << v;
    }
}

}  // namespace
}  // namespace amc
