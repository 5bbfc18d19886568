// Leaf mesh alone -> hierarchy (import_mesh, base detection): known answers on uniform and small
// adaptive refinements, round trips over random hierarchies, the semi-regular and irregular meshes
// of the shared data.
#include "hierarchy_checks.h"
#include "import/base_detection.h"
#include "import/hierarchy_from_levels.h"

#include <amc/import.h>
#include <amc/mesh_io.h>
#include <amc/refinement.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <numeric>

namespace amc {
namespace {

using testing::Random;
using testing::shuffled;

Triangle normalized(Triangle t) {
    const int r = t[0] < t[1] ? (t[0] < t[2] ? 0 : 2) : (t[1] < t[2] ? 1 : 2);
    return {t[size_t(r)], t[size_t(r + 1) % 3], t[size_t(r + 2) % 3]};
}

// The imported hierarchy is valid and its leaf mesh is the input: the same triangles (same
// orientation) on the same positions, related by vertex_of_input.
::testing::AssertionResult reproduces(const ImportedHierarchy& imported, const TriangleMesh& input) {
    const Hierarchy& h = imported.hierarchy;
    if (!testing::hierarchy_is_valid(h)) return testing::hierarchy_is_valid(h);
    if (imported.vertex_of_input.size() != input.positions.size()) return ::testing::AssertionFailure() << "vertex map size";
    const std::vector<uint32_t> canonical = canonical_vertex_order(h);
    const LeafMesh leaf = extract_leaf_mesh(h);
    std::vector<uint32_t> input_of_canonical(leaf.mesh.positions.size(), 0xffffffffu);
    for (uint32_t i = 0; i < input.positions.size(); ++i) {
        const VertexId v = imported.vertex_of_input[i];
        if (!(h.position(v) == input.positions[i])) return ::testing::AssertionFailure() << "position of vertex " << i;
        input_of_canonical[canonical[v]] = i;
    }
    std::vector<Triangle> built, given;
    for (const Triangle& t : leaf.mesh.triangles) {
        built.push_back(normalized({input_of_canonical[t[0]], input_of_canonical[t[1]], input_of_canonical[t[2]]}));
    }
    for (const Triangle& t : input.triangles) given.push_back(normalized(t));
    std::sort(built.begin(), built.end());
    std::sort(given.begin(), given.end());
    if (built != given) return ::testing::AssertionFailure() << "leaf mesh differs from the input";
    return ::testing::AssertionSuccess();
}

bool forest_is_uniform(const Hierarchy& h) {
    const int depth = h.depth();
    for (NodeId n : h.leaves()) {
        if (h.level(n) != depth) return false;
    }
    return true;
}

TEST(ImportMesh, UniformRefinementsReduceToTheirBase) {
    for (const auto& [name, mesh] : testing::fixture_meshes()) {
        for (int levels = 1; levels <= 4; ++levels) {
            Hierarchy h(mesh);
            refine_uniformly(h, levels);
            const TriangleMesh input = shuffled(extract_leaf_mesh(h).mesh, uint64_t(levels));
            const ImportedHierarchy imported = import_mesh(input, name);
            EXPECT_EQ(imported.hierarchy.root_count(), mesh.triangles.size()) << name << " levels " << levels;
            EXPECT_EQ(imported.hierarchy.depth(), levels) << name;
            EXPECT_TRUE(forest_is_uniform(imported.hierarchy)) << name;
            EXPECT_TRUE(reproduces(imported, input)) << name << " levels " << levels;
        }
    }
}

// One refined triangle, then deeper refinements inside it: green closures of one and two
// hanging nodes, both diagonals.
TEST(ImportMesh, SmallAdaptiveRefinementsReduceToTheirBase) {
    int cases = 0;
    for (const auto& [name, mesh] : testing::fixture_meshes()) {
        for (NodeId root = 0; root < mesh.triangles.size(); root += 3) {
            Hierarchy h(mesh);
            h.refine(root);
            const TriangleMesh one = extract_leaf_mesh(h).mesh;
            const ImportedHierarchy imported = import_mesh(shuffled(one, root), name);
            // The icosahedron is itself a refinement (see below): its bases can be coarser.
            EXPECT_LE(imported.hierarchy.root_count(), mesh.triangles.size()) << name << " root " << root;
            EXPECT_TRUE(reproduces(imported, shuffled(one, root))) << name;
            ++cases;
        }
    }
    EXPECT_GT(cases, 10);
}

// The icosahedron, combinatorially, is the octahedron with two opposite faces split red and the
// six others closed green (12 vertices of valence 5, 20 faces): a coarser base than itself.
TEST(ImportMesh, TheIcosahedronIsARefinedOctahedron) {
    const TriangleMesh icosahedron = make_icosahedron();
    const ImportedHierarchy imported = import_mesh(shuffled(icosahedron, 3), "icosahedron");
    const Hierarchy& h = imported.hierarchy;
    EXPECT_EQ(h.root_count(), 8u);
    EXPECT_EQ(h.base().positions.size(), 6u);
    EXPECT_EQ(h.node_count(), 16u);  // two roots split
    const HierarchyStats stats = compute_stats(h);
    EXPECT_EQ(stats.one_hanging, 6u);
    EXPECT_TRUE(reproduces(imported, shuffled(icosahedron, 3)));
}

TEST(ImportMesh, IrregularMeshesAreTheirOwnBase) {
    for (const auto& [name, mesh] : testing::fixture_meshes()) {
        if (name == "icosahedron") continue;
        const ImportedHierarchy imported = import_mesh(mesh, name);
        EXPECT_EQ(imported.hierarchy.root_count(), mesh.triangles.size()) << name;
        EXPECT_EQ(imported.hierarchy.node_count(), mesh.triangles.size()) << name;
        EXPECT_TRUE(reproduces(imported, mesh)) << name;
    }
}

TEST(ImportMesh, RefusesInvalidMeshesNamingThem) {
    TriangleMesh mesh = make_icosahedron();
    mesh.triangles[3] = {mesh.triangles[3][0], mesh.triangles[3][2], mesh.triangles[3][1]};  // flipped
    try {
        import_mesh(mesh, "flipped.obj");
        FAIL() << "a flipped face was accepted";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("flipped.obj"), std::string::npos) << e.what();
    }
}

// The build's final check: a base whose vertices name the wrong input vertices (two swapped)
// builds a valid hierarchy whose leaf mesh is not the input, which is refused, naming the input.
TEST(ImportMesh, HierarchyFromLevelsRefusesALeafMeshThatDiffers) {
    Hierarchy h(make_icosahedron());
    refine_uniformly(h, 1);
    const TriangleMesh input = shuffled(extract_leaf_mesh(h).mesh, 7);
    DetectedBase detected = truncated(input, detect_base(input), 0);
    EXPECT_TRUE(reproduces(hierarchy_from_levels(input, detected, "leaf.obj"), input));
    std::swap(detected.leaf_vertex_of_base[0], detected.leaf_vertex_of_base[1]);
    try {
        hierarchy_from_levels(input, detected, "leaf.obj");
        FAIL() << "a leaf mesh that differs from the input was accepted";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("leaf.obj"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("differs from the input"), std::string::npos) << e.what();
    }
}

// When the search runs again in reverse order: figures of searched runs (docs/IMPORT.md, "Searched
// twice"). Irregular meshes read a few small patches only (horse: 96,794 of 96,966 left, 2 levels);
// random seed 64 of the test below undoes nothing in its order and reaches its base of 20 in reverse.
TEST(ImportMesh, SearchedAgainWhereTheSearchStoppedFarFromABase) {
    EXPECT_FALSE(searched_again(96794, 96966, 2));  // horse.obj
    EXPECT_FALSE(searched_again(3618, 3674, 2));    // bunny.obj
    EXPECT_TRUE(searched_again(12946, 12946, 0));   // fandisk.obj: nothing undone (the same both ways)
    EXPECT_TRUE(searched_again(1230, 1230, 0));     // random seed 64
    EXPECT_TRUE(searched_again(19112, 100000, 5));  // fandisk_gauss, shuffled by seed 0
    EXPECT_TRUE(searched_again(308, 390, 3));       // random seed 54: 79 % left
    EXPECT_FALSE(searched_again(542, 74792, 4));    // front_1: its true base
    EXPECT_FALSE(searched_again(500, 100000, 5));   // fandisk_mean at its base
}

// Random hierarchies (refinement and coarsening, every fixture topology): the leaf mesh,
// shuffled, comes back as a valid hierarchy with that leaf mesh. How often the base found is as
// coarse as the true one is printed and must not fall below today's figures (docs/IMPORT.md,
// section 2, states them).
// Random hierarchy s of the tests below (refinement and coarsening over fixture s mod 4) and its
// leaf mesh, shuffled.
struct RandomCase {
    std::string name;
    Hierarchy truth;
    TriangleMesh input;
};

RandomCase random_case(int s) {
    const auto meshes = testing::fixture_meshes();
    const auto& [name, mesh] = meshes[size_t(s) % meshes.size()];
    Random random{uint64_t(s) * 7 + 3};
    Hierarchy h(mesh);
    refine_randomly(h, 50 + uint32_t(random.next() % 1500), 2 + int(random.next() % 5), uint64_t(s), (s % 3) * 0.2);
    TriangleMesh input = shuffled(extract_leaf_mesh(h).mesh, uint64_t(s));
    return {name, std::move(h), std::move(input)};
}

TEST(ImportMesh, RandomHierarchiesRoundTrip) {
    int at_most_true = 0, total = 0;
    uint64_t found = 0, truth = 0;
    for (int s = 0; s < 200; ++s) {
        const auto [name, h, input] = random_case(s);
        const ImportedHierarchy imported = import_mesh(input, name);
        ASSERT_TRUE(reproduces(imported, input)) << name << " seed " << s;
        ++total;
        at_most_true += imported.hierarchy.root_count() <= h.root_count();
        found += imported.hierarchy.root_count();
        truth += h.root_count();
    }
    std::printf("[import_mesh] random hierarchies: base as coarse as the true one in %d of %d; %lu base triangles found, %lu true\n",
                at_most_true, total, (unsigned long)found, (unsigned long)truth);
    EXPECT_GE(at_most_true, 66);
    EXPECT_LE(found, 77451u);
}

// A level keeps only what it made (DetectedLevel): the mesh each level leaves is made again from
// the leaf triangles in the order the search ran over them (reversed where the second search
// won), and must be the mesh the search left: the whole replay gives the base triangle for
// triangle, and the first k levels alone build a hierarchy that reproduces the input.
TEST(ImportMesh, DetectedLevelsReplayToTheMeshesTheyLeft) {
    int reversed = 0, cases = 0;
    for (int s : {3, 10, 17, 54, 64, 71, 100, 133}) {
        const auto [name, h, input] = random_case(s);
        const DetectedBase detected = detect_base(input, name);
        reversed += detected.found_in_reverse;
        const std::vector<Triangle> leaf = detected.found_in_reverse
                                               ? std::vector<Triangle>(input.triangles.rbegin(), input.triangles.rend())
                                               : input.triangles;
        const uint32_t vertex_count = uint32_t(input.positions.size());
        std::vector<Triangle> base;
        for (const Triangle& t : detected.base.triangles) {
            base.push_back({detected.leaf_vertex_of_base[t[0]], detected.leaf_vertex_of_base[t[1]], detected.leaf_vertex_of_base[t[2]]});
        }
        EXPECT_EQ(mesh_after(leaf, detected.levels, detected.levels.size(), vertex_count), base) << name << " seed " << s;
        for (size_t k = 1; k < detected.levels.size(); ++k) {
            const DetectedBase first = truncated(input, detected, k);
            EXPECT_EQ(first.base.triangles.size(), detected.levels[k - 1].triangles_left) << name << " seed " << s << " k " << k;
            EXPECT_TRUE(reproduces(hierarchy_from_levels(input, first, name), input)) << name << " seed " << s << " k " << k;
            ++cases;
        }
    }
    EXPECT_GT(reversed, 0);  // seed 64 reaches its base in reverse only
    EXPECT_GT(cases, 8);
}

// ---- the shared data -------------------------------------------------------------------------

std::filesystem::path shared_data() { return AMC_SHARED_DATA_DIR; }

TEST(ImportMesh, SharedDataSemiRegularMeshes) {
    if (!std::filesystem::is_directory(shared_data())) GTEST_SKIP() << "no shared data at " << shared_data();
    const struct {
        const char* file;
        uint32_t base_triangles;
        int levels;
    } cases[] = {{"bunny-sr-l3.obj", 500, 3}, {"elephant-sr-l2.obj", 588, 2}, {"icosphere-l3.obj", 20, 3}};
    for (const auto& c : cases) {
        const TriangleMesh mesh = read_mesh((shared_data() / c.file).string());
        for (const TriangleMesh& input : {mesh, shuffled(mesh, 11)}) {
            const ImportedHierarchy imported = import_mesh(input, c.file);
            EXPECT_EQ(imported.hierarchy.root_count(), c.base_triangles) << c.file;
            EXPECT_EQ(imported.hierarchy.depth(), c.levels) << c.file;
            EXPECT_TRUE(forest_is_uniform(imported.hierarchy)) << c.file;
            EXPECT_TRUE(reproduces(imported, input)) << c.file;
        }
    }
}

// A few small patches of these meshes happen to read as refinements; the rest is base. The
// search runs once on them (searched_again): venus in reverse order would end at 98,000 triangles.
TEST(ImportMesh, SharedDataIrregularMeshesAreMostlyTheirOwnBase) {
    if (!std::filesystem::is_directory(shared_data())) GTEST_SKIP() << "no shared data at " << shared_data();
    const struct {
        const char* file;
        uint32_t base_triangles;
    } cases[] = {{"bunny.obj", 3618}, {"horse.obj", 96794}, {"feline.off", 98202}, {"fandisk.obj", 12946}, {"venus.off", 98066}};
    for (const auto& c : cases) {
        const char* file = c.file;
        const TriangleMesh mesh = read_mesh((shared_data() / file).string());
        const ImportedHierarchy imported = import_mesh(mesh, file);
        EXPECT_TRUE(reproduces(imported, mesh)) << file;
        EXPECT_EQ(imported.hierarchy.root_count(), c.base_triangles) << file;
        std::printf("[import_mesh] %-12s %6zu triangles -> base of %6u\n", file, mesh.triangles.size(),
                    imported.hierarchy.root_count());
    }
}

// The corpus's fandisk_mean (scripts/corpus.sh: fandisk remeshed by mean curvature, 500 base
// triangles, 10^5 faces, level 5), shuffled. Its first step takes one wrong one-block patch that
// it cannot tell from the true ones; the parent of that block stands in the way of the true patch
// of the seventh step. Taken back and the search run again, it reaches the true base
// (docs/IMPORT.md, "One-block patches taken back"). The face orders of seeds 1 and 6 stop at about
// 48,500 triangles in their own order and reach the base in reverse order ("Searched twice");
// seed 2 reaches it in its own.
TEST(ImportMesh, SharedDataFandiskMeanRemeshFindsItsBase) {
    if (!std::filesystem::is_regular_file(shared_data() / "fandisk.obj")) GTEST_SKIP() << "no shared data at " << shared_data();
    SurfaceRemeshOptions options;
    options.criterion = RefinementCriterion::mean_curvature;
    options.base_triangles = 500;
    options.target_faces = 100000;
    options.max_level = 5;
    const Hierarchy h = remesh_adaptively(read_mesh((shared_data() / "fandisk.obj").string()), options);
    ASSERT_EQ(h.root_count(), 500u);
    for (uint64_t seed : {1, 2, 6}) {
        const TriangleMesh input = shuffled(extract_leaf_mesh(h).mesh, seed);
        const ImportedHierarchy imported = import_mesh(input, "fandisk_mean");
        EXPECT_EQ(imported.hierarchy.root_count(), 500u) << "seed " << seed;
        EXPECT_TRUE(reproduces(imported, input)) << "seed " << seed;
    }
}

}  // namespace
}  // namespace amc
