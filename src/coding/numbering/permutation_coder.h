// Permutations of 0..n-1 in the numbering block (docs/FORMAT.md, section 6): as ranks among the
// values not used yet, each relative to the rank that continues the previous value (a caller's
// order that follows the canonical one costs almost nothing; a random one about log2(n!) bits),
// or as a walk over a graph of the elements (a caller's order that walks the mesh costs a few
// bits an element).
#pragma once

#include "coding/entropy/arithmetic_coder.h"

#include <amc/mesh.h>

#include <cstdint>
#include <vector>

namespace amc {

// Frozen values (written to files).
enum class PermutationMethod : uint8_t { identity = 0, uniform = 1, adaptive = 2, walk = 3 };

// The rank methods (identity, uniform, adaptive) over `sequence`, and their decoder; `what` names
// the order in messages. Throws Error (corrupt) on a rank no encoder writes.
void encode_permutation(ArithmeticEncoder& encoder, PermutationMethod method, const std::vector<uint32_t>& sequence);
std::vector<uint32_t> decode_permutation(ArithmeticDecoder& decoder, PermutationMethod method, uint32_t n,
                                         const char* what);
// Identity where the sequence is 0..n-1, else the smaller of uniform and adaptive.
PermutationMethod best_method(const std::vector<uint32_t>& sequence);

// A graph over the elements of a permutation (vertices: leaf mesh edges; triangles: shared
// edges), as adjacency lists sorted by element.
struct Graph {
    std::vector<uint32_t> start, neighbors;
};
Graph vertex_graph(const std::vector<Triangle>& leaf, uint32_t vertices);
Graph triangle_graph(const std::vector<Triangle>& leaf);

// Method 3 (walk): `sequence` in the caller's order, each element predicted to be one of the
// unused neighbours in `graph` of the one before it, others as rank differences among all unused
// ones; and its decoder. Throws Error (corrupt) on a step no encoder writes.
void encode_walk(ArithmeticEncoder& encoder, const Graph& graph, const std::vector<uint32_t>& sequence);
std::vector<uint32_t> decode_walk(ArithmeticDecoder& decoder, const Graph& graph, uint32_t n, const char* what);

}  // namespace amc
