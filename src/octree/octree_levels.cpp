// Building the levels of a forest: children in canonical order, neighbours from the parents'.
#include "octree/octree_levels.h"

#include "common/check.h"

#include <algorithm>

namespace amc {

namespace {

uint64_t morton(const Octant& o, int dim) {
    uint64_t key = 0;
    const int bits = octree_root_log2(dim);
    for (int b = bits - 1; b >= 0; --b) {
        if (dim == 3) key = (key << 1) | ((uint32_t(o.z) >> b) & 1);
        key = (key << 1) | ((uint32_t(o.y) >> b) & 1);
        key = (key << 1) | ((uint32_t(o.x) >> b) & 1);
    }
    return key;
}

}  // namespace

OctreeLevels::OctreeLevels(const TreeConnectivity& conn) : faces_(conn) {
    const uint32_t trees = conn.tree_count();
    const int faces = 2 * conn.dim;
    OctreeLevel roots;
    roots.tree.resize(trees);
    roots.coord.assign(size_t(trees) * 3, 0);
    roots.parent.assign(trees, kNoOctant);
    roots.first_child.assign(trees, kNoOctant);
    roots.neighbor.resize(size_t(trees) * faces);
    for (uint32_t t = 0; t < trees; ++t) {
        roots.tree[t] = t;
        for (int f = 0; f < faces; ++f) {
            const FaceGlue& g = faces_.glue(t, f);
            roots.neighbor[size_t(t) * faces + f] = g.boundary ? kTreeBoundary : g.tree;
        }
    }
    levels_.push_back(std::move(roots));
    octants_ = trees;
}

void OctreeLevels::add_children(const std::vector<uint8_t>& refined, uint64_t max_octants) {
    OctreeLevel& up = levels_.back();
    const int d = dim(), faces = 2 * d, children = 1 << d;
    uint64_t refined_count = 0;
    for (uint8_t r : refined) refined_count += r != 0;
    const uint64_t count = refined_count << d;
    AMC_REQUIRE(count <= max_octants && octants_ + count <= max_octants, limit_exceeded,
                "the forest would have more than " + std::to_string(max_octants) + " octants");
    const int l = depth() + 1;
    OctreeLevel down;
    down.tree.resize(count);
    down.coord.resize(count * 3);
    down.parent.resize(count);
    down.first_child.assign(count, kNoOctant);
    down.neighbor.resize(count * faces);
    uint32_t next = 0;
    for (uint32_t p = 0; p < up.size(); ++p) {
        if (!refined[p]) continue;
        up.first_child[p] = next;
        for (int c = 0; c < children; ++c, ++next) {
            down.tree[next] = up.tree[p];
            down.parent[next] = p;
            for (int a = 0; a < 3; ++a) down.coord[size_t(next) * 3 + a] = 2 * up.coord[size_t(p) * 3 + a] + ((c >> a) & 1);
        }
    }
    // Neighbours: a sibling, or a child of the parent's neighbour across the same face.
    for (uint32_t n = 0; n < count; ++n) {
        const uint32_t p = down.parent[n];
        const int c = int(n - up.first_child[p]);
        for (int f = 0; f < faces; ++f) {
            const int a = f / 2, side = f & 1;
            uint32_t& out = down.neighbor[size_t(n) * faces + f];
            if (((c >> a) & 1) != side) {
                out = n + (side ? 1u << a : 0u) - (side ? 0u : 1u << a);
                continue;
            }
            const uint32_t q = up.neighbor[size_t(p) * faces + f];
            if (!is_octant(q)) {
                out = q;
                continue;
            }
            if (up.first_child[q] == kNoOctant) {
                out = kCoarserRegion;
                continue;
            }
            uint32_t tree = down.tree[n];
            int32_t at[3] = {down.coord[size_t(n) * 3], down.coord[size_t(n) * 3 + 1], down.coord[size_t(n) * 3 + 2]};
            at[a] += side ? 1 : -1;
            faces_.wrap(tree, l, at);
            out = up.first_child[q] + uint32_t((at[0] & 1) | ((at[1] & 1) << 1) | ((at[2] & 1) << 2));
        }
    }
    levels_.push_back(std::move(down));
    octants_ += count;
}

uint32_t OctreeLevels::find(uint32_t tree, int l, const int32_t c[3]) const {
    if (l > depth()) return kNoOctant;
    uint32_t n = tree;
    for (int k = 1; k <= l; ++k) {
        const uint32_t first = levels_[k - 1].first_child[n];
        if (first == kNoOctant) return kNoOctant;
        const int shift = l - k;
        n = first + uint32_t(((c[0] >> shift) & 1) | (((c[1] >> shift) & 1) << 1) | (((c[2] >> shift) & 1) << 2));
    }
    return n;
}

OctreeForest OctreeLevels::leaves(const TreeConnectivity& conn) const {
    OctreeForest forest;
    forest.connectivity = conn;
    const int d = dim(), root = octree_root_log2(d), children = 1 << d;
    forest.tree_offsets.push_back(0);
    std::vector<std::pair<int, uint32_t>> stack;  // level, octant
    for (uint32_t t = 0; t < conn.tree_count(); ++t) {
        stack.push_back({0, t});
        while (!stack.empty()) {
            const auto [l, n] = stack.back();
            stack.pop_back();
            const OctreeLevel& lv = levels_[l];
            if (lv.first_child[n] == kNoOctant) {
                Octant o;
                o.x = lv.coord[size_t(n) * 3] << (root - l);
                o.y = lv.coord[size_t(n) * 3 + 1] << (root - l);
                o.z = lv.coord[size_t(n) * 3 + 2] << (root - l);
                o.level = int8_t(l);
                forest.leaves.push_back(o);
                continue;
            }
            for (int c = children - 1; c >= 0; --c) stack.push_back({l + 1, lv.first_child[n] + uint32_t(c)});
        }
        forest.tree_offsets.push_back(forest.leaves.size());
    }
    return forest;
}

OctreeLevels octree_levels_of(const OctreeForest& forest, std::vector<std::vector<uint8_t>>* refined_out, uint64_t max_octants) {
    const int d = forest.dim(), children = 1 << d, root = octree_root_log2(d);
    OctreeLevels levels(forest.connectivity);
    // Each octant's leaves are a range of its tree's leaves; children split it by Morton keys.
    std::vector<uint64_t> keys(forest.leaves.size());
    for (size_t i = 0; i < keys.size(); ++i) keys[i] = morton(forest.leaves[i], d);
    std::vector<std::pair<uint64_t, uint64_t>> ranges;
    for (uint32_t t = 0; t < forest.tree_count(); ++t) ranges.push_back({forest.tree_offsets[t], forest.tree_offsets[t + 1]});
    for (int l = 0;; ++l) {
        const OctreeLevel& lv = levels.level(l);
        std::vector<uint8_t> refined(lv.size());
        bool any = false;
        for (size_t i = 0; i < lv.size(); ++i) {
            refined[i] = forest.leaves[ranges[i].first].level > l;
            any |= refined[i] != 0;
        }
        if (refined_out) refined_out->push_back(refined);
        if (!any) break;
        std::vector<std::pair<uint64_t, uint64_t>> next;
        const int shift = d * (root - l - 1);  // Morton bits below a child of level l + 1
        for (size_t i = 0; i < lv.size(); ++i) {
            if (!refined[i]) continue;
            const auto [begin, end] = ranges[i];
            const uint64_t base = keys[begin] >> (shift + d) << (shift + d);
            uint64_t start = begin;
            for (int c = 0; c < children; ++c) {
                const uint64_t limit = base + (uint64_t(c + 1) << shift);
                const uint64_t stop = c + 1 == children ? end
                                                         : uint64_t(std::lower_bound(keys.begin() + start, keys.begin() + end, limit) - keys.begin());
                next.push_back({start, stop});
                start = stop;
            }
        }
        levels.add_children(refined, max_octants);
        ranges = std::move(next);
    }
    return levels;
}

}  // namespace amc
