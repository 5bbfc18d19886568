// Context groups of the hierarchy coder (paper, section II-D, Table 2).
//
// The context of a node's symbol is how many of its three same-level edge neighbours are known to
// be refined (x), known not to be refined (y), or not yet coded (z), x + y + z = 3: ten groups.
// How edges without a coded neighbour count:
//   - a base-mesh boundary edge counts as "not refined": nothing can refine across it, just as
//     a leaf neighbour does not;
//   - an inner edge without a same-level neighbour (the region across is coarser) also counts as
//     "not refined"; such a node is culled by 1-regularity and only carries a symbol when that
//     rule is switched off.
// Group (3,0,0) only carries symbols when hanging-node culling is off.
#pragma once

#include <amc/hierarchy_coder.h>

namespace amc {

constexpr int kContextGroupCount = 10;

// Table 2's order: (2,1,0) (2,0,1) (1,2,0) (1,1,1) (1,0,2) (0,3,0) (0,2,1) (0,1,2) (0,0,3), then (3,0,0).
constexpr int kContextGroupOf[4][4] = {
    // unrefined: 0   1   2   3          (refined = row)
    {8, 7, 6, 5},    // refined 0: (0,0,3) (0,1,2) (0,2,1) (0,3,0)
    {4, 3, 2, -1},   // refined 1: (1,0,2) (1,1,1) (1,2,0)
    {1, 0, -1, -1},  // refined 2: (2,0,1) (2,1,0)
    {9, -1, -1, -1}, // refined 3: (3,0,0)
};

inline int context_group_of(int refined, int unrefined) { return kContextGroupOf[refined][unrefined]; }

}  // namespace amc
