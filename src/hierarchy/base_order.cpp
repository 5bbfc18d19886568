// Re-expresses a hierarchy over a reordered base mesh (paper, II-B: the forest is matched to the
// base-mesh coder's deterministic output order, so no bits are spent on the order).
#include <amc/hierarchy.h>

#include <string>

namespace amc {

Hierarchy reorder_base(const Hierarchy& h, const std::vector<uint32_t>& vertex_order,
                       const std::vector<uint32_t>& triangle_order, const std::vector<uint8_t>& rotation,
                       std::vector<VertexId>* vertex_map) {
    const TriangleMesh& old_base = h.base();
    if (vertex_order.size() != old_base.positions.size() || triangle_order.size() != old_base.triangles.size() ||
        rotation.size() != triangle_order.size())
        throw Error("reorder_base: orders do not match the base mesh");
    std::vector<uint32_t> new_id(vertex_order.size(), kNoVertex);
    for (uint32_t i = 0; i < vertex_order.size(); ++i) {
        if (vertex_order[i] >= new_id.size() || new_id[vertex_order[i]] != kNoVertex)
            throw Error("reorder_base: vertex order is not a permutation");
        new_id[vertex_order[i]] = i;
    }
    TriangleMesh base;
    base.single_precision = old_base.single_precision;
    base.positions.resize(vertex_order.size());
    for (uint32_t i = 0; i < vertex_order.size(); ++i) base.positions[i] = old_base.positions[vertex_order[i]];
    base.triangles.resize(triangle_order.size());
    std::vector<uint8_t> seen(triangle_order.size(), 0);
    for (uint32_t t = 0; t < triangle_order.size(); ++t) {
        const uint32_t o = triangle_order[t];
        if (o >= seen.size() || seen[o] || rotation[t] > 2) throw Error("reorder_base: triangle order is not a permutation");
        seen[o] = 1;
        for (int i = 0; i < 3; ++i) base.triangles[t][i] = new_id[old_base.triangles[o][(i + rotation[t]) % 3]];
    }

    // Replay the forest breadth-first. A node rotated by r has as child k the old node's child
    // red_split::kRotatedChild[r][k], rotated by r as well. The default
    // diagonal rule is cyclic, so diagonal flags carry over unchanged.
    Hierarchy out(std::move(base));
    out.reserve(h.node_count(), h.vertex_count());  // grown once, not by doubling split by split
    if (vertex_map != nullptr) vertex_map->assign(h.positions().size(), kNoVertex);
    out.set_vertex_placer([](void*, Vec3 a, Vec3) { return a; }, nullptr);  // positions copied below
    std::vector<std::pair<NodeId, NodeId>> queue;  // (old node, new node)
    std::vector<uint8_t> node_rotation;
    for (uint32_t t = 0; t < triangle_order.size(); ++t) {
        queue.push_back({triangle_order[t], t});
        node_rotation.push_back(rotation[t]);
    }
    for (size_t i = 0; i < queue.size(); ++i) {
        const auto [old_node, new_node] = queue[i];
        const int r = node_rotation[i];
        out.set_diagonal_flipped(new_node, h.diagonal_flipped(old_node));
        if (vertex_map != nullptr) {
            for (int i = 0; i < 3; ++i) (*vertex_map)[h.vertex(old_node, (i + r) % 3)] = out.vertex(new_node, i);
        }
        if (h.is_leaf(old_node)) continue;
        out.split(new_node);
        for (int e = 0; e < 3; ++e) out.set_position(out.midpoint(new_node, e), h.position(h.midpoint(old_node, (e + r) % 3)));
        for (int k = 0; k < 4; ++k) {
            queue.push_back({h.child(old_node, red_split::kRotatedChild[r][k]), out.child(new_node, k)});
            node_rotation.push_back(uint8_t(r));
        }
    }
    out.set_vertex_placer(nullptr, nullptr);
    return out;
}

}  // namespace amc
