// The blocks of a chunked .amc file after its base mesh (docs/FORMAT.md 3.11-3.14): the chunk
// table, the seam, one block per chunk. Chunks are coded and decoded on several threads; a reader
// may decode any subset of them.
#pragma once

#include "coding/chunks/chunk_coder.h"  // ChunkEncoderMemories
#include "coding/chunks/chunk_layout.h"
#include "coding/chunks/chunk_merge.h"
#include "coding/container.h"
#include "coding/geometry/float_coder.h"  // CoordinateSpace

#include <amc/codec.h>

#include <cstdint>
#include <future>
#include <utility>
#include <vector>

namespace amc {

// Faces of the conforming leaf mesh (1 + hanging nodes per leaf), counted on up to `threads` threads.
uint64_t leaf_face_count(const Hierarchy& h, unsigned threads = 1);

struct ChunkedBlocks {
    std::vector<std::pair<BlockType, std::vector<uint8_t>>> blocks;  // chunk table, seam, chunks
    bool static_geometry = false;  // some chunk level uses geometry mode 3
    bool grid_geometry = false;    // some chunk level uses geometry mode 4
    bool unit_geometry = false;    // some chunk level uses geometry mode 5
    bool raw_side = false;         // some chunk level has its raw bits in a side stream (version 14)
    bool stencil_tables = false;   // some chunk level uses geometry mode 6 or 7 (version 15)
    bool base_side = false;        // the seam block (and so the base geometry block) has a raw side stream (version 21)
    int levels = 0;                // of the deepest chunk
};

// Codes `h` (decoder base order, positions as the decoder will have them) in the chunks `ranges`
// on up to `threads` threads; `root_of` is root_of_nodes(h), `root_nodes` nodes_per_root(h,
// root_of). Adds the hierarchy and geometry bytes and the level statistics (summed over chunks) to
// `stats`. With `kept` (an EncodeContext's), each thread codes its chunks in one memory of it.
// `base_raw_bits`: the base geometry block has raw bits for a side stream (a bit-exact file of
// version 21 then; so too when the seam has some, and then both blocks are in that layout).
ChunkedBlocks encode_chunked(const Hierarchy& h, const std::vector<uint32_t>& root_of, const std::vector<uint64_t>& root_nodes,
                             const std::vector<RootRange>& ranges,
                             const EncodeOptions& options, CoordinateSpace space, unsigned threads, EncodeStats& stats,
                             bool base_raw_bits, ChunkEncoderMemories* kept = nullptr);

// The chunk table of a file of `version`, read and checked against the base (root counts) and
// the file's node count.
struct ChunkTable {
    std::vector<RootRange> roots;
    std::vector<uint64_t> nodes;
    std::vector<uint64_t> own_vertices;  // vertices neither base nor seam vertices (version 13 on; else empty)
    std::vector<uint64_t> offsets;  // of each chunk block from the end of the table block
    size_t end = 0;                 // file offset of the end of the table block
};
ChunkTable read_chunk_table(const Block& block, uint8_t version, uint64_t base_triangles, uint64_t nodes, size_t file_size);

struct ChunkedDecodeInput {
    const TriangleMesh* base = nullptr;  // the decoded base mesh
    CoordinateSpace space;
    uint8_t version = kChunkedVersion;
    uint64_t vertices = 0;  // the file's vertex count (metadata)
    DecodeOptions options;
    std::future<std::vector<Vec3>>* zeroed_positions = nullptr;  // ChunkMergeInput's
    ChunkDecoders* kept_decoders = nullptr;                       // ChunkMergeInput's
    Hierarchy* spare = nullptr;                                   // ChunkMergeInput's
};

// Reads the chunk table and seam blocks at the reader's position and decodes the chunks in
// `selected` (indices in increasing order; all of them when null), seeking to each through the
// table, then merges them: the hierarchy over base_of_roots of their roots. Leaves the reader
// after the last chunk block when all are decoded. `counts_out` receives the merged hierarchy's
// counts as the chunks' decoders know them (for the metadata check, without a pass over its
// nodes), when every level is decoded.
Hierarchy decode_chunked(BlockReader& reader, const ChunkedDecodeInput& input, uint64_t nodes,
                         const std::vector<uint32_t>* selected, ChunkTable* table_out = nullptr,
                         MergedCounts* counts_out = nullptr);

}  // namespace amc
