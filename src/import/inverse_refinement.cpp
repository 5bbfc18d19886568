// The inverse step (docs/IMPORT.md, "Leaf mesh alone"): one refinement level undone, its small
// patches kept only where the next level confirms them. The search itself: level_finder.h.
#include "import/inverse_refinement.h"

#include "import/level_finder.h"

#include <algorithm>

namespace amc::detail {

using inverse::LevelFinder;


CoarserLevel undo_refinement_level(const std::vector<Triangle>& fine, const std::vector<uint8_t>& refined,
                                   uint32_t vertex_count, const std::vector<uint8_t>* active,
                                   const std::vector<uint8_t>* kept, bool give_up_retraced) {
    // Large patches first: they are what a level looks like where the mesh is finest. Small
    // ones are also what wrong readings look like where it is not finest yet (the true blocks
    // there become valid only once the finer ones around are undone), so a small patch is kept
    // only when the next level confirms it: one of its parents lies in a valid patch there.
    LevelFinder finder(fine, refined, vertex_count, kept, give_up_retraced);
    constexpr uint32_t kLarge = 12;  // vertices removed: four blocks or more
    const size_t all = finder.commit(active);
    std::vector<size_t> small;
    for (size_t id = 0; id < all; ++id) {
        if (finder.removed_by(id) < kLarge) small.push_back(id);
    }
    if (small.empty()) {
        CoarserLevel out = finder.coarser_level();
        out.blockers = finder.blockers();
        return out;
    }
    std::vector<uint32_t> parent_of_block;
    CoarserLevel trial = finder.coarser_level(&parent_of_block);
    LevelFinder next(trial.triangles, trial.refined, vertex_count, kept);
    std::vector<uint8_t> confirmed(small.size(), 0);
    for (size_t k = 0; k < small.size(); ++k) {
        for (uint32_t parent : finder.parents_of(small[k], parent_of_block)) {
            if (next.could_be_in_block(parent)) {
                confirmed[k] = 1;
                break;
            }
        }
    }
    // Nothing confirmed and nothing large: the small patches are all there is (the top level).
    if (all == small.size() && std::count(confirmed.begin(), confirmed.end(), 1) == 0) {
        trial.blockers = finder.blockers();
        return trial;
    }
    for (size_t k = 0; k < small.size(); ++k) {
        if (!confirmed[k]) finder.release_patch(small[k]);
    }
    CoarserLevel out = finder.coarser_level();
    out.blockers = finder.blockers();
    return out;
}

}  // namespace amc::detail
