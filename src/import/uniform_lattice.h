// Uniformly refined leaf meshes (semi-regular remeshes): every base triangle split K times, no
// green triangle. Each base triangle's region is a triangular grid that is read off the leaf
// mesh's connectivity alone (docs/IMPORT.md, "uniform refinement").
#pragma once

#include <amc/hierarchy.h>

#include "import/leaf_halfedges.h"

#include <string>
#include <vector>

namespace amc {

// When `leaf` is the uniform refinement of h's base (h: unrefined roots whose vertex i is leaf
// vertex leaf_of_base[i]), refines h uniformly and returns the leaf vertex of every vertex of h;
// returns an empty vector when it is not (the general reconstruction then decides).
std::vector<uint32_t> reconstruct_uniform(Hierarchy& h, const std::vector<uint32_t>& leaf_of_base,
                                          const TriangleMesh& leaf, const LeafHalfedges& halfedges);

}  // namespace amc
