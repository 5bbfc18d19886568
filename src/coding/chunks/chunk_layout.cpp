// Chunks of roots: balancing, extraction and merging (chunk_layout.h).
#include "coding/chunks/chunk_layout.h"

#include "common/check.h"

#include <utility>

namespace amc {

namespace {

// A node of a chunk hierarchy and the same node in the whole one.
struct NodePair {
    NodeId chunk, whole;
};

}  // namespace

std::vector<uint64_t> nodes_per_root(const Hierarchy& h) {
    std::vector<uint32_t> root_of(h.node_capacity(), 0);
    std::vector<uint64_t> count(h.root_count(), 0);
    for (NodeId n : h.breadth_first_order()) {  // parents before children
        root_of[n] = n < h.root_count() ? n : root_of[h.parent(n)];
        ++count[root_of[n]];
    }
    return count;
}

std::vector<RootRange> balanced_chunks(const std::vector<uint64_t>& nodes_per_root, uint32_t chunks) {
    uint64_t total = 0;
    for (uint64_t n : nodes_per_root) total += n;
    std::vector<RootRange> out;
    const uint32_t roots = uint32_t(nodes_per_root.size());
    chunks = std::max<uint32_t>(1, std::min(chunks, roots));
    uint64_t running = 0;
    RootRange current;
    for (uint32_t r = 0; r < roots; ++r) {
        running += nodes_per_root[r];
        ++current.count;
        const uint32_t k = uint32_t(out.size());
        // Close chunk k at its share, keeping at least one root for each chunk still to come.
        const bool share_reached = running * chunks >= total * (k + 1);
        const bool roots_needed = roots - (r + 1) <= chunks - (k + 1);
        if (k + 1 < chunks && (share_reached || roots_needed)) {
            out.push_back(current);
            current = RootRange{r + 1, 0};
        }
    }
    out.push_back(current);
    return out;
}

TriangleMesh base_of_roots(const TriangleMesh& base, const std::vector<RootRange>& roots, std::vector<VertexId>& base_vertex) {
    std::vector<VertexId> index(base.positions.size(), kNoVertex);
    for (const RootRange& range : roots)
        for (uint32_t t = range.first; t < range.first + range.count; ++t)
            for (int i = 0; i < 3; ++i) index[base.triangles[t][i]] = 0;
    TriangleMesh out;
    out.single_precision = base.single_precision;
    base_vertex.clear();
    for (VertexId v = 0; v < index.size(); ++v) {
        if (index[v] == kNoVertex) continue;
        index[v] = VertexId(base_vertex.size());
        base_vertex.push_back(v);
        out.positions.push_back(base.positions[v]);
    }
    for (const RootRange& range : roots)
        for (uint32_t t = range.first; t < range.first + range.count; ++t)
            out.triangles.push_back({index[base.triangles[t][0]], index[base.triangles[t][1]], index[base.triangles[t][2]]});
    return out;
}

Hierarchy extract_roots(const Hierarchy& h, const std::vector<RootRange>& roots, std::vector<VertexId>* vertex_of) {
    std::vector<VertexId> base_vertex;
    Hierarchy out(base_of_roots(h.base(), roots, base_vertex));
    std::vector<VertexId> ids = base_vertex;
    std::vector<NodePair> level, next;
    NodeId local = 0;
    for (const RootRange& range : roots)
        for (uint32_t r = range.first; r < range.first + range.count; ++r) level.push_back({local++, r});
    while (!level.empty()) {
        next.clear();
        for (const NodePair p : level) {
            if (h.is_leaf(p.whole)) {
                out.set_diagonal_flipped(p.chunk, h.diagonal_flipped(p.whole));
                continue;
            }
            out.split(p.chunk);  // balanced: its neighbours in the chunk are those of the whole
            if (ids.size() < out.positions().size()) ids.resize(out.positions().size(), kNoVertex);
            for (int e = 0; e < 3; ++e) {
                const VertexId m = out.midpoint(p.chunk, e), whole = h.midpoint(p.whole, e);
                out.set_position(m, h.position(whole));
                ids[m] = whole;
            }
            for (int k = 0; k < 4; ++k) next.push_back({out.child(p.chunk, k), h.child(p.whole, k)});
        }
        std::swap(level, next);
    }
    if (vertex_of != nullptr) *vertex_of = std::move(ids);
    return out;
}

}  // namespace amc
