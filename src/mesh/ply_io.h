// Stanford PLY: ASCII, binary little- and big-endian; a "vertex" element with x, y, z and a
// "face" element with a vertex_indices (or vertex_index) list; other properties and elements
// are skipped.
#pragma once

#include <string>
#include <string_view>

#include "amc/mesh.h"
#include "amc/mesh_io.h"

namespace amc {

// Parses PLY bytes; `what` names the source in messages. Faces must have exactly 3 vertices.
// Element counts are checked against the data size before anything is allocated. Throws Error.
TriangleMesh parse_ply(std::string_view bytes, const std::string& what);

// PLY with float x, y, z when mesh.single_precision, double otherwise, and faces as
// "list uchar int vertex_indices". Binary (little-endian) files hold nothing else: meshio 5 cannot
// read a binary face element with more properties, nor a file with more elements. ASCII files add
// "uchar level" and "uchar green" face properties for the non-empty arrays of `cells` (their sizes
// must equal the triangle count), which meshio reads as cell data.
std::string format_ply(const TriangleMesh& mesh, const CellData* cells = nullptr,
                       MeshEncoding encoding = MeshEncoding::binary);

}  // namespace amc
