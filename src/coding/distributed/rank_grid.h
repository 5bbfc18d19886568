// The grid of a quantized file written by ranks (EncodeOptions::quantize_bits; rank_encoder.h).
// The serial encoder spans the grid over the bounding box of every position and snaps all
// positions to it before predicting (FORMAT.md 5.4); ranks agree on the same box by exchanging
// their own boxes, then each snaps its own positions.
//
// Only the box's lower corner is stored (the grid's origin), and a coordinate's value fixes its
// bits except for zero: the serial encoder keeps the first of +0 and -0 it meets in vertex id
// order (std::fmin keeps its first argument on ties). Ranks reproduce that for the whole
// hierarchy numbered in canonical vertex order (canonical_vertex_order: base vertices, then the
// midpoints level by level, roots in order), which is how a rank's chunk is numbered; the key of
// a vertex in that order is (level, first root of the rank, ordinal within the rank).
#pragma once

#include "coding/distributed/rank_encoder.h"
#include "coding/geometry/float_coder.h"

#include <cstdint>
#include <string>
#include <vector>

namespace amc {

// One rank's box (plain data: it travels as bytes). Per axis the smallest and largest coordinate,
// and the canonical key of the first vertex with the smallest.
struct RankBox {
    double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    uint64_t lo_key[3][3] = {};
};

// The box of the whole base mesh (every rank holds it) and the rank's own vertices.
RankBox rank_box(const TriangleMesh& base, const RankChunk& part);

// The serial encoder's grid of `bits` over the boxes of all ranks (any order). Throws Error
// (invalid_input) naming `what` when the box spans more than the double range.
Quantizer grid_of_ranks(const std::vector<RankBox>& boxes, int bits, const std::string& what);

// The rank's positions snapped to the grid, as the serial encoder snaps the whole (float64 from
// then on); returns the largest coordinate error among them.
double snap_to_grid(RankChunk& part, const Quantizer& grid);
// The base mesh snapped alike.
TriangleMesh snapped_base(const TriangleMesh& base, const Quantizer& grid);
// A seam split's vertex snapped alike.
void snap_to_grid(std::vector<SeamSplit>& splits, const Quantizer& grid);

}  // namespace amc
