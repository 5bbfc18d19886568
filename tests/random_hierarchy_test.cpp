// Property tests: random refine/coarsen sequences on base meshes of several topologies; every
// invariant after every operation, and file round trips at the end of each sequence.
#include "hierarchy_checks.h"

namespace amc {
namespace {

using testing::Random;

TEST(RandomHierarchies, ThousandRefineCoarsenSequencesKeepEveryInvariant) {
    const auto meshes = testing::fixture_meshes();
    int sequences = 0;
    uint64_t operations = 0, coarsenings = 0;
    for (int s = 0; s < 1000; ++s) {
        const auto& [name, mesh] = meshes[size_t(s) % meshes.size()];
        Random random{uint64_t(s) + 1};
        Hierarchy h(mesh);
        const int steps = 10 + int(random.next() % 40);
        const int max_level = 2 + int(random.next() % 4);
        for (int step = 0; step < steps; ++step) {
            std::vector<NodeId> nodes = h.breadth_first_order();
            const NodeId n = nodes[random.next() % nodes.size()];
            if (random.next() % 3 == 0) {
                if (h.parent(n) != kNoNode) coarsenings += h.coarsen(h.parent(n));
            } else if (h.is_leaf(n) && h.level(n) < max_level) {
                h.refine(n);
            }
            if (random.next() % 4 == 0 && h.is_leaf(n) && h.hanging_node_count(n) == 2) {
                h.set_diagonal_flipped(n, !h.diagonal_flipped(n));
            }
            ++operations;
            const std::string problem = check_invariants(h);
            ASSERT_EQ(problem, "") << name << " sequence " << s << " step " << step;
        }
        ASSERT_TRUE(testing::hierarchy_is_valid(h)) << name << " sequence " << s;
        const Hierarchy back = deserialize_hierarchy(serialize_hierarchy(h), "memory");
        ASSERT_TRUE(identical(h, back)) << name << " sequence " << s;
        ++sequences;
    }
    EXPECT_EQ(sequences, 1000);
    EXPECT_GT(coarsenings, operations / 20) << "the sequences must exercise coarsening";
}

TEST(RandomHierarchies, LargeRandomHierarchiesAreValid) {
    for (const auto& [name, mesh] : testing::fixture_meshes()) {
        Hierarchy h(mesh);
        refine_randomly(h, 20000, 7, 99, 0.3);
        EXPECT_GE(h.leaf_count(), 20000u) << name;
        EXPECT_TRUE(testing::hierarchy_is_valid(h)) << name;
        EXPECT_TRUE(identical(h, deserialize_hierarchy(serialize_hierarchy(h), "memory"))) << name;
    }
}

TEST(RandomHierarchies, RandomRefinementIsDeterministic) {
    Hierarchy a(make_icosahedron()), b(make_icosahedron());
    refine_randomly(a, 5000, 6, 42, 0.2);
    refine_randomly(b, 5000, 6, 42, 0.2);
    EXPECT_TRUE(identical(a, b));
}

}  // namespace
}  // namespace amc
