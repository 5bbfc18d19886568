#include "import/anchored_reconstruction.h"

#include "common/no_index.h"
#include "import/base_detection.h"
#include "import/hierarchy_from_levels.h"
#include "import/inverse_refinement.h"

#include <algorithm>

namespace amc {
namespace {

Triangle normalized(Triangle t) {
    const int r = t[0] < t[1] ? (t[0] < t[2] ? 0 : 2) : (t[1] < t[2] ? 1 : 2);
    return {t[size_t(r)], t[size_t(r + 1) % 3], t[size_t(r + 2) % 3]};
}

}  // namespace

std::vector<uint32_t> reconstruct_anchored(Hierarchy& h, const std::vector<uint32_t>& leaf_of_base,
                                           const TriangleMesh& leaf, const std::string& what,
                                           UndoSteps* steps) {
    const uint32_t vertex_count = uint32_t(leaf.positions.size());
    std::vector<uint8_t> kept(vertex_count, 0);
    for (uint32_t l : leaf_of_base) kept[l] = 1;
    DetectedBase detected;
    const std::vector<Triangle>* triangles = &leaf.triangles;
    std::vector<uint8_t> refined(leaf.triangles.size(), 0);
    std::vector<uint8_t> changed;
    const size_t base_triangles = h.base().triangles.size();
    while (detected.levels.size() < size_t(kMaxLevel) && triangles->size() > base_triangles) {
        detail::CoarserLevel coarser = detail::undo_refinement_level(
            *triangles, refined, vertex_count, detected.levels.empty() ? nullptr : &changed, &kept);
        if (coarser.red_blocks == 0) break;
        DetectedLevel level;
        level.splits = std::move(coarser.splits);
        level.closures = coarser.green_groups;
        level.triangles = std::move(coarser.triangles);
        refined = std::move(coarser.refined);
        changed = std::move(coarser.changed);
        detected.levels.push_back(std::move(level));
        triangles = &detected.levels.back().triangles;
    }
    if (steps) {
        steps->step.assign(vertex_count, kNeverUndone);
        for (size_t step = 0; step < detected.levels.size(); ++step) {
            for (const std::array<uint32_t, 6>& split : detected.levels[step].splits) {
                for (int k = 3; k < 6; ++k) steps->step[split[size_t(k)]] = uint8_t(step + 1);
            }
        }
        steps->remaining = *triangles;
    }
    if (triangles->size() != base_triangles) return {};
    std::vector<Triangle> found, wanted;
    found.reserve(base_triangles);
    wanted.reserve(base_triangles);
    for (const Triangle& t : *triangles) found.push_back(normalized(t));
    for (const Triangle& t : h.base().triangles) {
        wanted.push_back(normalized({leaf_of_base[t[0]], leaf_of_base[t[1]], leaf_of_base[t[2]]}));
    }
    std::sort(found.begin(), found.end());
    std::sort(wanted.begin(), wanted.end());
    if (found != wanted) return {};
    detected.base = h.base();
    detected.leaf_vertex_of_base = leaf_of_base;
    ImportedHierarchy built = hierarchy_from_levels(leaf, detected, what);
    h = std::move(built.hierarchy);
    std::vector<uint32_t> leaf_of_vertex(h.positions().size(), kNoIndex);
    for (uint32_t l = 0; l < built.vertex_of_input.size(); ++l) leaf_of_vertex[built.vertex_of_input[l]] = l;
    return leaf_of_vertex;
}

}  // namespace amc
