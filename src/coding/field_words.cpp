#include "coding/field_words.h"

namespace amc {

bool integer_in_range(int64_t value, FieldType type) {
    switch (type) {
        case FieldType::int8: return value >= INT8_MIN && value <= INT8_MAX;
        case FieldType::uint8: return value >= 0 && value <= UINT8_MAX;
        case FieldType::int16: return value >= INT16_MIN && value <= INT16_MAX;
        case FieldType::uint16: return value >= 0 && value <= UINT16_MAX;
        case FieldType::int32: return value >= INT32_MIN && value <= INT32_MAX;
        case FieldType::uint32: return value >= 0 && value <= int64_t(UINT32_MAX);
        default: return true;
    }
}

Precision precision_of(FieldType float_type) {
    return float_type == FieldType::float32 ? Precision::float32 : Precision::float64;
}

int word_bits(FieldType type) { return type == FieldType::float32 ? 32 : 64; }

uint64_t word_mask(FieldType type) { return word_bits(type) == 32 ? 0xFFFFFFFFull : ~uint64_t{0}; }

uint64_t word_of(const Field& field, size_t k) {
    return is_float_type(field.type) ? ordered_bits(field.values[k], precision_of(field.type)) : uint64_t(field.integers[k]);
}

}  // namespace amc
