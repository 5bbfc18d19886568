// Field values as the field coders see them (series fields, forest and octree leaf data): each
// value an N-bit word whose differences are coded — integers as themselves (N = 64), floats as
// their ordered bits (float_coder.h; N = 32 or 64) — and integers checked against their type.
#pragma once

#include <amc/field.h>

#include "coding/geometry/float_coder.h"

#include <cstddef>
#include <cstdint>

namespace amc {

// Whether `value` fits the integer type `type` (int64 and uint64: any bit pattern).
bool integer_in_range(int64_t value, FieldType type);

Precision precision_of(FieldType float_type);
int word_bits(FieldType type);
uint64_t word_mask(FieldType type);
// Value `k` of `field` as a word.
uint64_t word_of(const Field& field, size_t k);

}  // namespace amc
