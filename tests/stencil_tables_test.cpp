// .amc version 15 (docs/FORMAT.md 5.9): geometry modes 6 and 7, the midpoint's and the butterfly's
// predictions with static tables per axis, rANS and raw bits, in bit-exact files. Round trips
// (float64 and float32, level blocks and chunks), the version they make, the automatic choice on
// coordinates that use all their bits, and the errors a decoder reports for the modes where the
// format has none and for streams cut short.
#include "hierarchy_checks.h"
#include "level_block_rewrite.h"

#include "coding/container.h"
#include "coding/format_version.h"
#include "common/little_endian.h"

#include <amc/codec.h>
#include <amc/refinement.h>

#include <cfloat>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace amc {
namespace {

using testing::decode_error;
using testing::rewritten;
using testing::bumpy_torus;

bool uses(const EncodeStats& stats, GeometryPredictor p) {
    for (const LevelStats& l : stats.per_level)
        if (l.predictor == p) return true;
    return false;
}

TEST(StencilTables, ForcedModesRoundTripAsVersion15) {
    for (bool single : {false, true}) {
        const Hierarchy h = bumpy_torus(single);
        for (GeometryPredictor p : {GeometryPredictor::midpoint_static, GeometryPredictor::butterfly_static}) {
            SCOPED_TRACE(std::string(single ? "float32 " : "float64 ") + std::to_string(int(p)));
            EncodeOptions options;
            options.predictor = p;
            EncodeStats stats;
            const std::vector<uint8_t> bytes = encode(h, options, &stats);
            ASSERT_EQ(bytes[4], kBaseRawSideVersion);  // 15 with the base's raw bits in a side stream
            EXPECT_TRUE(uses(stats, p));
            const Hierarchy back = decode(bytes.data(), bytes.size());
            EXPECT_TRUE(identical(back, in_decoder_order(h, options)));
            // Every prefix of levels (progressive decoding).
            for (int l = 0; l < h.depth(); ++l) {
                DecodeOptions prefix;
                prefix.max_level = l;
                EXPECT_EQ(decode(bytes.data(), bytes.size(), prefix).depth(), l);
            }
            // In chunks too (a version-15 file holds chunks as version 13 does), on 1 and 2 threads.
            options.chunks = 3;
            const std::vector<uint8_t> chunked = encode(h, options);
            ASSERT_EQ(chunked[4], kBaseRawSideVersion);
            EXPECT_EQ(inspect(chunked.data(), chunked.size()).chunks.size(), 3u);
            for (unsigned threads : {1u, 2u}) {
                DecodeOptions on;
                on.threads = threads;
                EXPECT_TRUE(identical(decode(chunked.data(), chunked.size(), on), back));
            }
        }
    }
}

// Coordinates of any exponent and sign, some past DBL_MAX / 2 (Hierarchy::is_far), on levels of
// thousands of vertices: residuals whose raw bits take two reads (bit length above 59), every
// branch of the float64 level decoder (streams read with and without bounds tests, missing
// butterfly wings), and the decoded hierarchy's far flag.
TEST(StencilTables, WildFloat64CoordinatesRoundTrip) {
    Hierarchy h = bumpy_torus(false, 6000, 6);
    testing::Random random{29};
    auto any_bits = [&random] { return random.next() << 33 ^ random.next() << 2 ^ random.next(); };  // next() has 31 bits
    for (VertexId v = 0; v < h.positions().size(); ++v) {
        if (v % 3 != 0) continue;
        double xyz[3];
        for (double& c : xyz) {
            do c = bit_cast<double>(any_bits()); while (!std::isfinite(c));
        }
        if (v % 7 == 0) xyz[1] = 0.9 * DBL_MAX;
        h.set_position(v, {xyz[0], xyz[1], xyz[2]});
    }
    for (GeometryPredictor p : {GeometryPredictor::midpoint_static, GeometryPredictor::butterfly_static}) {
        SCOPED_TRACE(int(p));
        EncodeOptions options;
        options.predictor = p;
        EncodeStats stats;
        const std::vector<uint8_t> bytes = encode(h, options, &stats);
        ASSERT_TRUE(uses(stats, p));
        EXPECT_TRUE(identical(decode(bytes.data(), bytes.size()), in_decoder_order(h, options)));
    }
}

// Coordinates that use all their bits: the automatic choice takes a static stencil mode on the
// large levels, at most 1 % above the adaptive predictors' bytes.
TEST(StencilTables, AutomaticChoiceTakesThemWhereSmallest) {
    const Hierarchy h = bumpy_torus(false, 6000, 5);
    EncodeStats stats;
    const std::vector<uint8_t> bytes = encode(h, {}, &stats);
    ASSERT_EQ(bytes[4], kBaseRawSideVersion);  // 15 with the base's raw bits in a side stream
    EXPECT_TRUE(uses(stats, GeometryPredictor::midpoint_static) || uses(stats, GeometryPredictor::butterfly_static));
    EXPECT_TRUE(identical(decode(bytes.data(), bytes.size()), in_decoder_order(h, {})));
    for (GeometryPredictor p : {GeometryPredictor::midpoint, GeometryPredictor::butterfly}) {
        EncodeOptions adaptive;
        adaptive.predictor = p;
        // Each level at most 1 % above its smallest adaptive code (kStencilPreference).
        EXPECT_LE(double(bytes.size()), 1.01 * double(encode(h, adaptive).size()));
    }
}

// Where every new vertex is its edge's midpoint (the L-shaped FE model), the normal frame, the unit
// frame and the static midpoint code the same zero tokens in a level's static bytes: the automatic
// choice keeps the first of them, mode 3, on the levels a static mode wins (level_geometry.cpp
// codes no static mode that could at best tie with an earlier one).
TEST(StencilTables, ExactMidpointsKeepTheFirstOfTheTyingStaticModes) {
    const Hierarchy h = make_l_shape_model(6);
    EncodeStats chosen;
    encode(h, {}, &chosen);
    std::vector<EncodeStats> forced(3);
    const GeometryPredictor tying[3] = {GeometryPredictor::normal_frame, GeometryPredictor::unit_normal_frame,
                                        GeometryPredictor::midpoint_static};
    for (int m = 0; m < 3; ++m) {
        EncodeOptions options;
        options.predictor = tying[m];
        encode(h, options, &forced[size_t(m)]);
    }
    int static_levels = 0;
    for (size_t l = 0; l < chosen.per_level.size(); ++l) {
        if (chosen.per_level[l].new_vertices == 0) continue;
        EXPECT_EQ(forced[1].per_level[l].bytes, forced[0].per_level[l].bytes) << "level " << l;
        EXPECT_EQ(forced[2].per_level[l].bytes, forced[0].per_level[l].bytes) << "level " << l;
        if (chosen.per_level[l].predictor == GeometryPredictor::midpoint ||
            chosen.per_level[l].predictor == GeometryPredictor::butterfly)
            continue;
        ++static_levels;
        EXPECT_EQ(chosen.per_level[l].predictor, GeometryPredictor::normal_frame) << "level " << l;
        EXPECT_EQ(chosen.per_level[l].bytes, forced[0].per_level[l].bytes) << "level " << l;
    }
    EXPECT_GT(static_levels, 0);
}

TEST(StencilTables, QuantizedFilesRefuseThem) {
    const Hierarchy h = bumpy_torus(false);
    EncodeOptions quantized;
    quantized.quantize_bits = 16;
    EXPECT_LT(encode(h, quantized)[4], kStencilTablesVersion);  // not candidates there
    quantized.predictor = GeometryPredictor::butterfly_static;
    EXPECT_THROW(encode(h, quantized), Error);
}

TEST(StencilTables, DecoderRefusesThemWhereTheFormatHasNoneAndCutStreams) {
    const Hierarchy h = bumpy_torus(false);
    EncodeOptions options;
    options.predictor = GeometryPredictor::butterfly_static;
    const std::vector<uint8_t> bytes = encode(h, options);
    ASSERT_EQ(bytes[4], kBaseRawSideVersion);  // 15 with the base's raw bits in a side stream (rewritten() makes it 15)
    auto same = [](std::vector<uint8_t>&) {};
    EXPECT_EQ(decode_error(rewritten(bytes, kStencilTablesVersion, bytes[5], same)), "");
    // Version 14 and older have no predictors 6 and 7, nor a side-stream flag on them.
    EXPECT_NE(decode_error(rewritten(bytes, kRawSideVersion, bytes[5], same)).find("bad predictor"), std::string::npos);
    EXPECT_NE(decode_error(rewritten(bytes, kStencilTablesVersion, bytes[5], [](std::vector<uint8_t>& p) { p[0] |= 0x80; }))
                  .find("bad predictor"),
              std::string::npos);
    // Mode 6's stream read as mode 7's decodes other positions or fails, never crashes.
    (void)decode_error(rewritten(bytes, kStencilTablesVersion, bytes[5], [](std::vector<uint8_t>& p) { p[0] = 6; }));
    // In a quantized file they are errors.
    EncodeOptions quantized;
    quantized.quantize_bits = 12;
    quantized.predictor = GeometryPredictor::normal_frame;
    const std::vector<uint8_t> q = encode(h, quantized);
    EXPECT_NE(decode_error(rewritten(q, kStencilTablesVersion, q[5], [](std::vector<uint8_t>& p) { p[0] = 7; })).find("bad predictor"),
              std::string::npos);
    // Raw bits one byte short, or one byte too long, are errors.
    auto cut = [](bool shorter) {
        return [shorter](std::vector<uint8_t>& p) {
            if (p.size() < 64) return;
            if (shorter) p.pop_back();
            else p.push_back(0);
        };
    };
    EXPECT_NE(decode_error(rewritten(bytes, kStencilTablesVersion, bytes[5], cut(true))), "");
    EXPECT_NE(decode_error(rewritten(bytes, kStencilTablesVersion, bytes[5], cut(false))), "");
    // Every truncation of the file is an error.
    for (size_t n = 0; n < bytes.size(); n += 1 + n / 50) EXPECT_FALSE(try_decode(bytes.data(), n).ok) << n;
}

}  // namespace
}  // namespace amc
