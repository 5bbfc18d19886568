#include "import/triangle_adjacency.h"

#include <algorithm>
#include <tuple>
#include <utility>

namespace amc::detail {

TriangleAdjacency::TriangleAdjacency(const std::vector<Triangle>& triangles, uint32_t vertex_count)
    : twin_(triangles.size() * 3, kNoHalfEdge), out_start_(size_t(vertex_count) + 2, 0),
      boundary_(vertex_count, 0) {
    const uint32_t half_edges = uint32_t(triangles.size() * 3);
    auto start_of = [&](uint32_t h) { return triangles[h / 3][h % 3]; };
    auto end_of = [&](uint32_t h) { return triangles[h / 3][(h % 3 + 1) % 3]; };
    for (uint32_t h = 0; h < half_edges; ++h) ++out_start_[start_of(h) + 2];
    for (size_t v = 2; v < out_start_.size(); ++v) out_start_[v] += out_start_[v - 1];
    out_end_.resize(half_edges);
    out_half_edge_.resize(half_edges);
    for (uint32_t h = 0; h < half_edges; ++h) {
        const uint32_t slot = out_start_[start_of(h) + 1]++;
        out_end_[slot] = end_of(h);
        out_half_edge_[slot] = h;
    }
    out_start_.pop_back();
    // Sort each vertex's half-edges by end vertex: insertion sort for the small fans of real
    // meshes, a full sort for the rare large one (a fan of thousands must not cost its square).
    std::vector<std::pair<uint32_t, uint32_t>> large;
    for (uint32_t v = 0; v < vertex_count; ++v) {
        const uint32_t first = out_start_[v], last = out_start_[v + 1];
        if (last - first > 32) {
            large.clear();
            for (uint32_t i = first; i < last; ++i) large.emplace_back(out_end_[i], out_half_edge_[i]);
            std::sort(large.begin(), large.end());
            for (uint32_t i = first; i < last; ++i) std::tie(out_end_[i], out_half_edge_[i]) = large[i - first];
            continue;
        }
        for (uint32_t i = first + 1; i < last; ++i) {
            const uint32_t end = out_end_[i], h = out_half_edge_[i];
            uint32_t j = i;
            for (; j > first && out_end_[j - 1] > end; --j) {
                out_end_[j] = out_end_[j - 1];
                out_half_edge_[j] = out_half_edge_[j - 1];
            }
            out_end_[j] = end;
            out_half_edge_[j] = h;
        }
    }
    for (uint32_t h = 0; h < half_edges; ++h) {
        twin_[h] = find(end_of(h), start_of(h));
        if (twin_[h] == kNoHalfEdge) boundary_[start_of(h)] = boundary_[end_of(h)] = 1;
    }
}

uint32_t TriangleAdjacency::find(uint32_t from, uint32_t to) const {
    const uint32_t* first = out_end_.data() + out_start_[from];
    const uint32_t* last = out_end_.data() + out_start_[from + 1];
    // A vertex has about six half-edges: a scan beats a binary search; a large fan is searched.
    const uint32_t* it = first;
    if (last - first > 16) {
        it = std::lower_bound(first, last, to);
    } else {
        while (it != last && *it < to) ++it;
    }
    return it != last && *it == to ? out_half_edge_[size_t(it - out_end_.data())] : kNoHalfEdge;
}

}  // namespace amc::detail
