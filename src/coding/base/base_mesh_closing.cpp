// The closed, manifold version of a base mesh; see base_mesh_closing.h.
#include "coding/base/base_mesh_closing.h"

#include <numeric>
#include <unordered_map>

namespace amc {
namespace {

uint64_t edge_key(uint32_t a, uint32_t b) { return (uint64_t{a} << 32) | b; }

uint32_t find_root(std::vector<uint32_t>& parent, uint32_t x) {
    while (parent[x] != x) {
        parent[x] = parent[parent[x]];
        x = parent[x];
    }
    return x;
}

}  // namespace

ClosedMesh make_closed(const TriangleMesh& mesh) {
    const uint32_t f = static_cast<uint32_t>(mesh.triangles.size());
    ClosedMesh cm;
    cm.real_triangles = f;
    std::unordered_map<uint64_t, uint32_t> halfedge;
    halfedge.reserve(3 * size_t{f});
    for (uint32_t t = 0; t < f; ++t) {
        for (int k = 0; k < 3; ++k) {
            const Triangle& tri = mesh.triangles[t];
            if (!halfedge.emplace(edge_key(tri[k], tri[(k + 1) % 3]), 3 * t + k).second)
                throw EncoderGaveUp{};
        }
    }
    // Corners of one vertex sharing an edge belong to one fan.
    std::vector<uint32_t> parent(3 * size_t{f});
    std::iota(parent.begin(), parent.end(), 0u);
    for (uint32_t t = 0; t < f; ++t) {
        const Triangle& tri = mesh.triangles[t];
        for (int k = 0; k < 3; ++k) {
            const auto it = halfedge.find(edge_key(tri[(k + 1) % 3], tri[k]));
            if (it == halfedge.end()) continue;
            const uint32_t other = it->second / 3 * 3 + (it->second % 3 + 1) % 3;  // corner of tri[k]
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
    // Boundary loops, closed by dummy fans.
    halfedge.clear();
    for (uint32_t t = 0; t < f; ++t)
        for (int k = 0; k < 3; ++k)
            if (!halfedge.emplace(edge_key(cm.triangles[t][k], cm.triangles[t][(k + 1) % 3]), 3 * t + k).second)
                throw EncoderGaveUp{};
    const uint32_t used = static_cast<uint32_t>(cm.original.size());
    std::vector<uint32_t> boundary_next(used, kNoVertex);
    for (uint32_t t = 0; t < f; ++t) {
        for (int k = 0; k < 3; ++k) {
            const uint32_t a = cm.triangles[t][k], b = cm.triangles[t][(k + 1) % 3];
            if (halfedge.count(edge_key(b, a))) continue;
            if (boundary_next[a] != kNoVertex) throw EncoderGaveUp{};
            boundary_next[a] = b;
        }
    }
    std::vector<uint8_t> done(used, 0);
    for (uint32_t start = 0; start < used; ++start) {
        if (boundary_next[start] == kNoVertex || done[start]) continue;
        const uint32_t d = static_cast<uint32_t>(cm.original.size());
        cm.original.push_back(kNoVertex);
        ++cm.dummies;
        uint32_t a = start;
        for (uint32_t steps = 0; !done[a]; ++steps) {
            if (steps > used) throw EncoderGaveUp{};
            done[a] = 1;
            const uint32_t b = boundary_next[a];
            if (b == kNoVertex) throw EncoderGaveUp{};
            cm.triangles.push_back({b, a, d});
            a = b;
        }
        if (a != start) throw EncoderGaveUp{};
    }
    // Twins; every halfedge must have one now.
    halfedge.clear();
    const uint32_t fc = static_cast<uint32_t>(cm.triangles.size());
    for (uint32_t t = 0; t < fc; ++t)
        for (int k = 0; k < 3; ++k)
            if (!halfedge.emplace(edge_key(cm.triangles[t][k], cm.triangles[t][(k + 1) % 3]), 3 * t + k).second)
                throw EncoderGaveUp{};
    cm.twin.assign(3 * size_t{fc}, kNoVertex);
    for (uint32_t t = 0; t < fc; ++t) {
        for (int k = 0; k < 3; ++k) {
            const auto it = halfedge.find(edge_key(cm.triangles[t][(k + 1) % 3], cm.triangles[t][k]));
            if (it == halfedge.end()) throw EncoderGaveUp{};
            cm.twin[3 * t + k] = it->second;
        }
    }
    return cm;
}

}  // namespace amc
