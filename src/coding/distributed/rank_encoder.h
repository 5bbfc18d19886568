// A chunked .amc file written in pieces by several processes (MPI ranks, include/amc/mpi.h), with no
// MPI here: the steps each rank takes and what they exchange, as plain functions over values, so
// that one process can play every rank (tests/rank_encoder_test.cpp) and amcodec_mpi only moves
// bytes. docs/MPI.md explains the design.
//
// Each rank holds the whole base mesh and the trees of one run of roots. The file is exactly what
// encode() writes for the whole hierarchy with EncodeOptions::keep_base_order and chunk_roots set
// to the ranks' root counts: one chunk per rank that owns roots, in root order (quantized files:
// for one case of signed zeros, of the whole numbered canonically; rank_grid.h).
//   1. rank_chunk: the rank's forest checked against the base and expressed as the serial
//      encoder's chunk of those roots.
//   2. (exchange every rank's root range) rank_layout: the chunks, and which rank holds which.
//   2b. Quantized files only: (exchange every rank's box) the grid (rank_grid.h); each rank snaps
//      its positions to it.
//   3. seam_splits: the splits the rank's trees make on the edges between chunks, with their
//      vertices' positions. (exchange them all) rank_seam: the same seam on every rank.
//   4. encode_rank_chunk: the rank's chunk block, after checking that its trees fit the seam
//      (balance and closure across it, which no single rank can check alone).
//   5. (exchange the summaries) chunked_file_head: the bytes before the first chunk block; each
//      chunk block starts where the blocks before it end; end_block closes the file.
#pragma once

#include "coding/chunks/chunk_coder.h"
#include "coding/chunks/chunk_layout.h"
#include "coding/chunks/seam.h"

#include <amc/codec.h>

#include <cstdint>
#include <string>
#include <vector>

namespace amc {

// The refusals of what a rank-wise file can not hold (a numbering, the mixing mode; docs/MPI.md
// says why): Error (invalid_input) naming `what`.
void check_rank_options(const EncodeOptions& options, const std::string& what);

struct RankChunk {
    uint32_t first_root = 0;
    Hierarchy chunk;                    // over base_of_roots of {first_root, roots}, as extract_roots makes it
    std::vector<VertexId> base_vertex;  // chunk base vertex i is base vertex base_vertex[i]
};

// Checks `forest` against `base` and re-expresses it. `forest` is a hierarchy over the triangles
// first_root .. first_root + forest.root_count() - 1 of `base`: its triangle i has the corners of
// base triangle first_root + i in the same order, under any vertex numbering, and the same base
// positions bit for bit. Throws Error (invalid_input) naming `what` and the first mismatch, or
// what check_before_writing refuses.
RankChunk rank_chunk(const TriangleMesh& base, uint32_t first_root, const Hierarchy& forest, const std::string& what);

struct RankLayout {
    std::vector<RootRange> chunks;        // in root order: one per rank that owns roots
    std::vector<int32_t> chunk_of_rank;   // -1 for a rank without roots
    std::vector<uint32_t> chunk_of_root;
};
// `ranges[r]`: rank r's roots. They must cut 0 .. roots - 1 into runs without gap or overlap (in
// any rank order; empty ranges are allowed). Throws Error (invalid_input) otherwise.
RankLayout rank_layout(uint32_t roots, const std::vector<RootRange>& ranges);

// The splits `part` makes on the seam edges of `layout` that its roots touch.
std::vector<SeamSplit> seam_splits(const RankChunk& part, const TriangleMesh& base, const RankLayout& layout);

// The seam from every rank's splits (Seam::from_splits), the two sides' positions compared as the
// ranks gave them; on `grid` (quantized files; null: bit-exact) the seam then holds them snapped,
// over the snapped base, as the serial encoder's seam does.
Seam rank_seam(const TriangleMesh& base, const RankLayout& layout, std::vector<SeamSplit> splits, const Quantizer* grid);

// What every rank tells the others about its chunk (plain data: it travels as bytes).
struct ChunkSummary {
    uint64_t roots = 0, nodes = 0, own_vertices = 0, faces = 0, block_bytes = 0;
    uint32_t levels = 0, static_geometry = 0, grid_geometry = 0, unit_geometry = 0, raw_side = 0, stencil_tables = 0;
};

struct RankCode {
    std::vector<uint8_t> block;  // the framed chunk block
    ChunkSummary summary;
};
// Checks that the rank's trees fit the seam (no node refined next to a coarser leaf across it, no
// leaf with three hanging nodes) and codes its chunk block, its positions on `grid` (quantized
// files, already snapped to it; null: bit-exact). Throws Error (invalid_input) naming `what` when
// they do not.
RankCode encode_rank_chunk(const RankChunk& part, const Seam& seam, const EncodeOptions& options, const Quantizer* grid,
                           const std::string& what);

// The bytes before the first chunk block: header, metadata, base mesh, chunk table and seam block.
// `chunks` in root order; only the seam's splits and the summaries vary between ranks' files.
// `grid` as for encode_rank_chunk; `base` as the ranks hold it (not snapped).
std::vector<uint8_t> chunked_file_head(const TriangleMesh& base, const Seam& seam, const std::vector<ChunkSummary>& chunks,
                                       const EncodeOptions& options, const Quantizer* grid);
// The END block, the file's last 9 bytes.
std::vector<uint8_t> end_block();

}  // namespace amc
