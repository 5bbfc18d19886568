// The level-wise traversal shared by the hierarchy encoder and decoder (paper, II-B, II-C, II-E).
//
// Within a level every node is decided exactly once: either a rule implies its state (culled:
// 1-regularity, hanging nodes, uniform levels) or one symbol is coded in the node's context group.
// The encoder answers `code` from the hierarchy it holds; the decoder from the stream. Both see
// the same decisions in the same order, so they agree on every context.
//
// The traversal does not run on amc::Hierarchy but on a "level forest": one level at a time as a
// dense array of 16-byte nodes in canonical (breadth-first) order, with neighbours as local indices
// into the same array. Level l+1 is derived from level l and its decisions alone, mirroring
// Hierarchy::split's linking, so the coder touches compact memory in near-sequential order and the
// decoder builds the Hierarchy once at the end. Local index i of level l is the node's position
// in the level's canonical order, which is also the order of the naive traversal.
#pragma once

#include "coding/context_groups.h"
#include "common/huge_pages.h"

#include <amc/hierarchy.h>
#include <amc/hierarchy_coder.h>

#include <array>
#include <cstdint>
#include <vector>

namespace amc {

enum class Fate : uint8_t { coded, uniform, one_regularity, hanging_nodes };

constexpr uint32_t kNoLocal = 0xffffffffu;

// One node of a level.
struct LevelNode {
    uint32_t nbr[3];   // same-level neighbour across edge e (local index), or kNoLocal
    uint8_t nbr_edge;  // the neighbour's local index of the shared edge, 2 bits per edge
    uint8_t flags;     // bits 0-2: boundary edge; bit 3: complete (Hierarchy::has_all_neighbors);
                       // bit 4: diagonal flipped (decoder, once the level is decided)
    uint8_t state;     // bit 0 decided, bit 1 refined; bits 4-5 decided refined neighbours (edges)
    uint8_t priority;  // improved traversal's bucket
};
static_assert(sizeof(LevelNode) == 16, "LevelNode is meant to be 16 bytes");
constexpr uint8_t kCompleteFlag = 8;
constexpr uint8_t kFlippedFlag = 16;
constexpr uint8_t kDecided = 1;
constexpr uint8_t kRefined = 2;
constexpr uint8_t kRefinedNeighbor = 16;  // unit of the refined-neighbour count in `state`
constexpr uint8_t kRefinedNeighborMask = 0x30;

inline uint8_t complete_flag(const uint32_t nbr[3], uint8_t boundary) {
    return ((nbr[0] != kNoLocal) | (boundary & 1)) & ((nbr[1] != kNoLocal) | ((boundary >> 1) & 1)) &
                   ((nbr[2] != kNoLocal) | ((boundary >> 2) & 1))
               ? kCompleteFlag
               : 0;
}

// Level 0: the roots of `h` (root ids are local indices).
inline void root_level(const Hierarchy& h, std::vector<LevelNode>& level) {
    level.resize(h.root_count());
    for (NodeId r = 0; r < h.root_count(); ++r) {
        LevelNode& node = level[r];
        uint8_t boundary = 0, edges = 0;
        for (int e = 0; e < 3; ++e) {
            node.nbr[e] = h.neighbor(r, e);
            if (node.nbr[e] != kNoNode) edges = uint8_t(edges | (h.neighbor_edge(r, e) << (2 * e)));
            boundary = uint8_t(boundary | (int(h.is_boundary_edge(r, e)) << e));
        }
        node.nbr_edge = edges;
        node.flags = uint8_t(boundary | complete_flag(node.nbr, boundary));
        node.state = 0;
        node.priority = 0;
    }
}

// Level l+1 from level l (every node decided): the children of the refined nodes in canonical
// order, linked exactly as Hierarchy::split links them. `first_child` is scratch.
inline void derive_next_level(const std::vector<LevelNode>& level, std::vector<uint32_t>& first_child,
                              std::vector<LevelNode>& next) {
    const size_t n = level.size();
    resize_scratch(first_child, n);
    uint32_t count = 0;
    for (size_t i = 0; i < n; ++i) {
        first_child[i] = count;
        count += (level[i].state & kRefined) ? 4u : 0u;
    }
    resize_scratch(next, count);
    const LevelNode* in = level.data();
    const uint32_t* fc = first_child.data();
    LevelNode* out = next.data();
    for (size_t i = 0; i < n; ++i) {
        const LevelNode& p = in[i];
        if (!(p.state & kRefined)) continue;
        // Across parent edge e: the neighbour's children for the first half (child e) and the
        // second half (child (e+1)%3) of the edge.
        uint32_t first_half[3], second_half[3];
        unsigned eq[3];
        for (int e = 0; e < 3; ++e) {
            const uint32_t q = p.nbr[e];
            eq[e] = (p.nbr_edge >> (2 * e)) & 3u;
            if (q != kNoLocal && (in[q].state & kRefined)) {
                const uint32_t qc = fc[q];
                first_half[e] = qc + (eq[e] == 2 ? 0 : eq[e] + 1);
                second_half[e] = qc + eq[e];
            } else {
                first_half[e] = second_half[e] = kNoLocal;
                eq[e] = 0;
            }
        }
        const uint32_t c = fc[i];
        LevelNode* ch = out + c;
        const uint8_t boundary = p.flags & 7;
        for (int k = 0; k < 3; ++k) {
            const int inner = k == 2 ? 0 : k + 1;  // (k+1)%3, shared with the center
            const int prev = k == 0 ? 2 : k - 1;   // (k+2)%3
            LevelNode& node = ch[k];
            node.nbr[k] = first_half[k];
            node.nbr[prev] = second_half[prev];
            node.nbr[inner] = c + 3;
            node.nbr_edge = uint8_t((eq[k] << (2 * k)) | (eq[prev] << (2 * prev)) | (unsigned(inner) << (2 * inner)));
            const uint8_t b = uint8_t(boundary & ((1u << k) | (1u << prev)));
            node.flags = uint8_t(b | complete_flag(node.nbr, b));
            node.state = 0;
            node.priority = 0;
        }
        LevelNode& center = ch[3];
        for (int e = 0; e < 3; ++e) center.nbr[e] = c + uint32_t(e == 0 ? 2 : e - 1);  // corner (e+2)%3
        center.nbr_edge = uint8_t(0 | (1 << 2) | (2 << 4));
        center.flags = kCompleteFlag;
        center.state = 0;
        center.priority = 0;
    }
}

// Number of refined neighbours of a decided level's node (its hanging nodes once it is a leaf).
inline int refined_neighbor_count(const LevelNode* nodes, uint32_t i) {
    int count = 0;
    for (int e = 0; e < 3; ++e) {
        const uint32_t q = nodes[i].nbr[e];
        count += q != kNoLocal && (nodes[q].state & kRefined);
    }
    return count;
}

// The unrefined edge of a leaf with exactly two hanging nodes.
inline int unrefined_edge(const LevelNode* nodes, uint32_t i) {
    for (int e = 0; e < 2; ++e) {
        const uint32_t q = nodes[i].nbr[e];
        if (q == kNoLocal || !(nodes[q].state & kRefined)) return e;
    }
    return 2;
}

class LevelTraversal {
public:
    explicit LevelTraversal(const HierarchyCoderOptions& options) : options_(options) {}

    // Decides every node of `level` (undecided, canonical order) and records the decisions in
    // the nodes' state.
    //   code(uint32_t i, int context_group) -> bool   the node's symbol (coded by the caller)
    //   force(uint32_t i, Fate fate, bool refined) -> bool   a decision implied by a rule; returns
    //       the node's actual state (the decoder: `refined`; the encoder: the hierarchy's, so even
    //       an invalid hierarchy keeps the level forest in step with it)
    template <class Code, class Force>
    void run(std::vector<LevelNode>& level, bool uniform_level, Code&& code, Force&& force) {
        LevelNode* nodes = level.data();
        const uint32_t n = static_cast<uint32_t>(level.size());
        if (uniform_level) {
            for (uint32_t i = 0; i < n; ++i) {
                nodes[i].state = uint8_t(kDecided | (force(i, Fate::uniform, true) ? kRefined : 0));
            }
            return;
        }
        if (options_.traversal == Traversal::naive) {
            for (uint32_t i = 0; i < n; ++i) decide(nodes, i, code, force);
            return;
        }
        // Improved traversal: a bucket queue over priorities 0 (culled: nothing to code) to 4 (no
        // neighbour decided yet); each decided neighbour lowers a node's priority by one. The
        // lowest non-empty bucket goes first, each bucket last in, first out; an entry is stale
        // once its node is decided or has moved to a lower bucket, and is skipped. Every node
        // enters at most five buckets: linear time.
        // Two buckets need no storage: bucket 4 starts with every unculled node in canonical order
        // and never receives another, so it is a cursor; bucket 0 starts with the nodes culled at
        // the outset in canonical order (a cursor) under a stack of nodes culled later.
        const bool cull_incomplete = options_.cull_one_regularity;
        for (uint32_t i = 0; i < n; ++i)
            nodes[i].priority = cull_incomplete && !(nodes[i].flags & kCompleteFlag) ? 0 : 4;
        for (auto& stack : stacks_) {
            stack.clear();
            if (stack.capacity() < n) stack.reserve(n);
        }
        uint32_t* const top_base[4] = {stacks_[0].data(), stacks_[1].data(), stacks_[2].data(), stacks_[3].data()};
        uint32_t* top[4] = {top_base[0], top_base[1], top_base[2], top_base[3]};
        uint32_t culled_cursor = 0, fresh_cursor = 0;
        for (;;) {
            uint32_t i;
            if (top[0] != top_base[0]) {
                i = *--top[0];  // entries of bucket 0 are never stale
            } else {
                while (culled_cursor < n && (nodes[culled_cursor].priority != 0 || (nodes[culled_cursor].state & kDecided)))
                    ++culled_cursor;
                if (culled_cursor < n) {
                    i = culled_cursor++;
                } else {
                    int p = 1;
                    while (p < 4 && top[p] == top_base[p]) ++p;
                    if (p < 4) {
                        i = *--top[p];
                        if ((nodes[i].state & kDecided) || nodes[i].priority != p) continue;
                    } else {
                        while (fresh_cursor < n && (nodes[fresh_cursor].priority != 4 || (nodes[fresh_cursor].state & kDecided)))
                            ++fresh_cursor;
                        if (fresh_cursor == n) break;
                        i = fresh_cursor++;
                    }
                }
            }
            decide(nodes, i, code, force);
            for (int e = 0; e < 3; ++e) {
                const uint32_t q = nodes[i].nbr[e];
                if (q == kNoLocal) continue;
                LevelNode& m = nodes[q];
                if ((m.state & kDecided) || m.priority == 0) continue;
                const uint8_t next = fate_of(nodes, q) != Fate::coded ? 0 : uint8_t(m.priority > 1 ? m.priority - 1 : 1);
                if (next != m.priority) {
                    m.priority = next;
                    *top[next]++ = q;
                }
            }
        }
    }

private:
    // The rule that decides node i given what is known now, or Fate::coded.
    Fate fate_of(const LevelNode* nodes, uint32_t i) const {
        if (options_.cull_one_regularity && !(nodes[i].flags & kCompleteFlag)) return Fate::one_regularity;
        // The count of decided refined neighbours is kept up to date by decide().
        if (options_.cull_hanging_nodes && (nodes[i].state & kRefinedNeighborMask) == 3 * kRefinedNeighbor)
            return Fate::hanging_nodes;
        return Fate::coded;
    }

    template <class Code, class Force>
    void decide(LevelNode* nodes, uint32_t i, Code& code, Force& force) {
        const Fate fate = fate_of(nodes, i);
        bool refined;
        if (fate == Fate::coded) {
            int r = 0, u = 0;
            for (int e = 0; e < 3; ++e) {
                const uint32_t q = nodes[i].nbr[e];
                if (q == kNoLocal) {
                    ++u;  // boundary, or a coarser region: see context_groups.h
                } else {
                    const uint8_t s = nodes[q].state;
                    r += (s >> 1) & 1;
                    u += s & ~(s >> 1) & 1;
                }
            }
            refined = code(i, context_group_of(r, u));
        } else {
            refined = force(i, fate, fate == Fate::hanging_nodes);
        }
        nodes[i].state = uint8_t(nodes[i].state | kDecided | (refined ? kRefined : 0));
        if (refined) {
            for (int e = 0; e < 3; ++e) {
                const uint32_t q = nodes[i].nbr[e];
                if (q != kNoLocal && (nodes[q].state & kRefinedNeighborMask) != kRefinedNeighborMask)
                    nodes[q].state = uint8_t(nodes[q].state + kRefinedNeighbor);
            }
        }
    }

    HierarchyCoderOptions options_;
    std::array<std::vector<uint32_t>, 4> stacks_;  // buckets 0-3 (each holds at most one entry per node)
};

}  // namespace amc
