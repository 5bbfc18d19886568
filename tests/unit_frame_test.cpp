// Geometry mode 5 (docs/FORMAT.md 5.8, .amc version 12): mode 3 with the frame of summed unit
// normals. Bit-exact round trips in both precisions and on a grid, the size it saves on a surface
// remesh (whose new vertices lie on that frame's line), the version it makes, the option that keeps
// version 11's choices, and the errors a decoder reports for a mode-5 block where the format has none.
#include "hierarchy_checks.h"
#include "level_block_rewrite.h"

#include "coding/container.h"
#include "coding/format_version.h"

#include <amc/codec.h>
#include <amc/refinement.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace amc {
namespace {

bool uses(const EncodeStats& stats, GeometryPredictor p) {
    return std::any_of(stats.per_level.begin(), stats.per_level.end(), [p](const LevelStats& l) { return l.predictor == p; });
}

std::string decode_error(const std::vector<uint8_t>& bytes) {
    const DecodeResult r = try_decode(bytes.data(), bytes.size());
    return r.ok ? "" : r.error;
}

// The file's blocks rewritten with `version` (checksums made anew), every level block's predictor
// byte that is `from` set to `to`.
std::vector<uint8_t> with_predictors(const std::vector<uint8_t>& bytes, uint8_t version, uint8_t from, uint8_t to) {
    return testing::rewritten(bytes, version, bytes[5], [&](std::vector<uint8_t>& payload) {
        if (!payload.empty() && payload[0] == from) payload[0] = to;
    });
}

// A small adaptive remesh of the bumpy sphere (new vertices placed along the summed unit normals).
Hierarchy remesh(SurfacePrecision precision) {
    SurfaceRemeshOptions options;
    options.base_triangles = 100;
    options.max_level = 4;
    options.target_faces = 4000;
    options.precision = precision;
    return remesh_adaptively(make_bumpy_sphere(3), options);
}

TEST(UnitFrameGeometry, RoundTripsBitExactInBothPrecisionsAndOnAGrid) {
    for (SurfacePrecision precision : {SurfacePrecision::float64, SurfacePrecision::float32}) {
        const Hierarchy h = remesh(precision);
        ASSERT_EQ(h.single_precision(), precision == SurfacePrecision::float32);
        EncodeOptions forced;
        forced.predictor = GeometryPredictor::unit_normal_frame;
        EncodeStats stats;
        const std::vector<uint8_t> bytes = encode(h, forced, &stats);
        EXPECT_EQ(bytes[4], kBaseRawSideVersion);  // 12 with the base's raw bits in a side stream
        EXPECT_TRUE(uses(stats, GeometryPredictor::unit_normal_frame));
        EXPECT_TRUE(identical(decode(bytes.data(), bytes.size()), in_decoder_order(h, forced)));
    }
    // On a grid mode 5 decodes to what mode 3 decodes to (the same snapped positions).
    const Hierarchy h = remesh(SurfacePrecision::float64);
    for (int bits : {1, 3, 12, 30}) {
        EncodeOptions mode3;
        mode3.quantize_bits = bits;
        mode3.predictor = GeometryPredictor::normal_frame;
        EncodeOptions mode5 = mode3;
        mode5.predictor = GeometryPredictor::unit_normal_frame;
        const std::vector<uint8_t> a = encode(h, mode3), b = encode(h, mode5);
        EXPECT_EQ(b[4], kUnitFrameVersion);
        EXPECT_TRUE(identical(decode(a.data(), a.size()), decode(b.data(), b.size()))) << bits << " bits";
    }
}

// The remesher's new vertices lie on the line of the unit-normal frame: the two roles after the
// first cost a few bits instead of most of the mantissa.
TEST(UnitFrameGeometry, BitExactRemeshesCodeFarSmallerThanInModeThree) {
    for (SurfacePrecision precision : {SurfacePrecision::float64, SurfacePrecision::float32}) {
        const Hierarchy h = remesh(precision);
        EncodeOptions mode3;
        mode3.predictor = GeometryPredictor::normal_frame;
        EncodeOptions mode5 = mode3;
        mode5.predictor = GeometryPredictor::unit_normal_frame;
        EncodeStats a, b;
        encode(h, mode3, &a);
        encode(h, mode5, &b);
        EXPECT_LT(double(b.geometry_bytes), (precision == SurfacePrecision::float64 ? 0.7 : 0.85) * double(a.geometry_bytes))
            << (precision == SurfacePrecision::float64 ? "float64" : "float32");
        EXPECT_EQ(a.hierarchy_bytes, b.hierarchy_bytes);
    }
}

// The automatic encoder tries mode 5 on every level of a bit-exact file (version 12 where it wins);
// unit_normals = false gives version 11's encoder's choices, and quantized files never try it.
TEST(UnitFrameGeometry, AutomaticChoiceAndTheOptionThatKeepsTheOldChoices) {
    const Hierarchy h = remesh(SurfacePrecision::float64);
    EncodeOptions defaults, old;
    old.unit_normals = false;
    EncodeStats stats, old_stats;
    const std::vector<uint8_t> bytes = encode(h, defaults, &stats);
    const std::vector<uint8_t> old_bytes = encode(h, old, &old_stats);
    EXPECT_TRUE(uses(stats, GeometryPredictor::unit_normal_frame));
    EXPECT_EQ(bytes[4], kBaseRawSideVersion);  // 12 with the base's raw bits in a side stream
    EXPECT_FALSE(uses(old_stats, GeometryPredictor::unit_normal_frame));
    EXPECT_EQ(old_bytes[4], kBaseRawSideVersion);  // before version 21: below 12
    EXPECT_LT(bytes.size(), old_bytes.size());
    EXPECT_TRUE(identical(decode(bytes.data(), bytes.size()), decode(old_bytes.data(), old_bytes.size())));
    EncodeOptions quantized;
    quantized.quantize_bits = 12;
    EncodeStats q;
    const uint8_t quantized_version = encode(h, quantized, &q)[4];
    EXPECT_TRUE(quantized_version < kUnitFrameVersion || quantized_version == kGroupedGridVersion)  // 18: mode 4's levels
        << int(quantized_version);
    EXPECT_FALSE(uses(q, GeometryPredictor::unit_normal_frame));
    // Chunked files carry it too (version 13: chunks, whatever their geometry modes; 21 with the
    // base's and the seam's raw bits in side streams).
    EncodeOptions chunked;
    chunked.chunks = 3;
    EncodeStats c;
    const std::vector<uint8_t> chunked_bytes = encode(h, chunked, &c);
    EXPECT_EQ(chunked_bytes[4], kBaseRawSideVersion);
    EXPECT_EQ(inspect(chunked_bytes.data(), chunked_bytes.size()).chunks.size(), 3u);
    EXPECT_TRUE(identical(decode(chunked_bytes.data(), chunked_bytes.size()), decode(bytes.data(), bytes.size())));
}

TEST(UnitFrameGeometry, DecoderRefusesModeFiveWhereTheFormatHasNone) {
    const Hierarchy h = remesh(SurfacePrecision::float64);
    EncodeOptions forced;
    forced.predictor = GeometryPredictor::unit_normal_frame;
    const std::vector<uint8_t> bytes = encode(h, forced);
    ASSERT_EQ(bytes[4], kBaseRawSideVersion);  // with_predictors() rewrites it as older versions
    EXPECT_EQ(decode_error(with_predictors(bytes, kUnitFrameVersion, 5, 5)), "");
    // Version 11 and older have no predictor 5.
    EXPECT_NE(decode_error(with_predictors(bytes, kThirdMixingVersion, 5, 5)).find("bad predictor"), std::string::npos);
    EXPECT_NE(decode_error(with_predictors(bytes, kStaticGeometryVersion, 5, 5)).find("bad predictor"), std::string::npos);
    // Predictor 6 is not defined, and version 12 has no predictor 4 in a bit-exact file.
    EXPECT_NE(decode_error(with_predictors(bytes, kUnitFrameVersion, 5, 6)).find("bad predictor"), std::string::npos);
    EXPECT_NE(decode_error(with_predictors(bytes, kUnitFrameVersion, 5, 4)).find("bad predictor"), std::string::npos);
    // Mode-5 blocks read as mode 3: an error or another hierarchy, never a crash; not this one.
    const std::vector<uint8_t> as_mode_3 = with_predictors(bytes, kUnitFrameVersion, 5, 3);
    const DecodeResult r = try_decode(as_mode_3.data(), as_mode_3.size());
    if (r.ok) EXPECT_FALSE(identical(r.hierarchy, decode(bytes.data(), bytes.size())));
    else EXPECT_FALSE(r.error.empty());
    // Every truncation of a mode-5 file is an error.
    for (size_t n = 0; n < bytes.size(); n += 1 + n / 50) EXPECT_FALSE(try_decode(bytes.data(), n).ok) << n;
}

}  // namespace
}  // namespace amc
