// The inverse step (docs/IMPORT.md, "Leaf mesh alone"): one refinement level undone, its small
// patches kept only where the next level confirms them. The search itself: level_finder.h.
#include "import/inverse_refinement.h"

#include "import/level_finder.h"

#include "common/no_index.h"

#include <algorithm>
#include <utility>

namespace amc::detail {

using inverse::LevelFinder;

namespace {

// The triangles of `mesh` around the triangles `seeds` that LevelFinder::could_be_in_block reads:
// every triangle at a vertex within two edges of a seed's vertices (a center it tries lies across a
// seed's edge; its midpoints, apexes and fans' inner vertices are within two edges of the seed's
// vertices, and each of those needs its whole star: its size, its twins, its boundary, its edges).
// Over vertices renumbered from 0 (`kept` likewise), with `local_of[s]` the index of seed s. The
// search there then answers as on the whole mesh, at the cost of the neighbourhood instead of a
// search built over the whole coarser level.
struct Neighbourhood {
    std::vector<Triangle> triangles;
    std::vector<uint8_t> refined;
    std::vector<uint8_t> kept;
    uint32_t vertex_count = 0;
    std::vector<uint32_t> local_of;
};

Neighbourhood neighbourhood(const std::vector<Triangle>& mesh, const std::vector<uint8_t>& refined, uint32_t vertex_count,
                            const std::vector<uint32_t>& seeds, const std::vector<uint8_t>* kept) {
    // The triangles at each vertex (a counting sort).
    std::vector<uint32_t> start(size_t(vertex_count) + 2, 0);
    for (const Triangle& t : mesh) {
        for (uint32_t v : t) ++start[v + 2];
    }
    for (size_t v = 2; v < start.size(); ++v) start[v] += start[v - 1];
    std::vector<uint32_t> at(mesh.size() * 3);
    for (uint32_t t = 0; t < mesh.size(); ++t) {
        for (uint32_t v : mesh[t]) at[start[v + 1]++] = t;
    }
    // Vertices within two edges of the seeds' vertices, then the triangles at them.
    constexpr uint32_t kNotReached = kNoIndex;
    std::vector<uint32_t> local_vertex(vertex_count, kNotReached);
    std::vector<uint32_t> vertices;
    auto reach = [&](uint32_t v) {
        if (local_vertex[v] == kNotReached) local_vertex[v] = uint32_t(vertices.size()), vertices.push_back(v);
    };
    for (uint32_t s : seeds) {
        for (uint32_t v : mesh[s]) reach(v);
    }
    for (size_t ring = 0, begin = 0; ring < 2; ++ring) {
        const size_t end = vertices.size();
        for (size_t k = std::exchange(begin, end); k < end; ++k) {
            const uint32_t v = vertices[k];
            for (uint32_t i = start[v]; i < start[v + 1]; ++i) {
                for (uint32_t w : mesh[at[i]]) reach(w);
            }
        }
    }
    const size_t inner = vertices.size();  // the vertices whose stars are whole
    std::vector<uint32_t> local_triangle;  // per triangle of the neighbourhood: its index in `mesh`
    std::vector<uint32_t> triangle_of(mesh.size(), kNoIndex);
    for (size_t k = 0; k < inner; ++k) {
        const uint32_t v = vertices[k];
        for (uint32_t i = start[v]; i < start[v + 1]; ++i) {
            if (triangle_of[at[i]] == kNoIndex) triangle_of[at[i]] = uint32_t(local_triangle.size()), local_triangle.push_back(at[i]);
        }
    }
    Neighbourhood out;
    out.triangles.reserve(local_triangle.size());
    out.refined.reserve(local_triangle.size());
    for (uint32_t t : local_triangle) {
        out.refined.push_back(refined[t]);
        for (uint32_t v : mesh[t]) reach(v);  // the outer vertices, their stars cut
        out.triangles.push_back({local_vertex[mesh[t][0]], local_vertex[mesh[t][1]], local_vertex[mesh[t][2]]});
    }
    out.vertex_count = uint32_t(vertices.size());
    if (kept) {
        out.kept.resize(vertices.size());
        for (size_t k = 0; k < vertices.size(); ++k) out.kept[k] = (*kept)[vertices[k]];
    }
    out.local_of.assign(mesh.size(), kNoIndex);
    for (uint32_t s : seeds) out.local_of[s] = triangle_of[s];
    return out;
}

}  // namespace


CoarserLevel undo_refinement_level(const std::vector<Triangle>& fine, const std::vector<uint8_t>& refined,
                                   uint32_t vertex_count, const std::vector<uint8_t>* active,
                                   const std::vector<uint8_t>* kept, bool give_up_retraced,
                                   const std::atomic<bool>* cancel) {
    // Large patches first: they are what a level looks like where the mesh is finest. Small
    // ones are also what wrong readings look like where it is not finest yet (the true blocks
    // there become valid only once the finer ones around are undone), so a small patch is kept
    // only when the next level confirms it: one of its parents lies in a valid patch there.
    LevelFinder finder(fine, refined, vertex_count, kept, give_up_retraced, cancel);
    constexpr uint32_t kLarge = 12;  // vertices removed: four blocks or more
    const size_t all = finder.commit(active);
    if (finder.cancelled()) return CoarserLevel{};
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
    std::vector<std::vector<uint32_t>> parents(small.size());
    std::vector<uint32_t> all_parents;
    for (size_t k = 0; k < small.size(); ++k) {
        parents[k] = finder.parents_of(small[k], parent_of_block);
        all_parents.insert(all_parents.end(), parents[k].begin(), parents[k].end());
    }
    const Neighbourhood around = neighbourhood(trial.triangles, trial.refined, vertex_count, all_parents, kept);
    LevelFinder next(around.triangles, around.refined, around.vertex_count, kept ? &around.kept : nullptr);
    std::vector<uint8_t> confirmed(small.size(), 0);
    for (size_t k = 0; k < small.size(); ++k) {
        for (uint32_t parent : parents[k]) {
            if (next.could_be_in_block(around.local_of[parent])) {
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
