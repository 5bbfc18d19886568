// The static geometry mode of a level (docs/FORMAT.md 5.6): the positions a level creates,
// predicted in the normal frame (geometry_prediction.h), their residuals mapped to tokens coded
// with interleaved rANS under three frequency tables the level block carries (one per role: the
// normal's axis, then the two others), and the bits below each token copied to a raw bit stream.
// Built for decode speed: one table look-up per coordinate instead of a dozen adaptive binary
// decisions, and the noise bits of bit-exact coordinates read 57 at a time.
//
// Token of a residual of sign s (1 = negative) and magnitude m, k = bit length of m:
//   m = 0: token 0;  1 <= m < 8: token 2m - 1 + s;
//   m >= 8: token 15 + 4 (k - 4) + (the two bits below the leading one); raw bits: s, then the
//   k - 3 low bits of m (most significant first, in two values of k - 35 and 32 bits when
//   k - 3 > 32).
//
// Geometry mode 4 (FORMAT.md 5.7, quantized files only) is mode 3 with the frame's normal summed
// from unit normals (the surface remesher's direction) and six tables: each role's residuals split
// by where the prediction t (in grid steps) lies between two grid points. Where the
// surface is flat at the grid's scale the residual is rounding noise: 0 when t is near a grid point,
// 0 or a step towards the second-nearest grid point, about evenly, when t is near half-way (the
// midpoint of two grid points whose sum is odd). The residual's sign is turned so that positive
// points towards the second-nearest grid point.
#pragma once

#include "coding/entropy/arithmetic_coder.h"
#include "coding/entropy/rans_coder.h"
#include "coding/geometry/float_coder.h"

#include <amc/hierarchy.h>

#include <array>
#include <cstdint>
#include <utility>
#include <vector>

namespace amc {

constexpr int kStaticRoles = 3;
constexpr int kGridBins = 2;  // mode 4: |t - round(t)| below or from 1/4
constexpr int kMaxStaticTables = kStaticRoles * kGridBins;
// Mode 3 uses the first three (one per role), mode 4 all six (table 2 role + bin).
using StaticTables = std::array<RansTable, kMaxStaticTables>;

// The number of tables of a static mode: 3 (mode 3) or 6 (mode 4, `grid_bins`).
constexpr int static_table_count(bool grid_bins) { return grid_bins ? kMaxStaticTables : kStaticRoles; }

// The code of one level's new positions in the static mode. `created` are the level's new
// vertices (new_vertices_of_level) with their positions set in h (the decoder's values: on the grid
// when quantized).
class StaticLevelEncoder {
public:
    // grid_bins: mode 4 (space must be quantized), else mode 3.
    StaticLevelEncoder(const Hierarchy& h, const std::vector<std::pair<NodeId, int>>& created, CoordinateSpace space,
                       bool grid_bins = false);
    // The tables (three, or six in mode 4), into the level's arithmetic payload after the hierarchy part.
    void write_tables(ArithmeticEncoder& encoder) const;
    const std::vector<uint8_t>& rans_bytes() const { return rans_; }
    const std::vector<uint8_t>& raw_bytes() const { return raw_; }
    // The bytes this mode costs the level's positions: tables (coded alone), both streams and the
    // varint of the rANS length.
    size_t estimated_bytes() const;

private:
    StaticTables tables_;
    int table_count_ = kStaticRoles;
    std::vector<uint8_t> rans_, raw_;
};

// Reads the tables (three, or six with grid_bins); false when they are not valid for `space` (a
// frequency sum other than 2^12, a token larger than the space's residuals can be).
bool read_static_tables(ArithmeticDecoder& decoder, CoordinateSpace space, bool grid_bins, StaticTables& tables);

// Decodes the positions of `created` (in order) and sets them in h. False when the streams are
// corrupt: a grid coordinate out of range, a non-finite coordinate, an overrun, or streams that do
// not end where the last coordinate ends.
bool decode_static_positions(Hierarchy& h, const std::vector<std::pair<NodeId, int>>& created, CoordinateSpace space,
                             bool grid_bins, const StaticTables& tables, const uint8_t* rans, size_t rans_size, const uint8_t* raw,
                             size_t raw_size);

}  // namespace amc
