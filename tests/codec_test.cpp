// The .amc file: bit-exact round trips, quantization, progressive decoding, corrupt files.
#include "coding/base_order_search.h"
#include "coding/container.h"
#include "coding/hierarchy/coder_switches.h"
#include "coding/hierarchy/hierarchy_stream.h"
#include "hierarchy_checks.h"

#include <amc/codec.h>
#include <amc/hierarchy_coder.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <string>

namespace amc {
namespace {

struct Random {
    uint64_t state;
    uint64_t next() {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        return state ^ (state >> 29);
    }
};

// What the decoder must give back: the input expressed in the base coder's order.
Hierarchy expected_decoding(const Hierarchy& h) { return in_decoder_order(h); }

// Coordinates that stress a lossless float coder: random bit patterns of finite values,
// denormals, signed zeros, huge and tiny magnitudes, and exact midpoints.
double stress_coordinate(Random& random, bool single) {
    switch (random.next() % 6) {
        case 0: return 0.0;
        case 1: return -0.0;
        case 2: return (random.next() % 2 ? 1 : -1) * std::ldexp(double(random.next() % 1000 + 1), single ? -149 : -1074);  // denormal
        case 3: return (random.next() % 2 ? 1 : -1) * std::ldexp(double(random.next() % 1000), single ? 100 : 900);
        case 4: return std::ldexp(double(random.next() % 100000), -random.next() % 60);
        default: {
            if (single) {
                uint32_t bits = uint32_t(random.next());
                float f;
                std::memcpy(&f, &bits, 4);
                return std::isfinite(f) ? double(f) : 1.5;
            }
            uint64_t bits = random.next();
            double d;
            std::memcpy(&d, &bits, 8);
            return std::isfinite(d) ? d : 2.5;
        }
    }
}

Hierarchy random_hierarchy(uint64_t seed, bool single) {
    Random random{seed};
    const auto meshes = testing::fixture_meshes();
    TriangleMesh base = meshes[random.next() % meshes.size()].mesh;
    base.single_precision = single;
    for (Vec3& p : base.positions) {
        if (single) p = Vec3{double(float(p.x)), double(float(p.y)), double(float(p.z))};
    }
    Hierarchy h(base);
    refine_randomly(h, h.root_count() + uint32_t(random.next() % 400), 1 + int(random.next() % 5), seed);
    for (NodeId n : h.leaves()) {
        if (h.hanging_node_count(n) == 2 && random.next() % 3 == 0) h.set_diagonal_flipped(n, true);
    }
    if (seed % 2 == 0) {  // half keep exact midpoints (finite-element style), half get stress values
        for (VertexId v = 0; v < h.positions().size(); ++v) {
            h.set_position(v, {stress_coordinate(random, single), stress_coordinate(random, single),
                               stress_coordinate(random, single)});
        }
    }
    return h;
}

TEST(Codec, ThousandRandomHierarchiesRoundTripBitExactly) {
    for (uint64_t seed = 1; seed <= 1000; ++seed) {
        const bool single = seed % 4 < 2;
        const Hierarchy h = random_hierarchy(seed, single);
        EncodeOptions options;
        options.predictor = GeometryPredictor(seed % 4);
        const std::vector<uint8_t> bytes = encode(h, options);
        const Hierarchy back = decode(bytes.data(), bytes.size());
        ASSERT_TRUE(identical(back, expected_decoding(h))) << "seed " << seed;
        ASSERT_EQ(check_invariants(back), "");
    }
}

TEST(Codec, ExactMidpointsCostAlmostNothing) {
    Hierarchy h(make_l_shape(4));
    refine_randomly(h, 50000, 9, 3);
    EncodeStats stats;
    const std::vector<uint8_t> bytes = encode(h, {}, &stats);
    EXPECT_LT(double(stats.geometry_bytes) * 8 / double(stats.vertices - stats.base_vertices), 0.1)
        << "bits per refinement vertex";
    EXPECT_TRUE(identical(decode(bytes.data(), bytes.size()), expected_decoding(h)));
}

TEST(Codec, QuantizedErrorIsBounded) {
    const Hierarchy h = random_hierarchy(3, false);
    Hierarchy smooth(make_bumpy_sphere(1));
    refine_randomly(smooth, 3000, 5, 9);
    for (int bits : {8, 12, 16}) {
        EncodeOptions options;
        options.quantize_bits = bits;
        EncodeStats stats;
        const std::vector<uint8_t> bytes = encode(smooth, options, &stats);
        const Hierarchy back = decode(bytes.data(), bytes.size());
        const Hierarchy expected = in_decoder_order(smooth, options);
        ASSERT_EQ(back.node_count(), expected.node_count());
        const std::vector<uint32_t> ca = canonical_vertex_order(back), cb = canonical_vertex_order(expected);
        std::vector<Vec3> pa(back.vertex_count()), pb(expected.vertex_count());
        for (size_t v = 0; v < ca.size(); ++v) if (ca[v] != 0xffffffffu) pa[ca[v]] = back.position(VertexId(v));
        for (size_t v = 0; v < cb.size(); ++v) if (cb[v] != 0xffffffffu) pb[cb[v]] = expected.position(VertexId(v));
        double worst = 0;
        for (size_t i = 0; i < pa.size(); ++i) {
            worst = std::max({worst, std::fabs(pa[i].x - pb[i].x), std::fabs(pa[i].y - pb[i].y), std::fabs(pa[i].z - pb[i].z)});
        }
        EXPECT_LE(worst, stats.max_error * (1 + 1e-9)) << bits;
        EXPECT_GT(stats.max_error, 0.0);
        EXPECT_LE(stats.max_error, 2.5 / double(1u << bits) * 1.01) << "half a step of a box about 2.5 wide";
    }
    (void)h;
}

// Geometry mode 3 (normal frame, static tables, rANS): bit-exact and on the grid, in float32 and
// float64, and chosen by the automatic encoder on a curved surface remesh, where it codes smaller.
TEST(Codec, NormalFrameModeRoundTripsAndWinsOnSurfaces) {
    const Hierarchy surface = testing::curved_sphere_remesh(6000);
    for (int bits : {0, 12, 16}) {
        for (bool single : {false, true}) {
            if (single && bits != 0) continue;
            Hierarchy h = surface;
            if (single) {
                h.set_single_precision(true);
                for (VertexId v = 0; v < h.positions().size(); ++v) {
                    const Vec3 p = h.position(v);
                    h.set_position(v, Vec3{double(float(p.x)), double(float(p.y)), double(float(p.z))});
                }
            }
            EncodeOptions options;
            options.quantize_bits = bits;
            options.grid_contexts = false;  // mode 3 against the adaptive modes (mode 4: grid_geometry_test)
            size_t sizes[4] = {};
            for (GeometryPredictor p : {GeometryPredictor::automatic, GeometryPredictor::midpoint, GeometryPredictor::butterfly,
                                        GeometryPredictor::normal_frame}) {
                options.predictor = p;
                EncodeStats stats;
                const std::vector<uint8_t> bytes = encode(h, options, &stats);
                sizes[int(p)] = bytes.size();
                const Hierarchy back = decode(bytes.data(), bytes.size());
                const Hierarchy expected = in_decoder_order(h, options);
                if (bits == 0) {
                    ASSERT_TRUE(identical(back, expected)) << bits << " " << single << " " << int(p);
                } else {
                    ASSERT_EQ(back.vertex_count(), expected.vertex_count());
                    // On the grid: each decoded position is the input's snapped to it.
                    const std::vector<uint32_t> ca = canonical_vertex_order(back), cb = canonical_vertex_order(expected);
                    std::vector<Vec3> pa(back.vertex_count()), pb(expected.vertex_count());
                    for (size_t v = 0; v < ca.size(); ++v) if (ca[v] != 0xffffffffu) pa[ca[v]] = back.position(VertexId(v));
                    for (size_t v = 0; v < cb.size(); ++v) if (cb[v] != 0xffffffffu) pb[cb[v]] = expected.position(VertexId(v));
                    for (size_t i = 0; i < pa.size(); ++i) {
                        ASSERT_LE(std::max({std::fabs(pa[i].x - pb[i].x), std::fabs(pa[i].y - pb[i].y), std::fabs(pa[i].z - pb[i].z)}),
                                  stats.max_error * (1 + 1e-9)) << i;
                    }
                }
                const uint8_t version = bytes[4];
                const bool uses_mode_3 = std::any_of(stats.per_level.begin(), stats.per_level.end(),
                                                     [](const LevelStats& l) { return l.predictor == GeometryPredictor::normal_frame; });
                // Bit-exact files are version 21 (their bases' raw bits in a side stream) whatever their levels.
                if (bits == 0) {
                    EXPECT_EQ(version, kBaseRawSideVersion) << int(p);
                } else {
                    EXPECT_EQ(version == kStaticGeometryVersion, uses_mode_3) << int(p);
                }
            }
            EXPECT_LT(sizes[3], sizes[1]) << "normal frame below midpoint, bits " << bits;
            EXPECT_LT(sizes[3], sizes[2]) << "normal frame below butterfly, bits " << bits;
            EXPECT_LE(sizes[0], std::min(sizes[1], sizes[2]) + 8) << "automatic is at most a few bytes above the best";
        }
    }
}

// Lower efforts judge the geometry modes of large levels on a sample of them (EncodeOptions::effort):
// the choices may differ, the decoded hierarchy does not, and the sizes stay within 2 % of the
// highest effort's.
TEST(Codec, EveryEffortDecodesToTheSameHierarchy) {
    Hierarchy h(make_icosahedron());
    refine_uniformly(h, 6);  // the last level creates 30720 vertices: enough to be judged on a sample
    testing::Random random{3};
    for (VertexId v = 0; v < h.positions().size(); ++v) {
        const Vec3 p = h.position(v);
        h.set_position(v, (1.0 + 1e-3 * double(random.next() % 1000) / 1000.0) / std::sqrt(dot(p, p)) * p);
    }
    for (int bits : {0, 12}) {
        EncodeOptions options;
        options.quantize_bits = bits;
        options.effort = kMaxGeometryEffort;
        const std::vector<uint8_t> best = encode(h, options);
        const Hierarchy expected = decode(best.data(), best.size());
        for (int effort = 0; effort < kMaxGeometryEffort; ++effort) {
            options.effort = effort;
            const std::vector<uint8_t> bytes = encode(h, options);
            EXPECT_TRUE(identical(decode(bytes.data(), bytes.size()), expected)) << "bits " << bits << ", effort " << effort;
            EXPECT_LE(double(bytes.size()), 1.02 * double(best.size())) << "bits " << bits << ", effort " << effort;
        }
    }
}

// Efforts 3 and 4 (coding/base_order_search.h) also code the file in other base orders and keep
// the smallest: it decodes bit-exactly in the order in_decoder_order gives at that effort, is never
// larger than effort 2's or the default's, and is smaller on a curved remesh whose base (200
// triangles: a single try of the base coder) starts badly, in both hierarchy modes: a search
// skipped fails.
TEST(Codec, EffortsThreeAndFourChooseTheBaseOrder) {
    const Hierarchy h = testing::curved_sphere_remesh(6000);
    for (const HierarchyContexts contexts : {HierarchyContexts::paper, HierarchyContexts::mixed}) {
        int smaller = 0;
        for (const int bits : {0, 12}) {
            EncodeOptions options;
            options.hierarchy_contexts = contexts;
            options.quantize_bits = bits;
            const std::vector<uint8_t> fallback = encode(h, options);
            options.effort = kMaxGeometryEffort;
            const std::vector<uint8_t> two = encode(h, options);
            for (int effort = kBaseOrderEffort; effort <= kMaxEffort; ++effort) {
                SCOPED_TRACE(std::string(contexts == HierarchyContexts::mixed ? "mixed" : "paper") + ", bits " +
                             std::to_string(bits) + ", effort " + std::to_string(effort));
                options.effort = effort;
                options.keep_base_order = false;
                EncodeStats stats;
                const std::vector<uint8_t> searched = encode(h, options, &stats);
                EXPECT_EQ(stats.total_bytes, searched.size());
                EXPECT_LE(searched.size(), two.size());
                EXPECT_LE(searched.size(), fallback.size());
                smaller += searched.size() < two.size();
                const Hierarchy back = decode(searched.data(), searched.size());
                const Hierarchy ordered = in_decoder_order(h, options);
                if (bits == 0) {
                    EXPECT_TRUE(identical(back, ordered));
                } else {  // on the grid: the same as that order kept by the explicit base mode
                    EncodeOptions kept = options;
                    kept.keep_base_order = true;
                    const std::vector<uint8_t> file = encode(ordered, kept);
                    EXPECT_TRUE(identical(back, decode(file.data(), file.size())));
                }
                EXPECT_FALSE(identical(in_decoder_order(h), ordered) && searched.size() < two.size());
                // A fixed base order leaves nothing to choose: effort 2's bytes.
                options.keep_base_order = true;
                const std::vector<uint8_t> fixed = encode(h, options);
                options.effort = kMaxGeometryEffort;
                EXPECT_EQ(fixed, encode(h, options));
            }
        }
        EXPECT_GE(smaller, 2);
    }
}

TEST(Codec, EffortOutsideItsRangeIsRefused) {
    Hierarchy h(make_icosahedron());
    refine_uniformly(h, 1);
    for (int effort : {-1, kMaxEffort + 1}) {
        EncodeOptions options;
        options.effort = effort;
        try {
            encode(h, options);
            ADD_FAILURE() << "effort " << effort << " was taken";
        } catch (const Error& e) {
            EXPECT_EQ(e.code(), ErrorCode::invalid_input);
            EXPECT_NE(std::string(e.what()).find("effort " + std::to_string(effort)), std::string::npos) << e.what();
        }
    }
}

// An EncodeContext's memory (the first pass's level forest and lists, the static modes' buffers)
// goes from one encode to the next: hierarchies of other sizes, level counts and precisions, other
// geometry modes and efforts, chunked and mixed files in between, and the context after
// release() and after a move, must each give the bytes and sizes encode() gives without one.
TEST(Codec, EncodesThroughAContextAreThoseWithoutOne) {
    const Hierarchy surface = testing::curved_sphere_remesh(6000);
    Hierarchy sphere(make_icosahedron());
    refine_uniformly(sphere, 5);  // 7680 new vertices on the last level: the modes are weighed on a sample
    testing::Random random{7};
    for (VertexId v = 0; v < sphere.positions().size(); ++v) {
        const Vec3 p = sphere.position(v);
        sphere.set_position(v, (1.0 + 1e-3 * double(random.next() % 1000) / 1000.0) / std::sqrt(dot(p, p)) * p);
    }
    const Hierarchy small = random_hierarchy(2, false), single = random_hierarchy(5, true), exact = random_hierarchy(9, false);
    struct Case {
        const Hierarchy* h;
        int bits, effort;
        bool mixed, roles;
        uint32_t chunks;
    };
    const Case cases[] = {{&sphere, 0, kDefaultEffort, false, false, 0}, {&surface, 0, kDefaultEffort, false, false, 0},
                          {&small, 0, kDefaultEffort, false, false, 0},  {&sphere, 12, kDefaultEffort, false, false, 0},
                          {&surface, 16, kMaxGeometryEffort, false, false, 0},   {&single, 0, kDefaultEffort, false, false, 0},
                          {&surface, 0, kDefaultEffort, true, false, 0}, {&exact, 0, kDefaultEffort, false, false, 2},
                          {&surface, 12, kDefaultEffort, false, true, 0}, {&sphere, 0, 0, false, false, 0},
                          {&surface, 12, kDefaultEffort, false, false, 4}, {&sphere, 0, kDefaultEffort, false, false, 3},
                          {&surface, 12, kBaseOrderEffort, false, false, 0}};
    EncodeContext context;
    for (int pass = 0; pass < 2; ++pass) {
        for (size_t c = 0; c < std::size(cases); ++c) {
            SCOPED_TRACE("case " + std::to_string(c) + ", pass " + std::to_string(pass));
            EncodeOptions options;
            options.quantize_bits = cases[c].bits;
            options.effort = cases[c].effort;
            options.hierarchy_contexts = cases[c].mixed ? HierarchyContexts::mixed : HierarchyContexts::paper;
            options.grid_contexts = !cases[c].roles;
            options.chunks = cases[c].chunks;
            options.threads = cases[c].chunks > 1 ? 2 : 0;  // chunks: each thread's chunk memory kept, in turn
            EncodeStats with, without;
            const std::vector<uint8_t> bytes = encode(context, *cases[c].h, options, &with);
            EXPECT_EQ(bytes, encode(*cases[c].h, options, &without));
            EXPECT_EQ(with.total_bytes, without.total_bytes);
            EXPECT_EQ(with.geometry_bytes, without.geometry_bytes);
        }
        if (pass == 0) context.release();
    }
    EncodeContext moved = std::move(context);
    EXPECT_EQ(encode(moved, surface), encode(surface));
    EXPECT_EQ(encode(context, sphere), encode(sphere));  // a moved-from context starts afresh
}

// DecodeOptions::lean_memory gives working memory back to the system as soon as nothing reads it
// (amc decode's setting); anything given back too early reads as zeros and builds a wrong
// hierarchy. Lean against plain decodes: a uniform sphere (its last level all leaves, decided
// without symbols: its links serve the split alone and go back at once), an adaptive remesh,
// lossless and quantized, the mixing mode, two chunks, and a progressive decode.
TEST(Codec, LeanDecodesBuildWhatPlainDecodesBuild) {
    const Hierarchy surface = testing::curved_sphere_remesh(6000);
    Hierarchy sphere(make_icosahedron());
    refine_uniformly(sphere, 5);  // 20,480 leaves: the last level's links span many pages
    struct Case {
        const Hierarchy* h;
        int bits;
        bool mixed;
        uint32_t chunks;
        int max_level;
    };
    const Case cases[] = {{&sphere, 0, false, 0, -1},  {&sphere, 12, false, 0, -1}, {&surface, 0, false, 0, -1},
                          {&surface, 16, false, 0, -1}, {&surface, 12, true, 0, -1}, {&surface, 12, false, 2, -1},
                          {&sphere, 12, false, 0, 4}};
    for (size_t c = 0; c < std::size(cases); ++c) {
        SCOPED_TRACE("case " + std::to_string(c));
        EncodeOptions options;
        options.quantize_bits = cases[c].bits;
        options.hierarchy_contexts = cases[c].mixed ? HierarchyContexts::mixed : HierarchyContexts::paper;
        options.chunks = cases[c].chunks;
        const std::vector<uint8_t> bytes = encode(*cases[c].h, options);
        DecodeOptions plain, lean;
        plain.max_level = lean.max_level = cases[c].max_level;
        lean.lean_memory = true;
        const Hierarchy expected = decode(bytes.data(), bytes.size(), plain);
        EXPECT_TRUE(identical(decode(bytes.data(), bytes.size(), lean), expected));
        EXPECT_EQ(expected.node_count(), cases[c].max_level < 0 ? cases[c].h->node_count() : 20u * (1 + 4 + 16 + 64 + 256));
    }
}

TEST(Codec, ProgressiveDecodingGivesEveryLevelMesh) {
    Hierarchy h(make_icosahedron());
    refine_randomly(h, 5000, 6, 21);
    const std::vector<uint8_t> bytes = encode(h);
    const Hierarchy expected = expected_decoding(h);
    for (int level = 0; level <= h.depth(); ++level) {
        DecodeOptions options;
        options.max_level = level;
        const Hierarchy part = decode(bytes.data(), bytes.size(), options);
        const LeafMesh got = extract_leaf_mesh(part), want = extract_leaf_mesh(expected, level);
        EXPECT_EQ(got.mesh.triangles, want.mesh.triangles) << level;
        ASSERT_EQ(got.mesh.positions.size(), want.mesh.positions.size()) << level;
        for (size_t i = 0; i < got.mesh.positions.size(); ++i) ASSERT_TRUE(got.mesh.positions[i] == want.mesh.positions[i]);
    }
}

TEST(Codec, BaseMeshesWithBoundaryHandlesAndComponents) {
    TriangleMesh two = make_torus(6, 5, 2.0, 0.7);
    const TriangleMesh square = make_square(3);
    const uint32_t offset = uint32_t(two.positions.size());
    for (Vec3 p : square.positions) two.positions.push_back(p + Vec3{10, 0, 0});
    for (Triangle t : square.triangles) two.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
    for (const TriangleMesh& mesh : {two, make_l_shape(2), make_torus(9, 7, 3.0, 1.0)}) {
        Hierarchy h(mesh);
        refine_randomly(h, 2000, 5, 4);
        const std::vector<uint8_t> bytes = encode(h);
        EXPECT_TRUE(identical(decode(bytes.data(), bytes.size()), expected_decoding(h)));
    }
}

TEST(Codec, EveryTruncationAndManyCorruptionsAreErrors) {
    Hierarchy h(make_torus(6, 5, 2.0, 0.7));
    refine_randomly(h, 800, 4, 8);
    const std::vector<uint8_t> bytes = encode(h);
    for (size_t length = 0; length < bytes.size(); ++length) {
        EXPECT_THROW(decode(bytes.data(), length), Error) << length;
    }
    Random random{77};
    int accepted = 0;
    for (int trial = 0; trial < 10000; ++trial) {
        std::vector<uint8_t> corrupt = bytes;
        const int flips = 1 + int(random.next() % 3);
        for (int f = 0; f < flips; ++f) corrupt[random.next() % corrupt.size()] ^= uint8_t(1u << (random.next() % 8));
        if (corrupt == bytes) continue;  // the same bit flipped twice
        const DecodeResult result = try_decode(corrupt.data(), corrupt.size());
        if (result.ok) ++accepted;
        else EXPECT_FALSE(result.error.empty());
    }
    EXPECT_EQ(accepted, 0) << "checksums catch every corruption of this size";
}

// A file still arriving: every prefix that holds the base mesh decodes to the levels whose blocks
// are complete, exactly as --level of the whole file; shorter prefixes are refused as truncated.
TEST(Codec, EveryPrefixDecodesPartiallyAsTheLevelsItHolds) {
    Hierarchy h(make_torus(6, 5, 2.0, 0.7));
    refine_randomly(h, 800, 4, 8);
    const LeafMesh leaf = extract_leaf_mesh(h);
    LeafNumbering reversed;  // any bijection will do: the numbering block must arrive whole too
    for (uint32_t v = 0; v < leaf.mesh.positions.size(); ++v) reversed.vertex.push_back(uint32_t(leaf.mesh.positions.size()) - 1 - v);
    for (uint32_t f = 0; f < leaf.mesh.triangles.size(); ++f) reversed.face.push_back(uint32_t(leaf.mesh.triangles.size()) - 1 - f);
    reversed.rotation.assign(leaf.mesh.triangles.size(), 0);
    EncodeOptions options;
    options.numbering = &reversed;
    const std::vector<uint8_t> bytes = encode(h, options);
    const FileInfo info = inspect(bytes.data(), bytes.size());
    ASSERT_GE(info.levels, 4);
    LeafNumbering full_numbering;
    const Hierarchy full = decode(bytes.data(), bytes.size(), {}, &full_numbering);
    ASSERT_FALSE(full_numbering.empty());

    std::vector<Hierarchy> at_level;
    for (int level = 0; level < info.levels; ++level) {
        DecodeOptions cut;
        cut.max_level = level;
        at_level.push_back(decode(bytes.data(), bytes.size(), cut));
    }
    size_t base_end = 0;
    for (const FileBlock& block : info.blocks)
        if (block.name == "base geometry") base_end = block.offset + block.size;
    ASSERT_GT(base_end, 0u);
    int complete_files = 0;
    for (size_t length = 0; length <= bytes.size(); ++length) {
        if (length < base_end) {
            try {
                decode_partial(bytes.data(), length);
                ADD_FAILURE() << "a prefix of " << length << " bytes cuts the base mesh but decoded";
            } catch (const Error& e) {
                EXPECT_TRUE(e.code() == ErrorCode::truncated || e.code() == ErrorCode::bad_magic) << length << ": " << e.what();
            }
            continue;
        }
        int arrived = 0;  // level blocks wholly inside the prefix
        bool numbering_arrived = false;
        for (const FileBlock& block : info.blocks) {
            if (block.offset + block.size > length) continue;
            if (block.level >= 0) ++arrived;
            if (block.name == "numbering") numbering_arrived = true;
        }
        const PartialDecode partial = decode_partial(bytes.data(), length);
        EXPECT_EQ(partial.levels, info.levels);
        if (arrived == info.levels) {
            ++complete_files;
            EXPECT_TRUE(partial.complete) << length;
            EXPECT_EQ(partial.level, info.levels - 1);
            EXPECT_TRUE(identical(partial.hierarchy, full)) << length;
            EXPECT_EQ(partial.numbering.vertex, numbering_arrived ? full_numbering.vertex : std::vector<uint32_t>{}) << length;
        } else {
            EXPECT_FALSE(partial.complete) << length;
            EXPECT_EQ(partial.level, arrived) << length;
            EXPECT_TRUE(identical(partial.hierarchy, at_level[size_t(arrived)])) << length;
            EXPECT_TRUE(partial.numbering.empty());
        }
    }
    EXPECT_GT(complete_files, 10);  // the numbering and end blocks arrive after the last level

    // A complete block that is damaged is an error, not a block still to come.
    size_t level0 = 0;
    for (const FileBlock& block : info.blocks)
        if (block.level == 0) level0 = block.offset;
    std::vector<uint8_t> damaged(bytes.begin(), bytes.end() - 1);
    damaged[level0 + 6] ^= 1;
    EXPECT_THROW(decode_partial(damaged.data(), damaged.size()), Error);
}

// The checksums stop the corruptions above at the container, so here each mutated block gets a
// valid checksum again: every payload parser (base connectivity and geometry, levels, metadata)
// and the checks between blocks see bit flips, overwritten, inserted and removed bytes, truncated
// and extended payloads, dropped and swapped blocks and flipped header flags. Each file must
// decode to a valid hierarchy or fail with a message, never crash (the sanitizer build runs this
// too). AMC_FUZZ_FILES scales the run for longer campaigns (200 mutations a file; default 16).
TEST(Codec, MutatedBlocksWithValidChecksumsAreErrorsOrValidHierarchies) {
    const char* files_env = std::getenv("AMC_FUZZ_FILES");
    const int files = files_env != nullptr ? std::max(1, std::atoi(files_env)) : 16;
    Random random{2026};
    uint64_t trials = 0, decoded = 0;
    for (int file = 0; file < files; ++file) {
        TriangleMesh base;
        switch (file % 4) {
            case 0: base = make_icosahedron(); break;
            case 1: base = make_torus(3 + int(random.next() % 5), 3 + int(random.next() % 5), 2.0, 0.7); break;
            case 2: base = make_square(1 + int(random.next() % 4)); break;
            default: base = make_l_shape(1 + int(random.next() % 3)); break;
        }
        Hierarchy h(base);
        refine_randomly(h, 50 + uint32_t(random.next() % 3000), 1 + int(random.next() % 6), random.next());
        EncodeOptions options;
        options.hierarchy = coder_options_from_switches(int(random.next() % kCoderSwitchCombinations));
        const int quantize_bits[] = {0, 0, 8, 12, 16, 24};
        options.quantize_bits = quantize_bits[random.next() % 6];
        if (file % 2 == 1) options.predictor = GeometryPredictor::normal_frame;  // geometry mode 3 in every level
        const std::vector<uint8_t> bytes = encode(h, options);
        BlockReader reader(bytes.data(), bytes.size());
        using Blocks = std::vector<std::pair<BlockType, std::vector<uint8_t>>>;
        Blocks blocks;
        Block block;
        while (reader.next(block)) {
            if (block.type != BlockType::end) blocks.push_back({block.type, {block.payload, block.payload + block.size}});
        }
        auto rewrite = [&reader](uint8_t flags, const Blocks& parts) {
            BlockWriter writer(reader.version(), flags);
            for (const auto& [type, payload] : parts) writer.add(type, payload);
            return writer.finish();
        };
        // Rewritten unchanged, the file is the same: the mutations below reach the payloads.
        ASSERT_TRUE(rewrite(reader.flags(), blocks) == bytes) << "file " << file;
        for (int trial = 0; trial < 200; ++trial) {
            auto mutated = blocks;
            uint8_t flags = reader.flags();
            if (random.next() % 20 == 0) flags = uint8_t(flags ^ (1u << (random.next() % 3)));
            const int mutations = 1 + int(random.next() % 4);
            for (int m = 0; m < mutations; ++m) {
                std::vector<uint8_t>& p = mutated[random.next() % mutated.size()].second;
                const size_t at = p.empty() ? 0 : random.next() % p.size();
                switch (random.next() % 7) {
                    case 0:
                    case 1:
                        if (!p.empty()) p[at] = uint8_t(p[at] ^ (1u << (random.next() % 8)));
                        break;
                    case 2:
                        if (!p.empty()) p[at] = uint8_t(random.next());
                        break;
                    case 3: p.resize(random.next() % (p.size() + 1)); break;
                    case 4:
                        for (int k = 1 + int(random.next() % 8); k > 0; --k) p.push_back(uint8_t(random.next()));
                        break;
                    case 5: p.insert(p.begin() + std::ptrdiff_t(at), uint8_t(random.next())); break;
                    default:
                        if (!p.empty()) {
                            const size_t n = std::min<size_t>(p.size() - at, 1 + random.next() % 4);
                            p.erase(p.begin() + std::ptrdiff_t(at), p.begin() + std::ptrdiff_t(at + n));
                        }
                        break;
                }
            }
            if (random.next() % 30 == 0 && mutated.size() > 1)
                mutated.erase(mutated.begin() + std::ptrdiff_t(random.next() % mutated.size()));
            if (random.next() % 30 == 0) std::swap(mutated[random.next() % mutated.size()], mutated[random.next() % mutated.size()]);
            const std::vector<uint8_t> corrupt = rewrite(flags, mutated);
            DecodeOptions decode_options;
            decode_options.max_nodes = 1u << 20;
            const DecodeResult result = try_decode(corrupt.data(), corrupt.size(), decode_options);
            ++trials;
            if (result.ok) {
                ++decoded;
                ASSERT_EQ(check_invariants(result.hierarchy), "") << "file " << file << ", trial " << trial;
            } else {
                ASSERT_FALSE(result.error.empty()) << "file " << file << ", trial " << trial;
                ASSERT_EQ(result.error.find("checksum"), std::string::npos)
                    << "every block was checksummed anew: " << result.error;
            }
        }
    }
    EXPECT_LT(decoded, trials / 10) << "most mutations are caught";
}

// A producer whose diagonals follow a rule of absolute local indices: the file keeps the input's
// local vertex order of the base triangles (their rotations cost log2 3 bits each) instead of
// paying an orientation bit for about half the two-hanging-node leaves.
// The one LEB128 reader and its limits: 64 bits in payloads, 63 (9 bytes) for the hierarchy
// stream's symbol count (FORMAT.md 2).
TEST(Codec, VarintsAreReadUpToTheirLimit) {
    auto read = [](std::vector<uint8_t> bytes, int max_bits, uint64_t& value) {
        size_t pos = 0;
        return read_varint(bytes.data(), bytes.size(), pos, value, max_bits);
    };
    uint64_t value = 0;
    std::vector<uint8_t> max64(9, 0xff);
    max64.push_back(0x01);
    EXPECT_EQ(read(max64, 64, value), VarintRead::ok);
    EXPECT_EQ(value, UINT64_MAX);
    max64.back() = 0x02;
    EXPECT_EQ(read(max64, 64, value), VarintRead::too_long);
    max64.back() = 0x81;
    max64.push_back(0x00);
    EXPECT_EQ(read(max64, 64, value), VarintRead::too_long);
    EXPECT_EQ(read({0x80, 0x80}, 64, value), VarintRead::truncated);
    std::vector<uint8_t> max63(8, 0xff);
    max63.push_back(0x7f);
    EXPECT_EQ(read(max63, 63, value), VarintRead::ok);
    EXPECT_EQ(value, UINT64_MAX >> 1);
    max63.back() = 0xff;
    max63.push_back(0x00);
    EXPECT_EQ(read(max63, 63, value), VarintRead::too_long);
    std::vector<uint8_t> out;
    for (uint64_t v : {uint64_t(0), uint64_t(127), uint64_t(128), uint64_t(1) << 35, UINT64_MAX}) {
        out.clear();
        put_varint(out, v);
        EXPECT_EQ(read(out, 64, value), VarintRead::ok);
        EXPECT_EQ(value, v);
    }
    // The hierarchy stream's header refuses a tenth byte of its symbol count.
    HierarchyStreamHeader header;
    std::vector<uint8_t> stream{uint8_t(coder_switches(HierarchyCoderOptions{})), 0, 0};
    stream.insert(stream.end(), max63.begin(), max63.end());
    try {
        read_hierarchy_stream_header(stream.data(), stream.size(), header);
        ADD_FAILURE() << "a 10-byte symbol count was read";
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), ErrorCode::corrupt);
        EXPECT_NE(std::string(e.what()).find("symbol count is too long"), std::string::npos) << e.what();
    }
}

TEST(Codec, DiagonalRulesOfAbsoluteLocalIndicesStayCheap) {
    Hierarchy h(make_torus(12, 10, 2.0, 0.7));
    refine_randomly(h, 20000, 6, 12);
    for (NodeId n : h.leaves()) {
        if (h.hanging_node_count(n) != 2) continue;
        int u = 0;
        while (h.has_hanging_node(n, u)) ++u;
        h.set_diagonal_flipped(n, diagonal_flag_by_rule(DiagonalRule::lower_local_index, u));
    }
    EncodeStats stats;
    EncodeOptions with_statistics;
    with_statistics.hierarchy_statistics = true;
    const std::vector<uint8_t> bytes = encode(h, with_statistics, &stats);
    EXPECT_GT(stats.hierarchy.coded, 0u);
    EXPECT_EQ(stats.hierarchy.diagonal_exceptions, 0u);
    EXPECT_TRUE(identical(decode(bytes.data(), bytes.size()), in_decoder_order(h)));
    Hierarchy by_default = h;
    for (NodeId n : by_default.leaves()) by_default.set_diagonal_flipped(n, false);
    EncodeStats default_stats;
    encode(by_default, {}, &default_stats);
    EXPECT_LT(double(stats.total_bytes), double(default_stats.total_bytes) + 0.2 * h.root_count() + 8)
        << "at most the rotations (1.6 bits per base triangle) more than the default rule";
}

std::string decode_error(const std::vector<uint8_t>& bytes) {
    try {
        decode(bytes.data(), bytes.size());
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

// A newer version is refused as such, before anything after the version byte is looked at (the
// header checksum no longer matches here); version 0 was never written.
TEST(Codec, NewerVersionIsRefusedClearly) {
    Hierarchy h(make_icosahedron());
    std::vector<uint8_t> bytes = encode(h);
    ASSERT_EQ(bytes[4], kBaseRawSideVersion);  // bit-exact: its base's raw bits in a side stream
    bytes[4] = kNewestVersion + 1;
    const std::string newer = "unsupported .amc version " + std::to_string(kNewestVersion + 1) +
                              " (newer than this build, which reads versions 1 to " + std::to_string(kNewestVersion) + ")";
    EXPECT_EQ(decode_error(bytes), newer);
    bytes[4] = 0;
    EXPECT_EQ(decode_error(bytes), "unknown .amc version 0");
    bytes[4] = kBaseRawSideVersion;
    EXPECT_EQ(decode_error(bytes), "");
}

TEST(Codec, InspectListsTheBlocks) {
    Hierarchy h(make_icosahedron());
    refine_randomly(h, 500, 4, 2);
    const std::vector<uint8_t> bytes = encode(h);
    const FileInfo info = inspect(bytes.data(), bytes.size());
    ASSERT_GE(info.blocks.size(), 5u);
    EXPECT_EQ(info.blocks.front().name, "metadata");
    EXPECT_EQ(info.blocks.back().name, "end");
    uint64_t total = 12;  // the file header
    for (const FileBlock& b : info.blocks) total += b.size;
    EXPECT_EQ(total, bytes.size());
    EXPECT_EQ(info.nodes, h.node_count());
    EXPECT_EQ(info.levels, h.depth() + 1);
}

}  // namespace
}  // namespace amc
