// The red split: a node (v0, v1, v2), whose edge e joins v_e and v_{(e+1)%3} at its midpoint m_e,
// becomes four children. This header alone fixes the child order: which corners and midpoints
// each child has and how the children link. Hierarchy, its bulk split and the coders' level
// forest derive their tables from kChildPoints (scripts/check_child_order.sh checks that no other
// source restates it).
#pragma once

#include <cstdint>

namespace amc {
namespace red_split {

// The six points of a split: the parent's corners v0..v2 are points 0-2, the midpoints m0..m2 of
// its edges points 3-5.
constexpr int kCorner = 0;
constexpr int kMidpoint = 3;

// Child k's vertex i, as a point of the split. Children 0-2 are the corner children at v0..v2,
// child 3 the center. Every child's edge e is parallel to the parent's edge e, so local indices
// mean the same thing on all levels.
constexpr uint8_t kChildPoints[4][3] = {
    {kCorner + 0, kMidpoint + 0, kMidpoint + 2},
    {kMidpoint + 0, kCorner + 1, kMidpoint + 1},
    {kMidpoint + 2, kMidpoint + 1, kCorner + 2},
    {kMidpoint + 1, kMidpoint + 2, kMidpoint + 0},
};
constexpr int kCenter = 3;

// ---- derived from kChildPoints --------------------------------------------------------------

// Whether point p lies on the parent's edge e (its two ends and its midpoint).
constexpr bool on_parent_edge(int p, int e) { return p == kCorner + e || p == kCorner + (e + 1) % 3 || p == kMidpoint + e; }

// Whether child k's edge e lies on the parent's edge e (an outer edge), not inside the parent.
constexpr bool is_outer(int k, int e) {
    return on_parent_edge(kChildPoints[k][e], e) && on_parent_edge(kChildPoints[k][(e + 1) % 3], e);
}

// The sibling across child k's inner edge e (it meets it across its own edge e), or -1.
constexpr int sibling(int k, int e) {
    for (int j = 0; j < 4; ++j) {
        if (j != k && kChildPoints[j][e] == kChildPoints[k][(e + 1) % 3] &&
            kChildPoints[j][(e + 1) % 3] == kChildPoints[k][e])
            return j;
    }
    return -1;
}

// The child whose edge e holds the first half of the parent's edge e (from v_e to m_e), and the
// one whose edge e holds the second half (m_e to v_{e+1}).
constexpr int first_half_child(int e) {
    for (int k = 0; k < 4; ++k) {
        if (is_outer(k, e) && (kChildPoints[k][e] == kCorner + e || kChildPoints[k][(e + 1) % 3] == kCorner + e)) return k;
    }
    return -1;
}
constexpr int second_half_child(int e) {
    for (int k = 0; k < 4; ++k) {
        if (is_outer(k, e) && (kChildPoints[k][e] == kCorner + (e + 1) % 3 ||
                               kChildPoints[k][(e + 1) % 3] == kCorner + (e + 1) % 3))
            return k;
    }
    return -1;
}

// The neighbours of a split node's edge run the other way: across the first half of edge e lies
// the neighbour's child on the second half of its edge eq, and across the second half the one on
// the first half.
constexpr int child_across_first_half(int eq) { return second_half_child(eq); }
constexpr int child_across_second_half(int eq) { return first_half_child(eq); }

// Which vertex of the center child is the midpoint of the parent's edge e.
constexpr int center_vertex_of_midpoint(int e) {
    for (int i = 0; i < 3; ++i) {
        if (kChildPoints[kCenter][i] == kMidpoint + e) return i;
    }
    return -1;
}

// A node whose vertex i is an old node's vertex (i + r) % 3 (the same triangle, rotated) has as
// child k the old node's child rotated_child(k, r), rotated by r as well.
constexpr int rotate_point(int p, int r) {
    return p < kMidpoint ? kCorner + (p - kCorner + r) % 3 : kMidpoint + (p - kMidpoint + r) % 3;
}
constexpr int rotated_child(int k, int r) {
    for (int j = 0; j < 4; ++j) {
        bool same = true;
        for (int i = 0; i < 3; ++i) same = same && kChildPoints[j][(i + r) % 3] == rotate_point(kChildPoints[k][i], r);
        if (same) return j;
    }
    return -1;
}

// Per child k, its links as bit masks over the parent's: the bits of the parent's neighbour edge
// indices (2 bits per edge) that carry over to its outer edges, the fixed indices of its inner
// edges (a sibling meets it across the same edge index), and the parent's boundary edges it lies on.
struct ChildEdges {
    uint8_t outer;
    uint8_t inner;
    uint8_t boundary;
};
constexpr ChildEdges child_edges(int k) {
    ChildEdges c{0, 0, 0};
    for (int e = 0; e < 3; ++e) {
        if (is_outer(k, e)) {
            c.outer = uint8_t(c.outer | 3u << (2 * e));
            c.boundary = uint8_t(c.boundary | 1u << e);
        } else {
            c.inner = uint8_t(c.inner | unsigned(e) << (2 * e));
        }
    }
    return c;
}
constexpr ChildEdges kChildEdges[4] = {child_edges(0), child_edges(1), child_edges(2), child_edges(3)};

// The twelve link words of four siblings: word 3k + e is child k's neighbour across its edge e.
constexpr int link_word(int k, int e) { return 3 * k + e; }
// The words of the children on the first and the second half of the parent's edge e.
constexpr int first_half_word(int e) { return link_word(first_half_child(e), e); }
constexpr int second_half_word(int e) { return link_word(second_half_child(e), e); }

// What fills link word w: the neighbour across the first (kFirstHalf) or second (kSecondHalf)
// half of the parent's edge `edge`, or sibling `sibling` (kSibling).
struct LinkSource {
    enum Kind : uint8_t { kFirstHalf, kSecondHalf, kSibling } kind;
    uint8_t edge;     // kFirstHalf, kSecondHalf
    uint8_t sibling;  // kSibling
};
constexpr LinkSource link_source(int w) {
    const int k = w / 3, e = w % 3;
    if (!is_outer(k, e)) return {LinkSource::kSibling, 0, uint8_t(sibling(k, e))};
    return {first_half_child(e) == k ? LinkSource::kFirstHalf : LinkSource::kSecondHalf, uint8_t(e), 0};
}

// The same as tables, for indices known only at run time.
struct LinkSources {
    LinkSource of[12];
    constexpr LinkSources() : of() {
        for (int w = 0; w < 12; ++w) of[w] = link_source(w);
    }
};
constexpr LinkSources kLinkSources{};
constexpr uint8_t kFirstHalfChild[3] = {first_half_child(0), first_half_child(1), first_half_child(2)};
constexpr uint8_t kSecondHalfChild[3] = {second_half_child(0), second_half_child(1), second_half_child(2)};
constexpr uint8_t kCenterVertexOfMidpoint[3] = {center_vertex_of_midpoint(0), center_vertex_of_midpoint(1),
                                                center_vertex_of_midpoint(2)};
constexpr uint8_t kRotatedChild[3][4] = {{rotated_child(0, 0), rotated_child(1, 0), rotated_child(2, 0), rotated_child(3, 0)},
                                         {rotated_child(0, 1), rotated_child(1, 1), rotated_child(2, 1), rotated_child(3, 1)},
                                         {rotated_child(0, 2), rotated_child(1, 2), rotated_child(2, 2), rotated_child(3, 2)}};

// ---- checks of the definition: a permutation of the points per child, each edge outer or
// shared with exactly one sibling, each half of each parent edge in exactly one child ------------
constexpr bool well_formed() {
    for (int k = 0; k < 4; ++k) {
        for (int e = 0; e < 3; ++e) {
            if (is_outer(k, e) == (sibling(k, e) >= 0)) return false;
            if (!is_outer(k, e) && sibling(sibling(k, e), e) != k) return false;
        }
    }
    for (int e = 0; e < 3; ++e) {
        if (first_half_child(e) < 0 || second_half_child(e) < 0 || first_half_child(e) == second_half_child(e))
            return false;
        if (center_vertex_of_midpoint(e) < 0) return false;
    }
    for (int r = 0; r < 3; ++r) {
        for (int k = 0; k < 4; ++k) {
            if (rotated_child(k, r) < 0) return false;
        }
    }
    for (int e = 0; e < 3; ++e) {
        if (is_outer(kCenter, e)) return false;  // the center lies inside
    }
    return true;
}
static_assert(well_formed(), "kChildPoints is not a red split");

}  // namespace red_split
}  // namespace amc
