// Re-expressing a hierarchy over a reordered, rotated base mesh keeps every element and position.
#include "hierarchy_checks.h"

#include "coding/hierarchy/hierarchy_level_coder.h"

#include <algorithm>
#include <array>
#include <numeric>

namespace amc {
namespace {

// The leaf mesh as a sorted list of triangles given by their corner positions, each rotated so
// the smallest position comes first (orientation kept): independent of any numbering.
std::vector<std::array<double, 9>> geometric_triangles(const Hierarchy& h) {
    const LeafMesh leaf = extract_leaf_mesh(h);
    std::vector<std::array<double, 9>> out;
    for (const Triangle& t : leaf.mesh.triangles) {
        std::array<std::array<double, 3>, 3> c;
        for (int i = 0; i < 3; ++i) {
            const Vec3 p = leaf.mesh.positions[t[i]];
            c[i] = {p.x, p.y, p.z};
        }
        const int first = int(std::min_element(c.begin(), c.end()) - c.begin());
        std::array<double, 9> key;
        for (int i = 0; i < 3; ++i) {
            for (int k = 0; k < 3; ++k) key[3 * i + k] = c[(first + i) % 3][k];
        }
        out.push_back(key);
    }
    std::sort(out.begin(), out.end());
    return out;
}

TEST(BaseOrder, ReorderedHierarchyHasTheSameElements) {
    uint64_t state = 5;
    auto next = [&] {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        return uint32_t(state >> 33);
    };
    for (const auto& [name, mesh] : testing::fixture_meshes()) {
        Hierarchy h(mesh);
        refine_randomly(h, 2000, 5, 3);
        for (NodeId n : h.leaves()) {
            if (h.hanging_node_count(n) == 2 && next() % 2) h.set_diagonal_flipped(n, true);
        }
        std::vector<uint32_t> vertex_order(mesh.positions.size()), triangle_order(mesh.triangles.size());
        std::iota(vertex_order.begin(), vertex_order.end(), 0u);
        std::iota(triangle_order.begin(), triangle_order.end(), 0u);
        for (size_t i = vertex_order.size(); i > 1; --i) std::swap(vertex_order[i - 1], vertex_order[next() % i]);
        for (size_t i = triangle_order.size(); i > 1; --i) std::swap(triangle_order[i - 1], triangle_order[next() % i]);
        std::vector<uint8_t> rotation(triangle_order.size());
        for (uint8_t& r : rotation) r = uint8_t(next() % 3);
        const Hierarchy moved = reorder_base(h, vertex_order, triangle_order, rotation);
        EXPECT_TRUE(testing::hierarchy_is_valid(moved)) << name;
        EXPECT_EQ(moved.node_count(), h.node_count()) << name;
        EXPECT_EQ(geometric_triangles(moved), geometric_triangles(h)) << name;
        // The encoder tallies the rotated hierarchy's diagonal exceptions on the input instead.
        std::vector<uint8_t> rotation_of_root(triangle_order.size());
        for (size_t t = 0; t < triangle_order.size(); ++t) rotation_of_root[triangle_order[t]] = rotation[t];
        const DiagonalExceptions direct = diagonal_exceptions(moved), tallied = diagonal_exceptions(h, rotation_of_root);
        EXPECT_GT(direct.leaves, 0u) << name;
        EXPECT_EQ(tallied.leaves, direct.leaves) << name;
        for (int r = 0; r < kDiagonalRuleCount; ++r) EXPECT_EQ(tallied.by_rule[r], direct.by_rule[r]) << name << " rule " << r;
    }
}

TEST(BaseOrder, BadOrdersAreRefused) {
    Hierarchy h(make_icosahedron());
    std::vector<uint32_t> vertices(12, 0), triangles(20);
    std::iota(triangles.begin(), triangles.end(), 0u);
    EXPECT_THROW(reorder_base(h, vertices, triangles, std::vector<uint8_t>(20, 0)), Error);
}

}  // namespace
}  // namespace amc
