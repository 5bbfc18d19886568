// The leaves of a forest as a conforming triangle or tetrahedron mesh (docs/OCTREE.md,
// "Conforming leaf meshes"). Every face of a leaf (every edge in 2D) is cut at every leaf corner
// on it, so hanging nodes become ordinary vertices. 3D: each square face of a leaf is
// triangulated by a rule both leaves beside it evaluate alike — the union of its four quarters
// when a leaf on either side is finer there (its centre is a leaf corner), else split by the
// diagonal through its corner of smallest point id when no leaf corner lies on its edges, else
// fanned from its centre — and the hexahedron is the cone of its centre over those triangles.
// 2D: the leaf is split by a diagonal when no leaf corner lies on its edges, else fanned from its
// centre. Leaf corners on an edge are found by halving: if any lies strictly inside a dyadic
// segment of a leaf edge, its midpoint is one (the octant of that segment's length holding it is
// refined), so the recursion stops at the first midpoint that is not a leaf corner.
#include <amc/mesh_io.h>

#include "common/check.h"
#include "common/no_index.h"
#include "octree/forest_points.h"

#include <algorithm>
#include <array>
#include <cstdlib>

namespace amc {

namespace {

using Lattice = std::array<int64_t, 3>;

// 2D trees may be of either hand (p4est's Moebius strip): +1 or -1 per tree, so that triangles
// counter-clockwise in their tree's frame times its hand are oriented alike across every gluing
// (a Moebius strip has no such choice; the first found is kept). Each connected part starts from
// its first tree, whose hand makes its triangles counter-clockwise in the xy-plane when it is not
// perpendicular to it (a planar forest's triangles all have positive area).
std::vector<int> tree_hands(const TreeConnectivity& conn) {
    static const int kTraversal[4] = {-1, 1, 1, -1};  // face corner order of a counter-clockwise walk, per face
    std::vector<int> hand(conn.tree_count(), 0);
    for (uint32_t seed = 0; seed < conn.tree_count(); ++seed) {
        if (hand[seed] != 0) continue;
        const Vec3 p0 = tree_point(conn, seed, 0, 0, 0), u = tree_point(conn, seed, 1, 0, 0) - p0, v = tree_point(conn, seed, 0, 1, 0) - p0;
        hand[seed] = u.x * v.y - u.y * v.x < 0 ? -1 : 1;
        std::vector<uint32_t> stack{seed};
        while (!stack.empty()) {
            const uint32_t t = stack.back();
            stack.pop_back();
            for (int f = 0; f < 4; ++f) {
                const uint32_t nt = conn.tree_to_tree[size_t(t) * 4 + f];
                const int nf = conn.tree_to_face[size_t(t) * 4 + f] % 4, reversed = conn.tree_to_face[size_t(t) * 4 + f] / 4;
                if (hand[nt] != 0) continue;
                // The two walks pass the shared side in opposite directions.
                hand[nt] = -hand[t] * kTraversal[f] * kTraversal[nf] * (reversed ? -1 : 1);
                stack.push_back(nt);
            }
        }
    }
    return hand;
}

struct Vertex {
    Lattice p;
    ForestPoints::Point point;
};

class Extraction {
public:
    Extraction(const OctreeForest& forest, ConformingLeafMesh& out) : forest_(forest), out_(out), points_(forest.connectivity) {
        if (forest.dim() == 2) hand_ = tree_hands(forest.connectivity);
    }

    void run() {
        const int d = forest_.dim();
        // About 1.1 corners per leaf, 0.6 added points per leaf in 3D; 3 triangles or 16 tetrahedra.
        const size_t leaves = forest_.leaves.size();
        points_.reserve(2 * leaves + 64);
        leaf_corners_.reserve(leaves << d);
        out_.cells.reserve((d == 2 ? 3 * 3 : 16 * 4) * leaves);
        out_.leaf.reserve((d == 2 ? 3 : 16) * leaves);
        for (uint32_t t = 0; t < forest_.tree_count(); ++t)
            for (uint64_t i = forest_.tree_offsets[t]; i < forest_.tree_offsets[t + 1]; ++i)
                for (int c = 0; c < (1 << d); ++c) leaf_corners_.push_back(points_.add(t, corner(forest_.leaves[i], c).data()));
        corner_ids_ = points_.size();
        out_.corner_points = uint32_t(points_.positions().size());
        for (uint32_t t = 0; t < forest_.tree_count(); ++t) {
            tree_ = t;
            for (uint64_t i = forest_.tree_offsets[t]; i < forest_.tree_offsets[t + 1]; ++i) {
                leaf_ = uint32_t(i);
                origin_ = corner(forest_.leaves[i], 0), length_ = length(forest_.leaves[i]);
                std::fill(edge_has_corner_, edge_has_corner_ + 12, int8_t(-1));
                if (d == 2) leaf_2d(forest_.leaves[i]);
                else leaf_3d(forest_.leaves[i]);
            }
        }
        out_.dim = d;
        out_.points = points_.positions();
        out_.forest_point = points_.id_of_position();
    }

private:
    int64_t length(const Octant& o) const { return int64_t(1) << (octree_root_log2(forest_.dim()) - o.level); }

    Lattice corner(const Octant& o, int c) const {
        const int64_t len = length(o);
        return {o.x + ((c & 1) ? len : 0), o.y + ((c & 2) ? len : 0), o.z + ((c & 4) ? len : 0)};
    }

    // The leaf's own corners come from the first pass, the rest from the table.
    Vertex vertex(const Lattice& p) {
        int c = 0;
        for (int a = 0; a < 3; ++a) {
            if (p[a] == origin_[a]) continue;
            if (p[a] != origin_[a] + length_) return {p, points_.find(tree_, p.data())};
            c |= 1 << a;
        }
        return {p, leaf_corners_[(size_t(leaf_) << forest_.dim()) + c]};
    }

    bool is_leaf_corner(const Lattice& p) const {
        const ForestPoints::Point found = points_.find(tree_, p.data());
        return found.id != kNoIndex && found.id < corner_ids_;
    }

    // Appends the leaf corners strictly between a and b (a dyadic segment of a leaf edge), from a on.
    void edge_points(const Lattice& a, const Lattice& b, std::vector<Vertex>& out) {
        int64_t len = 0;
        Lattice m;
        for (int k = 0; k < 3; ++k) len = std::max(len, std::abs(b[k] - a[k])), m[k] = a[k] + (b[k] - a[k]) / 2;
        if (len < 2) return;
        if (len == length_) {  // a whole edge of the leaf: asked by its two faces (3D), looked up once
            int axis = 0, bits = 0;
            while (a[axis] == b[axis]) ++axis;
            for (int k = 0, bit = 0; k < 3; ++k)
                if (k != axis) bits |= (a[k] != origin_[k]) << bit++;
            int8_t& known = edge_has_corner_[axis * 4 + bits];
            if (known < 0) known = is_leaf_corner(m);
            if (!known) return;
        } else if (!is_leaf_corner(m)) {
            return;
        }
        edge_points(a, m, out);
        out.push_back(vertex(m));
        edge_points(m, b, out);
    }

    // The polygon of corners (in order around) with the leaf corners on its sides, in poly_.
    const std::vector<Vertex>& polygon(const Lattice* corners, int n) {
        poly_.clear();
        for (int k = 0; k < n; ++k) {
            poly_.push_back(vertex(corners[k]));
            edge_points(corners[k], corners[(k + 1) % n], poly_);
        }
        return poly_;
    }

    // Triangles of a polygon of four corners and the points on its sides: two by the diagonal through
    // the corner of smallest point id, or a fan from `centre` (added when needed).
    template <class Emit>
    void split_or_fan(const std::vector<Vertex>& poly, const Lattice& centre, bool centre_inside, Emit emit) {
        if (poly.size() == 4) {
            int k = 0;
            for (int i = 1; i < 4; ++i)
                if (poly[i].point.id < poly[k].point.id) k = i;
            emit(poly[k], poly[(k + 1) % 4], poly[(k + 2) % 4]);
            emit(poly[k], poly[(k + 2) % 4], poly[(k + 3) % 4]);
            return;
        }
        const Vertex c{centre, centre_inside ? points_.add_inside(tree_, centre.data()) : points_.add(tree_, centre.data())};
        for (size_t i = 0; i < poly.size(); ++i) emit(c, poly[i], poly[(i + 1) % poly.size()]);
    }

    void add_cell(std::initializer_list<const Vertex*> vertices) {
        for (const Vertex* v : vertices) out_.cells.push_back(v->point.place);
        out_.leaf.push_back(leaf_);
    }

    void leaf_2d(const Octant& o) {
        const Lattice corners[4] = {corner(o, 0), corner(o, 1), corner(o, 3), corner(o, 2)};  // counter-clockwise
        const int64_t half = length(o) / 2;
        split_or_fan(polygon(corners, 4), {o.x + half, o.y + half, 0}, true, [&](const Vertex& a, const Vertex& b, const Vertex& c) {
            // Counter-clockwise in the tree's frame, times its hand.
            const int64_t cross = (b.p[0] - a.p[0]) * (c.p[1] - a.p[1]) - (b.p[1] - a.p[1]) * (c.p[0] - a.p[0]);
            if ((cross > 0) == (hand_[tree_] > 0)) add_cell({&a, &b, &c});
            else add_cell({&a, &c, &b});
        });
    }

    // The triangles of a square face of side `len` at `origin` spanning axes u and v.
    template <class Emit>
    void face(const Lattice& origin, int u, int v, int64_t len, Emit emit) {
        Lattice centre = origin;
        centre[u] += len / 2, centre[v] += len / 2;
        if (len >= 2 && is_leaf_corner(centre)) {  // a leaf on one side is finer here: its faces
            for (int q = 0; q < 4; ++q) {
                Lattice quarter = origin;
                quarter[u] += (q & 1) ? len / 2 : 0, quarter[v] += (q & 2) ? len / 2 : 0;
                face(quarter, u, v, len / 2, emit);
            }
            return;
        }
        Lattice corners[4] = {origin, origin, origin, origin};
        corners[1][u] += len, corners[2][u] += len, corners[2][v] += len, corners[3][v] += len;
        split_or_fan(polygon(corners, 4), centre, false, emit);
    }

    void leaf_3d(const Octant& o) {
        const int64_t len = length(o);
        const Lattice mid{o.x + len / 2, o.y + len / 2, o.z + len / 2};
        const Vertex centre{mid, points_.add_inside(tree_, mid.data())};
        for (int f = 0; f < 6; ++f) {
            const int a = f / 2, u = a == 0 ? 1 : 0, v = a == 2 ? 1 : 2;
            Lattice origin = corner(o, 0);
            if (f & 1) origin[a] += len;
            face(origin, u, v, len, [&](const Vertex& p, const Vertex& q, const Vertex& r) {
                // Positive volume in the tree's frame: det(q - p, r - p, centre - p) > 0.
                const int64_t e[3][3] = {{q.p[0] - p.p[0], q.p[1] - p.p[1], q.p[2] - p.p[2]},
                                         {r.p[0] - p.p[0], r.p[1] - p.p[1], r.p[2] - p.p[2]},
                                         {mid[0] - p.p[0], mid[1] - p.p[1], mid[2] - p.p[2]}};
                const int64_t det = e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) -
                                    e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
                                    e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0]);
                if (det > 0) add_cell({&p, &q, &r, &centre});
                else add_cell({&p, &r, &q, &centre});
            });
        }
    }

    const OctreeForest& forest_;
    ConformingLeafMesh& out_;
    ForestPoints points_;
    std::vector<int> hand_;  // 2D: per tree, +1 or -1 (tree_hands)
    std::vector<Vertex> poly_;  // polygon()'s, used before the next call
    std::vector<ForestPoints::Point> leaf_corners_;  // 2^dim per leaf, z-order
    Lattice origin_{0, 0, 0};  // the current leaf's corner 0 and length
    int64_t length_ = 0;
    int8_t edge_has_corner_[12] = {};  // per edge of the current leaf (axis * 4 + the other axes' sides): -1 unknown
    uint32_t corner_ids_ = 0, tree_ = 0, leaf_ = 0;
};

}  // namespace

ConformingLeafMesh conforming_leaf_mesh(const OctreeForest& forest) {
    validate_octree_forest(forest, "forest");
    AMC_REQUIRE(forest.leaves.size() < kNoIndex, limit_exceeded, "more than 2^32 - 1 leaves for a conforming leaf mesh");
    ConformingLeafMesh mesh;
    Extraction(forest, mesh).run();
    return mesh;
}

}  // namespace amc
