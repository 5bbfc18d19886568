// One level of red-green refinement undone, found from connectivity alone: the inverse step that
// base detection (base_detection.h) repeats until nothing is left to undo.
//
// A mesh B is the level-1 mesh of a one-level hierarchy over a coarser mesh B' when its triangles
// split into red blocks (the four children of a split triangle: a center whose three vertices are
// edge midpoints, and three corners), green groups (the two or three closure triangles of a coarse
// triangle with one or two hanging nodes, either diagonal) and untouched triangles, such that each
// removed vertex is the midpoint of one coarse edge whose sides are red blocks, green groups or the
// boundary. The triangles of B may themselves carry refinement (`refined`): the coarser hierarchy
// then keeps their subtrees one level deeper, which balance allows only where a refined triangle
// has same-level neighbours on all its edges. docs/IMPORT.md describes the search.
#pragma once

#include <amc/mesh.h>

#include <array>
#include <atomic>
#include <cstdint>
#include <vector>

namespace amc::detail {

struct CoarserLevel {
    std::vector<Triangle> triangles;  // B' over the vertex ids of B (removed ids unused)
    std::vector<uint8_t> refined;     // per triangle of B': it has children (it is a red parent,
                                      // or an untouched triangle of B that was refined)
    std::vector<uint8_t> changed;     // per triangle of B': new (a parent or a closure's coarse
                                      // triangle), or left for a later step: where the next step
                                      // seeds
    uint32_t red_blocks = 0;          // blocks of four merged into their parent
    uint32_t green_groups = 0;        // closures merged into their coarse triangle
    uint32_t removed_vertices = 0;
    // Every undone split: its parent (v0, v1, v2) and midpoints (m0 on v0 -> v1, m1, m2).
    std::vector<std::array<uint32_t, 6>> splits;
    // Refined triangles that stood in the way of a large patch (a side across them invalid):
    // where an earlier step's small patch made them, that patch may be wrong.
    std::vector<Triangle> blockers;
};

// `fine` is edge-manifold and consistently oriented over vertex ids below vertex_count;
// refined[t] tells whether triangle t of `fine` has children; `active` (if given) marks where
// `fine` changed in the previous step (CoarserLevel::changed): only there is a new patch sought.
// `kept` (if given) marks vertices that must stay (the base vertices of an anchored import).
// `give_up_retraced` (the anchored import's search) gives up the growths that retrace a reading
// given up before (docs/IMPORT.md, "Retraced readings given up"); base detection keeps its answers.
// Returns red_blocks == 0 (and an empty mesh) when no level can be undone anywhere, or when
// `cancel` (if given) is set while the step runs (its answer is then not wanted). Linear in
// fine.size() + vertex_count.
CoarserLevel undo_refinement_level(const std::vector<Triangle>& fine, const std::vector<uint8_t>& refined,
                                   uint32_t vertex_count, const std::vector<uint8_t>* active = nullptr,
                                   const std::vector<uint8_t>* kept = nullptr, bool give_up_retraced = false,
                                   const std::atomic<bool>* cancel = nullptr);

}  // namespace amc::detail
