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

// The levels undone and the mesh they leave (`remaining`, the leaf triangles while none is).
struct UndoneLevels {
    DetectedBase detected;
    std::vector<Triangle> remaining;
};

// Levels undone from `leaf_triangles` until the base's count is left or nothing more can be undone.
UndoneLevels undo_levels(const std::vector<Triangle>& leaf_triangles, uint32_t vertex_count, size_t base_triangles,
                         const std::vector<uint8_t>& kept) {
    UndoneLevels out;
    out.remaining = leaf_triangles;
    std::vector<uint8_t> refined(leaf_triangles.size(), 0);
    std::vector<uint8_t> changed;
    std::vector<DetectedLevel>& levels = out.detected.levels;
    while (levels.size() < size_t(kMaxLevel) && out.remaining.size() > base_triangles) {
        detail::CoarserLevel coarser = detail::undo_refinement_level(
            out.remaining, refined, vertex_count, levels.empty() ? nullptr : &changed, &kept, /*give_up_retraced=*/true);
        if (coarser.red_blocks == 0) break;
        levels.push_back(detail::detected_level(coarser));
        out.remaining = std::move(coarser.triangles);
        refined = std::move(coarser.refined);
        changed = std::move(coarser.changed);
    }
    return out;
}

bool ends_at_base(const std::vector<Triangle>& triangles, const Hierarchy& h, const std::vector<uint32_t>& leaf_of_base) {
    const size_t base_triangles = h.base().triangles.size();
    if (triangles.size() != base_triangles) return false;
    std::vector<Triangle> found, wanted;
    found.reserve(base_triangles);
    wanted.reserve(base_triangles);
    for (const Triangle& t : triangles) found.push_back(normalized(t));
    for (const Triangle& t : h.base().triangles) {
        wanted.push_back(normalized({leaf_of_base[t[0]], leaf_of_base[t[1]], leaf_of_base[t[2]]}));
    }
    std::sort(found.begin(), found.end());
    std::sort(wanted.begin(), wanted.end());
    return found == wanted;
}

// The leaf triangles in the `k`th fixed other order: reversed, then shuffled by a fixed seed.
std::vector<Triangle> reordered(const std::vector<Triangle>& triangles, int k) {
    std::vector<Triangle> out(triangles.rbegin(), triangles.rend());
    uint64_t state = 0x9e3779b97f4a7c15ull * uint64_t(k);
    for (size_t i = out.size(); k > 1 && i > 1; --i) {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        std::swap(out[i - 1], out[(state >> 33) % i]);
    }
    return out;
}

}  // namespace

std::vector<uint32_t> reconstruct_anchored(Hierarchy& h, const std::vector<uint32_t>& leaf_of_base,
                                           const TriangleMesh& leaf, const std::string& what,
                                           UndoSteps* steps) {
    const uint32_t vertex_count = uint32_t(leaf.positions.size());
    // The search runs on base detection's breadth-first numbering (its reads then share cache
    // lines; it never compares vertex ids); what it found is given back in leaf ids.
    const std::vector<uint32_t> leaf_of = detail::breadth_first_vertices(leaf.triangles, vertex_count);
    std::vector<uint32_t> search_of(vertex_count);
    for (uint32_t v = 0; v < vertex_count; ++v) search_of[leaf_of[v]] = v;
    std::vector<Triangle> search_triangles = leaf.triangles;
    detail::renumber(search_triangles, search_of);
    std::vector<uint32_t> search_of_base(leaf_of_base.size());
    std::vector<uint8_t> kept(vertex_count, 0);
    for (size_t b = 0; b < leaf_of_base.size(); ++b) {
        search_of_base[b] = search_of[leaf_of_base[b]];
        kept[search_of_base[b]] = 1;
    }
    const size_t base_triangles = h.base().triangles.size();
    UndoneLevels undone = undo_levels(search_triangles, vertex_count, base_triangles, kept);
    if (steps) {  // the given order's, whatever the other orders below find
        steps->step.assign(vertex_count, kNeverUndone);
        for (size_t step = 0; step < undone.detected.levels.size(); ++step) {
            for (const std::array<uint32_t, 6>& split : undone.detected.levels[step].splits) {
                for (int k = 3; k < 6; ++k) steps->step[leaf_of[split[size_t(k)]]] = uint8_t(step + 1);
            }
        }
        steps->remaining = undone.remaining;
        detail::renumber(steps->remaining, leaf_of);
    }
    // The inverse step's search depends on the face order (where its growths seed): one order
    // may commit a wrong block and stop short of the base where another reaches it.
    constexpr int kOtherOrders = 3;
    for (int k = 1; k <= kOtherOrders && !ends_at_base(undone.remaining, h, search_of_base); ++k) {
        const std::vector<Triangle> triangles = reordered(search_triangles, k);
        undone = undo_levels(triangles, vertex_count, base_triangles, kept);
        if (undone.detected.levels.empty()) break;  // no order undoes anything: none will
    }
    if (!ends_at_base(undone.remaining, h, search_of_base)) return {};
    DetectedBase& detected = undone.detected;
    for (DetectedLevel& level : detected.levels) {
        detail::renumber(level.made, leaf_of);
        for (auto& split : level.splits) {
            for (uint32_t& v : split) v = leaf_of[v];
        }
    }
    detected.base = h.base();
    detected.leaf_vertex_of_base = leaf_of_base;
    ImportedHierarchy built = hierarchy_from_levels(leaf, detected, what);
    h = std::move(built.hierarchy);
    std::vector<uint32_t> leaf_of_vertex(h.positions().size(), kNoIndex);
    for (uint32_t l = 0; l < built.vertex_of_input.size(); ++l) leaf_of_vertex[built.vertex_of_input[l]] = l;
    return leaf_of_vertex;
}

}  // namespace amc
