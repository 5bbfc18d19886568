// The combinatorial reconstruction of a hierarchy from its base and its leaf mesh (docs/IMPORT.md,
// section 1, "Anchored inverse refinement"): levels of red-green refinement are undone bottom-up
// from the connectivity alone (inverse_refinement.h), the base vertices kept, until the base
// triangles are left; the hierarchy is then built split by split from the base down.
#pragma once

#include <amc/hierarchy.h>

#include "import/undo_steps.h"

#include <cstdint>
#include <string>
#include <vector>

namespace amc {

// `h` is a hierarchy of unrefined roots over the base, whose vertex i is leaf vertex
// leaf_of_base[i]. On success builds its forest and returns the leaf vertex of every vertex of h
// (0xffffffff for none); returns an empty vector when the undone levels do not end at the base
// triangles (the caller tries another way, then reports the error). The caller verifies the
// whole leaf mesh afterwards. `steps` (if given) receives, whether the base was reached or not,
// what the levels undone say (undo_steps.h).
std::vector<uint32_t> reconstruct_anchored(Hierarchy& h, const std::vector<uint32_t>& leaf_of_base,
                                           const TriangleMesh& leaf, const std::string& what,
                                           UndoSteps* steps = nullptr);

}  // namespace amc
