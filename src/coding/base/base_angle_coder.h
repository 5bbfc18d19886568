// Mode 2 of the base connectivity stream: the angle-guided cut-border coder (FORMAT.md 4.10-4.16;
// the design and its measurements: docs/BASE_CODER.md).
//
// A cut-border conquest (Gumhold–Straßer, Edgebreaker's C/R/L/E/S ops and M merges) over the
// closed, manifold version of the mesh (base_mesh_closing.h). Positions are decoded as vertices
// are created (the parallelogram of the gate's triangle predicts them), so every op can be
// predicted from the geometry already known, as in Lee, Alliez and Desbrun's Angle-Analyzer:
//  * "the tip is the vertex before u" (R) and "the vertex after v" (L) are coded with the class
//    of the angle the closing triangle would have at u (at v) and the triangles already decoded
//    around it;
//  * after R the gate moves to the nearby border vertex with the smallest convex gap, the one most
//    likely to close next (Alliez–Desbrun's rule of conquering the vertex with the fewest free
//    edges first, with the angle standing in for the unknown valence), which keeps splits rare;
//  * a split's tip is most often the border vertex nearest to where a new vertex would be
//    predicted: one bit says so.
#pragma once

#include "coding/entropy/arithmetic_coder.h"
#include "coding/base/base_mesh_coder.h"

#include <amc/mesh.h>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace amc {

// Mode 3 is mode 2 with a split's predicted tip looked for only this many candidates from either
// end of the loop (FORMAT.md 4.17), so that its walk stays linear on meshes of long loops.
constexpr uint32_t kTipWindow = 8;
constexpr uint32_t tip_window_of(BaseConnectivityMode mode) {
    return mode == BaseConnectivityMode::angle_windowed ? kTipWindow : 0;
}

// The whole stream of `mode` (2 or 3), mode bits included; fills the code's orders. With `search`,
// the shortest of several start triangles and gate radii (FORMAT.md 4.16), as many as
// `search_budget` (triangles coded in all) allows, tried on up to `threads` threads (the result
// does not depend on them), else version 4's single try. Throws EncoderGaveUp when the mesh does
// not fit the mode.
std::vector<uint8_t> encode_angle_mode(const TriangleMesh& mesh, BaseMeshCode& code, BaseConnectivityMode mode,
                                       bool search, unsigned threads, uint64_t search_budget);
// The stream of `mode` from one start (the shortest context set). Throws EncoderGaveUp as above,
// invalid_input when the start is not one of the mesh's.
std::vector<uint8_t> encode_angle_mode(const TriangleMesh& mesh, BaseMeshCode& code, BaseConnectivityMode mode,
                                       const BaseStart& start);

// Decodes the rest of a mode-2 or mode-3 stream (after the two mode bits) of `size` bytes, reading
// the positions from `source` as vertices are created. Throws Error.
DecodedBaseMesh decode_angle_mode(ArithmeticDecoder& dec, size_t size, uint32_t vertex_count,
                                  const BasePositionSource& source, uint32_t max_isolated, BaseConnectivityMode mode);

}  // namespace amc
