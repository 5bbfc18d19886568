// The red split in bulk (<amc/red_split.h>), as the hierarchy's split_level and the coders' level
// forest write it: the vertices of four new siblings, and their twelve link words. Two forms that
// compute the same: red_split_scalar (always compiled; the reference) and red_split_sse2 (where
// the compiler targets SSE2), whose shuffles are planned at compile time from kChildPoints.
// `red_split_kernels` names the form in use: the one place that chooses (tests compare both).
#pragma once

#include <amc/red_split.h>

#include "common/simd.h"

#include <cstddef>
#include <cstdint>
#include <cstring>

namespace amc {

// The neighbour's child (lanes 0-2) across the first and the second half of each edge e, by the
// node's neighbour edge indices (2 bits per edge). Lane 3 holds a sibling offset the SSE2 form
// needs (red_split_sse2::kLinkPlan); the scalar form ignores it. Both halves of one code share a
// 32-byte entry, so that one register addresses them.
struct HalfEdgeChildren {
    static constexpr uint32_t kFirstLane3 = 3, kSecondLane3 = 2;
    struct Entry {
        alignas(16) uint32_t first[4];
        uint32_t second[4];
    };
    Entry of[64];
    constexpr HalfEdgeChildren() : of() {
        for (int code = 0; code < 64; ++code) {
            for (int e = 0; e < 3; ++e) {
                const int eq = (code >> (2 * e)) & 3;
                of[code].first[e] = eq < 3 ? uint32_t(red_split::child_across_first_half(eq)) : 0;
                of[code].second[e] = eq < 3 ? uint32_t(red_split::child_across_second_half(eq)) : 0;
            }
            of[code].first[3] = kFirstLane3;
            of[code].second[3] = kSecondLane3;
        }
    }
};
constexpr HalfEdgeChildren kHalfEdgeChildren{};

namespace red_split_scalar {

// The vertices of four new siblings (child k's at the 16 bytes from child[k].v: its three vertex
// ids, then a fourth word of all ones, the caller's "none") from the parent's corners and the
// midpoints of its edges.
template <class Node>
inline void write_child_vertices(Node* child, const uint32_t corner[3], const uint32_t mid[3]) {
    for (int k = 0; k < 4; ++k) {
        uint32_t words[4];
        for (int i = 0; i < 3; ++i) {
            const int p = red_split::kChildPoints[k][i];
            words[i] = p < red_split::kMidpoint ? corner[p - red_split::kCorner] : mid[p - red_split::kMidpoint];
        }
        words[3] = 0xffffffffu;
        std::memcpy(reinterpret_cast<char*>(&child[k]) + offsetof(Node, v), words, sizeof(words));
    }
}

// The twelve link words of block b's four children (out[k].nbr[e]: child k's neighbour across
// edge e, as local indices; child k of block b is 4b + k) from the blocks q0..q2 of the parent's
// neighbours (all ones for none; blocks are below 2^30) and the parent's neighbour edge indices.
// Returns the parent's edges with a neighbour (bits 0-2).
template <class Links>
inline unsigned write_child_links(Links* out, uint32_t b, uint32_t q0, uint32_t q1, uint32_t q2, uint8_t nbr_edge) {
    const HalfEdgeChildren::Entry& children = kHalfEdgeChildren.of[nbr_edge & 63u];
    const uint32_t q[3] = {q0, q1, q2};
    uint32_t first[3], second[3];
    unsigned linked = 0;
    for (int e = 0; e < 3; ++e) {
        const uint32_t none = uint32_t(static_cast<int32_t>(q[e]) >> 31);
        first[e] = (4 * q[e] + children.first[e]) | none;
        second[e] = (4 * q[e] + children.second[e]) | none;
        linked |= (1u << e) & ~none;
    }
    for (int w = 0; w < 12; ++w) {
        const red_split::LinkSource s = red_split::kLinkSources.of[w];
        out[w / 3].nbr[w % 3] = s.kind == red_split::LinkSource::kFirstHalf    ? first[s.edge]
                                : s.kind == red_split::LinkSource::kSecondHalf ? second[s.edge]
                                                                                : 4 * b + s.sibling;
    }
    return linked;
}

}  // namespace red_split_scalar

#if AMC_SSE2
namespace red_split_sse2 {

// One 4-lane store made by _mm_shuffle_ps(a, b, imm) (lanes 0-1 from a, 2-3 from b), plus `add`.
struct ShufflePlan {
    uint8_t a = 0, b = 0;  // which source vector
    int imm = 0;
    int32_t add[4] = {};
    bool adds = false;
    bool found = false;
};

// Vertices: the sources are P = (v0, v1, v2, none), Q = (m0, m1, m2, none) and PQ = (v0, m0, v1,
// m1); child k's store is its three points and none.
enum VertexSource : uint8_t { kPQ, kQ, kP };
constexpr int vertex_lane(uint8_t source, int point) {  // point 6: none
    if (point == 6) return source == kPQ ? -1 : 3;
    if (source == kPQ) return point == 0 ? 0 : point == 3 ? 1 : point == 1 ? 2 : point == 4 ? 3 : -1;
    if (source == kP) return point < 3 ? point : -1;
    return point >= 3 ? point - 3 : -1;
}
constexpr ShufflePlan vertex_plan(int k) {
    const int points[4] = {red_split::kChildPoints[k][0], red_split::kChildPoints[k][1], red_split::kChildPoints[k][2], 6};
    ShufflePlan plan;
    for (uint8_t a = kPQ; a <= kP && !plan.found; ++a) {
        for (uint8_t b = kPQ; b <= kP && !plan.found; ++b) {
            int lanes[4] = {vertex_lane(a, points[0]), vertex_lane(a, points[1]), vertex_lane(b, points[2]),
                            vertex_lane(b, points[3])};
            if (lanes[0] < 0 || lanes[1] < 0 || lanes[2] < 0 || lanes[3] < 0) continue;
            plan.a = a;
            plan.b = b;
            plan.imm = lanes[0] | lanes[1] << 2 | lanes[2] << 4 | lanes[3] << 6;
            plan.found = true;
        }
    }
    return plan;
}
constexpr ShufflePlan kVertexPlan[4] = {vertex_plan(0), vertex_plan(1), vertex_plan(2), vertex_plan(3)};
static_assert(kVertexPlan[0].found && kVertexPlan[1].found && kVertexPlan[2].found && kVertexPlan[3].found,
              "no shuffle writes these child vertices");

// The immediates pass through template parameters: at -O0 GCC's intrinsic macros accept only a
// literal constant, not a member of a constexpr object.
template <int imm>
inline __m128 shuffle_ps(__m128 a, __m128 b) { return _mm_shuffle_ps(a, b, imm); }
template <int imm>
inline __m128i shuffle_epi32(__m128i a) { return _mm_shuffle_epi32(a, imm); }

template <int k>
inline __m128 child_vertex_vector(__m128 p, __m128 q, __m128 pq) {
    constexpr ShufflePlan plan = kVertexPlan[k];
    const __m128 a = plan.a == kPQ ? pq : plan.a == kQ ? q : p;
    const __m128 b = plan.b == kPQ ? pq : plan.b == kQ ? q : p;
    if constexpr (plan.a == plan.b) return _mm_castsi128_ps(shuffle_epi32<plan.imm>(_mm_castps_si128(a)));
    return shuffle_ps<plan.imm>(a, b);
}

// The same with the corners as lanes 0-2 of `pi` and all ones in lane 3 (a leaf's first 16 bytes,
// loaded whole).
template <class Node>
inline void write_child_vertices(Node* child, __m128i pi, const uint32_t mid[3]) {
    const __m128i qi = _mm_set_epi32(-1, int(mid[2]), int(mid[1]), int(mid[0]));
    const __m128 p = _mm_castsi128_ps(pi), q = _mm_castsi128_ps(qi);
    const __m128 pq = _mm_castsi128_ps(_mm_unpacklo_epi32(pi, qi));
    auto store = [](Node& node, __m128 v) {
        _mm_storeu_si128(reinterpret_cast<__m128i*>(reinterpret_cast<char*>(&node) + offsetof(Node, v)), _mm_castps_si128(v));
    };
    store(child[0], child_vertex_vector<0>(p, q, pq));
    store(child[1], child_vertex_vector<1>(p, q, pq));
    store(child[2], child_vertex_vector<2>(p, q, pq));
    store(child[3], child_vertex_vector<3>(p, q, pq));
}

template <class Node>
inline void write_child_vertices(Node* child, const uint32_t corner[3], const uint32_t mid[3]) {
    write_child_vertices(child, _mm_set_epi32(-1, int(corner[2]), int(corner[1]), int(corner[0])), mid);
}

// Links: the sources are F = (first0, first1, first2, c + kFirstLane3) and S = (second0..2,
// c + kSecondLane3) with c = 4b; the three stores are words 0-3, 4-7, 8-11. A sibling's word is
// lane 3 of either plus a constant.
enum LinkVector : uint8_t { kF, kS };
struct LinkLane {
    int lane;
    int32_t add;
};
constexpr LinkLane link_lane(uint8_t source, int w) {
    const red_split::LinkSource s = red_split::link_source(w);
    if (s.kind == red_split::LinkSource::kSibling) {
        const uint32_t base = source == kF ? HalfEdgeChildren::kFirstLane3 : HalfEdgeChildren::kSecondLane3;
        return {3, int32_t(s.sibling) - int32_t(base)};
    }
    const bool wanted = (s.kind == red_split::LinkSource::kFirstHalf) == (source == kF);
    return {wanted ? int(s.edge) : -1, 0};
}
constexpr ShufflePlan link_plan(int j) {
    ShufflePlan plan;
    const uint8_t order[4][2] = {{kF, kS}, {kF, kF}, {kS, kS}, {kS, kF}};
    for (int o = 0; o < 4 && !plan.found; ++o) {
        const uint8_t a = order[o][0], b = order[o][1];
        const LinkLane lanes[4] = {link_lane(a, 4 * j), link_lane(a, 4 * j + 1), link_lane(b, 4 * j + 2),
                                   link_lane(b, 4 * j + 3)};
        if (lanes[0].lane < 0 || lanes[1].lane < 0 || lanes[2].lane < 0 || lanes[3].lane < 0) continue;
        plan.a = a;
        plan.b = b;
        plan.imm = lanes[0].lane | lanes[1].lane << 2 | lanes[2].lane << 4 | lanes[3].lane << 6;
        for (int i = 0; i < 4; ++i) {
            plan.add[i] = lanes[i].add;
            plan.adds = plan.adds || lanes[i].add != 0;
        }
        plan.found = true;
    }
    return plan;
}
constexpr ShufflePlan kLinkPlan[3] = {link_plan(0), link_plan(1), link_plan(2)};
static_assert(kLinkPlan[0].found && kLinkPlan[1].found && kLinkPlan[2].found, "no shuffle writes these child links");

template <int j>
inline __m128i child_link_vector(__m128 f, __m128 s) {
    constexpr ShufflePlan plan = kLinkPlan[j];
    const __m128i v = _mm_castps_si128(shuffle_ps<plan.imm>(plan.a == kF ? f : s, plan.b == kF ? f : s));
    if constexpr (!plan.adds) return v;
    return _mm_add_epi32(v, _mm_set_epi32(plan.add[3], plan.add[2], plan.add[1], plan.add[0]));
}

template <class Links>
inline unsigned write_child_links(Links* out, uint32_t b, uint32_t q0, uint32_t q1, uint32_t q2, uint8_t nbr_edge) {
    static_assert(sizeof(Links) == 12, "four siblings' links are twelve consecutive words");
    const HalfEdgeChildren::Entry& children = kHalfEdgeChildren.of[nbr_edge & 63u];
    // Lanes 0-2: edge e; lane 3: the block itself, whose first child is c = 4b.
    const __m128i q = _mm_set_epi32(int(b), int(q2), int(q1), int(q0));
    const __m128i none = _mm_srai_epi32(q, 31);
    const __m128i base = _mm_slli_epi32(q, 2);
    auto halves = [&](const uint32_t* offsets) {
        const __m128i v = _mm_add_epi32(base, _mm_load_si128(reinterpret_cast<const __m128i*>(offsets)));
        return _mm_castsi128_ps(_mm_or_si128(v, none));
    };
    const __m128 f = halves(children.first), s = halves(children.second);
    __m128i* words = reinterpret_cast<__m128i*>(out->nbr);
    _mm_storeu_si128(words, child_link_vector<0>(f, s));
    _mm_storeu_si128(words + 1, child_link_vector<1>(f, s));
    _mm_storeu_si128(words + 2, child_link_vector<2>(f, s));
    return ~unsigned(_mm_movemask_ps(_mm_castsi128_ps(none))) & 7u;
}

}  // namespace red_split_sse2
namespace red_split_kernels = red_split_sse2;
#else
namespace red_split_kernels = red_split_scalar;
#endif

}  // namespace amc
