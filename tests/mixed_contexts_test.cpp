// The hierarchy coder's mixing mode (.amc version 8, docs/FORMAT.md 2.1): bit-exact round trips
// under every coder switch, quantized and float32 files, stress coordinates; smaller than the
// paper's contexts on a curved remesh; refused in files of older versions.
#include "coding/container.h"
#include "coding/format_version.h"
#include "coding/hierarchy/coder_switches.h"
#include "coding/entropy/arithmetic_coder.h"
#include "coding/hierarchy/context_mixing.h"
#include "coding/hierarchy/hierarchy_level_coder.h"
#include "coding/hierarchy/mixed_contexts.h"
#include "coding/hierarchy/trained_states.h"
#include "hierarchy_checks.h"

#include <amc/codec.h>
#include <amc/refinement.h>

#include <cmath>
#include <cstring>
#include <map>
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

// Positions that push the geometric features to their edges: huge, tiny, denormal and repeated
// coordinates (overflowing products, zero areas and lengths).
double wild_coordinate(Random& random) {
    switch (random.next() % 5) {
        case 0: return 0.0;
        case 1: return std::ldexp(double(random.next() % 1000 + 1), -1074);
        case 2: return (random.next() % 2 ? 1 : -1) * std::ldexp(double(random.next() % 1000), 900);
        case 3: return 1.0;
        default: return std::ldexp(double(random.next() % 100000), -int(random.next() % 60));
    }
}

TEST(MixedContexts, SquashAndStretchAreMonotoneInverses) {
    int previous = 0;
    for (int x = -2047; x <= 2047; ++x) {
        const int p = mixing::squash(x);
        ASSERT_GE(p, previous) << x;
        ASSERT_GE(p, 1);
        ASSERT_LE(p, 4095);
        previous = p;
    }
    for (int p = 1; p < 4096; ++p) {
        // stretch(p) is the least x with squash(x) >= p (the top of the range above 4094).
        const int x = mixing::stretch(p);
        if (p > mixing::squash(2047)) continue;
        ASSERT_GE(mixing::squash(x), p) << p;
        if (x > -2047) {
            ASSERT_LT(mixing::squash(x - 1), p) << p;
        }
    }
    EXPECT_EQ(mixing::squash(0), 2047);
    EXPECT_EQ(mixing::stretch(2047), 0);
}

// The fourth model's quadric (FORMAT.md 2.4) on a bowl and a saddle of the same principal
// curvatures' sizes: it tells them apart by the mean curvature, where the dihedral angles cannot.
TEST(MixedContexts, QuadricCurvaturesTellABowlFromASaddle) {
    for (double sign : {1.0, -1.0}) {
        Hierarchy h(make_square(8));
        refine_uniformly(h, 2);
        for (VertexId v = 0; v < VertexId(h.vertex_count()); ++v) {
            const Vec3 p = h.position(v);
            const double x = p.x - 0.5, y = p.y - 0.5;
            h.set_position(v, {p.x, p.y, 0.5 * (x * x + sign * y * y)});  // principal curvatures 1 and `sign`
        }
        int checked = 0;
        for (NodeId n = 0; n < NodeId(h.node_count()); ++n) {
            if (h.level(n) != 2) continue;
            Vec3 c{0, 0, 0};
            double longest = 0;
            for (int e = 0; e < 3; ++e) {
                const Vec3 a = h.position(h.vertex(n, e)), b = h.position(h.vertex(n, (e + 1) % 3));
                c = c + (1.0 / 3.0) * a;
                longest = std::max(longest, std::sqrt(dot(b - a, b - a)));
            }
            if (std::fabs(c.x - 0.5) > 0.1 || std::fabs(c.y - 0.5) > 0.1) continue;
            const std::array<double, 2> k = quadric_curvatures(h, n, longest);
            // Bowl: |H| = 1, sqrt|K| = 1; saddle: H = 0, sqrt|K| = 1 (times the longest edge).
            EXPECT_NEAR(k[0] / longest, sign > 0 ? 1.0 : 0.0, 0.05) << n;
            EXPECT_NEAR(k[1] / longest, 1.0, 0.05) << n;
            ++checked;
        }
        EXPECT_GE(checked, 8);
        // A flat square's nodes have none; a node on the boundary (a missing neighbour) none either.
        Hierarchy flat(make_square(4));
        refine_uniformly(flat, 1);
        for (NodeId n = 0; n < NodeId(flat.node_count()); ++n) {
            const std::array<double, 2> k = quadric_curvatures(flat, n, 1.0);
            EXPECT_EQ(k[0], 0.0);
            EXPECT_EQ(k[1], 0.0);
        }
    }
}

TEST(MixedContexts, RandomHierarchiesRoundTripBitExactlyUnderEverySwitch) {
    Random random{77};
    const auto meshes = testing::fixture_meshes();
    for (int trial = 0; trial < 240; ++trial) {
        TriangleMesh base = meshes[random.next() % meshes.size()].mesh;
        const bool single = trial % 3 == 1 && trial % 4 != 3;
        base.single_precision = single;
        if (single) {
            for (Vec3& p : base.positions) p = Vec3{double(float(p.x)), double(float(p.y)), double(float(p.z))};
        }
        Hierarchy h(base);
        refine_randomly(h, h.root_count() + uint32_t(random.next() % 600), 1 + int(random.next() % 5), random.next());
        if (trial % 4 == 3) {
            for (VertexId v = 0; v < h.positions().size(); ++v)
                h.set_position(v, {wild_coordinate(random), wild_coordinate(random), wild_coordinate(random)});
        } else if (!single) {
            // Off the midpoints, as a surface remesh places them.
            for (VertexId v = 0; v < h.positions().size(); ++v) {
                const Vec3 p = h.position(v);
                h.set_position(v, p + 0.01 * double(random.next() % 100) * Vec3{p.y, p.z, p.x});
            }
        }
        EncodeOptions options;
        options.hierarchy_contexts = HierarchyContexts::mixed;
        options.hierarchy = coder_options_from_switches(int(random.next() % kCoderSwitchCombinations));
        if (trial % 4 != 3) {
            const int bits[] = {0, 0, 10, 16};
            options.quantize_bits = single ? 0 : bits[random.next() % 4];
        }
        options.predictor = GeometryPredictor(random.next() % 4);
        const std::vector<uint8_t> bytes = encode(h, options);
        // The seventh model's version, or an older model's where it codes smaller (14 where a
        // bit-exact level is adaptive, its raw bits in a side stream; 21 where the seventh model's
        // bit-exact base has its raw bits in one).
        ASSERT_TRUE(bytes[4] == kSeventhMixingVersion || bytes[4] == kSixthMixingVersion || bytes[4] == kFifthMixingVersion ||
                    bytes[4] == kFourthMixingVersion || bytes[4] == kThirdMixingVersion ||
                    (options.quantize_bits == 0 && (bytes[4] == kRawSideVersion || bytes[4] == kBaseRawSideVersion)))
            << trial;
        const Hierarchy back = decode(bytes.data(), bytes.size());
        Hierarchy expected = in_decoder_order(h, options);
        if (options.quantize_bits != 0) {
            // The forest and the vertex numbering are the input's; the positions are on the grid.
            ASSERT_EQ(back.vertex_count(), expected.vertex_count()) << "trial " << trial;
            expected.set_single_precision(false);
            for (VertexId v = 0; v < expected.positions().size(); ++v) expected.set_position(v, back.position(v));
        }
        ASSERT_TRUE(identical(back, expected)) << "trial " << trial;
        ASSERT_EQ(check_invariants(back), "");
        // Every prefix of levels too (progressive decoding).
        for (int l = 0; l <= back.depth(); ++l) {
            DecodeOptions prefix;
            prefix.max_level = l;
            ASSERT_EQ(decode(bytes.data(), bytes.size(), prefix).depth(), l) << "trial " << trial;
        }
    }
}

TEST(MixedContexts, SmallerThanThePapersContextsOnACurvedRemesh) {
    const Hierarchy h = testing::curved_sphere_remesh(20000);
    EncodeStats paper, mixed;
    encode(h, {}, &paper);
    EncodeOptions options;
    options.hierarchy_contexts = HierarchyContexts::mixed;
    const std::vector<uint8_t> bytes = encode(h, options, &mixed);
    EXPECT_LT(double(mixed.hierarchy_bytes), 0.95 * double(paper.hierarchy_bytes))
        << mixed.hierarchy_bytes << " against " << paper.hierarchy_bytes;
    EXPECT_TRUE(identical(decode(bytes.data(), bytes.size()), in_decoder_order(h, options)));
    // Without the option the file is what it was (the paper's contexts, an older version; without
    // geometry mode 5 too, which a bit-exact remesh takes and which makes version 12).
    EncodeOptions paper_options;
    paper_options.unit_normals = false;
    std::vector<uint8_t> plain = encode(h, paper_options);
    // 14: adaptive levels' raw side streams; 21: the base's too.
    EXPECT_TRUE(plain[4] < kMixedContextsVersion || plain[4] == kRawSideVersion || plain[4] == kBaseRawSideVersion);
}

// The coded symbols' code length under `model` (the hierarchy's own features, as the encoder
// computes them).
double mixing_model_bits(const Hierarchy& h, MixingModel model) {
    HierarchyLevelEncoder coder(h, HierarchyCoderOptions{}, kHierarchyStreamVersion, nullptr, true);
    coder.set_mixing_model(model);
    ArithmeticEncoder sink;
    for (int l = 0; l < coder.level_count(); ++l) coder.encode_level(l, sink);
    double bits = 0;
    for (const ContextGroupStats& g : coder.stats().groups) bits += g.coded_bits;
    return bits;
}

// A local threshold against the coded nodes of the level (refined / unrefined) stays 0 while no
// such node is coded.
void expect_zero_until_coded(const MixedFeatures& f, int refined, int unrefined) {
    if (f.coded_refined == 0) {
        EXPECT_EQ(refined, 0);
    }
    if (f.coded_unrefined == 0) {
        EXPECT_EQ(unrefined, 0);
    }
}

// The fifth model's local threshold (FORMAT.md 2.5): the features see only nodes coded before, and
// they make a curved remesh's code smaller than the fourth model's.
TEST(MixedContexts, TheLocalThresholdCodesACurvedRemeshSmallerThanTheFourthModel) {
    const Hierarchy h = testing::curved_sphere_remesh(20000);
    const HierarchyLevelEncoder coder(h, HierarchyCoderOptions{}, kHierarchyStreamVersion, nullptr, true);
    int compared = 0, first_of_level = 0, level = -1;
    for (const auto& [f, bit] : coder.mixed_symbols()) {
        if (f.level != level) {
            level = f.level;
            ++first_of_level;
            // The first symbol of a level: no node of the level is coded yet.
            EXPECT_EQ(f.coded_refined + f.coded_unrefined, 0);
            EXPECT_EQ(f.thr_refined + f.thr_unrefined, 0);
        }
        EXPECT_LE(f.coded_refined, 7);
        EXPECT_LE(f.thr_refined, 31);
        EXPECT_LE(f.thr_unrefined, 31);
        expect_zero_until_coded(f, f.thr_refined, f.thr_unrefined);
        compared += f.thr_refined != 0 && f.thr_unrefined != 0;
    }
    EXPECT_GE(first_of_level, 3);
    EXPECT_GT(compared, 1000);
    const double fourth = mixing_model_bits(h, MixingModel::fourth), fifth = mixing_model_bits(h, MixingModel::fifth);
    EXPECT_LT(fifth, fourth);
}

// The sixth model's ring means of the quadric (FORMAT.md 2.6): they average the node's quadric
// curvature with its neighbours', their local threshold sees only nodes coded before, and they make
// a curved remesh's code smaller than the fifth model's.
TEST(MixedContexts, TheQuadricsRingMeansCodeACurvedRemeshSmallerThanTheFifthModel) {
    const Hierarchy h = testing::curved_sphere_remesh(20000);
    const HierarchyLevelEncoder coder(h, HierarchyCoderOptions{}, kHierarchyStreamVersion, nullptr, true);
    int level = -1, averaged = 0, compared = 0;
    for (const auto& [f, bit] : coder.mixed_symbols()) {
        if (f.level != level) {
            level = f.level;
            EXPECT_EQ(f.quad_refined + f.quad_unrefined, 0) << "the first symbol of a level: no node of it is coded yet";
        }
        expect_zero_until_coded(f, f.quad_refined, f.quad_unrefined);
        EXPECT_LE(f.ring_quad_mean, 63);
        EXPECT_LE(f.quad_refined, 31);
        averaged += f.ring_quad_mean != f.quad_mean;
        compared += f.quad_refined != 0 && f.quad_unrefined != 0;
    }
    EXPECT_GT(averaged, 1000);
    EXPECT_GT(compared, 1000);
    const double fifth = mixing_model_bits(h, MixingModel::fifth), sixth = mixing_model_bits(h, MixingModel::sixth);
    EXPECT_LT(sixth, fifth);
}

// The seventh model's trained initial states (FORMAT.md 2.7): each table's string has a state per
// slot, in the alphabet; a state starts its slot at squash(128 s) with kTrainedCount symbols seen
// (known answers), an untrained slot flat.
TEST(MixedContexts, TheTrainedStatesCoverTheirTablesAndStartAtTheirStates) {
    const MixedHierarchyModel seventh(MixingModel::seventh);
    size_t trained = 0, slots = 0;
    for (size_t k = 0; k < kTrainedTables.size(); ++k) {
        SCOPED_TRACE(kTrainedTables[k]);
        const std::string states = kTrainedStateTables[k];
        ASSERT_EQ(states.size(), seventh.table_size(kTrainedTables[k]));
        for (char c : states) {
            ASSERT_TRUE(c == kUntrainedSlot || trained_state_char(trained_state_of(c)) == c) << c;
            trained += c != kUntrainedSlot;
        }
        slots += states.size();
    }
    EXPECT_EQ(slots, 112704u);
    EXPECT_GT(trained, slots / 4);
    for (int s = -kLargestTrainedState; s <= kLargestTrainedState; ++s) EXPECT_EQ(trained_state_of(trained_state_char(s)), s);
    EXPECT_EQ(trained_state_char(0), '0');
    EXPECT_EQ(trained_state_char(15), 'O');
    EXPECT_EQ(trained_state_char(-1), 'a');
    const BitModel flat = trained_state(kUntrainedSlot, 8), even = trained_state('0', 8), likely = trained_state('O', 8);
    const BitModel unlikely = trained_state('a', 8);
    EXPECT_EQ(flat.p, uint32_t{1} << 31);
    EXPECT_EQ(flat.n, 0);
    EXPECT_EQ(even.p, uint32_t{2047} << 20);  // squash(0)
    EXPECT_EQ(likely.p, uint32_t{4093} << 20);    // squash(1920), the last knot but one
    EXPECT_EQ(unlikely.p, uint32_t{1546} << 20);  // squash(-128): odds of e^-1/2
    EXPECT_EQ(likely.n, kTrainedCount);
    EXPECT_EQ(likely.limit_log2, 8);
}

// The trained states make a curved remesh's code smaller than the sixth model's: the remesh is none
// of the training models (bunny, elephant and the rest: bench/trained_states).
TEST(MixedContexts, TheTrainedStatesCodeACurvedRemeshSmallerThanTheSixthModel) {
    const Hierarchy h = testing::curved_sphere_remesh(20000);
    const double sixth = mixing_model_bits(h, MixingModel::sixth), seventh = mixing_model_bits(h, MixingModel::seventh);
    EXPECT_LT(seventh, sixth);
}

// The traversal bit of the hierarchy header (FORMAT.md 2) in every mixing model's version the
// encoder writes: the same hierarchy coded in the naive and in the improved traversal gives two
// files whose hierarchy codes differ, and each decodes to the input; a decoder that read either
// file in the other traversal's order would decode another forest (or fail). The older models'
// versions come from small random hierarchies, where they code smaller, the seventh's (20, and 21
// bit-exact) from curved remeshes.
TEST(MixedContexts, EveryMixingVersionDecodesBothTraversals) {
    std::map<int, int> seen[2];  // by traversal: version -> files
    auto round_trips = [&](const Hierarchy& h, int bits, const std::string& name) {
        EncodeOptions options;
        options.hierarchy_contexts = HierarchyContexts::mixed;
        options.choose_traversal = false;
        options.quantize_bits = bits;
        std::vector<uint8_t> files[2];
        for (const Traversal t : {Traversal::naive, Traversal::improved}) {
            SCOPED_TRACE(name + (t == Traversal::naive ? ", naive" : ", improved"));
            options.hierarchy.traversal = t;
            std::vector<uint8_t>& bytes = files[int(t)];
            bytes = encode(h, options);
            Hierarchy expected = in_decoder_order(h, options);
            const Hierarchy back = decode(bytes.data(), bytes.size());
            if (bits != 0) {
                ASSERT_EQ(back.vertex_count(), expected.vertex_count());
                expected.set_single_precision(false);
                for (VertexId v = 0; v < expected.positions().size(); ++v) expected.set_position(v, back.position(v));
            }
            ASSERT_TRUE(identical(back, expected));
            ++seen[int(t)][bytes[4]];
        }
        ASSERT_NE(files[0], files[1]) << name;
    };
    Random random{31};
    const auto meshes = testing::fixture_meshes();
    for (int trial = 0; trial < 120; ++trial) {
        Hierarchy h(meshes[random.next() % meshes.size()].mesh);
        refine_randomly(h, h.root_count() + uint32_t(random.next() % 800), 2 + int(random.next() % 4), random.next());
        for (VertexId v = 0; v < h.positions().size(); ++v) {
            const Vec3 p = h.position(v);
            h.set_position(v, p + 0.01 * double(random.next() % 100) * Vec3{p.y, p.z, p.x});
        }
        round_trips(h, trial % 2 == 0 ? 0 : 12, "trial " + std::to_string(trial));
    }
    const Hierarchy remesh = testing::curved_sphere_remesh(8000);
    for (const int bits : {0, 12}) round_trips(remesh, bits, "remesh, " + std::to_string(bits) + " bits");
    for (const int version : {int(kThirdMixingVersion), int(kFourthMixingVersion), int(kFifthMixingVersion), int(kSixthMixingVersion),
                              int(kSeventhMixingVersion), int(kBaseRawSideVersion)}) {
        EXPECT_GE(seen[int(Traversal::naive)][version], 1) << "no naive file of version " << version;
        EXPECT_GE(seen[int(Traversal::improved)][version], 1) << "no improved file of version " << version;
    }
}

// EncodeOptions::choose_traversal: the mixing mode's file is the smaller of the two traversals'
// (the seventh model's, or an older model's in the asked traversal), a tie the asked one's; the
// paper mode ignores it.
TEST(MixedContexts, TheEncoderKeepsTheSmallerTraversal) {
    int naive_won = 0, improved_won = 0;
    for (const uint32_t faces : {3000u, 8000u, 20000u}) {
        const Hierarchy h = testing::curved_sphere_remesh(faces);
        for (const int bits : {0, 12}) {
            EncodeOptions options;
            options.hierarchy_contexts = HierarchyContexts::mixed;
            options.quantize_bits = bits;
            options.choose_traversal = false;
            std::vector<uint8_t> files[2];
            for (const Traversal t : {Traversal::naive, Traversal::improved}) {
                options.hierarchy.traversal = t;
                files[int(t)] = encode(h, options);
            }
            options.choose_traversal = true;
            options.hierarchy.traversal = Traversal::improved;
            const std::vector<uint8_t> chosen = encode(h, options);
            const bool naive = files[0].size() < files[1].size();
            // The naive file in the seventh model (an older one is not tried in the other traversal).
            const bool naive_seventh = files[0][4] == kSeventhMixingVersion || files[0][4] == kBaseRawSideVersion;
            if (naive && naive_seventh) {
                EXPECT_EQ(chosen, files[0]) << faces << " faces, " << bits << " bits";
                ++naive_won;
            } else if (!naive) {
                EXPECT_EQ(chosen, files[1]) << faces << " faces, " << bits << " bits";
                ++improved_won;
            }
            EXPECT_LE(chosen.size(), files[1].size());
            EXPECT_TRUE(identical(decode(chosen.data(), chosen.size()), in_decoder_order(h, options)) || bits != 0);
            EncodeOptions paper = options;
            paper.hierarchy_contexts = HierarchyContexts::paper;
            EncodeOptions paper_asked = paper;
            paper_asked.choose_traversal = false;
            EXPECT_EQ(encode(h, paper), encode(h, paper_asked));
        }
    }
    EXPECT_GE(naive_won, 1);
    EXPECT_GE(improved_won, 1);
}

TEST(MixedContexts, TheModeIsRefusedInOlderVersions) {
    Hierarchy h(make_icosahedron());
    refine_randomly(h, 200, 3, 5);
    EncodeOptions options;
    options.hierarchy_contexts = HierarchyContexts::mixed;
    const std::vector<uint8_t> bytes = encode(h, options);
    // The same blocks framed as the version before.
    BlockReader reader(bytes.data(), bytes.size());
    BlockWriter writer(kMixedContextsVersion - 1, reader.flags());
    Block block{};
    while (reader.next(block)) {
        if (block.type == BlockType::end) break;
        writer.add(block.type, std::vector<uint8_t>(block.payload, block.payload + block.size));
    }
    const std::vector<uint8_t> older = writer.finish();
    try {
        decode(older.data(), older.size());
        FAIL() << "a file of the version before with mixed contexts decoded";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("mixed hierarchy contexts in a version-" + std::to_string(kMixedContextsVersion - 1) + " file"),
                  std::string::npos)
            << e.what();
    }
}

}  // namespace
}  // namespace amc
