// One .amc file written and read by many MPI processes (library amcodec_mpi, CMake option
// AMC_WITH_MPI; docs/MPI.md). Every call here is collective: all ranks of `comm` make it, with
// their own arguments.
//
// Writing: each rank holds the whole base mesh (the same on every rank, as p4est replicates its
// coarse mesh) and the trees of one run of roots (base triangles); it codes them as one chunk of a
// chunked file (docs/FORMAT.md 3.11), and all ranks write the file together with MPI-IO. The file
// is byte for byte what the serial encoder writes for the whole hierarchy with
// EncodeOptions::keep_base_order and chunk_roots set to the ranks' root counts, so `amc decode`,
// decode() and every reader read it; the decoded roots are in the ranks' order.
//
// Reading: any number of ranks, each reading (MPI-IO) the file's head and the chunk blocks that
// hold its share of the roots, and decoding those alone.
#pragma once

#include <amc/codec.h>

#include <mpi.h>

#include <cstdint>
#include <string>
#include <vector>

namespace amc::mpi {

struct WriteStats {
    uint64_t file_bytes = 0;     // the whole file
    uint64_t rank_bytes = 0;     // what this rank wrote
    uint64_t seam_vertices = 0;  // vertices on edges between ranks, stored once in the seam block
    double max_error = 0;        // quantized files: the largest coordinate error of any rank (0: bit-exact)
    double encode_seconds = 0;   // this rank: checks, seam, its chunk (wall clock)
    double write_seconds = 0;    // the exchanges of sizes and the collective write, renaming included
};

// Writes `path` with every rank of `comm`.
// - `base`: the whole base mesh, identical on every rank (checked).
// - `forest`: this rank's roots and their trees, a hierarchy over the base triangles first_root ..
//   first_root + forest.root_count() - 1: triangle i of forest.base() has the corners of base
//   triangle first_root + i in the same order, its vertices numbered as the rank likes, at the
//   base's positions bit for bit. The ranks' runs must cut the base's triangles without gap or
//   overlap, in any rank order; a rank may own none (Hierarchy(TriangleMesh{})).
// - Across rank boundaries the forests must fit as parts of one hierarchy (checked): balance (no
//   node refined next to a leaf two levels coarser across the boundary, no leaf with three hanging
//   nodes counting those of the other side), and the same position, bit for bit, for a vertex both
//   sides create on a shared edge. A leaf's diagonal flag must be the whole hierarchy's: a leaf
//   next to the boundary whose green closure has a hanging node of the other side keeps the flag
//   that closure has (HIERARCHY.md), though its own forest does not show that node.
// - `options`: as for encode(): hierarchy coder switches, predictor, quantize_bits (the grid spans
//   every rank's positions; the ranks agree on it) and grid_contexts; keep_base_order and
//   chunk_roots are implied; a numbering and mixed contexts are refused (docs/MPI.md says why).
// Written to a temporary name next to `path` and renamed by rank 0 once every rank has written.
// Throws Error on every rank when any rank's input is refused (the message names the rank and the
// problem; nothing is written) or the file can not be written (ErrorCode::io).
void write(MPI_Comm comm, const std::string& path, const TriangleMesh& base, uint32_t first_root, const Hierarchy& forest,
           const EncodeOptions& options = {}, WriteStats* stats = nullptr);

struct Share {
    uint32_t first_root = 0;             // the share's roots: first_root .. first_root + roots - 1 of the file
    uint32_t file_roots = 0;             // the file's root count
    Hierarchy hierarchy;                 // their trees, as extract_roots of the whole decoded file makes them
    std::vector<uint32_t> base_vertices; // base vertex i of hierarchy is the file's base vertex base_vertices[i]
    uint64_t bytes_read = 0;             // bytes this rank read from the file
    double seconds = 0;                  // wall clock of the whole call
};

// Reads the roots first_root .. first_root + root_count - 1 of `path` on this rank (any run, 0
// roots included; ranks may overlap). Each rank reads the file's head (rank 0 finds its end) and
// the chunk blocks covering its run, decodes them alone and keeps its roots. Throws Error on every
// rank when any rank's run or the file is refused (the message names the file and, for a run, the
// rank).
Share read(MPI_Comm comm, const std::string& path, uint32_t first_root, uint32_t root_count, const DecodeOptions& options = {});

// The same with the file cut along its chunks: each rank reads a run of whole chunks, the runs
// balanced by the chunk table's node counts, so that no two ranks decode one chunk. Ranks past the
// chunk count read no roots (first_root = the file's root count); a file without chunks is one
// chunk, read by rank 0.
Share read(MPI_Comm comm, const std::string& path, const DecodeOptions& options = {});

}  // namespace amc::mpi
