// .amc version 21 (docs/FORMAT.md 3.5, 3.13): bit-exact files carry the raw bits of their base
// positions and of their seam vertices in a side stream after the arithmetic code of the base
// geometry block and of the seam block. Round trips (whole, chunked, mixed), the layout against the
// format's text, the size against the same symbols in the arithmetic code, where the version is not
// written, and the errors a decoder reports for side streams cut short or overlong.
#include "hierarchy_checks.h"
#include "level_block_rewrite.h"

#include "coding/base/base_mesh_coder.h"
#include "coding/container.h"
#include "coding/format_version.h"
#include "coding/geometry/float_coder.h"
#include "coding/geometry/geometry_prediction.h"

#include <amc/codec.h>

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace amc {
namespace {

using testing::bumpy_torus;
using testing::decode_error;
using testing::projected_sphere;
using testing::rewritten;

// The file with the payload of its first block of `type` passed through `edit` (checksums anew),
// under `version` (0: its own) with its blocks as they are.
std::vector<uint8_t> with_block_edited(const std::vector<uint8_t>& bytes, BlockType type,
                                       const std::function<void(std::vector<uint8_t>&)>& edit, uint8_t version = 0) {
    BlockReader reader(bytes.data(), bytes.size());
    BlockWriter writer(version != 0 ? version : reader.version(), reader.flags());
    Block block;
    bool done = false;
    while (reader.next(block)) {
        if (block.type == BlockType::end) break;
        std::vector<uint8_t> payload(block.payload, block.payload + block.size);
        if (block.type == type && !done) {
            edit(payload);
            done = true;
        }
        writer.add(block.type, payload);
    }
    return writer.finish();
}

std::vector<uint8_t> block_of(const std::vector<uint8_t>& bytes, BlockType type) {
    BlockReader reader(bytes.data(), bytes.size());
    Block block;
    while (reader.next(block))
        if (block.type == type) return std::vector<uint8_t>(block.payload, block.payload + block.size);
    return {};
}

TEST(BaseRawSide, BitExactFilesRoundTripAsVersion21) {
    for (bool single : {false, true}) {
        SCOPED_TRACE(single ? "float32" : "float64");
        const Hierarchy h = bumpy_torus(single);
        const std::vector<uint8_t> bytes = encode(h);
        ASSERT_EQ(bytes[4], kBaseRawSideVersion);
        const Hierarchy back = decode(bytes.data(), bytes.size());
        EXPECT_TRUE(identical(back, in_decoder_order(h, {})));
        DecodeOptions base_only;
        base_only.max_level = 0;
        EXPECT_EQ(decode(bytes.data(), bytes.size(), base_only).node_count(), h.root_count());
        // The same file with the base's raw bits in the arithmetic code, as version 20: the same
        // hierarchy, a few bytes apart (the varint and the padding, against the range coder's end).
        const std::vector<uint8_t> as20 = rewritten(bytes, kSeventhMixingVersion, bytes[5], [](std::vector<uint8_t>&) {});
        EXPECT_TRUE(identical(decode(as20.data(), as20.size()), back));
        const size_t side = block_of(bytes, BlockType::base_geometry).size(), inline_code = block_of(as20, BlockType::base_geometry).size();
        EXPECT_LE(side, inline_code + 4);
        EXPECT_GE(side + 4, inline_code);
    }
}

// FORMAT.md 3.5 read literally: varint A, A bytes of arithmetic code, then exactly the raw bits of
// every base coordinate's residual (5.2: k - 3 of them when k >= 4), padded to a byte.
TEST(BaseRawSide, BaseBlockFollowsTheFormatText) {
    const Hierarchy h = bumpy_torus(false);
    const std::vector<uint8_t> bytes = encode(h);
    ASSERT_EQ(bytes[4], kBaseRawSideVersion);
    const std::vector<uint8_t> block = block_of(bytes, BlockType::base_geometry);
    size_t pos = 0;
    uint64_t arithmetic = 0;
    ASSERT_EQ(read_varint(block.data(), block.size(), pos, arithmetic), VarintRead::ok);
    ASSERT_LE(pos + arithmetic, block.size());
    DecodeOptions base_only;
    base_only.max_level = 0;
    const Hierarchy base = decode(bytes.data(), bytes.size(), base_only);
    const std::vector<uint8_t> connectivity = block_of(bytes, BlockType::base_connectivity);
    uint64_t raw_bits = 0;
    decode_base_mesh(
        connectivity.data(), connectivity.size(), uint32_t(base.base().positions.size()),
        [&](uint32_t i, const BaseStencil& stencil, const std::vector<Vec3>& previous) {
            raw_bits += position_raw_bits(Precision::float64, base.position(i), predict_parallelogram(previous, stencil));
            return base.position(i);
        },
        0);
    EXPECT_GT(raw_bits, 1000u);
    EXPECT_EQ(block.size() - pos - arithmetic, (raw_bits + 7) / 8);
}

// Chunked: the seam block has the layout too, and the file decodes as the unchunked one does, on
// one thread and two.
TEST(BaseRawSide, ChunkedFilesCarryTheSeamsRawBitsApart) {
    for (bool single : {false, true}) {
        SCOPED_TRACE(single ? "float32" : "float64");
        const Hierarchy h = bumpy_torus(single);
        EncodeOptions chunked;
        chunked.chunks = 3;
        const std::vector<uint8_t> bytes = encode(h, chunked);
        ASSERT_EQ(bytes[4], kBaseRawSideVersion);
        ASSERT_EQ(inspect(bytes.data(), bytes.size()).chunks.size(), 3u);
        const std::vector<uint8_t> whole = encode(h);
        for (unsigned threads : {1u, 2u}) {
            DecodeOptions on;
            on.threads = threads;
            EXPECT_TRUE(identical(decode(bytes.data(), bytes.size(), on), decode(whole.data(), whole.size())));
        }
        // The seam's raw bits one byte short, or one byte too long: errors.
        auto shorter = [](std::vector<uint8_t>& p) { p.pop_back(); };
        auto longer = [](std::vector<uint8_t>& p) { p.push_back(0); };
        EXPECT_NE(decode_error(with_block_edited(bytes, BlockType::seam, shorter)), "");
        EXPECT_NE(decode_error(with_block_edited(bytes, BlockType::seam, longer)), "");
    }
}

// Quantized files keep their versions and bytes (their base residuals' few raw bits stay in the
// arithmetic code); a quantized file marked version 21 is refused.
TEST(BaseRawSide, QuantizedFilesKeepTheirVersions) {
    const Hierarchy h = projected_sphere(800, 4, 5);
    for (int bits : {12, 16}) {
        EncodeOptions quantized;
        quantized.quantize_bits = bits;
        const std::vector<uint8_t> bytes = encode(h, quantized);
        EXPECT_LT(bytes[4], kBaseRawSideVersion);
        EXPECT_EQ(decode_error(bytes), "");
        EXPECT_NE(decode_error(rewritten(bytes, kBaseRawSideVersion, bytes[5], [](std::vector<uint8_t>&) {})).find("bit-exact only"),
                  std::string::npos);
    }
}

// The mixing mode writes version 21 with its seventh model; an older model that codes the file
// smaller keeps its version and the base's raw bits in the arithmetic code.
TEST(BaseRawSide, MixedFilesTakeItWithTheSeventhModelOnly) {
    const Hierarchy h = projected_sphere(1200, 4, 7);
    EncodeOptions mixed;
    mixed.hierarchy_contexts = HierarchyContexts::mixed;
    const std::vector<uint8_t> bytes = encode(h, mixed);
    EXPECT_TRUE(bytes[4] == kBaseRawSideVersion || bytes[4] < kSeventhMixingVersion);
    EXPECT_TRUE(identical(decode(bytes.data(), bytes.size()), in_decoder_order(h, mixed)));
    if (bytes[4] == kBaseRawSideVersion) {
        const std::vector<uint8_t> as20 = rewritten(bytes, kSeventhMixingVersion, bytes[5], [](std::vector<uint8_t>&) {});
        EXPECT_TRUE(identical(decode(as20.data(), as20.size()), decode(bytes.data(), bytes.size())));
    }
}

TEST(BaseRawSide, DecoderRefusesBadSideStreams) {
    const Hierarchy h = bumpy_torus(false);
    const std::vector<uint8_t> bytes = encode(h);
    ASSERT_EQ(bytes[4], kBaseRawSideVersion);
    // The raw bits one byte short, or one byte too long.
    auto shorter = [](std::vector<uint8_t>& p) { p.pop_back(); };
    auto longer = [](std::vector<uint8_t>& p) { p.push_back(0); };
    EXPECT_NE(decode_error(with_block_edited(bytes, BlockType::base_geometry, shorter)).find("raw bits"), std::string::npos);
    EXPECT_NE(decode_error(with_block_edited(bytes, BlockType::base_geometry, longer)).find("raw bits"), std::string::npos);
    // An arithmetic part longer than the block.
    auto overlong = [](std::vector<uint8_t>& p) {
        size_t pos = 0;
        uint64_t a = 0;
        read_varint(p.data(), p.size(), pos, a);
        std::vector<uint8_t> out;
        put_varint(out, p.size());
        out.insert(out.end(), p.begin() + std::ptrdiff_t(pos), p.end());
        p = out;
    };
    EXPECT_NE(decode_error(with_block_edited(bytes, BlockType::base_geometry, overlong)).find("longer than the block"),
              std::string::npos);
    // Read as version 20 (raw bits expected in the arithmetic code), the bytes are corrupt or
    // another base, never a crash; and every truncation of the file is an error.
    (void)decode_error(with_block_edited(bytes, BlockType::base_geometry, [](std::vector<uint8_t>&) {}, kSeventhMixingVersion));
    for (size_t n = 0; n < bytes.size(); n += 1 + n / 40) EXPECT_FALSE(try_decode(bytes.data(), n).ok) << n;
}

}  // namespace
}  // namespace amc
