// Stanford PLY: ASCII, binary little- and big-endian; a "vertex" element with x, y, z and a
// "face" element with a vertex_indices (or vertex_index) list; other properties and elements
// are skipped.
#pragma once

#include <string>
#include <string_view>

#include "amc/mesh.h"

namespace amc {

// Parses PLY bytes; `what` names the source in messages. Faces must have exactly 3 vertices.
// Element counts are checked against the data size before anything is allocated. Throws Error.
TriangleMesh parse_ply(std::string_view bytes, const std::string& what);

// Binary little-endian PLY: float x, y, z when mesh.single_precision, double otherwise; faces as
// "list uchar int vertex_indices", plus "uchar level" and "uchar green" face properties for the
// non-empty arrays of `cells` (their sizes must equal the triangle count).
std::string format_ply(const TriangleMesh& mesh, const CellData* cells = nullptr);

}  // namespace amc
