// The seam of a chunked .amc file (docs/FORMAT.md 3.13): the base edges whose two triangles lie in
// different chunks, and on each, the tree of its dyadic segments that refinement split (on either
// side), with the position of every vertex that splitting created. Stored once, before the chunks,
// so that each chunk decodes alone: a chunk takes the vertices on its edges to other chunks from
// here instead of coding them (no vertex is stored twice), and learns whether a leaf of its own
// carries a hanging node from the other side (the green closure's diagonals).
//
// Vertices are named by *keys*: base vertex v is key v, seam vertex s is key V + s (V base
// vertices). A segment is named by its two end keys, in either order.
#pragma once

#include "coding/geometry/float_coder.h"  // CoordinateSpace
#include "coding/geometry/position_coder.h"  // RawSideCode
#include "common/keyed_hash.h"

#include <amc/hierarchy.h>

#include <cstdint>
#include <utility>
#include <vector>

namespace amc {

// The base edges between chunks, as (triangle, local edge) of the lower-numbered of their two
// triangles, triangles in order, edges 0, 1, 2: the order of the seam block.
std::vector<std::pair<uint32_t, int>> seam_edges(const TriangleMesh& base, const std::vector<uint32_t>& chunk_of_root);

// A split seam segment, as one side of the seam sees it (an MPI rank's roots, amc/mpi.h): seam edge
// `edge` (an index into seam_edges), segment `segment` of its tree numbered as in a binary heap (1:
// the whole edge from its first end, 2s and 2s + 1 the halves of s from that end), and the position
// of the vertex that splitting it created.
struct SeamSplit {
    uint32_t edge = 0;
    uint64_t segment = 1;
    Vec3 position;
};

class Seam {
public:
    static constexpr int32_t kNotSeam = -1;     // the segment lies on no seam edge
    static constexpr int32_t kUnsplit = -2;     // a seam segment that nothing refined

    Seam() = default;
    // The seam of `h` (the encoder's, in decoder base order): `key_of_vertex` receives each vertex
    // id's key (kNoVertex for vertices that are neither base nor seam vertices).
    Seam(const Hierarchy& h, const std::vector<uint32_t>& chunk_of_root, std::vector<uint32_t>& key_of_vertex);
    // The same seam from the splits of every side, in any order (a split made by both sides may be
    // listed twice). Throws Error (invalid_input) when two give one vertex different positions.
    static Seam from_splits(const TriangleMesh& base, const std::vector<uint32_t>& chunk_of_root, std::vector<SeamSplit> splits);
    // The seam block's payload (FORMAT.md 3.13): its arithmetic code, and with `raw_side` (bit-exact
    // coordinates) the positions' raw bits apart (version 21: RawSideCode::joined() is the block),
    // else in the code (the block is `arithmetic`).
    RawSideCode encode(CoordinateSpace space, bool raw_side) const;
    // Reads a seam block, with its raw bits in a side stream when `raw_side` (base_raw_side()).
    // `max_vertices` bounds the seam vertices (the file's refinement vertices); the block's size
    // bounds them too. Throws Error on a corrupt block.
    static Seam decode(const uint8_t* data, size_t size, const TriangleMesh& base, const std::vector<uint32_t>& chunk_of_root,
                       CoordinateSpace space, uint64_t max_vertices, bool raw_side);

    uint32_t base_vertex_count() const { return base_vertices_; }
    uint32_t vertex_count() const { return uint32_t(positions_.size()); }
    Vec3 position(uint32_t s) const { return positions_[s]; }
    const std::vector<Vec3>& positions() const { return positions_; }
    // The seam vertex splitting segment (a, b) (keys), kUnsplit, or kNotSeam.
    int32_t find(uint32_t a, uint32_t b) const { return segments_.find(segment_key(a, b)); }

private:
    // Segment key -> seam vertex or kUnsplit, by open addressing: a lookup reads one or two
    // neighbouring slots, where std::unordered_map's node chains missed the cache on every new
    // vertex a chunk's decoder puts on its boundary.
    class SegmentTable {
    public:
        void set(uint64_t key, int32_t value);
        int32_t find(uint64_t key) const;  // kNotSeam when absent

    private:
        static constexpr uint64_t kEmpty = ~uint64_t{0};  // no segment's key: its two ends differ
        size_t slot_of(uint64_t key) const;
        // Keyed (keyed_hash.h): a file numbers its base vertices as it likes, and the unkeyed
        // Fibonacci hash let a matching's segments share one probe run (docs/FUZZING.md).
        KeyedWordHash hash_;
        std::vector<std::pair<uint64_t, int32_t>> slots_;
        size_t used_ = 0;
    };
    static uint64_t segment_key(uint32_t a, uint32_t b) {
        return a < b ? (uint64_t(a) << 32) | b : (uint64_t(b) << 32) | a;
    }
    uint32_t base_vertices_ = 0;
    std::vector<Vec3> positions_;  // of the seam vertices, in block order
    SegmentTable segments_;
    // The encoder's trees in block order (pre-order): each segment, and its midpoint when split.
    struct Segment {
        bool split;
        uint8_t level;
        Vec3 a, b;  // ends
        uint32_t vertex;  // seam vertex, when split
    };
    std::vector<Segment> trace_;
    bool single_precision_ = false;
};

// The keys of a chunk hierarchy's vertices: base and seam vertices by the seam's keys, others
// kNoVertex. A chunk's coder grows it level by level as vertices are created.
using VertexKeys = std::vector<uint32_t>;

}  // namespace amc
