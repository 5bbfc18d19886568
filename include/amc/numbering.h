// The caller's own numbering of a leaf mesh: which vertex and which face of the caller's mesh
// each element of the canonical leaf mesh (extract_leaf_mesh) is, so that arrays stored by the
// caller's vertex or face index stay valid after a round trip through amcodec.
#pragma once

#include <amc/hierarchy.h>

#include <cstdint>
#include <vector>

namespace amc {

// Relative to extract_leaf_mesh(h) of one hierarchy h:
//   caller's vertex i is leaf vertex vertex[i];
//   caller's face j is leaf triangle face[j], its corners rotated: the caller's corner c is the
//   leaf triangle's corner (c + rotation[j]) % 3.
// Both maps are bijections (a leaf mesh uses every vertex of its hierarchy).
struct LeafNumbering {
    std::vector<uint32_t> vertex;
    std::vector<uint32_t> face;
    std::vector<uint8_t> rotation;
    bool empty() const { return vertex.empty() && face.empty(); }
};

// The numbering of `mesh`, the caller's leaf mesh of `h`: mesh vertex i is hierarchy vertex
// vertex_of_input[i] (a VertexId of h, as the importers return it). Throws Error when `mesh` is
// not the leaf mesh of `h` under that map (a face that is no leaf triangle, a vertex map that is
// not a bijection onto the live vertices, a face listed twice or missing).
LeafNumbering leaf_numbering(const Hierarchy& h, const TriangleMesh& mesh,
                             const std::vector<VertexId>& vertex_of_input);

// The leaf mesh numbered as the caller numbered it: positions and triangles (and `cells`, when
// given, reordered alike). Throws Error when the numbering does not fit the leaf mesh.
TriangleMesh renumber_leaf_mesh(const LeafMesh& leaf, const LeafNumbering& numbering,
                                CellData* cells = nullptr);

// Checks that `numbering` is a pair of bijections that fits a leaf mesh of `vertices` vertices and
// `faces` triangles with rotations 0..2; returns a description of the first problem, or "".
std::string check_numbering(const LeafNumbering& numbering, uint64_t vertices, uint64_t faces);

}  // namespace amc
