// The octree coder: bit-exact round trips over random balanced forests in 2D and 3D, every switch,
// progressive decoding, refusal of unbalanced input, and hostile files (every truncation, every
// byte changed, counts that ask for too much).
#include "coding/container.h"
#include "octree/octree_file.h"
#include "octree/octree_traversal.h"
#include "octree_test_util.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>

namespace amc {
namespace {

OctreeForest decode(const std::vector<uint8_t>& bytes, const OctreeDecodeOptions& options = {}) {
    return decode_octree_forest(bytes.data(), bytes.size(), options);
}

TEST(OctreeCoder, RoundTripsRandomBalancedForests) {
    std::mt19937_64 rng(1);
    for (int round = 0; round < 300; ++round) {
        const int dim = 2 + round % 2;
        const OctreeForest forest = octree_test::random_balanced_forest(dim, rng, round % 5 == 0 ? OctreeBalance::corner : OctreeBalance::face);
        OctreeEncodeOptions options;
        const unsigned bits = unsigned(rng());
        options.uniform_levels = bits & 1;
        options.truncate = bits & 2;
        options.context_groups = bits & 4;
        options.improved_traversal = bits & 8;
        options.cull_by_balance = (bits & 48) != 0;
        OctreeEncodeStats stats;
        const std::vector<uint8_t> bytes = encode_octree_forest(forest, options, &stats);
        const OctreeForest back = decode(bytes);
        ASSERT_TRUE(back == forest) << "round " << round;
        EXPECT_EQ(encode_octree_forest(back, options), bytes);
        EXPECT_EQ(stats.nodes, count_octree_forest(forest).nodes);
        EXPECT_EQ(stats.uniform + stats.culled + stats.truncated + stats.coded, stats.nodes);
        EXPECT_EQ(stats.file_bytes, bytes.size());
    }
}

TEST(OctreeCoder, UnbalancedForestsRefusedOrCodedWithoutCulling) {
    std::mt19937_64 rng(2);
    int refused = 0;
    for (int round = 0; round < 40; ++round) {
        const int dim = 2 + round % 2;
        const OctreeForest raw = random_octree_forest(octree_test::random_connectivity(dim, rng), rng(), 0.4, 1, dim == 2 ? 6 : 3);
        const bool balanced = octree_balance_violation(raw, OctreeBalance::face).empty();
        if (!balanced) {
            try {
                encode_octree_forest(raw);
                ADD_FAILURE() << "an unbalanced forest was encoded";
            } catch (const Error& e) {
                EXPECT_EQ(e.code(), ErrorCode::invalid_input);
                EXPECT_NE(std::string(e.what()).find("not 2:1 balanced"), std::string::npos);
                ++refused;
            }
        }
        OctreeEncodeOptions options;
        options.cull_by_balance = false;
        EXPECT_TRUE(decode(encode_octree_forest(raw, options)) == raw);
    }
    EXPECT_GT(refused, 10);
}

TEST(OctreeCoder, UniformForestCodesNoSymbol) {
    for (int dim : {2, 3}) {
        const OctreeForest uniform = uniform_octree_forest(brick_connectivity(dim, 2, 3, 2), dim == 2 ? 5 : 3);
        OctreeEncodeStats stats;
        const std::vector<uint8_t> bytes = encode_octree_forest(uniform, {}, &stats);
        EXPECT_EQ(stats.coded, 0u);
        EXPECT_EQ(stats.level_bytes, 0u);
        EXPECT_TRUE(decode(bytes) == uniform);
    }
}

// Known answer, counted by hand: one tree, its corner octant refined down to level 3.
TEST(OctreeCoder, KnownFatesOfACornerRefinement) {
    const TreeConnectivity conn = brick_connectivity(2, 1, 1);
    const OctreeForest forest = balance_octree_forest(
        refine_octree_forest(uniform_octree_forest(conn, 0), [](uint32_t, const Octant& o) { return o.x == 0 && o.y == 0; }, 3),
        OctreeBalance::face);
    // Levels: 1 root, 4 octants (the corner one refined), 4 (the corner one refined), 4 leaves.
    ASSERT_EQ(forest.leaves.size(), 10u);
    OctreeEncodeStats stats;
    const std::vector<uint8_t> bytes = encode_octree_forest(forest, {}, &stats);
    EXPECT_EQ(stats.nodes, 13u);
    // Level 0 is uniform. Level 1: 4 symbols (1 0 0 0). Levels 2 and 3: the three octants away
    // from the corner touch a coarser leaf (culled), the corner one is coded: 1, then 0. The
    // trailing 0 is truncated.
    EXPECT_EQ(stats.uniform, 1u);
    EXPECT_EQ(stats.culled, 6u);
    EXPECT_EQ(stats.coded, 5u);
    EXPECT_EQ(stats.truncated, 1u);
    EXPECT_TRUE(decode(bytes) == forest);
}

TEST(OctreeCoder, ProgressiveDecodingGivesTheCoarseLevels) {
    std::mt19937_64 rng(4);
    for (int round = 0; round < 40; ++round) {
        const OctreeForest forest = octree_test::random_balanced_forest(2 + round % 2, rng);
        const std::vector<uint8_t> bytes = encode_octree_forest(forest);
        const int depth = count_octree_forest(forest).depth;
        for (int level = 0; level <= depth + 1; ++level) {
            OctreeDecodeOptions options;
            options.max_level = level;
            const OctreeForest coarse = decode(bytes, options);
            // The forest cut at `level`: leaves below it replaced by their ancestors there.
            const OctreeForest expected = refine_octree_forest(
                uniform_octree_forest(forest.connectivity, 0),
                [&](uint32_t t, const Octant& o) {
                    for (uint64_t i = forest.tree_offsets[t]; i < forest.tree_offsets[t + 1]; ++i) {
                        const Octant& leaf = forest.leaves[i];
                        const int shift = octree_root_log2(forest.dim()) - o.level;
                        if (leaf.level > o.level && (leaf.x >> shift) == (o.x >> shift) && (leaf.y >> shift) == (o.y >> shift) &&
                            (leaf.z >> shift) == (o.z >> shift))
                            return true;
                    }
                    return false;
                },
                level);
            ASSERT_TRUE(coarse == expected) << "round " << round << " level " << level;
        }
    }
}

TEST(OctreeCoder, EveryTruncationAndEveryChangedByteIsAnError) {
    std::mt19937_64 rng(6);
    for (int round = 0; round < 6; ++round) {
        const OctreeForest forest = octree_test::random_balanced_forest(2 + round % 2, rng);
        const std::vector<uint8_t> bytes = encode_octree_forest(forest);
        for (size_t n = 0; n < bytes.size(); ++n) {
            std::vector<uint8_t> cut(bytes.begin(), bytes.begin() + n);
            EXPECT_THROW(decode(cut), Error) << n;
        }
        for (size_t i = 0; i < bytes.size(); ++i) {
            std::vector<uint8_t> changed = bytes;
            changed[i] ^= uint8_t(1 + rng() % 255);
            EXPECT_THROW(decode(changed), Error) << i;
        }
        std::vector<uint8_t> longer = bytes;
        longer.push_back(0);
        EXPECT_THROW(decode(longer), Error);
    }
}

// A file whose blocks are well framed (checksums right) but whose contents lie.
std::vector<uint8_t> framed(const OctreeMetadata& meta, const std::vector<uint8_t>& connectivity,
                            const std::vector<std::vector<uint8_t>>& level_payloads) {
    BlockWriter writer(kOctreeFraming, kOctreeBaseVersion, 0);
    writer.add(uint8_t(OctreeBlock::metadata), write_octree_metadata(meta));
    writer.add(uint8_t(OctreeBlock::connectivity), connectivity);
    for (const auto& p : level_payloads) writer.add(uint8_t(OctreeBlock::level), p);
    return writer.finish();
}

ErrorCode error_of(const std::vector<uint8_t>& bytes, const OctreeDecodeOptions& options = {}) {
    try {
        decode(bytes, options);
    } catch (const Error& e) {
        return e.code();
    }
    return ErrorCode(0);
}

TEST(OctreeCoder, HostileCountsAreRefusedBeforeAllocating) {
    const TreeConnectivity conn = brick_connectivity(3, 1, 1, 1);
    const std::vector<uint8_t> c = write_octree_connectivity(conn);
    OctreeMetadata meta;
    meta.dim = 3;
    meta.trees = 1;
    meta.switches = kOctreeUniformLevels | kOctreeTruncate | kOctreeCullByBalance;
    // 18 uniform levels of an octree: 8^18 octants.
    meta.levels = 19;
    meta.uniform_levels = 18;
    meta.octants = (uint64_t{1} << 62) + 1;
    meta.leaves = meta.octants - (meta.octants - 1) / 8;
    EXPECT_EQ(error_of(framed(meta, c, std::vector<std::vector<uint8_t>>(19))), ErrorCode::limit_exceeded);
    // Within the limit as announced, but the uniform levels make more octants than that.
    meta.octants = 1 + 8 * 100;
    meta.leaves = meta.octants - 100;
    EXPECT_EQ(error_of(framed(meta, c, std::vector<std::vector<uint8_t>>(19))), ErrorCode::corrupt);
    // More levels than the dimension allows.
    meta.levels = 20;
    EXPECT_EQ(error_of(framed(meta, c, std::vector<std::vector<uint8_t>>(20))), ErrorCode::corrupt);
    // A connectivity that announces more trees than its bytes hold.
    meta.levels = 2;
    meta.uniform_levels = 1;
    meta.octants = 9;
    meta.leaves = 8;
    meta.trees = 1000000;
    EXPECT_EQ(error_of(framed(meta, c, std::vector<std::vector<uint8_t>>(2))), ErrorCode::corrupt);
    meta.trees = 1;
    EXPECT_EQ(decode(framed(meta, c, std::vector<std::vector<uint8_t>>(2))).leaves.size(), 8u);
    // A small limit.
    OctreeDecodeOptions small;
    small.max_nodes = 8;
    EXPECT_EQ(error_of(framed(meta, c, std::vector<std::vector<uint8_t>>(2)), small), ErrorCode::limit_exceeded);
    // The count of symbols larger than the symbols there are.
    meta.count = 5;
    EXPECT_EQ(error_of(framed(meta, c, std::vector<std::vector<uint8_t>>(2))), ErrorCode::corrupt);
}

TEST(OctreeCoder, WrongMagicAndNewerVersion) {
    std::vector<uint8_t> bytes = encode_octree_forest(uniform_octree_forest(brick_connectivity(2, 1, 1), 1));
    std::vector<uint8_t> amc = bytes;
    amc[2] = 'C', amc[3] = 'F';
    EXPECT_EQ(error_of(amc), ErrorCode::bad_magic);
    std::vector<uint8_t> newer = bytes;
    newer[4] = kOctreeNewestVersion + 1;
    EXPECT_EQ(error_of(newer), ErrorCode::unsupported_version);
}

}  // namespace
}  // namespace amc

namespace amc {
namespace {

// Golden .amq files (tests/data/golden/amq-v1/), kept forever: each decodes to the forest it was
// made from, and the encoder still writes exactly its bytes. AMC_UPDATE_GOLDEN=1 writes the
// missing files (never overwrites one).
struct OctreeGoldenCase {
    std::string name;
    OctreeForest forest;
    OctreeEncodeOptions options;
};

std::vector<OctreeGoldenCase> octree_golden_cases() {
    std::vector<OctreeGoldenCase> cases;
    cases.push_back({"circle_2d_face",
                     balance_octree_forest(sphere_octree_forest(brick_connectivity(2, 1, 1), {0.5, 0.5, 0}, 0.35, 6), OctreeBalance::face),
                     {}});
    cases.push_back({"front_3d_periodic_corner",
                     balance_octree_forest(front_octree_forest(brick_connectivity(3, 2, 1, 1, true), 1.0, 4), OctreeBalance::corner),
                     {}});
    // Two cubes, the second turned a quarter about x (orientation 1), glued by their vertices.
    TreeConnectivity cube = brick_connectivity(3, 2, 1, 1);
    std::vector<uint32_t> turned = cube.tree_to_vertex;
    for (int c = 0; c < 8; ++c)
        turned[8 + c] = cube.tree_to_vertex[8 + ((c & 1) | ((1 - ((c >> 2) & 1)) << 1) | (((c >> 1) & 1) << 2))];
    cases.push_back({"turned_3d_random",
                     balance_octree_forest(random_octree_forest(connectivity_from_vertices(3, cube.vertices, turned), 5, 0.4, 1, 4),
                                           OctreeBalance::face),
                     {}});
    OctreeEncodeOptions plain;
    plain.context_groups = false;
    plain.improved_traversal = false;
    plain.truncate = false;
    plain.uniform_levels = false;
    TreeConnectivity no_vertices = brick_connectivity(2, 3, 1, 1, true);
    no_vertices.vertices.clear();
    no_vertices.tree_to_vertex.clear();
    cases.push_back({"random_2d_plain_no_vertices",
                     balance_octree_forest(random_octree_forest(no_vertices, 9, 0.45, 1, 6), OctreeBalance::face), plain});
    return cases;
}

TEST(OctreeGolden, FilesDecodeAndEncoderBytesArePinned) {
    const std::string dir = std::string(AMC_TEST_DATA_DIR) + "/golden/amq-v1/";
    const bool update = std::getenv("AMC_UPDATE_GOLDEN") != nullptr;
    for (const OctreeGoldenCase& c : octree_golden_cases()) {
        const std::string path = dir + c.name + ".amq";
        const std::vector<uint8_t> bytes = encode_octree_forest(c.forest, c.options);
        std::ifstream in(path, std::ios::binary);
        if (!in) {
            ASSERT_TRUE(update) << path << " is missing (AMC_UPDATE_GOLDEN=1 writes it)";
            std::filesystem::create_directories(dir);
            std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
            continue;
        }
        const std::vector<uint8_t> golden((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        EXPECT_TRUE(decode(golden) == c.forest) << path;
        EXPECT_EQ(bytes, golden) << path << ": the encoder's bytes changed (a new .amq version?)";
    }
}

}  // namespace
}  // namespace amc
