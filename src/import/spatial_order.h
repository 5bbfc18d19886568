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

// The cells of morton_codes: a coordinate c on axis a lies at t = (c - low[a]) * scale in cell
// units, in cell cell_of(t) of 1024 (clamped: the largest coordinate, and points outside, fall in
// the end cells).
struct MortonFrame {
    static constexpr uint32_t kCellsPerAxis = 1024;  // 30-bit codes
    double low[3] = {0, 0, 0};
    double scale = 0;  // 0: one cell (no extent, or one too large)
    MortonFrame() = default;
    explicit MortonFrame(const std::vector<Vec3>& positions);
    // From the positions' least and greatest coordinates.
    MortonFrame(const double least[3], const double greatest[3]);
    double t(double c, int a) const { return (c - low[a]) * scale; }
    static uint32_t cell_of(double t) { return t >= 0 ? uint32_t(t < kCellsPerAxis - 1 ? t : kCellsPerAxis - 1) : 0; }  // NaN: 0
};

// The indices of `codes` in increasing order of their codes, equal ones in index order (two
// counting-sort passes).
std::vector<uint32_t> order_by_codes(const std::vector<uint32_t>& codes);

}  // namespace amc::detail
