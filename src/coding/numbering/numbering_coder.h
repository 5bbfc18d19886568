// The numbering block of the .amc file (docs/FORMAT.md, section 6): the caller's vertex and face
// numbering of the leaf mesh, coded against the canonical leaf mesh the decoder rebuilds.
#pragma once

#include <amc/numbering.h>

#include <cstdint>
#include <vector>

namespace amc {

// What the encoder chose, and the size of each part (bytes of its code on its own).
struct NumberingCodeStats {
    int vertex_method = 0, face_method = 0, face_reference = 0, rotation_mode = 0;
    size_t vertex_bytes = 0, face_bytes = 0, rotation_bytes = 0;
};

// The block's payload for `numbering` of a leaf mesh with these triangles (in leaf order). The
// encoder tries every reference order and method and keeps the smallest code.
std::vector<uint8_t> encode_numbering(const LeafNumbering& numbering, const std::vector<Triangle>& leaf_triangles,
                                      NumberingCodeStats* stats = nullptr);

// Decodes a payload for the leaf mesh with these triangles and `vertices` vertices. Throws Error
// on a payload that does not fit it (counts, methods, ranks out of range, truncation).
LeafNumbering decode_numbering(const uint8_t* data, size_t size, const std::vector<Triangle>& leaf_triangles,
                               uint32_t vertices);

// The caller's numbering of the input's leaf mesh, re-expressed against the leaf mesh of `h`, the
// input reordered (vertex_map: input vertex id -> id in h): what the encoder stores.
LeafNumbering numbering_after_reorder(const Hierarchy& input, const LeafNumbering& numbering, const Hierarchy& h,
                                      const std::vector<VertexId>& vertex_map);

}  // namespace amc
