// The closed, manifold version of a base mesh; see base_mesh_closing.h.
#include "coding/base/base_mesh_closing.h"

#include <algorithm>
#include <numeric>

namespace amc {
namespace {

// The halfedges of a triangle list by their first vertex (counting sort), each with its second,
// sorted by it: a halfedge (a, b) is found by a binary search among a's (a hash map of all of them
// cost the closing most of its time; a pass over a's was quadratic in a's valence).
class HalfedgeIndex {
public:
    // False when two halfedges are equal (the mesh is not edge-manifold and consistently oriented).
    bool build(const std::vector<Triangle>& triangles) {
        uint32_t vertex_count = 0;
        for (const Triangle& t : triangles)
            for (uint32_t v : t) vertex_count = std::max(vertex_count, v + 1);
        first_.assign(size_t{vertex_count} + 1, 0);
        for (const Triangle& t : triangles)
            for (uint32_t v : t) ++first_[v + 1];
        std::partial_sum(first_.begin(), first_.end(), first_.begin());
        entries_.assign(3 * triangles.size(), Entry{});
        std::vector<uint32_t> next(first_.begin(), first_.end() - 1);
        for (uint32_t t = 0; t < triangles.size(); ++t)
            for (int k = 0; k < 3; ++k) entries_[next[triangles[t][k]]++] = {triangles[t][(k + 1) % 3], 3 * t + uint32_t(k)};
        auto by_end = [](const Entry& x, const Entry& y) { return x.to < y.to; };
        auto same_end = [](const Entry& x, const Entry& y) { return x.to == y.to; };
        for (uint32_t a = 0; a < vertex_count; ++a) {
            const auto begin = entries_.begin() + first_[a], end = entries_.begin() + first_[a + 1];
            std::sort(begin, end, by_end);
            if (std::adjacent_find(begin, end, same_end) != end) return false;
        }
        return true;
    }
    // The halfedge (a, b), or kNoVertex.
    uint32_t find(uint32_t a, uint32_t b) const {
        if (size_t{a} + 1 >= first_.size()) return kNoVertex;
        const auto end = entries_.begin() + first_[a + 1];
        const auto it = std::lower_bound(entries_.begin() + first_[a], end, b, [](const Entry& x, uint32_t to) { return x.to < to; });
        return it != end && it->to == b ? it->halfedge : kNoVertex;
    }

private:
    struct Entry {
        uint32_t to = kNoVertex, halfedge = kNoVertex;
    };
    std::vector<uint32_t> first_;  // vertex a's halfedges are entries_[first_[a] .. first_[a + 1])
    std::vector<Entry> entries_;
};

uint32_t find_root(std::vector<uint32_t>& parent, uint32_t x) {
    while (parent[x] != x) {
        parent[x] = parent[parent[x]];
        x = parent[x];
    }
    return x;
}

}  // namespace

// One halfedge index, of the input: splitting a vertex into its fans keeps every twin (a twin pair
// joins the corners at both of its ends), and the dummy fans' twins follow from their loops.
ClosedMesh make_closed(const TriangleMesh& mesh) {
    const uint32_t f = static_cast<uint32_t>(mesh.triangles.size());
    ClosedMesh cm;
    cm.real_triangles = f;
    HalfedgeIndex halfedge;
    if (!halfedge.build(mesh.triangles)) throw EncoderGaveUp{};
    cm.twin.assign(3 * size_t{f}, kNoVertex);
    // Corners of one vertex sharing an edge belong to one fan.
    std::vector<uint32_t> parent(3 * size_t{f});
    std::iota(parent.begin(), parent.end(), 0u);
    for (uint32_t t = 0; t < f; ++t) {
        const Triangle& tri = mesh.triangles[t];
        for (int k = 0; k < 3; ++k) {
            const uint32_t opposite = halfedge.find(tri[(k + 1) % 3], tri[k]);
            if (opposite == kNoVertex) continue;
            cm.twin[3 * t + k] = opposite;
            const uint32_t other = opposite / 3 * 3 + (opposite % 3 + 1) % 3;  // corner of tri[k]
            parent[find_root(parent, 3 * t + k)] = find_root(parent, other);
        }
    }
    std::vector<uint32_t> closed_of_root(3 * size_t{f}, kNoVertex);
    cm.triangles.resize(f);
    for (uint32_t c = 0; c < 3 * f; ++c) {
        const uint32_t r = find_root(parent, c);
        if (closed_of_root[r] == kNoVertex) {
            closed_of_root[r] = static_cast<uint32_t>(cm.original.size());
            cm.original.push_back(mesh.triangles[c / 3][c % 3]);
        }
        cm.triangles[c / 3][c % 3] = closed_of_root[r];
    }
    // Boundary loops (the halfedges without a twin), closed by dummy fans.
    const uint32_t used = static_cast<uint32_t>(cm.original.size());
    std::vector<uint32_t> boundary_from(used, kNoVertex);  // per closed vertex: its boundary halfedge
    for (uint32_t h = 0; h < 3 * f; ++h) {
        if (cm.twin[h] != kNoVertex) continue;
        const uint32_t a = cm.corner_vertex(h);
        if (boundary_from[a] != kNoVertex) throw EncoderGaveUp{};
        boundary_from[a] = h;
    }
    std::vector<uint8_t> done(used, 0);
    for (uint32_t start = 0; start < used; ++start) {
        if (boundary_from[start] == kNoVertex || done[start]) continue;
        const uint32_t d = static_cast<uint32_t>(cm.original.size());
        cm.original.push_back(kNoVertex);
        ++cm.dummies;
        const uint32_t first = static_cast<uint32_t>(cm.triangles.size());
        uint32_t a = start;
        for (uint32_t steps = 0; !done[a]; ++steps) {
            if (steps > used) throw EncoderGaveUp{};
            done[a] = 1;
            const uint32_t h = boundary_from[a];
            if (h == kNoVertex) throw EncoderGaveUp{};
            const uint32_t b = cm.corner_vertex(ClosedMesh::next_halfedge(h));
            const uint32_t t = static_cast<uint32_t>(cm.triangles.size());
            cm.triangles.push_back({b, a, d});
            cm.twin[h] = 3 * t;
            cm.twin.push_back(h);           // (b, a)
            cm.twin.push_back(3 * t - 1);   // (a, d): the previous dummy triangle's (d, a)
            cm.twin.push_back(3 * t + 4);   // (d, b): the next one's (b, d)
            a = b;
        }
        if (a != start) throw EncoderGaveUp{};
        // The loop closes: its first and last dummy triangles are neighbours.
        const uint32_t last = static_cast<uint32_t>(cm.triangles.size()) - 1;
        cm.twin[3 * first + 1] = 3 * last + 2;
        cm.twin[3 * last + 2] = 3 * first + 1;
    }
    return cm;
}

}  // namespace amc
