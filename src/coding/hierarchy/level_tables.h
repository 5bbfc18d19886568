// The hierarchy coder's constant tables over state bytes and block codes (level_forest.h): how a
// new block starts, how a culled neighbour lowers a node, which rule decides a node, and its
// context group.
#pragma once

#include "coding/hierarchy/context_groups.h"
#include "coding/hierarchy/level_forest.h"

#include <amc/red_split.h>

#include <cstdint>

namespace amc {

enum class Fate : uint8_t { coded, uniform, hanging_nodes };

// The state of a node once one more of its neighbours is culled by 1-regularity, before any node
// of the level is decided otherwise: an undecided node moves one bucket down, not below 1 (the
// improved traversal's rule; with nothing refined, no other rule can cull it). A table: the
// lowered nodes follow no pattern, and GCC made the test a branch.
struct LoweredByCulledNeighbor {
    uint8_t of[256];
    constexpr LoweredByCulledNeighbor() : of() {
        for (int s = 0; s < 256; ++s) {
            const bool moves = !(s & kDecided) && (s >> kPriorityShift) > 1;
            of[s] = uint8_t(s - (moves ? 1 << kPriorityShift : 0));
        }
    }
};
constexpr LoweredByCulledNeighbor kLoweredByCulledNeighbor{};

// What a new block takes from its parent's linked edges (bits 0-2: the edges with a refined
// neighbour) and boundary edges (bits 3-5), in one 16-byte entry; a table without the 1-regularity
// rule and one with it:
//  - the four children's state bytes (byte k: child k). A child is complete when each of its
//    outer edges (red_split::is_outer) has a neighbour or is boundary; the center has none, so it
//    always is. Without the rule every child starts undecided, a complete one in bucket 4
//    (kFreshPriority), an incomplete one in 0. With the rule an incomplete child starts decided
//    (not refined), and a complete one one bucket lower for each incomplete sibling;
//  - with the rule, the neighbours outside the block of its incomplete children across linked
//    edges, whose priority goes down once the rule culls those children, as byte offsets into the
//    block's twelve words of neighbours (red_split::link_word). An incomplete child has at most one
//    such neighbour (its other outer edge is missing), a block at most two (a third would not
//    compile: writing past lowered_offset is no constant expression);
//  - the mask of the linked edges' two-bit neighbour edge indices;
//  - two counts in one word, so that one addition keeps both: the ends the new vertices count
//    beyond 3 (bits 0-31: a vertex on an edge of its own counts 2 ends, one on an edge shared with
//    a refined neighbour 1, so 3 to 6 a block) and the children that are not complete (bits
//    32-63). Neither sum can overflow: a level has fewer than 2^32 nodes, so fewer than 2^30
//    blocks.
struct NewBlock {
    uint32_t states = 0;
    uint8_t lowered_offset[2] = {};
    uint8_t lowered_count = 0;
    uint8_t edge_mask = 0;
    uint64_t counts = 0;
};
static_assert(sizeof(NewBlock) == 16, "NewBlock is meant to be 16 bytes");
struct NewBlocks {
    NewBlock of[2][64];  // [cull_one_regularity][code]
    constexpr NewBlocks() : of() {
        constexpr uint32_t kFresh = kComplete | kFreshPriority;
        for (int culled = 0; culled < 2; ++culled) {
            for (int code = 0; code < 64; ++code) {
                NewBlock& block = of[culled][code];
                bool missing[3] = {};
                for (int e = 0; e < 3; ++e) missing[e] = !(((code >> e) | (code >> (3 + e))) & 1);
                // A child is complete when none of its outer edges is missing (the center has none).
                bool complete[4] = {};
                uint32_t ends = 0, incomplete = 0;
                for (int k = 0; k < 4; ++k) {
                    complete[k] = true;
                    for (int e = 0; e < 3; ++e) complete[k] = complete[k] && !(red_split::is_outer(k, e) && missing[e]);
                    incomplete += !complete[k];
                }
                for (int k = 0; k < 4; ++k) {
                    uint32_t state = complete[k] ? kFresh : culled ? uint32_t(kDecided) : 0u;
                    if (culled && complete[k]) {
                        // One bucket lower for each sibling the rule culls.
                        for (int e = 0; e < 3; ++e) {
                            const int s = red_split::sibling(k, e);
                            if (s >= 0 && !complete[s]) state -= 1u << kPriorityShift;
                        }
                    }
                    block.states |= state << (8 * k);
                }
                for (int e = 0; e < 3; ++e) {
                    const bool linked = (code >> e) & 1;
                    if (linked) block.edge_mask = uint8_t(block.edge_mask | (3 << (2 * e)));
                    ends += linked ? 1 : 2;
                }
                block.counts = (ends - 3) | uint64_t(incomplete) << 32;
                if (!culled) continue;
                // The incomplete children's neighbours across a linked edge lie outside the block.
                for (int f = 0; f < 3; ++f) {
                    if (!((code >> f) & 1)) continue;
                    if (!complete[red_split::first_half_child(f)])
                        block.lowered_offset[block.lowered_count++] = uint8_t(4 * red_split::first_half_word(f));
                    if (!complete[red_split::second_half_child(f)])
                        block.lowered_offset[block.lowered_count++] = uint8_t(4 * red_split::second_half_word(f));
                }
            }
        }
    }
};
constexpr NewBlocks kNewBlocks{};

// The culling rules in force (paper II-C): which rule decides an undecided node in state s
// during the traversal, or Fate::coded. (The nodes 1-regularity culls are decided before it:
// root_level and derive_next_level make them so.)
struct CullRules {
    bool one_regularity;
    bool hanging_nodes;
    Fate fate(uint8_t s) const {
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

}  // namespace amc
