// A vertex order in which vertices near in space are near in memory (Morton order of their
// positions): the import runs on it, because a user's leaf mesh may list its vertices in any
// order, and on a shuffled 10^6-face mesh nearly every lookup missed the cache.
#pragma once

#include <amc/mesh.h>

#include <cstdint>
#include <vector>

namespace amc::detail {

// The vertex ids in Morton (Z-curve) order of their positions on a 1024^3 grid over the
// bounding box; vertices of one cell keep their order. Linear (two counting-sort passes).
// Coordinates must be finite. `sorted_codes`, if given, gets the codes in that order.
std::vector<uint32_t> spatial_vertex_order(const std::vector<Vec3>& positions,
                                           std::vector<uint32_t>* sorted_codes = nullptr);

// The 30-bit Morton code of each vertex on that grid (bit 3k + a: bit k of the cell on axis a).
std::vector<uint32_t> morton_codes(const std::vector<Vec3>& positions);

}  // namespace amc::detail
