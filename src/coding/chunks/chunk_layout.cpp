// Chunks of roots: balancing, extraction and merging (chunk_layout.h).
#include "coding/chunks/chunk_layout.h"

#include "common/check.h"
#include "hierarchy/hierarchy_builder.h"

#include <algorithm>
#include <utility>

namespace amc {

std::vector<uint32_t> root_of_nodes(const Hierarchy& h) {
    std::vector<uint32_t> root_of(h.node_capacity(), kNoNode);
    for (NodeId r = 0; r < h.root_count(); ++r) root_of[r] = r;
    // A forest only ever refined numbers parents before their children: one pass over the blocks
    // of four siblings (alive or removed together).
    // Without unused ids (the encoder's reordered forest) no node is read, only the parents.
    const bool all_alive = h.node_count() == h.node_capacity();
    bool parents_first = true;
    for (NodeId c = h.root_count(); c < h.node_capacity() && parents_first; c += 4) {
        if (!all_alive && !h.is_alive(c)) continue;
        const NodeId p = h.parent(c);
        parents_first = p < c;
        std::fill(root_of.begin() + c, root_of.begin() + c + 4, parents_first ? root_of[p] : kNoNode);
    }
    if (!parents_first)
        for (NodeId n : h.breadth_first_order()) root_of[n] = n < h.root_count() ? n : root_of[h.parent(n)];
    return root_of;
}

std::vector<uint64_t> nodes_per_root(const Hierarchy& h, const std::vector<uint32_t>& root_of) {
    // By blocks of four siblings (alive or removed together), from root_of alone: unused ids have no
    // root there, and its 4 bytes a node are read instead of the nodes themselves.
    std::vector<uint64_t> count(h.root_count(), 1);
    for (NodeId c = h.root_count(); c < h.node_capacity(); c += 4)
        if (root_of[c] != kNoNode) count[root_of[c]] += 4;
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
    size_t triangles = 0;
    for (const RootRange& range : roots) triangles += range.count;
    base_vertex.clear();
    std::vector<VertexId> index;  // with a pass over the whole base: its vertices' new ids
    // The roots' vertices in increasing order: marked in a pass over the whole base's, or sorted
    // when the roots are few against it (the encoder's chunks: that pass for each made N chunks
    // quadratic). Either way the same numbering.
    const bool sorted = triangles < base.positions.size() / 32;
    if (sorted) {
        base_vertex.reserve(3 * triangles);
        for (const RootRange& range : roots)
            for (uint32_t t = range.first; t < range.first + range.count; ++t)
                base_vertex.insert(base_vertex.end(), base.triangles[t].begin(), base.triangles[t].end());
        std::sort(base_vertex.begin(), base_vertex.end());
        base_vertex.erase(std::unique(base_vertex.begin(), base_vertex.end()), base_vertex.end());
    } else {
        index.assign(base.positions.size(), kNoVertex);
        for (const RootRange& range : roots)
            for (uint32_t t = range.first; t < range.first + range.count; ++t)
                for (int i = 0; i < 3; ++i) index[base.triangles[t][i]] = 0;
        for (VertexId v = 0; v < index.size(); ++v) {
            if (index[v] == kNoVertex) continue;
            index[v] = VertexId(base_vertex.size());
            base_vertex.push_back(v);
        }
    }
    auto new_id = [&](VertexId v) {
        return sorted ? VertexId(std::lower_bound(base_vertex.begin(), base_vertex.end(), v) - base_vertex.begin()) : index[v];
    };
    TriangleMesh out;
    out.single_precision = base.single_precision;
    out.positions.reserve(base_vertex.size());
    for (VertexId v : base_vertex) out.positions.push_back(base.positions[v]);
    out.triangles.reserve(triangles);
    for (const RootRange& range : roots)
        for (uint32_t t = range.first; t < range.first + range.count; ++t)
            out.triangles.push_back({new_id(base.triangles[t][0]), new_id(base.triangles[t][1]), new_id(base.triangles[t][2])});
    return out;
}

Hierarchy extract_roots(const Hierarchy& h, const std::vector<RootRange>& roots, std::vector<VertexId>* vertex_of) {
    std::vector<NodeId> local(h.node_capacity());
    return extract_roots(h, roots, root_of_nodes(h), local.data(), vertex_of);
}

Hierarchy extract_roots(const Hierarchy& h, const std::vector<RootRange>& roots, const std::vector<uint32_t>& root_of,
                        NodeId* local, std::vector<VertexId>* vertex_of, SubforestRoom* room) {
    std::vector<VertexId> base_vertex;
    TriangleMesh base = base_of_roots(h.base(), roots, base_vertex);
    std::vector<NodeId> root_ids;
    // Marks over the span of the roots taken, not over all roots: one chunk's extraction is linear in it.
    uint32_t span_first = UINT32_MAX, span_end = 0;
    for (const RootRange& range : roots) {
        if (range.count == 0) continue;
        span_first = std::min(span_first, range.first);
        span_end = std::max(span_end, range.first + range.count);
    }
    std::vector<uint8_t> root_in(span_end > span_first ? span_end - span_first : 0, 0);
    for (const RootRange& range : roots)
        for (uint32_t r = range.first; r < range.first + range.count; ++r) {
            root_ids.push_back(r);
            root_in[r - span_first] = 1;
        }
    return HierarchyBuilder::subforest(h, std::move(base), root_ids, base_vertex, root_of, root_in, span_first, local, vertex_of, room);
}

}  // namespace amc
