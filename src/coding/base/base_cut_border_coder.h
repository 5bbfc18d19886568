// Mode 0 of the base connectivity stream: the cut-border coder of format versions 1 and 2 (a
// Gumhold–Straßer cut-border machine with Edgebreaker-like C/R/L/E/S ops and M merges, ops
// coded with contexts from the number of triangles decoded around the gate's vertices; FORMAT.md
// 4.3-4.7). The writer takes it only where modes 2 and 3 do not fit (it needs no positions);
// earlier files decode with it. The cut border itself: base_cut_border.h.
#pragma once

#include "coding/entropy/arithmetic_coder.h"
#include "coding/base/base_mesh_coder.h"

#include <amc/mesh.h>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace amc {

// The whole stream, mode bits included; fills the code's orders. Throws EncoderGaveUp when the
// mesh does not fit the mode.
std::vector<uint8_t> encode_cut_border(const TriangleMesh& mesh, BaseMeshCode& code);

// Decodes the rest of a mode-0 stream (after the two mode bits) of `size` bytes: connectivity
// and stencils, no positions. Throws Error.
DecodedBaseMesh decode_cut_border(ArithmeticDecoder& dec, size_t size, uint32_t vertex_count, uint32_t max_isolated);

}  // namespace amc
