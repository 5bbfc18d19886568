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

}  // namespace amc
