// The .amc file: a hierarchy (base mesh, forest, diagonals, positions) compressed losslessly,
// laid out coarse to fine so that any prefix of levels decodes (docs/FORMAT.md).
#pragma once

#include <amc/hierarchy.h>
#include <amc/hierarchy_coder.h>
#include <amc/numbering.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace amc {

enum class GeometryPredictor : uint8_t {
    automatic = 0,  // per level, whichever of the candidates codes smaller
    midpoint = 1,
    butterfly = 2,
    // The normal frame with static tables and rANS (docs/FORMAT.md 5.6): faster to decode, and
    // smaller on surface remeshes; files that use it are .amc version 6.
    normal_frame = 3,
    // Quantized files only: the normal frame with six tables, each role's residuals split by where
    // the prediction falls between two grid points (docs/FORMAT.md 5.7): 11-12 % smaller geometry
    // at 12 bits, 3-4 % at 16 bits on the surface remeshes; files that use it are .amc version 9.
    normal_frame_grid = 4,
    // The normal frame of mode 4 (the two triangles' unit normals summed, the surface remesher's
    // direction) with mode 3's three tables (docs/FORMAT.md 5.8): bit-exact remeshes' new vertices
    // lie on that line up to rounding; files that use it are .amc version 12.
    unit_normal_frame = 5,
    // Bit-exact files only: the midpoint's and the butterfly's predictions with mode 3's residual
    // tokens, three static tables (one per axis), rANS and raw bits (docs/FORMAT.md 5.9): the
    // adaptive predictors' sizes at a fraction of their decode; files that use them are .amc version 15.
    midpoint_static = 6,
    butterfly_static = 7,
};

// How the hierarchy symbols of an .amc file are modelled (docs/HIERARCHY_CODER.md).
enum class HierarchyContexts : uint8_t {
    paper = 0,  // the paper's ten context groups, one adaptive model each (the fastest to decode)
    // Sixteen models under richer contexts (structure one level up, decided neighbours' neighbours,
    // decoded geometry) mixed logistically: 5-33% smaller hierarchy code on the corpus, slower to
    // decode; files that use it are .amc version 11 (FORMAT.md 2.3), one chunk.
    mixed = 1,
};

constexpr int kMaxGeometryEffort = 2;  // the highest effort that weighs the geometry modes alone
constexpr int kMaxEffort = 4;
constexpr int kDefaultEffort = 1;

struct EncodeOptions {
    HierarchyCoderOptions hierarchy;  // the connectivity coder's switches (defaults: the full method)
    HierarchyContexts hierarchy_contexts = HierarchyContexts::paper;
    // The mixing mode also codes the forest in the other traversal (the written model only) and
    // keeps the smaller file; a tie keeps hierarchy.traversal. About 30 % more encode time
    // (docs/HIERARCHY_CODER.md, "The traversal of the mixing mode"). False: hierarchy.traversal
    // alone. The paper mode ignores it.
    bool choose_traversal = true;
    // 0: bit-exact coordinates. 1..30: coordinates quantized to a grid of 2^bits steps over the
    // bounding box (lossy; EncodeStats::max_error tells how much).
    int quantize_bits = 0;
    GeometryPredictor predictor = GeometryPredictor::automatic;
    // Quantized files: the automatic predictor also tries geometry mode 4 (normal_frame_grid) on
    // every level and keeps it where it codes smaller (such files are version 9). Bit-exact files
    // have no grid and ignore it; false keeps quantized files at mode 3 (version 6 or 7).
    bool grid_contexts = true;
    // The automatic predictor also tries geometry mode 5 (unit_normal_frame) on every level of a
    // bit-exact file and keeps it where it codes smaller (such files are version 12); false keeps
    // the choices of version 11's encoder.
    bool unit_normals = true;
    // How hard the encoder looks (docs/CODEC.md, "Encode effort"). 0..kMaxGeometryEffort weigh
    // each level's geometry modes: kMaxGeometryEffort codes every candidate until it is the
    // smallest or can not be; lower efforts judge the adaptive predictors from a sample of the
    // level first (faster encodes, slightly larger files). 3 and 4 also choose the base order: the
    // file at effort 2 in the base coder's order and in the 4 (16) of 16 (64) other start
    // triangles' orders with the smallest base blocks, the smallest file kept (docs/HIERARCHY_CODER.md,
    // "The base order as an encoder choice", for sizes and times); with keep_base_order or a stored
    // numbering they are effort 2. The decoder reads every choice alike. encode() refuses an effort
    // outside 0..kMaxEffort (invalid_input).
    int effort = kDefaultEffort;
    // The caller's numbering of the input's leaf mesh (leaf_numbering()), or null. The encoder
    // re-expresses it against the leaf mesh the decoder rebuilds (EncodeStats::numbering) and,
    // with store_numbering, stores it in the file so that decode returns it (docs/FORMAT.md,
    // section 6; its cost per model is in docs/CODEC.md).
    const LeafNumbering* numbering = nullptr;
    bool store_numbering = true;
    // Chunks (docs/FORMAT.md 3.11): the forest cut into runs of roots, each decodable on its own,
    // coded and decoded on several threads. 0: one chunk per `chunk_faces` faces of the leaf mesh
    // (at least one), and fewer when that code holds less than `min_chunk_bytes` per chunk and one
    // chunk per min_chunk_bytes removes a quarter of them or more (it is then coded again in that
    // many; 0: never): each chunk costs some bytes of its own, which weigh about 1 % in a chunk of
    // 64 KiB, and coding again doubles the forest's encode time (docs/CODEC.md, "Chunks"). A file of one
    // chunk is written as before chunks existed (version 6 or lower, byte for byte); more chunks
    // make a version-7 file.
    uint32_t chunks = 0;
    uint64_t chunk_faces = 500000;
    uint64_t min_chunk_bytes = 65536;
    // Explicit chunks instead: the number of roots of each chunk, in file order (the input's own
    // order with keep_base_order), adding up to the root count; `chunks` and `chunk_faces` are then
    // ignored. One entry writes a file without chunks. A file written by MPI ranks (amc/mpi.h) is
    // the serial encoder's with the ranks' root counts here and keep_base_order.
    std::vector<uint32_t> chunk_roots;
    // The base mesh kept in the input's vertex and triangle order (the base connectivity's explicit
    // mode, docs/FORMAT.md 4.8) instead of the base coder's: root t of the decoded file is root t
    // of the input, so chunks are runs of the caller's roots. Costs about 3 log2(V) bits per base
    // triangle where the base coder needs 1-2 bits per vertex (docs/MPI.md).
    bool keep_base_order = false;
    // Threads that code chunks, or at efforts 3 and 4 the base orders' files, at once; 0: every
    // core. The bytes do not depend on it.
    unsigned threads = 0;
    // Fill EncodeStats::hierarchy (the hierarchy coder's own statistics, for files of one chunk):
    // the coded symbols are replayed through the models, about 4 % of a default encode and the
    // whole model again in the mixing mode, so only when asked for. The bytes do not depend on it.
    bool hierarchy_statistics = false;
};

struct LevelStats {
    uint64_t nodes = 0;          // nodes of this level
    uint64_t new_vertices = 0;   // vertices its refinement creates
    uint64_t bytes = 0;          // size of the level block
    GeometryPredictor predictor = GeometryPredictor::midpoint;
};

struct EncodeStats {
    uint64_t total_bytes = 0;
    uint64_t header_bytes = 0;              // file header and metadata block
    uint64_t base_connectivity_bytes = 0;
    uint64_t base_geometry_bytes = 0;
    uint64_t hierarchy_bytes = 0;           // refinement symbols and orientation bits, all levels
    uint64_t geometry_bytes = 0;            // positions of refinement vertices, all levels
    uint64_t framing_bytes = 0;             // block headers and checksums
    uint64_t numbering_bytes = 0;           // the numbering block's payload (0 without one)
    uint64_t faces = 0, vertices = 0, nodes = 0, base_vertices = 0, base_triangles = 0;
    int levels = 0;
    double max_error = 0;                   // largest coordinate error (0 unless quantized)
    std::vector<LevelStats> per_level;
    HierarchyCodeStats hierarchy;           // the hierarchy coder's own statistics (EncodeOptions::hierarchy_statistics)
    // EncodeOptions::numbering against extract_leaf_mesh of the decoded hierarchy (empty without
    // one): the map a caller keeps when the file does not store it.
    LeafNumbering numbering;
};

// Compresses `h`. The decoder rebuilds it over the base mesh in the base coder's order (vertices
// and triangles renumbered, each triangle's vertices possibly rotated; see reorder_base), so the
// result is identical to reorder_base(h, ...) of the input — same elements, same positions.
std::vector<uint8_t> encode(const Hierarchy& h, const EncodeOptions& options = {}, EncodeStats* stats = nullptr);

// Working memory that encodes through it keep for the next one, as zstd's ZSTD_CCtx: the hierarchy
// coder's first pass (its level forest and per-level lists) and the static geometry modes'
// buffers, kept after the encode returns until release() or the context's end, so that the next
// encode neither allocates them nor has the system fault their pages in again (docs/BENCHMARKS.md,
// "One-core encode, nineteenth step"); for a chunked file, one such memory for each thread that
// coded chunks (a worker thread's memory is otherwise fresh at every encode: "Threads and memory").
// encode() without a context keeps nothing. A context serves one encode at a time; the bytes are
// those of encode() without it.
class EncodeContext {
public:
    EncodeContext();
    ~EncodeContext();
    EncodeContext(EncodeContext&&) noexcept;
    EncodeContext& operator=(EncodeContext&&) noexcept;
    EncodeContext(const EncodeContext&) = delete;
    EncodeContext& operator=(const EncodeContext&) = delete;
    void release();  // frees the kept memory (the next encode allocates it again)

private:
    struct Kept;
    std::unique_ptr<Kept> kept_;
    friend std::vector<uint8_t> encode(EncodeContext&, const Hierarchy&, const EncodeOptions&, EncodeStats*);
};
std::vector<uint8_t> encode(EncodeContext& context, const Hierarchy& h, const EncodeOptions& options = {},
                            EncodeStats* stats = nullptr);

// `h` as decode(encode(h, options)) returns it: over the base mesh in the base coder's order
// (cheap: codes the base connectivity only), with the input's positions. The order depends on the
// base positions the decoder sees, so pass the options of the encoding (only quantize_bits
// matters, and efforts 3 and 4, whose order is their search's: then it codes the whole file).
// identical(decode(encode(h)), in_decoder_order(h)) holds for every bit-exact encoding.
Hierarchy in_decoder_order(const Hierarchy& h, const EncodeOptions& options = {});

struct DecodeOptions {
    int max_level = -1;                  // stop after this level: the mesh of that level
    uint64_t max_nodes = 1ull << 26;     // refuse files that would build more nodes than this
    unsigned threads = 0;                // threads that decode chunks at once; 0: every core
    // Give working memory back to the system as soon as no later step reads it, over the last
    // levels, for a lower peak (`amc decode` sets it: one decode a process). Same result; a
    // process that decodes again faults those pages in again, several times slower on files of
    // 10^5 faces (docs/BENCHMARKS.md, "Decode peak memory at corpus size").
    bool lean_memory = false;
};

// Throws Error naming the problem (bad magic, newer version, checksum, structure) on a corrupt or
// truncated file, with its kind in Error::code(); never crashes or hangs. Memory and time grow at
// most linearly with `size`, and the hierarchy is bounded by options.max_nodes besides: every
// count is checked against the bytes that can hold it before anything is allocated for it.
// When the file stores a numbering and `numbering` is not null, it receives it (relative to
// extract_leaf_mesh of the result); it is left empty otherwise, and always when max_level cuts
// the decoding short (a numbering describes the whole leaf mesh).
Hierarchy decode(const uint8_t* data, size_t size, const DecodeOptions& options = {},
                 LeafNumbering* numbering = nullptr);

// Working memory that decodes through it keep for the next one, as zstd's ZSTD_DCtx: the chunk
// decoders of every thread a decode of a chunked file used (about 15 bytes a node of the largest
// chunk each), kept after the decode returns until release() or the context's end, so that the
// next decode does not allocate and fault them in again (a new worker thread's memory is fresh
// at every decode). decode() without a context keeps nothing. A context serves one decode at a
// time; the results are those of decode() without it.
class DecodeContext {
public:
    DecodeContext();
    ~DecodeContext();
    DecodeContext(DecodeContext&&) noexcept;
    DecodeContext& operator=(DecodeContext&&) noexcept;
    DecodeContext(const DecodeContext&) = delete;
    DecodeContext& operator=(const DecodeContext&) = delete;
    void release();  // frees the kept memory (the next decode allocates it again)
    // Gives back a hierarchy the caller is done with (an earlier result, say): the next decode of
    // a chunked file through the context builds its result in that memory, already resident,
    // instead of having fresh pages faulted in and zeroed by the system. Kept until then.
    void recycle(Hierarchy&& done);

private:
    struct Kept;
    std::unique_ptr<Kept> kept_;
    friend Hierarchy decode(DecodeContext&, const uint8_t*, size_t, const DecodeOptions&, LeafNumbering*);
};
Hierarchy decode(DecodeContext& context, const uint8_t* data, size_t size, const DecodeOptions& options = {},
                 LeafNumbering* numbering = nullptr);

// decode() without a context and without exceptions, for callers that prefer status values.
struct DecodeResult {
    bool ok = false;
    ErrorCode code = ErrorCode::invalid_input;  // when !ok: the kind of problem
    std::string error;                          // when !ok: the message decode would throw
    Hierarchy hierarchy;
    LeafNumbering numbering;  // the stored numbering, if any (see decode)
};
DecodeResult try_decode(const uint8_t* data, size_t size, const DecodeOptions& options = {}) noexcept;

// A file that is still arriving: the bytes so far, cut anywhere after the base mesh's blocks.
// Complete blocks are checked as decode checks them; the block being received is ignored.
struct PartialDecode {
    Hierarchy hierarchy;      // levels 0 .. level, as decode with max_level = level returns it
    int level = 0;            // the finest level whose nodes are all known
    int levels = 0;           // the file's level count, from its metadata
    bool complete = false;    // every level block arrived: the whole hierarchy (level = levels - 1)
    LeafNumbering numbering;  // the stored numbering, once complete and its block arrived
};
// Throws Error (ErrorCode::truncated) when the prefix ends before the base mesh is complete, and
// like decode on anything corrupt in the complete blocks.
PartialDecode decode_partial(const uint8_t* data, size_t size, const DecodeOptions& options = {});

// What `amc info` prints: the blocks of a file with their sizes, without decoding the payloads.
struct FileBlock {
    uint8_t type = 0;
    std::string name;
    uint64_t offset = 0, size = 0;  // the whole block: header, payload, checksum
    int level = -1;                 // for level blocks
};
// A chunk of a chunked file (version 7): its roots, nodes and block.
struct ChunkInfo {
    uint32_t first_root = 0, roots = 0;
    uint64_t nodes = 0;
    uint64_t offset = 0, size = 0;  // the chunk block: header, payload, checksum
};
struct FileInfo {
    int version = 0;
    std::vector<ChunkInfo> chunks;  // empty for a file without chunks (it decodes as one)
    bool single_precision = false;
    int quantize_bits = 0;
    uint64_t base_vertices = 0, base_triangles = 0, nodes = 0, vertices = 0, faces = 0;
    int levels = 0;
    std::vector<FileBlock> blocks;
};
FileInfo inspect(const uint8_t* data, size_t size);  // throws Error like decode

// Some chunks of a file alone: the hierarchy over the selected chunks' roots (their forests,
// positions and diagonals; edges towards other chunks are boundary edges here, so a leaf there has
// no hanging node from the other side). The base mesh is the selected roots' triangles in file
// order over the base vertices they use, in file order.
struct ChunkDecode {
    Hierarchy hierarchy;
    std::vector<uint32_t> roots;          // root i of the result is root roots[i] of the whole file
    std::vector<uint32_t> base_vertices;  // base vertex i of the result is base vertex base_vertices[i]
};
// `chunks`: indices into inspect(...).chunks, increasing. A file without chunks has one, chunk 0.
// Reads the header, the base mesh, the chunk table and the seam, then only the selected chunks'
// blocks. Throws Error like decode, and ErrorCode::invalid_input for a chunk not in the file.
ChunkDecode decode_chunks(const uint8_t* data, size_t size, const std::vector<uint32_t>& chunks,
                          const DecodeOptions& options = {});
// The chunks (increasing) that hold the given roots (base triangles of the file, in decoder order).
std::vector<uint32_t> chunks_covering(const FileInfo& info, const std::vector<uint32_t>& base_triangles);

}  // namespace amc
