// Refinement histories: known answers on small cases, random histories that replay to the same
// hierarchies through the file, and bad files refused with the line of the problem.
#include "hierarchy_checks.h"

#include <amc/import.h>
#include <amc/mesh_io.h>

#include <algorithm>

namespace amc {
namespace {

using testing::hierarchy_is_valid;
using testing::Random;

TriangleMesh one_triangle() {
    TriangleMesh mesh;
    mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    mesh.triangles = {{0, 1, 2}};
    return mesh;
}

size_t element_count(const Hierarchy& h) { return extract_leaf_mesh(h).mesh.triangles.size(); }

TEST(History, RefineThenCoarsenOneTriangle) {
    Hierarchy h(one_triangle());
    apply_adaptation_step(h, {0}, {});
    EXPECT_EQ(h.leaf_count(), 4u);
    EXPECT_EQ(element_count(h), 4u);
    apply_adaptation_step(h, {}, {0, 1, 2, 3});
    EXPECT_EQ(h.node_count(), 1u);
    EXPECT_TRUE(identical(h, Hierarchy(one_triangle())));
}

TEST(History, RefiningTheCenterChildMakesItsSiblingsGreen) {
    Hierarchy h(one_triangle());
    apply_adaptation_step(h, {0}, {});
    // Elements in canonical order: children 0..3 of the root; element 3 is the center child.
    apply_adaptation_step(h, {3}, {});
    EXPECT_EQ(h.leaf_count(), 7u);
    EXPECT_EQ(element_count(h), 10u);  // four red grandchildren, three corner children bisected
    EXPECT_TRUE(hierarchy_is_valid(h));
}

TEST(History, MarkingAGreenElementRefinesItsNodeRed) {
    Hierarchy h(make_square(1));
    apply_adaptation_step(h, {0}, {});  // root 0 refined: root 1 bisected (elements 0 and 1)
    ASSERT_EQ(element_count(h), 6u);
    ASSERT_EQ(extract_leaf_mesh(h).source[0], 1u);
    apply_adaptation_step(h, {1}, {});  // the second half of the bisection: its node, root 1
    Hierarchy expected(make_square(1));
    expected.refine(0);
    expected.refine(1);
    EXPECT_TRUE(identical(h, expected));
}

TEST(History, RefinementFollowsBalanceAndClosure) {
    Hierarchy h(make_square(2));
    Hierarchy expected(make_square(2));
    apply_adaptation_step(h, {2}, {});
    const NodeId node = extract_leaf_mesh(expected).source[2];
    expected.refine(node);
    // Deeper: refine the first child of that node, which balance spreads.
    const uint32_t element = 4;
    const NodeId deeper = extract_leaf_mesh(expected).source[element];
    apply_adaptation_step(h, {element}, {});
    expected.refine(deeper);
    EXPECT_TRUE(identical(h, expected));
    EXPECT_TRUE(hierarchy_is_valid(h));
}

TEST(History, CoarseningNeedsEveryElementOfTheFourChildren) {
    Hierarchy h(one_triangle());
    apply_adaptation_step(h, {0}, {});
    apply_adaptation_step(h, {}, {0, 1, 2});  // three of four: nothing happens
    EXPECT_EQ(h.leaf_count(), 4u);
    // Refinement wins: listing every element but one for coarsening and that one for refinement
    // refines it and keeps its parent; the other root, all of whose children are listed, goes.
    Hierarchy g(make_square(1));
    apply_adaptation_step(g, {0, 1}, {});  // both roots refined: 8 red elements
    const LeafMesh leaf = extract_leaf_mesh(g);
    ASSERT_EQ(leaf.source.size(), 8u);
    const NodeId refined = leaf.source[7];  // the center child of root 1
    ASSERT_EQ(g.parent(refined), 1u);
    apply_adaptation_step(g, {7}, {0, 1, 2, 3, 4, 5, 6});
    EXPECT_FALSE(g.is_leaf(refined));
    EXPECT_FALSE(g.is_leaf(1));
    EXPECT_TRUE(g.is_leaf(0));  // root 0 coarsened: its children bordered only root 1's corner children
    EXPECT_TRUE(hierarchy_is_valid(g));
}

TEST(History, CoarseningWaitsForBalance) {
    // Root 0 refined twice at a corner next to root 1, root 1 refined once: root 1's children may
    // not be coarsened while root 0's grandchildren border them.
    Hierarchy h(make_square(1));
    h.refine(0);
    h.refine(h.child(0, 0));
    ASSERT_FALSE(h.is_leaf(1));
    const LeafMesh leaf = extract_leaf_mesh(h);
    std::vector<uint32_t> of_root1;
    for (uint32_t e = 0; e < leaf.source.size(); ++e) {
        if (h.parent(leaf.source[e]) == 1) of_root1.push_back(e);
    }
    ASSERT_FALSE(of_root1.empty());
    const Hierarchy before = h;
    apply_adaptation_step(h, {}, of_root1);
    EXPECT_EQ(h.can_coarsen(1), false);
    EXPECT_TRUE(identical(h, before));
}

TEST(History, BadStepsAreRefusedAndLeaveTheHierarchyUnchanged) {
    Hierarchy h(one_triangle());
    apply_adaptation_step(h, {0}, {});
    const Hierarchy before = h;
    auto refused = [&](const std::vector<uint32_t>& refine, const std::vector<uint32_t>& coarsen, const std::string& text) {
        try {
            apply_adaptation_step(h, refine, coarsen);
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
            EXPECT_EQ(e.code(), ErrorCode::invalid_input);
            EXPECT_TRUE(identical(h, before));
            return;
        }
        ADD_FAILURE() << "accepted: " << text;
    };
    refused({4}, {}, "refine element 4 is out of range (the mesh has 4 elements)");
    refused({}, {1, 1}, "coarsen element 1 is listed twice");
    refused({2}, {2}, "element 2 is listed for both refinement and coarsening");
}

// ---- random histories through the file --------------------------------------------------------

// A history of `steps` random steps over `base`: some elements refined, and some parents whose
// children are leaves listed for coarsening, element by element.
RefinementHistory random_history(const TriangleMesh& base, int steps, uint64_t seed, std::vector<Hierarchy>* states) {
    RefinementHistory history;
    history.base = base;
    Hierarchy h(base);
    Random random{seed};
    for (int s = 0; s < steps; ++s) {
        const LeafMesh leaf = extract_leaf_mesh(h);
        AdaptationStep step;
        const size_t elements = leaf.source.size();
        std::vector<uint8_t> used(elements, 0);
        const size_t refinements = 1 + random.next() % 8;
        for (size_t r = 0; r < refinements; ++r) {
            const uint32_t e = uint32_t(random.next() % elements);
            if (used[e] || h.level(leaf.source[e]) >= 7) continue;
            used[e] = 1;
            step.refine.push_back(e);
        }
        if (s >= 2) {
            // Parents whose four children are leaves: list all their elements for some of them,
            // and only some elements for others (which must then stay refined).
            std::vector<std::vector<uint32_t>> of_node(h.node_capacity());
            for (uint32_t e = 0; e < elements; ++e) of_node[leaf.source[e]].push_back(e);
            for (NodeId n : h.breadth_first_order()) {
                if (h.is_leaf(n) || random.next() % 3 != 0) continue;
                bool leaves = true;
                for (int k = 0; k < 4; ++k) leaves = leaves && h.is_leaf(h.child(n, k));
                if (!leaves) continue;
                const bool partly = random.next() % 4 == 0;
                for (int k = 0; k < 4; ++k) {
                    for (uint32_t e : of_node[h.child(n, k)]) {
                        if (used[e] || (partly && k == 3)) continue;
                        used[e] = 1;
                        step.coarsen.push_back(e);
                    }
                }
            }
            // Element order within a list does not matter.
            std::reverse(step.coarsen.begin(), step.coarsen.end());
        }
        apply_adaptation_step(h, step.refine, step.coarsen);
        EXPECT_TRUE(hierarchy_is_valid(h));
        states->push_back(h);
        history.steps.push_back(step);
    }
    return history;
}

TEST(History, RandomHistoriesReplayThroughTheFile) {
    for (const auto& fixture : testing::fixture_meshes()) {
        for (uint64_t seed = 1; seed <= 3; ++seed) {
            TriangleMesh base = fixture.mesh;
            base.single_precision = seed == 2;
            if (base.single_precision) {
                for (Vec3& p : base.positions) p = {double(float(p.x)), double(float(p.y)), double(float(p.z))};
            }
            std::vector<Hierarchy> recorded;
            const RefinementHistory history = random_history(base, 10, seed, &recorded);
            const std::string text = format_history(history);
            const RefinementHistory parsed = parse_history(text, "random.history");
            ASSERT_EQ(parsed.steps.size(), history.steps.size());
            EXPECT_EQ(format_history(parsed), text);  // the file reads back to the same bytes
            const std::vector<Hierarchy> replayed = replay_history(parsed);
            ASSERT_EQ(replayed.size(), recorded.size());
            for (size_t i = 0; i < recorded.size(); ++i) {
                EXPECT_TRUE(identical(replayed[i], recorded[i])) << fixture.name << " seed " << seed << " step " << i;
            }
        }
    }
}

TEST(History, FileWithBasePathReplays) {
    const std::string dir = ::testing::TempDir();
    write_mesh(dir + "/history_base.obj", make_icosahedron());
    write_file_atomically(dir + "/run.history",
                          "amc-history 1\n# an icosahedron refined twice\nbase history_base.obj\n"
                          "step\nrefine 0 5\nstep\nrefine 1\n");
    const RefinementHistory history = read_history(dir + "/run.history");
    ASSERT_EQ(history.steps.size(), 2u);
    EXPECT_EQ(history.steps[1].line, 6u);
    const std::vector<Hierarchy> states = replay_history(history);
    Hierarchy expected(make_icosahedron());
    apply_adaptation_step(expected, {0, 5}, {});
    EXPECT_TRUE(identical(states[0], expected));
    apply_adaptation_step(expected, {1}, {});
    EXPECT_TRUE(identical(states[1], expected));
}

// ---- bad files ---------------------------------------------------------------------------------

std::string parse_error(const std::string& text) {
    try {
        replay_history(parse_history(text, "bad.history", ::testing::TempDir()));
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

TEST(History, BadFilesAreRefusedNamingTheLine) {
    const std::string base = "base-inline 3 1\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n";
    const struct {
        std::string text, message;
    } cases[] = {
        {"", "bad.history:1: not an amc refinement history"},
        {"# comment first\namc-history 1\n" + base, "not an amc refinement history"},
        {"amc-historie 1\n" + base, "bad.history:1: not an amc refinement history"},
        {"amc-history 2\n" + base, "bad.history:1: version 2 is newer than this build reads (1)"},
        {"amc-history one\n" + base, "bad.history:1: expected an integer, not 'one'"},
        {"amc-history 1\n", "bad.history: no base mesh"},
        {"amc-history 1\nstep\n", "bad.history:2: a step before the base mesh"},
        {"amc-history 1\n" + base + base, "bad.history:7: a second base mesh"},
        {"amc-history 1\n" + base + "refine 0\n", "bad.history:7: \"refine\" before the first \"step\""},
        {"amc-history 1\n" + base + "step\nrefine 0 x\n", "bad.history:8: expected an integer, not 'x'"},
        {"amc-history 1\n" + base + "step\ncoarsen -1\n", "bad.history:8: element -1 is not an element index"},
        {"amc-history 1\n" + base + "step\nsplit 0\n", "bad.history:8: unknown keyword 'split'"},
        {"amc-history 1\n" + base + "step 2\n", "bad.history:7: \"step\" takes nothing after it"},
        {"amc-history 1\nbase-inline 4 1\nv 0 0 0\nf 0 1 2\n", "bad.history:2: the counts 4 and 1 do not fit"},
        {"amc-history 1\nbase-inline 3 1\nv 0 0 0\nv 1 0\nv 0 1 0\nf 0 1 2\n", "bad.history:4: expected vertex line"},
        {"amc-history 1\nbase-inline 3 1\nv 0 0 0\nv 1 0 z\nv 0 1 0\nf 0 1 2\n", "bad.history:4: expected a number, not 'z'"},
        {"amc-history 1\nbase-inline 3 1\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 3\n", "bad.history:6: vertex index 3 out of range"},
        {"amc-history 1\nbase-inline 3 1 float16\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", "expected float32 or float64"},
        {"amc-history 1\nbase-inline 5 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 1 1 1\nf 0 1 2\nf 1 0 3\nf 0 1 4\n",
         "bad.history:2: inline base mesh: edge (0,1) is shared by 3 triangles"},
        {"amc-history 1\nbase no_such_file.obj\nstep\n", "bad.history:2: base mesh: "},
        {"amc-history 1\n" + base + "step\nrefine 0\nstep\nrefine 4\n", "bad.history:9: step 2: refine element 4 is out of range"},
        {"amc-history 1\n" + base + "step\nrefine 0 0\n", "bad.history:7: step 1: refine element 0 is listed twice"},
    };
    for (const auto& c : cases) {
        const std::string message = parse_error(c.text);
        EXPECT_NE(message.find(c.message), std::string::npos) << "expected \"" << c.message << "\", got \"" << message
                                                               << "\" for:\n"
                                                               << c.text;
    }
}

}  // namespace
}  // namespace amc
