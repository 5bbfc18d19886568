// The structure of a VTU file (vtu_reader.h), read in a first pass: its pieces, their arrays and
// where each array's data lies, up to the appended data.
#pragma once

#include "mesh/vtk_types.h"

#include <amc/mesh.h>

#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

namespace amc::vtu {

// Structure no writer produces is `corrupt` unless a call says otherwise: `truncated` for data
// that ends early, `invalid_input` for valid VTK that is not a triangle mesh we read,
// `bad_magic` for files that are not VTK XML, `limit_exceeded` past 32-bit counts.
[[noreturn]] void fail(const std::string& what, const std::string& message, ErrorCode code = ErrorCode::corrupt);

// Point indices and triangle numbers are 32-bit.
constexpr uint64_t kMaxElements = std::numeric_limits<uint32_t>::max();

enum class DataFormat { ascii, binary, appended };
enum class Section { points, cells, point_data, cell_data };

struct ArrayElement {
    std::string name;
    Section section = Section::points;
    ValueType type = ValueType::float64;
    uint64_t components = 1;
    DataFormat format = DataFormat::ascii;
    uint64_t offset = 0;    // appended: where the data starts after the '_'
    std::string_view text;  // ascii and binary: the element's text
    std::size_t line = 0;  // of the DataArray tag, for messages
};

struct PieceElement {
    uint64_t points = 0, cells = 0;
    std::vector<ArrayElement> arrays;
};

struct Layout {
    bool big_endian = false;
    unsigned header_bytes = 4;  // header_type UInt32 (VTK's default) or UInt64
    bool zlib = false;
    std::vector<PieceElement> pieces;
    bool has_appended = false;
    bool appended_base64 = false;
    std::string_view appended;  // from the byte after the '_'
};

// The structure of `bytes`; `what` names the source in messages. Throws Error.
Layout read_layout(std::string_view bytes, const std::string& what);

}  // namespace amc::vtu
