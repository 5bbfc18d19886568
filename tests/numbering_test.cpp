// The caller's numbering: found by matching faces, stored in the numbering block, restored exactly.
#include <amc/codec.h>
#include <amc/numbering.h>
#include <amc/refinement.h>

#include "coding/container.h"
#include "coding/numbering/numbering_coder.h"
#include "hierarchy_checks.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>

namespace amc {
namespace {

using testing::Random;

// The leaf mesh of h as a caller might hold it: vertices and faces shuffled, each face's corners
// rotated; with the hierarchy vertex of each of its vertices.
struct CallerMesh {
    TriangleMesh mesh;
    std::vector<VertexId> vertex_of_input;
};

CallerMesh shuffled_leaf_mesh(const Hierarchy& h, Random& random, bool shuffle_vertices, bool shuffle_faces,
                              bool rotate_faces) {
    const LeafMesh leaf = extract_leaf_mesh(h);
    const std::vector<uint32_t> canonical = canonical_vertex_order(h);
    std::vector<VertexId> id_of_leaf_vertex(leaf.mesh.positions.size());
    for (VertexId v = 0; v < canonical.size(); ++v)
        if (canonical[v] != kNoVertex) id_of_leaf_vertex[canonical[v]] = v;
    const uint32_t n = uint32_t(leaf.mesh.positions.size());
    std::vector<uint32_t> order(n);  // caller vertex i is leaf vertex order[i]
    for (uint32_t i = 0; i < n; ++i) order[i] = i;
    if (shuffle_vertices)
        for (uint32_t i = n; i > 1; --i) std::swap(order[i - 1], order[random.next() % i]);
    std::vector<uint32_t> caller_of_leaf(n);
    CallerMesh out;
    out.mesh.single_precision = leaf.mesh.single_precision;
    for (uint32_t i = 0; i < n; ++i) {
        caller_of_leaf[order[i]] = i;
        out.mesh.positions.push_back(leaf.mesh.positions[order[i]]);
        out.vertex_of_input.push_back(id_of_leaf_vertex[order[i]]);
    }
    for (const Triangle& t : leaf.mesh.triangles) {
        const int r = rotate_faces ? int(random.next() % 3) : 0;
        out.mesh.triangles.push_back({caller_of_leaf[t[r]], caller_of_leaf[t[(r + 1) % 3]], caller_of_leaf[t[(r + 2) % 3]]});
    }
    if (shuffle_faces) {
        auto& f = out.mesh.triangles;
        for (size_t i = f.size(); i > 1; --i) std::swap(f[i - 1], f[random.next() % i]);
    }
    return out;
}

bool same_mesh(const TriangleMesh& a, const TriangleMesh& b) {
    if (a.triangles != b.triangles || a.positions.size() != b.positions.size()) return false;
    for (size_t i = 0; i < a.positions.size(); ++i)
        if (!(a.positions[i] == b.positions[i])) return false;
    return true;
}

Hierarchy random_hierarchy(int seed) {
    const std::vector<testing::NamedMesh> bases = testing::fixture_meshes();
    Hierarchy h(bases[seed % bases.size()].mesh);
    refine_randomly(h, 200 + 37 * uint32_t(seed), 6, uint64_t(seed) + 1, seed % 2 ? 0.2 : 0.0);
    Random random{uint64_t(seed) * 7 + 3};
    for (NodeId n : h.leaves())
        if (random.next() % 3 == 0) h.set_diagonal_flipped(n, true);
    return h;
}

double log2_factorial(double n) { return std::lgamma(n + 1) / std::log(2.0); }

TEST(Numbering, FoundAndRestoredExactly) {
    for (int seed = 0; seed < 20; ++seed) {
        const Hierarchy h = random_hierarchy(seed);
        Random random{uint64_t(seed) + 11};
        const CallerMesh caller = shuffled_leaf_mesh(h, random, seed % 4 != 0, seed % 3 != 0, seed % 2 == 0);
        const LeafNumbering numbering = leaf_numbering(h, caller.mesh, caller.vertex_of_input);
        EXPECT_TRUE(same_mesh(renumber_leaf_mesh(extract_leaf_mesh(h), numbering), caller.mesh)) << "seed " << seed;
    }
}

TEST(Numbering, StoredNumberingDecodesToTheCallersMesh) {
    for (int seed = 0; seed < 24; ++seed) {
        const Hierarchy h = random_hierarchy(seed);
        Random random{uint64_t(seed) + 5};
        const CallerMesh caller = shuffled_leaf_mesh(h, random, seed % 4 != 1, seed % 3 != 1, seed % 2 == 1);
        const LeafNumbering numbering = leaf_numbering(h, caller.mesh, caller.vertex_of_input);
        EncodeOptions options;
        options.numbering = &numbering;
        options.quantize_bits = seed % 5 == 0 ? 12 : 0;
        EncodeStats stats;
        const std::vector<uint8_t> bytes = encode(h, options, &stats);
        EXPECT_GE(bytes[4], kNumberingVersion);  // 4 when the base is in connectivity mode 2
        LeafNumbering decoded_numbering;
        const Hierarchy decoded = decode(bytes.data(), bytes.size(), {}, &decoded_numbering);
        EXPECT_EQ(decoded_numbering.vertex, stats.numbering.vertex);
        EXPECT_EQ(decoded_numbering.face, stats.numbering.face);
        EXPECT_EQ(decoded_numbering.rotation, stats.numbering.rotation);
        const TriangleMesh restored = renumber_leaf_mesh(extract_leaf_mesh(decoded), decoded_numbering);
        EXPECT_EQ(restored.triangles, caller.mesh.triangles) << "seed " << seed;
        if (options.quantize_bits == 0) {
            EXPECT_TRUE(same_mesh(restored, caller.mesh)) << "seed " << seed;
        }
    }
}

TEST(Numbering, KeptOutOfTheFileTheMapStillFitsTheDecodedMesh) {
    const Hierarchy h = random_hierarchy(3);
    Random random{99};
    const CallerMesh caller = shuffled_leaf_mesh(h, random, true, true, true);
    const LeafNumbering numbering = leaf_numbering(h, caller.mesh, caller.vertex_of_input);
    EncodeOptions options;
    options.numbering = &numbering;
    options.store_numbering = false;
    EncodeStats stats;
    const std::vector<uint8_t> bytes = encode(h, options, &stats);
    EXPECT_TRUE(bytes[4] == kBaseVersion || bytes[4] == kSearchedBaseVersion || bytes[4] == kRawSideVersion ||
                bytes[4] == kBaseRawSideVersion);  // not the numbering's version 3
    EXPECT_EQ(stats.numbering_bytes, 0u);
    LeafNumbering none;
    const Hierarchy decoded = decode(bytes.data(), bytes.size(), {}, &none);
    EXPECT_TRUE(none.empty());
    EXPECT_TRUE(same_mesh(renumber_leaf_mesh(extract_leaf_mesh(decoded), stats.numbering), caller.mesh));
}

TEST(Numbering, CanonicalOrderCostsAlmostNothingAndARandomOneAboutLog2Factorial) {
    const Hierarchy h = random_hierarchy(7);
    Random random{1};
    for (bool shuffled : {false, true}) {
        const CallerMesh caller = shuffled_leaf_mesh(h, random, shuffled, shuffled, shuffled);
        const LeafNumbering numbering = leaf_numbering(h, caller.mesh, caller.vertex_of_input);
        EncodeOptions options;
        options.numbering = &numbering;
        EncodeStats stats;
        encode(h, options, &stats);
        const double v = double(caller.mesh.positions.size()), f = double(caller.mesh.triangles.size());
        const double bound_bits = log2_factorial(v) + log2_factorial(f) + f * std::log2(3.0);
        std::printf("%s: %u vertices, %u faces, %llu bytes, log2 bound %.0f bytes\n", shuffled ? "shuffled" : "canonical",
                    unsigned(v), unsigned(f), (unsigned long long)stats.numbering_bytes, bound_bits / 8);
        if (!shuffled) {
            // The decoder's base order differs from the input's, so even the canonical order of the
            // input costs a little: the base vertices' permutation and local rotations.
            EXPECT_LT(double(stats.numbering_bytes), 0.1 * bound_bits / 8 + 16);
        } else {
            EXPECT_LT(double(stats.numbering_bytes), bound_bits / 8 * 1.02 + 16);
            EXPECT_GT(double(stats.numbering_bytes), bound_bits / 8 * 0.98);
        }
    }
}

TEST(Numbering, AnOrderThatWalksTheMeshCostsAFewBitsPerElement) {
    // A grid numbered row by row, as mesh generators write it: each vertex and face is next to the
    // one before, so the walk method codes it; round trip exact.
    const TriangleMesh grid = make_square(40);
    const Hierarchy h(grid);
    std::vector<VertexId> vertex_of_input(grid.positions.size());
    for (uint32_t i = 0; i < vertex_of_input.size(); ++i) vertex_of_input[i] = i;
    EncodeOptions options;
    const LeafNumbering numbering = leaf_numbering(h, grid, vertex_of_input);
    options.numbering = &numbering;
    EncodeStats stats;
    const std::vector<uint8_t> bytes = encode(h, options, &stats);
    const Hierarchy decoded = decode(bytes.data(), bytes.size());
    const std::vector<Triangle> leaf = extract_leaf_mesh(decoded).mesh.triangles;
    NumberingCodeStats code;
    encode_numbering(stats.numbering, leaf, &code);
    EXPECT_EQ(code.vertex_method, 3);
    const double v = double(grid.positions.size()), f = double(grid.triangles.size());
    EXPECT_LT(8.0 * double(code.vertex_bytes) / v, 3.0);
    EXPECT_LT(8.0 * double(code.face_bytes) / f, 2.0);
    LeafNumbering back;
    decode(bytes.data(), bytes.size(), {}, &back);
    EXPECT_TRUE(same_mesh(renumber_leaf_mesh(extract_leaf_mesh(decoded), back), grid));
}

TEST(Numbering, MeshesThatAreNotTheLeafMeshAreRefused) {
    const Hierarchy h = random_hierarchy(2);
    Random random{4};
    CallerMesh caller = shuffled_leaf_mesh(h, random, true, true, true);
    CallerMesh flipped = caller;
    std::swap(flipped.mesh.triangles[5][0], flipped.mesh.triangles[5][1]);
    EXPECT_THROW(leaf_numbering(h, flipped.mesh, flipped.vertex_of_input), Error);
    CallerMesh repeated = caller;
    repeated.vertex_of_input[1] = repeated.vertex_of_input[0];
    EXPECT_THROW(leaf_numbering(h, repeated.mesh, repeated.vertex_of_input), Error);
    CallerMesh missing = caller;
    missing.mesh.triangles.pop_back();
    EXPECT_THROW(leaf_numbering(h, missing.mesh, missing.vertex_of_input), Error);
    CallerMesh twice = caller;
    twice.mesh.triangles[1] = twice.mesh.triangles[0];
    EXPECT_THROW(leaf_numbering(h, twice.mesh, twice.vertex_of_input), Error);
}

TEST(Numbering, EveryTruncationAndFlipOfTheBlockIsRefusedOrExact) {
    const Hierarchy h = random_hierarchy(5);
    Random random{8};
    const CallerMesh caller = shuffled_leaf_mesh(h, random, true, true, true);
    const LeafNumbering numbering = leaf_numbering(h, caller.mesh, caller.vertex_of_input);
    EncodeOptions options;
    options.numbering = &numbering;
    EncodeStats stats;
    const std::vector<uint8_t> bytes = encode(h, options, &stats);
    const Hierarchy decoded = decode(bytes.data(), bytes.size());
    const std::vector<Triangle> leaf = extract_leaf_mesh(decoded).mesh.triangles;
    BlockReader reader(bytes.data(), bytes.size());
    Block block{};
    std::vector<uint8_t> payload;
    while (reader.next(block))
        if (block.type == BlockType::numbering) payload.assign(block.payload, block.payload + block.size);
    ASSERT_FALSE(payload.empty());
    for (size_t cut = 0; cut < payload.size(); ++cut) {
        try {
            const LeafNumbering n = decode_numbering(payload.data(), cut, leaf, decoded.vertex_count());
            EXPECT_TRUE(check_numbering(n, decoded.vertex_count(), leaf.size()).empty());
        } catch (const Error&) {
        }
    }
    for (int trial = 0; trial < 500; ++trial) {
        std::vector<uint8_t> p = payload;
        p[random.next() % p.size()] ^= uint8_t(1u << (random.next() % 8));
        try {
            const LeafNumbering n = decode_numbering(p.data(), p.size(), leaf, decoded.vertex_count());
            EXPECT_TRUE(check_numbering(n, decoded.vertex_count(), leaf.size()).empty());
        } catch (const Error&) {
        }
    }
}

}  // namespace
}  // namespace amc

namespace amc {
namespace {

// Files with a numbering block are pinned byte for byte: tests/data/golden/v3/ (base connectivity
// mode 0), v4/, v5/ and v14/ (decoded only) and v21/ (what the encoder writes now: the base's raw
// bits in a side stream too). A new version's file goes into a new
// directory (AMC_UPDATE_GOLDEN=1 writes only a missing file), never over an old one.
TEST(NumberingGolden, NumberedFilesArePinnedAndRestoreTheCallersMesh) {
    Hierarchy h(make_l_shape(2));
    refine_randomly(h, 300, 5, 17);
    Random random{2026};
    const CallerMesh caller = shuffled_leaf_mesh(h, random, true, true, true);
    const LeafNumbering numbering = leaf_numbering(h, caller.mesh, caller.vertex_of_input);
    EncodeOptions options;
    options.numbering = &numbering;
    const std::vector<uint8_t> bytes = encode(h, options);
    const std::string newest = std::string(AMC_TEST_DATA_DIR) + "/golden/v21/lshape_random_numbered.amc";
    if (std::getenv("AMC_UPDATE_GOLDEN") != nullptr && !std::ifstream(newest))  // a new file, never over an old one
        std::ofstream(newest, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    for (const int version : {3, 4, 5, 14, 21}) {
        const std::string path = std::string(AMC_TEST_DATA_DIR) + "/golden/v" + std::to_string(version) + "/lshape_random_numbered.amc";
        std::ifstream file(path, std::ios::binary);
        ASSERT_TRUE(file) << path << " is missing";
        const std::vector<uint8_t> golden((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
        if (version == 21) {
            EXPECT_EQ(bytes, golden) << "the bitstream changed";
        }
        EXPECT_EQ(inspect(golden.data(), golden.size()).version, version);
        LeafNumbering decoded_numbering;
        const Hierarchy decoded = decode(golden.data(), golden.size(), {}, &decoded_numbering);
        EXPECT_TRUE(same_mesh(renumber_leaf_mesh(extract_leaf_mesh(decoded), decoded_numbering), caller.mesh)) << version;
    }
}

}  // namespace
}  // namespace amc
