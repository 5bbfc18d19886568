// Importing adaptive meshes that amcodec did not build itself (docs/IMPORT.md):
//   * a base mesh and a conforming leaf mesh (any vertex and face order) -> the hierarchy whose
//     extract_leaf_mesh is exactly that leaf mesh;
//   * a leaf mesh alone -> the same, over the coarsest base found in its connectivity;
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

// ---- leaf mesh alone -> hierarchy (docs/IMPORT.md, section 2) --------------------------------

// Finds the coarsest base of which `mesh` is a red-green refinement and returns the hierarchy
// (vertex_of_input as in ImportedHierarchy): adaptive and semi-regular meshes get their forest,
// an irregular mesh (mostly) itself as the base with no refinement. Combinatorial: no position is
// consulted. Never fails on a valid mesh (validate_triangle_mesh; `what` names it in the error
// otherwise). Linear time in practice (docs/IMPORT.md, "Speed"). The search runs on up to two of
// `threads` threads (0: every core); the result does not depend on it.
ImportedHierarchy import_mesh(const TriangleMesh& mesh, const std::string& what = "mesh", unsigned threads = 0);

// ---- refinement histories (docs/IMPORT.md, section 3) -----------------------------------------

// One adaptation step as finite-element codes mark it. Elements are the triangles of the current
// state's leaf mesh, numbered as extract_leaf_mesh lists them.
struct AdaptationStep {
    std::vector<uint32_t> refine;   // each element's node is refined red (balance and closure follow)
    std::vector<uint32_t> coarsen;  // a parent is coarsened when every element of its four children
                                    // is listed (and none is refined) and balance allows it
    uint32_t line = 0;              // the step's line in its file (0: not read from a file)
};

// Applies one step to h: first every refinement (Hierarchy::refine, so balance and closure refine
// more), then the coarsenings, deepest level first (Hierarchy::coarsen). New vertices are placed
// by h's vertex placer. Throws Error (ErrorCode::invalid_input) naming the element for an index
// out of range, an element listed twice, or an element listed for both; h is unchanged then.
void apply_adaptation_step(Hierarchy& h, const std::vector<uint32_t>& refine, const std::vector<uint32_t>& coarsen);

struct RefinementHistory {
    TriangleMesh base;
    std::vector<AdaptationStep> steps;
    std::string source = "history";  // names the history in error messages
};

// The hierarchy after each step: result[i] is the state after steps[0..i]. An element index out
// of range for its state is refused here (the file reader can not know the states): the error
// names the source, the step's line and the element.
std::vector<Hierarchy> replay_history(const RefinementHistory& history);

}  // namespace amc
