// The .amh hierarchy file: exact round trips and validation of every field.
#include "hierarchy_checks.h"

#include <amc/codec.h>

#include <cstring>

namespace amc {
namespace {

Hierarchy sample_hierarchy() {
    Hierarchy h(make_torus(6, 5, 2.0, 0.7));
    refine_randomly(h, 2000, 5, 7);
    // Override some diagonals of two-hanging-node leaves.
    int flipped = 0;
    for (NodeId n : h.leaves()) {
        if (h.hanging_node_count(n) == 2 && (flipped++ % 2) == 0) h.set_diagonal_flipped(n, true);
    }
    return h;
}

TEST(HierarchyFile, RoundTripIsIdentical) {
    const Hierarchy h = sample_hierarchy();
    const std::string bytes = serialize_hierarchy(h);
    const Hierarchy back = deserialize_hierarchy(bytes, "memory");
    EXPECT_TRUE(identical(h, back));
    EXPECT_TRUE(testing::hierarchy_is_valid(back));
    EXPECT_EQ(serialize_hierarchy(back), bytes) << "the file is canonical";
    EXPECT_EQ(extract_leaf_mesh(back).mesh.triangles, extract_leaf_mesh(h).mesh.triangles);
}

// A hierarchy read from a file has had its structure checked, so writers skip that check, until
// the forest changes: a split that leaves a neighbour with three hanging nodes is refused again.
TEST(HierarchyFile, WritersCheckAgainOnceTheForestChanges) {
    const Hierarchy read = deserialize_hierarchy(serialize_hierarchy(sample_hierarchy()), "memory");
    EXPECT_FALSE(encode(read, EncodeOptions{}).empty());
    bool broken = false;
    for (NodeId n : read.leaves()) {
        if (!read.can_split(n)) continue;
        Hierarchy h = read;
        h.split(n);
        if (check_invariants(h).empty()) continue;
        EXPECT_THROW(serialize_hierarchy(h), Error);
        EXPECT_THROW(encode(h, EncodeOptions{}), Error);
        broken = true;
        break;
    }
    EXPECT_TRUE(broken) << "no split broke the closure";
}

TEST(HierarchyFile, IdenticalNoticesDifferences) {
    const Hierarchy h = sample_hierarchy();
    Hierarchy moved = h;
    moved.set_position(h.vertex_count() - 1, {1e9, 0, 0});
    EXPECT_FALSE(identical(h, moved));
    Hierarchy flipped = h;
    for (NodeId n : h.leaves()) {
        if (h.hanging_node_count(n) == 2) {
            flipped.set_diagonal_flipped(n, !h.diagonal_flipped(n));
            break;
        }
    }
    EXPECT_FALSE(identical(h, flipped));
    Hierarchy refined = h;
    refined.refine(refined.leaves().front());
    EXPECT_FALSE(identical(h, refined));
}

TEST(HierarchyFile, SinglePrecisionStaysSingle) {
    TriangleMesh base = make_bumpy_sphere(0);
    Hierarchy h(base);
    refine_uniformly(h, 2);
    const std::string bytes = serialize_hierarchy(h);
    const Hierarchy back = deserialize_hierarchy(bytes, "memory");
    EXPECT_TRUE(back.single_precision());
    EXPECT_TRUE(identical(h, back));
}

TEST(HierarchyFile, EveryTruncationIsRejected) {
    const Hierarchy h = sample_hierarchy();
    const std::string bytes = serialize_hierarchy(h);
    for (size_t length = 0; length < bytes.size(); length += (length < 200 ? 1 : 97)) {
        EXPECT_THROW(deserialize_hierarchy(bytes.substr(0, length), "cut"), Error) << length;
    }
    EXPECT_THROW(deserialize_hierarchy(bytes + "x", "long"), Error);
}

TEST(HierarchyFile, CorruptionsGiveErrorsOrValidHierarchies) {
    Hierarchy h(make_icosahedron());
    refine_randomly(h, 300, 4, 5);
    const std::string bytes = serialize_hierarchy(h);
    uint64_t state = 12345;
    for (int trial = 0; trial < 3000; ++trial) {
        std::string corrupt = bytes;
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        const size_t at = size_t(state >> 33) % corrupt.size();
        corrupt[at] = char(corrupt[at] ^ char(1u << ((state >> 20) % 8)));
        try {
            const Hierarchy back = deserialize_hierarchy(corrupt, "corrupt");
            EXPECT_EQ(check_invariants(back), "");
        } catch (const Error&) {
        }
    }
}

TEST(HierarchyFile, MessagesNameTheProblem) {
    Hierarchy h(make_icosahedron());
    h.refine(0);
    std::string bytes = serialize_hierarchy(h);
    std::string bad_magic = bytes;
    bad_magic[0] = 'X';
    try {
        deserialize_hierarchy(bad_magic, "f.amh");
        FAIL();
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("f.amh"), std::string::npos);
        EXPECT_NE(std::string(e.what()).find("magic"), std::string::npos);
    }
}

TEST(HierarchyFile, UnbalancedForestIsRejected) {
    Hierarchy h(make_icosahedron());
    h.refine(0);
    std::string bytes = serialize_hierarchy(h);
    // Patch node count (header field 5, at byte 20) to 28 and set the bit of node 0's first child.
    const uint32_t nodes = 28;
    std::memcpy(&bytes[20], &nodes, 4);
    const size_t bits_at = 32 + 12 * 3 * 8 + 20 * 12;
    bytes[bits_at + 20 / 8] = char(uint8_t(bytes[bits_at + 20 / 8]) | (1u << (20 % 8)));
    // The file now claims 4 more nodes and 3 more vertices than it holds, so append their bytes.
    const uint32_t vertices = 6;
    std::memcpy(&bytes[28], &vertices, 4);
    bytes.insert(bits_at + 3, std::string(1, '\0'));  // 28 bits need 4 bytes, 24 needed 3
    bytes += std::string(3 * 3 * 8, '\0');
    try {
        deserialize_hierarchy(bytes, "u.amh");
        FAIL() << "accepted an unbalanced forest";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("balanced"), std::string::npos) << e.what();
    }
}

// A leaf whose three neighbours are refined (a root of the icosahedron with its three neighbour
// roots split) is not a closed forest.
TEST(HierarchyFile, LeafWithThreeHangingNodesIsRejected) {
    const Hierarchy unrefined(make_icosahedron());
    std::string bytes = serialize_hierarchy(unrefined);
    const uint32_t nodes = 20 + 3 * 4, vertices = 3 * 3;  // the three neighbours share no edge
    std::memcpy(&bytes[20], &nodes, 4);
    std::memcpy(&bytes[28], &vertices, 4);
    const size_t bits_at = 32 + 12 * 3 * 8 + 20 * 12;
    bytes.insert(bits_at + 3, std::string(1, '\0'));  // 32 bits need 4 bytes, 20 needed 3
    for (int e = 0; e < 3; ++e) {
        const NodeId q = unrefined.neighbor(0, e);
        bytes[bits_at + q / 8] = char(uint8_t(bytes[bits_at + q / 8]) | (1u << (q % 8)));
    }
    bytes += std::string(size_t(vertices) * 3 * 8, '\0');
    try {
        deserialize_hierarchy(bytes, "c.amh");
        FAIL() << "accepted a leaf with three hanging nodes";
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), ErrorCode::corrupt);
        EXPECT_NE(std::string(e.what()).find("element 0 has three hanging nodes"), std::string::npos) << e.what();
    }
}

// The node count is checked against the refinement bits before the forest is built in room made
// for that many nodes.
TEST(HierarchyFile, NodeCountMustMatchTheRefinementBits) {
    Hierarchy h(make_icosahedron());
    h.refine(0);
    std::string bytes = serialize_hierarchy(h);
    uint32_t nodes = 0;
    std::memcpy(&nodes, &bytes[20], 4);
    const uint32_t claimed = nodes + 4;  // one more refined node than the bits say
    std::memcpy(&bytes[20], &claimed, 4);
    const size_t bits_at = 32 + 12 * 3 * 8 + 20 * 12;
    if ((claimed + 7) / 8 > (nodes + 7) / 8) bytes.insert(bits_at + (nodes + 7) / 8, std::string(1, '\0'));
    try {
        deserialize_hierarchy(bytes, "n.amh");
        FAIL() << "accepted a node count the refinement bits do not make";
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), ErrorCode::corrupt);
        EXPECT_NE(std::string(e.what()).find("announces " + std::to_string(claimed) + " nodes but the refinement bits make " +
                                             std::to_string(nodes)),
                  std::string::npos)
            << e.what();
    }
}

}  // namespace
}  // namespace amc
