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
// Coordinates must be finite.
std::vector<uint32_t> spatial_vertex_order(const std::vector<Vec3>& positions);

// The 30-bit Morton code of each vertex (bit 3k + a: bit k of its cell on axis a). Each axis
// has 1024 cells over its extent, as spatial_vertex_order takes them; with `cubic_cells`, every
// axis has cells of one size, 1024 over the largest extent (a flat mesh's thin axis then splits
// no cell before the others do).
std::vector<uint32_t> morton_codes(const std::vector<Vec3>& positions, bool cubic_cells);

// The indices of `codes` in increasing order of their codes, equal ones in index order (two
// counting-sort passes).
std::vector<uint32_t> order_by_codes(const std::vector<uint32_t>& codes);

}  // namespace amc::detail
