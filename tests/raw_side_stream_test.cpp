// .amc version 14 (docs/FORMAT.md 3.6, 5.2): the adaptive level blocks (predictors 1, 2) of
// bit-exact files carry their coordinates' raw bits in a side stream after the arithmetic code,
// flagged by bit 7 of the predictor byte. Round trips, the version it makes and where it is not
// made, the size against the same symbols in the arithmetic code, and the errors a decoder reports
// for a flag where the format has none and for a side stream cut short or overlong. Such files are
// version 21 now (their bases' raw bits in a side stream too: base_raw_side_test.cpp).
#include "hierarchy_checks.h"
#include "level_block_rewrite.h"

#include "coding/container.h"
#include "coding/entropy/rans_coder.h"
#include "coding/format_version.h"
#include "coding/geometry/float_coder.h"

#include <amc/codec.h>
#include <amc/refinement.h>

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace amc {
namespace {

using testing::decode_error;
using testing::rewritten;
using testing::bumpy_torus;

TEST(RawSideStream, BitExactAdaptiveLevelsRoundTripAsVersion14) {
    for (bool single : {false, true}) {
        const Hierarchy h = bumpy_torus(single);
        for (GeometryPredictor p : {GeometryPredictor::midpoint, GeometryPredictor::butterfly}) {
            EncodeOptions options;
            options.predictor = p;
            const std::vector<uint8_t> bytes = encode(h, options);
            ASSERT_EQ(bytes[4], kBaseRawSideVersion);
            EXPECT_TRUE(identical(decode(bytes.data(), bytes.size()), in_decoder_order(h, options)));
            const std::vector<uint8_t> as14 = rewritten(bytes, kRawSideVersion, bytes[5], [](std::vector<uint8_t>&) {});
            EXPECT_TRUE(identical(decode(as14.data(), as14.size()), in_decoder_order(h, options)));
            // In chunks too (a version-14 file holds chunks as version 13 does).
            options.chunks = 3;
            const std::vector<uint8_t> chunked = encode(h, options);
            ASSERT_EQ(chunked[4], kBaseRawSideVersion);
            EXPECT_EQ(inspect(chunked.data(), chunked.size()).chunks.size(), 3u);
            EXPECT_TRUE(identical(decode(chunked.data(), chunked.size()), decode(bytes.data(), bytes.size())));
        }
    }
}

TEST(RawSideStream, QuantizedFilesAndStaticModesKeepTheirVersions) {
    const Hierarchy h = bumpy_torus(false);
    EncodeOptions quantized;
    quantized.quantize_bits = 16;
    quantized.predictor = GeometryPredictor::butterfly;
    EXPECT_LT(encode(h, quantized)[4], kRawSideVersion);
    EncodeOptions unit;
    unit.predictor = GeometryPredictor::unit_normal_frame;  // the last level (no vertices) stays unflagged
    const std::vector<uint8_t> bytes = encode(h, unit);
    EXPECT_EQ(bytes[4], kBaseRawSideVersion);  // for the base's raw bits; version 12 before them
    BlockReader reader(bytes.data(), bytes.size());
    Block block;
    while (reader.next(block)) {
        if (block.type == BlockType::level) {
            EXPECT_EQ(block.payload[0] & 0x80, 0);
        }
    }
}

// The same symbols as the arithmetic coder's raw bits: the side stream costs its varint and
// padding per level, and position_raw_bits is still the bound of the level's code.
TEST(RawSideStream, SameCodeLengthAsRawBitsInTheArithmeticCode) {
    const Precision precision = Precision::float64;
    FloatResidualModels inline_models(3), side_models(3);
    ArithmeticEncoder inline_encoder, side_encoder;
    RawBitWriter raw;
    uint64_t raw_bits = 0;
    std::vector<Vec3> actual, predicted;
    for (int i = 0; i < 2000; ++i) {
        const double t = 0.001 * i;
        actual.push_back({std::sin(t) + 1e-9 * i, std::cos(3 * t), t * t});
        predicted.push_back({std::sin(t), std::cos(3 * t) + 1e-7, t * t * (1 + 1e-12)});
        encode_position(inline_encoder, inline_models, 0, precision, actual.back(), predicted.back());
        encode_position(side_encoder, side_models, 0, precision, actual.back(), predicted.back(), &raw);
        raw_bits += position_raw_bits(precision, actual.back(), predicted.back());
    }
    ASSERT_GT(raw_bits, 50000u);
    EXPECT_EQ(raw.bits(), raw_bits);
    const std::vector<uint8_t> inline_code = inline_encoder.finish(), side_code = side_encoder.finish();
    const std::vector<uint8_t> side_bits = raw.finish();
    EXPECT_NEAR(double(side_code.size() + side_bits.size()), double(inline_code.size()), 8.0);
    ArithmeticDecoder decoder(side_code.data(), side_code.size());
    RawBitReader reader(side_bits.data(), side_bits.size());
    FloatResidualModels models(3);
    for (size_t i = 0; i < actual.size(); ++i) {
        const Vec3 p = decode_position(decoder, models, 0, precision, predicted[i], &reader);
        ASSERT_EQ(p.x, actual[i].x);
        ASSERT_EQ(p.y, actual[i].y);
        ASSERT_EQ(p.z, actual[i].z);
    }
    EXPECT_TRUE(reader.ended_cleanly());
    EXPECT_FALSE(decoder.overran());
}

TEST(RawSideStream, DecoderRefusesTheFlagWhereTheFormatHasNoneAndBadSideStreams) {
    const Hierarchy h = bumpy_torus(false);
    EncodeOptions butterfly;
    butterfly.predictor = GeometryPredictor::butterfly;
    const std::vector<uint8_t> bytes = encode(h, butterfly);
    ASSERT_EQ(bytes[4], kBaseRawSideVersion);
    const uint8_t flags = bytes[5];
    auto same = [](std::vector<uint8_t>&) {};
    EXPECT_EQ(decode_error(rewritten(bytes, kRawSideVersion, flags, same)), "");
    EXPECT_EQ(decode_error(rewritten(bytes, kBaseRawSideVersion, flags, same)), "");
    // Version 13 and older have no flag.
    EXPECT_NE(decode_error(rewritten(bytes, kChunkVerticesVersion, flags, same)).find("bad predictor"), std::string::npos);
    // Not on a static mode's predictor, nor in a quantized file.
    auto on_every_level = [](uint8_t byte) {
        return [byte](std::vector<uint8_t>& p) {
            if (!p.empty()) p[0] = byte;
        };
    };
    EXPECT_NE(decode_error(rewritten(bytes, kRawSideVersion, flags, on_every_level(0x85))).find("bad predictor"), std::string::npos);
    EncodeOptions quantized = butterfly;
    quantized.quantize_bits = 12;
    const std::vector<uint8_t> q = encode(h, quantized);
    EXPECT_NE(decode_error(rewritten(q, kRawSideVersion, q[5], on_every_level(0x82))).find("bad predictor"), std::string::npos);
    // Side streams one byte short, or one byte too long, are errors.
    auto flagged_levels = [](bool shorter) {
        return [shorter](std::vector<uint8_t>& p) {
            if (p.size() < 64 || (p[0] & 0x80) == 0) return;
            if (shorter) p.pop_back();
            else p.push_back(0);
        };
    };
    EXPECT_NE(decode_error(rewritten(bytes, kRawSideVersion, flags, flagged_levels(true))), "");
    EXPECT_NE(decode_error(rewritten(bytes, kRawSideVersion, flags, flagged_levels(false))), "");
    // Every truncation of the file is an error.
    for (size_t n = 0; n < bytes.size(); n += 1 + n / 50) EXPECT_FALSE(try_decode(bytes.data(), n).ok) << n;
}

}  // namespace
}  // namespace amc
