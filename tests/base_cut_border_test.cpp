// Mode 0's cut border keeps each loop twice, as a ring and as a splay tree: every answer the
// trees give (gate choice, walks, offsets, loop membership) must be what a scan of the ring gives,
// after any sequence of the machine's operations.
#include "coding/base/base_cut_border.h"

#include <gtest/gtest.h>

#include <random>
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

}  // namespace
}  // namespace amc
