// The base mesh made closed and manifold for the cut-border coders (FORMAT.md 4.3, 4.9): one
// vertex per fan of an original vertex (the extra ones are *copies*), and every boundary loop
// closed by a *dummy* vertex with a fan of dummy triangles. Encoder side only.
#pragma once

#include "coding/base/base_mesh_stream.h"

#include <amc/hierarchy.h>  // kNoVertex
#include <amc/mesh.h>

#include <cstdint>
#include <vector>

namespace amc {

struct ClosedMesh {
    std::vector<Triangle> triangles;  // 0 .. real_triangles-1 are the input's, same rotation
    std::vector<uint32_t> original;   // per closed vertex: input vertex, or kNoVertex for dummies
    std::vector<uint32_t> twin;       // per halfedge 3 t + k (corner k to k + 1): the opposite one
    uint32_t real_triangles = 0;
    uint32_t dummies = 0;

    uint32_t corner_vertex(uint32_t halfedge) const { return triangles[halfedge / 3][halfedge % 3]; }
    static uint32_t next_halfedge(uint32_t h) { return h / 3 * 3 + (h % 3 + 1) % 3; }
    static uint32_t prev_halfedge(uint32_t h) { return h / 3 * 3 + (h % 3 + 2) % 3; }
};

// Throws EncoderGaveUp when the mesh is not edge-manifold and consistently oriented.
ClosedMesh make_closed(const TriangleMesh& mesh);

}  // namespace amc
