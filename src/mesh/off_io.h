// OFF (Object File Format): "OFF", "nv nf ne", nv vertex lines, nf face lines "3 i j k" (0-based).
#pragma once

#include <string>
#include <string_view>

#include "amc/mesh.h"

namespace amc {

// Parses OFF text; `what` names the source in messages. '#' comments, tabs and extra white
// space are allowed; values after a face's indices (colours) are ignored. Counts are checked
// against the file size before anything is allocated. Throws Error.
TriangleMesh parse_off(std::string_view text, const std::string& what);

// OFF with the shortest decimals that read back bit-exact.
std::string format_off(const TriangleMesh& mesh);

}  // namespace amc
