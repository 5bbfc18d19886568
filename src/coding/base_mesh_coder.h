// Single-rate connectivity coder of the base mesh (paper II-B: "the base mesh is coded by a
// single-rate coder"). The refinement hierarchy is coded relative to the base mesh, so the base
// mesh only needs its triangles; positions are coded separately with the parallelogram stencils
// this coder reports.
//
// Scheme: a cut-border machine (Gumhold–Straßer; Edgebreaker-like "C/L/R/E/S" plus "M" merge ops)
// over a CLOSED, manifold version of the mesh, with every symbol coded by the adaptive binary
// arithmetic coder of arithmetic_coder.h.
//  * Non-manifold vertices (several triangle fans touching at one vertex) are split into one
//    vertex per fan; the decoder merges them back with an explicit copy list.
//  * Every boundary loop is closed by a dummy vertex and a fan of dummy triangles; dummy vertices
//    are flagged when created and dropped, with their triangles, by the decoder.
//  * Each connected component starts with one triangle (three new vertices) and is conquered
//    from a stack of border loops. The gate is the border edge (u, v) after the focus vertex u;
//    the triangle beyond it has tip w and is one of
//      C  w is new                       (gate stays at u: the fan of u is walked)
//      R  w is the border vertex before u (u is finished; the gate moves to the border vertex
//         with the most decoded triangles, CutBorder::choose_gate)
//      L  w is the border vertex after v
//      E  the loop has three vertices and is closed
//      S  w is elsewhere on the current loop: split (offset: adaptive side bit and gamma length,
//         raw mantissa)
//      M  w is on another loop of the stack: merge (loop index and offset, raw bits; one per
//         handle, so the number of M ops is the genus)
//    The C and R/L decisions are coded with contexts from the number of triangles already
//    decoded around u (and v), which makes them close to a valence code.
//  * If anything about the mesh defeats the scheme (or the encoder's self-check by decoding
//    fails), the encoder falls back to an explicit list of triangles (mode 1). It never fails on
//    a mesh with indices in range.
//
// Stream (whole-buffer: the decoder must be given exactly the bytes of `BaseMeshCode::bytes`;
// the container stores the length). All of it is one arithmetic-coded stream:
//   2 raw bits mode (0 = cut-border, 1 = explicit, 2-3 reserved: rejected).
//   Mode 0: counts, each Elias-gamma of (x + 1) in raw bits: vertex count V, isolated vertices I
//     (appended at the end of the vertex order), dummy vertices D, vertex copies K, components C,
//     merges M. The closed mesh has Vc = V - I + D + K vertices and Fc = 2 Vc - 4 C + 4 M
//     triangles. Then per component the start triangle and the ops (C: one adaptive dummy flag
//     when D > 0), then K pairs (copy, target) of closed vertex indices in raw bits.
//   Mode 1: V and F (gamma), then 3 F vertex indices of bit_length(V - 1) raw bits.
// The decoder validates every count and index, bounds every loop by the counts, and throws
// amc::Error on anything inconsistent or on a truncated stream.
#pragma once

#include <amc/mesh.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace amc {

// Parallelogram stencil (a, b, c) of a vertex: predict a + b - c from vertices decoded earlier.
// (a, -1, -1) means "predict a"; (-1, -1, -1) means no prediction.
using BaseStencil = std::array<int32_t, 3>;

struct BaseMeshCode {
    std::vector<uint8_t> bytes;              // whole-buffer stream (see above)
    std::vector<uint32_t> vertex_order;      // decoder vertex i = original vertex vertex_order[i]
    std::vector<uint32_t> triangle_order;    // decoder triangle t = original triangle_order[t]
    std::vector<uint8_t> triangle_rotation;  // decoder triangle t = (o[r], o[r+1], o[r+2]) of
                                             // original triangle o, r = rotation
    std::vector<BaseStencil> stencils;       // per decoder vertex, as the decoder reports them
};

// Codes the connectivity of `mesh` (positions unused). Throws Error only when a triangle's
// index is out of range.
BaseMeshCode encode_base_connectivity(const TriangleMesh& mesh);

struct DecodedBaseConnectivity {
    uint32_t vertex_count = 0;
    std::vector<Triangle> triangles;    // in decoder order, same orientation as the original
    std::vector<BaseStencil> stencils;  // per decoder vertex, entries decoded earlier or -1
};

// Decodes a stream of encode_base_connectivity; refuses more than `max_vertices` vertices.
// Throws Error on corrupt or truncated input. The stream bounds its triangles, but isolated
// vertices cost it no bits: the caller bounds them with `max_vertices` (the .amc decoder by the
// base geometry block, where every vertex costs at least 15 symbols).
DecodedBaseConnectivity decode_base_connectivity(const uint8_t* data, size_t size,
                                                 uint32_t max_vertices);

}  // namespace amc
