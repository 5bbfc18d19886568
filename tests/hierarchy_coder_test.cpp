// The hierarchy coder: exact round trips under every combination of switches, exhaustive small
// hierarchies, known answers (uniform meshes cost nothing), entropy bound, corrupt streams.
#include "coding/hierarchy/coder_switches.h"
#include "coding/geometry/geometry_prediction.h"
#include "coding/hierarchy/hierarchy_level_coder.h"
#include "hierarchy_checks.h"

#include <amc/hierarchy_coder.h>
#include <amc/refinement.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <utility>

namespace amc {
namespace {

using testing::Random;

HierarchyCoderOptions options_from_bits(int bits) { return coder_options_from_switches(bits); }
constexpr int kOptionCombinations = kCoderSwitchCombinations;

// Same base, forest and effective diagonals (positions are not part of this stream).
bool same_connectivity(const Hierarchy& a, const Hierarchy& b) {
    const std::vector<NodeId> oa = a.breadth_first_order(), ob = b.breadth_first_order();
    if (oa.size() != ob.size() || a.base().triangles != b.base().triangles) return false;
    for (size_t i = 0; i < oa.size(); ++i) {
        if (a.is_leaf(oa[i]) != b.is_leaf(ob[i])) return false;
        if (a.is_leaf(oa[i]) && a.hanging_node_count(oa[i]) == 2 &&
            a.diagonal_flipped(oa[i]) != b.diagonal_flipped(ob[i]))
            return false;
    }
    return extract_leaf_mesh(a).mesh.triangles == extract_leaf_mesh(b).mesh.triangles;
}

::testing::AssertionResult round_trips(const Hierarchy& h, const HierarchyCoderOptions& o) {
    const std::vector<uint8_t> bytes = encode_hierarchy(h, o);
    const Hierarchy back = decode_hierarchy(h.base(), bytes.data(), bytes.size());
    if (!same_connectivity(h, back)) return ::testing::AssertionFailure() << "decoded hierarchy differs";
    return ::testing::AssertionSuccess();
}

// Random hierarchies with random diagonals: half follow one of the rules, half are random.
Hierarchy random_hierarchy(uint64_t seed) {
    Random random{seed};
    const auto meshes = testing::fixture_meshes();
    Hierarchy h(meshes[random.next() % meshes.size()].mesh);
    const uint32_t leaves = h.root_count() + uint32_t(random.next() % 300);
    refine_randomly(h, leaves, 1 + int(random.next() % 5), seed, (random.next() % 3) * 0.15);
    const int mode = int(random.next() % 6);
    for (NodeId n : h.leaves()) {
        if (h.hanging_node_count(n) != 2) continue;
        int u = 0;
        while (h.has_hanging_node(n, u)) ++u;
        const bool flag = mode < kDiagonalRuleCount ? diagonal_flag_by_rule(DiagonalRule(mode), u)
                                                    : bool(random.next() % 2);
        h.set_diagonal_flipped(n, flag);
    }
    return h;
}

TEST(HierarchyCoder, TenThousandRandomHierarchiesUnderEverySwitchCombination) {
    uint64_t round_trips_done = 0;
    for (uint64_t seed = 1; seed <= 10000; ++seed) {
        const Hierarchy h = random_hierarchy(seed);
        // Every hierarchy under the full method and one rotating combination; the first 300
        // under all 64 combinations.
        ASSERT_TRUE(round_trips(h, {})) << "seed " << seed;
        ASSERT_TRUE(round_trips(h, options_from_bits(int(seed % kOptionCombinations)))) << "seed " << seed;
        round_trips_done += 2;
        if (seed <= 300) {
            for (int bits = 0; bits < kOptionCombinations; ++bits) {
                ASSERT_TRUE(round_trips(h, options_from_bits(bits))) << "seed " << seed << " switches " << bits;
                ++round_trips_done;
            }
        }
    }
    EXPECT_EQ(round_trips_done, 20000u + 300u * 64u);
}

// Every balanced, closed hierarchy of one triangle up to depth 3 and of two triangles up to
// depth 2, found by deciding every node breadth-first (each choice replayed on a fresh copy).
void enumerate(const Hierarchy& h, std::vector<NodeId> level, size_t index, int depth_left,
               std::vector<Hierarchy>& out) {
    if (index == level.size()) {
        for (NodeId n : level) {
            if (h.is_leaf(n) && h.hanging_node_count(n) == 3) return;  // closure violated
        }
        std::vector<NodeId> next;
        for (NodeId n : level) {
            if (!h.is_leaf(n)) {
                for (int k = 0; k < 4; ++k) next.push_back(h.child(n, k));
            }
        }
        if (next.empty() || depth_left == 0) {
            if (depth_left == 0 && !next.empty()) return;
            out.push_back(h);
            return;
        }
        enumerate(h, next, 0, depth_left - 1, out);
        return;
    }
    enumerate(h, level, index + 1, depth_left, out);  // leave level[index] a leaf
    if (depth_left > 0 && h.can_split(level[index])) {
        Hierarchy refined = h;
        refined.split(level[index]);
        enumerate(refined, level, index + 1, depth_left, out);
    }
}

TEST(HierarchyCoder, ExhaustiveSmallHierarchies) {
    TriangleMesh triangle;
    triangle.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    triangle.triangles = {{0, 1, 2}};
    TriangleMesh square = make_square(1);
    std::vector<Hierarchy> all;
    enumerate(Hierarchy(triangle), {0}, 0, 3, all);
    const size_t triangle_count = all.size();
    enumerate(Hierarchy(square), {0, 1}, 0, 2, all);
    EXPECT_GT(triangle_count, 100u);
    EXPECT_GT(all.size() - triangle_count, 100u);
    for (size_t index = 0; index < all.size(); ++index) {
        const Hierarchy& h = all[index];
        ASSERT_EQ(check_invariants(h), "");
        // With every diagonal choice of its two-hanging-node leaves (up to 2^3 of them), and once under a
        // rotating switch combination.
        std::vector<NodeId> two;
        for (NodeId n : h.leaves()) {
            if (h.hanging_node_count(n) == 2) two.push_back(n);
        }
        const uint32_t choices = two.size() > 3 ? 8 : 1u << two.size();
        for (uint32_t c = 0; c < choices; ++c) {
            Hierarchy variant = h;
            for (size_t i = 0; i < two.size(); ++i) variant.set_diagonal_flipped(two[i], (c >> (i % 3)) & 1);
            ASSERT_TRUE(round_trips(variant, options_from_bits(63)));
        }
        ASSERT_TRUE(round_trips(h, options_from_bits(int(index % kOptionCombinations))));
    }
    std::printf("exhaustive: %zu hierarchies of a triangle (depth <= 3), %zu of a square (depth <= 2)\n",
                triangle_count, all.size() - triangle_count);
}

TEST(HierarchyCoder, UniformMeshCodesNoSymbol) {
    for (const auto& [name, mesh] : testing::fixture_meshes()) {
        for (int levels = 0; levels <= 4; ++levels) {
            Hierarchy h(mesh);
            refine_uniformly(h, levels);
            HierarchyCodeStats stats;
            const std::vector<uint8_t> bytes = encode_hierarchy(h, {}, &stats);
            EXPECT_EQ(stats.coded, 0u) << name;
            EXPECT_EQ(stats.uniform_levels, levels) << name;
            EXPECT_EQ(stats.payload_bytes, 0u) << name;
            EXPECT_EQ(bytes.size(), 9u) << name << ": magic, version, switches, U, rule, symbol count 0";
            const Hierarchy back = decode_hierarchy(h.base(), bytes.data(), bytes.size());
            EXPECT_TRUE(identical(h, back)) << name;
        }
    }
}

TEST(HierarchyCoder, SymbolAccountingAddsUp) {
    for (uint64_t seed = 1; seed <= 50; ++seed) {
        const Hierarchy h = random_hierarchy(seed);
        HierarchyCodeStats s;
        encode_hierarchy(h, {}, &s);
        EXPECT_EQ(s.nodes, h.node_count());
        EXPECT_EQ(s.culled_uniform + s.culled_one_regularity + s.culled_hanging_nodes + s.truncated + s.coded, s.nodes);
        uint64_t grouped = 0;
        for (const ContextGroupStats& g : s.groups) grouped += g.symbols;
        EXPECT_EQ(grouped, s.coded);
        EXPECT_EQ(s.groups[context_group_index(3, 0, 0)].symbols, 0u) << "(3,0,0) is always culled";
    }
}

TEST(HierarchyCoder, DiagonalsOfAnyLocalIndexRuleAreFree) {
    Hierarchy h(make_torus(6, 5, 2.0, 0.7));
    refine_randomly(h, 3000, 5, 17);
    for (int rule = 0; rule < kDiagonalRuleCount; ++rule) {
        for (NodeId n : h.leaves()) {
            if (h.hanging_node_count(n) != 2) continue;
            int u = 0;
            while (h.has_hanging_node(n, u)) ++u;
            h.set_diagonal_flipped(n, diagonal_flag_by_rule(DiagonalRule(rule), u));
        }
        HierarchyCodeStats s;
        const std::vector<uint8_t> bytes = encode_hierarchy(h, {}, &s);
        EXPECT_GT(s.two_hanging_leaves, 50u);
        EXPECT_EQ(s.diagonal_exceptions, 0u) << "rule " << rule;
        EXPECT_FALSE(s.orientation_coded);
        EXPECT_EQ(s.orientation_bits, 0.0);
        const Hierarchy back = decode_hierarchy(h.base(), bytes.data(), bytes.size());
        EXPECT_TRUE(same_connectivity(h, back));
    }
    // One exception: orientation bits are coded, with their own model, and cost little.
    NodeId exception = kNoNode;
    for (NodeId n : h.leaves()) {
        if (h.hanging_node_count(n) == 2) exception = n;
    }
    h.set_diagonal_flipped(exception, !h.diagonal_flipped(exception));
    HierarchyCodeStats s;
    const std::vector<uint8_t> bytes = encode_hierarchy(h, {}, &s);
    EXPECT_EQ(s.diagonal_exceptions, 1u);
    EXPECT_TRUE(s.orientation_coded);
    EXPECT_LT(s.orientation_bits, 40.0);
    EXPECT_TRUE(same_connectivity(h, decode_hierarchy(h.base(), bytes.data(), bytes.size())));
}

TEST(HierarchyCoder, CodeSizeApproachesConditionalEntropy) {
    Hierarchy h(make_bumpy_sphere(0));
    refine_randomly(h, 200000, 8, 5);
    HierarchyCodeStats s;
    const std::vector<uint8_t> bytes = encode_hierarchy(h, {}, &s);
    const double bound_bytes = s.conditional_entropy_bits / 8 + s.header_bytes;
    EXPECT_LT(double(bytes.size()), 1.01 * bound_bytes) << "within 1% of H(X|context) plus header";
    EXPECT_NEAR(double(s.payload_bytes) * 8, s.adaptive_code_bits, 0.005 * s.adaptive_code_bits + 64);
}

TEST(HierarchyCoder, ContextsAndImprovedTraversalPayOff) {
    const Hierarchy h = make_l_shape_model(9);
    HierarchyCodeStats full, no_context, naive;
    HierarchyCoderOptions o;
    encode_hierarchy(h, o, &full);
    o.use_contexts = false;
    encode_hierarchy(h, o, &no_context);
    o.use_contexts = true;
    o.traversal = Traversal::naive;
    encode_hierarchy(h, o, &naive);
    EXPECT_LT(full.payload_bytes, no_context.payload_bytes);
    EXPECT_LT(full.payload_bytes, naive.payload_bytes);
    EXPECT_LE(full.groups[context_group_index(0, 0, 3)].symbols, 4u) << "one start per connected region";
}

TEST(HierarchyCoder, ProgressiveDecodingStopsAfterAnyLevel) {
    Hierarchy h(make_icosahedron());
    refine_randomly(h, 20000, 7, 23);
    const std::vector<uint8_t> bytes = encode_hierarchy(h);
    for (int level = 0; level <= h.depth(); ++level) {
        HierarchyDecodeOptions options;
        options.max_level = level;
        const Hierarchy part = decode_hierarchy(h.base(), bytes.data(), bytes.size(), options);
        EXPECT_LE(part.depth(), level);
        EXPECT_EQ(extract_leaf_mesh(part).mesh.triangles, extract_leaf_mesh(h, level).mesh.triangles) << level;
    }
}

TEST(HierarchyCoder, EveryTruncationAndRandomCorruptionIsSafe) {
    Hierarchy h(make_torus(6, 5, 2.0, 0.7));
    refine_randomly(h, 2000, 6, 31);
    const std::vector<uint8_t> bytes = encode_hierarchy(h);
    HierarchyDecodeOptions options;
    options.max_nodes = 1u << 20;
    uint64_t errors = 0, valid = 0;
    for (size_t length = 0; length < bytes.size(); ++length) {
        try {
            const Hierarchy back = decode_hierarchy(h.base(), bytes.data(), length, options);
            EXPECT_EQ(check_invariants(back), "");
            ++valid;
        } catch (const Error&) {
            ++errors;
        }
    }
    Random random{99};
    for (int trial = 0; trial < 5000; ++trial) {
        std::vector<uint8_t> corrupt = bytes;
        const int flips = 1 + int(random.next() % 4);
        for (int f = 0; f < flips; ++f) corrupt[random.next() % corrupt.size()] ^= uint8_t(1u << (random.next() % 8));
        try {
            const Hierarchy back = decode_hierarchy(h.base(), corrupt.data(), corrupt.size(), options);
            EXPECT_EQ(check_invariants(back), "");
            ++valid;
        } catch (const Error&) {
            ++errors;
        }
    }
    EXPECT_GT(errors, bytes.size() / 2) << "most truncations are detected";
}

// One decoder and one target hierarchy for stream after stream of other bases, sizes, switches
// and depths, corrupt streams among them: each result is exactly decode_hierarchy's.
TEST(HierarchyCoder, ReusedDecoderMatchesFreshDecodes) {
    HierarchyDecoder decoder;
    Hierarchy out;
    Random random{5};
    int decoded = 0, refused = 0;
    for (uint64_t seed = 1; seed <= 400; ++seed) {
        const Hierarchy h = random_hierarchy(seed);
        std::vector<uint8_t> bytes = encode_hierarchy(h, options_from_bits(int(random.next() % kOptionCombinations)));
        HierarchyDecodeOptions options;
        if (seed % 5 == 0) options.max_level = int(random.next() % 4);
        if (seed % 7 == 0) bytes.resize(random.next() % (bytes.size() + 1));
        if (seed % 11 == 0 && !bytes.empty()) bytes[random.next() % bytes.size()] ^= uint8_t(1u << (random.next() % 8));
        Hierarchy fresh;
        bool fresh_ok = true;
        try {
            fresh = decode_hierarchy(h.base(), bytes.data(), bytes.size(), options);
        } catch (const Error&) {
            fresh_ok = false;
        }
        try {
            decoder.decode(h.base(), bytes.data(), bytes.size(), out, options);
            ASSERT_TRUE(fresh_ok) << "seed " << seed;
            ASSERT_TRUE(identical(out, fresh)) << "seed " << seed;
            ASSERT_EQ(check_invariants(out), "") << "seed " << seed;
            ++decoded;
        } catch (const Error&) {
            ASSERT_FALSE(fresh_ok) << "seed " << seed;
            ASSERT_EQ(check_invariants(out), "") << "seed " << seed;
            ++refused;
        }
    }
    EXPECT_GT(decoded, 300);
    EXPECT_GT(refused, 10);
}

// Every new vertex of `h` lies where `place` puts it from its edge's end points.
::testing::AssertionResult midpoints_placed(const Hierarchy& h, Vec3 (*place)(Vec3, Vec3)) {
    for (NodeId n : h.breadth_first_order()) {
        if (h.is_leaf(n)) continue;
        for (int e = 0; e < 3; ++e) {
            const Vec3 expected = place(h.position(h.vertex(n, e)), h.position(h.vertex(n, (e + 1) % 3)));
            if (!(h.position(h.midpoint(n, e)) == expected))
                return ::testing::AssertionFailure() << "midpoint of edge " << e << " of node " << n;
        }
    }
    return ::testing::AssertionSuccess();
}

Vec3 lifted(Vec3 a, Vec3 b) { return 0.5 * (a + b) + Vec3{0, 0, 0.125}; }
Vec3 to_single(Vec3 p) { return {double(float(p.x)), double(float(p.y)), double(float(p.z))}; }

// The decoder builds each level in one pass (Hierarchy::split_level), with one loop for each kind
// of vertex placer: the default midpoint of double and of single precision bases, and any other.
TEST(HierarchyCoder, DecodedVerticesArePlacedByTheHierarchysPlacer) {
    for (uint64_t seed = 1; seed <= 30; ++seed) {
        const Hierarchy h = random_hierarchy(seed);
        const bool single = seed % 2 == 0;
        TriangleMesh base = h.base();
        base.single_precision = single;
        if (single) {
            for (Vec3& p : base.positions) p = to_single(p);
        }
        const std::vector<uint8_t> bytes = encode_hierarchy(h, HierarchyCoderOptions{});
        const Hierarchy decoded = decode_hierarchy(base, bytes.data(), bytes.size());
        ASSERT_TRUE(same_connectivity(h, decoded)) << "seed " << seed;
        if (single) {
            EXPECT_TRUE(midpoints_placed(decoded, [](Vec3 a, Vec3 b) { return to_single(0.5 * (a + b)); }))
                << "seed " << seed;
        } else {
            EXPECT_TRUE(midpoints_placed(decoded, [](Vec3 a, Vec3 b) { return 0.5 * (a + b); })) << "seed " << seed;
        }
        // Another placer, symmetric in its end points as every placer must be.
        HierarchyStreamHeader header;
        const size_t header_size = read_standalone_stream_header(bytes.data(), bytes.size(), header);
        HierarchyLevelDecoder coder(base, header, UINT64_MAX);
        coder.hierarchy().set_vertex_placer([](void*, Vec3 a, Vec3 b) { return lifted(a, b); }, nullptr);
        ArithmeticDecoder decoder(bytes.data() + header_size, bytes.size() - header_size);
        while (!coder.done()) coder.decode_level(decoder);
        ASSERT_TRUE(same_connectivity(h, coder.hierarchy())) << "seed " << seed;
        EXPECT_TRUE(midpoints_placed(coder.hierarchy(), lifted)) << "seed " << seed;
    }
}

// Every frame corner of the last decode_level's new vertices (new_vertex_corners()), walked in
// runs of 1, 2, ... 64 vertices, so that runs end inside a parent's edges; asking past them throws.
std::vector<FrameCorners> walked_corners(const HierarchyLevelDecoder& coder) {
    NewVertexCorners walk = coder.new_vertex_corners();
    std::vector<FrameCorners> out;
    for (size_t run = 1; out.size() < walk.size(); run = run % NewVertexCorners::kRun + 1) {
        const size_t n = std::min(run, walk.size() - out.size());
        const FrameCorners* corners = walk.next(n);
        out.insert(out.end(), corners, corners + n);
    }
    EXPECT_THROW(walk.next(1), Error);
    return out;
}

// The complete decoder's listing (set_new_vertex_listing): each new vertex's frame corners as
// frame_corners reads them in the built hierarchy, ids in listing order, positions left at zero
// for the geometry; the same hierarchy as the decoder that lists (node, edge) pairs.
TEST(HierarchyCoder, ListedNewVerticesCarryTheirFrameCorners) {
    size_t listed = 0, with_far_corner = 0;
    for (uint64_t seed = 1; seed <= 30; ++seed) {
        const Hierarchy h = random_hierarchy(seed);
        const std::vector<uint8_t> bytes = encode_hierarchy(h, HierarchyCoderOptions{});
        HierarchyStreamHeader header;
        const size_t header_size = read_standalone_stream_header(bytes.data(), bytes.size(), header);
        HierarchyLevelDecoder pairs(h.base(), header, UINT64_MAX), corners(h.base(), header, UINT64_MAX);
        corners.set_new_vertex_listing(true, false);
        ArithmeticDecoder pairs_decoder(bytes.data() + header_size, bytes.size() - header_size);
        ArithmeticDecoder corners_decoder(bytes.data() + header_size, bytes.size() - header_size);
        while (!pairs.done()) {
            ASSERT_FALSE(corners.done());
            pairs.decode_level(pairs_decoder);
            corners.decode_level(corners_decoder);
            const Hierarchy& a = pairs.hierarchy();
            const Hierarchy& b = corners.hierarchy();
            ASSERT_TRUE(corners.new_vertices().empty());
            ASSERT_EQ(corners.new_vertex_count(), pairs.new_vertices().size()) << "seed " << seed;
            ASSERT_EQ(corners.new_vertex_first() + corners.new_vertex_count(), b.positions().size());
            const std::vector<FrameCorners> walked = walked_corners(corners);
            ASSERT_EQ(walked.size(), corners.new_vertex_count());
            for (size_t k = 0; k < corners.new_vertex_count(); ++k) {
                const auto [n, e] = pairs.new_vertices()[k];
                const FrameCorners expected = frame_corners(a, n, e), got = walked[k];
                ASSERT_TRUE(expected.a == got.a && expected.b == got.b && expected.c == got.c && expected.d == got.d)
                    << "seed " << seed << ", vertex " << k;
                ASSERT_EQ(a.midpoint(n, e), corners.new_vertex_first() + k) << "seed " << seed;
                const Vec3 p = b.position(corners.new_vertex_first() + VertexId(k));
                ASSERT_TRUE(p.x == 0 && p.y == 0 && p.z == 0) << "seed " << seed << ", vertex " << k;
                ++listed;
                with_far_corner += got.d != kNoVertex;
            }
        }
        ASSERT_TRUE(corners.done());
        EXPECT_TRUE(same_connectivity(pairs.hierarchy(), corners.hierarchy())) << "seed " << seed;
    }
    // Vertices inside the mesh (a neighbour across the edge) and on its boundary.
    EXPECT_GT(with_far_corner, listed / 2);
    EXPECT_LT(with_far_corner, listed);
}

// split_level reserves a level's vertex room by the level decoder's count (LevelSplits::
// new_vertex_count, derive_next_level's) instead of counting again: the count is the number of
// vertices the level's splits make, level by level, listed or not. With appended positions
// (set_new_vertex_listing's third argument) the level leaves them to the caller, who appends
// exactly that many.
TEST(HierarchyCoder, LevelDecoderCountsTheVerticesSplitLevelMakes) {
    for (uint64_t seed = 1; seed <= 30; ++seed) {
        const Hierarchy h = random_hierarchy(seed);
        const std::vector<uint8_t> bytes = encode_hierarchy(h, HierarchyCoderOptions{});
        HierarchyStreamHeader header;
        const size_t header_size = read_standalone_stream_header(bytes.data(), bytes.size(), header);
        HierarchyLevelDecoder coder(h.base(), header, UINT64_MAX);
        const bool appended = seed % 3 == 0;
        coder.set_new_vertex_listing(seed % 2 == 1 || appended, seed % 2 == 0 && !appended, appended);
        ArithmeticDecoder decoder(bytes.data() + header_size, bytes.size() - header_size);
        while (!coder.done()) {
            const size_t before = coder.hierarchy().positions().size();
            coder.decode_level(decoder);
            if (appended) {
                ASSERT_EQ(coder.hierarchy().positions().size(), before) << "seed " << seed;
                ASSERT_EQ(coder.new_vertex_first(), before) << "seed " << seed;
                const std::vector<Vec3> made(coder.new_vertex_count(), Vec3{1, 2, 3});
                HierarchyBuilder::append_positions(coder.hierarchy(), made.data(), made.size(), true);
            }
            ASSERT_EQ(coder.vertex_count(), coder.hierarchy().vertex_count()) << "seed " << seed;
            ASSERT_EQ(coder.vertex_count(), coder.hierarchy().positions().size()) << "seed " << seed;
            ASSERT_EQ(coder.hierarchy().positions().size() - before, coder.new_vertex_count()) << "seed " << seed;
        }
        EXPECT_EQ(coder.hierarchy().vertex_count(), h.vertex_count()) << "seed " << seed;
    }
}

// A lean decoder (set_lean) gives its working memory back as soon as nothing reads it any more;
// anything given back too early would read as zeros and build wrong levels. Every level decoded
// lean against a plain decoder, listing corners and (node, edge) pairs, on hierarchies whose
// levels span many pages of working memory.
TEST(HierarchyCoder, LeanDecoderBuildsWhatThePlainOneBuilds) {
    for (uint64_t seed = 1; seed <= 4; ++seed) {
        const Hierarchy h = testing::projected_sphere(60000, 7, seed);
        const std::vector<uint8_t> bytes = encode_hierarchy(h, HierarchyCoderOptions{});
        HierarchyStreamHeader header;
        const size_t header_size = read_standalone_stream_header(bytes.data(), bytes.size(), header);
        HierarchyLevelDecoder plain(h.base(), header, UINT64_MAX), lean(h.base(), header, UINT64_MAX);
        const bool listed = seed % 2 == 1;
        plain.set_new_vertex_listing(listed, true);
        lean.set_new_vertex_listing(listed, true);
        ArithmeticDecoder plain_decoder(bytes.data() + header_size, bytes.size() - header_size);
        ArithmeticDecoder lean_decoder(bytes.data() + header_size, bytes.size() - header_size);
        size_t largest_level = 0;
        while (!plain.done()) {
            ASSERT_FALSE(lean.done());
            largest_level = std::max(largest_level, plain.level_size());
            lean.set_lean(true);
            plain.decode_level(plain_decoder);
            lean.decode_level(lean_decoder);
            ASSERT_EQ(lean.new_vertex_count(), plain.new_vertex_count()) << "seed " << seed;
            ASSERT_TRUE(lean.new_vertices() == plain.new_vertices()) << "seed " << seed;
            const std::vector<FrameCorners> plain_corners = listed ? walked_corners(plain) : std::vector<FrameCorners>{};
            const std::vector<FrameCorners> lean_corners = listed ? walked_corners(lean) : std::vector<FrameCorners>{};
            ASSERT_EQ(plain_corners.size(), lean_corners.size());
            for (size_t k = 0; listed && k < plain.new_vertex_count(); ++k) {
                const FrameCorners a = plain_corners[k], b = lean_corners[k];
                ASSERT_TRUE(a.a == b.a && a.b == b.b && a.c == b.c && a.d == b.d) << "seed " << seed << ", vertex " << k;
            }
        }
        ASSERT_TRUE(lean.done());
        lean.finish();
        EXPECT_TRUE(identical(plain.hierarchy(), lean.hierarchy())) << "seed " << seed;
        EXPECT_TRUE(same_connectivity(h, lean.hierarchy())) << "seed " << seed;
        EXPECT_GT(largest_level, size_t(20000)) << "seed " << seed;  // links of many pages
    }
}

// A single-stream decoder (set_single_stream, the default decode's) frees working memory as soon
// as no later level reads it: before the last level (the stored symbols used up), and wherever a
// level shrinks below half its scratch. Anything freed too early is read after its free (the
// sanitizer builds catch it) or overwritten, and builds wrong levels. Every level against a plain
// decoder, listing corners and (node, edge) pairs: a remesh, a uniform sphere (its last level
// decided without symbols) and the graded L-shape, whose levels shrink past the finest region.
TEST(HierarchyCoder, SingleStreamDecoderBuildsWhatThePlainOneBuilds) {
    Hierarchy sphere(make_icosahedron());
    refine_uniformly(sphere, 5);
    const Hierarchy cases[] = {testing::projected_sphere(30000, 7, 3), std::move(sphere), make_l_shape_model(9)};
    for (size_t c = 0; c < std::size(cases); ++c) {
        const Hierarchy& h = cases[c];
        const std::vector<uint8_t> bytes = encode_hierarchy(h, HierarchyCoderOptions{});
        HierarchyStreamHeader header;
        const size_t header_size = read_standalone_stream_header(bytes.data(), bytes.size(), header);
        for (const bool listed : {false, true}) {
            SCOPED_TRACE("case " + std::to_string(c) + (listed ? ", listed" : ""));
            HierarchyLevelDecoder plain(h.base(), header, UINT64_MAX), single(h.base(), header, UINT64_MAX);
            plain.set_new_vertex_listing(listed, true);
            single.set_new_vertex_listing(listed, true);
            single.set_single_stream(true);
            ArithmeticDecoder plain_decoder(bytes.data() + header_size, bytes.size() - header_size);
            ArithmeticDecoder single_decoder(bytes.data() + header_size, bytes.size() - header_size);
            std::vector<size_t> level_sizes;
            while (!plain.done()) {
                ASSERT_FALSE(single.done());
                level_sizes.push_back(plain.level_size());
                plain.decode_level(plain_decoder);
                single.decode_level(single_decoder);
                ASSERT_EQ(single.new_vertex_count(), plain.new_vertex_count());
                ASSERT_TRUE(single.new_vertices() == plain.new_vertices());
                if (!listed) continue;
                const std::vector<FrameCorners> a = walked_corners(plain), b = walked_corners(single);
                ASSERT_EQ(a.size(), b.size());
                for (size_t k = 0; k < a.size(); ++k)
                    ASSERT_TRUE(a[k].a == b[k].a && a[k].b == b[k].b && a[k].c == b[k].c && a[k].d == b[k].d) << "vertex " << k;
            }
            ASSERT_TRUE(single.done());
            single.finish();
            EXPECT_TRUE(identical(plain.hierarchy(), single.hierarchy()));
            EXPECT_TRUE(same_connectivity(h, single.hierarchy()));
            if (c == 2) {  // the L-shape's levels shrink: some level less than half the one two before
                bool shrinks = false;
                for (size_t l = 2; l < level_sizes.size(); ++l) shrinks |= 2 * level_sizes[l] < level_sizes[l - 2];
                EXPECT_TRUE(shrinks);
            }
        }
    }
}

#if defined(__linux__)
// What set_lean relies on: the pages of working memory given back hold nothing of what was
// written there (they read as zeros), and the elements before them are kept.
TEST(HierarchyCoder, ReleasedWorkingMemoryIsGivenBack) {
    constexpr size_t n = size_t(1) << 20, kept = n / 2;
    ScratchArray<uint32_t> scratch;
    uint32_t* words = scratch.reserve(n);
    std::fill(words, words + n, 0xffffffffu);
    scratch.release_from(kept);
    EXPECT_TRUE(std::all_of(words, words + kept, [](uint32_t w) { return w == 0xffffffffu; }));
    const size_t page_words = 65536 / sizeof(uint32_t);  // past any page size Linux uses
    EXPECT_TRUE(std::all_of(words + kept + page_words, words + n - page_words, [](uint32_t w) { return w == 0; }));
}
#endif

// The improved traversal's starting states (FORMAT.md, section 2): with the 1-regularity rule,
// a level's incomplete nodes are decided (not refined) before its traversal, and every other node
// starts in bucket max(1, 4 - its incomplete neighbours). derive_next_level makes them from
// tables; here they are counted over each level's links, on every level of 300 random
// hierarchies. (The round trips can not see a wrong start: encoder and decoder share it.)
TEST(HierarchyCoder, LevelsStartWithTheCulledNodesDecided) {
    size_t nodes = 0, culled = 0, lowered = 0;
    for (uint64_t seed = 1; seed <= 300; ++seed) {
        const Hierarchy h = random_hierarchy(seed);
        LevelTraversal traversal{HierarchyCoderOptions{}, kHierarchyStreamVersion};
        Level level, next;
        RefinedNumbering numbering;
        root_level(h, level, true);
        std::vector<NodeId> ids(h.root_count()), next_ids;
        for (NodeId r = 0; r < h.root_count(); ++r) ids[r] = r;
        for (int l = 0; !level.empty(); ++l) {
            const uint32_t n = uint32_t(level.size());
            const uint8_t* state = level.state();
            size_t wrong = 0;
            with_links(level, [&](auto links) {
                auto complete = [&](uint32_t i) {
                    const LevelLinks node = links(i);
                    return complete_state(node.nbr, node.flags) != 0;
                };
                for (uint32_t i = 0; i < n; ++i) {
                    uint8_t expected = kDecided;
                    if (complete(i)) {
                        int culled_neighbours = 0;
                        for (const uint32_t q : links(i).nbr) culled_neighbours += q != kNoLocal && !complete(q);
                        expected = uint8_t(kComplete | std::max(1, 4 - culled_neighbours) << kPriorityShift);
                        lowered += culled_neighbours > 0;
                    } else {
                        ++culled;
                    }
                    if (state[i] != expected && wrong++ == 0)
                        ADD_FAILURE() << "seed " << seed << ", level " << l << ", node " << i << ": state "
                                      << int(state[i]) << ", expected " << int(expected);
                }
            });
            ASSERT_EQ(wrong, 0u);
            nodes += n;
            // Decided as the encoder decides them, from the hierarchy.
            auto refined = [&](uint32_t i) { return !h.is_leaf(ids[i]); };
            traversal.run(level, false, [&](uint32_t i, int) { return refined(i); },
                          [&](uint32_t i, Fate, bool) { return refined(i); });
            next_ids.clear();
            for (uint32_t i = 0; i < n; ++i) {
                if (!refined(i)) continue;
                const NodeId c = h.child(ids[i], 0);
                next_ids.insert(next_ids.end(), {c, c + 1, c + 2, c + 3});
            }
            scan_decided_level(level, numbering, nullptr);
            derive_next_level(level, numbering, next, true);
            std::swap(level, next);
            ids.swap(next_ids);
        }
    }
    // The hierarchies exercise the rule: many culled nodes, many lowered neighbours.
    EXPECT_GT(culled, nodes / 10);
    EXPECT_GT(lowered, nodes / 10);
}

// FORMAT.md, section 2, read literally and run on the Hierarchy itself: the symbols of every level
// in the order and with the context groups the text gives for stream `version` (1 or 2), for all
// switches on (improved) or all but the improved traversal (naive). Diagonals follow rule 0, so
// the stream has no orientation bits; U and the symbol count come from the coder's header.
std::vector<std::pair<int, bool>> symbols_as_specified(const Hierarchy& h, int version, bool improved,
                                                       int uniform_levels) {
    std::vector<std::pair<int, bool>> symbols;
    const std::vector<NodeId> order = h.breadth_first_order();  // canonical: level by level
    const int group_of[4][4] = {{8, 7, 6, 5}, {4, 3, 2, -1}, {1, 0, -1, -1}, {9, -1, -1, -1}};  // [x][y]
    size_t begin = 0;
    for (int l = 0; begin < order.size(); ++l) {
        size_t end = begin;
        while (end < order.size() && h.level(order[end]) == l) ++end;
        const std::vector<NodeId> level(order.begin() + long(begin), order.begin() + long(end));
        begin = end;
        if (l < uniform_levels) continue;
        std::map<NodeId, uint32_t> index;
        for (uint32_t i = 0; i < level.size(); ++i) index[level[i]] = i;
        const uint32_t n = uint32_t(level.size());
        std::vector<bool> decided(n, false), refined(n, false);
        std::vector<int> priority(n, 4);
        auto neighbour = [&](uint32_t i, int e) -> int64_t {
            const NodeId q = h.neighbor(level[i], e);
            return q == kNoNode ? -1 : int64_t(index.at(q));
        };
        auto culled_by_one_regularity = [&](uint32_t i) {
            for (int e = 0; e < 3; ++e) {
                if (neighbour(i, e) < 0 && !h.is_boundary_edge(level[i], e)) return true;
            }
            return false;
        };
        auto hanging = [&](uint32_t i) {
            for (int e = 0; e < 3; ++e) {
                const int64_t q = neighbour(i, e);
                if (q < 0 || !decided[size_t(q)] || !refined[size_t(q)]) return false;
            }
            return true;
        };
        auto decide = [&](uint32_t i) {
            if (hanging(i)) {
                refined[i] = true;
            } else {
                int x = 0, y = 0;
                for (int e = 0; e < 3; ++e) {
                    const int64_t q = neighbour(i, e);
                    if (q < 0) ++y;
                    else if (decided[size_t(q)]) (refined[size_t(q)] ? x : y) += 1;
                }
                refined[i] = !h.is_leaf(level[i]);
                symbols.push_back({group_of[x][y], refined[i]});
            }
            decided[i] = true;
        };
        std::vector<std::pair<uint32_t, int>> stack[5];  // (node, its priority when pushed)
        // Step 2's update of the neighbours of a decided node.
        auto update_neighbours = [&](uint32_t i) {
            for (int e = 0; e < 3; ++e) {
                const int64_t q = neighbour(i, e);
                if (q < 0 || decided[size_t(q)] || priority[size_t(q)] == 0) continue;
                const int now = hanging(uint32_t(q)) ? 0 : std::max(1, priority[size_t(q)] - 1);
                if (now == priority[size_t(q)]) continue;
                priority[size_t(q)] = now;
                stack[now].push_back({uint32_t(q), now});
            }
        };
        if (version == 1) {
            // "Version 1": the culled nodes are decided in their turn.
            if (!improved) {
                for (uint32_t i = 0; i < n; ++i) {
                    if (culled_by_one_regularity(i)) decided[i] = true;  // not refined, no symbol
                    else decide(i);
                }
                continue;
            }
            for (uint32_t i = 0; i < n; ++i) priority[i] = culled_by_one_regularity(i) ? 0 : 4;
            for (uint32_t i = n; i-- > 0;) {
                if (priority[i] == 4) stack[4].push_back({i, 4});
            }
            for (uint32_t i = 0; i < n; ++i) {
                if (priority[i] != 0) continue;
                decided[i] = true;
                update_neighbours(i);
            }
        } else {
            // First every node 1-regularity culls: not refined, no symbol.
            for (uint32_t i = 0; i < n; ++i) decided[i] = culled_by_one_regularity(i);
            if (!improved) {
                for (uint32_t i = 0; i < n; ++i) {
                    if (!decided[i]) decide(i);
                }
                continue;
            }
            for (uint32_t i = 0; i < n; ++i) {
                if (decided[i]) continue;
                int culled = 0;
                for (int e = 0; e < 3; ++e) culled += neighbour(i, e) >= 0 && decided[size_t(neighbour(i, e))];
                priority[i] = std::max(1, 4 - culled);
            }
            for (uint32_t i = n; i-- > 0;) {
                if (!decided[i]) stack[priority[i]].push_back({i, priority[i]});
            }
        }
        for (;;) {
            int p = 0;
            while (p < 5 && stack[p].empty()) ++p;
            if (p == 5) break;
            const auto [i, pushed] = stack[p].back();
            stack[p].pop_back();
            if (decided[i] || priority[i] != pushed) continue;
            decide(i);
            update_neighbours(i);
        }
    }
    return symbols;
}

// fork(): a coder of the same first pass, before any level is coded, codes as a coder made
// afresh (in the mixing mode in another model: the encoder's two files from one first pass).
TEST(HierarchyCoder, AForkCodesAsAFreshCoder) {
    auto payload_of = [](HierarchyLevelEncoder& coder) {
        ArithmeticEncoder encoder;
        for (int l = 0; l < coder.level_count(); ++l) coder.encode_level(l, encoder);
        return encoder.finish();
    };
    for (uint64_t seed = 1; seed <= 20; ++seed) {
        const Hierarchy h = random_hierarchy(seed);
        for (const bool mixed : {false, true}) {
            HierarchyLevelEncoder coder(h, HierarchyCoderOptions{}, kHierarchyStreamVersion, nullptr, mixed);
            const std::unique_ptr<HierarchyLevelEncoder> fork = coder.fork();
            HierarchyLevelEncoder fresh(h, HierarchyCoderOptions{}, kHierarchyStreamVersion, nullptr, mixed);
            if (mixed) {
                fork->set_mixing_model(MixingModel::third);
                fresh.set_mixing_model(MixingModel::third);
            }
            ASSERT_EQ(fork->header(), fresh.header()) << "seed " << seed;
            ASSERT_EQ(payload_of(*fork), payload_of(fresh)) << "seed " << seed << (mixed ? ", mixed" : "");
            HierarchyLevelEncoder written(h, HierarchyCoderOptions{}, kHierarchyStreamVersion, nullptr, mixed);
            ASSERT_EQ(payload_of(coder), payload_of(written)) << "seed " << seed << (mixed ? ", mixed" : "");
            EXPECT_THROW(coder.fork(), Error);  // its levels are coded
        }
    }
}

// A hierarchy stream of `version` (the header's fields and the payload, without the tag).
std::vector<uint8_t> stream_of_version(const Hierarchy& h, const HierarchyCoderOptions& options, uint8_t version) {
    HierarchyLevelEncoder coder(h, options, version);
    ArithmeticEncoder encoder;
    for (int l = 0; l < coder.level_count(); ++l) coder.encode_level(l, encoder);
    const std::vector<uint8_t> payload = encoder.finish();
    std::vector<uint8_t> out = coder.header();
    out.insert(out.end(), payload.begin(), payload.end());
    return out;
}

TEST(HierarchyCoder, StreamsFollowTheFormatText) {
    for (uint64_t seed = 1; seed <= 200; ++seed) {
        Hierarchy h = random_hierarchy(seed);
        for (NodeId n : h.leaves()) {
            if (h.hanging_node_count(n) != 2) continue;
            int u = 0;
            while (h.has_hanging_node(n, u)) ++u;
            h.set_diagonal_flipped(n, diagonal_flag_by_rule(DiagonalRule(0), u));
        }
        for (const int run : {0, 1, 2, 3}) {
            const int version = 1 + run / 2;
            const bool improved = run % 2 == 0;
            HierarchyCoderOptions options;
            options.traversal = improved ? Traversal::improved : Traversal::naive;
            const std::vector<uint8_t> stream = stream_of_version(h, options, uint8_t(version));
            HierarchyStreamHeader header;
            const size_t header_size = read_hierarchy_stream_header(stream.data(), stream.size(), header);
            ASSERT_FALSE(header.orientation_coded);
            const auto symbols = symbols_as_specified(h, version, improved, header.uniform_levels);
            ASSERT_LE(header.symbol_count, symbols.size());
            HierarchyModels models;
            ArithmeticEncoder encoder;
            for (uint64_t k = 0; k < header.symbol_count; ++k) {
                encoder.encode(symbols[k].second, models.for_group(symbols[k].first, true));
            }
            for (uint64_t k = header.symbol_count; k < symbols.size(); ++k) ASSERT_FALSE(symbols[k].second);
            const std::vector<uint8_t> payload = encoder.finish();
            ASSERT_EQ(std::vector<uint8_t>(stream.begin() + long(header_size), stream.end()), payload)
                << "seed " << seed << ", version " << version << (improved ? ", improved" : ", naive") << " traversal";
        }
        // The encoder's own streams are version 2.
        HierarchyStreamHeader header;
        const std::vector<uint8_t> stream = encode_hierarchy(h);
        read_standalone_stream_header(stream.data(), stream.size(), header, 1);
        EXPECT_EQ(header.version, 2);
        EXPECT_EQ(std::vector<uint8_t>(stream.begin() + 5, stream.end()), stream_of_version(h, {}, 2)) << "tag: 5 bytes";
    }
}

// A node split against Hierarchy::split's precondition (it lacks a neighbour) has no stream: the
// decoder would refuse it. The encoder says so, under every switch combination.
// The level coders hand the geometry coder each level's new vertices: the same list, in the same
// order, as a walk of the level's nodes in the hierarchy finds.
TEST(HierarchyCoder, LevelCodersListTheNewVerticesAndLeafFacesOfEachLevel) {
    for (uint64_t seed = 1; seed <= 200; ++seed) {
        const Hierarchy h = random_hierarchy(seed);
        const HierarchyCoderOptions options = options_from_bits(int(seed % kOptionCombinations));
        HierarchyLevelEncoder coder(h, options);
        ArithmeticEncoder encoder;
        size_t listed = 0;
        for (int l = 0; l < coder.level_count(); ++l) {
            ASSERT_EQ(coder.new_vertices(l), new_vertices_of_level(h, coder.level_nodes(l))) << "seed " << seed << ", level " << l;
            listed += coder.new_vertices(l).size();
            coder.encode_level(l, encoder);
        }
        ASSERT_EQ(listed, h.vertex_count() - h.base().positions.size()) << "seed " << seed;
        const std::vector<uint8_t> payload = encoder.finish();
        HierarchyLevelDecoder decoder(h.base(), coder.header().data(), coder.header().size(), kHierarchyStreamVersion,
                                      UINT64_MAX);
        ArithmeticDecoder in(payload.data(), payload.size());
        while (!decoder.done()) {
            const std::vector<NodeId> nodes = decoder.level_nodes();
            ASSERT_EQ(nodes.size(), decoder.level_size());
            ASSERT_EQ(nodes.front(), decoder.level_first());
            decoder.decode_level(in);
            ASSERT_EQ(decoder.new_vertices(), new_vertices_of_level(decoder.hierarchy(), nodes)) << "seed " << seed;
        }
        // The faces counted off the levels' state bytes are the leaf mesh's.
        ASSERT_EQ(decoder.leaf_faces(), extract_leaf_mesh(decoder.hierarchy()).mesh.triangles.size()) << "seed " << seed;
    }
}

TEST(HierarchyCoder, UnbalancedHierarchyIsRefusedByTheEncoder) {
    Hierarchy h(make_icosahedron());
    h.split(0);
    const NodeId corner = h.child(0, 0);
    ASSERT_FALSE(h.has_all_neighbors(corner));
    h.split(corner);
    for (int bits = 0; bits < kOptionCombinations; ++bits) {
        try {
            encode_hierarchy(h, options_from_bits(bits));
            ADD_FAILURE() << "switches " << bits << ": encoded an unbalanced hierarchy";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("not balanced"), std::string::npos) << e.what();
        }
    }
}

TEST(HierarchyCoder, HugeUniformLevelCountIsRefused) {
    Hierarchy h(make_icosahedron());
    std::vector<uint8_t> bytes = encode_hierarchy(h);
    bytes[5 + 1] = 19;  // after the tag, U: 20 * 4^19 nodes
    try {
        decode_hierarchy(h.base(), bytes.data(), bytes.size());
        ADD_FAILURE() << "decoded";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("more than"), std::string::npos) << e.what();
    }
}

std::string decode_error(const TriangleMesh& base, const std::vector<uint8_t>& bytes,
                         const HierarchyDecodeOptions& options = {}) {
    try {
        decode_hierarchy(base, bytes.data(), bytes.size(), options);
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

std::vector<uint8_t> concatenated(std::vector<uint8_t> a, const std::vector<uint8_t>& b) {
    a.insert(a.end(), b.begin(), b.end());
    return a;
}

// Every version of the stream decodes, tagged or not (FORMAT.md, section 2): version 1 under every
// switch combination, untagged streams as the caller says; a newer version is refused as such.
TEST(HierarchyCoder, EveryStreamVersionDecodes) {
    for (uint64_t seed = 1; seed <= 300; ++seed) {
        const Hierarchy h = random_hierarchy(seed);
        const HierarchyCoderOptions options = options_from_bits(int(seed % kOptionCombinations));
        const std::vector<uint8_t> v1 = stream_of_version(h, options, 1), v2 = stream_of_version(h, options, 2);
        HierarchyDecodeOptions untagged_v1;
        untagged_v1.untagged_version = 1;
        const std::pair<std::vector<uint8_t>, HierarchyDecodeOptions> cases[] = {
            {concatenated(hierarchy_stream_tag(1), v1), {}},
            {concatenated(hierarchy_stream_tag(2), v2), {}},
            {concatenated(hierarchy_stream_tag(1), v1), untagged_v1},  // the tag wins
            {v1, untagged_v1},
            {v2, {}}};
        for (const auto& [bytes, decode_options] : cases) {
            const Hierarchy back = decode_hierarchy(h.base(), bytes.data(), bytes.size(), decode_options);
            ASSERT_TRUE(same_connectivity(h, back)) << "seed " << seed;
        }
    }
    // The versions differ: a version-1 stream read as version 2 decodes wrongly or not at all on
    // some of these hierarchies.
    int misread = 0;
    for (uint64_t seed = 1; seed <= 100; ++seed) {
        const Hierarchy h = random_hierarchy(seed);
        const std::vector<uint8_t> v1 = stream_of_version(h, {}, 1);
        try {
            misread += !same_connectivity(h, decode_hierarchy(h.base(), v1.data(), v1.size()));
        } catch (const Error&) {
            ++misread;
        }
    }
    EXPECT_GT(misread, 10);
}

TEST(HierarchyCoder, NewerAndUnknownStreamVersionsAreRefused) {
    Hierarchy h(make_icosahedron());
    refine_uniformly(h, 1);
    std::vector<uint8_t> bytes = encode_hierarchy(h);
    ASSERT_EQ(std::string(bytes.begin(), bytes.begin() + 4), "AMHS");
    ASSERT_EQ(bytes[4], kHierarchyStreamVersion);
    bytes[4] = kHierarchyStreamVersion + 1;
    EXPECT_NE(decode_error(h.base(), bytes).find("unsupported version 3 (newer than this build, which reads versions 1 to 2)"),
              std::string::npos)
        << decode_error(h.base(), bytes);
    bytes[4] = 0;
    EXPECT_NE(decode_error(h.base(), bytes).find("unknown version 0"), std::string::npos);
    bytes[4] = kHierarchyStreamVersion;
    bytes[3] = 'X';
    EXPECT_NE(decode_error(h.base(), bytes).find("bad magic"), std::string::npos);
    EXPECT_NE(decode_error(h.base(), {'A', 'M', 'H', 'S'}).find("truncated"), std::string::npos);
    HierarchyDecodeOptions untagged_v3;
    untagged_v3.untagged_version = 3;
    const std::vector<uint8_t> untagged = stream_of_version(h, {}, 2);
    EXPECT_NE(decode_error(h.base(), untagged, untagged_v3).find("unsupported version 3"), std::string::npos);
}

}  // namespace
}  // namespace amc
