// Field helpers (include/amc/field.h).
#include <amc/field.h>

#include <cmath>
#include <cstring>
#include <limits>

namespace amc {

bool is_float_type(FieldType type) { return type == FieldType::float32 || type == FieldType::float64; }

const char* field_type_name(FieldType type) {
    switch (type) {
        case FieldType::int8: return "Int8";
        case FieldType::uint8: return "UInt8";
        case FieldType::int16: return "Int16";
        case FieldType::uint16: return "UInt16";
        case FieldType::int32: return "Int32";
        case FieldType::uint32: return "UInt32";
        case FieldType::int64: return "Int64";
        case FieldType::uint64: return "UInt64";
        case FieldType::float32: return "Float32";
        case FieldType::float64: return "Float64";
    }
    return "unknown";
}

bool identical(const Field& a, const Field& b) {
    if (a.name != b.name || a.association != b.association || a.type != b.type || a.components != b.components ||
        a.integers != b.integers || a.values.size() != b.values.size())
        return false;
    return a.values.empty() || std::memcmp(a.values.data(), b.values.data(), a.values.size() * sizeof(double)) == 0;
}

double max_abs_difference(const Field& a, const Field& b) {
    if (a.type != b.type || a.components != b.components || a.value_count() != b.value_count())
        return std::numeric_limits<double>::infinity();
    double worst = 0;
    for (size_t i = 0; i < a.values.size(); ++i) worst = std::max(worst, std::fabs(a.values[i] - b.values[i]));
    return worst;
}

}  // namespace amc
