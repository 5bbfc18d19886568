// The red-green forest: construction over a base mesh, split, balanced refinement with closure,
// coarsening, and the canonical breadth-first order (the decoders' bulk split: level_split.cpp).
#include <amc/hierarchy.h>

#include "hierarchy/hierarchy_builder.h"

#include "common/check.h"
#include "common/huge_pages.h"
#include "hierarchy/midpoint_placers.h"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

namespace amc {

Vec3 midpoint_placer(void* single_precision, Vec3 a, Vec3 b) {
    return round_if(single_precision, {midpoint_coordinate(a.x, b.x), midpoint_coordinate(a.y, b.y), midpoint_coordinate(a.z, b.z)});
}

namespace {

// One past the highest vertex the triangles use; throws Error when that is not a vertex of the
// mesh (not a validated mesh: refused before anything is sized by it).
uint64_t checked_vertex_end(const TriangleMesh& base) {
    uint32_t highest = 0;
    for (const Triangle& t : base.triangles) highest = std::max({highest, t[0], t[1], t[2]});
    const uint64_t vertex_end = base.triangles.empty() ? 0 : uint64_t{highest} + 1;
    if (vertex_end > base.positions.size())
        throw Error("base mesh: a triangle refers to vertex " + std::to_string(vertex_end - 1) + " of " +
                    std::to_string(base.positions.size()));
    return vertex_end;
}

}  // namespace

Hierarchy::Hierarchy(TriangleMesh base) : base_(std::move(base)) { make_roots(checked_vertex_end(base_)); }

void Hierarchy::make_roots(uint64_t vertex_end) {
    const uint32_t f0 = root_count();
    const Triangle* const triangles = base_.triangles.data();
    nodes_.resize(f0);
    positions_.assign(base_.positions.begin(), base_.positions.end());
    for (const Vec3& p : positions_) far_positions_.raise_if(is_far(p));
    live_nodes_ = f0;
    live_vertices_ = static_cast<uint32_t>(positions_.size());

    // The directed edges grouped by their first vertex (a counting sort, linear in the mesh), each
    // as (second vertex, triangle, edge) in triangle order. The neighbour across (a,b) is the
    // triangle with (b,a), among the few edges leaving b; the last one if there are several (a
    // mesh that is not consistently oriented). A decoder starts from the base mesh for every
    // stream: sorting the edges took 3% of a 10^5-node decode over 500 roots, and a division
    // by 3 per half-edge a tenth of a decode's restart over 4000 (docs/HIERARCHY_CODER.md, Speed).
    for (uint32_t t = 0; t < f0; ++t) {
        Node& node = nodes_[t];
        for (int i = 0; i < 3; ++i) {
            node.v[i] = triangles[t][i];
            node.nbr[i] = kNoNode;
        }
        node.first_child = kNoNode;
        node.nbr_edge = 0;
        node.level = 0;
        node.flags = 0;
        node.reserved = 0;
    }
    struct Leaving {
        uint32_t to;
        uint32_t triangle;
        uint32_t edge;
    };
    std::vector<size_t> start(size_t(vertex_end) + 2, 0);
    for (uint32_t t = 0; t < f0; ++t)
        for (int i = 0; i < 3; ++i) ++start[size_t(triangles[t][i]) + 2];
    for (size_t v = 2; v < start.size(); ++v) start[v] += start[v - 1];
    std::vector<Leaving> leaving(3 * size_t(f0));
    for (uint32_t t = 0; t < f0; ++t)
        for (uint32_t i = 0; i < 3; ++i) leaving[start[size_t(triangles[t][i]) + 1]++] = {triangles[t][i == 2 ? 0 : i + 1], t, i};
    // Per vertex b: b's leaving edges (b, to) noted by `to` (the entry's index), then the edge
    // (a, b) before each in its triangle finds its neighbour's (b, a) at once; the last one in
    // triangle order, as a search would. A note left by a vertex before b lies outside b's entries.
    std::vector<size_t> leaving_to(size_t(vertex_end), ~size_t{0});
    for (size_t b = 0; b < vertex_end; ++b) {
        const size_t first = start[b], count = start[b + 1] - first;
        for (size_t k = first; k < first + count; ++k) leaving_to[leaving[k].to] = k;
        for (size_t k = first; k < first + count; ++k) {
            const uint32_t t = leaving[k].triangle, e = leaving[k].edge == 0 ? 2 : leaving[k].edge - 1;  // (a, b)
            const size_t found = leaving_to[nodes_[t].v[e]];
            if (found - first >= count) {
                nodes_[t].flags |= uint8_t(1u << e);
            } else {
                nodes_[t].nbr[e] = leaving[found].triangle;
                nodes_[t].nbr_edge |= uint8_t(leaving[found].edge << (2 * e));
            }
        }
    }
    set_vertex_placer(nullptr, nullptr);
}

void Hierarchy::reset(TriangleMesh base) {
    // The node and position arrays keep their memory; nothing is copied twice. A base that is
    // refused leaves the hierarchy as it was.
    const uint64_t vertex_end = checked_vertex_end(base);
    base_ = std::move(base);
    nodes_.clear();
    block_parent_.clear();
    positions_.clear();
    far_positions_ = FarFlag();
    free_blocks_.clear();
    free_vertices_.clear();
    structure_checked_ = false;
    make_roots(vertex_end);
}

void Hierarchy::set_vertex_placer(VertexPlacer placer, void* context) {
    if (placer == nullptr) {
        static int round_to_float;  // any non-null context asks the midpoint placer to round
        placer = midpoint_placer;
        context = base_.single_precision ? &round_to_float : nullptr;
    }
    placer_ = placer;
    placer_context_ = context;
}

void Hierarchy::reserve(size_t nodes, size_t vertices) {
    reserve_huge(nodes_, nodes);
    reserve_huge(block_parent_, nodes > root_count() ? (nodes - root_count()) / 4 : 0);
    reserve_huge(positions_, vertices);
}

void Hierarchy::set_diagonal_flipped(NodeId n, bool flipped) {
    nodes_[n].flags = uint8_t((nodes_[n].flags & ~8u) | (flipped ? 8u : 0u));
}

int Hierarchy::depth() const {
    int d = 0;
    for (const Node& node : nodes_) {
        if (node.level != kDeadLevel) d = std::max(d, int(node.level));
    }
    return d;
}

void Hierarchy::link(NodeId a, int ea, NodeId b, int eb) {
    nodes_[a].nbr[ea] = b;
    nodes_[a].nbr_edge = uint8_t((nodes_[a].nbr_edge & ~(3u << (2 * ea))) | (unsigned(eb) << (2 * ea)));
    nodes_[b].nbr[eb] = a;
    nodes_[b].nbr_edge = uint8_t((nodes_[b].nbr_edge & ~(3u << (2 * eb))) | (unsigned(ea) << (2 * eb)));
}

VertexId Hierarchy::new_vertex(Vec3 p) {
    ++live_vertices_;
    if (!free_vertices_.empty()) {
        VertexId v = free_vertices_.back();
        free_vertices_.pop_back();
        positions_[v] = p;
        far_positions_.raise_if(is_far(p));
        return v;
    }
    positions_.push_back(p);
    far_positions_.raise_if(is_far(p));
    return static_cast<VertexId>(positions_.size() - 1);
}

NodeId Hierarchy::allocate_children(NodeId parent) {
    live_nodes_ += 4;
    if (!free_blocks_.empty()) {
        NodeId c = free_blocks_.back();
        free_blocks_.pop_back();
        block_parent_[(c - root_count()) / 4] = parent;
        return c;
    }
    NodeId c = static_cast<NodeId>(nodes_.size());
    nodes_.resize(nodes_.size() + 4);
    block_parent_.push_back(parent);
    return c;
}

void Hierarchy::split(NodeId n) {
    structure_checked_ = false;
    VertexId m[3];
    for (int e = 0; e < 3; ++e) {
        NodeId q = nodes_[n].nbr[e];
        if (q != kNoNode && !is_leaf(q)) {
            m[e] = midpoint(q, neighbor_edge(n, e));
        } else {
            Vec3 a = positions_[nodes_[n].v[e]];
            Vec3 b = positions_[nodes_[n].v[(e + 1) % 3]];
            m[e] = new_vertex(placer_(placer_context_, a, b));
        }
    }
    const NodeId c = allocate_children(n);  // may reallocate nodes_: no references held across
    const Node parent = nodes_[n];
    write_vertices(&nodes_[c], parent.v, m);
    for (int k = 0; k < 4; ++k) {
        Node& child = nodes_[c + k];
        for (int i = 0; i < 3; ++i) child.nbr[i] = kNoNode;
        child.nbr_edge = 0;
        child.level = uint8_t(parent.level + 1);
        child.flags = uint8_t(parent.flags & red_split::kChildEdges[k].boundary);
        child.reserved = 0;
    }
    for (int k = 0; k < 4; ++k) {
        for (int e = 0; e < 3; ++e) {
            const int s = red_split::sibling(k, e);
            if (s > k) link(c + NodeId(k), e, c + NodeId(s), e);
        }
    }
    // The edge runs the other way in the neighbour: the first half of ours is the second of its.
    for (int e = 0; e < 3; ++e) {
        NodeId q = parent.nbr[e];
        if (q == kNoNode || is_leaf(q)) continue;
        int eq = neighbor_edge(n, e);
        link(c + red_split::kFirstHalfChild[e], e, child(q, red_split::kSecondHalfChild[eq]), eq);
        link(c + red_split::kSecondHalfChild[e], e, child(q, red_split::kFirstHalfChild[eq]), eq);
    }
    nodes_[n].first_child = c;
}

void HierarchyBuilder::undo_splits(Hierarchy& h, const std::vector<NodeId>& parents, size_t from) {
    AMC_REQUIRE(h.free_blocks_.empty() && h.free_vertices_.empty(), invalid_input,
                "undo_splits: the hierarchy has ids free for reuse");
    for (size_t i = parents.size(); i-- > from;) {
        const NodeId n = parents[i];
        const NodeId c = h.nodes_[n].first_child;
        AMC_REQUIRE(c != kNoNode && size_t(c) + 4 == h.nodes_.size(), invalid_input,
                    "undo_splits: node " + std::to_string(n) + " is not the last one split");
        // Edges 2, 1, 0: split() made their new vertices in the order 0, 1, 2.
        for (int e = 2; e >= 0; --e) {
            const NodeId q = h.nodes_[n].nbr[e];
            if (q != kNoNode && !h.is_leaf(q)) {
                const int eq = h.neighbor_edge(n, e);
                h.nodes_[h.child(q, red_split::kFirstHalfChild[eq])].nbr[eq] = kNoNode;
                h.nodes_[h.child(q, red_split::kSecondHalfChild[eq])].nbr[eq] = kNoNode;
            } else {
                AMC_REQUIRE(size_t(h.midpoint(n, e)) + 1 == h.positions_.size(), invalid_input,
                            "undo_splits: a midpoint of node " + std::to_string(n) + " is not the last vertex");
                h.positions_.pop_back();
                --h.live_vertices_;
            }
        }
        h.nodes_.resize(c);
        h.block_parent_.pop_back();
        h.live_nodes_ -= 4;
        h.nodes_[n].first_child = kNoNode;
    }
    h.structure_checked_ = false;
}

uint32_t Hierarchy::refine(NodeId n, std::vector<NodeId>* split_nodes) {
    if (!is_leaf(n)) return 0;
    uint32_t splits = 0;
    std::vector<NodeId> todo{n};
    while (!todo.empty()) {
        const NodeId x = todo.back();
        if (!is_leaf(x)) {
            todo.pop_back();
            continue;
        }
        // Balance: a missing same-level neighbour means the region across that edge is a
        // coarser leaf (the parent's neighbour); refine it first.
        bool blocked = false;
        for (int e = 0; e < 3 && !blocked; ++e) {
            if (nodes_[x].nbr[e] == kNoNode && !is_boundary_edge(x, e)) {
                todo.push_back(nodes_[parent(x)].nbr[e]);
                blocked = true;
            }
        }
        if (blocked) continue;
        todo.pop_back();
        if (nodes_[x].level >= kMaxLevel) throw Error("refine: level cap reached");
        split(x);
        ++splits;
        if (split_nodes != nullptr) split_nodes->push_back(x);
        // Closure: a same-level leaf with three hanging nodes is red refined.
        for (int e = 0; e < 3; ++e) {
            NodeId q = nodes_[x].nbr[e];
            if (q != kNoNode && is_leaf(q) && hanging_node_count(q) == 3) todo.push_back(q);
        }
    }
    return splits;
}

bool Hierarchy::can_coarsen(NodeId n) const {
    if (is_leaf(n)) return false;
    for (int k = 0; k < 4; ++k) {
        if (!is_leaf(child(n, k))) return false;
    }
    int refined_neighbours = 0;
    for (int e = 0; e < 3; ++e) {
        NodeId q = nodes_[n].nbr[e];
        if (q == kNoNode || is_leaf(q)) continue;
        ++refined_neighbours;
        int eq = neighbor_edge(n, e);
        // Children of q along the shared edge must stay within one level of n.
        if (!is_leaf(child(q, red_split::kFirstHalfChild[eq])) || !is_leaf(child(q, red_split::kSecondHalfChild[eq])))
            return false;
    }
    return refined_neighbours < 3;  // otherwise the closure would refine n again
}

bool Hierarchy::coarsen(NodeId n) {
    if (!can_coarsen(n)) return false;
    structure_checked_ = false;
    const NodeId c = nodes_[n].first_child;
    for (int e = 0; e < 3; ++e) {
        NodeId q = nodes_[n].nbr[e];
        if (q != kNoNode && !is_leaf(q)) {
            int eq = neighbor_edge(n, e);
            nodes_[child(q, red_split::kFirstHalfChild[eq])].nbr[eq] = kNoNode;
            nodes_[child(q, red_split::kSecondHalfChild[eq])].nbr[eq] = kNoNode;
        } else {
            free_vertices_.push_back(midpoint(n, e));
            --live_vertices_;
        }
    }
    for (int k = 0; k < 4; ++k) nodes_[c + k].level = kDeadLevel;
    free_blocks_.push_back(c);
    live_nodes_ -= 4;
    nodes_[n].first_child = kNoNode;
    return true;
}

std::vector<NodeId> Hierarchy::breadth_first_order() const {
    std::vector<NodeId> order;
    order.reserve(live_nodes_);
    for (NodeId r = 0; r < root_count(); ++r) order.push_back(r);
    for (size_t i = 0; i < order.size(); ++i) {
        NodeId n = order[i];
        if (!is_leaf(n)) {
            for (int k = 0; k < 4; ++k) order.push_back(child(n, k));
        }
    }
    return order;
}

std::vector<NodeId> Hierarchy::leaves() const {
    std::vector<NodeId> result;
    for (NodeId n : breadth_first_order()) {
        if (is_leaf(n)) result.push_back(n);
    }
    return result;
}

std::vector<uint32_t> canonical_vertex_order(const Hierarchy& h) { return canonical_vertex_order(h, h.breadth_first_order()); }

std::vector<uint32_t> canonical_vertex_order(const Hierarchy& h, const std::vector<NodeId>& breadth_first) {
    std::vector<uint32_t> order(h.positions().size(), kNoVertex);
    uint32_t next = 0;
    for (uint32_t v = 0; v < h.base().positions.size(); ++v) order[v] = next++;
    for (NodeId n : breadth_first) {
        if (h.is_leaf(n)) continue;
        for (int e = 0; e < 3; ++e) {
            VertexId m = h.midpoint(n, e);
            if (order[m] == kNoVertex) order[m] = next++;
        }
    }
    return order;
}

std::vector<Vec3> canonical_positions(const Hierarchy& h) {
    const std::vector<uint32_t> canonical = canonical_vertex_order(h);
    std::vector<Vec3> points(h.vertex_count());
    for (size_t v = 0; v < canonical.size(); ++v) {
        if (canonical[v] != kNoVertex) points[canonical[v]] = h.position(VertexId(v));
    }
    return points;
}

namespace {

bool same_bits(Vec3 a, Vec3 b) { return std::memcmp(&a, &b, sizeof(Vec3)) == 0; }

int two_hanging_diagonal(const Hierarchy& h, NodeId n) {
    return h.is_leaf(n) && h.hanging_node_count(n) == 2 ? int(h.diagonal_flipped(n)) : -1;
}

}  // namespace

bool identical(const Hierarchy& a, const Hierarchy& b) {
    if (a.base().triangles != b.base().triangles) return false;
    if (a.base().positions.size() != b.base().positions.size()) return false;
    if (a.single_precision() != b.single_precision()) return false;
    const std::vector<NodeId> oa = a.breadth_first_order();
    const std::vector<NodeId> ob = b.breadth_first_order();
    if (oa.size() != ob.size()) return false;
    for (size_t i = 0; i < oa.size(); ++i) {
        if (a.is_leaf(oa[i]) != b.is_leaf(ob[i])) return false;
        if (two_hanging_diagonal(a, oa[i]) != two_hanging_diagonal(b, ob[i])) return false;
    }
    if (a.vertex_count() != b.vertex_count()) return false;
    const std::vector<Vec3> pa = canonical_positions(a), pb = canonical_positions(b);
    for (size_t i = 0; i < pa.size(); ++i) {
        if (!same_bits(pa[i], pb[i])) return false;
    }
    return true;
}

}  // namespace amc
