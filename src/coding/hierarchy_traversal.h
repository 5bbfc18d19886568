// The level-wise traversal shared by the hierarchy encoder and decoder (paper, II-B, II-C, II-E).
//
// Within a level every node is decided exactly once: either a rule implies its state (culled:
// 1-regularity, hanging nodes, uniform levels) or one symbol is coded in the node's context group.
// The encoder answers `code` from the hierarchy it holds; the decoder from the stream. Both see
// the same decisions in the same order, so they agree on every context.
//
// The traversal does not run on amc::Hierarchy but on a "level forest": one level at a time as
// dense arrays in canonical (breadth-first) order, with neighbours as local indices into the same
// arrays. Level l+1 is derived from level l and its decisions alone, mirroring Hierarchy::split's
// linking, so the coder touches compact memory in near-sequential order and the decoder builds
// the Hierarchy once at the end. Local index i of level l is the node's position in the level's
// canonical order, which is also the order of the naive traversal.
//
// A level is two arrays: the links (16 bytes a node, read once per decision) and one state byte
// a node, which the traversal reads and writes for every neighbour; kept apart, the states of
// even the finest level stay in the processor's L2 cache.
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

struct LevelLinks {
    uint32_t nbr[3];   // same-level neighbour across edge e (local index), or kNoLocal
    uint8_t nbr_edge;  // the neighbour's local index of the shared edge, 2 bits per edge
    uint8_t flags;     // bits 0-2: boundary edge; bit 3: diagonal flipped (decoder, once decided)
    LevelLinks() {}  // uninitialized: every node's fields are set when its level is made
};
static_assert(sizeof(LevelLinks) == 16, "LevelLinks is meant to be 16 bytes");
constexpr uint8_t kFlippedFlag = 8;

// The state byte of a node.
constexpr uint8_t kDecided = 1;
constexpr uint8_t kRefined = 2;
constexpr uint8_t kRefinedNeighbor = 4;        // unit of the count of refined neighbours (bits 2-3)
constexpr uint8_t kRefinedNeighborMask = 12;   // decided refined neighbours; exact once all are decided
constexpr uint8_t kComplete = 16;              // Hierarchy::has_all_neighbors
constexpr int kPriorityShift = 5;              // bits 5-7: the improved traversal's bucket, 0..4
constexpr uint8_t kPriorityMask = 0xe0;

struct Level {
    std::vector<LevelLinks> links;
    std::vector<uint8_t> state;
    size_t size() const { return links.size(); }
    bool empty() const { return links.empty(); }
};

inline int refined_neighbors(uint8_t state) { return (state & kRefinedNeighborMask) >> 2; }

inline uint8_t complete_state(const uint32_t nbr[3], uint8_t boundary) {
    return ((nbr[0] != kNoLocal) | (boundary & 1)) & ((nbr[1] != kNoLocal) | ((boundary >> 1) & 1)) &
                   ((nbr[2] != kNoLocal) | ((boundary >> 2) & 1))
               ? kComplete
               : 0;
}

// Level 0: the roots of `h` (root ids are local indices).
inline void root_level(const Hierarchy& h, Level& level) {
    level.links.resize(h.root_count());
    level.state.resize(h.root_count());
    for (NodeId r = 0; r < h.root_count(); ++r) {
        LevelLinks& node = level.links[r];
        uint8_t boundary = 0, edges = 0;
        for (int e = 0; e < 3; ++e) {
            node.nbr[e] = h.neighbor(r, e);
            if (node.nbr[e] != kNoNode) edges = uint8_t(edges | (h.neighbor_edge(r, e) << (2 * e)));
            boundary = uint8_t(boundary | (int(h.is_boundary_edge(r, e)) << e));
        }
        node.nbr_edge = edges;
        node.flags = boundary;
        level.state[r] = complete_state(node.nbr, boundary);
    }
}

// Level l+1 from level l (every node decided): the children of the refined nodes in canonical
// order, linked exactly as Hierarchy::split links them. `first_child` is scratch.
inline void derive_next_level(const Level& level, std::vector<uint32_t>& first_child, Level& next) {
    const size_t n = level.size();
    const uint8_t* state = level.state.data();
    resize_scratch(first_child, n);
    uint32_t count = 0;
    for (size_t i = 0; i < n; ++i) {
        first_child[i] = count;
        count += (state[i] & kRefined) ? 4u : 0u;
    }
    resize_scratch(next.links, count);
    resize_scratch(next.state, count);
    const LevelLinks* in = level.links.data();
    const uint32_t* fc = first_child.data();
    LevelLinks* out = next.links.data();
    uint8_t* out_state = next.state.data();
    for (size_t i = 0; i < n; ++i) {
        if (!(state[i] & kRefined)) continue;
        const LevelLinks& p = in[i];
        // Across parent edge e: the neighbour's children for the first half (child e) and the
        // second half (child (e+1)%3) of the edge.
        uint32_t first_half[3], second_half[3];
        unsigned eq[3];
        for (int e = 0; e < 3; ++e) {
            const uint32_t q = p.nbr[e];
            eq[e] = (p.nbr_edge >> (2 * e)) & 3u;
            if (q != kNoLocal && (state[q] & kRefined)) {
                const uint32_t qc = fc[q];
                first_half[e] = qc + (eq[e] == 2 ? 0 : eq[e] + 1);
                second_half[e] = qc + eq[e];
            } else {
                first_half[e] = second_half[e] = kNoLocal;
                eq[e] = 0;
            }
        }
        const uint32_t c = fc[i];
        LevelLinks* ch = out + c;
        const uint8_t boundary = p.flags & 7;
        for (int k = 0; k < 3; ++k) {
            const int inner = k == 2 ? 0 : k + 1;  // (k+1)%3, shared with the center
            const int prev = k == 0 ? 2 : k - 1;   // (k+2)%3
            LevelLinks& node = ch[k];
            node.nbr[k] = first_half[k];
            node.nbr[prev] = second_half[prev];
            node.nbr[inner] = c + 3;
            node.nbr_edge = uint8_t((eq[k] << (2 * k)) | (eq[prev] << (2 * prev)) | (unsigned(inner) << (2 * inner)));
            const uint8_t b = uint8_t(boundary & ((1u << k) | (1u << prev)));
            node.flags = b;
            out_state[c + k] = complete_state(node.nbr, b);
        }
        LevelLinks& center = ch[3];
        for (int e = 0; e < 3; ++e) center.nbr[e] = c + uint32_t(e == 0 ? 2 : e - 1);  // corner (e+2)%3
        center.nbr_edge = uint8_t(0 | (1 << 2) | (2 << 4));
        center.flags = 0;
        out_state[c + 3] = kComplete;
    }
}

// The unrefined edge of a decided leaf with exactly two hanging nodes.
inline int unrefined_edge(const Level& level, uint32_t i) {
    for (int e = 0; e < 2; ++e) {
        const uint32_t q = level.links[i].nbr[e];
        if (q == kNoLocal || !(level.state[q] & kRefined)) return e;
    }
    return 2;
}

// The culling rules in force (paper II-C): which rule decides a node in state s, or Fate::coded.
struct CullRules {
    bool one_regularity;
    bool hanging_nodes;
    Fate fate(uint8_t s) const {
        if (one_regularity && !(s & kComplete)) return Fate::one_regularity;
        // The count of decided refined neighbours is kept up to date by LevelTraversal.
        if (hanging_nodes && (s & kRefinedNeighborMask) == 3 * kRefinedNeighbor) return Fate::hanging_nodes;
        return Fate::coded;
    }
};

// Context group by the neighbours' kinds, two bits each (edge e at bits 2e): 0 not yet decided,
// 1 not refined (or no neighbour: boundary, coarser region), 3 refined.
struct ContextTable {
    uint8_t group[64];
    constexpr ContextTable() : group() {
        for (int code = 0; code < 64; ++code) {
            int refined = 0, unrefined = 0;
            for (int e = 0; e < 3; ++e) {
                const int kind = (code >> (2 * e)) & 3;
                refined += kind == 3;
                unrefined += kind == 1 || kind == 2;
            }
            group[code] = uint8_t(kContextGroupOf[refined][unrefined]);
        }
    }
};
constexpr ContextTable kContextTable{};

class LevelTraversal {
public:
    explicit LevelTraversal(const HierarchyCoderOptions& options) : options_(options) {
        // What a decided neighbour does to a node's state in the improved traversal: an
        // undecided node outside bucket 0 moves one bucket down (not below 1), or to bucket 0
        // once its three refined neighbours make it culled (a node culled by 1-regularity is in
        // bucket 0 from the outset).
        const CullRules rules{options.cull_one_regularity, options.cull_hanging_nodes};
        for (int s = 0; s < 256; ++s) {
            const int p = s >> kPriorityShift;
            int next = p;
            if (!(s & kDecided) && p != 0 && p <= 4)
                next = rules.fate(uint8_t(s)) != Fate::coded ? 0 : (p > 1 ? p - 1 : 1);
            after_neighbor_decided_[s] = uint8_t((s & ~kPriorityMask) | (next << kPriorityShift));
        }
    }

    // Decides every node of `level` (undecided, canonical order) and records the decisions in
    // the nodes' state; afterwards each state's refined-neighbour count is exact.
    //   code(uint32_t i, int context_group) -> bool   the node's symbol (coded by the caller)
    //   force(uint32_t i, Fate fate, bool refined) -> bool   a decision implied by a rule; returns
    //       the node's actual state (the decoder: `refined`; the encoder: the hierarchy's, so even
    //       an invalid hierarchy keeps the level forest in step with it)
    template <class Code, class Force>
    void run(Level& level, bool uniform_level, Code&& code, Force&& force) {
        const LevelLinks* links = level.links.data();
        uint8_t* state = level.state.data();
        const uint32_t n = static_cast<uint32_t>(level.size());
        // A copy in a local: the state bytes written below could alias options_.
        const CullRules rules{options_.cull_one_regularity, options_.cull_hanging_nodes};
        if (uniform_level) {
            for (uint32_t i = 0; i < n; ++i) {
                if (force(i, Fate::uniform, true)) {
                    state[i] = uint8_t(state[i] | kDecided | kRefined);
                    add_refined_neighbor(links[i], state);
                } else {
                    state[i] = uint8_t(state[i] | kDecided);
                }
            }
            return;
        }
        if (options_.traversal == Traversal::naive) {
            for (uint32_t i = 0; i < n; ++i) decide(rules.fate(state[i]), links[i], state, i, code, force);
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
        const uint8_t initially_culled = rules.one_regularity ? uint8_t(0) : kComplete;
        for (uint32_t i = 0; i < n; ++i) {
            const uint8_t s = state[i];
            state[i] = uint8_t(((s | initially_culled) & kComplete) ? s | (4 << kPriorityShift) : s);
        }
        for (auto& stack : stacks_) {
            stack.clear();
            if (stack.capacity() < n) stack.reserve(n);
        }
        uint32_t* const bottom[4] = {stacks_[0].data(), stacks_[1].data(), stacks_[2].data(), stacks_[3].data()};
        uint32_t* top[4] = {bottom[0], bottom[1], bottom[2], bottom[3]};
        uint32_t culled_cursor = 0, fresh_cursor = 0;
        constexpr uint8_t kDecidedOrPriority = kDecided | kPriorityMask;
        uint8_t transition[256];  // a local copy: the state bytes written below could alias the member
        for (int k = 0; k < 256; ++k) transition[k] = after_neighbor_decided_[k];
        int current = 0;  // every bucket below this one is empty
        uint32_t i = 0;
        bool culled = false;
        bool popped = false;  // i was taken off its bucket by the previous step
        for (;;) {
            // A node from bucket 0 is culled; from any other bucket it carries a symbol (its
            // priority was set when its fate last changed).
            if (popped) {
                popped = false;
            } else if (current == 0) {
                if (top[0] != bottom[0]) {
                    i = *--top[0];  // entries of bucket 0 are never stale
                } else if (culled_cursor < n) {
                    i = culled_cursor++;
                    if ((state[i] & kDecidedOrPriority) != 0) continue;
                } else {
                    current = 1;
                    continue;
                }
                culled = true;
            } else if (current < 4) {
                if (top[current] == bottom[current]) {
                    ++current;
                    continue;
                }
                i = *--top[current];
                if ((state[i] & kDecidedOrPriority) != (current << kPriorityShift)) continue;
                culled = false;
            } else if (fresh_cursor < n) {
                i = fresh_cursor++;
                if ((state[i] & kDecidedOrPriority) != (4 << kPriorityShift)) continue;
                culled = false;
            } else {
                break;
            }
            const LevelLinks node = links[i];
            decide(culled ? rules.fate(state[i]) : Fate::coded, node, state, i, code, force);
            // The pushes of this step; the last one into the lowest bucket is the next node
            // whenever that bucket is now the lowest non-empty one. Knowing it here, rather than
            // reading it back from the bucket, keeps the stack and the state byte out of the
            // chain of loads from one node to the next.
            uint32_t next = 0;
            int next_bucket = 5;
            for (int e = 0; e < 3; ++e) {
                const uint32_t q = node.nbr[e];
                if (q == kNoLocal) continue;
                const uint8_t s = state[q];
                const uint8_t t = transition[s];
                if (t == s) continue;
                state[q] = t;
                // Last in, first out: q is likely to be decided soon, and its links are usually
                // not in cache yet.
                __builtin_prefetch(links + q);
                const int bucket = t >> kPriorityShift;
                *top[bucket]++ = q;
                if (bucket <= next_bucket) {
                    next = q;
                    next_bucket = bucket;
                }
            }
            if (next_bucket <= current) {
                current = next_bucket;
                --top[current];
                i = next;
                culled = current == 0;
                popped = true;
            }
        }
    }

private:
    static void add_refined_neighbor(const LevelLinks& node, uint8_t* state) {
        for (int e = 0; e < 3; ++e) {
            const uint32_t q = node.nbr[e];
            if (q != kNoLocal && (state[q] & kRefinedNeighborMask) != kRefinedNeighborMask)
                state[q] = uint8_t(state[q] + kRefinedNeighbor);
        }
    }

    // The context group of a node: its neighbours refined, not refined, not yet decided.
    static int context_group(const LevelLinks& node, const uint8_t* state) {
        unsigned code = 0;
        for (int e = 0; e < 3; ++e) {
            const uint32_t q = node.nbr[e];
            // No neighbour (boundary, or a coarser region: see context_groups.h) counts as not
            // refined; a neighbour's kind is its decided and refined bits.
            const unsigned kind = q == kNoLocal ? 1u : state[q] & (kDecided | kRefined);
            code |= kind << (2 * e);
        }
        return kContextTable.group[code];
    }

    // Decides node i (links `node`) whose fate is known: codes its symbol or applies the rule,
    // records the decision and counts it at the neighbours.
    template <class Code, class Force>
    static void decide(Fate fate, const LevelLinks& node, uint8_t* state, uint32_t i, Code& code, Force& force) {
        const bool refined = fate == Fate::coded ? code(i, context_group(node, state))
                                                 : force(i, fate, fate == Fate::hanging_nodes);
        state[i] = uint8_t(state[i] | kDecided | (refined ? kRefined : 0));
        if (refined) add_refined_neighbor(node, state);
    }

    HierarchyCoderOptions options_;
    uint8_t after_neighbor_decided_[256];  // state -> state, see the constructor
    std::array<std::vector<uint32_t>, 4> stacks_;  // buckets 0-3 (each holds at most one entry per node)
};

}  // namespace amc
