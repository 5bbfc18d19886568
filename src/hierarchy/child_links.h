// How the four children of a refined node take their links from it (child order and local
// indexing: include/amc/hierarchy.h). Shared by Hierarchy::split_level and the coders' level
// forest, which link children in bulk and must agree with Hierarchy::split.
#pragma once

#include <cstdint>

namespace amc {

// Per child k: the bits of the parent's neighbour edge indices (2 bits per edge) that carry over to
// its outer edges (children are parallel to their parent), the fixed indices of its inner edges
// (corner k and the center meet across their edges (k+1)%3), and the parent's boundary edges it
// lies on (corner k: edges k and (k+2)%3; the center: none).
struct ChildEdges {
    uint8_t outer;
    uint8_t inner;
    uint8_t boundary;
};
constexpr ChildEdges kChildEdges[4] = {
    {0x33, 1u << 2, 5},
    {0x0f, 2u << 4, 3},
    {0x3c, 0u, 6},
    {0x00, (1u << 2) | (2u << 4), 0},
};

// The same-level neighbours of the four children (nbr[k][e]: child k across its edge e), given
// the first child's id c and, per parent edge e, the neighbours across its first half (child e's
// edge e) and its second half (child (e+1)%3's edge e).
struct ChildNeighbors {
    uint32_t nbr[4][3];
};
inline ChildNeighbors child_neighbors(uint32_t c, const uint32_t first[3], const uint32_t second[3]) {
    return {{{first[0], c + 3, second[2]},
             {second[0], first[1], c + 3},
             {c + 3, second[1], first[2]},
             {c + 2, c, c + 1}}};
}

}  // namespace amc
