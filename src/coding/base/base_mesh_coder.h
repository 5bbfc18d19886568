// Single-rate coder of the base mesh (paper II-B: "the base mesh is coded by a single-rate
// coder"). The refinement hierarchy is coded relative to the base mesh, which also serves as the
// whole mesh when a plain irregular mesh is coded without refinement.
//
// The stream (FORMAT.md section 4) has modes:
//  * 2, angle-guided cut border (base_angle_coder.h): a cut-border conquest over a closed,
//    manifold version of the mesh whose ops are predicted from the geometry decoded so far — the
//    angle a triangle closing the gap at the gate's vertices would have there — and whose gate
//    moves to the border vertex with the smallest such gap. The decoder therefore reads the base
//    positions (FORMAT.md 3.5) while it decodes the connectivity, vertex by vertex, through a
//    BasePositionSource. This is what the encoder writes.
//  * 1, explicit: a list of triangles. The fallback for anything mode 2 can not code.
//  * 0, cut border with degree contexts (base_cut_border_coder.h): format versions 1 and 2 wrote
//    it; it still decodes.
// Whatever the mode, the decoder also reports one parallelogram stencil per vertex; positions
// are predicted from it (section 3.5) in decoder order.
#pragma once

#include <amc/mesh.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

namespace amc {

// Written to the stream (its first two raw bits): values are frozen.
// angle_windowed (mode 3, files of version 22 on) is `angle` with its split tips looked for near
// the gate only (FORMAT.md 4.17).
enum class BaseConnectivityMode : uint8_t { cut_border = 0, explicit_triangles = 1, angle = 2, angle_windowed = 3 };

// Parallelogram stencil (a, b, c) of a vertex: predict a + b - c from vertices decoded earlier.
// (a, -1, -1) means "predict a"; (-1, -1, -1) means no prediction.
using BaseStencil = std::array<int32_t, 3>;

struct BaseMeshCode {
    std::vector<uint8_t> bytes;              // whole-buffer stream (FORMAT.md section 4)
    std::vector<uint32_t> vertex_order;      // decoder vertex i = original vertex vertex_order[i]
    std::vector<uint32_t> triangle_order;    // decoder triangle t = original triangle_order[t]
    std::vector<uint8_t> triangle_rotation;  // decoder triangle t = (o[r], o[r+1], o[r+2]) of
                                             // original triangle o, r = rotation
    std::vector<BaseStencil> stencils;       // per decoder vertex, as the decoder reports them
    BaseConnectivityMode mode = BaseConnectivityMode::explicit_triangles;
};

// Codes the connectivity of `mesh`. Its positions must be exactly those the decoder will
// reconstruct (quantized ones snapped to the grid): mode 2 predicts from them. Throws Error only
// when a triangle's index is out of range or the mesh is too large for the stream's counts.
// Mode 2's search runs on up to `threads` threads; the code does not depend on them. It codes at
// most `search_budget` triangles in all (the first candidate always), about 0.15 s at the full budget.
constexpr uint64_t kFullBaseSearch = uint64_t{1} << 20;
// The budget that tries one start triangle of a mesh of `triangles` in every rotation and gate
// radius: below five radii' worth the search is the single try.
uint64_t one_start_search_budget(uint64_t triangles);
BaseMeshCode encode_base_connectivity(const TriangleMesh& mesh, unsigned threads = 1,
                                      uint64_t search_budget = kFullBaseSearch);

// The same with one given mode (tests and benchmarks); throws Error when the mesh does not fit
// it (the explicit mode always fits). Without `search`, mode 2 starts at the first input triangle
// with gate radius 5 alone: the stream format version 4's encoder wrote (FORMAT.md 4.16).
BaseMeshCode encode_base_connectivity(const TriangleMesh& mesh, BaseConnectivityMode mode, bool search = true);

// Where mode 2's conquest starts: the input's triangle `first` from its corner `rotation` (0-2),
// with gate radius `radius` (0-7). The decoder reads any start alike (FORMAT.md 4.16); the start
// fixes the decoder's base order, so an encoder may choose it for the rest of the file too
// (EncodeOptions::effort 3).
struct BaseStart {
    uint32_t first = 0, rotation = 0, radius = 5;
};
// Mode 2 from `start` alone; throws Error when the mesh does not fit mode 2 from there.
BaseMeshCode encode_base_connectivity(const TriangleMesh& mesh, const BaseStart& start);

// The decoder's source of base positions: the position of decoder vertex `vertex`, whose
// stencil is `stencil`, given the positions of vertices 0 .. vertex-1 in `decoded`. Called once
// per vertex, in order 0, 1, ...; mode 2 calls it while it decodes the connectivity, the other
// modes after. It may throw to abort the decode.
using BasePositionSource =
    std::function<Vec3(uint32_t vertex, const BaseStencil& stencil, const std::vector<Vec3>& decoded)>;

struct DecodedBaseMesh {
    uint32_t vertex_count = 0;
    std::vector<Triangle> triangles;    // in decoder order, same orientation as the original
    std::vector<BaseStencil> stencils;  // per decoder vertex, entries decoded earlier or -1
    std::vector<Vec3> positions;        // per decoder vertex, from the source
};

// The mode of a stream (its first two raw bits), without decoding it.
BaseConnectivityMode base_connectivity_mode(const uint8_t* data, size_t size);

// Decodes a stream of encode_base_connectivity of a mesh with exactly `vertex_count` vertices.
// Throws Error on corrupt or truncated input; memory and time stay linear in vertex_count and
// the stream's size. The stream bounds its triangles, but isolated vertices (used by no
// triangle) cost it no bits: a stream announcing more than `max_isolated` of them is refused on
// its counts, before anything is sized by them (the .amc decoder passes 0: its base mesh uses
// every vertex).
DecodedBaseMesh decode_base_mesh(const uint8_t* data, size_t size, uint32_t vertex_count,
                                 const BasePositionSource& positions, uint32_t max_isolated = UINT32_MAX);

}  // namespace amc
