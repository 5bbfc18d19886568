// What every writer of a hierarchy checks first (encode, write_hierarchy): the checks its reader
// makes, so that whatever is written can be read back.
#pragma once

#include <amc/hierarchy.h>

#include <string>

namespace amc {

// The base mesh (validate_triangle_mesh: manifold, consistently oriented, no unused vertex, no
// degenerate or repeated triangle, finite positions), the structure (check_invariants) and, with
// `positions`, check_positions. Throws Error naming `what` and the first problem, in the words
// the reader would use. The structure is taken as checked when a reader has checked it and
// nothing has changed it since (HierarchyBuilder::structure_checked).
// The structural checks run on up to `threads` threads; the first problem in node order is named.
void check_before_writing(const Hierarchy& h, const std::string& what, bool positions, unsigned threads = 1);

// check_invariants on up to `threads` threads (the same answer as with one).
std::string check_invariants(const Hierarchy& h, unsigned threads);

}  // namespace amc
