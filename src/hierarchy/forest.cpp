// The red-green forest: construction over a base mesh, split, balanced refinement with closure,
// coarsening, and the canonical breadth-first order.
#include <amc/hierarchy.h>

#include "common/exact_float.h"
#include "common/huge_pages.h"
#include "common/simd.h"
#include "hierarchy/hierarchy_builder.h"
#include "hierarchy/red_split_kernels.h"
#include "mesh/vertex_buckets.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <iterator>
#include <string>
#include <utility>
#include <vector>

namespace amc {

namespace {

// 0.5 * (a + b) bit for bit wherever that is finite: the correctly rounded midpoint (halving is
// exact). Where a + b overflows (coordinates beyond DBL_MAX / 2), 0.5 * a + 0.5 * b: exact halves
// of such large values rounded once, the same correctly rounded midpoint, and finite.
double midpoint_coordinate(double a, double b) {
    const double s = a + b;
    return std::fabs(s) <= DBL_MAX ? rounded(0.5 * s) : rounded(0.5 * a) + rounded(0.5 * b);
}

Vec3 round_if(void* single_precision, Vec3 m) {
    return single_precision != nullptr ? rounded_to_float(m) : m;
}

Vec3 midpoint_placer(void* single_precision, Vec3 a, Vec3 b) {
    return round_if(single_precision, {midpoint_coordinate(a.x, b.x), midpoint_coordinate(a.y, b.y), midpoint_coordinate(a.z, b.z)});
}

// midpoint_placer where no coordinate lies beyond DBL_MAX / 2: then a + b can not overflow.
Vec3 near_midpoint_placer(void* single_precision, Vec3 a, Vec3 b) { return round_if(single_precision, rounded_scaled(0.5, a + b)); }

// The end points of a new vertex.
struct Ends {
    VertexId a, b;
};

// A random-access range over the end points of new vertices whose elements are their positions,
// made by `Place` as std::vector::insert copies them: each is written once, into the reserved
// capacity, with no test of the capacity per vertex (push_back's) and no zero-fill first
// (resize's). The end points' positions are fetched kAhead vertices early.
template <class Place>
class NewPositions {
public:
    using iterator_category = std::random_access_iterator_tag;
    using value_type = Vec3;
    using difference_type = std::ptrdiff_t;
    using pointer = const Vec3*;
    using reference = Vec3;

    NewPositions(const Ends* at, const Ends* end, const Vec3* positions, Place place)
        : at_(at), end_(end), positions_(positions), place_(place) {}
    Vec3 operator*() const { return place_(positions_[at_->a], positions_[at_->b]); }
    NewPositions& operator++() {
        if (at_ + kAhead < end_) {
            __builtin_prefetch(positions_ + at_[kAhead].a);
            __builtin_prefetch(positions_ + at_[kAhead].b);
        }
        ++at_;
        return *this;
    }
    NewPositions operator++(int) {
        NewPositions old = *this;
        ++*this;
        return old;
    }
    NewPositions& operator--() {
        --at_;
        return *this;
    }
    NewPositions operator--(int) {
        NewPositions old = *this;
        --at_;
        return old;
    }
    NewPositions& operator+=(difference_type n) {
        at_ += n;
        return *this;
    }
    NewPositions& operator-=(difference_type n) {
        at_ -= n;
        return *this;
    }
    NewPositions operator+(difference_type n) const { return NewPositions(*this) += n; }
    NewPositions operator-(difference_type n) const { return NewPositions(*this) -= n; }
    friend NewPositions operator+(difference_type n, const NewPositions& it) { return it + n; }
    difference_type operator-(const NewPositions& other) const { return at_ - other.at_; }
    Vec3 operator[](difference_type n) const { return *(*this + n); }
    bool operator==(const NewPositions& other) const { return at_ == other.at_; }
    bool operator!=(const NewPositions& other) const { return at_ != other.at_; }
    bool operator<(const NewPositions& other) const { return at_ < other.at_; }
    bool operator>(const NewPositions& other) const { return at_ > other.at_; }
    bool operator<=(const NewPositions& other) const { return at_ <= other.at_; }
    bool operator>=(const NewPositions& other) const { return at_ >= other.at_; }

private:
    // The end points' positions miss the cache far more often than the nodes: with 8 vertices
    // ahead, the loads still waited.
    static constexpr std::ptrdiff_t kAhead = 32;
    const Ends* at_;
    const Ends* end_;
    const Vec3* positions_;
    Place place_;
};

}  // namespace

Hierarchy::Hierarchy(TriangleMesh base) : base_(std::move(base)) {
    const uint32_t f0 = root_count();
    nodes_.resize(f0);
    positions_ = base_.positions;
    for (const Vec3& p : positions_) far_positions_ |= is_far(p);
    live_nodes_ = f0;
    live_vertices_ = static_cast<uint32_t>(positions_.size());

    // The directed edges grouped by their first vertex (bucket_by_vertex, linear in the mesh),
    // each as (second vertex, 3 * triangle + edge) in triangle order. The neighbour across (a,b) is
    // the triangle with (b,a), found among the few edges leaving b; the last one if there are
    // several (a mesh that is not consistently oriented). A decoder starts from the base mesh for
    // every stream, and sorting the edges took 3% of a 10^5-node decode over 500 roots.
    uint64_t vertex_end = 0;  // one past the highest vertex used
    for (uint32_t t = 0; t < f0; ++t) {
        Node& node = nodes_[t];
        for (int i = 0; i < 3; ++i) {
            node.v[i] = base_.triangles[t][i];
            node.nbr[i] = kNoNode;
            vertex_end = std::max(vertex_end, uint64_t{node.v[i]} + 1);
        }
        node.first_child = kNoNode;
        node.nbr_edge = 0;
        node.level = 0;
        node.flags = 0;
        node.reserved = 0;
    }
    if (vertex_end > positions_.size())  // not a validated mesh: refuse before sizing by it
        throw Error("base mesh: a triangle refers to vertex " + std::to_string(vertex_end - 1) + " of " +
                    std::to_string(positions_.size()));
    struct Leaving {
        uint32_t to;
        uint32_t half_edge;  // 3 * triangle + edge
    };
    std::vector<Leaving> leaving;
    const std::vector<size_t> start = bucket_by_vertex(
        size_t(vertex_end), 3 * size_t(f0), [&](size_t h) { return nodes_[h / 3].v[h % 3]; },
        [&](size_t h) { return Leaving{nodes_[h / 3].v[(h % 3 + 1) % 3], uint32_t(h)}; }, leaving);
    for (uint32_t t = 0; t < f0; ++t) {
        for (int e = 0; e < 3; ++e) {
            const uint32_t a = nodes_[t].v[e], b = nodes_[t].v[(e + 1) % 3];
            uint32_t found = kNoNode;
            for (size_t k = start[b]; k < start[b + 1]; ++k) {
                if (leaving[k].to == a) found = leaving[k].half_edge;
            }
            if (found == kNoNode) {
                nodes_[t].flags |= uint8_t(1u << e);
            } else {
                nodes_[t].nbr[e] = found / 3;
                nodes_[t].nbr_edge |= uint8_t((found % 3) << (2 * e));
            }
        }
    }
    set_vertex_placer(nullptr, nullptr);
}

void Hierarchy::reset(TriangleMesh base) {
    Hierarchy roots(std::move(base));
    nodes_.assign(roots.nodes_.begin(), roots.nodes_.end());
    block_parent_.clear();
    positions_.assign(roots.positions_.begin(), roots.positions_.end());
    far_positions_ = roots.far_positions_;
    free_blocks_.clear();
    free_vertices_.clear();
    base_ = std::move(roots.base_);
    live_nodes_ = roots.live_nodes_;
    live_vertices_ = roots.live_vertices_;
    set_vertex_placer(nullptr, nullptr);
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
        far_positions_ |= is_far(p);
        return v;
    }
    positions_.push_back(p);
    far_positions_ |= is_far(p);
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

// split_level writes each new node as three pieces: its vertices and first child (none; bytes
// 0-15), its neighbours (bytes 16-27) and its four bytes of edges, level, flags and a reserved 0.
// Four siblings' pieces are made in registers and stored whole: scalar stores of every field
// made the build store-bound.

// The vertices of four new siblings, in the child order of <amc/red_split.h>, from their parent's
// corners and the midpoints of its edges, and their first child (none) (split and split_level).
void Hierarchy::write_vertices(Node* child, const VertexId corner[3], const VertexId m[3]) {
    static_assert(sizeof(Node) == 32 && offsetof(Node, first_child) == 12 && offsetof(Node, nbr) == 16 &&
                      offsetof(Node, nbr_edge) == 28,
                  "split_level writes nodes by this layout");
    // The fourth word is first_child: kNoNode.
    static_assert(kNoNode == 0xffffffffu, "write_child_vertices fills the fourth word with all ones");
    red_split_kernels::write_child_vertices(child, corner, m);
}

// The last four bytes of four new siblings but their level (word k: child k; the last byte is
// `reserved`, 0), by the parent's
// neighbour edge indices of its linked edges (bits 0-5) and its boundary edges (bits 6-8).
struct ChildTails {
    uint32_t word[4];
};
struct ChildTailTable {
    ChildTails of[512];
    constexpr ChildTailTable() : of() {
        for (unsigned code = 0; code < 512; ++code) {
            const unsigned outer = code & 63u, boundary = code >> 6;
            for (unsigned k = 0; k < 4; ++k) {
                const red_split::ChildEdges& edges = red_split::kChildEdges[k];
                of[code].word[k] = ((outer & edges.outer) | edges.inner) | (boundary & edges.boundary) << 16;
            }
        }
    }
};
constexpr ChildTailTable kChildTails{};

void Hierarchy::write_tail(Node& node, uint32_t word) {
    // Bytes nbr_edge, level, flags, reserved in that order (little endian word).
#if AMC_LITTLE_ENDIAN
    std::memcpy(&node.nbr_edge, &word, 4);
#else
    node.nbr_edge = uint8_t(word);
    node.level = uint8_t(word >> 8);
    node.flags = uint8_t(word >> 16);
    node.reserved = uint8_t(word >> 24);
#endif
}

// The neighbours of four new siblings from their local links; a local index becomes the id
// offset + index, kNoNode stays. Each child's store also fills its last four bytes, which
// write_tail writes afterwards.
void Hierarchy::write_neighbors(Node* child, const Neighbors* siblings, uint32_t offset) {
    const uint32_t* links = siblings[0].nbr;  // word 3k + e: child k, edge e (Neighbors' static_assert)
#if AMC_SSE2
    const __m128i all_ones = _mm_set1_epi32(-1);
    const __m128i add = _mm_set1_epi32(int(offset));
    auto ids = [&](const uint32_t* at) {
        const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i*>(at));
        return _mm_or_si128(_mm_add_epi32(v, add), _mm_cmpeq_epi32(v, all_ones));
    };
    const __m128i t0 = ids(links), t1 = ids(links + 4), t2 = ids(links + 8);
    // Lanes 0-2 of each piece are words 3k..3k+2.
    auto store = [](Node& node, __m128i v) { _mm_storeu_si128(reinterpret_cast<__m128i*>(node.nbr), v); };
    store(child[0], t0);
    store(child[1], _mm_or_si128(_mm_srli_si128(t0, 12), _mm_slli_si128(t1, 4)));
    store(child[2], _mm_or_si128(_mm_srli_si128(t1, 8), _mm_slli_si128(t2, 8)));
    store(child[3], _mm_srli_si128(t2, 4));
#else
    for (int k = 0; k < 4; ++k) {
        for (int e = 0; e < 3; ++e) {
            const uint32_t t = links[3 * k + e];
            child[k].nbr[e] = t == kNoNode ? kNoNode : t + offset;
        }
    }
#endif
}

void Hierarchy::split_level(const LevelSplits& splits) {
    const NodeId* const parents = splits.parents;
    const uint32_t count = splits.count;
    if (!free_blocks_.empty() || !free_vertices_.empty()) {
        // Reused ids: take the general path (the decoders never get here).
        for (uint32_t i = 0; i < count; ++i) split(parents[i]);
        return;
    }
    // The neighbour of child e of parents[i] across the first half of the parent's edge e.
    auto first_half = [children = splits.children](uint32_t i, int e) {
        return children[size_t(4) * i + red_split::kFirstHalfChild[e]].nbr[e];
    };
    const size_t c0 = nodes_.size();
    const size_t new_nodes = c0 + size_t(4) * count;
    if (new_nodes > nodes_.capacity()) reserve(std::max(new_nodes, nodes_.capacity() + nodes_.capacity() / 2), 0);
    if (positions_.size() + size_t(3) * count > positions_.capacity()) {
        // Maybe not enough room: count exactly. Edge e of parent i gets a new vertex unless an
        // earlier parent across it made one.
        size_t new_vertices = 0;
        for (uint32_t i = 0; i < count; ++i) {
            for (int e = 0; e < 3; ++e) new_vertices += !(first_half(i, e) / 4 < i);
        }
        const size_t vertices = positions_.size() + new_vertices;
        if (vertices > positions_.capacity()) reserve(0, std::max(vertices, positions_.capacity() + positions_.capacity() / 2));
    }
    nodes_.resize(new_nodes);
    block_parent_.resize((new_nodes - root_count()) / 4);
    NodeId* const block_parent = block_parent_.data() + (c0 - root_count()) / 4;
    const size_t v0 = positions_.size();
    Node* nodes = nodes_.data();
    VertexId next_vertex = VertexId(v0);
    const bool default_placer = placer_ == midpoint_placer;
    // The parents go in chunks: first their children and links, listing the end points of the
    // new vertices, then the new vertices' positions. Apart, the position loads (which miss the
    // cache) overlap each other instead of stalling the loop that writes the nodes.
    constexpr uint32_t kChunk = 256;
    Ends ends[3 * kChunk];
    // The parents are fetched 16 parents early (what else was tried: HIERARCHY_CODER.md, Speed, item 13).
    constexpr uint32_t kParentsAhead = 16;
    const uint32_t offset = uint32_t(c0);
    for (uint32_t chunk = 0; chunk < count; chunk += kChunk) {
        const uint32_t chunk_end = std::min(count, chunk + kChunk);
        uint32_t new_vertices = 0;
        for (uint32_t i = chunk; i < chunk_end; ++i) {
            if (i + kParentsAhead < count) __builtin_prefetch(nodes + parents[i + kParentsAhead]);
            const NodeId n = parents[i];
            Node& parent = nodes[n];
            const NodeId c = NodeId(c0 + size_t(4) * i);
            unsigned linked_edges = 0;
            VertexId m[3];
            for (int e = 0; e < 3; ++e) {
                const uint32_t t = first_half(i, e);  // kNoNode / 4 is never below i
                linked_edges |= t == kNoNode ? 0u : 3u << (2 * e);
                if (t / 4 < i) {
                    const unsigned eq = (parent.nbr_edge >> (2 * e)) & 3u;
                    m[e] = nodes[c0 + (t & ~3u) + red_split::kCenter].v[red_split::kCenterVertexOfMidpoint[eq]];
                } else {
                    ends[new_vertices++] = {parent.v[e], parent.v[e == 2 ? 0 : e + 1]};
                    m[e] = next_vertex++;
                }
            }
            // The children's edges (red_split::kChildEdges): linked outer edges take the parent's neighbour
            // edge index.
            const unsigned outer = parent.nbr_edge & linked_edges;
            const uint32_t level = uint32_t(parent.level + 1) << 8;
            const unsigned boundary = parent.flags;
            Node* child = nodes + c;
            write_vertices(child, parent.v, m);
            write_neighbors(child, splits.children + size_t(4) * i, offset);
            block_parent[i] = n;
            const ChildTails& tails = kChildTails.of[outer | (boundary & 7u) << 6];
            for (int k = 0; k < 4; ++k) write_tail(child[k], tails.word[k] | level);
            parent.first_child = c;
        }
        // Within the reserved capacity: no reallocation, so `positions` stays valid. One loop a
        // vertex placer, so that the default ones are inlined.
        const Vec3* positions = positions_.data();
        auto append = [&](auto place) {
            using Made = NewPositions<decltype(place)>;
            positions_.insert(positions_.end(), Made(ends, ends + new_vertices, positions, place),
                              Made(ends + new_vertices, ends + new_vertices, positions, place));
        };
        if (!default_placer || far_positions_) {
            const size_t first = positions_.size();
            append([placer = placer_, context = placer_context_](Vec3 a, Vec3 b) { return placer(context, a, b); });
            for (size_t v = first; v < positions_.size(); ++v) far_positions_ |= is_far(positions_[v]);
        } else if (placer_context_ != nullptr) {
            append([context = placer_context_](Vec3 a, Vec3 b) { return near_midpoint_placer(context, a, b); });
        } else {
            append([](Vec3 a, Vec3 b) { return near_midpoint_placer(nullptr, a, b); });
        }
    }
    live_nodes_ += 4 * count;
    live_vertices_ += uint32_t(next_vertex - v0);
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

std::vector<uint32_t> canonical_vertex_order(const Hierarchy& h) {
    std::vector<uint32_t> order(h.positions().size(), kNoVertex);
    uint32_t next = 0;
    for (uint32_t v = 0; v < h.base().positions.size(); ++v) order[v] = next++;
    for (NodeId n : h.breadth_first_order()) {
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
