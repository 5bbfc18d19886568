// Importing adaptive meshes that amcodec did not build itself (docs/IMPORT.md):
//   * a base mesh and a conforming leaf mesh (any vertex and face order) -> the hierarchy whose
//     extract_leaf_mesh is exactly that leaf mesh;
//   * refinement histories: "refine these elements / coarsen these" steps replayed on a base.
#pragma once

#include <amc/hierarchy.h>

#include <cstdint>
#include <string>
#include <vector>

namespace amc {

// ---- base mesh + leaf mesh -> hierarchy ------------------------------------------------------

struct ImportedHierarchy {
    Hierarchy hierarchy;
    // Input leaf vertex i is vertex vertex_of_input[i] of `hierarchy` (a VertexId).
    std::vector<VertexId> vertex_of_input;
};

// Finds the forest over `base` and every two-hanging-node diagonal such that extract_leaf_mesh of
// the result is exactly `leaf`: the same triangles (same orientation) on the same positions, the
// vertices related by vertex_of_input. The result's base mesh has base's triangles and the
// positions of the matched leaf vertices; single_precision follows the leaf mesh. The search is
// combinatorial (no vertex has to lie at an edge midpoint), linear in the leaf mesh, and ends with
// a check of the whole leaf mesh, so a wrong reconstruction can not pass.
// Base vertex i is leaf vertex leaf_vertex_of_base[i]; when the map is empty, base vertices are
// matched to leaf vertices by exact position. `what` names the leaf mesh in error messages.
// Throws Error naming the first offending leaf face or vertex (input numbering) when the leaf mesh
// is not a red-green refinement of the base.
ImportedHierarchy import_leaf_mesh(const TriangleMesh& base, const TriangleMesh& leaf,
                                   const std::vector<uint32_t>& leaf_vertex_of_base = {},
                                   const std::string& what = "leaf mesh");

// The same on files (read_mesh: OBJ, OFF, PLY); errors name the files.
ImportedHierarchy import_leaf_mesh_files(const std::string& base_path, const std::string& leaf_path);

}  // namespace amc
