// Positions of a series frame (docs/FORMAT.md, section 7.6): vertices that persist from the
// previous frame keep their positions (static mesh) or are predicted by them (moving mesh); new
// vertices are predicted from their edge on the coarser level (midpoint or butterfly, chosen per
// level), as in the .amc file.
#pragma once

#include "series/frame_state.h"

#include <amc/mesh.h>

#include <cstdint>
#include <vector>

namespace amc {

// Mode 2 (series version 2): static, and every new vertex exactly at its edge's midpoint (the
// section is this one byte).
enum class FrameGeometryMode : uint8_t { static_mesh = 0, moving = 1, at_midpoints = 2 };

// `positions` in canonical order (order[i] is canonical vertex i). Sets them in `out` and returns
// the section's bytes in the given series version.
std::vector<uint8_t> encode_frame_geometry(const Hierarchy& prev, const std::vector<FrameVertex>& order,
                                           const std::vector<Vec3>& positions, int version, Hierarchy& out,
                                           FrameGeometryMode* mode = nullptr);
// Throws Error (corrupt, truncated) naming `what`.
void decode_frame_geometry(const Hierarchy& prev, const std::vector<FrameVertex>& order, const uint8_t* data,
                           size_t size, int version, Hierarchy& out);

}  // namespace amc
