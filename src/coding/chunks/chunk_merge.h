// Decoding the chunks of a chunked .amc file into one hierarchy, the whole over their roots
// (chunked_file.h), each chunk straight into the whole: on one thread in chunk order; on several,
// when the chunk table gives each chunk's nodes and own vertices (version 13 on), each into its
// slice of the whole's nodes and vertices at once.
#pragma once

#include "coding/chunks/chunk_coder.h"
#include "coding/chunks/chunk_layout.h"
#include "coding/chunks/seam.h"
#include "coding/container.h"

#include <amc/codec.h>

#include <cstdint>
#include <future>
#include <memory>
#include <mutex>
#include <vector>

namespace amc {

constexpr uint64_t kUnknownVertices = UINT64_MAX;  // a chunk table before version 13

// One chunk to decode: its block (checksum not yet checked) and the chunk table's entry.
struct ChunkJob {
    uint32_t chunk = 0;
    Block block{};
    RootRange roots;
    uint64_t nodes = 0;
    uint64_t own_vertices = kUnknownVertices;  // neither base nor seam vertices
};

// Idle chunk decoders, each keeping the working memory of the chunks it decoded. A decode takes
// one a thread and gives it back after its chunks; a DecodeContext keeps its set between decodes,
// so that a worker thread's decoder is not freed into that thread's malloc arena, trimmed, and
// faulted in again by the next decode (docs/BENCHMARKS.md, "Threads and memory"). Thread-safe.
class ChunkDecoders {
public:
    // An idle decoder, or a new one when none is idle. Restart it before use.
    std::unique_ptr<HierarchyLevelDecoder> take();
    // A decoder whose chunks all decoded; one whose decode threw is dropped instead (not given back).
    void give_back(std::unique_ptr<HierarchyLevelDecoder> decoder);
    void clear();

private:
    std::mutex mutex_;
    std::vector<std::unique_ptr<HierarchyLevelDecoder>> idle_;
};

struct ChunkMergeInput {
    const BlockReader* reader = nullptr;  // of the file: checks each chunk block before it is decoded
    const TriangleMesh* base = nullptr;  // the file's base mesh
    const Seam* seam = nullptr;
    CoordinateSpace space;
    uint8_t file_version = 0;
    bool whole_file = true;  // every chunk, in order
    uint64_t vertices = 0;   // the file's vertex count (metadata)
    size_t file_size = 0;
    DecodeOptions options;
    // The whole's positions, being zeroed on another thread (start_zeroed_positions); may be null.
    std::future<std::vector<Vec3>>* zeroed_positions = nullptr;
    // The caller's decoders, kept warm after the decode (DecodeContext); null: decoders made for
    // this decode, which on one thread give their working memory back over their last chunk
    // (ChunkPlace::last).
    ChunkDecoders* kept_decoders = nullptr;
    // A hierarchy the caller is done with (DecodeContext::recycle), or null: the whole is built in
    // its memory (HierarchyBuilder::adopt_storage), which is left empty.
    Hierarchy* spare = nullptr;
};

// What the chunks' decoders know of the merged hierarchy, when every level is decoded.
struct MergedCounts {
    uint64_t faces = 0;  // of its leaf mesh (leaf_face_count)
    int depth = 0;       // Hierarchy::depth
};

// Starts zeroing `vertices` positions on another thread while the base mesh and the seam are
// decoded: decoding chunks into slices of the whole (several threads, version 13 on) needs them
// before any chunk starts (2 % of a decode). An invalid future when no thread could be started.
// The whole's node pages are faulted in by the decoders of the slices, each its own: made resident
// here too they took 5-8 ms more than the base mesh, all of it waited for (docs/BENCHMARKS.md,
// "Threads and memory").
std::future<std::vector<Vec3>> start_zeroed_positions(size_t vertices);

// Decodes `jobs` (chunks in increasing order) and merges them: the hierarchy over base_of_roots of
// their roots, its vertices the base's, the seam vertices the chunks hold (in seam order), then
// each chunk's own.
Hierarchy decode_and_merge_chunks(const std::vector<ChunkJob>& jobs, const ChunkMergeInput& input, MergedCounts& counts);

}  // namespace amc
