// Anything encoded decodes: every writer (encode, encode_hierarchy, serialize_hierarchy) either
// refuses its input with an Error or writes what its reader reads back as the same hierarchy. A
// property test over random hierarchies, corrupted in every way the public API allows, with
// positions anywhere in the double range, float32 and float64, quantized or not; and the known
// cases one by one.
#include "coding/base/base_stage.h"
#include "coding/hierarchy/coder_switches.h"
#include "coding/geometry/float_coder.h"
#include "common/exact_float.h"
#include "hierarchy_checks.h"

#include <amc/codec.h>
#include <amc/hierarchy_coder.h>

#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>

namespace amc {
namespace {

using testing::Random;

double random_double_bits(Random& random) {
    const uint64_t bits = random.next() << 33 ^ random.next() << 2 ^ random.next();
    double x;
    std::memcpy(&x, &bits, 8);
    return x;
}

float random_float_bits(Random& random) {
    const uint32_t bits = uint32_t(random.next() << 1 ^ random.next());
    float x;
    std::memcpy(&x, &bits, 4);
    return x;
}

// A coordinate anywhere in the double range: any bit pattern (NaN, infinities, subnormals
// included), a value near the largest double, or a scaled ordinary one.
double random_coordinate(Random& random, bool single) {
    switch (random.next() % 4) {
        case 0: return single ? double(random_float_bits(random)) : random_double_bits(random);
        case 1: return (random.next() % 2 ? 1 : -1) * (single ? double(FLT_MAX) : DBL_MAX) * (1.0 - double(random.next() % 4) * 1e-16);
        case 2: return std::ldexp(double(random.next() % 2000) - 1000.0, int(random.next() % 2100) - 1075);
        default: return double(random.next() % 100) / 7.0;
    }
}

Vec3 random_position(Random& random, bool single) {
    return {random_coordinate(random, single), random_coordinate(random, single), random_coordinate(random, single)};
}

// Base meshes the Hierarchy constructor takes but a decoder refuses.
TriangleMesh broken_base(Random& random) {
    TriangleMesh mesh = make_icosahedron();
    switch (random.next() % 5) {
        case 0: mesh.positions.push_back({9, 9, 9}); break;                              // unused vertex
        case 1: std::swap(mesh.triangles[3][0], mesh.triangles[3][1]); break;            // flipped triangle
        case 2: mesh.triangles.push_back(mesh.triangles[5]); break;                      // repeated triangle
        case 3: mesh.triangles[7][2] = mesh.triangles[7][1]; break;                      // degenerate triangle
        default: mesh.triangles.push_back({mesh.triangles[0][0], mesh.triangles[0][1], 11}); break;  // non-manifold
    }
    return mesh;
}

// Splits leaves without balance or closure (Hierarchy::split does not check its precondition):
// unbalanced nodes, leaves with three hanging nodes, levels beyond the cap. Returns whether it
// found a place to do so.
bool corrupt_structure(Hierarchy& h, Random& random) {
    switch (random.next() % 3) {
        case 0: {  // split a leaf that lacks a neighbour
            for (NodeId n : h.leaves()) {
                if (!h.has_all_neighbors(n)) {
                    h.split(n);
                    return true;
                }
            }
            break;
        }
        case 1: {  // split the three neighbours of a leaf
            for (NodeId n : h.leaves()) {
                bool all = true;
                for (int e = 0; e < 3; ++e) all &= h.neighbor(n, e) != kNoNode && h.is_leaf(h.neighbor(n, e));
                if (!all) continue;
                for (int e = 0; e < 3; ++e) h.split(h.neighbor(n, e));
                return true;
            }
            break;
        }
        default: {  // a chain of center children down to and beyond the level cap
            NodeId n = h.leaves().front();
            while (h.level(n) <= kMaxLevel) {
                h.split(n);
                n = h.child(n, 3);
            }
            return true;
        }
    }
    return false;
}

Hierarchy random_case(uint64_t seed, Random& random, bool& corrupted) {
    corrupted = false;
    const auto meshes = testing::fixture_meshes();
    const bool broken = random.next() % 10 == 0;
    TriangleMesh base = broken ? broken_base(random) : meshes[random.next() % meshes.size()].mesh;
    if (!broken && random.next() % 3 == 0) base = make_bumpy_sphere(0);  // float32 coordinates
    const bool single = base.single_precision;
    Hierarchy h(std::move(base));
    corrupted = broken;
    if (broken) {
        // Not refined: refine() assumes a valid base (its balancing can run forever otherwise).
        if (random.next() % 2) h.split(0);
        return h;
    }
    refine_randomly(h, h.root_count() + uint32_t(random.next() % 200), 1 + int(random.next() % 4), seed);
    for (NodeId n : h.leaves()) {
        if (h.hanging_node_count(n) == 2 && random.next() % 3 == 0) h.set_diagonal_flipped(n, true);
    }
    if (random.next() % 4 == 0) {  // coarsening leaves ids free for reuse
        for (NodeId n = 0; n < h.node_capacity(); ++n) {
            if (h.is_alive(n) && !h.is_leaf(n) && random.next() % 4 == 0) h.coarsen(n);
        }
    }
    switch (random.next() % 6) {
        case 0:  // a few positions anywhere, base vertices included
            for (int k = 0; k < 3; ++k) h.set_position(VertexId(random.next() % h.positions().size()), random_position(random, single));
            break;
        case 1: {  // everything scaled towards the ends of the range
            const int shift = int(random.next() % 1100);
            for (VertexId v = 0; v < h.positions().size(); ++v) {
                const Vec3 p = h.position(v);
                h.set_position(v, {std::ldexp(p.x, shift), std::ldexp(p.y, shift), std::ldexp(p.z, shift)});
            }
            break;
        }
        case 2: {  // refined further with vertices placed anywhere (the default placer beyond DBL_MAX / 2)
            for (VertexId v = 0; v < h.base().positions.size(); ++v) h.set_position(v, random_position(random, single));
            refine_randomly(h, h.leaf_count() + 30, 3, seed + 1);
            break;
        }
        case 3:  // a double hierarchy declared float32
            if (!single) h.set_single_precision(true);
            break;
        default: break;
    }
    if (random.next() % 8 == 0) corrupted = corrupt_structure(h, random);
    return h;
}

// What decoding an encoding of `h` gives: h with its positions snapped to the encoder's grid when
// quantized, in decoder order (base connectivity mode 2 orders the base by the decoded positions).
Hierarchy expected_decoding(const Hierarchy& h, int quantize_bits) {
    if (quantize_bits == 0) return in_decoder_order(h);
    Hierarchy snapped = h;
    snapped.set_single_precision(false);
    std::vector<Vec3> points;
    const std::vector<uint32_t> order = canonical_vertex_order(snapped);
    for (VertexId v = 0; v < order.size(); ++v) {
        if (order[v] != 0xffffffffu) points.push_back(snapped.position(v));
    }
    const Quantizer quantizer = make_quantizer(points, quantize_bits);
    for (VertexId v = 0; v < order.size(); ++v) {
        if (order[v] != 0xffffffffu) snapped.set_position(v, dequantize(quantizer, snap_to_grid(quantizer, snapped.position(v))));
    }
    return in_decoder_order(snapped);
}

TEST(EncodeDecode, EveryWriterRefusesOrWritesWhatItsReaderReadsBack) {
    int encoded = 0, refused = 0, quantized = 0, corrupted_cases = 0, extreme = 0;
    for (uint64_t seed = 1; seed <= 3000; ++seed) {
        Random random{seed * 7919};
        bool corrupted = false;
        const Hierarchy h = random_case(seed, random, corrupted);
        corrupted_cases += corrupted;
        EncodeOptions options;
        options.hierarchy = coder_options_from_switches(int(random.next() % kCoderSwitchCombinations));
        options.predictor = GeometryPredictor(random.next() % 3);
        if (random.next() % 3 == 0) options.quantize_bits = 1 + int(random.next() % 30);
        const bool valid = check_invariants(h).empty();
        SCOPED_TRACE("seed " + std::to_string(seed));
        // .amc
        std::vector<uint8_t> bytes;
        EncodeStats stats;
        try {
            bytes = encode(h, options, &stats);
        } catch (const Error& e) {
            ++refused;
            ASSERT_NE(std::string(e.what()).find("encode: "), std::string::npos) << e.what();
        }
        if (!bytes.empty()) {
            ++encoded;
            quantized += options.quantize_bits != 0;
            ASSERT_TRUE(valid) << "encoded an invalid hierarchy: " << check_invariants(h);
            ASSERT_FALSE(corrupted);
            const DecodeResult back = try_decode(bytes.data(), bytes.size());
            ASSERT_TRUE(back.ok) << back.error;
            ASSERT_TRUE(identical(back.hierarchy, expected_decoding(h, options.quantize_bits)));
            ASSERT_TRUE(std::isfinite(stats.max_error));
            bool far = false;
            for (const Vec3& p : h.positions()) far |= std::fabs(p.x) > 1e300 || std::fabs(p.y) > 1e300 || std::fabs(p.z) > 1e300;
            extreme += far;
        }
        // The hierarchy stream (connectivity only).
        std::vector<uint8_t> stream;
        try {
            stream = encode_hierarchy(h, options.hierarchy);
        } catch (const Error& e) {
            ASSERT_NE(std::string(e.what()).find("encode_hierarchy: "), std::string::npos) << e.what();
        }
        if (!stream.empty()) {
            Hierarchy back;
            try {
                back = decode_hierarchy(h.base(), stream.data(), stream.size());
            } catch (const Error& e) {
                FAIL() << "encode_hierarchy wrote a stream that decode_hierarchy refuses: " << e.what();
            }
            if (valid) {
                ASSERT_EQ(extract_leaf_mesh(back).mesh.triangles, extract_leaf_mesh(h).mesh.triangles);
            }
        }
        // The hierarchy file.
        std::string file;
        try {
            file = serialize_hierarchy(h);
        } catch (const Error& e) {
            ASSERT_NE(std::string(e.what()).find("hierarchy file: "), std::string::npos) << e.what();
        }
        if (!file.empty()) {
            ASSERT_TRUE(valid);
            Hierarchy back;
            try {
                back = deserialize_hierarchy(file, "test");
            } catch (const Error& e) {
                FAIL() << "serialize_hierarchy wrote a file that deserialize_hierarchy refuses: " << e.what();
            }
            ASSERT_TRUE(identical(back, h));
        }
    }
    std::printf("%d encoded and decoded back identically, %d refused; %d quantized, %d with coordinates beyond 1e300; "
                "%d corrupted in structure or base\n",
                encoded, refused, quantized, extreme, corrupted_cases);
    // The cases cover both outcomes, quantized files and positions near the ends of the range.
    EXPECT_GT(encoded, 1000);
    EXPECT_GT(refused, 300);
    EXPECT_GT(quantized, 200);
    EXPECT_GT(corrupted_cases, 300);
    EXPECT_GT(extreme, 20);
}

std::string encode_error(const Hierarchy& h, const EncodeOptions& options = {}) {
    try {
        encode(h, options);
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

// The default placer kept finite midpoints of coordinates beyond DBL_MAX / 2 (0.5 * (a + b)
// overflowed), and equals 0.5 * (a + b) bit for bit wherever that is finite: so no position of an
// existing hierarchy moved (the golden files pin it too).
TEST(EncodeDecode, DefaultPlacerIsFiniteAndUnchangedWhereItWasFinite) {
    Random random{42};
    uint64_t compared = 0, overflowing = 0;
    for (int k = 0; k < 6000; ++k) {
        // Any two doubles; two of one sign near the top of the range; one and a power-of-two
        // fraction of it (subnormal halves included).
        double a = random_double_bits(random), b = random_double_bits(random);
        if (k % 3 == 1) {
            a = std::copysign(DBL_MAX * (0.5 + double(random.next() % 1000) / 2000.0), a);
            b = std::copysign(DBL_MAX * (0.5 + double(random.next() % 1000) / 2000.0), a);
        } else if (k % 3 == 2) {
            b = std::ldexp(a, -int(random.next() % 8));
        }
        if (!std::isfinite(a) || !std::isfinite(b)) continue;
        TriangleMesh mesh;
        mesh.positions = {{a, 0, 0}, {b, 1, 0}, {0, 0, 1}};
        mesh.triangles = {{0, 1, 2}};
        Hierarchy h(mesh);
        h.split(0);
        const double placed = h.position(h.midpoint(0, 0)).x, old = 0.5 * (a + b);
        ASSERT_TRUE(std::isfinite(placed)) << a << " " << b;
        ASSERT_TRUE(placed >= std::fmin(a, b) && placed <= std::fmax(a, b)) << a << " " << b;
        if (std::isfinite(old)) {
            ASSERT_EQ(std::memcmp(&placed, &old, 8), 0) << a << " " << b;
            ++compared;
        } else {
            ++overflowing;
        }
    }
    EXPECT_GT(compared, 3000u);
    EXPECT_GT(overflowing, 1000u);
    // The case: a hierarchy near DBL_MAX refines to finite positions and encodes.
    TriangleMesh mesh = make_icosahedron();
    for (Vec3& p : mesh.positions) p = {p.x * DBL_MAX, p.y * DBL_MAX, p.z * DBL_MAX};
    Hierarchy h(mesh);
    refine_uniformly(h, 2);
    EXPECT_EQ(check_positions(h), "");
    const std::vector<uint8_t> bytes = encode(h);
    EXPECT_TRUE(identical(decode(bytes.data(), bytes.size()), in_decoder_order(h)));
    // The decoders' bulk split (Hierarchy::split_level) places them as split() does.
    const std::vector<uint8_t> stream = encode_hierarchy(h);
    EXPECT_TRUE(identical(decode_hierarchy(h.base(), stream.data(), stream.size()), h));
}

// The writer checks positions in ranges of 2^16 vertices on the encode's threads; the message
// names the first bad vertex, whichever range a thread finished first.
TEST(EncodeDecode, TheFirstBadPositionIsNamedOnAnyThreads) {
    Hierarchy h(make_icosahedron());
    refine_uniformly(h, 7);
    ASSERT_GT(h.positions().size(), size_t(2) << 16);
    h.set_position(150000, {0, 0, NAN});
    h.set_position(70000, {INFINITY, 0, 0});
    for (unsigned threads : {1u, 2u, 3u}) {
        EncodeOptions options;
        options.threads = threads;
        EXPECT_EQ(encode_error(h, options), "encode: vertex 70000 has a non-finite coordinate") << threads << " threads";
    }
}

// The writer's float32 test passes coordinates that are zero or normal float32 values in one
// integer pass and tests the others exactly: values on both sides of each of its bounds.
TEST(EncodeDecode, SinglePrecisionPositionsAreTestedExactlyAtTheFloatBounds) {
    Hierarchy h(make_icosahedron());
    refine_uniformly(h, 1);
    for (VertexId v = 0; v < h.positions().size(); ++v) {
        const Vec3 p = h.position(v);
        h.set_position(v, {rounded_to_float(p.x), rounded_to_float(p.y), rounded_to_float(p.z)});
    }
    h.set_single_precision(true);
    ASSERT_EQ(encode_error(h), "");
    const double floats[] = {0.0, -0.0, FLT_MAX, -FLT_MAX, FLT_MIN, -FLT_MIN, std::ldexp(1.0, -127), std::ldexp(3.0, -149),
                             FLT_TRUE_MIN, std::ldexp(1.0 + std::ldexp(1.0, -23), 5), std::ldexp(1.0, 127)};
    const double others[] = {std::ldexp(1.0, 128), std::nextafter(double(FLT_MAX), 1e300), std::ldexp(1.0, -150),
                             std::ldexp(1.0 + std::ldexp(1.0, -24), 5), std::ldexp(1.0 + std::ldexp(1.0, -20), -140),
                             std::ldexp(1.0, -1074), 1e300, std::nextafter(0.5, 1.0)};
    for (const double x : floats) {
        Hierarchy with = h;
        with.set_position(7, {0.5, x, 0.25});
        EXPECT_EQ(encode_error(with), "") << x;
    }
    for (const double x : others) {
        Hierarchy with = h;
        with.set_position(7, {0.5, x, 0.25});
        EXPECT_NE(encode_error(with).find("is not a float32 value"), std::string::npos) << x;
    }
}

TEST(EncodeDecode, KnownCasesAreRefusedWithTheDecodersWords) {
    // A base with an unused vertex, a flipped triangle: the decoder's validate_triangle_mesh text.
    TriangleMesh unused = make_icosahedron();
    unused.positions.push_back({2, 2, 2});
    EXPECT_EQ(encode_error(Hierarchy(unused)),
              "encode: base mesh: vertex 12 is not used by any triangle (isolated vertices cannot be coded)");
    TriangleMesh flipped = make_icosahedron();
    std::swap(flipped.triangles[0][0], flipped.triangles[0][1]);
    EXPECT_NE(encode_error(Hierarchy(flipped)).find("(inconsistent orientation)"), std::string::npos);
    // Non-finite positions, and non-float positions in a float32 hierarchy.
    Hierarchy h(make_icosahedron());
    refine_uniformly(h, 1);
    Hierarchy infinite = h;
    infinite.set_position(20, {0, INFINITY, 0});
    EXPECT_EQ(encode_error(infinite), "encode: vertex 20 has a non-finite coordinate");
    Hierarchy single = h;
    single.set_single_precision(true);
    EXPECT_NE(encode_error(single).find("is not a float32 value"), std::string::npos);
    // A node refined beyond the level cap: the decoder says it "can not be refined".
    Hierarchy deep(make_icosahedron());
    NodeId n = 0;
    while (deep.level(n) <= kMaxLevel) {
        deep.split(n);
        n = deep.child(n, 3);
    }
    EXPECT_NE(encode_error(deep).find("level cap"), std::string::npos) << encode_error(deep);
    try {
        encode_hierarchy(deep);
        ADD_FAILURE() << "encode_hierarchy took a node beyond the level cap";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("level cap"), std::string::npos) << e.what();
    }
    // A leaf with three hanging nodes.
    Hierarchy open(make_icosahedron());
    for (int e = 0; e < 3; ++e) open.split(open.neighbor(0, e));
    ASSERT_EQ(open.hanging_node_count(0), 3);
    EXPECT_NE(encode_error(open).find("three hanging nodes"), std::string::npos);
    try {
        encode_hierarchy(open);
        ADD_FAILURE() << "encode_hierarchy took a leaf with three hanging nodes";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("three hanging nodes"), std::string::npos) << e.what();
    }
}

// Setting a base vertex's position moves the base mesh's vertex too: encode stores it.
TEST(EncodeDecode, BaseVertexPositionsAreEncoded) {
    Hierarchy h(make_icosahedron());
    refine_uniformly(h, 1);
    h.set_position(3, {0.25, -7.5, 1e-300});
    EXPECT_EQ(h.base().positions[3].y, -7.5);
    const std::vector<uint8_t> bytes = encode(h);
    const Hierarchy back = decode(bytes.data(), bytes.size());
    EXPECT_TRUE(identical(back, in_decoder_order(h)));
    bool found = false;
    for (const Vec3& p : back.base().positions) found |= p.x == 0.25 && p.y == -7.5 && p.z == 1e-300;
    EXPECT_TRUE(found);
}

// A box that reaches the largest double: every reconstruction stays finite (the encoder snaps a
// point one step down where rounding would carry it past DBL_MAX), and max_error is finite.
TEST(EncodeDecode, QuantizedBoxReachingTheLargestDoubleStaysFinite) {
    for (int bits = 1; bits <= 30; ++bits) {
        TriangleMesh mesh = make_icosahedron();
        for (Vec3& p : mesh.positions) p = {(p.x + 1) * 0.5 * DBL_MAX, (p.y + 1) * 0.25 * DBL_MAX, p.z};
        double top = 0;
        for (const Vec3& p : mesh.positions) top = std::fmax(top, p.x);
        for (Vec3& p : mesh.positions) {
            if (p.x == top) p.x = DBL_MAX;
        }
        Hierarchy h(mesh);
        refine_uniformly(h, 1);
        EncodeOptions options;
        options.quantize_bits = bits;
        EncodeStats stats;
        const std::vector<uint8_t> bytes = encode(h, options, &stats);
        EXPECT_TRUE(std::isfinite(stats.max_error)) << bits;
        const DecodeResult back = try_decode(bytes.data(), bytes.size());
        ASSERT_TRUE(back.ok) << bits << ": " << back.error;
        EXPECT_TRUE(identical(back.hierarchy, expected_decoding(h, bits))) << bits;
    }
}

// A file beyond the decoder's node limit (an 84 M-face hierarchy against the default 2^26 nodes)
// is refused with a message that says how to raise the limit.
TEST(EncodeDecode, NodeLimitMessageSaysHowToRaiseIt) {
    Hierarchy h(make_icosahedron());
    refine_uniformly(h, 2);
    const std::vector<uint8_t> bytes = encode(h);
    DecodeOptions small;
    small.max_nodes = 100;
    const DecodeResult r = try_decode(bytes.data(), bytes.size(), small);
    ASSERT_FALSE(r.ok);
    EXPECT_EQ(r.code, ErrorCode::limit_exceeded);
    EXPECT_EQ(r.error, "file holds 420 nodes, more than the limit of 100 (raise it: amc decode --max-nodes, "
                       "DecodeOptions::max_nodes)");
    small.max_nodes = 420;
    EXPECT_TRUE(try_decode(bytes.data(), bytes.size(), small).ok);
}

// One chunk is coded from the input read in the base coder's order (TurnedRoots); an input with
// free ids is reordered into a copy first. Both ways give the same bytes: the same forest with
// free ids, and compacted without them (reorder_base with the identity orders), encoded at 12
// bits and bit-exact. The fixture meshes flip diagonals at random; the torus follows a rule of
// absolute local indices, which the base coder's rotations would break, so its roots keep the
// input's order (Codec.DiagonalRulesOfAbsoluteLocalIndicesStayCheap).
TEST(EncodeDecode, InputReadInBaseOrderCodesAsItsReorderedCopy) {
    Random random{29};
    auto meshes = testing::fixture_meshes();
    meshes.push_back({"torus by rule", make_torus(4, 3, 2.0, 0.7)});
    int cases = 0, kept_rotations = 0;
    for (const auto& [name, mesh] : meshes) {
        const bool by_rule = name == "torus by rule";
        Hierarchy h(mesh);
        refine_randomly(h, h.root_count() + (by_rule ? 3000 : 300), by_rule ? 5 : 4, 7);
        for (NodeId n = 0; n < h.node_capacity(); ++n)
            if (h.is_alive(n) && !h.is_leaf(n) && h.level(n) >= 2 && random.next() % 8 == 0) h.coarsen(n);
        for (NodeId n : h.leaves()) {
            if (h.hanging_node_count(n) != 2) continue;
            const int unrefined = !h.has_hanging_node(n, 0) ? 0 : !h.has_hanging_node(n, 1) ? 1 : 2;
            h.set_diagonal_flipped(n, by_rule ? diagonal_flag_by_rule(DiagonalRule::lower_local_index, unrefined)
                                              : random.next() % 3 == 0);
        }
        ASSERT_LT(h.node_count(), h.node_capacity()) << name << ": nothing coarsened, no free ids";
        std::vector<uint32_t> vertex_order(h.base().positions.size()), triangle_order(h.root_count());
        for (uint32_t i = 0; i < vertex_order.size(); ++i) vertex_order[i] = i;
        for (uint32_t i = 0; i < triangle_order.size(); ++i) triangle_order[i] = i;
        const Hierarchy compact = reorder_base(h, vertex_order, triangle_order, std::vector<uint8_t>(triangle_order.size(), 0));
        ASSERT_EQ(compact.node_count(), compact.node_capacity()) << name;
        kept_rotations += base_code_order(compact, base_code_of(compact, nullptr, EncodeOptions())).keep_rotations;
        for (int bits : {12, 0}) {
            // Also with leaves enough for two chunks but faces for one (counted before the order).
            for (uint64_t chunk_faces : {EncodeOptions().chunk_faces, uint64_t(h.leaf_count()) + 1}) {
                EncodeOptions options;
                options.quantize_bits = bits;
                options.chunk_faces = chunk_faces;
                EXPECT_EQ(encode(h, options), encode(compact, options)) << name << ", " << bits << " bits, " << chunk_faces;
                ++cases;
            }
        }
        // A float32 input quantized: the turned way reads its nodes with grid points apart from
        // them (HierarchyOnGrid), which are doubles as in the reordered copy (at 30 bits most
        // predictions rounded to float would move to another grid point).
        auto as_float32 = [](Hierarchy x) {
            for (VertexId v = 0; v < x.positions().size(); ++v) {
                const Vec3 p = x.position(v);
                x.set_position(v, {double(float(p.x)), double(float(p.y)), double(float(p.z))});
            }
            x.set_single_precision(true);
            return x;
        };
        for (int bits : {12, 30}) {
            EncodeOptions options;
            options.quantize_bits = bits;
            EXPECT_EQ(encode(as_float32(h), options), encode(as_float32(compact), options)) << name << ", float32, " << bits << " bits";
        }
    }
    EXPECT_GE(cases, 16);
    EXPECT_EQ(kept_rotations, 1);
}

}  // namespace
}  // namespace amc
