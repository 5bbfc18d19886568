// Conforming triangle / tetrahedron meshes of octree forests (conforming_leaf_mesh): cells meet
// face to face, the boundary is the forest's, every leaf is covered exactly once with positive
// cells, known counts, leaf data on every cell.
#include <amc/mesh_io.h>
#include <amc/octree.h>

#include "octree_test_util.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <map>
#include <random>
#include <unistd.h>

namespace amc {
namespace {

double det3(Vec3 a, Vec3 b, Vec3 c) {
    return a.x * (b.y * c.z - b.z * c.y) - a.y * (b.x * c.z - b.z * c.x) + a.z * (b.x * c.y - b.y * c.x);
}

double norm(Vec3 a) { return std::sqrt(dot(a, a)); }

// The measure (area, volume) of a leaf of an affine tree.
double leaf_measure(const OctreeForest& forest, uint32_t tree, const Octant& o) {
    const TreeConnectivity& conn = forest.connectivity;
    const Vec3 p0 = tree_point(conn, tree, 0, 0, 0), px = tree_point(conn, tree, 1, 0, 0) - p0,
               py = tree_point(conn, tree, 0, 1, 0) - p0;
    if (forest.dim() == 2) return norm(cross(px, py)) * std::ldexp(1.0, -2 * o.level);
    return std::abs(det3(px, py, tree_point(conn, tree, 0, 0, 1) - p0)) * std::ldexp(1.0, -3 * o.level);
}

// The facets (edges in 2D, triangles in 3D) of every cell, oriented outward, by their sorted
// points: how many cells have each, and the sum of their orientations (+1 / -1 against the sorted
// order). `ids` names the points (the points themselves, or the forest points they stand for).
std::map<std::array<uint32_t, 3>, std::pair<int, int>> facets(const ConformingLeafMesh& mesh, const std::vector<uint32_t>& ids) {
    static const int kEdges[3][2] = {{0, 1}, {1, 2}, {2, 0}};  // of a counter-clockwise triangle
    static const int kFaces[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};  // of a positive tetrahedron
    std::map<std::array<uint32_t, 3>, std::pair<int, int>> out;
    const int n = mesh.dim + 1;
    for (size_t c = 0; c < mesh.cell_count(); ++c) {
        const uint32_t* v = &mesh.cells[c * n];
        for (int f = 0; f < n; ++f) {
            std::array<uint32_t, 3> key{0, 0, 0};
            int parity = 1;
            for (int k = 0; k < mesh.dim; ++k) key[k] = ids[v[mesh.dim == 2 ? kEdges[f][k] : kFaces[f][k]]];
            for (int i = 0; i < mesh.dim; ++i)  // bubble sort, counting swaps
                for (int j = 0; j + 1 < mesh.dim - i; ++j)
                    if (key[j] > key[j + 1]) std::swap(key[j], key[j + 1]), parity = -parity;
            auto& e = out[key];
            ++e.first, e.second += parity;
        }
    }
    return out;
}

struct Summary {
    size_t cells = 0, points = 0;
};

bool affine_trees(const TreeConnectivity& conn) {
    for (uint32_t t = 0; t < conn.tree_count(); ++t) {
        const Vec3 p0 = tree_point(conn, t, 0, 0, 0);
        const Vec3 e[3] = {tree_point(conn, t, 1, 0, 0) - p0, tree_point(conn, t, 0, 1, 0) - p0, tree_point(conn, t, 0, 0, 1) - p0};
        for (int c = 0; c < (1 << conn.dim); ++c) {
            Vec3 want = p0;
            for (int a = 0; a < conn.dim; ++a)
                if (c & (1 << a)) want = want + e[a];
            if (norm(tree_point(conn, t, c & 1, (c >> 1) & 1, (c >> 2) & 1) - want) > 1e-12 * (1 + norm(p0))) return false;
        }
    }
    return true;
}

// The measure of the forest's boundary in space: the tree faces glued to nothing, and (periodic
// gluing) those glued to faces with other coarse vertices. 3D faces must be planar.
double boundary_measure(const TreeConnectivity& conn) {
    const int d = conn.dim, faces = 2 * d, corners = 1 << d;
    double sum = 0;
    for (uint32_t t = 0; t < conn.tree_count(); ++t)
        for (int f = 0; f < faces; ++f) {
            Vec3 p[4];
            std::vector<uint32_t> mine, theirs;
            for (int c = 0, k = 0; c < corners; ++c) {
                if (((c >> (f / 2)) & 1) != (f & 1)) continue;
                p[k++] = tree_point(conn, t, c & 1, (c >> 1) & 1, (c >> 2) & 1);
                if (!conn.vertices.empty()) mine.push_back(conn.tree_to_vertex[size_t(t) * corners + c]);
            }
            const uint32_t nt = conn.tree_to_tree[size_t(t) * faces + f];
            const int nf = conn.tree_to_face[size_t(t) * faces + f] % faces;
            for (int c = 0; c < corners; ++c)
                if (!conn.vertices.empty() && ((c >> (nf / 2)) & 1) == (nf & 1)) theirs.push_back(conn.tree_to_vertex[size_t(nt) * corners + c]);
            std::sort(mine.begin(), mine.end());
            std::sort(theirs.begin(), theirs.end());
            if ((nt == t && nf == f) || mine != theirs) sum += d == 2 ? norm(p[1] - p[0]) : norm(cross(p[3] - p[0], p[2] - p[1])) / 2;
        }
    return sum;
}

// Every check of a conforming mesh: positive cells, each leaf's measure exactly covered (affine
// trees), facets shared by two cells of opposite orientation or on the boundary, whose measure
// they fill exactly (a facet matched by none inside would add to it).
Summary expect_conforming(const OctreeForest& forest) {
    const ConformingLeafMesh mesh = conforming_leaf_mesh(forest);
    const int d = forest.dim(), n = d + 1;
    EXPECT_EQ(mesh.dim, d);
    EXPECT_EQ(mesh.cells.size(), mesh.cell_count() * n);
    EXPECT_EQ(mesh.forest_point.size(), mesh.points.size());
    bool planar = true;
    for (const Vec3& p : mesh.points) planar &= p.z == mesh.points[0].z;
    // Positive cells; per leaf, the cells' measures add up to the leaf's.
    std::vector<double> covered(forest.leaves.size(), 0.0);
    size_t negative = 0;
    for (size_t c = 0; c < mesh.cell_count(); ++c) {
        const uint32_t* v = &mesh.cells[c * n];
        const Vec3 a = mesh.points[v[0]], e1 = mesh.points[v[1]] - a, e2 = mesh.points[v[2]] - a;
        // A surface (p4est's cubed) has no sign to check: its triangles' area.
        const double measure = d == 3 ? det3(e1, e2, mesh.points[v[3]] - a) / 6 : planar ? (e1.x * e2.y - e1.y * e2.x) / 2 : norm(cross(e1, e2)) / 2;
        negative += measure <= 0;
        covered[mesh.leaf[c]] += measure;
    }
    EXPECT_EQ(negative, 0u) << "cells not positively oriented";
    if (affine_trees(forest.connectivity))
        for (uint32_t t = 0; t < forest.tree_count(); ++t)
            for (uint64_t i = forest.tree_offsets[t]; i < forest.tree_offsets[t + 1]; ++i) {
                const double want = leaf_measure(forest, t, forest.leaves[i]);
                EXPECT_NEAR(covered[i], want, 1e-12 * want) << "leaf " << i;
            }
    // Facets: two cells with opposite orientations, or one on the boundary.
    std::vector<uint32_t> same(mesh.points.size());
    for (uint32_t i = 0; i < same.size(); ++i) same[i] = i;
    double boundary = 0;
    size_t bad = 0, inner = 0;
    for (const auto& [key, count] : facets(mesh, same)) {
        if (count.first == 2 && count.second == 0) {
            ++inner;
            continue;
        }
        if (count.first != 1) {
            ++bad;
            continue;
        }
        const Vec3 a = mesh.points[key[0]], b = mesh.points[key[1]], c = mesh.points[key[2]];
        boundary += d == 2 ? norm(b - a) : norm(cross(b - a, c - a)) / 2;
    }
    EXPECT_EQ(bad, 0u) << "facets of more than two cells, or of two with the same orientation";
    EXPECT_GT(inner, 0u);
    const double want = boundary_measure(forest.connectivity);
    EXPECT_NEAR(boundary, want, 1e-9 * want) << "facets not matched by a neighbour cell inside the forest";
    // No hanging node: no point strictly inside a cell's edge (small meshes: every pair).
    if (mesh.points.size() < 3000) {
        std::vector<std::pair<uint32_t, uint32_t>> edges;
        for (size_t c = 0; c < mesh.cell_count(); ++c)
            for (int i = 0; i < n; ++i)
                for (int j = i + 1; j < n; ++j) edges.push_back(std::minmax(mesh.cells[c * n + i], mesh.cells[c * n + j]));
        std::sort(edges.begin(), edges.end());
        edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
        size_t hanging = 0;
        for (const auto& [i, j] : edges) {
            const Vec3 a = mesh.points[i], e = mesh.points[j] - a;
            for (uint32_t k = 0; k < mesh.corner_points; ++k) {
                const Vec3 p = mesh.points[k] - a;
                const double s = dot(p, e) / dot(e, e);
                hanging += s > 1e-9 && s < 1 - 1e-9 && norm(p - s * e) < 1e-9 * norm(e);
            }
        }
        EXPECT_EQ(hanging, 0u) << "leaf corners inside cell edges";
    }
    return {mesh.cell_count(), mesh.points.size()};
}

OctreeForest refined_in_corner(int dim) {
    const OctreeForest once = uniform_octree_forest(brick_connectivity(dim, 1, 1, 1), 1);
    return refine_octree_forest(once, [](uint32_t, const Octant& o) { return o.level == 1 && o.x == 0 && o.y == 0 && o.z == 0; }, 2);
}

TEST(OctreeConforming, OneTreeRefinedInOneCornerKnownCounts) {
    // 2D: 4 level-2 leaves (2 triangles each), the two level-1 leaves beside them with one hanging
    // node each (4 + 1 from their centre), the far one 2. Points: 14 corners + 2 centres.
    const Summary two = expect_conforming(refined_in_corner(2));
    EXPECT_EQ(two.cells, 4 * 2 + 2 * 5 + 2u);
    EXPECT_EQ(two.points, 16u);
    // 3D: 8 level-2 leaves of 12 tetrahedra; the three face neighbours of the refined child:
    // 8 (a face of four quarters) + 4 faces with a hanging node (5) + 2 = 30; the three edge
    // neighbours: 2 faces with a hanging node, 4 plain = 18; the far one 12. Points: 46 corners,
    // 15 cell centres, 12 face centres.
    const Summary three = expect_conforming(refined_in_corner(3));
    EXPECT_EQ(three.cells, 8 * 12 + 3 * 30 + 3 * 18 + 12u);
    EXPECT_EQ(three.points, 46 + 15 + 12u);
}

TEST(OctreeConforming, TwoTurnedTreesOneRefinedKnownCounts) {
    // Two trees side by side, the one at x < 1 refined once: its 2^d leaves are plain; the other's
    // face towards it is four quarters (3D) and its faces beside that have one hanging node each.
    for (int dim = 2; dim <= 3; ++dim)
        for (uint64_t seed = 1; seed <= 6; ++seed) {
            std::mt19937_64 rng(seed);
            const TreeConnectivity conn = octree_test::turned_brick(dim, 2, 1, 1, rng);
            const OctreeForest forest = refine_octree_forest(
                uniform_octree_forest(conn, 0), [&](uint32_t t, const Octant&) { return tree_point(conn, t, 0.5, 0.5, 0.5).x < 1; }, 1);
            SCOPED_TRACE("dim " + std::to_string(dim) + " seed " + std::to_string(seed));
            const Summary s = expect_conforming(forest);
            if (dim == 2) {
                EXPECT_EQ(s.cells, 4 * 2 + 5u);
                EXPECT_EQ(s.points, 9 + 2 + 1u);
            } else {
                EXPECT_EQ(s.cells, 8 * 12 + 8 + 4 * 5 + 2u);
                EXPECT_EQ(s.points, 27 + 4 + 9 + 4u);
            }
        }
}

TEST(OctreeConforming, TreesMeetingOnlyAtAnEdgeOrACorner) {
    // Through the coarse vertices: 2D, two squares sharing only the vertex (1, 1) share that point;
    // 3D, two cubes sharing only the edge x = y = 1, the first refined once: the edge's midpoint
    // is a vertex of the second cube's cells too (its two faces there have one hanging node each:
    // 5 + 5 + 4 * 2 tetrahedra).
    for (int dim = 2; dim <= 3; ++dim) {
        std::vector<Vec3> vertices;
        std::vector<uint32_t> tree_to_vertex;
        for (int t = 0; t < 2; ++t)
            for (int c = 0; c < (1 << dim); ++c) {
                const Vec3 p{double(t + (c & 1)), double(t + ((c >> 1) & 1)), double((c >> 2) & 1)};
                const auto it = std::find(vertices.begin(), vertices.end(), p);
                tree_to_vertex.push_back(uint32_t(it - vertices.begin()));
                if (it == vertices.end()) vertices.push_back(p);
            }
        const TreeConnectivity conn = connectivity_from_vertices(dim, vertices, tree_to_vertex);
        const OctreeForest forest = refine_octree_forest(uniform_octree_forest(conn, 0), [](uint32_t t, const Octant&) { return t == 0; }, 1);
        SCOPED_TRACE("dim " + std::to_string(dim));
        const Summary s = expect_conforming(forest);
        EXPECT_EQ(s.cells, dim == 2 ? 4 * 2 + 2u : 8 * 12 + 5 + 5 + 4 * 2u);
        EXPECT_EQ(s.points, dim == 2 ? 9 + 3u : 27 + 6 + 9 + 2u);
    }
}

TEST(OctreeConforming, RandomForestsOfEveryBalanceAndConnectivity) {
    std::mt19937_64 rng(28);
    for (int round = 0; round < 24; ++round) {
        const int dim = 2 + round % 2;
        const OctreeBalance balance = OctreeBalance((round / 2) % 3 + 1);
        const OctreeForest forest = octree_test::random_balanced_forest(dim, rng, balance);
        SCOPED_TRACE("round " + std::to_string(round));
        expect_conforming(forest);
    }
}

// p4est's coarse meshes with vertices where three, five or six trees meet (star, cubed, disk)
// and turned or glued cubes. (Not the Moebius strip: no orientation fits it.)
TEST(OctreeConforming, IrregularCoarseMeshesOfP4est) {
    if (!octree_p4est_available()) GTEST_SKIP() << "built without p4est (cmake -DAMC_WITH_P4EST=ON, libp4est-dev)";
    uint64_t seed = 3;
    for (const auto& [dim, name] : std::vector<std::pair<int, std::string>>{
             {2, "star"}, {2, "corner"}, {2, "cubed"}, {2, "disk"}, {3, "rotcubes"}, {3, "twocubes"}, {3, "brick235"}}) {
        const TreeConnectivity conn = p4est_builtin_connectivity(dim, name);
        for (OctreeBalance balance : {OctreeBalance::face, OctreeBalance::corner}) {
            SCOPED_TRACE(name + " balance " + std::to_string(int(balance)));
            expect_conforming(balance_octree_forest(random_octree_forest(conn, seed++, dim == 2 ? 0.3 : 0.2, 1, dim == 2 ? 5 : 3), balance));
        }
    }
}

TEST(OctreeConforming, UnbalancedForestsToo) {
    std::mt19937_64 rng(7);
    for (int dim = 2; dim <= 3; ++dim) {
        const TreeConnectivity conn = octree_test::turned_brick(dim, 2, 2, 1, rng);
        const OctreeForest forest = random_octree_forest(conn, rng(), 0.4, 1, dim == 2 ? 7 : 4);
        ASSERT_FALSE(octree_balance_violation(forest, OctreeBalance::face).empty());
        expect_conforming(forest);
    }
}

TEST(OctreeConforming, PeriodicGluingKeepsBothSidesAlike) {
    // Fully periodic: in space the periodic faces are boundary (checked above); as points of the
    // forest every facet is shared by two cells of opposite orientation.
    for (int dim = 2; dim <= 3; ++dim) {
        const TreeConnectivity conn = brick_connectivity(dim, 2, 1, 1, true, true, true);
        const OctreeForest forest = balance_octree_forest(
            sphere_octree_forest(conn, {0.1, 0.2, 0.3}, 0.3, dim == 2 ? 6 : 4), OctreeBalance::face);
        expect_conforming(forest);
        const ConformingLeafMesh mesh = conforming_leaf_mesh(forest);
        EXPECT_LT(*std::max_element(mesh.forest_point.begin(), mesh.forest_point.end()), mesh.points.size() - 1) << "no point glued";
        for (const auto& [key, count] : facets(mesh, mesh.forest_point)) {
            ASSERT_EQ(count.first, 2) << key[0] << " " << key[1] << " " << key[2];
            ASSERT_EQ(count.second, 0);
        }
    }
}

TEST(OctreeConforming, VtuCellsCarryTheirLeafsData) {
    OctreeForest forest = balance_octree_forest(sphere_octree_forest(brick_connectivity(2, 2, 1), {1, 0.5, 0}, 0.3, 5), OctreeBalance::face);
    Field u{"u", FieldAssociation::cell, FieldType::float64, 2, {}, {}};
    for (size_t i = 0; i < forest.leaves.size(); ++i) {
        u.values.push_back(0.5 * double(i));
        u.values.push_back(-double(forest.leaves[i].level));
    }
    forest.leaf_data.push_back(u);
    const std::string path =
        (std::filesystem::temp_directory_path() / ("amc_conforming_" + std::to_string(::getpid()) + ".vtu")).string();
    write_octree_vtu(path, forest, VtuEncoding::binary_zlib, OctreeVtuCells::conforming);
    const VtuMesh back = read_vtu(path);  // triangles: our reader reads them back
    std::filesystem::remove(path);
    const ConformingLeafMesh mesh = conforming_leaf_mesh(forest);
    ASSERT_EQ(back.mesh.triangles.size(), mesh.cell_count());
    ASSERT_EQ(back.mesh.positions.size(), mesh.points.size());
    const DataArray* leaf = nullptr, *values = nullptr, *level = nullptr, *added = nullptr;
    for (const DataArray& a : back.cell_data) {
        if (a.name == "leaf") leaf = &a;
        if (a.name == "u") values = &a;
        if (a.name == "level") level = &a;
    }
    for (const DataArray& a : back.point_data)
        if (a.name == "added_point") added = &a;
    ASSERT_TRUE(leaf && values && level && added);
    ASSERT_EQ(values->components, 2u);
    for (size_t c = 0; c < mesh.cell_count(); ++c) {
        const size_t i = mesh.leaf[c];
        ASSERT_EQ(leaf->value(c), double(i));
        ASSERT_EQ(values->value(2 * c), 0.5 * double(i));
        ASSERT_EQ(values->value(2 * c + 1), -double(forest.leaves[i].level));
        ASSERT_EQ(level->value(c), double(forest.leaves[i].level));
    }
    for (size_t p = 0; p < mesh.points.size(); ++p) ASSERT_EQ(added->value(p), p < mesh.corner_points ? 0.0 : 1.0);
}

}  // namespace
}  // namespace amc
