// The forest level by level, as the coder walks it (paper II-B: breadth first): the octants of
// each level in canonical order (tree by tree, Morton order inside a tree), their parents and
// children, and their face neighbours of the same level. The level after a level holds the
// children of its refined octants in that order, child after child in z-order.
#pragma once

#include "octree/tree_faces.h"

#include <amc/octree.h>

#include <cstdint>
#include <vector>

namespace amc {

constexpr uint32_t kNoOctant = 0xffffffffu;
// Values of OctreeLevel::neighbor besides octant indices.
constexpr uint32_t kCoarserRegion = 0xffffffffu;  // no octant of this level across: the leaf there is coarser
constexpr uint32_t kTreeBoundary = 0xfffffffeu;   // the boundary of the coarse mesh
inline bool is_octant(uint32_t neighbor) { return neighbor < kTreeBoundary; }

struct OctreeLevel {
    std::vector<uint32_t> tree;
    std::vector<int32_t> coord;        // 3 per octant: integer coordinates at this level, 0 .. 2^level - 1
    std::vector<uint32_t> parent;      // index in the level before (kNoOctant for roots)
    std::vector<uint32_t> first_child; // index in the level after, or kNoOctant for a leaf
    std::vector<uint32_t> neighbor;    // 2 * dim per octant: across face f, an index, kCoarserRegion or kTreeBoundary

    size_t size() const { return tree.size(); }
};

class OctreeLevels {
public:
    // Level 0: the roots, one per tree, with their neighbours. `conn` must be valid.
    explicit OctreeLevels(const TreeConnectivity& conn);

    int dim() const { return faces_.dim(); }
    int face_count() const { return 2 * faces_.dim(); }
    const TreeFaces& faces() const { return faces_; }
    int depth() const { return int(levels_.size()) - 1; }  // index of the last level
    const OctreeLevel& level(int l) const { return levels_[l]; }
    uint64_t octant_count() const { return octants_; }

    // Appends the next level: the children of the last level's octants with refined[i] != 0, in
    // canonical order, and their neighbours. Throws Error(limit_exceeded) past `max_octants`
    // octants in all, before allocating for them.
    void add_children(const std::vector<uint8_t>& refined, uint64_t max_octants);

    // The octant of level l at coordinates c in `tree`, or kNoOctant (descends from the root).
    uint32_t find(uint32_t tree, int l, const int32_t c[3]) const;

    // The leaves tree by tree in Morton order (p4est's order), as a forest over `conn`.
    OctreeForest leaves(const TreeConnectivity& conn) const;

private:
    TreeFaces faces_;
    std::vector<OctreeLevel> levels_;
    uint64_t octants_ = 0;
};

// The levels of a valid forest (validate_octree_forest), with max_octants as in add_children.
// refined[l][i] tells whether octant i of level l is refined.
OctreeLevels octree_levels_of(const OctreeForest& forest, std::vector<std::vector<uint8_t>>* refined, uint64_t max_octants);

}  // namespace amc
