// What VTK calls things: DataArray value type names ("Float32") and cell type numbers
// (5 = triangle). The one place the VTU reader, the writer and their messages look them up.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "amc/mesh.h"

namespace amc {

// VTK writes the host's byte order and says which; we do the same.
constexpr bool kHostBigEndian = __BYTE_ORDER__ == __ORDER_BIG_ENDIAN__;

constexpr int64_t kVtkTriangle = 5;
constexpr int64_t kVtkPolygon = 7;

// "Int8" ... "Float64", as the DataArray type attribute spells them.
std::string_view vtk_type_name(ValueType type);
// The value type named by a DataArray type attribute; false for names we do not read
// ("String", "Bit", "Float16", ...).
bool parse_vtk_type_name(std::string_view name, ValueType& type);
// Bytes per value.
std::size_t value_size(ValueType type);
bool is_integer(ValueType type);

// "a quad (VTK type 9)", "a cell of VTK type 77": for messages about refused cells.
std::string describe_vtk_cell_type(int64_t type);

}  // namespace amc
