// One DataArray of a VTU file decoded (ascii, inline base64, appended raw or base64; zlib blocks
// or plain; UInt32 or UInt64 headers; either byte order), its declared sizes checked against the
// bytes that are really there before anything is allocated.
#pragma once

#include "mesh/vtu_layout.h"

#include <amc/mesh_io.h>

#include <cstdint>
#include <string>

namespace amc::vtu {

// Names one array in messages: "Points", "Cells array 'types'", "point data 'u'".
std::string describe(const ArrayElement& a, const std::string& piece);

// The array's values, which must be `tuples` tuples of its components. `piece` prefixes
// messages ("piece 2: " or ""), `what` names the file. zlib blocks inflate on up to `threads`
// threads (0: every core; the values and errors do not depend on it). Throws Error.
DataArray decode_array(const Layout& layout, const ArrayElement& a, uint64_t tuples, const std::string& piece,
                       const std::string& what, unsigned threads);

}  // namespace amc::vtu
