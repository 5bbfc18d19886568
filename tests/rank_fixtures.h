// Fixtures of the rank-wise writers' tests (tests/rank_encoder_test.cpp, tests/mpi/): adaptive
// hierarchies, cuts of their roots into ranks, and each rank's forest as a simulation holds it.
#pragma once

#include "coding/chunks/chunk_layout.h"
#include "hierarchy_checks.h"

#include <amc/hierarchy.h>

#include <numeric>
#include <vector>

namespace amc::testing {

struct RankForest {
    uint32_t first_root = 0;
    Hierarchy forest;
};

// Rank r's forest as a simulation would hold it: the trees of its roots, over its own triangles
// with its own numbering of their vertices.
inline Hierarchy forest_of(const Hierarchy& whole, RootRange roots, uint64_t seed) {
    const Hierarchy forest = extract_roots(whole, {roots});
    std::vector<uint32_t> order(forest.base().positions.size());
    std::iota(order.begin(), order.end(), 0u);
    Random random{seed};
    for (size_t i = order.size(); i > 1; --i) std::swap(order[i - 1], order[random.next() % i]);
    std::vector<uint32_t> triangles(roots.count);
    std::iota(triangles.begin(), triangles.end(), 0u);
    return reorder_base(forest, order, triangles, std::vector<uint8_t>(roots.count, 0));
}

inline std::vector<RankForest> ranks_of(const Hierarchy& whole, const std::vector<uint32_t>& counts, uint64_t seed) {
    std::vector<RankForest> ranks;
    uint32_t first = 0;
    for (uint32_t count : counts) {
        ranks.push_back({first, forest_of(whole, {first, count}, seed + first)});
        first += count;
    }
    return ranks;
}

inline Hierarchy adaptive_hierarchy(uint64_t seed) {
    Random random{seed};
    const auto meshes = fixture_meshes();
    TriangleMesh base = shuffled(meshes[seed % meshes.size()].mesh, seed);
    const bool single = seed % 3 == 1;
    base.single_precision = single;
    if (single)
        for (Vec3& p : base.positions) p = Vec3{double(float(p.x)), double(float(p.y)), double(float(p.z))};
    Hierarchy h(base);
    refine_randomly(h, h.root_count() + 80 + uint32_t(random.next() % 500), 1 + int(random.next() % 5), seed);
    for (NodeId n : h.leaves())
        if (h.hanging_node_count(n) == 2 && random.next() % 3 == 0) h.set_diagonal_flipped(n, true);
    if (seed % 2 == 0) {  // positions off the midpoints
        for (VertexId v = h.base().positions.size(); v < h.positions().size(); ++v) {
            const Vec3 p = h.position(v);
            const Vec3 q{p.x + 1e-3 * double(random.next() % 100), p.y, p.z - 1e-4 * double(random.next() % 10)};
            h.set_position(v, single ? Vec3{double(float(q.x)), double(float(q.y)), double(float(q.z))} : q);
        }
    }
    return h;
}

// Root counts of `ranks` ranks adding up to `roots`; with `empty`, rank 1 owns none.
inline std::vector<uint32_t> cut(uint32_t roots, uint32_t ranks, uint64_t seed, bool empty) {
    Random random{seed};
    std::vector<uint32_t> counts(ranks, 1);
    if (empty) counts[1] = 0;
    for (uint32_t r = empty ? ranks - 1 : ranks; r < roots; ++r) {
        uint32_t k = uint32_t(random.next() % ranks);
        if (empty && k == 1) k = 0;
        ++counts[k];
    }
    return counts;
}

}  // namespace amc::testing
