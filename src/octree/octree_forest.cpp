// Forests of quadtrees and octrees: validity, counts, and the refinement generators for tests and
// benchmarks (uniform, around a sphere, a moving front, random).
#include "octree/octree_levels.h"

#include "common/check.h"
#include "common/exact_float.h"
#include "common/mixing.h"
#include "octree/octree_leaf_data.h"

#include <algorithm>
#include <cmath>

namespace amc {

bool operator==(const OctreeForest& a, const OctreeForest& b) {
    const TreeConnectivity &x = a.connectivity, &y = b.connectivity;
    return x.dim == y.dim && x.vertices == y.vertices && x.tree_to_vertex == y.tree_to_vertex &&
           x.tree_to_tree == y.tree_to_tree && x.tree_to_face == y.tree_to_face && a.tree_offsets == b.tree_offsets &&
           a.leaves == b.leaves && a.leaf_data.size() == b.leaf_data.size() &&
           std::equal(a.leaf_data.begin(), a.leaf_data.end(), b.leaf_data.begin(), identical);
}

void validate_octree_forest(const OctreeForest& forest, const std::string& what) {
    validate_connectivity(forest.connectivity, what);
    const int d = forest.dim(), root = octree_root_log2(d), max_level = octree_max_level(d);
    const uint32_t trees = forest.tree_count();
    AMC_REQUIRE(forest.tree_offsets.size() == size_t(trees) + 1 && forest.tree_offsets[0] == 0 &&
                    forest.tree_offsets.back() == forest.leaves.size(),
                invalid_input, what + ": tree_offsets must hold trees + 1 offsets from 0 to the number of leaves");
    for (uint32_t t = 0; t < trees; ++t) {
        const uint64_t begin = forest.tree_offsets[t], end = forest.tree_offsets[t + 1];
        AMC_REQUIRE(begin < end && end <= forest.leaves.size(), invalid_input,
                    what + ": tree " + std::to_string(t) + " has no leaves (or offsets out of order)");
        // Morton order without gaps: each leaf starts where the one before ended.
        uint64_t expected = 0;  // Morton position in units of the finest octant
        for (uint64_t i = begin; i < end; ++i) {
            const Octant& o = forest.leaves[i];
            const std::string where = what + ": tree " + std::to_string(t) + " leaf " + std::to_string(i - begin);
            AMC_REQUIRE(o.level >= 0 && o.level <= max_level, invalid_input, where + " has level " + std::to_string(o.level));
            const int32_t len = int32_t(1) << (root - o.level);
            const int32_t c[3] = {o.x, o.y, d == 3 ? o.z : 0};
            AMC_REQUIRE(d == 3 || o.z == 0, invalid_input, where + ": z is not 0 in 2D");
            for (int a = 0; a < d; ++a)
                AMC_REQUIRE(c[a] >= 0 && c[a] < (int32_t(1) << root) && c[a] % len == 0, invalid_input,
                            where + ": coordinate " + std::to_string(c[a]) + " is outside the tree or not aligned to level " +
                                std::to_string(o.level));
            uint64_t key = 0;
            for (int b = root - 1; b >= 0; --b)
                for (int a = d - 1; a >= 0; --a) key = (key << 1) | ((uint32_t(c[a]) >> b) & 1);
            AMC_REQUIRE(key == expected, invalid_input,
                        where + (key < expected ? " overlaps the leaves before it or is out of Morton order"
                                                : " leaves a gap after the leaves before it"));
            expected += uint64_t(1) << (d * (root - o.level));
        }
        AMC_REQUIRE(expected == uint64_t(1) << (d * root), invalid_input, what + ": the leaves of tree " + std::to_string(t) + " do not cover it");
    }
    validate_leaf_fields(forest.leaf_data, forest.leaves.size(), what);
}

OctreeForestCounts count_octree_forest(const OctreeForest& forest) {
    OctreeForestCounts counts;
    counts.leaves = forest.leaves.size();
    for (const Octant& o : forest.leaves) counts.depth = std::max(counts.depth, int(o.level));
    // A full 2^d-ary tree with L leaves has (L - 1) / (2^d - 1) inner nodes.
    counts.nodes = counts.leaves + (counts.leaves - forest.tree_count()) / ((uint64_t(1) << forest.dim()) - 1);
    return counts;
}

OctreeForest uniform_octree_forest(const TreeConnectivity& conn, int level, uint64_t max_leaves) {
    OctreeForest roots;
    roots.connectivity = conn;
    for (uint32_t t = 0; t <= conn.tree_count(); ++t) roots.tree_offsets.push_back(t);
    roots.leaves.assign(conn.tree_count(), Octant{});
    return refine_octree_forest(roots, [](uint32_t, const Octant&) { return true; }, level, max_leaves);
}

OctreeForest refine_octree_forest(const OctreeForest& forest, const std::function<bool(uint32_t, const Octant&)>& refine,
                                  int max_level, uint64_t max_leaves) {
    validate_octree_forest(forest, "refine_octree_forest");
    const int d = forest.dim(), root = octree_root_log2(d);
    max_level = std::min(max_level, octree_max_level(d));
    OctreeForest out;
    out.connectivity = forest.connectivity;
    out.tree_offsets.push_back(0);
    std::vector<Octant> stack;
    for (uint32_t t = 0; t < forest.tree_count(); ++t) {
        for (uint64_t i = forest.tree_offsets[t]; i < forest.tree_offsets[t + 1]; ++i) {
            stack.push_back(forest.leaves[i]);
            while (!stack.empty()) {
                const Octant o = stack.back();
                stack.pop_back();
                if (o.level >= max_level || !refine(t, o)) {
                    AMC_REQUIRE(out.leaves.size() < max_leaves, limit_exceeded,
                                "forest: more than " + std::to_string(max_leaves) + " leaves");
                    out.leaves.push_back(o);
                    continue;
                }
                const int32_t half = int32_t(1) << (root - o.level - 1);
                for (int c = (1 << d) - 1; c >= 0; --c) {
                    Octant child = o;
                    child.level = int8_t(o.level + 1);
                    child.x += (c & 1) ? half : 0;
                    child.y += (c & 2) ? half : 0;
                    child.z += (c & 4) ? half : 0;
                    stack.push_back(child);
                }
            }
        }
        out.tree_offsets.push_back(out.leaves.size());
    }
    return out;
}

Vec3 tree_point(const TreeConnectivity& conn, uint32_t tree, double u, double v, double w) {
    if (conn.vertices.empty()) return {u, v, conn.dim == 3 ? w : 0.0};
    const int corners = 1 << conn.dim;
    Vec3 p;
    for (int c = 0; c < corners; ++c) {
        const double weight = rounded(rounded(((c & 1) ? u : 1 - u) * ((c & 2) ? v : 1 - v)) * (conn.dim == 3 ? ((c & 4) ? w : 1 - w) : 1.0));
        p = p + rounded_scaled(weight, conn.vertices[conn.tree_to_vertex[size_t(tree) * corners + c]]);
    }
    return p;
}

namespace {

// The corners of an octant in space.
int octant_corners(const TreeConnectivity& conn, uint32_t tree, const Octant& o, Vec3 out[8]) {
    const int d = conn.dim, root = octree_root_log2(d);
    const double scale = std::ldexp(1.0, -root), len = std::ldexp(1.0, -o.level);
    for (int c = 0; c < (1 << d); ++c)
        out[c] = tree_point(conn, tree, rounded(o.x * scale) + ((c & 1) ? len : 0), rounded(o.y * scale) + ((c & 2) ? len : 0),
                            rounded(o.z * scale) + ((c & 4) ? len : 0));
    return 1 << d;
}

}  // namespace

OctreeForest sphere_octree_forest(const TreeConnectivity& conn, Vec3 center, double radius, int max_level, uint64_t max_leaves) {
    return refine_octree_forest(uniform_octree_forest(conn, 0),
                                [&](uint32_t t, const Octant& o) {
                                    Vec3 p[8];
                                    const int n = octant_corners(conn, t, o, p);
                                    Vec3 lo = p[0], hi = p[0];
                                    for (int i = 1; i < n; ++i) {
                                        lo = {std::min(lo.x, p[i].x), std::min(lo.y, p[i].y), std::min(lo.z, p[i].z)};
                                        hi = {std::max(hi.x, p[i].x), std::max(hi.y, p[i].y), std::max(hi.z, p[i].z)};
                                    }
                                    // Nearest and farthest points of the box from the centre.
                                    auto clamp = [](double x, double a, double b) { return std::max(a, std::min(b, x)); };
                                    const Vec3 near{clamp(center.x, lo.x, hi.x), clamp(center.y, lo.y, hi.y), clamp(center.z, lo.z, hi.z)};
                                    const Vec3 far{std::abs(center.x - lo.x) > std::abs(center.x - hi.x) ? lo.x : hi.x,
                                                   std::abs(center.y - lo.y) > std::abs(center.y - hi.y) ? lo.y : hi.y,
                                                   std::abs(center.z - lo.z) > std::abs(center.z - hi.z) ? lo.z : hi.z};
                                    const double dn = std::sqrt(exact_dot(near - center, near - center));
                                    const double df = std::sqrt(exact_dot(far - center, far - center));
                                    return dn <= radius && radius <= df;
                                },
                                max_level, max_leaves);
}

OctreeForest front_octree_forest(const TreeConnectivity& conn, double t, int max_level, uint64_t max_leaves) {
    return refine_octree_forest(uniform_octree_forest(conn, 0),
                                [&](uint32_t tree, const Octant& o) {
                                    Vec3 p[8];
                                    const int n = octant_corners(conn, tree, o, p);
                                    Vec3 mid;
                                    for (int i = 0; i < n; ++i) mid = mid + rounded_scaled(1.0 / n, p[i]);
                                    const Vec3 diag = p[n - 1] - p[0];
                                    const double size = std::sqrt(exact_dot(diag, diag));
                                    const double phi = mid.x + rounded(0.3 * std::sin(4 * mid.y)) + rounded(0.2 * std::cos(3 * mid.z)) - t;
                                    // A band of about two octants at every level: graded towards the front.
                                    return std::abs(phi) < 1.2 * size;
                                },
                                max_level, max_leaves);
}

OctreeForest random_octree_forest(const TreeConnectivity& conn, uint64_t seed, double p, int min_level, int max_level,
                                  uint64_t max_leaves) {
    SplitMix64 random{seed * kGoldenGamma + 1};
    return refine_octree_forest(uniform_octree_forest(conn, 0),
                                [&](uint32_t, const Octant& o) { return o.level < min_level || random.unit() < p; },
                                max_level, max_leaves);
}

}  // namespace amc
