// import_mesh: base detection, then the hierarchy built from what it found.
#include <amc/import.h>

#include "import/base_detection.h"
#include "import/hierarchy_from_levels.h"

namespace amc {

ImportedHierarchy import_mesh(const TriangleMesh& mesh, const std::string& what, unsigned threads) {
    const DetectedBase detected = detect_base(mesh, what, threads);
    // The build checks the result against the input; should a detected level ever fail that
    // check, the coarser levels are given up one by one, down to the mesh itself as its base.
    for (size_t levels = detected.levels.size();; --levels) {
        try {
            return hierarchy_from_levels(mesh, truncated(mesh, detected, levels), what);
        } catch (const Error&) {
            if (levels == 0) throw;
        }
    }
}

}  // namespace amc
