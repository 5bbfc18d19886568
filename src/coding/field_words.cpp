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

bool set_word(Field& field, size_t k, uint64_t w) {
    if (is_float_type(field.type)) {
        field.values[k] = from_ordered_bits(w, precision_of(field.type));
        return true;
    }
    field.integers[k] = int64_t(w);
    return integer_in_range(field.integers[k], field.type);
}

void encode_word(ArithmeticEncoder& encoder, FloatResidualModels::Context& context, FieldType type, uint64_t word,
                 uint64_t predicted) {
    const uint64_t mask = word_mask(type);
    const uint64_t d = (word - predicted) & mask;
    const bool negative = (d >> (word_bits(type) - 1)) & 1;
    encode_signed_residual(encoder, context, negative, negative ? (~d + 1) & mask : d);
}

uint64_t decode_word(ArithmeticDecoder& decoder, FloatResidualModels& models, FloatResidualModels::Context& context,
                     FieldType type, uint64_t predicted) {
    bool negative;
    uint64_t magnitude;
    decode_signed_residual(decoder, models, context, negative, magnitude);
    return (negative ? predicted - magnitude : predicted + magnitude) & word_mask(type);
}

}  // namespace amc
