// 2:1 balance (p4est_balance): a refined octant needs its face (edge, corner) neighbours of its
// own level, that is their parents refined. The smallest balanced refinement is built from the
// finest level up: the octants that must be refined at level l - 1 are the parents of those at
// level l and of their neighbours.
#include "octree/octree_levels.h"

#include "common/check.h"
#include "octree/tree_corners.h"

#include <algorithm>
#include <array>
#include <set>

namespace amc {

namespace {

// Offsets to the neighbours a balance type asks for: 2 * dim faces, then edges, then corners.
std::vector<std::array<int, 3>> neighbor_offsets(int dim, OctreeBalance balance) {
    std::vector<std::array<int, 3>> out;
    for (int dz = dim == 3 ? -1 : 0; dz <= (dim == 3 ? 1 : 0); ++dz)
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                const int nonzero = (dx != 0) + (dy != 0) + (dz != 0);
                if (nonzero == 0) continue;
                const bool wanted = nonzero == 1 || (nonzero == 2 && dim == 3 && balance != OctreeBalance::face) ||
                                    (nonzero == dim && balance == OctreeBalance::corner);
                if (wanted) out.push_back({dx, dy, dz});
            }
    std::stable_sort(out.begin(), out.end(), [](const auto& a, const auto& b) {
        return (a[0] != 0) + (a[1] != 0) + (a[2] != 0) < (b[0] != 0) + (b[1] != 0) + (b[2] != 0);
    });
    return out;
}

struct Key {  // an octant of some level: its tree and coordinates
    uint32_t tree;
    int32_t c[3];
    bool operator<(const Key& o) const {
        if (tree != o.tree) return tree < o.tree;
        if (c[2] != o.c[2]) return c[2] < o.c[2];
        if (c[1] != o.c[1]) return c[1] < o.c[1];
        return c[0] < o.c[0];
    }
    bool operator==(const Key& o) const { return tree == o.tree && c[0] == o.c[0] && c[1] == o.c[1] && c[2] == o.c[2]; }
};

// The same-level positions an offset from octant c of `tree` reaches: across faces one after the
// other, and (offsets that leave the tree on two or more axes) around the coarse vertex or edge
// unless `gone_around` (this level's) holds it: from every octant there the same positions but
// its own, which is the octant or its face neighbour. Once each, else quadratic in the trees there.
void reached(const TreeFaces& faces, const TreeCorners& corners, uint32_t tree, int l, const int32_t c[3],
             const std::array<int, 3>& off, std::set<TreeCorners::Meeting>& gone_around,
             std::vector<TreeCorners::Place>& out) {
    out.clear();
    TreeCorners::Place q{tree, {c[0] + off[0], c[1] + off[1], c[2] + off[2]}};
    int outside = 0;
    for (int a = 0; a < 3; ++a) outside += q.c[a] < 0 || q.c[a] >= (int32_t(1) << l);
    if (outside >= 2 && gone_around.insert(corners.meeting(tree, l, q.c)).second) corners.neighbours(tree, l, q.c, out);
    if (faces.wrap(q.tree, l, q.c)) out.push_back(q);
}

std::string describe(const OctreeLevel& lv, uint32_t n, int l) {
    return "tree " + std::to_string(lv.tree[n]) + " octant (" + std::to_string(lv.coord[3 * size_t(n)]) + ", " +
           std::to_string(lv.coord[3 * size_t(n) + 1]) + ", " + std::to_string(lv.coord[3 * size_t(n) + 2]) + ") of level " +
           std::to_string(l);
}

}  // namespace

OctreeForest balance_octree_forest(const OctreeForest& forest, OctreeBalance balance) {
    validate_octree_forest(forest, "balance_octree_forest");
    std::vector<std::vector<uint8_t>> refined;
    const OctreeLevels levels = octree_levels_of(forest, &refined, UINT64_MAX);
    const TreeFaces& faces = levels.faces();
    const TreeCorners corners(forest.connectivity);
    const auto offsets = neighbor_offsets(forest.dim(), balance);
    std::vector<TreeCorners::Place> places;
    std::set<TreeCorners::Meeting> gone_around;
    // must[l]: the octants of level l that must be refined, sorted.
    std::vector<std::vector<Key>> must(levels.depth() + 1);
    for (int l = 0; l <= levels.depth(); ++l) {
        const OctreeLevel& lv = levels.level(l);
        for (uint32_t n = 0; n < lv.size(); ++n)
            if (refined[l][n]) must[l].push_back({lv.tree[n], {lv.coord[3 * n], lv.coord[3 * n + 1], lv.coord[3 * n + 2]}});
    }
    for (int l = levels.depth(); l >= 1; --l) {
        std::sort(must[l].begin(), must[l].end());
        must[l].erase(std::unique(must[l].begin(), must[l].end()), must[l].end());
        gone_around.clear();
        for (const Key& k : must[l]) {
            must[l - 1].push_back({k.tree, {k.c[0] >> 1, k.c[1] >> 1, k.c[2] >> 1}});
            for (const auto& off : offsets) {
                reached(faces, corners, k.tree, l, k.c, off, gone_around, places);
                for (const TreeCorners::Place& q : places) must[l - 1].push_back({q.tree, {q.c[0] >> 1, q.c[1] >> 1, q.c[2] >> 1}});
            }
        }
    }
    std::sort(must[0].begin(), must[0].end());
    must[0].erase(std::unique(must[0].begin(), must[0].end()), must[0].end());
    const int depth = levels.depth();
    return refine_octree_forest(
        uniform_octree_forest(forest.connectivity, 0),
        [&](uint32_t tree, const Octant& o) {
            const int shift = octree_root_log2(forest.dim()) - o.level;
            const Key k{tree, {o.x >> shift, o.y >> shift, o.z >> shift}};
            return o.level <= depth && std::binary_search(must[o.level].begin(), must[o.level].end(), k);
        },
        octree_max_level(forest.dim()));
}

std::string octree_balance_violation(const OctreeForest& forest, OctreeBalance balance) {
    validate_octree_forest(forest, "octree_balance_violation");
    std::vector<std::vector<uint8_t>> refined;
    const OctreeLevels levels = octree_levels_of(forest, &refined, UINT64_MAX);
    const auto offsets = neighbor_offsets(forest.dim(), balance);
    const TreeCorners corners(forest.connectivity);
    std::vector<TreeCorners::Place> places;
    std::set<TreeCorners::Meeting> gone_around;
    for (int l = 1; l <= levels.depth(); ++l) {
        const OctreeLevel& lv = levels.level(l);
        gone_around.clear();
        for (uint32_t n = 0; n < lv.size(); ++n) {
            if (!refined[l][n]) continue;
            for (const auto& off : offsets) {
                reached(levels.faces(), corners, lv.tree[n], l, &lv.coord[3 * size_t(n)], off, gone_around, places);
                for (const TreeCorners::Place& q : places)
                    if (levels.find(q.tree, l, q.c) == kNoOctant)
                        return describe(lv, n, l) + " is refined, but its neighbour at offset (" + std::to_string(off[0]) + ", " +
                               std::to_string(off[1]) + ", " + std::to_string(off[2]) + ") in tree " + std::to_string(q.tree) +
                               " lies in a leaf two or more levels coarser";
            }
        }
    }
    return "";
}

}  // namespace amc
