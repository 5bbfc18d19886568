// Uniform refinement read off the connectivity: straight lines through degree-6 vertices and the
// triangular grid of each base triangle (docs/IMPORT.md, "uniform refinement").
#include "import/uniform_lattice.h"

#include "common/keyed_hash.h"
#include "common/no_index.h"

#include <amc/red_split.h>

#include <unordered_map>
#include <utility>
#include <vector>

namespace amc {

namespace {


// The vertex after `p` on the straight line coming from `previous`: three faces clockwise around
// p, the line having the faces of its left side on the left. In a uniform refinement every leaf
// triangle is red, so this is exact, inside and along the boundary.
uint32_t straight_on(const LeafHalfedges& he, uint32_t previous, uint32_t p) {
    uint32_t w = previous;
    for (int k = 0; k < 3 && w != kNoIndex; ++k) w = he.apex(w, p);
    return w;
}

// Walks `steps` leaf edges from a through x; the vertex reached, or kNoIndex.
uint32_t walk(const LeafHalfedges& he, uint32_t a, uint32_t x, uint32_t steps) {
    uint32_t previous = a, p = x;
    for (uint32_t s = 1; s < steps && p != kNoIndex; ++s) {
        const uint32_t next = straight_on(he, previous, p);
        previous = p;
        p = next;
    }
    return p;
}

// The first out-edge of a leaf vertex (in its fan's order) whose walk of `steps` edges ends at a
// given vertex. Each out-edge is walked once and its end kept: the roots at a boundary vertex,
// whose turns stop at the boundary, each ask, and a fan of k of them asked in the wrong order
// walked k out-edges k times.
class RayFinder {
public:
    RayFinder(const LeafHalfedges& he, uint32_t steps) : he_(he), steps_(steps), walked_(he.vertex_count(), 0) {}

    // The vertex after a toward b, or kNoIndex: the answer of a scan of a's out-edges in order.
    uint32_t toward(uint32_t a, uint32_t b) {
        const auto known = first_toward_.find(key(a, b));
        if (known != first_toward_.end()) return known->second;
        for (uint32_t& i = walked_[a]; i < he_.degree(a);) {
            const uint32_t candidate = he_.out_vertex(a, i++);
            const uint32_t end = walk(he_, a, candidate, steps_);
            if (end == kNoIndex) continue;
            first_toward_.try_emplace(key(a, end), candidate);  // an earlier out-edge to the same end stays
            if (end == b) return candidate;
        }
        return kNoIndex;
    }

private:
    static uint64_t key(uint32_t a, uint32_t b) { return (uint64_t(a) << 32) | b; }
    const LeafHalfedges& he_;
    const uint32_t steps_;
    std::vector<uint32_t> walked_;  // per leaf vertex: its out-edges walked so far
    // Keyed (keyed_hash.h): libstdc++ hashes an integer to itself, and the leaf ids are the file's
    // numbering where one Morton cell holds the mesh (a far component stretches the box; docs/FUZZING.md).
    std::unordered_map<uint64_t, uint32_t, KeyedWordHash> first_toward_;
};

}  // namespace

std::vector<uint32_t> reconstruct_uniform(Hierarchy& h, const std::vector<uint32_t>& leaf_of_base,
                                          const TriangleMesh& leaf, const LeafHalfedges& he) {
    const uint32_t f0 = h.root_count();
    int depth = 0;
    for (uint64_t f = f0; f < leaf.triangles.size(); f *= 4) ++depth;
    if ((uint64_t(f0) << (2 * depth)) != leaf.triangles.size() || depth == 0 || depth > 15) return {};
    const uint32_t n = 1u << depth;
    std::vector<uint8_t> is_base(leaf.positions.size(), 0);
    for (uint32_t l : leaf_of_base) is_base[l] = 1;

    // The first leaf vertex on root t's edge c (from corner c toward corner c + 1).
    std::vector<uint32_t> ray(3 * size_t(f0), kNoIndex);
    RayFinder rays(he, n);
    for (NodeId t = 0; t < f0; ++t) {
        for (int c = 0; c < 3; ++c) {
            if (ray[3 * t + c] != kNoIndex) continue;
            // Find the direction toward corner c + 1 by walking from each neighbour of corner c;
            // then turn around the corner: one leaf face per base triangle.
            const uint32_t a = leaf_of_base[h.vertex(t, c)];
            const uint32_t b = leaf_of_base[h.vertex(t, (c + 1) % 3)];
            uint32_t x = rays.toward(a, b);
            if (x == kNoIndex) return {};
            NodeId r = t;
            int corner = c;
            for (uint32_t turns = 0; turns < he.degree(a) + 1 && ray[3 * r + corner] == kNoIndex; ++turns) {
                ray[3 * r + corner] = x;  // CCW: the next triangle around a holds the edge a -> corner + 2
                const int e = (corner + 2) % 3;
                const NodeId next = h.neighbor(r, e);
                if (next == kNoNode) break;
                corner = h.neighbor_edge(r, e);
                r = next;
                x = he.apex(a, x);
                if (x == kNoIndex) return {};
            }
        }
    }

    // Each root's grid P(i, j), i + j <= n: row 0 is its edge 0, row j + 1 the apexes of the
    // upward triangles (P(i, j), P(i + 1, j), P(i, j + 1)).
    const size_t grid_size = size_t(n + 1) * (n + 2) / 2;
    auto row_start = [n](uint32_t j) { return size_t(j) * (n + 1) - size_t(j) * (j - 1) / 2; };
    std::vector<uint32_t> grid(grid_size * f0, kNoIndex);
    for (NodeId t = 0; t < f0; ++t) {
        uint32_t* g = grid.data() + grid_size * t;
        g[0] = leaf_of_base[h.vertex(t, 0)];
        g[1] = ray[3 * t];
        for (uint32_t i = 1; i < n; ++i) {
            g[i + 1] = straight_on(he, g[i - 1], g[i]);
            if (g[i + 1] == kNoIndex || (is_base[g[i]])) return {};
        }
        if (g[n] != leaf_of_base[h.vertex(t, 1)]) return {};
        for (uint32_t j = 0; j < n; ++j) {
            const uint32_t* row = g + row_start(j);
            uint32_t* above = g + row_start(j + 1);
            for (uint32_t i = 0; i + j < n; ++i) {
                above[i] = he.apex(row[i], row[i + 1]);
                if (above[i] == kNoIndex) return {};
            }
        }
        if (g[row_start(n)] != leaf_of_base[h.vertex(t, 2)]) return {};
    }

    for (int level = 0; level < depth; ++level) {
        for (NodeId node : h.leaves()) h.split(node);
    }
    std::vector<uint32_t> leaf_of_vertex(h.positions().size(), kNoIndex);
    for (VertexId v = 0; v < leaf_of_base.size(); ++v) leaf_of_vertex[v] = leaf_of_base[v];
    struct Item {
        NodeId node;
        uint32_t i[3], j[3];  // grid coordinates of the corners
    };
    std::vector<Item> stack;
    for (NodeId t = 0; t < f0; ++t) {
        const uint32_t* g = grid.data() + grid_size * t;
        stack.push_back({t, {0, n, 0}, {0, 0, n}});
        while (!stack.empty()) {
            const Item item = stack.back();
            stack.pop_back();
            for (int c = 0; c < 3; ++c) {
                const uint32_t l = g[row_start(item.j[c]) + item.i[c]];
                uint32_t& known = leaf_of_vertex[h.vertex(item.node, c)];
                if (known == kNoIndex) {
                    known = l;
                } else if (known != l) {
                    return {};  // two grids disagree along a shared edge
                }
            }
            if (h.is_leaf(item.node)) continue;
            // The split's six points (red_split.h): corners, then the midpoints of edges 0-2.
            uint32_t pi[6], pj[6];
            for (int e = 0; e < 3; ++e) {
                pi[red_split::kCorner + e] = item.i[e];
                pj[red_split::kCorner + e] = item.j[e];
                pi[red_split::kMidpoint + e] = (item.i[e] + item.i[(e + 1) % 3]) / 2;
                pj[red_split::kMidpoint + e] = (item.j[e] + item.j[(e + 1) % 3]) / 2;
            }
            for (int k = 0; k < 4; ++k) {
                Item child{h.child(item.node, k), {}, {}};
                for (int v = 0; v < 3; ++v) {
                    child.i[v] = pi[red_split::kChildPoints[k][v]];
                    child.j[v] = pj[red_split::kChildPoints[k][v]];
                }
                stack.push_back(child);
            }
        }
    }
    return leaf_of_vertex;
}

}  // namespace amc
