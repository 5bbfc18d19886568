// The conforming leaf mesh: red leaves as they are, green closure of hanging nodes (paper, Fig. 3).
#include <amc/hierarchy.h>

#include "hierarchy/hierarchy_builder.h"

namespace amc {

LeafMesh extract_leaf_mesh(const Hierarchy& h, int max_level) {
    const std::vector<NodeId> breadth_first = h.breadth_first_order();
    const std::vector<uint32_t> canonical = canonical_vertex_order(h, breadth_first);
    const bool cut = max_level >= 0;
    LeafMesh out;
    out.mesh.single_precision = h.single_precision();
    // Uncut, every vertex is a corner of a leaf or the hanging node of a green closure.
    uint32_t used_vertices = cut ? static_cast<uint32_t>(h.base().positions.size()) : h.vertex_count();
    // A leaf gives one triangle, or two or three when closed: room for a quarter of them closed
    // without growing (the vectors double once where more are).
    const size_t room = size_t(h.leaf_count()) + h.leaf_count() / 4;
    out.mesh.triangles.reserve(room);
    out.cells.level.reserve(room);
    out.cells.is_green.reserve(room);
    out.source.reserve(room);

    auto emit = [&](NodeId n, VertexId a, VertexId b, VertexId c, bool green) {
        out.mesh.triangles.push_back({canonical[a], canonical[b], canonical[c]});
        out.cells.level.push_back(uint8_t(h.level(n)));
        out.cells.is_green.push_back(green ? 1 : 0);
        out.source.push_back(n);
    };

    for (NodeId n : breadth_first) {
        const bool at_cut = cut && h.level(n) >= max_level;
        if (cut && h.level(n) > max_level) break;  // breadth-first: all later nodes are finer
        if (!h.is_leaf(n) && !at_cut) continue;
        bool hanging[3];
        VertexId mid[3];
        int count = 0;
        for (int e = 0; e < 3; ++e) {
            hanging[e] = !at_cut && h.has_hanging_node(n, e);
            if (hanging[e]) {
                mid[e] = h.midpoint(h.neighbor(n, e), h.neighbor_edge(n, e));
                if (cut) used_vertices = std::max(used_vertices, canonical[mid[e]] + 1);
                ++count;
            }
        }
        const VertexId v[3] = {h.vertex(n, 0), h.vertex(n, 1), h.vertex(n, 2)};
        if (cut)
            for (int i = 0; i < 3; ++i) used_vertices = std::max(used_vertices, canonical[v[i]] + 1);
        if (count == 0) {
            emit(n, v[0], v[1], v[2], false);
        } else if (count == 1) {
            const int e = hanging[0] ? 0 : hanging[1] ? 1 : 2;
            const VertexId a = v[e], b = v[(e + 1) % 3], c = v[(e + 2) % 3];
            emit(n, a, mid[e], c, true);
            emit(n, mid[e], b, c, true);
        } else if (count == 2) {
            const int u = !hanging[0] ? 0 : !hanging[1] ? 1 : 2;  // the unrefined edge
            const VertexId a = v[u], b = v[(u + 1) % 3], c = v[(u + 2) % 3];
            const VertexId m1 = mid[(u + 1) % 3], m2 = mid[(u + 2) % 3];
            emit(n, m2, m1, c, true);
            if (!h.diagonal_flipped(n)) {  // default diagonal m_{u+1} -- v_u
                emit(n, a, b, m1, true);
                emit(n, a, m1, m2, true);
            } else {  // flipped diagonal m_{u+2} -- v_{u+1}
                emit(n, a, b, m2, true);
                emit(n, b, m1, m2, true);
            }
        } else {
            throw Error("leaf mesh: node " + std::to_string(n) +
                        " has three hanging nodes (closure violated)");
        }
    }
    out.mesh.positions.resize(used_vertices);
    for (size_t v = 0; v < canonical.size(); ++v) {
        if (canonical[v] < used_vertices) out.mesh.positions[canonical[v]] = h.position(VertexId(v));
    }
    return out;
}

}  // namespace amc
