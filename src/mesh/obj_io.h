// Wavefront OBJ: "v x y z" and "f i j k" lines (1-based), triangles only.
#pragma once

#include <string>

#include "amc/mesh.h"
#include "amc/mesh_io.h"

namespace amc {

// Parses OBJ text; `what` names the source in messages. Faces must have exactly 3 vertices.
// Does not validate the mesh beyond index ranges (read_mesh does). Throws Error.
TriangleMesh parse_obj(const std::string& text, const std::string& what);

// "v x y z" lines with the shortest decimals that read back bit-exact, then "f i j k" (1-based).
std::string format_obj(const TriangleMesh& mesh);

}  // namespace amc
