// Per-leaf data of an octree forest (docs/FORMAT.md section 8.6): one "leaf field" block per
// field, its values coded bit-exact against the value of the leaf before it in p4est's order.
#pragma once

#include <amc/octree.h>

#include <cstdint>
#include <string>
#include <vector>

namespace amc {

// Names unique, 1 .. kMaxLeafFieldName bytes; cell association; 1 .. kMaxLeafFieldComponents
// components; one tuple per leaf; integers in their type's range; Float32 values floats.
// Throws Error (invalid_input) naming `what` and the field.
void validate_leaf_fields(const std::vector<Field>& fields, uint64_t leaves, const std::string& what);

// The payload of a leaf field block for a forest with these leaves (validated fields only).
std::vector<uint8_t> write_leaf_field(const Field& field, const std::vector<Octant>& leaves);
// Reads one leaf field block; refuses more than max_values values (limit_exceeded) before
// allocating. Throws Error (corrupt, truncated) naming the field.
Field read_leaf_field(const uint8_t* data, size_t size, const std::vector<Octant>& leaves, uint64_t max_values);

// Bytes one value of the type takes (1, 2, 4 or 8).
size_t field_type_bytes(FieldType type);

}  // namespace amc
