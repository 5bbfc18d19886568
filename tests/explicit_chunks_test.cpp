// EncodeOptions::chunk_roots and keep_base_order: chunks cut where the caller says, over the base
// mesh in the caller's own order (what an MPI writer's file is, include/amc/mpi.h).
#include "coding/format_version.h"
#include "hierarchy_checks.h"

#include <amc/codec.h>

#include <numeric>

namespace amc {
namespace {

using testing::Random;

Hierarchy adaptive_hierarchy(uint64_t seed) {
    Random random{seed};
    const auto meshes = testing::fixture_meshes();
    Hierarchy h(testing::shuffled(meshes[seed % meshes.size()].mesh, seed));
    refine_randomly(h, h.root_count() + 80 + uint32_t(random.next() % 400), 1 + int(random.next() % 4), seed);
    for (NodeId n : h.leaves())
        if (h.hanging_node_count(n) == 2 && random.next() % 3 == 0) h.set_diagonal_flipped(n, true);
    return h;
}

// Random root counts of `chunks` chunks (each at least one) adding up to `roots`.
std::vector<uint32_t> random_cut(uint32_t roots, uint32_t chunks, uint64_t seed) {
    Random random{seed};
    std::vector<uint32_t> counts(chunks, 1);
    for (uint32_t r = chunks; r < roots; ++r) ++counts[random.next() % chunks];
    return counts;
}

TEST(ExplicitChunks, KeepBaseOrderDecodesToTheInputItself) {
    for (uint64_t seed = 0; seed < 8; ++seed) {
        SCOPED_TRACE("seed " + std::to_string(seed));
        const Hierarchy h = adaptive_hierarchy(seed);
        EncodeOptions options;
        options.keep_base_order = true;
        const std::vector<uint8_t> bytes = encode(h, options);
        const Hierarchy back = decode(bytes.data(), bytes.size());
        EXPECT_EQ(back.base().triangles, h.base().triangles);
        ASSERT_EQ(back.base().positions.size(), h.base().positions.size());
        for (size_t v = 0; v < h.base().positions.size(); ++v) EXPECT_EQ(back.base().positions[v], h.base().positions[v]);
        EXPECT_TRUE(identical(back, h));
        EXPECT_TRUE(identical(in_decoder_order(h, options), h));
    }
}

TEST(ExplicitChunks, ChunksAreCutWhereTheCallerSays) {
    for (uint64_t seed = 0; seed < 12; ++seed) {
        SCOPED_TRACE("seed " + std::to_string(seed));
        const Hierarchy h = adaptive_hierarchy(seed);
        for (bool keep : {false, true}) {
            EncodeOptions options;
            options.keep_base_order = keep;
            const uint32_t chunks = 2 + uint32_t(seed % 4);
            options.chunk_roots = random_cut(h.root_count(), chunks, seed);
            const std::vector<uint8_t> bytes = encode(h, options);
            const FileInfo info = inspect(bytes.data(), bytes.size());
            ASSERT_GE(info.version, kChunkVerticesVersion);  // 14 with raw side streams
            ASSERT_EQ(info.chunks.size(), chunks);
            uint32_t first = 0;
            for (uint32_t c = 0; c < chunks; ++c) {
                EXPECT_EQ(info.chunks[c].first_root, first);
                EXPECT_EQ(info.chunks[c].roots, options.chunk_roots[c]);
                first += options.chunk_roots[c];
            }
            const Hierarchy back = decode(bytes.data(), bytes.size());
            EXPECT_TRUE(identical(back, in_decoder_order(h, options)));
            if (keep) {
                EXPECT_TRUE(identical(back, h));
            }
            // One entry: the whole forest in one piece, as without chunks.
            options.chunk_roots = {h.root_count()};
            const std::vector<uint8_t> one = encode(h, options);
            EXPECT_TRUE(inspect(one.data(), one.size()).chunks.empty());
            options.chunk_roots.clear();
            options.chunks = 1;
            EXPECT_EQ(one, encode(h, options));
        }
    }
}

TEST(ExplicitChunks, RootCountsThatDoNotCutTheForestAreRefused) {
    const Hierarchy h = adaptive_hierarchy(3);
    EncodeOptions options;
    for (const std::vector<uint32_t>& bad : {std::vector<uint32_t>{h.root_count() - 1},
                                             std::vector<uint32_t>{h.root_count(), 1},
                                             std::vector<uint32_t>{0, h.root_count()}}) {
        options.chunk_roots = bad;
        try {
            encode(h, options);
            ADD_FAILURE() << "accepted bad chunk_roots";
        } catch (const Error& e) {
            EXPECT_EQ(e.code(), ErrorCode::invalid_input);
            EXPECT_NE(std::string(e.what()).find("chunk"), std::string::npos) << e.what();
        }
    }
}

}  // namespace
}  // namespace amc
