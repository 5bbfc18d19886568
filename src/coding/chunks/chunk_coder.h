// One chunk of a chunked .amc file (docs/FORMAT.md 3.14): the hierarchy of the chunk's roots over
// their own base triangles, coded level by level as a whole file codes its levels (hierarchy
// symbols, orientation bits, new positions), except that the vertices on seam edges come from
// the seam block, and followed by the diagonal flags of the leaves whose closure only the seam
// reveals (a hanging node from another chunk).
#pragma once

#include "coding/chunks/seam.h"
#include "coding/format_version.h"
#include "coding/geometry/float_coder.h"  // CoordinateSpace
#include "coding/geometry/static_position_coder.h"  // StaticEncoderBuffers
#include "coding/hierarchy/hierarchy_level_coder.h"

#include <amc/codec.h>

#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

namespace amc {

struct ChunkCode {
    std::vector<uint8_t> bytes;       // the chunk block's payload
    uint64_t hierarchy_bytes = 0;     // estimated as in EncodeStats
    uint64_t geometry_bytes = 0;
    uint64_t faces = 0;               // faces of the whole leaf mesh that belong to the chunk's leaves
    bool static_geometry = false;     // a level uses geometry mode 3 (predictor 3)
    bool grid_geometry = false;       // a level uses geometry mode 4 (predictor 4)
    bool unit_geometry = false;       // a level uses geometry mode 5 (predictor 5)
    bool raw_side = false;            // a level's raw bits are in a side stream (kRawSideFlag: version 14)
    bool stencil_tables = false;      // a level uses geometry mode 6 or 7 (version 15)
    std::vector<LevelStats> levels;
};

// The working memory of one chunk's encoder: its first pass's and its static geometry modes'
// buffers, kept from one chunk to the next it codes.
struct ChunkEncoderMemory {
    HierarchyLevelEncoder::Memory first_pass;
    StaticEncoderBuffers statics;
};

// Idle chunk encoders' memories (the mirror of ChunkDecoders): an encode takes one a thread and
// gives it back after its chunks; an EncodeContext keeps its set between encodes, so that a worker
// thread's memory is not freed into that thread's malloc arena, trimmed, and faulted in again by
// the next encode (docs/BENCHMARKS.md, "Threads and memory"). Thread-safe.
class ChunkEncoderMemories {
public:
    // An idle memory, or a new one when none is idle.
    std::unique_ptr<ChunkEncoderMemory> take();
    // A memory whose chunks all coded; one whose encode threw is dropped instead (not given back).
    void give_back(std::unique_ptr<ChunkEncoderMemory> memory);

private:
    std::mutex mutex_;
    std::vector<std::unique_ptr<ChunkEncoderMemory>> idle_;
};

// Codes `chunk` (extract_roots of the whole hierarchy, positions as the decoder will have them).
// `keys` holds the seam keys of the chunk's vertex ids (seam.h). The encoder works in `memory`
// when given (one thread at a time).
ChunkCode encode_chunk(const Hierarchy& chunk, const VertexKeys& keys, const Seam& seam, const HierarchyCoderOptions& options,
                       GeometryPredictor predictor, CoordinateSpace space, bool grid_contexts = false,
                       bool unit_normals = false, int effort = kMaxGeometryEffort, ChunkEncoderMemory* memory = nullptr);

struct ChunkDecodeLimits {
    uint64_t max_nodes = 0;     // the chunk's node count from the chunk table (within the caller's limit)
    int max_level = -1;         // progressive decoding: stop after this level
    uint8_t file_version = kChunkedVersion;  // which level geometry modes the file may hold
    uint8_t stream_version = kHierarchyStreamVersion;
};

// Where a chunk is decoded: the `roots` roots of `target` from `first_root`, unrefined and linked
// among themselves only (its links to other chunks cut), their descendants appended to `target`
// or written into `slice` of it.
// `keys` tells the seam keys of target's vertex ids: its base vertex v is key base_keys[v], and
// every seam vertex s is placed already, as vertex seam_first + s.
struct ChunkVertexKeys {
    const std::vector<VertexId>* base_keys = nullptr;
    VertexId seam_first = 0;
    uint32_t seam_count = 0;
    uint32_t seam_base_vertices = 0;  // the seam's keys of seam vertices start here (Seam::base_vertex_count)
    uint32_t key(VertexId v) const {
        if (v < base_keys->size()) return (*base_keys)[v];
        return v - seam_first < seam_count ? seam_base_vertices + (v - seam_first) : kNoVertex;
    }
};
struct ChunkPlace {
    Hierarchy* target = nullptr;
    NodeId first_root = 0;
    uint32_t roots = 0;
    ChunkVertexKeys keys;
    uint8_t* seam_used = nullptr;  // seam_used[s] set to 1 when the chunk splits off seam vertex s
    HierarchySlice* slice = nullptr;  // where its nodes and own vertices go; null: appended to target
    bool last = false;  // no chunk follows on its decoder (its working memory need not be kept warm)
};

// What a chunk's decoder knows of its trees once every level is decoded.
struct ChunkCounts {
    uint64_t faces = 0;  // its leaves' faces in the whole leaf mesh (ChunkCode::faces)
    int depth = 0;       // its finest level
};

// Decodes a chunk block's payload into `place` with `decoder` (restarted; a decoder used again
// keeps its working memory). Throws Error naming `what` on a corrupt chunk. `counts` receives its
// counts (meaningful when every level is decoded).
void decode_chunk(HierarchyLevelDecoder& decoder, const uint8_t* data, size_t size, const ChunkPlace& place,
                  const Seam& seam, CoordinateSpace space, const ChunkDecodeLimits& limits, const std::string& what,
                  ChunkCounts& counts);

}  // namespace amc
