// Re-expresses a hierarchy over a reordered base mesh (paper, II-B: the forest is matched to the
// base-mesh coder's deterministic output order, so no bits are spent on the order), or over the
// base triangles of some of its roots (the encoder's chunks).
#include "hierarchy/hierarchy_builder.h"

#include "common/check.h"
#include "common/huge_pages.h"
#include "common/parallel.h"

#include <amc/hierarchy.h>

#include <algorithm>
#include <memory>
#include <string>

namespace amc {

namespace {
// i % 3 for i in 0..5: an edge index plus a rotation, without the division's multiply and shifts
// (a tenth of the reorder's instructions were these remainders).
constexpr int kEdgeMod3[6] = {0, 1, 2, 0, 1, 2};
}  // namespace

Hierarchy reorder_base(const Hierarchy& h, const std::vector<uint32_t>& vertex_order,
                       const std::vector<uint32_t>& triangle_order, const std::vector<uint8_t>& rotation,
                       std::vector<VertexId>* vertex_map) {
    return HierarchyBuilder::reorder_base(h, vertex_order, triangle_order, rotation, vertex_map, 1);
}

Hierarchy HierarchyBuilder::reorder_base(const Hierarchy& h, const std::vector<uint32_t>& vertex_order,
                                         const std::vector<uint32_t>& triangle_order, const std::vector<uint8_t>& rotation,
                                         std::vector<VertexId>* vertex_map, unsigned threads) {
    std::vector<uint32_t> new_id;
    TriangleMesh base = reordered_base_mesh(h.base(), vertex_order, triangle_order, rotation, new_id);
    return reordered(h, std::move(base), triangle_order, rotation, new_id, vertex_map, threads);
}

TriangleMesh HierarchyBuilder::reordered_base_mesh(const TriangleMesh& old_base, const std::vector<uint32_t>& vertex_order,
                                                   const std::vector<uint32_t>& triangle_order,
                                                   const std::vector<uint8_t>& rotation, std::vector<uint32_t>& new_id) {
    if (vertex_order.size() != old_base.positions.size() || triangle_order.size() != old_base.triangles.size() ||
        rotation.size() != triangle_order.size())
        throw Error("reorder_base: orders do not match the base mesh");
    new_id.assign(vertex_order.size(), kNoVertex);
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
    return base;
}

// What replaying the forest breadth-first with split() gives (each node's children in the rotated
// order, each split creating the midpoints its earlier-split neighbours have not), made directly
// and in parallel: the replay's order fixes every id, so each node is written on its own. A node
// rotated by r has as child k the old node's child red_split::kRotatedChild[r][k], rotated by r
// as well; its edge e is the old node's edge (e + r) % 3. The default diagonal rule is cyclic, so
// diagonal flags carry over unchanged.
Hierarchy HierarchyBuilder::reordered(const Hierarchy& h, TriangleMesh base, const std::vector<uint32_t>& triangle_order,
                                      const std::vector<uint8_t>& rotation, const std::vector<uint32_t>& base_vertex_id,
                                      std::vector<VertexId>* vertex_map_out, unsigned threads) {
    Hierarchy out(std::move(base));
    const NodeId roots = out.root_count();
    // The replay's order: node j of the result is old node old_of[j] turned by turn[j]. It is
    // breadth-first, so made a level at a time: each level's nodes in ranges on `threads` threads,
    // the split ones counted first, then their children placed after the level in that order.
    // These arrays, new_of and creates are left unset: only live nodes are reached and looked up,
    // and each entry is written by the threads' passes before it is read, which takes the first
    // touch of their pages off the serial part too.
    const std::unique_ptr<NodeId[]> old_of = written_whole_array<NodeId>(h.node_capacity());
    const std::unique_ptr<NodeId[]> first_child = written_whole_array<NodeId>(h.node_capacity());
    const std::unique_ptr<uint8_t[]> turn = written_whole_array<uint8_t>(h.node_capacity());
    const std::unique_ptr<NodeId[]> new_of = written_whole_array<NodeId>(h.node_capacity());
    for (uint32_t t = 0; t < triangle_order.size(); ++t) {
        old_of[t] = triangle_order[t];
        turn[t] = rotation[t];
    }
    // Each pass reads the old nodes in the replay's order, which jumps about h: fetched kAhead early.
    constexpr size_t kAhead = 16;
    constexpr size_t kRange = size_t(1) << 16;  // nodes per task
    std::vector<uint64_t> split_before;  // per range of the level: its split nodes, then the ranges' before it
    size_t begin = 0, end = roots;  // the level's nodes; at the end, every node
    while (begin < end) {
        const size_t level_ranges = (end - begin + kRange - 1) / kRange;
        split_before.assign(level_ranges + 1, 0);
        // (Through local pointers and counts: a store through a uint8_t may alias anything, and made
        // the compiler reload the vectors' pointers after each.)
        parallel_for(level_ranges, threads, [&](size_t i) {  // first_child[j]: the old node's, for now
            const NodeId* old = old_of.get();
            NodeId* first = first_child.get();
            uint64_t split = 0;
            for (size_t j = begin + i * kRange, stop = std::min(end, begin + (i + 1) * kRange); j < stop; ++j) {
                if (j + kAhead < end) prefetch(h, old[j + kAhead]);
                new_of[old[j]] = NodeId(j);
                first[j] = h.is_leaf(old[j]) ? kNoNode : h.child(old[j], 0);
                split += first[j] != kNoNode;
            }
            split_before[i + 1] = split;
        });
        for (size_t i = 0; i < level_ranges; ++i) split_before[i + 1] += split_before[i];
        const size_t next_end = end + 4 * size_t(split_before[level_ranges]);
        AMC_REQUIRE(next_end <= h.node_capacity(), limit_exceeded, "reorder_base: more nodes than the hierarchy holds");
        parallel_for(level_ranges, threads, [&](size_t i) {
            NodeId* old = old_of.get();
            NodeId* first = first_child.get();
            uint8_t* turned = turn.get();
            size_t next = end + 4 * size_t(split_before[i]);
            for (size_t j = begin + i * kRange, stop = std::min(end, begin + (i + 1) * kRange); j < stop; ++j) {
                const NodeId old_first = first[j];
                if (old_first == kNoNode) continue;
                first[j] = NodeId(next);
                const uint8_t r = turned[j];
                for (int k = 0; k < 4; ++k) {
                    old[next + size_t(k)] = old_first + NodeId(red_split::kRotatedChild[r][k]);
                    turned[next + size_t(k)] = r;
                }
                next += 4;
            }
        });
        begin = end;
        end = next_end;
    }
    const size_t n = end;
    // Split node j creates the midpoint of its edge e unless its same-level neighbour there was
    // split before it (split() then takes the neighbour's): bit e of creates[j].
    const std::unique_ptr<uint8_t[]> creates = written_whole_array<uint8_t>(n);
    const size_t ranges = (n + kRange - 1) / kRange;
    std::vector<uint64_t> first_vertex(ranges + 1, 0);
    parallel_for(ranges, threads, [&](size_t i) {
        uint64_t created = 0;  // not first_vertex[i + 1]: neighbouring ranges' counts share cache lines
        for (size_t j = i * kRange; j < std::min(n, (i + 1) * kRange); ++j) {
            if (j + kAhead < n) prefetch(h, old_of[j + kAhead]);
            uint8_t made = 0;
            if (first_child[j] != kNoNode)
                for (int e = 0; e < 3; ++e) {
                    const NodeId q = h.neighbor(old_of[j], kEdgeMod3[e + turn[j]]);
                    if (q == kNoNode || h.is_leaf(q) || new_of[q] > j) {
                        made |= uint8_t(1u << e);
                        ++created;
                    }
                }
            creates[j] = made;
        }
        first_vertex[i + 1] = created;
    });
    first_vertex[0] = out.positions_.size();
    for (size_t i = 0; i < ranges; ++i) first_vertex[i + 1] += first_vertex[i];
    AMC_REQUIRE(first_vertex[ranges] < kNoVertex, limit_exceeded, "reorder_base: too many vertices");
    std::vector<VertexId> own_map;
    std::vector<VertexId>& vertex_map = vertex_map_out != nullptr ? *vertex_map_out : own_map;
    reserve_huge(vertex_map, h.positions().size(), HugePages::written_whole);
    vertex_map.assign(h.positions().size(), kNoVertex);
    for (size_t v = 0; v < base_vertex_id.size(); ++v) vertex_map[v] = base_vertex_id[v];
    reserve_huge(out.positions_, size_t(first_vertex[ranges]), HugePages::written_whole);
    out.positions_.resize(size_t(first_vertex[ranges]));
    // The midpoints, numbered in the replay's order; each written by the node that creates it. (The
    // constructor marked far base positions.)
    parallel_for(ranges, threads, [&](size_t i) {
        VertexId next = VertexId(first_vertex[i]);
        bool far = false;
        for (size_t j = i * kRange; j < std::min(n, (i + 1) * kRange); ++j) {
            if (j + kAhead < n && creates[j + kAhead] != 0) prefetch(h, old_of[j + kAhead]);
            if (first_child[j] == kNoNode) continue;
            for (int e = 0; e < 3; ++e) {
                if (!((creates[j] >> e) & 1)) continue;
                const VertexId old = h.midpoint(old_of[j], kEdgeMod3[e + turn[j]]);
                vertex_map[old] = next;
                out.positions_[next] = h.position(old);
                far |= Hierarchy::is_far(out.positions_[next++]);
            }
        }
        out.far_positions_.raise_if(far);
    });
    reserve_huge(out.nodes_, n, HugePages::written_whole);
    out.nodes_.resize(n);  // Node() writes nothing: each is written whole below
    reserve_huge(out.block_parent_, (n - roots) / 4, HugePages::written_whole);
    out.block_parent_.assign((n - roots) / 4, kNoNode);
    parallel_for(ranges, threads, [&](size_t i) {
        for (size_t j = i * kRange; j < std::min(n, (i + 1) * kRange); ++j) {
            if (j + kAhead < n) prefetch(h, old_of[j + kAhead]);
            const NodeId o = old_of[j];
            const int r = turn[j];
            Hierarchy::Node& node = out.nodes_[j];
            if (first_child[j] != kNoNode) out.block_parent_[(first_child[j] - roots) / 4] = NodeId(j);
            node.first_child = first_child[j];
            if (j < roots) {  // the constructor linked the roots
                node.flags = uint8_t((node.flags & 7u) | (h.diagonal_flipped(o) ? 8u : 0u));
                continue;
            }
            node.nbr_edge = 0;
            node.flags = h.diagonal_flipped(o) ? 8u : 0u;
            for (int e = 0; e < 3; ++e) {
                const int old_edge = kEdgeMod3[e + r];
                node.v[e] = vertex_map[h.vertex(o, old_edge)];
                const NodeId q = h.neighbor(o, old_edge);
                node.nbr[e] = q == kNoNode ? kNoNode : new_of[q];
                if (q != kNoNode)
                    node.nbr_edge |= uint8_t(kEdgeMod3[h.neighbor_edge(o, old_edge) + 3 - turn[new_of[q]]] << (2 * e));
                if (h.is_boundary_edge(o, old_edge)) node.flags |= uint8_t(1u << e);
            }
            node.level = uint8_t(h.level(o));
            node.reserved = 0;
        }
    });
    out.live_nodes_ = uint32_t(n);
    out.live_vertices_ = uint32_t(out.positions_.size());
    return out;
}

// Written in the replay's order, so that each node finds its parent's vertices and midpoints made.
Hierarchy HierarchyBuilder::subforest(const Hierarchy& h, TriangleMesh base, const std::vector<NodeId>& roots,
                                      const std::vector<VertexId>& base_vertex, const std::vector<uint32_t>& root_of,
                                      const std::vector<uint8_t>& root_in, uint32_t root_in_first, NodeId* local,
                                      std::vector<VertexId>* vertex_of_out, SubforestRoom* room) {
    Hierarchy out(std::move(base));
    if (room != nullptr) adopt_storage(out, std::move(room->arrays));
    const NodeId root_count = out.root_count();
    // Node j of the result is node old_of[j] of h.
    std::vector<NodeId> old_of;
    if (room != nullptr) old_of.swap(room->old_of);
    old_of.assign(roots.begin(), roots.end());
    reserve_huge(old_of, h.node_count(), HugePages::written_whole);  // address space: only the chunk's part is touched
    for (size_t j = 0; j < old_of.size(); ++j) {
        const NodeId o = old_of[j];
        local[o] = NodeId(j);
        if (!h.is_leaf(o))
            for (int k = 0; k < 4; ++k) old_of.push_back(h.child(o, k));
    }
    const size_t n = old_of.size();
    auto taken = [&](NodeId q) {
        return q != kNoNode && root_of[q] - root_in_first < root_in.size() && root_in[root_of[q] - root_in_first] != 0;
    };
    std::vector<VertexId> vertex_of;
    if (room != nullptr) vertex_of.swap(room->vertex_of);
    vertex_of.assign(base_vertex.begin(), base_vertex.end());
    reserve_huge(vertex_of, h.positions().size(), HugePages::written_whole);
    reserve_huge(out.nodes_, n, HugePages::written_whole);
    out.nodes_.resize(n);  // the roots stay as the constructor made them
    reserve_huge(out.block_parent_, (n - root_count) / 4, HugePages::written_whole);
    out.block_parent_.assign((n - root_count) / 4, kNoNode);
    // One pass in the replay's order: node j's links, flags and first child; when it is split, its
    // midpoints (a new vertex unless its neighbour there was split before it: split() then takes
    // the neighbour's, read from the neighbour's children written already) and its four
    // children's vertices, level and boundary flags.
    NodeId next_child = root_count;
    for (size_t j = 0; j < n; ++j) {
        const NodeId o = old_of[j];
        Hierarchy::Node& node = out.nodes_[j];
        NodeId q[3], link[3];  // the neighbours in h, and in the result (kNoNode when not taken)
        for (int e = 0; e < 3; ++e) {
            q[e] = h.neighbor(o, e);
            link[e] = taken(q[e]) ? local[q[e]] : kNoNode;
        }
        if (j >= root_count) {
            node.nbr_edge = 0;
            for (int e = 0; e < 3; ++e) {
                node.nbr[e] = link[e];
                if (link[e] != kNoNode) node.nbr_edge |= uint8_t(h.neighbor_edge(o, e) << (2 * e));
            }
            node.reserved = 0;
        }
        const bool leaf = h.is_leaf(o);
        node.flags = uint8_t((node.flags & 7u) | (leaf && h.diagonal_flipped(o) ? 8u : 0u));
        node.first_child = leaf ? kNoNode : next_child;
        if (leaf) continue;
        VertexId mid[3];
        for (int e = 0; e < 3; ++e) {
            if (link[e] != kNoNode && link[e] < j && !h.is_leaf(q[e])) {
                mid[e] = out.midpoint(link[e], h.neighbor_edge(o, e));
            } else {
                mid[e] = VertexId(vertex_of.size());
                vertex_of.push_back(h.midpoint(o, e));
            }
        }
        out.block_parent_[(next_child - root_count) / 4] = NodeId(j);
        const VertexId points[6] = {node.v[0], node.v[1], node.v[2], mid[0], mid[1], mid[2]};
        for (int k = 0; k < 4; ++k) {
            Hierarchy::Node& child = out.nodes_[next_child + NodeId(k)];
            for (int i = 0; i < 3; ++i) child.v[i] = points[red_split::kChildPoints[k][i]];
            child.level = uint8_t(node.level + 1);
            child.flags = uint8_t(node.flags & red_split::kChildEdges[k].boundary);
        }
        next_child += 4;
    }
    reserve_huge(out.positions_, vertex_of.size(), HugePages::written_whole);
    out.positions_.resize(vertex_of.size());
    for (size_t v = base_vertex.size(); v < vertex_of.size(); ++v) {
        out.positions_[v] = h.position(vertex_of[v]);
        out.far_positions_.raise_if(Hierarchy::is_far(out.positions_[v]));
    }
    out.live_nodes_ = uint32_t(n);
    out.live_vertices_ = uint32_t(out.positions_.size());
    if (vertex_of_out != nullptr) *vertex_of_out = std::move(vertex_of);
    return out;
}

SubforestRoom HierarchyBuilder::subforest_room(const Hierarchy& h, size_t nodes, size_t vertices) {
    SubforestRoom room;
    nodes = std::min<size_t>(nodes, h.node_count());
    vertices = std::min(vertices, h.positions().size());
    reserve_huge(room.arrays.nodes_, nodes, HugePages::written_whole);
    reserve_huge(room.arrays.block_parent_, nodes / 4, HugePages::written_whole);
    reserve_huge(room.arrays.positions_, h.positions().size(), HugePages::written_whole);  // address space
    reserve_huge(room.old_of, h.node_count(), HugePages::written_whole);                  // as in subforest
    reserve_huge(room.vertex_of, h.positions().size(), HugePages::written_whole);
    room.nodes = nodes;
    room.vertices = vertices;
    return room;
}

void HierarchyBuilder::make_resident(SubforestRoom& room) {
    populate_pages(room.arrays.nodes_.data(), room.nodes * sizeof(Hierarchy::Node));
    populate_pages(room.arrays.block_parent_.data(), room.nodes / 4 * sizeof(NodeId));
    populate_pages(room.arrays.positions_.data(), room.vertices * sizeof(Vec3));
    populate_pages(room.old_of.data(), room.nodes * sizeof(NodeId));
    populate_pages(room.vertex_of.data(), room.vertices * sizeof(VertexId));
}

}  // namespace amc
