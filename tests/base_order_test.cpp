// Re-expressing a hierarchy over a reordered, rotated base mesh keeps every element and position.
#include "hierarchy_checks.h"

#include "coding/hierarchy/hierarchy_level_coder.h"
#include "common/huge_pages.h"
#include "hierarchy/hierarchy_builder.h"

#include <cstring>

#include <algorithm>
#include <array>
#include <numeric>

#if defined(__linux__)
#include <sys/mman.h>
#include <unistd.h>
#endif

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
    testing::Random random{5};
    for (const auto& [name, mesh] : testing::fixture_meshes()) {
        Hierarchy h(mesh);
        refine_randomly(h, 2000, 5, 3);
        for (NodeId n : h.leaves()) {
            if (h.hanging_node_count(n) == 2 && random.next() % 2) h.set_diagonal_flipped(n, true);
        }
        std::vector<uint32_t> vertex_order(mesh.positions.size()), triangle_order(mesh.triangles.size());
        std::iota(vertex_order.begin(), vertex_order.end(), 0u);
        std::iota(triangle_order.begin(), triangle_order.end(), 0u);
        for (size_t i = vertex_order.size(); i > 1; --i) std::swap(vertex_order[i - 1], vertex_order[random.next() % i]);
        for (size_t i = triangle_order.size(); i > 1; --i) std::swap(triangle_order[i - 1], triangle_order[random.next() % i]);
        std::vector<uint8_t> rotation(triangle_order.size());
        for (uint8_t& r : rotation) r = uint8_t(random.next() % 3);
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

// What reorder_base promises, done the plain way: the forest replayed breadth-first with split(),
// each node's children in the rotated order, positions copied.
Hierarchy replayed(const Hierarchy& h, const std::vector<uint32_t>& vertex_order, const std::vector<uint32_t>& triangle_order,
                   const std::vector<uint8_t>& rotation, std::vector<VertexId>& vertex_map) {
    std::vector<uint32_t> new_id(vertex_order.size());
    for (uint32_t i = 0; i < vertex_order.size(); ++i) new_id[vertex_order[i]] = i;
    TriangleMesh base;
    base.single_precision = h.base().single_precision;
    for (uint32_t v : vertex_order) base.positions.push_back(h.base().positions[v]);
    for (uint32_t t = 0; t < triangle_order.size(); ++t) {
        Triangle tri;
        for (int i = 0; i < 3; ++i) tri[i] = new_id[h.base().triangles[triangle_order[t]][(i + rotation[t]) % 3]];
        base.triangles.push_back(tri);
    }
    Hierarchy out(base);
    vertex_map.assign(h.positions().size(), kNoVertex);
    out.set_vertex_placer([](void*, Vec3 a, Vec3) { return a; }, nullptr);
    std::vector<std::pair<NodeId, NodeId>> queue;
    std::vector<uint8_t> turn;
    for (uint32_t t = 0; t < triangle_order.size(); ++t) {
        queue.push_back({triangle_order[t], t});
        turn.push_back(rotation[t]);
    }
    for (size_t i = 0; i < queue.size(); ++i) {
        const NodeId old_node = queue[i].first, new_node = queue[i].second;
        const int r = turn[i];
        out.set_diagonal_flipped(new_node, h.diagonal_flipped(old_node));
        for (int k = 0; k < 3; ++k) vertex_map[h.vertex(old_node, (k + r) % 3)] = out.vertex(new_node, k);
        if (h.is_leaf(old_node)) continue;
        out.split(new_node);
        for (int e = 0; e < 3; ++e) out.set_position(out.midpoint(new_node, e), h.position(h.midpoint(old_node, (e + r) % 3)));
        for (int k = 0; k < 4; ++k) {
            queue.push_back({h.child(old_node, red_split::kRotatedChild[r][k]), out.child(new_node, k)});
            turn.push_back(uint8_t(r));
        }
    }
    out.set_vertex_placer(nullptr, nullptr);
    return out;
}

// Node for node and vertex for vertex the same hierarchy: ids, links, flags, positions' bits.
bool same_ids(const Hierarchy& a, const Hierarchy& b) {
    if (a.node_capacity() != b.node_capacity() || a.node_count() != b.node_count() || a.positions().size() != b.positions().size())
        return false;
    for (NodeId n = 0; n < a.node_capacity(); ++n) {
        if (a.is_alive(n) != b.is_alive(n)) return false;
        if (!a.is_alive(n)) continue;
        if (a.level(n) != b.level(n) || a.is_leaf(n) != b.is_leaf(n) || a.parent(n) != b.parent(n) ||
            a.diagonal_flipped(n) != b.diagonal_flipped(n) || (!a.is_leaf(n) && a.child(n, 0) != b.child(n, 0)))
            return false;
        for (int e = 0; e < 3; ++e)
            if (a.vertex(n, e) != b.vertex(n, e) || a.neighbor(n, e) != b.neighbor(n, e) ||
                a.is_boundary_edge(n, e) != b.is_boundary_edge(n, e) ||
                (a.neighbor(n, e) != kNoNode && a.neighbor_edge(n, e) != b.neighbor_edge(n, e)))
                return false;
    }
    return std::memcmp(a.positions().data(), b.positions().data(), a.positions().size() * sizeof(Vec3)) == 0;
}

TEST(BaseOrder, ReorderingGivesTheIdsOfAReplayOnAnyThreads) {
    testing::Random random{11};
    for (const auto& [name, mesh] : testing::fixture_meshes()) {
        Hierarchy h(mesh);
        refine_randomly(h, 3000, 6, 7);
        for (NodeId n : h.leaves()) {  // some nodes removed again: dead ids and vertices in the input
            const NodeId p = h.parent(n);
            if (p != kNoNode && h.is_alive(n) && !h.is_leaf(p) && random.next() % 7 == 0) h.coarsen(p);
        }
        for (NodeId n : h.leaves())
            if (h.hanging_node_count(n) == 2 && random.next() % 2) h.set_diagonal_flipped(n, true);
        for (VertexId v = 0; v < h.positions().size(); ++v)  // positions off the midpoints
            h.set_position(v, Vec3{h.position(v).x + 1e-3 * (random.next() % 100), h.position(v).y, h.position(v).z});
        std::vector<uint32_t> vertex_order(mesh.positions.size()), triangle_order(mesh.triangles.size());
        std::iota(vertex_order.begin(), vertex_order.end(), 0u);
        std::iota(triangle_order.begin(), triangle_order.end(), 0u);
        for (size_t i = vertex_order.size(); i > 1; --i) std::swap(vertex_order[i - 1], vertex_order[random.next() % i]);
        for (size_t i = triangle_order.size(); i > 1; --i) std::swap(triangle_order[i - 1], triangle_order[random.next() % i]);
        std::vector<uint8_t> rotation(triangle_order.size());
        for (uint8_t& r : rotation) r = uint8_t(random.next() % 3);
        std::vector<VertexId> expected_map;
        const Hierarchy expected = replayed(h, vertex_order, triangle_order, rotation, expected_map);
        for (unsigned threads : {1u, 3u}) {
            std::vector<VertexId> map;
            const Hierarchy moved = HierarchyBuilder::reorder_base(h, vertex_order, triangle_order, rotation, &map, threads);
            EXPECT_TRUE(same_ids(moved, expected)) << name << ", " << threads << " threads";
            EXPECT_EQ(map, expected_map) << name << ", " << threads << " threads";
            EXPECT_EQ(check_invariants(moved), "") << name;
        }
    }
}

// Levels of more than one task's nodes (2^16): the reorder and the diagonal tally split them into
// ranges, which several threads take in any order.
TEST(BaseOrder, LevelsOfSeveralRangesGiveTheSameResultOnAnyThreads) {
    testing::Random random{5};
    Hierarchy h(make_torus(6, 5, 2.0, 0.7));
    refine_randomly(h, 250000, 9, 3);
    for (NodeId n : h.leaves())
        if (h.hanging_node_count(n) == 2 && random.next() % 2) h.set_diagonal_flipped(n, true);
    std::vector<size_t> level_size(size_t(h.depth()) + 1, 0);
    for (NodeId n : h.breadth_first_order()) ++level_size[size_t(h.level(n))];
    ASSERT_GT(*std::max_element(level_size.begin(), level_size.end()), size_t(1) << 16);
    std::vector<uint32_t> vertex_order(h.base().positions.size()), triangle_order(h.root_count());
    std::iota(vertex_order.begin(), vertex_order.end(), 0u);
    std::iota(triangle_order.begin(), triangle_order.end(), 0u);
    for (size_t i = triangle_order.size(); i > 1; --i) std::swap(triangle_order[i - 1], triangle_order[random.next() % i]);
    std::vector<uint8_t> rotation(triangle_order.size()), rotation_of_root(triangle_order.size());
    for (uint8_t& r : rotation) r = uint8_t(random.next() % 3);
    for (size_t t = 0; t < triangle_order.size(); ++t) rotation_of_root[triangle_order[t]] = rotation[t];
    std::vector<VertexId> expected_map;
    const Hierarchy expected = replayed(h, vertex_order, triangle_order, rotation, expected_map);
    const DiagonalExceptions expected_tally = diagonal_exceptions(expected);
    EXPECT_GT(expected_tally.leaves, 0u);
    for (unsigned threads : {1u, 2u, 3u}) {
        std::vector<VertexId> map;
        const Hierarchy moved = HierarchyBuilder::reorder_base(h, vertex_order, triangle_order, rotation, &map, threads);
        EXPECT_TRUE(same_ids(moved, expected)) << threads << " threads";
        EXPECT_EQ(map, expected_map) << threads << " threads";
        for (const DiagonalExceptions& tally : {diagonal_exceptions(h, rotation_of_root, threads), diagonal_exceptions(moved, threads)}) {
            EXPECT_EQ(tally.leaves, expected_tally.leaves) << threads << " threads";
            for (int r = 0; r < kDiagonalRuleCount; ++r) EXPECT_EQ(tally.by_rule[r], expected_tally.by_rule[r]) << threads << " threads, rule " << r;
        }
    }
}

// The reordered copy's and the chunks' arrays ask malloc for whole huge pages less its header
// (huge_pages.h), from one huge page on; below that, for what they hold. Contents are kept.
TEST(BaseOrder, ArraysWrittenWholeAskForWholeHugePages) {
    EXPECT_EQ(written_whole_bytes(0), 0u);
    EXPECT_EQ(written_whole_bytes(kHugePage - 1), kHugePage - 1);
    EXPECT_EQ(written_whole_bytes(kHugePage), 2 * kHugePage - 2 * kMallocHeader);
    EXPECT_EQ(written_whole_bytes(2 * kHugePage - 2 * kMallocHeader), 2 * kHugePage - 2 * kMallocHeader);
    EXPECT_EQ(written_whole_bytes(2 * kHugePage - 2 * kMallocHeader + 1), 3 * kHugePage - 2 * kMallocHeader);
    EXPECT_EQ(written_whole_bytes(37594000), 18 * kHugePage - 2 * kMallocHeader);  // feline_1m's reordered nodes
    std::vector<uint32_t> ids = {7, 8, 9};
    reserve_huge(ids, 1000000, HugePages::written_whole);
    EXPECT_EQ(ids, (std::vector<uint32_t>{7, 8, 9}));
    EXPECT_EQ(ids.capacity(), (2 * kHugePage - 2 * kMallocHeader) / sizeof(uint32_t));
    std::vector<Vec3> small = {{1, 2, 3}};
    reserve_huge(small, 1000, HugePages::written_whole);
    EXPECT_EQ(small.capacity(), 1000u);
    EXPECT_EQ(small[0].y, 2);
}

#if defined(__linux__) && defined(MADV_POPULATE_WRITE)
// populate_pages goes one huge page a call: every whole page of its range is still made resident,
// from and to addresses that are not page-aligned, and none outside it.
TEST(BaseOrder, PopulatedPagesAreTheWholePagesOfTheRange) {
    const size_t page = size_t(sysconf(_SC_PAGESIZE));
    const size_t pages = 3 * kHugePage / page + 5, bytes = pages * page;
    void* map = mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    ASSERT_NE(map, MAP_FAILED);
    madvise(map, bytes, MADV_NOHUGEPAGE);  // a fault makes one page resident, whatever the system's default
    if (madvise(map, page, MADV_POPULATE_WRITE) != 0) {
        munmap(map, bytes);
        GTEST_SKIP() << "no MADV_POPULATE_WRITE (Linux before 5.14)";
    }
    char* const first = static_cast<char*>(map);
    populate_pages(first + 3 * page + 100, bytes - 3 * page - 100 - 200);  // whole pages 4 .. pages - 2
    std::vector<unsigned char> resident(pages);
    ASSERT_EQ(mincore(map, bytes, resident.data()), 0);
    for (size_t p = 1; p < pages; ++p) EXPECT_EQ(resident[p] & 1, p >= 4 && p + 1 < pages ? 1 : 0) << "page " << p;
    munmap(map, bytes);
}
#endif

TEST(BaseOrder, BadOrdersAreRefused) {
    Hierarchy h(make_icosahedron());
    std::vector<uint32_t> vertices(12, 0), triangles(20);
    std::iota(triangles.begin(), triangles.end(), 0u);
    EXPECT_THROW(reorder_base(h, vertices, triangles, std::vector<uint8_t>(20, 0)), Error);
}

}  // namespace
}  // namespace amc
