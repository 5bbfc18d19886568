// Frame state and vertex order of the series coder (frame_state.h).
#include "series/frame_state.h"

#include "coding/geometry/geometry_prediction.h"

namespace amc {

void index_frame(FrameState& state) {
    const Hierarchy& h = state.h;
    state.canonical = canonical_vertex_order(h);
    state.first_cell.assign(h.node_capacity(), UINT32_MAX);
    state.closure.assign(h.node_capacity(), 0);
    uint32_t cells = 0;
    for (NodeId n : h.breadth_first_order()) {
        if (!h.is_leaf(n)) continue;
        uint8_t mask = 0;
        for (int e = 0; e < 3; ++e) mask |= uint8_t(h.has_hanging_node(n, e) << e);
        const int hanging = h.hanging_node_count(n);
        state.closure[n] = uint8_t(mask | ((hanging == 2 && h.diagonal_flipped(n)) << 3));
        state.first_cell[n] = cells;
        cells += uint32_t(1 + hanging);
    }
}

FrameState initial_state(const TriangleMesh& base) {
    FrameState s;
    s.h = Hierarchy(base);
    index_frame(s);
    return s;
}

std::vector<FrameVertex> frame_vertex_order(const Hierarchy& h, const Hierarchy& prev, const Counterparts& cp) {
    std::vector<FrameVertex> order;
    order.reserve(h.vertex_count());
    const uint32_t base_vertices = uint32_t(h.base().positions.size());
    for (VertexId v = 0; v < base_vertices; ++v) order.push_back({v, v, kNoNode, 0, 0});
    const std::vector<std::vector<NodeId>> levels = nodes_by_level(h);
    for (size_t l = 0; l < levels.size(); ++l) {
        for (const auto& [n, e] : new_vertices_of_level(h, levels[l])) {
            const NodeId p = n < cp.size() ? cp[n] : kNoNode;
            const VertexId previous = (p != kNoNode && !prev.is_leaf(p)) ? prev.midpoint(p, e) : kNoVertex;
            order.push_back({h.midpoint(n, e), previous, n, uint8_t(e), uint8_t(l + 1)});
        }
    }
    return order;
}

}  // namespace amc
