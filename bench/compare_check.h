// compare_bench: checking a peer's decoded mesh against the leaf mesh it was given. Peers may
// renumber vertices (Draco), reorder faces and rotate a face's vertices (meshoptimizer, Draco),
// split a vertex whose faces form more than one fan into copies (Draco) and move coordinates onto a
// grid (quantized modes); everything else must come back unchanged.
#pragma once

#include <amc/mesh.h>

#include <cstdint>
#include <string>
#include <vector>

namespace amc_bench {

struct MeshCheck {
    bool ok = false;
    std::string problem;           // empty when ok
    double max_error = 0;          // quantized decodes: largest coordinate difference
    uint64_t split_vertices = 0;   // decoded vertices beyond the original count (copies)
};

// Faces as multisets of vertex triples, each in its smallest rotation (orientation kept): equal
// when the decoder only reordered faces or rotated them.
MeshCheck check_same_faces(const std::vector<amc::Triangle>& original, const std::vector<amc::Triangle>& decoded);

// A lossless decode with its own vertex numbering: faces compared as multisets of position triples
// (bit-identical coordinates), each in its smallest rotation, orientation kept;
// every decoded position must be an input position, and there may be more decoded vertices than
// input vertices only by copies. Position triples, not a vertex map, because remeshed inputs can
// hold two vertices at one position (a projected midpoint landing on an input vertex).
MeshCheck check_decoded_mesh(const amc::TriangleMesh& original, const std::vector<amc::Vec3>& positions,
                             const std::vector<amc::Triangle>& triangles);

// A mesh against a reference with the same vertex numbering: the same faces in the same order,
// as many vertices, every vertex within `tolerance` per coordinate of the reference's vertex;
// max_error is the largest coordinate difference. `reference` names the reference in the problem
// text. Used for a quantized decode against the checked lossless decode of the same connectivity
// code (matching by position alone would be ambiguous: a coarse grid can put two vertices on one
// point), and for amcodec's quantized leaf mesh against the input's.
MeshCheck check_same_mesh_within(const std::vector<amc::Vec3>& reference_positions,
                                 const std::vector<amc::Triangle>& reference_triangles,
                                 const std::vector<amc::Vec3>& positions, const std::vector<amc::Triangle>& triangles,
                                 double tolerance, const std::string& reference);

}  // namespace amc_bench
