// The base mesh in the .amc file (docs/FORMAT.md 3.4, 3.5; paper II-B): the encoder codes the base
// connectivity first and expresses the whole hierarchy in the decoder's base order; the base
// connectivity block and the base geometry block (root rotations, then the base positions
// predicted by the parallelogram rule as the connectivity decoder creates the vertices).
#pragma once

#include "coding/base/base_mesh_coder.h"
#include "coding/container.h"
#include "coding/file_metadata.h"
#include "coding/geometry/position_coder.h"

#include <amc/codec.h>
#include <amc/hierarchy.h>
#include <amc/hierarchy_coder.h>

#include <vector>

namespace amc {

// Triangles mode 2's search may code for the base of `h` (FORMAT.md 4.16).
uint64_t base_search_budget(const Hierarchy& h);

// The base connectivity code of the input (positions as the decoder reconstructs them: on the
// grid when `quantizer` is set).
BaseMeshCode base_code_of(const Hierarchy& h, const Quantizer* quantizer, const EncodeOptions& options);

// Other orders of the base of `h` (EncodeOptions::effort 3): mode 2's codes from `count` start
// triangles spread over it (its first corner, gate radius 5), those whose order differs from
// `own`'s and from each other's, in start order, coded on up to `threads` threads. Quantized files
// pass their grid (`quantizer`).
std::vector<BaseMeshCode> base_order_candidates(const Hierarchy& h, const Quantizer* quantizer, const BaseMeshCode& own,
                                                uint32_t count, unsigned threads = 1);

// The base coder may rotate each triangle's vertices. The default diagonal rule does not care, but
// hierarchies made under a rule of absolute local indices would pay orientation bits: then storing
// each root's rotation (log2 3 bits) to keep the input's local order may be cheaper. Both readings
// are tallied on the input.
struct BaseCodeOrder {
    bool keep_rotations = false;   // the roots keep the input's local vertex order (kOptionRootRotations)
    std::vector<uint8_t> rotation;  // of each triangle in code order: the base coder's, or none when kept
};
BaseCodeOrder base_code_order(const Hierarchy& input, const BaseMeshCode& base_code, unsigned threads = 1);
// The order with the choice made: the rotations kept or the base coder's.
BaseCodeOrder base_code_order(const BaseMeshCode& base_code, bool keep_rotations);
// The choice from the diagonal flags' exceptions as the rotated forest and the input read them:
// whether log2 3 bits a triangle cost less than the orientation bits the rotations add.
bool keeps_rotations(const DiagonalExceptions& rotated, const DiagonalExceptions& unrotated, size_t triangles);

// The input with its base mesh in the base coder's order.
struct ReorderedInput {
    Hierarchy hierarchy;
    bool keep_rotations = false;     // the roots keep the input's local vertex order (kOptionRootRotations)
    std::vector<VertexId> vertex_map;  // input vertex id -> id in hierarchy, when asked for
};
// Reorders on up to `threads` threads (the result does not depend on them).
ReorderedInput in_base_code_order(const Hierarchy& input, const BaseMeshCode& base_code, bool want_vertex_map,
                                  unsigned threads = 1);

// The base geometry block of h (in base code order, positions as the decoder reconstructs them):
// its arithmetic code, and with `raw_side` (bit-exact coordinates) the positions' raw bits apart
// (version 21: RawSideCode::joined() is the block), else in the code (the block is `arithmetic`).
RawSideCode encode_base_geometry(const Hierarchy& h, const BaseMeshCode& base_code, bool keep_rotations, PositionCoder& positions,
                                 bool raw_side);

// The payloads of the base connectivity and base geometry blocks of a file of h coded over
// `base_code` (the roots in the base coder's rotations; a bit-exact file's raw bits apart, as version
// 21's): how an effort-3 encode ranks orders before coding the rest (base_order_search.h).
uint64_t base_blocks_bytes(const Hierarchy& h, const Quantizer* quantizer, const BaseMeshCode& base_code);

// Decodes the base mesh from its two blocks of a file of `file_version`, checked against the
// metadata; the result is a valid triangle mesh. Throws Error on a corrupt or truncated block.
TriangleMesh decode_base(const Block& connectivity, const Block& geometry, const Metadata& meta, uint8_t file_version,
                         bool single_precision, PositionCoder& positions);

}  // namespace amc
