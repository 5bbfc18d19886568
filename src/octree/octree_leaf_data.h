// Per-leaf data of an octree forest (docs/FORMAT.md section 8.6): one "leaf field" block per
// field, its values coded bit-exact against the value of the leaf before it in p4est's order.
#pragma once

#include <amc/octree.h>

#include <cstdint>
#include <string>
#include <vector>

namespace amc {

class PayloadReader;

// Names unique, 1 .. kMaxFieldNameBytes bytes; cell association; 1 .. kMaxFieldComponents
// components; one tuple per leaf; integers in their type's range; Float32 values floats.
// Throws Error (invalid_input) naming `what` and the field.
void validate_leaf_fields(const std::vector<Field>& fields, uint64_t leaves, const std::string& what);

// The payload of a leaf field block for a forest with these leaves (validated fields only).
std::vector<uint8_t> write_leaf_field(const Field& field, const std::vector<Octant>& leaves);
// Reads one leaf field block; refuses more than max_values values (limit_exceeded) before
// allocating. Throws Error (corrupt, truncated) naming the field.
Field read_leaf_field(const uint8_t* data, size_t size, const std::vector<Octant>& leaves, uint64_t max_values);

// The start of a leaf field block (name, type, components), which the forest series' temporal
// block shares (docs/FORMAT.md 7.12).
void write_leaf_field_head(const Field& field, std::vector<uint8_t>& out);
// Reads it; `block` names the block in messages. Throws Error (corrupt, truncated).
Field read_leaf_field_head(PayloadReader& in, const std::string& block);
// Sizes the field for `tuples` tuples after checking their values against max_values
// (limit_exceeded) and against what `bytes_left` can hold (corrupt).
void size_leaf_field(Field& field, uint64_t tuples, uint64_t max_values, uint64_t bytes_left);
// "leaf field \"name\"", as messages name a field.
std::string field_what(const std::string& name);

// Bytes one value of the type takes (1, 2, 4 or 8).
size_t field_type_bytes(FieldType type);

}  // namespace amc
