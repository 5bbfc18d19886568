// Solution data on a hierarchy's leaf mesh: named per-vertex and per-cell arrays, as VTU point
// and cell data hold them (docs/SERIES.md).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace amc {

// Frozen values: written to series files.
enum class FieldAssociation : uint8_t {
    point = 0,  // one tuple per vertex of the leaf mesh, in canonical vertex order
    cell = 1,   // one tuple per triangle of the leaf mesh, in extract_leaf_mesh's order
};

// The value types of a field, in the order of VTK's DataArray types (frozen: written to files).
enum class FieldType : uint8_t { int8, uint8, int16, uint16, int32, uint32, int64, uint64, float32, float64 };

bool is_float_type(FieldType type);
const char* field_type_name(FieldType type);  // "Float64", "Int32", ... (VTK's names)

// `components` values per point (or cell), tuple after tuple. Float fields keep their values in
// `values` (float32 values exactly representable as float); integer fields in `integers` (uint64
// values above 2^63 - 1 as their two's complement bit pattern).
struct Field {
    std::string name;
    FieldAssociation association = FieldAssociation::point;
    FieldType type = FieldType::float64;
    uint32_t components = 1;
    std::vector<double> values;
    std::vector<int64_t> integers;

    size_t value_count() const { return is_float_type(type) ? values.size() : integers.size(); }
    size_t tuple_count() const { return components == 0 ? 0 : value_count() / components; }
};

// Same name, association, type, components and values (bit for bit, NaN payloads included).
bool identical(const Field& a, const Field& b);

// Largest |a - b| over the values of two float fields of the same shape (0 for integers, which are
// always exact; infinity when the shapes differ).
double max_abs_difference(const Field& a, const Field& b);

}  // namespace amc
