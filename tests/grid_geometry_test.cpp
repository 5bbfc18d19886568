// Geometry mode 4 (docs/FORMAT.md 5.7, .amc version 9): the normal frame's tables split by where
// the prediction falls between two grid points. Round trips at every grid size, the version it
// makes, the size it saves where the surface is flat at the grid's scale, and the errors a decoder
// reports for a mode-4 block where the format does not allow one.
#include "hierarchy_checks.h"
#include "level_block_rewrite.h"

#include "coding/container.h"
#include "coding/format_version.h"

#include <amc/codec.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace amc {
namespace {

using testing::projected_sphere;

bool uses(const EncodeStats& stats, GeometryPredictor p) {
    return std::any_of(stats.per_level.begin(), stats.per_level.end(), [p](const LevelStats& l) { return l.predictor == p; });
}

std::string decode_error(const std::vector<uint8_t>& bytes) {
    const DecodeResult r = try_decode(bytes.data(), bytes.size());
    return r.ok ? "" : r.error;
}

// The file's blocks rewritten with `version` (checksums made anew), the first level block's
// predictor byte set to `predictor`.
std::vector<uint8_t> with_first_predictor(const std::vector<uint8_t>& bytes, uint8_t version, uint8_t predictor) {
    bool first = true;
    return testing::rewritten(bytes, version, bytes[5], [&](std::vector<uint8_t>& payload) {
        if (first && !payload.empty()) {
            payload[0] = predictor;
            first = false;
        }
    });
}

TEST(GridGeometry, RoundTripsOnEveryGridAsModeThreeDoes) {
    const Hierarchy h = projected_sphere(800, 5, 3);
    for (int bits : {1, 2, 3, 4, 5, 8, 12, 16, 20, 24, 30}) {
        SCOPED_TRACE("bits " + std::to_string(bits));
        EncodeOptions mode3;
        mode3.quantize_bits = bits;
        mode3.predictor = GeometryPredictor::normal_frame;
        const std::vector<uint8_t> reference = encode(h, mode3);
        const Hierarchy expected = decode(reference.data(), reference.size());
        EncodeOptions forced = mode3;
        forced.predictor = GeometryPredictor::normal_frame_grid;
        EncodeOptions automatic;
        automatic.quantize_bits = bits;
        automatic.grid_contexts = true;
        for (const EncodeOptions& options : {forced, automatic}) {
            EncodeStats stats;
            const std::vector<uint8_t> bytes = encode(h, options, &stats);
            const Hierarchy back = decode(bytes.data(), bytes.size());
            ASSERT_TRUE(identical(back, expected)) << "the same grid points as mode 3";
            ASSERT_EQ(check_invariants(back), "");
            const bool grid = uses(stats, GeometryPredictor::normal_frame_grid);
            if (options.predictor == GeometryPredictor::normal_frame_grid) {
                EXPECT_TRUE(grid);
            }
            if (grid) {
                EXPECT_EQ(bytes[4], kGroupedGridVersion) << "mode 4 makes version 18 (the grouped order)";
            } else {
                EXPECT_LT(bytes[4], kGridGeometryVersion);
            }
            // Progressive: every prefix of levels.
            for (int l = 0; l < stats.levels; ++l) {
                DecodeOptions prefix;
                prefix.max_level = l;
                EXPECT_EQ(decode(bytes.data(), bytes.size(), prefix).depth(), std::min(l, back.depth()));
            }
        }
    }
}

TEST(GridGeometry, RandomHierarchiesRoundTripInChunksAndWithTheMixingMode) {
    for (uint64_t seed = 1; seed <= 60; ++seed) {
        SCOPED_TRACE("seed " + std::to_string(seed));
        Hierarchy h = projected_sphere(50 + uint32_t(seed * 37 % 900), 1 + int(seed % 6), seed);
        if (seed % 3 == 0) {  // some positions off the sphere: residuals of every size
            testing::Random random{seed};
            for (VertexId v = 0; v < h.positions().size(); v += 5)
                h.set_position(v, h.position(v) + Vec3{double(random.next() % 1000) * 1e-4, 0.0, -double(random.next() % 100) * 1e-3});
        }
        EncodeOptions options;
        options.quantize_bits = 4 + int(seed % 24);
        options.grid_contexts = true;
        options.predictor = seed % 2 == 0 ? GeometryPredictor::normal_frame_grid : GeometryPredictor::automatic;
        if (seed % 4 == 1) options.chunks = 3;
        if (seed % 4 == 3) options.hierarchy_contexts = HierarchyContexts::mixed;
        EncodeOptions plain = options;
        plain.grid_contexts = false;
        plain.predictor = GeometryPredictor::normal_frame;
        const std::vector<uint8_t> reference = encode(h, plain);
        const std::vector<uint8_t> bytes = encode(h, options);
        const Hierarchy back = decode(bytes.data(), bytes.size());
        ASSERT_TRUE(identical(back, decode(reference.data(), reference.size())));
    }
}

// A tilted plane refined with exact midpoints (finite-element style), then quantized: every new
// vertex rounds to the grid point nearest its edge's midpoint, or to either of two when the
// midpoint lies half-way, which the split tables code in fewer bits; and the projected sphere,
// curved at the grid's scale, where the unit-normal frame still pays.
TEST(GridGeometry, SmallerOnFlatAndCurvedSurfaces) {
    Hierarchy plane(make_square(6));
    refine_randomly(plane, 20000, 7, 4);
    for (VertexId v = 0; v < plane.positions().size(); ++v) {
        const Vec3 p = plane.position(v);
        plane.set_position(v, {0.8 * p.x + 0.6 * p.z, p.y, -0.6 * p.x + 0.8 * p.z + 0.3 * p.y});
    }
    const Hierarchy sphere = projected_sphere(20000, 7, 5);
    for (int bits : {12, 16}) {
        for (const Hierarchy* h : std::vector<const Hierarchy*>{&plane, &sphere}) {
            EncodeOptions roles;
            roles.quantize_bits = bits;
            roles.grid_contexts = false;
            EncodeOptions grid = roles;
            grid.grid_contexts = true;
            EncodeStats a, b;
            encode(*h, roles, &a);
            encode(*h, grid, &b);
            EXPECT_TRUE(uses(b, GeometryPredictor::normal_frame_grid));
            // The plane: mostly rounding noise; the sphere (vertices projected radially, not along
            // the frame's normal): a little, and never more than mode 3 (the encoder keeps the smaller).
            EXPECT_LT(double(b.geometry_bytes), (h == &plane ? 0.8 : 1.0) * double(a.geometry_bytes))
                << "bits " << bits << (h == &plane ? " plane" : " sphere");
            EXPECT_EQ(a.hierarchy_bytes, b.hierarchy_bytes);
        }
    }
}

TEST(GridGeometry, WithoutTheOptionTheBytesAreModeThrees) {
    const Hierarchy h = projected_sphere(1500, 5, 9);
    EncodeOptions options;
    options.quantize_bits = 12;
    options.grid_contexts = false;
    EncodeStats stats;
    const std::vector<uint8_t> bytes = encode(h, options, &stats);
    EXPECT_FALSE(uses(stats, GeometryPredictor::normal_frame_grid));
    EXPECT_EQ(bytes[4], kStaticGeometryVersion);
}

TEST(GridGeometry, EncoderRefusesItWithoutAGrid) {
    const Hierarchy h = projected_sphere(100, 3, 1);
    EncodeOptions options;
    options.predictor = GeometryPredictor::normal_frame_grid;
    EXPECT_THROW(encode(h, options), Error);
    // The automatic choice with the option set but no grid simply does not try it.
    EncodeOptions automatic;
    automatic.grid_contexts = true;
    EncodeStats stats;
    const std::vector<uint8_t> bytes = encode(h, automatic, &stats);
    EXPECT_FALSE(uses(stats, GeometryPredictor::normal_frame_grid));
    // 14: adaptive levels' raw side streams; 21: the base's too.
    EXPECT_TRUE(bytes[4] < kGridGeometryVersion || bytes[4] == kRawSideVersion || bytes[4] == kBaseRawSideVersion);
}

// Grid contexts are the encoder's default for quantized files (the automatic choice tries mode 4
// on every level); bit-exact files have no grid and code as with the option off.
TEST(GridGeometry, QuantizedFilesTryModeFourByDefault) {
    const Hierarchy h = projected_sphere(800, 5, 3);
    EncodeOptions defaults;
    defaults.quantize_bits = 12;
    EncodeOptions roles = defaults;
    roles.grid_contexts = false;
    EncodeStats stats, roles_stats;
    const std::vector<uint8_t> bytes = encode(h, defaults, &stats);
    const std::vector<uint8_t> roles_bytes = encode(h, roles, &roles_stats);
    EXPECT_TRUE(uses(stats, GeometryPredictor::normal_frame_grid));
    EXPECT_EQ(bytes[4], kGroupedGridVersion);
    EXPECT_FALSE(uses(roles_stats, GeometryPredictor::normal_frame_grid));
    EXPECT_LT(bytes.size(), roles_bytes.size());
    EncodeOptions exact, exact_roles;
    exact_roles.grid_contexts = false;
    EXPECT_EQ(encode(h, exact), encode(h, exact_roles));
}

TEST(GridGeometry, DecoderRefusesModeFourWhereTheFormatHasNone) {
    const Hierarchy h = projected_sphere(600, 4, 2);
    EncodeOptions options;
    options.quantize_bits = 12;
    options.predictor = GeometryPredictor::normal_frame_grid;
    const std::vector<uint8_t> bytes = encode(h, options);
    ASSERT_EQ(bytes[4], kGroupedGridVersion);
    EXPECT_EQ(decode_error(with_first_predictor(bytes, kGroupedGridVersion, 4)), "");
    // Versions 9-17 read mode 4's tokens vertex after vertex: the grouped file's bytes as version 17
    // are another hierarchy or corrupt.
    const std::vector<uint8_t> as_17 = with_first_predictor(bytes, kFifthMixingVersion, 4);
    const DecodeResult per_vertex = try_decode(as_17.data(), as_17.size());
    EXPECT_TRUE(!per_vertex.ok || !identical(per_vertex.hierarchy, decode(bytes.data(), bytes.size())));
    // A version-6 file has no predictor 4 (nor has any version before 9).
    EXPECT_NE(decode_error(with_first_predictor(bytes, kStaticGeometryVersion, 4)).find("bad predictor"), std::string::npos);
    EXPECT_EQ(decode_error(with_first_predictor(bytes, kStaticGeometryVersion, 3)).find("bad predictor"), std::string::npos);
    // Nor has a bit-exact file, whatever its version.
    EncodeOptions exact;
    exact.predictor = GeometryPredictor::normal_frame;
    const std::vector<uint8_t> bit_exact = encode(h, exact);
    EXPECT_NE(decode_error(with_first_predictor(bit_exact, kGridGeometryVersion, 4)).find("bad predictor"), std::string::npos);
    EXPECT_EQ(decode_error(with_first_predictor(bit_exact, kGridGeometryVersion, 3)), "");
    // Predictor 5 is not defined.
    EXPECT_NE(decode_error(with_first_predictor(bytes, kGridGeometryVersion, 5)).find("bad predictor"), std::string::npos);
    // A mode-3 block read as mode 4 (and the reverse) is corrupt or a valid other hierarchy, never a crash.
    const std::vector<uint8_t> as_mode_3 = with_first_predictor(bytes, kGridGeometryVersion, 3);
    const DecodeResult r = try_decode(as_mode_3.data(), as_mode_3.size());
    if (!r.ok) {
        EXPECT_FALSE(r.error.empty());
    }
    // Every truncation of a mode-4 file is an error.
    for (size_t n = 0; n < bytes.size(); n += 1 + n / 50)
        EXPECT_FALSE(try_decode(bytes.data(), n).ok) << n;
}

}  // namespace
}  // namespace amc
