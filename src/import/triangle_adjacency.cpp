#include "import/triangle_adjacency.h"

#include <algorithm>
#include <tuple>
#include <utility>

namespace amc::detail {

TriangleAdjacency::TriangleAdjacency(const std::vector<Triangle>& triangles, uint32_t vertex_count)
    : out_start_(size_t(vertex_count) + 2, 0), boundary_(vertex_count, 0) {
    const uint32_t half_edges = uint32_t(triangles.size() * 3);
    for (const Triangle& t : triangles) {
        for (uint32_t v : t) ++out_start_[v + 2];
    }
    for (size_t v = 2; v < out_start_.size(); ++v) out_start_[v] += out_start_[v - 1];
    out_end_.reset(new uint32_t[half_edges]);
    out_half_edge_.reset(new uint32_t[half_edges]);
    for (uint32_t t = 0; t < triangles.size(); ++t) {
        for (uint32_t k = 0; k < 3; ++k) {
            const uint32_t slot = out_start_[triangles[t][k] + 1]++;
            out_end_[slot] = triangles[t][k == 2 ? 0 : k + 1];
            out_half_edge_[slot] = 3 * t + k;
        }
    }
    out_start_.pop_back();
    // Only a large fan is sorted by end vertex (find searches it); a vertex has about six
    // half-edges, which find scans whole, and no caller needs them in order.
    std::vector<std::pair<uint32_t, uint32_t>> large;
    for (uint32_t v = 0; v < vertex_count; ++v) {
        const uint32_t first = out_start_[v], last = out_start_[v + 1];
        if (last - first <= kScanned) continue;
        large.clear();
        for (uint32_t i = first; i < last; ++i) large.emplace_back(out_end_[i], out_half_edge_[i]);
        std::sort(large.begin(), large.end());
        for (uint32_t i = first; i < last; ++i) std::tie(out_end_[i], out_half_edge_[i]) = large[i - first];
    }
    // Each pair of twins found once, from its first half-edge.
    constexpr uint32_t kUnknown = kNoHalfEdge - 1;
    twin_.assign(half_edges, kUnknown);
    for (uint32_t t = 0; t < triangles.size(); ++t) {
        for (uint32_t k = 0; k < 3; ++k) {
            const uint32_t h = 3 * t + k;
            if (twin_[h] != kUnknown) continue;
            const uint32_t a = triangles[t][k], b = triangles[t][k == 2 ? 0 : k + 1];
            const uint32_t twin = find(b, a);
            twin_[h] = twin;
            if (twin != kNoHalfEdge) {
                twin_[twin] = h;
            } else {
                boundary_[a] = boundary_[b] = 1;
            }
        }
    }
}

uint32_t TriangleAdjacency::find(uint32_t from, uint32_t to) const {
    const uint32_t* first = out_end_.get() + out_start_[from];
    const uint32_t* last = out_end_.get() + out_start_[from + 1];
    // A vertex has about six half-edges: a scan beats a binary search; a large fan is sorted and searched.
    const uint32_t* it = first;
    if (last - first > kScanned) {
        it = std::lower_bound(first, last, to);
        return it != last && *it == to ? out_half_edge_[size_t(it - out_end_.get())] : kNoHalfEdge;
    }
    while (it != last && *it != to) ++it;
    return it != last ? out_half_edge_[size_t(it - out_end_.get())] : kNoHalfEdge;
}

}  // namespace amc::detail
