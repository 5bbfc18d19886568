// A vertex order in which vertices near in space are near in memory (Morton order of their
// positions): the import runs on it, because a user's leaf mesh may list its vertices in any
// order, and on a shuffled 10^6-face mesh nearly every lookup missed the cache.
#pragma once

#include <amc/mesh.h>

#include <cstdint>
#include <vector>

namespace amc::detail {

// The vertex ids in Morton (Z-curve) order of their positions on cubic cells (morton_codes);
// vertices of one cell keep their order. Linear (two counting-sort passes). Coordinates must be
// finite. `sorted_codes`, if given, receives the codes in that order (ascending), which the
// nearest-vertex tree over the vertices so numbered takes instead of computing them again.
std::vector<uint32_t> spatial_vertex_order(const std::vector<Vec3>& positions,
                                           std::vector<uint32_t>* sorted_codes = nullptr);

// The 30-bit Morton code of each vertex (bit 3k + a: bit k of its cell on axis a), on cubic
// cells: 1024 over the largest extent, every axis cut in cells of that size (cells per axis
// would split a flat mesh moved off its plane on its thin axis's noise first, scattering
// neighbours over the whole order and the tree's first splits).
std::vector<uint32_t> morton_codes(const std::vector<Vec3>& positions);

// The indices of `codes` in increasing order of their codes, equal ones in index order (two
// counting-sort passes).
std::vector<uint32_t> order_by_codes(const std::vector<uint32_t>& codes);

}  // namespace amc::detail
