// How many leaves and nodes a uniform refinement makes, counted only as far as a caller's cap:
// the refine command and the remesher refuse targets beyond their node limit before refining.
#pragma once

#include <cstdint>
#include <limits>

namespace amc {

// Leaves of `roots` triangles each split `levels` times (4 children a split), or a count above
// `cap` once it passes it.
inline uint64_t uniform_leaf_count(uint64_t roots, int levels, uint64_t cap) {
    uint64_t leaves = roots;
    for (int l = 0; l < levels && leaves <= cap && leaves <= std::numeric_limits<uint64_t>::max() / 4; ++l) leaves *= 4;
    return leaves;
}

// Their nodes, every level's, likewise.
inline uint64_t uniform_node_count(uint64_t roots, int levels, uint64_t cap) {
    uint64_t leaves = roots, nodes = roots;
    for (int l = 0; l < levels && nodes <= cap && leaves <= std::numeric_limits<uint64_t>::max() / 4; ++l) {
        leaves *= 4;
        nodes += leaves;
    }
    return nodes;
}

}  // namespace amc
