// VTK XML UnstructuredGrid (.vtu) reader: the structure from the XML, then every DataArray
// decoded (ascii, inline base64, appended raw or base64; zlib blocks or plain; UInt32 or UInt64
// headers; either byte order) with every count, offset and size checked before it is used.
#pragma once

#include <string>
#include <string_view>

#include "amc/mesh_io.h"

namespace amc {

// Parses the bytes of a .vtu file; `what` names the source in messages. Only triangles (and
// polygons of 3 points) are read; several Pieces are concatenated. Does not validate the mesh
// (read_vtu does). zlib blocks inflate on up to `threads` threads (0: every core; the result and
// errors do not depend on it). Throws Error.
VtuMesh parse_vtu(std::string_view bytes, const std::string& what, unsigned threads = 0);

}  // namespace amc
