// The default chunk count (src/coding/chunks/chunk_policy.h): one chunk per chunk_faces leaf faces,
// then fewer when the chunked code holds less than min_chunk_bytes per chunk and a quarter of the
// chunks or more would go; chunk counts the caller gives are kept.
#include "coding/chunks/chunk_policy.h"
#include "coding/container.h"
#include "hierarchy_checks.h"

#include <amc/codec.h>
#include <amc/refinement.h>

namespace amc {
namespace {

EncodeOptions policy(uint64_t chunk_faces, uint64_t min_chunk_bytes) {
    EncodeOptions options;
    options.chunk_faces = chunk_faces;
    options.min_chunk_bytes = min_chunk_bytes;
    options.grid_contexts = false;  // the pinned decisions do not depend on later geometry defaults
    options.unit_normals = false;
    return options;
}

EncodeOptions fixed(uint32_t chunks) {
    EncodeOptions options = policy(EncodeOptions{}.chunk_faces, EncodeOptions{}.min_chunk_bytes);
    options.chunks = chunks;
    return options;
}

// Bytes of the blocks after the base mesh that the policy weighs: chunk table, seam and chunks.
uint64_t forest_bytes(const std::vector<uint8_t>& file) {
    uint64_t bytes = 0;
    for (const FileBlock& block : inspect(file.data(), file.size()).blocks)
        if (block.type == uint8_t(BlockType::chunk_table) || block.type == uint8_t(BlockType::seam) ||
            block.type == uint8_t(BlockType::chunk))
            bytes += block.size;
    return bytes;
}

size_t chunk_count(const std::vector<uint8_t>& file) { return inspect(file.data(), file.size()).chunks.size(); }

// Every vertex at its edge's midpoint: a code of a few hundred bytes, like the corpus's `uniform`.
Hierarchy midpoint_sphere() {
    Hierarchy h(make_icosahedron());
    refine_uniformly(h, 5);  // 20480 faces
    return h;
}

// Positions off the midpoints (lossless: tens of bytes per vertex).
Hierarchy noisy_sphere() {
    Hierarchy h(make_bumpy_sphere(1));
    h.set_single_precision(false);
    refine_randomly(h, 6000, 4, 29);
    testing::Random random{29};
    for (VertexId v = 0; v < h.positions().size(); ++v) {
        const Vec3 p = h.position(v);
        h.set_position(v, Vec3{p.x + double(random.next() % 1000) * 1e-7, p.y, p.z - double(random.next() % 1000) * 1e-7});
    }
    return h;
}

TEST(ChunkPolicy, CountFromFacesAtTheDefaults) {
    const EncodeOptions defaults;
    EXPECT_EQ(defaults.chunk_faces, 500000u);
    EXPECT_EQ(defaults.min_chunk_bytes, 65536u);
    EXPECT_EQ(chunk_count_for(defaults, 0), 1u);
    EXPECT_EQ(chunk_count_for(defaults, 999999), 1u) << "the corpus (at most 327680 faces) is never cut";
    EXPECT_EQ(chunk_count_for(defaults, 1000000), 2u);
    EXPECT_EQ(chunk_count_for(defaults, 10000000), 20u);
    EXPECT_EQ(chunk_count_for(fixed(7), 10), 7u) << "a count the caller gives is kept";
}

TEST(ChunkPolicy, FewerChunksWhenTheCodeIsSmall) {
    const EncodeOptions options = policy(100, 1000);
    EXPECT_EQ(chunk_count_for_size(options, 4, 4000), 4u) << "1000 bytes per chunk: kept";
    EXPECT_EQ(chunk_count_for_size(options, 4, 3999), 3u) << "one chunk per 1000 bytes";
    EXPECT_EQ(chunk_count_for_size(options, 10, 2500), 2u);
    EXPECT_EQ(chunk_count_for_size(options, 4, 999), 1u);
    EXPECT_EQ(chunk_count_for_size(options, 4, 0), 1u);
    EXPECT_EQ(chunk_count_for_size(policy(100, 0), 4, 10), 4u) << "min_chunk_bytes 0: never fewer";
}

TEST(ChunkPolicy, CodedAgainOnlyForAQuarterOfTheChunks) {
    // A second code doubles the forest's encode time (the 5*10^7-face torus at 12 bits: 101 chunks
    // of 63 KiB made 97 for 0.07 % of the file), so it must remove a quarter of the chunks or more:
    // a code kept holds more than 3/4 of min_chunk_bytes a chunk.
    const EncodeOptions options = policy(100, 1000);
    EXPECT_EQ(chunk_count_for_size(options, 10, 9999), 10u) << "9 of 10: kept";
    EXPECT_EQ(chunk_count_for_size(options, 101, 97999), 101u) << "97 of 101: kept";
    EXPECT_EQ(chunk_count_for_size(options, 10, 8000), 10u) << "800 bytes a chunk: kept";
    EXPECT_EQ(chunk_count_for_size(options, 10, 7999), 7u) << "7 of 10: coded again";
    EXPECT_EQ(chunk_count_for_size(options, 8, 6999), 6u) << "6 of 8: exactly a quarter fewer";
    EXPECT_EQ(chunk_count_for_size(options, 8, 7000), 8u) << "7 of 8: kept";
    EXPECT_EQ(chunk_count_for_size(options, 2, 1999), 1u) << "1 of 2";
}

TEST(ChunkPolicy, SmallCodesAreWrittenInOneChunk) {
    const Hierarchy h = midpoint_sphere();
    const std::vector<uint8_t> cut = encode(h, policy(2048, 0));
    ASSERT_EQ(chunk_count(cut), 10u) << "20480 faces at 2048 a chunk";
    const std::vector<uint8_t> one = encode(h, fixed(1));
    EXPECT_GT(cut.size(), one.size() + 500) << "ten chunks of a midpoint model cost more than its whole code";
    EXPECT_EQ(encode(h, policy(2048, 65536)), one) << "a few hundred bytes: one chunk";
    EXPECT_EQ(chunk_count(encode(h, fixed(10))), 10u) << "chunks the caller asks for are kept";
}

TEST(ChunkPolicy, TheSecondTryTakesOneChunkPerMinChunkBytes) {
    const Hierarchy h = noisy_sphere();
    EncodeStats stats;
    const std::vector<uint8_t> ten = encode(h, policy(790, 0), &stats);
    ASSERT_EQ(chunk_count(ten), 10u) << stats.faces << " faces, 790 a chunk";
    const uint64_t bytes = forest_bytes(ten);
    ASSERT_GT(bytes, 10000u);
    EXPECT_EQ(encode(h, policy(790, bytes / 10)), ten) << "exactly min_chunk_bytes per chunk: kept";
    EXPECT_EQ(encode(h, policy(790, bytes / 10 + 1)), ten) << "nine chunks would remove less than a quarter: kept";
    const std::vector<uint8_t> seven = encode(h, policy(790, bytes / 7));
    EXPECT_EQ(chunk_count(seven), 7u);
    EXPECT_EQ(seven, encode(h, fixed(7)));
    const std::vector<uint8_t> three = encode(h, policy(790, bytes / 3));
    EXPECT_EQ(three, encode(h, fixed(3)));
    EXPECT_TRUE(identical(decode(three.data(), three.size()), decode(ten.data(), ten.size())));
}

}  // namespace
}  // namespace amc
