// The forest model: p4est's orientation rule, gluing by vertices, neighbours across turned trees,
// validation, balance against a brute-force check.
#include "octree/octree_levels.h"
#include "octree/tree_faces.h"
#include "octree_test_util.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace amc {
namespace {

using octree_test::turned_brick;

TEST(OctreeConnectivity, EveryOrientationHasOnePermutationAndBack) {
    for (int dim : {2, 3}) {
        for (int f = 0; f < 2 * dim; ++f) {
            for (int nf = 0; nf < 2 * dim; ++nf) {
                for (int o = 0; o < octree_orientations(dim); ++o) {
                    FaceCornerPerm perm{};
                    ASSERT_TRUE(face_corner_perm(dim, f, nf, o, perm)) << dim << " " << f << " " << nf << " " << o;
                    EXPECT_EQ(face_orientation(dim, f, nf, perm), o);
                    // Seen from the other side: the inverse permutation, the same orientation.
                    FaceCornerPerm inv{};
                    for (int i = 0; i < (1 << (dim - 1)); ++i) inv[perm[i]] = uint8_t(i);
                    EXPECT_EQ(face_orientation(dim, nf, f, inv), o) << dim << " " << f << " " << nf << " " << o;
                }
            }
        }
    }
}

TEST(OctreeConnectivity, KnownOrientations) {
    // Side by side: face 1 meets face 0 straight (orientation 0).
    const TreeConnectivity brick = brick_connectivity(2, 2, 1);
    EXPECT_EQ(brick.tree_to_tree[1], 1u);
    EXPECT_EQ(brick.tree_to_face[1], 0);
    EXPECT_EQ(connectivity_from_vertices(2, brick.vertices, brick.tree_to_vertex).tree_to_face, brick.tree_to_face);
    // Tree 1 turned by 180 degrees: face 1 meets face 1 (its old face 0), corners reversed: orientation 1.
    std::vector<uint32_t> t2v = brick.tree_to_vertex;
    std::swap(t2v[4], t2v[7]);
    std::swap(t2v[5], t2v[6]);
    const TreeConnectivity turned = connectivity_from_vertices(2, brick.vertices, t2v);
    EXPECT_EQ(turned.tree_to_tree[1], 1u);
    EXPECT_EQ(turned.tree_to_face[1], 1 + 4 * 1);
    EXPECT_EQ(turned.tree_to_face[4 + 1], 1 + 4 * 1);
    // 3D, tree 1 turned a quarter about x: its face 0 still meets tree 0's face 1. The lower face is
    // tree 1's face 0; its face corner 0, tree 1's (0, 0, 0), lies at (1, 1, 0), which is face corner
    // 1 of tree 0's face 1: orientation 1.
    const TreeConnectivity cube = brick_connectivity(3, 2, 1, 1);
    std::vector<uint32_t> q = cube.tree_to_vertex;
    for (int c = 0; c < 8; ++c) {
        // New corner c = (x, y, z) sits at old (x, 1 - z, y).
        const int x = c & 1, y = (c >> 1) & 1, z = (c >> 2) & 1;
        q[8 + c] = cube.tree_to_vertex[8 + (x | ((1 - z) << 1) | (y << 2))];
    }
    const TreeConnectivity quarter = connectivity_from_vertices(3, cube.vertices, q);
    EXPECT_EQ(quarter.tree_to_tree[1], 1u);
    EXPECT_EQ(quarter.tree_to_face[1], 0 + 6 * 1);
    EXPECT_EQ(quarter.tree_to_face[6 + 0], 1 + 6 * 1);
}

TEST(OctreeConnectivity, LeftHandedAndNonManifoldRefused) {
    const TreeConnectivity cube = brick_connectivity(3, 2, 1, 1);
    std::vector<uint32_t> mirrored = cube.tree_to_vertex;
    for (int c = 0; c < 8; c += 2) std::swap(mirrored[8 + c], mirrored[8 + c + 1]);  // tree 1 mirrored in x
    EXPECT_THROW(connectivity_from_vertices(3, cube.vertices, mirrored), Error);
    // In 2D a mirrored tree is fine (p4est's Moebius strip has one): orientation 1.
    TreeConnectivity brick = brick_connectivity(2, 2, 1);
    std::vector<uint32_t> flat = brick.tree_to_vertex;
    std::swap(flat[4], flat[5]);
    std::swap(flat[6], flat[7]);
    EXPECT_EQ(connectivity_from_vertices(2, brick.vertices, flat).tree_to_face[1], 1 + 4 * 0);
    std::vector<uint32_t> three = brick.tree_to_vertex;
    three.insert(three.end(), {1, 4, 2, 5});  // a third tree on the shared face
    EXPECT_THROW(connectivity_from_vertices(2, brick.vertices, three), Error);
    TreeConnectivity bad = brick;
    bad.tree_to_face[1] = 0 + 4;  // not what tree 1 says back
    EXPECT_THROW(validate_connectivity(bad, "test"), Error);
    bad = brick;
    bad.tree_to_tree[1] = 7;
    EXPECT_THROW(validate_connectivity(bad, "test"), Error);
}

// Every neighbour the levels find across turned trees touches the octant along a whole face: the
// face's corners, mapped by tree_point (exact on integer vertices), are those of a face of it.
TEST(OctreeConnectivity, NeighboursAcrossTurnedTreesShareTheFace) {
    std::mt19937_64 rng(5);
    for (int round = 0; round < 30; ++round) {
        const int dim = 2 + round % 2;
        const TreeConnectivity conn = turned_brick(dim, 2 + int(rng() % 2), 2, dim == 3 ? 2 : 1, rng);
        validate_connectivity(conn, "turned");
        const OctreeForest forest = uniform_octree_forest(conn, 2);
        std::vector<std::vector<uint8_t>> refined;
        const OctreeLevels levels = octree_levels_of(forest, &refined, UINT64_MAX);
        for (int l = 0; l <= levels.depth(); ++l) {
            const OctreeLevel& lv = levels.level(l);
            const double len = std::ldexp(1.0, -l);
            auto corner = [&](uint32_t n, int c) {
                return tree_point(conn, lv.tree[n], (lv.coord[3 * n] + (c & 1)) * len, (lv.coord[3 * n + 1] + ((c >> 1) & 1)) * len,
                                  (lv.coord[3 * n + 2] + ((c >> 2) & 1)) * len);
            };
            auto face_points = [&](uint32_t n, int f) {
                std::vector<std::array<double, 3>> pts;
                for (int c = 0; c < (1 << dim); ++c)
                    if (((c >> (f / 2)) & 1) == (f & 1)) {
                        const Vec3 p = corner(n, c);
                        pts.push_back({p.x, p.y, p.z});
                    }
                std::sort(pts.begin(), pts.end());
                return pts;
            };
            for (uint32_t n = 0; n < lv.size(); ++n) {
                for (int f = 0; f < 2 * dim; ++f) {
                    const uint32_t q = lv.neighbor[n * 2 * dim + f];
                    if (q == kTreeBoundary) continue;
                    ASSERT_TRUE(is_octant(q));
                    const auto mine = face_points(n, f);
                    bool found = false;
                    for (int g = 0; g < 2 * dim; ++g) found |= face_points(q, g) == mine;
                    ASSERT_TRUE(found) << "round " << round << " level " << l << " octant " << n << " face " << f;
                }
            }
        }
    }
}

TEST(OctreeForest, ValidationRefusesGapsOverlapsAndBadLevels) {
    const TreeConnectivity conn = brick_connectivity(2, 1, 1);
    OctreeForest forest = uniform_octree_forest(conn, 1);
    EXPECT_NO_THROW(validate_octree_forest(forest, "ok"));
    OctreeForest gap = forest;
    gap.leaves.erase(gap.leaves.begin() + 1);
    gap.tree_offsets[1] = 3;
    EXPECT_THROW(validate_octree_forest(gap, "gap"), Error);
    OctreeForest swapped = forest;
    std::swap(swapped.leaves[1], swapped.leaves[2]);
    EXPECT_THROW(validate_octree_forest(swapped, "order"), Error);
    OctreeForest misaligned = forest;
    misaligned.leaves[1].x += 1;
    EXPECT_THROW(validate_octree_forest(misaligned, "aligned"), Error);
    OctreeForest deep = uniform_octree_forest(conn, 0);
    deep.leaves[0].level = 30;
    EXPECT_THROW(validate_octree_forest(deep, "level"), Error);
    OctreeForest offsets = forest;
    offsets.tree_offsets = {0, 3};
    EXPECT_THROW(validate_octree_forest(offsets, "offsets"), Error);
}

TEST(OctreeForest, CountsAndLevelsRoundTrip) {
    std::mt19937_64 rng(11);
    for (int round = 0; round < 40; ++round) {
        const OctreeForest forest = octree_test::random_balanced_forest(2 + round % 2, rng);
        std::vector<std::vector<uint8_t>> refined;
        const OctreeLevels levels = octree_levels_of(forest, &refined, UINT64_MAX);
        EXPECT_EQ(levels.octant_count(), count_octree_forest(forest).nodes);
        EXPECT_TRUE(levels.leaves(forest.connectivity) == forest);
    }
}

// Brute force on one tree: leaves as boxes; two leaves sharing part of a face differ by at most a level.
std::string brute_force_face_violation(const OctreeForest& f) {
    const int dim = f.dim(), root = octree_root_log2(dim);
    for (const Octant& a : f.leaves)
        for (const Octant& b : f.leaves) {
            if (b.level <= a.level + 1) continue;
            const int64_t la = int64_t(1) << (root - a.level), lb = int64_t(1) << (root - b.level);
            const int64_t ca[3] = {a.x, a.y, a.z}, cb[3] = {b.x, b.y, b.z};
            int touching = 0, overlapping = 0;
            for (int k = 0; k < dim; ++k) {
                if (ca[k] + la == cb[k] || cb[k] + lb == ca[k]) ++touching;
                else if (ca[k] < cb[k] + lb && cb[k] < ca[k] + la) ++overlapping;
            }
            if (touching == 1 && overlapping == dim - 1) return "violation";
        }
    return "";
}

TEST(OctreeBalance, MatchesBruteForceAndIsMinimalClosure) {
    std::mt19937_64 rng(3);
    int unbalanced = 0;
    for (int round = 0; round < 60; ++round) {
        const int dim = 2 + round % 2;
        const TreeConnectivity conn = brick_connectivity(dim, 1, 1, 1);
        const OctreeForest raw = random_octree_forest(conn, rng(), 0.35, 1, dim == 2 ? 6 : 4);
        const bool violated = !octree_balance_violation(raw, OctreeBalance::face).empty();
        EXPECT_EQ(violated, !brute_force_face_violation(raw).empty()) << round;
        unbalanced += violated;
        const OctreeForest balanced = balance_octree_forest(raw, OctreeBalance::face);
        EXPECT_EQ(octree_balance_violation(balanced, OctreeBalance::face), "");
        EXPECT_EQ(brute_force_face_violation(balanced), "");
        EXPECT_TRUE(balance_octree_forest(balanced, OctreeBalance::face) == balanced);
        if (!violated) {
            EXPECT_TRUE(balanced == raw);
        }
        // A refinement of the input: every input leaf is covered by leaves at least as fine.
        EXPECT_GE(balanced.leaves.size(), raw.leaves.size());
        const OctreeForest corner = balance_octree_forest(raw, OctreeBalance::corner);
        EXPECT_EQ(octree_balance_violation(corner, OctreeBalance::corner), "");
        EXPECT_EQ(octree_balance_violation(corner, OctreeBalance::face), "");
        EXPECT_GE(corner.leaves.size(), balanced.leaves.size());
    }
    EXPECT_GT(unbalanced, 20);
}

TEST(OctreeBalance, AcrossTurnedAndPeriodicTrees) {
    std::mt19937_64 rng(17);
    for (int round = 0; round < 40; ++round) {
        const int dim = 2 + round % 2;
        const OctreeForest f = octree_test::random_balanced_forest(dim, rng, round % 4 == 0 ? OctreeBalance::corner : OctreeBalance::face);
        EXPECT_EQ(octree_balance_violation(f, OctreeBalance::face), "");
        EXPECT_NO_THROW(validate_octree_forest(f, "balanced"));
    }
}

// Trees that meet only at a corner (2D: two squares touching at one vertex; 3D: two cubes sharing
// one edge) constrain each other under corner (3D: edge) balance, and only then.
TEST(OctreeBalance, TreesMeetingOnlyAtACornerOrAnEdge) {
    for (int dim : {2, 3}) {
        std::vector<Vec3> vertices;
        std::vector<uint32_t> t2v;
        for (int t = 0; t < 2; ++t)
            for (int c = 0; c < (1 << dim); ++c) {
                // Tree 1 is tree 0 moved by (1, 1, 0): they share the vertex (1, 1) in 2D, the edge
                // x = y = 1 in 3D.
                const Vec3 p{double((c & 1) + t), double(((c >> 1) & 1) + t), double((c >> 2) & 1)};
                uint32_t v = 0;
                while (v < vertices.size() && !(vertices[v].x == p.x && vertices[v].y == p.y && vertices[v].z == p.z)) ++v;
                if (v == vertices.size()) vertices.push_back(p);
                t2v.push_back(v);
            }
        const TreeConnectivity conn = connectivity_from_vertices(dim, vertices, t2v);
        for (size_t i = 0; i < conn.tree_to_tree.size(); ++i) EXPECT_EQ(conn.tree_to_tree[i], i / (2 * dim)) << "no face is shared";
        // Tree 0 refined to level 4 at its corner (1, 1, 0).
        const int root = octree_root_log2(dim), level = dim == 2 ? 4 : 3;
        const OctreeForest raw = refine_octree_forest(
            uniform_octree_forest(conn, 0),
            [&](uint32_t tree, const Octant& o) {
                const int32_t len = int32_t(1) << (root - o.level);
                return tree == 0 && o.x + len == (int32_t(1) << root) && o.y + len == (int32_t(1) << root) && o.z == 0;
            },
            level);
        const OctreeBalance across = dim == 2 ? OctreeBalance::corner : OctreeBalance::edge;
        EXPECT_EQ(octree_balance_violation(raw, OctreeBalance::face), "");
        const std::string violation = octree_balance_violation(raw, across);
        EXPECT_NE(violation.find("in tree 1"), std::string::npos) << violation;
        // Face balance leaves tree 1 alone; corner / edge balance grades it down to level - 1 at (0, 0, 0).
        const OctreeForest by_face = balance_octree_forest(raw, OctreeBalance::face);
        EXPECT_EQ(by_face.tree_offsets[2] - by_face.tree_offsets[1], 1u);
        const OctreeForest balanced = balance_octree_forest(raw, across);
        EXPECT_EQ(octree_balance_violation(balanced, across), "");
        EXPECT_EQ(balanced.leaves[balanced.tree_offsets[1]].level, level - 1) << "dim " << dim;
    }
}

TEST(OctreeForest, GeneratorsRefineWhereAsked) {
    const TreeConnectivity conn = brick_connectivity(2, 2, 2);
    const OctreeForest circle = sphere_octree_forest(conn, {1, 1, 0}, 0.7, 6);
    EXPECT_EQ(count_octree_forest(circle).depth, 6);
    // The finest leaves hug the circle.
    const int root = octree_root_log2(2);
    for (uint32_t t = 0; t < circle.tree_count(); ++t)
        for (uint64_t i = circle.tree_offsets[t]; i < circle.tree_offsets[t + 1]; ++i) {
            const Octant& o = circle.leaves[i];
            if (o.level < 6) continue;
            const double len = std::ldexp(1.0, -o.level);
            const Vec3 c = tree_point(conn, t, std::ldexp(o.x, -root) + len / 2, std::ldexp(o.y, -root) + len / 2, 0);
            EXPECT_NEAR(std::hypot(c.x - 1, c.y - 1), 0.7, 2 * len);
        }
    const OctreeForest front = front_octree_forest(brick_connectivity(3, 1, 1, 1), 0.5, 5);
    EXPECT_EQ(count_octree_forest(front).depth, 5);
}

}  // namespace
}  // namespace amc
