// Half-edge adjacency of an edge-manifold, consistently oriented triangle list whose vertex ids are
// drawn from a larger range (the coarser meshes of base detection keep the leaf mesh's vertex ids).
// Half-edge 3t+i runs from triangle t's vertex i to its vertex (i+1)%3.
#pragma once

#include "common/no_index.h"

#include <amc/mesh.h>

#include <cstdint>
#include <memory>
#include <vector>

namespace amc::detail {

constexpr uint32_t kNoHalfEdge = kNoIndex;

class TriangleAdjacency {
public:
    // Linear in triangles + vertex_count: half-edges are grouped by start vertex with a counting
    // sort; a vertex's half-edges are sorted by their end vertex only when they are many.
    TriangleAdjacency(const std::vector<Triangle>& triangles, uint32_t vertex_count);

    // The opposite half-edge, or kNoHalfEdge on the boundary.
    uint32_t twin(uint32_t half_edge) const { return twin_[half_edge]; }
    // The half-edges that start at v: one per triangle around v.
    uint32_t star_size(uint32_t v) const { return out_start_[v + 1] - out_start_[v]; }
    const uint32_t* outgoing_begin(uint32_t v) const { return out_half_edge_.get() + out_start_[v]; }
    const uint32_t* outgoing_end(uint32_t v) const { return out_half_edge_.get() + out_start_[v + 1]; }
    // Their end vertices, in no particular order: every neighbour of v but, on the boundary, the
    // one before v.
    const uint32_t* ends_begin(uint32_t v) const { return out_end_.get() + out_start_[v]; }
    const uint32_t* ends_end(uint32_t v) const { return out_end_.get() + out_start_[v + 1]; }
    bool on_boundary(uint32_t v) const { return boundary_[v] != 0; }
    // Whether some triangle has the edge a-b (in either direction).
    // (Around an inner vertex every neighbour is the end of an outgoing half-edge.)
    bool has_edge(uint32_t a, uint32_t b) const {
        return find(a, b) != kNoHalfEdge || (boundary_[a] && find(b, a) != kNoHalfEdge);
    }

private:
    static constexpr uint32_t kScanned = 16;  // half-edges of a vertex that find scans (more: sorted)
    uint32_t find(uint32_t from, uint32_t to) const;  // the half-edge from -> to, or kNoHalfEdge

    std::vector<uint32_t> twin_;
    std::vector<uint32_t> out_start_;      // half-edges by start vertex: [out_start_[v], out_start_[v+1])
    // Their end vertices (ascending for more than kScanned) and ids; every entry is written by the
    // counting sort, so they are allocated without being zeroed first (a vector would).
    std::unique_ptr<uint32_t[]> out_end_;
    std::unique_ptr<uint32_t[]> out_half_edge_;
    std::vector<uint8_t> boundary_;
};

}  // namespace amc::detail
