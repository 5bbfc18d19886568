// Mode 0's cut border keeps each loop twice, as a ring and as a splay tree: every answer the
// trees give (gate choice, walks, offsets, loop membership) must be what a scan of the ring gives,
// after any sequence of the machine's operations.
#include "coding/base/base_cut_border.h"
#include "coding/base/base_mesh_coder.h"
#include "coding/base/base_mesh_stream.h"
#include "coding/entropy/arithmetic_coder.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <string>
#include <vector>

namespace amc {
namespace {

uint32_t ring_walk(const CutBorder& border, uint32_t n, uint32_t steps) {
    for (uint32_t i = 0; i < steps; ++i) n = border.next[n];
    return n;
}

// The old gate rule, by scanning: the first node from the gate on whose vertex has the most
// triangles.
uint32_t scanned_gate(const CutBorder& border) {
    const CutBorder::Loop& loop = border.stack.back();
    uint32_t best = loop.gate, n = loop.gate;
    for (uint32_t i = 1; i < loop.length; ++i) {
        n = border.next[n];
        if (border.degree[border.vert[n]] > border.degree[border.vert[best]]) best = n;
    }
    return best;
}

void expect_rings_match_lengths(const CutBorder& border) {
    for (const CutBorder::Loop& loop : border.stack) {
        uint32_t n = loop.gate, count = 0;
        do {
            ASSERT_EQ(border.prev[border.next[n]], n);
            n = border.next[n];
            ++count;
        } while (n != loop.gate && count <= loop.length);
        ASSERT_EQ(count, loop.length);
    }
}

TEST(CutBorder, TreesAnswerAsTheRingsDo) {
    std::mt19937 rng(7);
    for (int round = 0; round < 20; ++round) {
        CutBorder border(0, UINT64_MAX);
        auto new_vertex = [&] { return border.add_vertex(); };
        auto any_vertex = [&] { return uint32_t(rng() % border.degree.size()); };
        auto touch = [&](int count) {
            for (int i = 0; i < count; ++i) border.count_triangle(any_vertex(), any_vertex(), any_vertex());
        };
        const uint32_t a = new_vertex(), b = new_vertex(), c = new_vertex();
        border.start(a, b, c);
        for (int step = 0; step < 1500 && !border.stack.empty(); ++step) {
            const uint32_t length = border.top().length;
            const uint32_t g = border.top().gate, nv = border.next[g];
            const int kind = int(rng() % 10);
            if (kind < 4 && step < 1000) {
                border.op_new(new_vertex());
            } else if (kind < 6) {
                if (length == 3) border.op_end();
                else border.op_right();
                touch(int(rng() % 4));
                if (border.stack.empty()) break;
                const uint32_t expected = scanned_gate(border);
                border.choose_gate();
                ASSERT_EQ(border.top().gate, expected) << "round " << round << " step " << step;
            } else if (kind == 6 && length > 3) {
                border.op_left();
            } else if (kind == 7 && length >= 5) {
                const uint32_t k = 2 + uint32_t(rng() % (length - 4));
                const uint32_t n = border.walk(nv, k);
                ASSERT_EQ(n, ring_walk(border, nv, k));
                ASSERT_EQ(border.steps_between(nv, n), k);
                ASSERT_TRUE(border.same_loop(n, g));
                border.op_split(n, k);
            } else if (kind >= 8 && border.stack.size() >= 2) {
                const size_t index = rng() % (border.stack.size() - 1);
                const CutBorder::Loop other = border.stack[index];
                const uint32_t offset = uint32_t(rng() % other.length);
                const uint32_t n = border.walk(other.gate, offset);
                ASSERT_EQ(n, ring_walk(border, other.gate, offset));
                ASSERT_EQ(border.steps_between(other.gate, n), offset);
                ASSERT_FALSE(border.same_loop(n, g));
                border.op_merge(n, index);
            } else {
                touch(1);
            }
            expect_rings_match_lengths(border);
        }
    }
}

TEST(CutBorder, EveryBorderNodeOfAVertexIsListed) {
    CutBorder border(0, UINT64_MAX);
    for (int i = 0; i < 3; ++i) border.add_vertex();
    border.start(0, 1, 2);
    border.op_new(border.add_vertex());  // 0 -> 3 -> 2 -> 1
    border.op_new(border.add_vertex());  // 0 -> 4 -> 3 -> 2 -> 1
    // S from gate 0 -> 4 with the tip at vertex 2 (two steps after 4): vertex 2 then has two nodes.
    const uint32_t nv = border.next[border.top().gate];
    border.op_split(border.walk(nv, 2), 2);
    std::vector<uint32_t> nodes;
    for (uint32_t x = border.first_node_of(2); x != CutBorder::kNoBorderNode; x = border.next_node_of(x))
        nodes.push_back(x);
    ASSERT_EQ(nodes.size(), 2u);
    EXPECT_EQ(border.vert[nodes[0]], 2u);
    EXPECT_EQ(border.vert[nodes[1]], 2u);
    EXPECT_FALSE(border.same_loop(nodes[0], nodes[1]));
}

// count_triangle reports the budget passed: one update per border node of each vertex.
TEST(CutBorder, UpdatesAreCountedAgainstTheBudget) {
    CutBorder border(0, 6);
    for (int i = 0; i < 3; ++i) border.add_vertex();
    EXPECT_TRUE(border.count_triangle(0, 1, 2));  // no border nodes yet: no updates
    border.start(0, 1, 2);
    EXPECT_TRUE(border.count_triangle(0, 1, 2));  // 3 updates
    EXPECT_TRUE(border.count_triangle(0, 1, 2));  // 6
    EXPECT_FALSE(border.count_triangle(0, 1, 2));  // 9
    EXPECT_EQ(border.degree[0], 4u);
}

// A mode-0 stream made to update many border nodes (FORMAT.md 4.5): `rounds` splits whose tip is
// always vertex c leave c with a node in each of `rounds` small loops; an E then hands the gate to
// c (the most triangles), and `fans` C ops around c update every one of those nodes. The stream
// stops there, so a decoder that reads on fails later, on its end.
std::vector<uint8_t> many_nodes_of_one_vertex(uint32_t rounds, uint32_t fans, uint32_t& vertex_count) {
    vertex_count = 3 + 2 * rounds + fans;
    ArithmeticEncoder enc;
    enc.encode_bits_raw(0, 2);  // mode 0
    for (uint32_t count : {vertex_count, 0u, 0u, 0u, 1u, 0u}) put_count(enc, count);  // no isolated, dummies, copies; one component; no merges
    // The decoder's models, laid out as base_cut_border_coder.cpp's OpModels.
    BitModel is_new[8], is_right[8], is_left[8], is_split;
    SplitOffsetModels split;
    auto degree_class = [](uint32_t d) { return std::min<uint32_t>(d, 7); };
    CutBorder border(0, UINT64_MAX);
    auto gate = [&] { return border.top().gate; };
    auto u = [&] { return border.vert[gate()]; };
    auto v = [&] { return border.vert[border.next[gate()]]; };
    const uint32_t a = border.add_vertex(), b = border.add_vertex(), c = border.add_vertex();
    border.count_triangle(a, b, c);
    border.start(a, b, c);
    auto op_new = [&] {
        enc.encode(true, is_new[degree_class(border.degree[u()])]);
        const uint32_t w = border.add_vertex();
        border.count_triangle(u(), v(), w);
        border.op_new(w);
    };
    for (uint32_t round = 0; round < rounds; ++round) {
        op_new();
        op_new();  // a -> w -> w' -> c -> b: c is two steps after the gate's far end
        enc.encode(false, is_new[degree_class(border.degree[u()])]);
        enc.encode(false, is_right[degree_class(border.degree[u()])]);
        enc.encode(false, is_left[degree_class(border.degree[v()])]);
        if (border.stack.size() >= 2) enc.encode(true, is_split);
        put_split_offset(enc, split, 0, border.top().length - 4);
        const uint32_t tip = border.walk(border.next[gate()], 2);
        EXPECT_EQ(border.vert[tip], c);
        border.count_triangle(u(), v(), c);
        border.op_split(tip, 2);
    }
    enc.encode(false, is_new[degree_class(border.degree[u()])]);
    enc.encode(true, is_right[degree_class(border.degree[u()])]);  // E: a -> c -> b closes
    border.count_triangle(u(), v(), border.vert[border.prev[gate()]]);
    border.op_end();
    border.choose_gate();
    EXPECT_EQ(u(), c);
    for (uint32_t i = 0; i < fans; ++i) op_new();
    return enc.finish();
}

std::string decode_error(const std::vector<uint8_t>& stream, uint32_t vertex_count) {
    try {
        decode_base_mesh(stream.data(), stream.size(), vertex_count,
                         [](uint32_t, const BaseStencil&, const std::vector<Vec3>&) { return Vec3{0, 0, 0}; });
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

// 2,000 rounds (about 4 M updates: c's nodes are updated as they pile up) and 9,000 triangles
// around c's 2,000 nodes pass 64 · Fc + 2^24 updates (the decoder gives up there); with 5,000
// triangles they do not (it reads every op, then the bytes past them ask for one more vertex).
TEST(CutBorder, ModeZeroRefusesAStreamPastTheUpdateBound) {
    uint32_t vertices = 0;
    const std::vector<uint8_t> past = many_nodes_of_one_vertex(2000, 9000, vertices);
    EXPECT_NE(decode_error(past, vertices).find("too many border nodes"), std::string::npos) << decode_error(past, vertices);
    const std::vector<uint8_t> within = many_nodes_of_one_vertex(2000, 5000, vertices);
    const std::string error = decode_error(within, vertices);
    EXPECT_NE(error.find("more vertices than announced"), std::string::npos) << error;
}

}  // namespace
}  // namespace amc
