// The decoders' bulk build of a level (HierarchyBuilder::split_level, hierarchy_builder.h): a
// whole level's splits in one pass, with the links the decoder's level forest already knows.
#include <amc/hierarchy.h>

#include "common/check.h"
#include "common/compiler.h"
#include "common/huge_pages.h"
#include "common/simd.h"
#include "hierarchy/hierarchy_builder.h"
#include "hierarchy/midpoint_placers.h"
#include "hierarchy/red_split_kernels.h"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <iterator>

namespace amc {

namespace {

// The end points of a new vertex.
struct Ends {
    VertexId a, b;
};

// The end points' positions miss the cache far more often than the nodes: with 8 vertices
// ahead, the loads still waited.
constexpr std::ptrdiff_t kPositionsAhead = 32;

// A random-access range over the end points of new vertices whose elements are their positions,
// made by `Place` as std::vector::insert copies them: each is written once, into the reserved
// capacity, with no test of the capacity per vertex (push_back's) and no zero-fill first
// (resize's). The end points' positions are fetched kPositionsAhead vertices early, from entries
// the list holds past its end (so that no test guards the fetch).
template <class Place>
class NewPositions {
public:
    using iterator_category = std::random_access_iterator_tag;
    using value_type = Vec3;
    using difference_type = std::ptrdiff_t;
    using pointer = const Vec3*;
    using reference = Vec3;

    NewPositions(const Ends* at, const Vec3* positions, Place place) : at_(at), positions_(positions), place_(place) {}
    Vec3 operator*() const { return place_(positions_[at_->a], positions_[at_->b]); }
    NewPositions& operator++() {
        __builtin_prefetch(positions_ + at_[kPositionsAhead].a);
        __builtin_prefetch(positions_ + at_[kPositionsAhead].b);
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
    const Ends* at_;
    const Vec3* positions_;
    Place place_;
};

// near_midpoint_placer (midpoint_placers.h), rounded to float when `to_float`: x and y in one
// SSE2 register (the same IEEE operations, so the same bits).
template <bool to_float>
AMC_ALWAYS_INLINE Vec3 near_midpoint(const Vec3& a, const Vec3& b) {
#if AMC_SSE2
    static_assert(sizeof(Vec3) == 24 && offsetof(Vec3, y) == 8 && offsetof(Vec3, z) == 16, "Vec3 is x, y, z");
    const __m128d half = _mm_set1_pd(0.5);
    __m128d xy = _mm_mul_pd(_mm_add_pd(_mm_loadu_pd(&a.x), _mm_loadu_pd(&b.x)), half);
    __m128d z = _mm_mul_sd(_mm_add_sd(_mm_load_sd(&a.z), _mm_load_sd(&b.z)), half);
    if (to_float) {
        xy = _mm_cvtps_pd(_mm_cvtpd_ps(xy));
        z = _mm_cvtss_sd(z, _mm_cvtsd_ss(_mm_setzero_ps(), z));
    }
    Vec3 m;
    _mm_storeu_pd(&m.x, xy);
    _mm_store_sd(&m.z, z);
    return m;
#else
    static int round_to_float;  // any non-null context asks the placer to round
    return near_midpoint_placer(to_float ? &round_to_float : nullptr, a, b);
#endif
}

}  // namespace

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

namespace {

// A child's tail (its last four bytes) and its neighbours, written per parent by split_level
// (forced inline: a call per parent cost 3 % of a decode's instructions).
template <class Node>
AMC_ALWAYS_INLINE void store_tail(Node& node, uint32_t word) {
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
// offset + index, kNoNode stays. Each child's store also fills its tail, which store_tail writes
// afterwards.
template <class Node>
AMC_ALWAYS_INLINE void store_neighbors(Node* child, const Neighbors* siblings, uint32_t offset) {
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

// store_neighbors for links written in the children's own nodes (LevelSplits::links_in_place).
template <class Node>
AMC_ALWAYS_INLINE void turn_links_into_ids(Node* child, uint32_t offset) {
#if AMC_SSE2
    const __m128i all_ones = _mm_set1_epi32(-1);
    const __m128i add = _mm_set1_epi32(int(offset));
    for (int k = 0; k < 4; ++k) {
        __m128i* at = reinterpret_cast<__m128i*>(child[k].nbr);  // the three links and the tail
        const __m128i v = _mm_loadu_si128(at);
        _mm_storeu_si128(at, _mm_or_si128(_mm_add_epi32(v, add), _mm_cmpeq_epi32(v, all_ones)));
    }
#else
    for (int k = 0; k < 4; ++k) {
        for (int e = 0; e < 3; ++e) {
            const uint32_t t = child[k].nbr[e];
            child[k].nbr[e] = t == kNoNode ? kNoNode : t + offset;
        }
    }
#endif
}

// The parents i in [begin, end) of split_level's common case (links in `children`, the blocks'
// edges given, no seam vertex), in a loop of its own: in split_level's loop, which
// serves every case, GCC kept the loop's counters and the midpoints on the stack (about 25 loads
// and stores a parent). Returns the new vertices listed in `ends`; next_vertex moves past them.
// The parents are fetched kAhead parents early (what else was tried: HIERARCHY_CODER.md, Speed, item 13).
template <class Node>
AMC_NOIPA uint32_t split_plain_parents(Node* nodes, const uint32_t* parents, uint32_t begin, uint32_t end,
                                       uint32_t count, size_t c0, const Neighbors* children,
                                       const BlockEdges* child_edges, VertexId& next_vertex, Ends* ends) {
    constexpr uint32_t kAhead = 16;
    const uint32_t offset = uint32_t(c0);
    VertexId next = next_vertex;
    uint32_t listed = 0;
    for (uint32_t i = begin; i < end; ++i) {
        if (i + kAhead < count) __builtin_prefetch(nodes + parents[i + kAhead]);
        Node& parent = nodes[parents[i]];
        const size_t c = c0 + size_t(4) * i;
        VertexId m[3];
        for (int e = 0; e < 3; ++e) {
            const uint32_t t = children[size_t(4) * i + red_split::kFirstHalfChild[e]].nbr[e];  // kNoNode / 4 is never below i
            if (t / 4 < i) {  // made by the parent of block t / 4, in its centre child
                const unsigned eq = (parent.nbr_edge >> (2 * e)) & 3u;
                m[e] = nodes[c0 + (t & ~3u) + red_split::kCenter].v[red_split::kCenterVertexOfMidpoint[eq]];
            } else {
                ends[listed++] = {parent.v[e], parent.v[e == 2 ? 0 : e + 1]};
                m[e] = next++;
            }
        }
        const uint32_t level = uint32_t(parent.level + 1) << 8;
        Node* child = nodes + c;
#if AMC_SSE2
        // A leaf's first 16 bytes: its corners and first_child, kNoNode, the children's fourth word.
        red_split_sse2::write_child_vertices(child, _mm_loadu_si128(reinterpret_cast<const __m128i*>(parent.v)), m);
#else
        red_split_kernels::write_child_vertices(child, parent.v, m);
#endif
        store_neighbors(child, children + size_t(4) * i, offset);
        const ChildTails& tails = kChildTails.of[child_edges[i].nbr_edge | unsigned(child_edges[i].boundary & 7u) << 6];
        for (int k = 0; k < 4; ++k) store_tail(child[k], tails.word[k] | level);
        parent.first_child = NodeId(c);
    }
    next_vertex = next;
    return listed;
}

}  // namespace

ChildLinkRoom Hierarchy::open_children(HierarchySlice* slice, uint32_t count) {
    AMC_REQUIRE(free_blocks_.empty() && free_vertices_.empty(), invalid_input,
                "open_children: the room of a level needs a hierarchy that was only ever refined");
    const size_t c0 = slice != nullptr ? slice->next_node : nodes_.size();
    const size_t new_nodes = c0 + size_t(4) * count;
    if (slice != nullptr) {
        AMC_REQUIRE(new_nodes <= slice->node_end, corrupt, slice->owner + " does not hold the nodes the chunk table says");
    } else {
        if (new_nodes > nodes_.capacity()) reserve(std::max(new_nodes, nodes_.capacity() + nodes_.capacity() / 2), 0);
        nodes_.resize(new_nodes);  // Node() writes nothing
    }
    ChildLinkRoom room;
    static_assert(ChildLinkRoom::kStride * sizeof(uint32_t) == sizeof(Node), "the room's stride is a node");
    if (count > 0) room.words = nodes_[c0].nbr;
    return room;
}

void Hierarchy::split_level(const LevelSplits& splits) {
    const NodeId* const parents = splits.parents;
    const uint32_t count = splits.count;
    if (!free_blocks_.empty() || !free_vertices_.empty()) {
        // Reused ids: take the general path (the decoders never get here).
        AMC_REQUIRE(splits.place_new_vertices, invalid_input,
                    "split_level: unplaced vertices need a hierarchy that was only ever refined");
        for (uint32_t i = 0; i < count; ++i) split(parents[i]);
        return;
    }
    HierarchySlice* const slice = splits.slice;
    const bool in_place = splits.links_in_place;
    // open_children grew the hierarchy's end already.
    const size_t c0 = slice != nullptr ? slice->next_node : nodes_.size() - (in_place ? size_t(4) * count : 0);
    const size_t new_nodes = c0 + size_t(4) * count;
    // The neighbour of child e of parents[i] across the first half of the parent's edge e: in the
    // list, or in the child itself (a stride, not a test per read).
    const char* const links = in_place ? reinterpret_cast<const char*>(nodes_.data() + c0) + offsetof(Node, nbr)
                                       : reinterpret_cast<const char*>(splits.children);
    const size_t link_stride = in_place ? sizeof(Node) : sizeof(Neighbors);
    auto first_half = [links, link_stride](uint32_t i, int e) {
        uint32_t t;
        std::memcpy(&t, links + (size_t(4) * i + red_split::kFirstHalfChild[e]) * link_stride + sizeof(uint32_t) * size_t(e), 4);
        return t;
    };
    const size_t v0 = slice != nullptr ? slice->next_vertex : positions_.size();
    const size_t vertex_room = slice != nullptr ? slice->vertex_end : positions_.capacity();
    if (slice != nullptr) {
        AMC_REQUIRE(new_nodes <= slice->node_end, corrupt, slice->owner + " does not hold the nodes the chunk table says");
    } else if (new_nodes > nodes_.capacity()) {
        reserve(std::max(new_nodes, nodes_.capacity() + nodes_.capacity() / 2), 0);
    }
    if (v0 + size_t(3) * count > vertex_room) {
        // Maybe not enough room: count exactly, unless the caller did. Edge e of parent i gets a
        // new vertex unless an earlier parent across it made one, or boundary_vertex has one.
        const bool known = slice == nullptr && splits.boundary_vertex == nullptr &&
                           splits.new_vertex_count != LevelSplits::kUnknownCount;
        size_t new_vertices = known ? size_t(splits.new_vertex_count) : 0;
        for (uint32_t i = 0; !known && i < count; ++i) {
            const Node& parent = nodes_[parents[i]];
            for (int e = 0; e < 3; ++e)
                new_vertices += !(first_half(i, e) / 4 < i) &&
                                !(splits.boundary_vertex != nullptr && ((parent.flags >> e) & 1u) &&
                                  splits.boundary_vertex(splits.boundary_context, parent.v[e], parent.v[(e + 1) % 3]) != kNoVertex);
        }
        const size_t vertices = v0 + new_vertices;
        if (slice != nullptr)
            AMC_REQUIRE(vertices <= vertex_room, corrupt, slice->owner + " does not hold the vertices the chunk table says");
        else if (vertices > vertex_room)
            reserve(0, std::max(vertices, positions_.capacity() + positions_.capacity() / 2));
    }
    // Block i's parent is parents[i]: copied whole, not zero-filled and then written parent by parent.
    if (slice == nullptr) {
        nodes_.resize(new_nodes);
        block_parent_.insert(block_parent_.end(), parents, parents + count);
    } else {
        std::copy(parents, parents + count, block_parent_.begin() + std::ptrdiff_t((c0 - root_count()) / 4));
    }
    Node* nodes = nodes_.data();
    VertexId next_vertex = VertexId(v0);
    size_t positions_written = v0;
    const bool default_placer = placer_ == midpoint_placer;
    // The parents go in chunks: first their children and links, listing the end points of the
    // new vertices, then the new vertices' positions. Apart, the position loads (which miss the
    // cache) overlap each other instead of stalling the loop that writes the nodes.
    constexpr uint32_t kChunk = 256;
    Ends ends[3 * kChunk + kPositionsAhead] = {};  // set: the fetches ahead read past the chunk's
    // The parents are fetched 16 parents early (what else was tried: HIERARCHY_CODER.md, Speed, item 13).
    constexpr uint32_t kParentsAhead = 16;
    const uint32_t offset = uint32_t(c0);
    const auto boundary_vertex = splits.boundary_vertex;
    // No seam vertices and the blocks' edges given: a midpoint is new unless an earlier parent
    // made it, and the children's tails need not be found from their links.
    const BlockEdges* const child_edges = splits.child_edges;
    const bool fast = boundary_vertex == nullptr && child_edges != nullptr;
    const bool plain = fast && !in_place;
    for (uint32_t chunk = 0; chunk < count; chunk += kChunk) {
        const uint32_t chunk_end = std::min(count, chunk + kChunk);
        uint32_t new_vertices = 0;
        if (plain)
            new_vertices = split_plain_parents(nodes, parents, chunk, chunk_end, count, c0, splits.children,
                                               child_edges, next_vertex, ends);
        for (uint32_t i = plain ? chunk_end : chunk; i < chunk_end; ++i) {
            if (i + kParentsAhead < count) __builtin_prefetch(nodes + parents[i + kParentsAhead]);
            const NodeId n = parents[i];
            Node& parent = nodes[n];
            const NodeId c = NodeId(c0 + size_t(4) * i);
            unsigned linked_edges = 0;
            VertexId m[3];
            for (int e = 0; fast && e < 3; ++e) {
                const uint32_t t = first_half(i, e);  // kNoNode / 4 is never below i
                if (t / 4 < i) {
                    const unsigned eq = (parent.nbr_edge >> (2 * e)) & 3u;
                    m[e] = nodes[c0 + (t & ~3u) + red_split::kCenter].v[red_split::kCenterVertexOfMidpoint[eq]];
                } else {
                    ends[new_vertices++] = {parent.v[e], parent.v[e == 2 ? 0 : e + 1]};
                    m[e] = next_vertex++;
                }
            }
            for (int e = 0; !fast && e < 3; ++e) {
                const uint32_t t = first_half(i, e);  // kNoNode / 4 is never below i
                linked_edges |= t == kNoNode ? 0u : 3u << (2 * e);
                if (t / 4 < i) {
                    const unsigned eq = (parent.nbr_edge >> (2 * e)) & 3u;
                    m[e] = nodes[c0 + (t & ~3u) + red_split::kCenter].v[red_split::kCenterVertexOfMidpoint[eq]];
                } else {
                    const VertexId a = parent.v[e], b = parent.v[e == 2 ? 0 : e + 1];
                    const VertexId existing = boundary_vertex != nullptr && ((parent.flags >> e) & 1u)
                                                  ? boundary_vertex(splits.boundary_context, a, b)
                                                  : kNoVertex;
                    if (existing != kNoVertex) {
                        m[e] = existing;
                    } else {
                        ends[new_vertices++] = {a, b};
                        m[e] = next_vertex++;
                    }
                }
            }
            // The children's edges (red_split::kChildEdges): linked outer edges take the parent's neighbour
            // edge index.
            const unsigned tail_code = fast ? child_edges[i].nbr_edge | unsigned(child_edges[i].boundary & 7u) << 6
                                            : (parent.nbr_edge & linked_edges) | (parent.flags & 7u) << 6;
            const uint32_t level = uint32_t(parent.level + 1) << 8;
            Node* child = nodes + c;
#if AMC_SSE2
            // A leaf's first 16 bytes: its corners and first_child, kNoNode, the children's fourth word.
            red_split_sse2::write_child_vertices(child, _mm_loadu_si128(reinterpret_cast<const __m128i*>(parent.v)), m);
#else
            red_split_kernels::write_child_vertices(child, parent.v, m);  // write_vertices' (split() shares it)
#endif
            if (in_place)
                turn_links_into_ids(child, offset);
            else
                store_neighbors(child, splits.children + size_t(4) * i, offset);
            const ChildTails& tails = kChildTails.of[tail_code];
            for (int k = 0; k < 4; ++k) store_tail(child[k], tails.word[k] | level);
            parent.first_child = c;
        }
        if (!splits.place_new_vertices) {
            // A slice's are there already.
            if (slice == nullptr && !splits.append_new_positions) positions_.resize(positions_.size() + new_vertices);
            positions_written += new_vertices;
            continue;
        }
        // Within the reserved capacity: no reallocation, so `positions` stays valid. One loop a
        // vertex placer, so that the default ones are inlined.
        const Vec3* positions = positions_.data();
        const size_t first = positions_written;
        auto append = [&](auto place) {
            using Made = NewPositions<decltype(place)>;
            const Made from(ends, positions, place), to(ends + new_vertices, positions, place);
            if (slice != nullptr)
                std::copy(from, to, positions_.begin() + std::ptrdiff_t(first));
            else
                positions_.insert(positions_.end(), from, to);
        };
        positions_written += new_vertices;
        if (!default_placer || far_positions_.get()) {
            append([placer = placer_, context = placer_context_](Vec3 a, Vec3 b) { return placer(context, a, b); });
            for (size_t v = first; v < positions_written; ++v) far_positions_.raise_if(is_far(positions_[v]));
        } else if (placer_context_ != nullptr) {
            append([](const Vec3& a, const Vec3& b) { return near_midpoint<true>(a, b); });
        } else {
            append([](const Vec3& a, const Vec3& b) { return near_midpoint<false>(a, b); });
        }
    }
    if (slice != nullptr) {
        slice->next_node = NodeId(new_nodes);
        slice->next_vertex = next_vertex;
        return;
    }
    live_nodes_ += 4 * count;
    live_vertices_ += uint32_t(next_vertex - v0);
}

size_t NewVertexEdges::take(std::pair<NodeId, int>* out, size_t n) {
    const Hierarchy& h = *h_;
    size_t k = 0;
    uint32_t b = parent_;
    int e = edge_;
    VertexId next = next_vertex_;
    while (k < n && next != end_) {
        AMC_REQUIRE(b < parent_count_, corrupt, "split parents made fewer vertices than listed");
        const NodeId p = parents_[b];
        for (; e < 3 && k < n; ++e) {
            if (h.midpoint(p, e) != next) continue;  // an earlier parent's midpoint
            out[k++] = {p, e};
            ++next;
        }
        if (e == 3) {
            e = 0;
            ++b;
        }
    }
    parent_ = b;
    edge_ = e;
    next_vertex_ = next;
    return k;
}

const FrameCorners* NewVertexCorners::next(size_t n) {
    AMC_REQUIRE(n <= kRun && taken_ + n <= count_, invalid_input, "NewVertexCorners: more vertices asked for than made");
    taken_ += n;
    if (list_ != nullptr) return list_ + (taken_ - n);
    // The corners a parent made past the last run come first.
    const size_t carried = made_ - handed_;
    std::memmove(run_, run_ + handed_, carried * sizeof(FrameCorners));
    // The walk in locals: the stores of corners could alias members as far as the compiler knows.
    const Hierarchy& h = *h_;
    const NodeId* const parents = parents_;
    const uint32_t parent_count = parent_count_;
    uint32_t b = parent_;
    VertexId next_vertex = next_vertex_;
    FrameCorners* const out = run_;
    size_t k = carried;
    // split_level made parents[b]'s children at first_child + 4 b: the centre child's id needs no
    // load of the parent's, and the children are read in order.
    const NodeId first_child = parent_count > 0 ? h.child(parents[0], 0) : 0;
    AMC_REQUIRE(parent_count == 0 || h.child(parents[parent_count - 1], 0) == first_child + 4 * (parent_count - 1),
                invalid_input, "NewVertexCorners: the parents' children are not consecutive");
    // The parents are fetched 16 ahead, their neighbours 8 ahead (as split_level).
    constexpr uint32_t kParentsAhead = 16;
    while (k < n) {
        AMC_REQUIRE(b < parent_count, corrupt, "split parents made fewer vertices than listed");
        if (b + kParentsAhead < parent_count) HierarchyBuilder::prefetch(h, parents[b + kParentsAhead]);
        if (b + kParentsAhead / 2 < parent_count) {
            const NodeId ahead = parents[b + kParentsAhead / 2];
            for (int e = 0; e < 3; ++e) HierarchyBuilder::prefetch(h, h.neighbor(ahead, e));  // kNoNode: prefetches do not fault
        }
        const NodeId center = first_child + 4 * b + red_split::kCenter;
        const NodeId p = parents[b++];
        const VertexId v[5] = {h.vertex(p, 0), h.vertex(p, 1), h.vertex(p, 2), h.vertex(p, 0), h.vertex(p, 1)};
        const NodeId q[3] = {h.neighbor(p, 0), h.neighbor(p, 1), h.neighbor(p, 2)};
        const unsigned edges = HierarchyBuilder::neighbor_edges(h, p);
        const VertexId m[3] = {h.vertex(center, red_split::kCenterVertexOfMidpoint[0]),
                               h.vertex(center, red_split::kCenterVertexOfMidpoint[1]),
                               h.vertex(center, red_split::kCenterVertexOfMidpoint[2])};
        for (int e = 0; e < 3; ++e) {
            if (m[e] != next_vertex) continue;  // an earlier parent's midpoint, or a seam vertex
            static constexpr int kOpposite[4] = {2, 0, 1, 2};  // (eq + 2) % 3
            const VertexId d = q[e] == kNoNode ? kNoVertex : h.vertex(q[e], kOpposite[(edges >> (2 * e)) & 3u]);
            out[k++] = {v[e], v[e + 1], v[e + 2], d};
            ++next_vertex;
        }
    }
    parent_ = b;
    next_vertex_ = next_vertex;
    made_ = k;
    handed_ = n;
    return run_;
}

}  // namespace amc
