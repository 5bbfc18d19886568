// Field values as the field coders see them (series fields, forest and octree leaf data): each
// value an N-bit word whose differences are coded — integers as themselves (N = 64), floats as
// their ordered bits (float_coder.h; N = 32 or 64) — and integers checked against their type.
#pragma once

#include <amc/field.h>

#include "coding/geometry/float_coder.h"

#include <cstddef>
#include <cstdint>

namespace amc {

// Limits every field coder applies (series fields, octree and forest series leaf data).
constexpr size_t kMaxFieldNameBytes = 1024;
constexpr uint32_t kMaxFieldComponents = 1024;

// Whether `value` fits the integer type `type` (int64 and uint64: any bit pattern).
bool integer_in_range(int64_t value, FieldType type);

Precision precision_of(FieldType float_type);
int word_bits(FieldType type);
uint64_t word_mask(FieldType type);
// Value `k` of `field` as a word.
uint64_t word_of(const Field& field, size_t k);
// Sets value `k` of `field` (sized for its type) to word `w`; false for an integer outside its
// type's range.
bool set_word(Field& field, size_t k, uint64_t w);

// A value coded as its word's difference from a predicted word: a signed residual of the type's
// word width (encode_signed_residual).
void encode_word(ArithmeticEncoder& encoder, FloatResidualModels::Context& context, FieldType type, uint64_t word,
                 uint64_t predicted);
uint64_t decode_word(ArithmeticDecoder& decoder, FloatResidualModels& models, FloatResidualModels::Context& context,
                     FieldType type, uint64_t predicted);

}  // namespace amc
