// The hierarchy that base detection found, built split by split: the detected base, then the
// splits of every undone level from the coarsest to the finest, each midpoint the input vertex
// the detection named (no positions are consulted), and the diagonal of every two-hanging-node
// leaf read off the input mesh.
#pragma once

#include "import/base_detection.h"

#include <amc/import.h>

#include <string>

namespace amc {

// Builds the hierarchy and checks that its leaf mesh is exactly `mesh` (same triangles, same
// orientation, same positions) and that it passes check_invariants. Throws Error (naming `what`)
// when it does not, which a correct detection never causes.
ImportedHierarchy hierarchy_from_levels(const TriangleMesh& mesh, const DetectedBase& detected,
                                        const std::string& what);

}  // namespace amc
