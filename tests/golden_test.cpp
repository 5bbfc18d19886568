// Golden .amc files, one directory per format version (tests/data/golden/vN/), kept forever and
// never regenerated (docs/FORMAT.md, "Versions and compatibility"). Every file of every version
// decodes to the hierarchy it was made from; the files of the current version also pin the
// encoder's bytes. A change that alters the bitstream fails here: it is a new format version, whose
// files AMC_UPDATE_GOLDEN=1 ./amc_tests --gtest_filter='Golden*' writes into a new directory (it
// never overwrites a file).
#include "hierarchy_checks.h"
#include "sha256.h"

#include "coding/base/base_mesh_coder.h"
#include "coding/geometry/float_coder.h"
#include "coding/format_version.h"

#include <amc/codec.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <sstream>

namespace amc {
namespace {

struct GoldenCase {
    std::string name;
    Hierarchy hierarchy;
    EncodeOptions options;
};

// The hierarchies of the golden files: the same in every version.
std::vector<GoldenCase> golden_cases() {
    std::vector<GoldenCase> cases;
    {
        Hierarchy h(make_icosahedron());
        refine_uniformly(h, 2);
        cases.push_back({"icosahedron_uniform2", h, {}});
    }
    {
        Hierarchy h(make_l_shape(2));
        refine_to_size(h, [](Vec3 x) { return 0.2 * std::sqrt(x.x * x.x + x.y * x.y) + 0.01; }, 6);
        cases.push_back({"lshape_graded", h, {}});
    }
    {
        Hierarchy h(make_bumpy_sphere(0));  // float32 coordinates
        refine_randomly(h, 400, 4, 11);
        int k = 0;
        for (NodeId n : h.leaves()) {
            if (h.hanging_node_count(n) == 2 && (k++ % 3) == 0) h.set_diagonal_flipped(n, true);
        }
        cases.push_back({"bumpy_random_float32", h, {}});
        EncodeOptions quantized;
        quantized.quantize_bits = 12;
        quantized.grid_contexts = false;  // these versions' encoder: geometry mode 4 is not a candidate
        cases.push_back({"bumpy_random_q12", h, quantized});
    }
    {
        Hierarchy h(make_torus(6, 5, 2.0, 0.7));
        refine_randomly(h, 300, 3, 5);
        EncodeOptions naive;
        naive.hierarchy.traversal = Traversal::naive;
        naive.hierarchy.use_contexts = false;
        naive.predictor = GeometryPredictor::butterfly;
        cases.push_back({"torus_naive_butterfly", h, naive});
    }
    return cases;
}

std::string golden_path(int version, const std::string& name) {
    return std::string(AMC_TEST_DATA_DIR) + "/golden/v" + std::to_string(version) + "/" + name + ".amc";
}

std::vector<uint8_t> read_golden(const std::string& path) {
    std::ifstream file(path, std::ios::binary);
    return std::vector<uint8_t>((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
}

// What decoding an encoding of `h` in format `version` gives: h over the base in the base coder's
// order (connectivity mode 0 up to version 3, mode 2 from version 4, whose order depends on the base
// positions the decoder sees), with every position snapped to the quantizer's grid (FORMAT.md 5.4:
// the bounding box of all positions) when quantized. Mode 0's files may keep the roots' rotations
// or not (FORMAT.md 3.9): both candidates.
std::vector<Hierarchy> expected_decodings(const Hierarchy& h, const EncodeOptions& options, int version) {
    std::vector<Hierarchy> candidates;
    if (version >= kSearchedBaseVersion) {
        candidates.push_back(in_decoder_order(h, options));
    } else if (version == kAngleBaseVersion) {
        // Version 4's encoder: mode 2 without the search, over the base the decoder sees.
        TriangleMesh base = h.base();
        if (options.quantize_bits != 0) {
            std::vector<Vec3> points;
            const std::vector<uint32_t> order = canonical_vertex_order(h);
            for (VertexId v = 0; v < order.size(); ++v)
                if (order[v] != kNoVertex) points.push_back(h.position(v));
            const Quantizer quantizer = make_quantizer(points, options.quantize_bits);
            for (Vec3& p : base.positions) p = dequantize(quantizer, snap_to_grid(quantizer, p));
        }
        const BaseMeshCode mode2 = encode_base_connectivity(base, BaseConnectivityMode::angle, false);
        candidates.push_back(reorder_base(h, mode2.vertex_order, mode2.triangle_order, mode2.triangle_rotation));
        candidates.push_back(reorder_base(h, mode2.vertex_order, mode2.triangle_order,
                                          std::vector<uint8_t>(mode2.triangle_order.size(), 0)));
    } else {
        const BaseMeshCode mode0 = encode_base_connectivity(h.base(), BaseConnectivityMode::cut_border);
        candidates.push_back(reorder_base(h, mode0.vertex_order, mode0.triangle_order, mode0.triangle_rotation));
        candidates.push_back(reorder_base(h, mode0.vertex_order, mode0.triangle_order,
                                          std::vector<uint8_t>(mode0.triangle_order.size(), 0)));
    }
    if (options.quantize_bits == 0) return candidates;
    for (Hierarchy& expected : candidates) {
        expected.set_single_precision(false);
        std::vector<Vec3> points;
        const std::vector<uint32_t> order = canonical_vertex_order(expected);
        for (VertexId v = 0; v < order.size(); ++v) {
            if (order[v] != kNoVertex) points.push_back(expected.position(v));
        }
        const Quantizer quantizer = make_quantizer(points, options.quantize_bits);
        for (VertexId v = 0; v < order.size(); ++v) {
            if (order[v] != kNoVertex) expected.set_position(v, dequantize(quantizer, quantize(quantizer, expected.position(v))));
        }
    }
    return candidates;
}

bool decodes_to_one_of(const Hierarchy& back, const std::vector<Hierarchy>& candidates) {
    for (const Hierarchy& c : candidates)
        if (identical(back, c)) return true;
    return false;
}

// A golden file of `version` decodes to c's hierarchy, and every prefix of its levels to that
// level (progressive decoding).
void check_decodes(const std::vector<uint8_t>& golden, const GoldenCase& c, int version) {
    const Hierarchy back = decode(golden.data(), golden.size());
    EXPECT_TRUE(decodes_to_one_of(back, expected_decodings(c.hierarchy, c.options, version)));
    const int levels = inspect(golden.data(), golden.size()).levels;
    for (int l = 0; l < levels; ++l) {
        DecodeOptions prefix;
        prefix.max_level = l;
        EXPECT_EQ(decode(golden.data(), golden.size(), prefix).depth(), std::min(l, back.depth())) << "level " << l;
    }
}

// Writes `bytes` as c's file of `version` when AMC_UPDATE_GOLDEN is set and the file is missing
// (never over an existing one); returns the file (empty when missing).
std::vector<uint8_t> golden_file(const GoldenCase& c, int version, const std::vector<uint8_t>& bytes) {
    const std::string path = golden_path(version, c.name);
    if (std::getenv("AMC_UPDATE_GOLDEN") != nullptr && !std::filesystem::exists(path)) {
        std::filesystem::create_directories(std::filesystem::path(path).parent_path());
        std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    }
    return read_golden(path);
}

// The file of c in the version its bytes say (14: an adaptive level of a bit-exact file with its
// raw bits in a side stream; 15: a level of a bit-exact file in geometry mode 6 or 7; 16: the
// mixing mode's fourth model; 17: its fifth; 19: its sixth; 20: its seventh; 21: a bit-exact file
// with the base's raw bits in a side stream) equals the encoder's bytes and decodes to c's hierarchy (every prefix
// of levels too); the cases pinned by older versions' tests that encoders now write as one of those
// versions. The files of versions 14 to the written one's of the case still decode.
void pin_newer_encoding(const GoldenCase& c, const std::vector<uint8_t>& bytes) {
    const int written = bytes[4];
    SCOPED_TRACE(golden_path(written, c.name));
    const std::vector<uint8_t> golden = golden_file(c, written, bytes);
    ASSERT_FALSE(golden.empty()) << "missing";
    EXPECT_EQ(bytes, golden) << "the bitstream changed (a new format version: FORMAT.md, Versions)";
    EXPECT_EQ(inspect(golden.data(), golden.size()).version, written);
    check_decodes(golden, c, written);
    for (int version = kRawSideVersion; version < written; ++version) {
        const std::vector<uint8_t> older = read_golden(golden_path(version, c.name));
        if (!older.empty()) check_decodes(older, c, version);
    }
}

// c's golden file of `version`, which the encoder must reproduce byte for byte (empty when it is
// missing). AMC_UPDATE_GOLDEN writes a missing file first; it never overwrites one. A case written
// as a newer version of 14 on now (pin_newer_encoding) has its bytes pinned by its file of that
// version, and `version`'s file is returned for the caller to decode.
std::vector<uint8_t> pinned_encoding(const GoldenCase& c, int version, EncodeStats* stats = nullptr) {
    const std::vector<uint8_t> bytes = encode(c.hierarchy, c.options, stats);
    if (bytes.size() > 4 && bytes[4] > version && bytes[4] >= kRawSideVersion) {
        pin_newer_encoding(c, bytes);
        return read_golden(golden_path(version, c.name));
    }
    const std::vector<uint8_t> golden = golden_file(c, version, bytes);
    if (!golden.empty()) {
        EXPECT_EQ(bytes, golden) << golden_path(version, c.name) << ": the bitstream changed (a new format version: FORMAT.md, Versions)";
    }
    return golden;
}

// The versions with these cases: version 3 adds only the numbering block, whose golden files
// tests/numbering_test.cpp pins; version 4 writes these cases (mode 2 bases), version 5 too (its
// encoder searches mode 2's start triangle and gate radius).
constexpr int kVersionsOfTheCases[] = {1, 2, 4, 5};
// The version encode() writes for these cases.
constexpr int kCurrentVersionOfTheCases = kSearchedBaseVersion;

// Version 6 (level geometry mode 3, the normal frame with static tables and rANS): a random
// refinement of the icosahedron with every vertex projected onto the unit sphere (new vertices lie
// off their edge's midpoint along the normal, as in a surface remesh), bit-exact in float64 and at
// 12 bits, where the automatic encoder picks mode 3, and the float32 random hierarchy with mode 3
// forced.
std::vector<GoldenCase> static_geometry_cases() {
    std::vector<GoldenCase> cases;
    const Hierarchy sphere = testing::projected_sphere(1200, 4, 7);
    EncodeOptions exact;
    exact.unit_normals = false;  // version 6's encoder: geometry mode 5 is not a candidate
    cases.push_back({"sphere_random", sphere, exact});
    EncodeOptions quantized;
    quantized.quantize_bits = 12;
    quantized.grid_contexts = false;  // version 6's encoder: geometry mode 4 is not a candidate
    cases.push_back({"sphere_random_q12", sphere, quantized});
    Hierarchy h(make_bumpy_sphere(0));  // float32 coordinates
    refine_randomly(h, 400, 4, 11);
    EncodeOptions forced;
    forced.predictor = GeometryPredictor::normal_frame;
    cases.push_back({"bumpy_random_float32_normal", h, forced});
    return cases;
}

TEST(Golden, StaticGeometryFilesDecodeAndPinTheEncoder) {
    for (const GoldenCase& c : static_geometry_cases()) {
        SCOPED_TRACE(golden_path(kStaticGeometryVersion, c.name));
        EncodeStats stats;
        const std::vector<uint8_t> golden = pinned_encoding(c, kStaticGeometryVersion, &stats);
        ASSERT_FALSE(golden.empty()) << "missing";
        EXPECT_EQ(inspect(golden.data(), golden.size()).version, kStaticGeometryVersion);
        EXPECT_TRUE(std::any_of(stats.per_level.begin(), stats.per_level.end(),
                                [](const LevelStats& l) { return l.predictor == GeometryPredictor::normal_frame; }))
            << "the case exercises geometry mode 3";
        check_decodes(golden, c, kStaticGeometryVersion);
    }
}

// Version 7 (chunks): the cases above cut into chunks, so that seam edges cross boundaries, float32
// and quantized coordinates, flipped diagonals next to the seam, and geometry mode 3 in chunks.
std::vector<GoldenCase> chunked_cases() {
    std::vector<GoldenCase> cases;
    const std::vector<uint32_t> chunks = {4, 3, 5, 3, 2};
    size_t k = 0;
    for (GoldenCase c : golden_cases()) {
        c.options.chunks = chunks[k++ % chunks.size()];
        c.name += "_chunks" + std::to_string(c.options.chunks);
        cases.push_back(std::move(c));
    }
    for (GoldenCase c : static_geometry_cases()) {
        c.options.chunks = 4;
        c.name += "_chunks4";
        cases.push_back(std::move(c));
    }
    return cases;
}

// A chunked golden file decodes to the same hierarchy on 1, 2 and 3 threads (the decoder's two
// ways of putting chunks together).
void check_decodes_on_threads(const std::vector<uint8_t>& golden) {
    const Hierarchy one = decode(golden.data(), golden.size());
    for (unsigned threads : {2u, 3u}) {
        DecodeOptions options;
        options.threads = threads;
        EXPECT_TRUE(identical(decode(golden.data(), golden.size(), options), one)) << threads << " threads";
    }
}

// Encoders write chunked files as version 13 now (pinned below): version 7's files still decode.
TEST(Golden, ChunkedFilesOfVersion7Decode) {
    for (const GoldenCase& c : chunked_cases()) {
        const std::string path = golden_path(kChunkedVersion, c.name);
        SCOPED_TRACE(path);
        const std::vector<uint8_t> golden = read_golden(path);
        ASSERT_FALSE(golden.empty()) << "missing";
        const FileInfo info = inspect(golden.data(), golden.size());
        EXPECT_EQ(info.version, kChunkedVersion);
        EXPECT_EQ(info.chunks.size(), size_t(c.options.chunks));
        check_decodes(golden, c, kChunkedVersion);
        check_decodes_on_threads(golden);
    }
}

// Version 8 (the hierarchy coder's mixing mode, FORMAT.md 2.1): the projected sphere of version 6
// bit-exact and at 12 bits (geometric contexts from decoded positions), the graded L-shape
// (planar: structure only) and the torus with the naive traversal and no context groups (the
// switches under the mixing mode). Each in the traversal its options name: the encoder's choice of
// the smaller (EncodeOptions::choose_traversal) is tested in mixed_contexts_test.cpp.
std::vector<GoldenCase> mixed_contexts_cases() {
    std::vector<GoldenCase> cases;
    for (GoldenCase& c : static_geometry_cases()) {
        if (c.name == "bumpy_random_float32_normal") continue;
        c.name += "_mixed";
        c.options.hierarchy_contexts = HierarchyContexts::mixed;
        c.options.choose_traversal = false;
        cases.push_back(c);
    }
    for (GoldenCase& c : golden_cases()) {
        if (c.name != "lshape_graded" && c.name != "torus_naive_butterfly" && c.name != "bumpy_random_float32") continue;
        c.name += "_mixed";
        c.options.hierarchy_contexts = HierarchyContexts::mixed;
        c.options.choose_traversal = false;
        cases.push_back(c);
    }
    return cases;
}

// Version 8's files hold the mixing mode's first model, which encoders no longer write (version 11
// pins the encoder on the same cases, below): they decode.
TEST(Golden, MixedContextsFilesOfTheFirstModelDecode) {
    for (const GoldenCase& c : mixed_contexts_cases()) {
        const std::string path = golden_path(kMixedContextsVersion, c.name);
        SCOPED_TRACE(path);
        const std::vector<uint8_t> golden = read_golden(path);
        ASSERT_FALSE(golden.empty()) << "missing";
        EXPECT_EQ(inspect(golden.data(), golden.size()).version, kMixedContextsVersion);
        check_decodes(golden, c, kMixedContextsVersion);
    }
}

// Version 9 (level geometry mode 4, FORMAT.md 5.7): the projected sphere of version 6 at 12 bits
// with the automatic choice and grid contexts, at 16 bits with mode 4 forced in every level, at 5
// bits (few tokens), at 12 bits forced in four chunks, and at 12 bits under the mixing mode.
std::vector<GoldenCase> grid_geometry_cases() {
    std::vector<GoldenCase> cases;
    for (GoldenCase& c : static_geometry_cases()) {
        if (c.name != "sphere_random") continue;
        EncodeOptions grid;
        grid.quantize_bits = 12;
        grid.grid_contexts = true;
        cases.push_back({"sphere_random_q12_grid", c.hierarchy, grid});
        EncodeOptions forced;
        forced.quantize_bits = 16;
        forced.predictor = GeometryPredictor::normal_frame_grid;
        cases.push_back({"sphere_random_q16_grid_forced", c.hierarchy, forced});
        forced.quantize_bits = 5;
        cases.push_back({"sphere_random_q5_grid_forced", c.hierarchy, forced});
        EncodeOptions chunked = grid;
        chunked.chunks = 4;
        chunked.predictor = GeometryPredictor::normal_frame_grid;  // small chunks: the automatic choice keeps mode 3
        cases.push_back({"sphere_random_q12_grid_forced_chunks4", c.hierarchy, chunked});
        EncodeOptions mixed = grid;
        mixed.hierarchy_contexts = HierarchyContexts::mixed;
        mixed.choose_traversal = false;  // the improved traversal, as the case was made
        cases.push_back({"sphere_random_q12_grid_mixed", c.hierarchy, mixed});
    }
    return cases;
}

TEST(Golden, GridGeometryFilesDecodeAndPinTheEncoder) {
    const std::vector<GoldenCase> cases = grid_geometry_cases();
    ASSERT_EQ(cases.size(), 5u);
    for (const GoldenCase& c : cases) {
        EncodeStats stats;
        const std::string path = golden_path(kGridGeometryVersion, c.name);
        SCOPED_TRACE(path);
        if (c.options.hierarchy_contexts == HierarchyContexts::mixed || c.options.chunks > 1) {
            // The mixing mode's first model: encoders write version 11 now (pinned below); chunks:
            // version 13, then 18 (pinned below).
            const std::vector<uint8_t> golden = read_golden(path);
            ASSERT_FALSE(golden.empty()) << path << " is missing";
            EXPECT_EQ(inspect(golden.data(), golden.size()).version, kGridGeometryVersion);
            check_decodes(golden, c, kGridGeometryVersion);
            continue;
        }
        // Encoders write mode 4's tokens in the grouped order now (version 18, whose file of the
        // case pins the bytes): version 9's file still decodes.
        const std::vector<uint8_t> golden = pinned_encoding(c, kGridGeometryVersion, &stats);
        ASSERT_FALSE(golden.empty()) << path << " is missing";
        const FileInfo info = inspect(golden.data(), golden.size());
        EXPECT_EQ(info.version, kGridGeometryVersion);
        EXPECT_EQ(info.chunks.size(), size_t(0));
        EXPECT_TRUE(std::any_of(stats.per_level.begin(), stats.per_level.end(),
                                [](const LevelStats& l) { return l.predictor == GeometryPredictor::normal_frame_grid; }))
            << "the case exercises geometry mode 4";
        check_decodes(golden, c, kGridGeometryVersion);
    }
}

// Version 18 (mode 4's tokens grouped by runs of 64 vertices, FORMAT.md 5.7): version 9's cases
// but the mixed one (whose files keep the per-vertex order), pinned by the tests of versions 9 and
// 13 (pinned_encoding) in v18/. Each decodes, on 1 to 3 threads when chunked, to the hierarchy the
// case's older file (version 9, or 13 when chunked) decodes to, from other bytes: the same tables,
// other streams.
TEST(Golden, GroupedGridFilesDecodeAsTheOlderOrdersFilesDo) {
    int grouped_cases = 0;
    for (const GoldenCase& c : grid_geometry_cases()) {
        if (c.options.hierarchy_contexts == HierarchyContexts::mixed) continue;
        SCOPED_TRACE(golden_path(kGroupedGridVersion, c.name));
        const std::vector<uint8_t> grouped = read_golden(golden_path(kGroupedGridVersion, c.name));
        ASSERT_FALSE(grouped.empty()) << "missing";
        EXPECT_EQ(inspect(grouped.data(), grouped.size()).version, kGroupedGridVersion);
        check_decodes(grouped, c, kGroupedGridVersion);
        if (c.options.chunks > 1) check_decodes_on_threads(grouped);
        const std::vector<uint8_t> older =
            read_golden(golden_path(c.options.chunks > 1 ? kChunkVerticesVersion : kGridGeometryVersion, c.name));
        ASSERT_FALSE(older.empty());
        EXPECT_TRUE(identical(decode(grouped.data(), grouped.size()), decode(older.data(), older.size())));
        size_t differing = 0;
        for (size_t i = 0; i < std::min(grouped.size(), older.size()); ++i) differing += grouped[i] != older[i];
        EXPECT_GT(differing, 100u) << "the streams' order, not only the version";
        ++grouped_cases;
    }
    EXPECT_EQ(grouped_cases, 4);
}

// Versions 10 and 11 (the mixing mode's second and third models, FORMAT.md 2.2-2.3): version 8's
// cases and the projected sphere at 12 bits in geometry mode 4 under the mixing mode (version 9's
// mixed case).
std::vector<GoldenCase> later_mixing_cases() {
    std::vector<GoldenCase> cases = mixed_contexts_cases();
    for (const GoldenCase& c : grid_geometry_cases())
        if (c.options.hierarchy_contexts == HierarchyContexts::mixed) cases.push_back(c);
    return cases;
}

// Version 10's files hold the second model, which encoders no longer write (version 11 pins the
// encoder on the same cases, below): they decode, and are not first-model files.
TEST(Golden, SecondMixingModelFilesDecode) {
    const std::vector<GoldenCase> cases = later_mixing_cases();
    ASSERT_EQ(cases.size(), 6u);
    for (const GoldenCase& c : cases) {
        const std::string path = golden_path(kSecondMixingVersion, c.name);
        SCOPED_TRACE(path);
        const std::vector<uint8_t> golden = read_golden(path);
        ASSERT_FALSE(golden.empty()) << "missing";
        EXPECT_EQ(inspect(golden.data(), golden.size()).version, kSecondMixingVersion);
        check_decodes(golden, c, kSecondMixingVersion);
        // Not a first-model file: version 8's file of the case holds other bytes.
        const std::vector<uint8_t> first = read_golden(golden_path(c.options.grid_contexts && c.options.quantize_bits != 0 ? kGridGeometryVersion : kMixedContextsVersion, c.name));
        ASSERT_FALSE(first.empty());
        EXPECT_NE(first, golden);
    }
}

TEST(Golden, ThirdMixingModelFilesDecodeAndPinTheEncoder) {
    const std::vector<GoldenCase> cases = later_mixing_cases();
    ASSERT_EQ(cases.size(), 6u);
    for (const GoldenCase& c : cases) {
        SCOPED_TRACE(golden_path(kThirdMixingVersion, c.name));
        const std::vector<uint8_t> golden = pinned_encoding(c, kThirdMixingVersion);
        ASSERT_FALSE(golden.empty()) << "missing";
        EXPECT_EQ(inspect(golden.data(), golden.size()).version, kThirdMixingVersion);
        check_decodes(golden, c, kThirdMixingVersion);
        // Not a second-model file: version 10's file of the case holds other bytes.
        const std::vector<uint8_t> second = read_golden(golden_path(kSecondMixingVersion, c.name));
        ASSERT_FALSE(second.empty());
        EXPECT_NE(second, golden);
    }
}

// Version 16 (the mixing mode's fourth model, FORMAT.md 2.4), 17 (its fifth, 2.5), 19 (its sixth,
// 2.6) and 20 (its seventh, 2.7): the encoder writes the seventh unless an older model codes the
// file smaller, so no case grows against the file the third model made (its newest golden file of
// versions 11-15) nor against the fourth's (v16/), the fifth's (v17/) or the sixth's (v19/), which
// encoders wrote before and which still decode (the test above pins the bytes, in v20/ where 20).
TEST(Golden, SeventhMixingModelFilesAreNoLargerThanTheOlderModels) {
    int fourth = 0, fifth = 0, sixth = 0, seventh = 0;
    for (const GoldenCase& c : later_mixing_cases()) {
        SCOPED_TRACE(c.name);
        const std::vector<uint8_t> bytes = encode(c.hierarchy, c.options);
        std::vector<uint8_t> third;
        for (int version = kStencilTablesVersion; version >= kThirdMixingVersion && third.empty(); --version)
            third = read_golden(golden_path(version, c.name));
        ASSERT_FALSE(third.empty());
        EXPECT_LE(bytes.size(), third.size());
        size_t smallest_older = third.size();
        for (const int version : {kFourthMixingVersion, kFifthMixingVersion, kSixthMixingVersion}) {
            const std::vector<uint8_t> older = read_golden(golden_path(version, c.name));
            if (older.empty()) continue;
            ++(version == kFourthMixingVersion ? fourth : version == kFifthMixingVersion ? fifth : sixth);
            check_decodes(older, c, version);
            EXPECT_LE(bytes.size(), older.size()) << "version " << version;
            smallest_older = std::min(smallest_older, older.size());
        }
        if (bytes[4] == kSeventhMixingVersion || bytes[4] == kBaseRawSideVersion) {  // 21: bit-exact, the seventh model
            seventh += bytes.size() < smallest_older;
            check_decodes(bytes, c, bytes[4]);
        } else {
            EXPECT_EQ(bytes.size(), smallest_older) << "an older model's file, as before";
        }
    }
    EXPECT_GE(fourth, 1) << "some case has a fourth-model file";
    EXPECT_GE(fifth, 1) << "some case has a fifth-model file";
    EXPECT_GE(sixth, 1) << "some case has a sixth-model file";
    EXPECT_GE(seventh, 1) << "the trained states code some case smaller than every older model";
}

// Version 12 (level geometry mode 5, the normal frame of unit normals with three tables): the
// projected sphere bit-exact and under the mixing mode with the automatic choice (which takes mode
// 5), at 12 bits and in four chunks with mode 5 forced, and the float32 random hierarchy forced.
std::vector<GoldenCase> unit_frame_cases() {
    std::vector<GoldenCase> cases;
    for (const GoldenCase& c : static_geometry_cases()) {
        EncodeOptions forced;
        forced.predictor = GeometryPredictor::unit_normal_frame;
        if (c.name == "bumpy_random_float32_normal") cases.push_back({"bumpy_random_float32_unit", c.hierarchy, forced});
        if (c.name != "sphere_random") continue;
        cases.push_back({"sphere_random_unit", c.hierarchy, {}});
        EncodeOptions quantized = forced;
        quantized.quantize_bits = 12;
        cases.push_back({"sphere_random_q12_unit", c.hierarchy, quantized});
        EncodeOptions chunked = forced;
        chunked.chunks = 4;
        cases.push_back({"sphere_random_unit_chunks4", c.hierarchy, chunked});
        EncodeOptions mixed;
        mixed.hierarchy_contexts = HierarchyContexts::mixed;
        mixed.choose_traversal = false;  // the improved traversal, as the case was made
        cases.push_back({"sphere_random_unit_mixed", c.hierarchy, mixed});
    }
    return cases;
}

TEST(Golden, UnitFrameFilesDecodeAndPinTheEncoder) {
    const std::vector<GoldenCase> cases = unit_frame_cases();
    ASSERT_EQ(cases.size(), 5u);
    for (const GoldenCase& c : cases) {
        SCOPED_TRACE(golden_path(kUnitFrameVersion, c.name));
        EncodeStats stats;
        std::vector<uint8_t> golden;
        if (c.options.chunks > 1) {  // encoders write chunks as version 13 now (pinned below); this file still decodes
            encode(c.hierarchy, c.options, &stats);
            golden = read_golden(golden_path(kUnitFrameVersion, c.name));
        } else {
            golden = pinned_encoding(c, kUnitFrameVersion, &stats);
        }
        ASSERT_FALSE(golden.empty()) << "missing";
        const FileInfo info = inspect(golden.data(), golden.size());
        EXPECT_EQ(info.version, kUnitFrameVersion);
        EXPECT_EQ(info.chunks.size(), c.options.chunks > 1 ? size_t(c.options.chunks) : size_t(0));
        EXPECT_TRUE(std::any_of(stats.per_level.begin(), stats.per_level.end(),
                                [](const LevelStats& l) { return l.predictor == GeometryPredictor::unit_normal_frame; }))
            << "the case exercises geometry mode 5";
        check_decodes(golden, c, kUnitFrameVersion);
    }
}

// Version 13 (the chunk table lists each chunk's own vertices): every chunked case of versions 7, 9
// and 12, pinned, and decoded on 1, 2 and 3 threads.
std::vector<GoldenCase> chunk_vertices_cases() {
    std::vector<GoldenCase> cases = chunked_cases();
    for (const std::vector<GoldenCase>& more : {grid_geometry_cases(), unit_frame_cases()})
        for (const GoldenCase& c : more)
            if (c.options.chunks > 1) cases.push_back(c);
    return cases;
}

TEST(Golden, ChunkVerticesFilesDecodeAndPinTheEncoder) {
    const std::vector<GoldenCase> cases = chunk_vertices_cases();
    ASSERT_EQ(cases.size(), 10u);
    for (const GoldenCase& c : cases) {
        SCOPED_TRACE(golden_path(kChunkVerticesVersion, c.name));
        const std::vector<uint8_t> golden = pinned_encoding(c, kChunkVerticesVersion);
        ASSERT_FALSE(golden.empty()) << "missing";
        const FileInfo info = inspect(golden.data(), golden.size());
        EXPECT_EQ(info.version, kChunkVerticesVersion);
        EXPECT_EQ(info.chunks.size(), size_t(c.options.chunks));
        check_decodes(golden, c, kChunkVerticesVersion);
        check_decodes_on_threads(golden);
    }
}

// Version 15 (level geometry modes 6 and 7: the midpoint's and the butterfly's predictions under
// static tables per axis, FORMAT.md 5.9; bit-exact files): a bumpy torus whose coordinates use all
// their bits with the automatic choice, with mode 6 forced, in float32 with mode 7 forced, and in
// three chunks with mode 7 forced.
std::vector<GoldenCase> stencil_tables_cases() {
    std::vector<GoldenCase> cases;
    const Hierarchy torus = testing::bumpy_torus(false);
    cases.push_back({"torus_bumpy", testing::bumpy_torus(false, 6000, 5), {}});  // levels large enough for the tables
    EncodeOptions midpoint;
    midpoint.predictor = GeometryPredictor::midpoint_static;
    cases.push_back({"torus_bumpy_midpoint_static", torus, midpoint});
    EncodeOptions butterfly;
    butterfly.predictor = GeometryPredictor::butterfly_static;
    cases.push_back({"torus_bumpy_float32_butterfly_static", testing::bumpy_torus(true), butterfly});
    butterfly.chunks = 3;
    cases.push_back({"torus_bumpy_butterfly_static_chunks3", torus, butterfly});
    return cases;
}

TEST(Golden, StencilTablesFilesDecodeAndPinTheEncoder) {
    for (const GoldenCase& c : stencil_tables_cases()) {
        SCOPED_TRACE(golden_path(kStencilTablesVersion, c.name));
        EncodeStats stats;
        const std::vector<uint8_t> golden = pinned_encoding(c, kStencilTablesVersion, &stats);  // bytes pinned in v21/ now
        ASSERT_FALSE(golden.empty()) << "missing";
        const FileInfo info = inspect(golden.data(), golden.size());
        EXPECT_EQ(info.version, kStencilTablesVersion);
        EXPECT_EQ(info.chunks.size(), c.options.chunks > 1 ? size_t(c.options.chunks) : size_t(0));
        EXPECT_TRUE(std::any_of(stats.per_level.begin(), stats.per_level.end(), [](const LevelStats& l) {
            return l.predictor == GeometryPredictor::midpoint_static || l.predictor == GeometryPredictor::butterfly_static;
        })) << "the case exercises geometry mode 6 or 7";
        check_decodes(golden, c, kStencilTablesVersion);
        if (c.options.chunks > 1) check_decodes_on_threads(golden);
    }
}

// Version 22 (base connectivity mode 3, FORMAT.md 4.17): an irregular strip of 9,000 triangles,
// whose conquest walks mode 2 over its budget, refined at random in places: bit-exact (the base's
// side stream as in version 21), at 16 bits (geometry mode 4 in the grouped order) and at 16 bits
// in the mixing mode (the seventh model, mode 4 in the per-vertex order). At 12 bits the snapped
// base fits mode 2.
std::vector<GoldenCase> windowed_tip_cases() {
    std::vector<GoldenCase> cases;
    Hierarchy h(make_irregular_strip(1500, 3, 1));
    refine_randomly(h, 9600, 3, 3);
    cases.push_back({"strip_random", h, {}});
    EncodeOptions quantized;
    quantized.quantize_bits = 16;
    cases.push_back({"strip_random_q16", h, quantized});
    quantized.hierarchy_contexts = HierarchyContexts::mixed;
    cases.push_back({"strip_random_mixed_q16", h, quantized});
    return cases;
}

TEST(Golden, WindowedTipFilesDecodeAndPinTheEncoder) {
    for (const GoldenCase& c : windowed_tip_cases()) {
        SCOPED_TRACE(golden_path(kWindowedTipVersion, c.name));
        EXPECT_THROW(encode_base_connectivity(c.hierarchy.base(), BaseConnectivityMode::angle), Error)
            << "mode 2 walks over its budget on this base";
        EncodeStats stats;
        const std::vector<uint8_t> golden = pinned_encoding(c, kWindowedTipVersion, &stats);
        ASSERT_FALSE(golden.empty()) << "missing";
        const FileInfo info = inspect(golden.data(), golden.size());
        EXPECT_EQ(info.version, kWindowedTipVersion);
        if (c.options.quantize_bits != 0) {
            EXPECT_TRUE(std::any_of(stats.per_level.begin(), stats.per_level.end(), [](const LevelStats& l) {
                return l.predictor == GeometryPredictor::normal_frame_grid;
            })) << "the case exercises geometry mode 4 (grouped order, or per vertex when mixed)";
        }
        EXPECT_EQ(info.quantize_bits, c.options.quantize_bits);
        check_decodes(golden, c, kWindowedTipVersion);
        // Mode 3 is an error in a file of an older version.
        std::vector<uint8_t> older = golden;
        older[4] = kBaseRawSideVersion;
        EXPECT_THROW(decode(older.data(), older.size()), Error);
    }
}

TEST(Golden, FilesOfEveryVersionDecodeToTheirHierarchies) {
    for (const int version : kVersionsOfTheCases) {
        for (const GoldenCase& c : golden_cases()) {
            const std::string path = golden_path(version, c.name);
            const std::vector<uint8_t> golden = read_golden(path);
            ASSERT_FALSE(golden.empty()) << path << " is missing";
            SCOPED_TRACE(path);
            const FileInfo info = inspect(golden.data(), golden.size());
            EXPECT_EQ(info.version, version);
            EXPECT_EQ(info.quantize_bits, c.options.quantize_bits);
            EXPECT_EQ(info.single_precision, c.hierarchy.single_precision() && c.options.quantize_bits == 0);
            ASSERT_EQ(info.blocks.size(), size_t(4 + info.levels)) << "metadata, base connectivity, base geometry, levels, end";
            EXPECT_EQ(info.blocks[0].name, "metadata");
            EXPECT_EQ(info.blocks[1].name, "base connectivity");
            EXPECT_EQ(info.blocks[2].name, "base geometry");
            for (int l = 0; l < info.levels; ++l) EXPECT_EQ(info.blocks[size_t(3 + l)].level, l);
            EXPECT_EQ(info.blocks.back().name, "end");
            check_decodes(golden, c, version);
        }
    }
}

TEST(Golden, EncodingsMatchTheCurrentVersionsFiles) {
    for (const GoldenCase& c : golden_cases())
        EXPECT_FALSE(pinned_encoding(c, kCurrentVersionOfTheCases).empty()) << golden_path(kCurrentVersionOfTheCases, c.name) << " is missing";
}

// tests/data/golden/SHA256SUMS lists every golden file with its SHA-256, as `sha256sum` writes it
// (cd tests/data/golden && sha256sum -c SHA256SUMS): a file regenerated in place, added without
// its line, or lost fails here, and so does a readable version without golden files.
TEST(Golden, EveryFileHasItsCommittedHashAndEveryVersionItsFiles) {
    // FIPS 180-4's known answers first: the manifest is only as good as the hash.
    ASSERT_EQ(test::sha256_hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
    ASSERT_EQ(test::sha256_hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
    ASSERT_EQ(test::sha256_hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
              "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");

    const std::filesystem::path root = std::filesystem::path(AMC_TEST_DATA_DIR) / "golden";
    std::ifstream manifest_file(root / "SHA256SUMS");
    ASSERT_TRUE(manifest_file) << (root / "SHA256SUMS") << " is missing";
    std::map<std::string, std::string> manifest;  // path below golden/ -> hash
    for (std::string line; std::getline(manifest_file, line);) {
        std::istringstream fields(line);
        std::string hash, path;
        fields >> hash >> path;
        ASSERT_EQ(hash.size(), 64u) << "malformed line: " << line;
        ASSERT_TRUE(manifest.emplace(path, hash).second) << path << " is listed twice";
    }
    std::set<std::string> seen;
    for (const auto& entry : std::filesystem::recursive_directory_iterator(root)) {
        if (!entry.is_regular_file() || entry.path().filename() == "SHA256SUMS") continue;
        const std::string path = entry.path().lexically_relative(root).generic_string();
        seen.insert(path);
        const auto listed = manifest.find(path);
        if (listed == manifest.end()) {
            ADD_FAILURE() << path << " is not in SHA256SUMS: a new golden file gets its line "
                          << "(cd tests/data/golden && sha256sum " << path << " >> SHA256SUMS)";
            continue;
        }
        std::ifstream file(entry.path(), std::ios::binary);
        const std::string bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
        EXPECT_EQ(test::sha256_hex(bytes), listed->second)
            << path << " changed: golden files are never regenerated (a new format version gets a new directory)";
    }
    for (const auto& [path, hash] : manifest) EXPECT_TRUE(seen.count(path)) << path << " is listed but missing";
    for (int version = kOldestReadableVersion; version <= kNewestVersion; ++version) {
        const std::string prefix = "v" + std::to_string(version) + "/";
        const bool any = std::any_of(manifest.begin(), manifest.end(),
                                     [&](const auto& entry) { return entry.first.rfind(prefix, 0) == 0; });
        EXPECT_TRUE(any) << ".amc version " << version << " is readable but has no golden file in " << prefix;
    }
}

}  // namespace
}  // namespace amc
