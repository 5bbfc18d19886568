// The level forest the hierarchy coder's traversal runs on (hierarchy_traversal.h).
//
// The traversal does not run on amc::Hierarchy but on a "level forest": one level at a time as
// dense arrays in canonical (breadth-first) order, with neighbours as local indices into the same
// arrays. Level l+1 is derived from level l and its decisions alone, mirroring Hierarchy::split's
// linking, so the coder touches compact memory in near-sequential order and the decoder builds
// the Hierarchy once at the end. Local index i of level l is the node's position in the level's
// canonical order, which is also the order of the naive traversal.
//
// A level is its links and one state byte a node, which the traversal reads and writes for every
// neighbour; kept apart, the states of even the finest level stay in the processor's L2 cache.
// The roots' links are stored node by node (LevelLinks). Every finer level comes in blocks of
// four siblings (nodes 4b..4b+3 are the children of the level above's b-th refined node, in
// child order): each node keeps its three neighbours, which the traversal reads for every node
// it decides, and each block the two bytes of links its children take from their parent
// (BlockEdges). The decoder hands the neighbours on to HierarchyBuilder::split_level as they are.
#pragma once

#include "common/huge_pages.h"
#include "hierarchy/hierarchy_builder.h"

#include <amc/hierarchy.h>
#include <amc/red_split.h>

#include <algorithm>
#include <cstdint>
#include <vector>

namespace amc {

constexpr uint32_t kNoLocal = 0xffffffffu;

// The links of one node.
struct LevelLinks {
    uint32_t nbr[3];   // same-level neighbour across edge e (local index), or kNoLocal
    uint8_t nbr_edge;  // the neighbour's local index of the shared edge, 2 bits per edge (0 if none)
    uint8_t flags;     // bits 0-2: boundary edge
    LevelLinks() {}  // uninitialized: every node's fields are set when its level is made
};
static_assert(sizeof(LevelLinks) == 16, "LevelLinks is meant to be 16 bytes");

// The links of child k (0..3) of a block, by its parent's BlockEdges (red_split::kChildEdges).
inline LevelLinks child_links(const Neighbors& nbr, BlockEdges parent, unsigned k) {
    LevelLinks out;
    for (int e = 0; e < 3; ++e) out.nbr[e] = nbr.nbr[e];
    const red_split::ChildEdges& edges = red_split::kChildEdges[k];
    out.nbr_edge = uint8_t((parent.nbr_edge & edges.outer) | edges.inner);
    out.flags = uint8_t(parent.boundary & edges.boundary);
    return out;
}

// The state byte of a node.
constexpr uint8_t kDecided = 1;
constexpr uint8_t kRefined = 2;
constexpr uint8_t kRefinedNeighbor = 4;        // unit of the count of refined neighbours (bits 2-3)
constexpr uint8_t kRefinedNeighborMask = 12;   // decided refined neighbours; exact once all are decided
constexpr uint8_t kComplete = 16;              // Hierarchy::has_all_neighbors
constexpr int kPriorityShift = 5;              // bits 5-7: the improved traversal's bucket, 0..4
constexpr uint8_t kPriorityMask = 0xe0;

// The state a missing neighbour (kNoLocal) reads as: decided, not refined. Decided states take no
// transitions; the refined-neighbour counts added to it are never read.
constexpr uint8_t kNoNeighborState = kDecided;

struct Level {
    std::vector<LevelLinks> roots;  // level 0: every node's links
    ScratchArray<Neighbors> nbr;    // finer levels: every node's neighbours
    ScratchArray<BlockEdges> edges;  // finer levels: what each block of four siblings takes from its parent
    // The number of nodes without all neighbours (1-regularity culls them).
    uint32_t incomplete_count = 0;
    // Working memory of derive_next_level: the nodes whose priority a culled node in another block
    // lowers.
    ScratchArray<uint32_t> lowered;
    // After the level is decided (decoder): its refined nodes in canonical order, and the nodes
    // whose diagonal is flipped, ascending.
    ScratchArray<uint32_t> refined;
    uint32_t refined_count = 0;
    std::vector<uint32_t> flipped;
    // The vertices their splits create (derive_next_level's count).
    uint64_t new_vertices = 0;

    size_t size() const { return leaves_ != 0 ? leaves_ : state_count_ == 0 ? 0 : state_count_ - 1; }
    bool empty() const { return size() == 0; }
    // One state byte a node, preceded by kNoNeighborState: a neighbour index q reads its state at
    // state()[int32_t(q)], which for kNoLocal (-1) is that byte, so the hot loops need no test
    // for a missing neighbour. A new level's states say whether the node is complete and put
    // complete nodes in the improved traversal's bucket 4; with the 1-regularity rule the
    // incomplete ones are decided already and their neighbours' buckets lowered
    // (derive_next_level).
    uint8_t* state() { return states_.data() + 1; }
    const uint8_t* state() const { return states_.data() + 1; }
    // Their contents are unset (not zeroed: the level's maker writes every one).
    void resize_state(size_t n) {
        states_.reserve(n + 1)[0] = kNoNeighborState;
        state_count_ = n + 1;
        leaves_ = 0;
    }
    // A level of n leaves alone, derived into the room of its nodes (derive_next_level): no
    // states, which nothing would read (it is never traversed, and each node is one leaf face).
    void set_leaves(size_t n) {
        resize_state(0);
        leaves_ = n;
    }
    bool leaves_only() const { return leaves_ != 0; }
    bool is_root_level() const { return !roots.empty(); }
    // Gives the storage of everything but `refined` and `flipped` (what splitting the decided
    // level reads) back to the allocator.
    void free_all_but_splits() {
        std::vector<LevelLinks>().swap(roots);
        nbr.deallocate();
        edges.deallocate();
        lowered.deallocate();
        states_.deallocate();
        state_count_ = 0;
        leaves_ = 0;
    }
    // Gives back the storage that is far larger than a level of n nodes needs
    // (ScratchArray::shrink_for); its contents are dead.
    void shrink_for(size_t n) {
        nbr.shrink_for(n);
        edges.shrink_for(n / 4);
        lowered.shrink_for(n / 2);
        refined.shrink_for(n);
        states_.shrink_for(n + 1);
        if (states_.capacity() == 0) state_count_ = 0;
        leaves_ = 0;
    }

private:
    ScratchArray<uint8_t> states_;
    size_t state_count_ = 0;  // the level's nodes and the byte in front
    size_t leaves_ = 0;       // set_leaves
};

// The state byte of neighbour q (kNoLocal included, see Level::state).
inline uint8_t& neighbor_state(uint8_t* state, uint32_t q) { return state[static_cast<int32_t>(q)]; }
inline uint8_t neighbor_state(const uint8_t* state, uint32_t q) { return state[static_cast<int32_t>(q)]; }

// Link accessors for code that is instantiated per kind of level (hot loops): the branch on the
// kind is taken once a level, not once a node.
struct RootLinks {
    const LevelLinks* roots;
    LevelLinks operator()(uint32_t i) const { return roots[i]; }
    Neighbors neighbors(uint32_t i) const { return {{roots[i].nbr[0], roots[i].nbr[1], roots[i].nbr[2]}}; }
    void prefetch(uint32_t i) const { __builtin_prefetch(roots + i); }
};
struct BlockLinks {
    const Neighbors* nbr;
    const BlockEdges* edges;
    LevelLinks operator()(uint32_t i) const { return child_links(nbr[i], edges[i >> 2], i & 3); }
    Neighbors neighbors(uint32_t i) const { return nbr[i]; }
    void prefetch(uint32_t i) const { __builtin_prefetch(nbr + i); }
};

// Calls f(links accessor) with the accessor for `level`'s kind.
template <class F>
decltype(auto) with_links(const Level& level, F&& f) {
    if (level.is_root_level()) return f(RootLinks{level.roots.data()});
    return f(BlockLinks{level.nbr.data(), level.edges.data()});
}

// The priority bits of bucket 4, where a complete node starts (an incomplete one starts in 0).
constexpr uint8_t kFreshPriority = 4 << kPriorityShift;

inline int refined_neighbors(uint8_t state) { return (state & kRefinedNeighborMask) >> 2; }

inline uint8_t complete_state(const uint32_t nbr[3], uint8_t boundary) {
    return ((nbr[0] != kNoLocal) | (boundary & 1)) & ((nbr[1] != kNoLocal) | ((boundary >> 1) & 1)) &
                   ((nbr[2] != kNoLocal) | ((boundary >> 2) & 1))
               ? kComplete
               : 0;
}

// How the refined nodes of a decided level become the next level's blocks: each node's block (its
// rank among the refined nodes) or kNoLocal. block_of() has one more entry in front, kNoLocal,
// read for a missing neighbour as block_of()[int32_t(kNoLocal)].
class RefinedNumbering {
public:
    // Gives its pages back to the system (release_pages) until the next reset.
    void release() { blocks_.release_from(0); }
    // Gives its storage back to the allocator: all of it, or when it is far larger than a level
    // of n nodes needs.
    void deallocate() { blocks_.deallocate(); }
    void shrink_for(size_t n) { blocks_.shrink_for(n + 1); }
    // Null before the first reset (a level decided without a scan refines nothing: never read).
    const uint32_t* block_of() const { return blocks_.data() == nullptr ? nullptr : blocks_.data() + 1; }
    // Room for n nodes, which the caller fills (their contents are unspecified; the entry in
    // front is kNoLocal).
    uint32_t* reset(size_t n) {
        uint32_t* blocks = blocks_.reserve(n + 1);
        blocks[0] = kNoLocal;
        return blocks + 1;
    }

private:
    ScratchArray<uint32_t> blocks_;
};

// What a scan of a decided level finds besides the numbering.
struct DecidedLevelScan {
    uint32_t closures = 0;          // leaves with two or three hanging nodes listed
    bool refined_incomplete = false;  // a refined node lacks a neighbour: it can not be split
};

// Level 0: the roots of `h` (root ids are local indices). With `cull_one_regularity`, the
// incomplete roots are decided (not refined) and their neighbours' priorities lowered, as in
// derive_next_level.
void root_level(const Hierarchy& h, Level& level, bool cull_one_regularity);
// The same over the `count` roots from `first` (local index = id - first), linked among
// themselves only (a chunk's roots in the whole, their links to other chunks cut).
void root_level(const Hierarchy& h, NodeId first, uint32_t count, Level& level, bool cull_one_regularity);

// Numbers the refined nodes of a decided level: level.refined (canonical order) and the
// numbering. When `closures` is given, lists there the leaves with two or three hanging nodes.
// The decisions follow no pattern a branch predictor learns, so the state bytes are read 16 at a
// time as bit masks and only the set bits are visited.
DecidedLevelScan scan_decided_level(Level& level, RefinedNumbering& numbering, uint32_t* closures);

// The faces a decided level's leaves have in the conforming leaf mesh: one each, plus one per
// refined neighbour (the green closure's split). Read off the state bytes, so no links are loaded.
uint64_t leaf_faces_of_level(const Level& level);

// Level l+1 from level l (every node decided and numbered): the children of the refined nodes in
// canonical order, linked exactly as Hierarchy::split links them. Returns the number of vertices
// the splits create: one per edge of a refined node, shared where the neighbour is refined too.
// Across p's edge e lies p's neighbour q with its index eq of the edge; when q is refined, each
// half of the edge meets q's child on the other half of eq (red_split::child_across_first_half).
// With `cull_one_regularity` the incomplete nodes start decided (not refined) and every other
// node one bucket lower for each incomplete neighbour (NewBlock), as the improved traversal wants
// them: what the culled nodes' decisions would do to their neighbours, in any order.
// With `room` (words set, HierarchyBuilder::open_children's), the links go to the room of the
// nodes they become instead of next.nbr, and neither block edges nor states are made (next.nbr
// and next.edges are left as they were, next is Level::set_leaves): a level that only
// split_level (LevelSplits::links_in_place) reads, the last, needs none of them.
uint64_t derive_next_level(const Level& level, const RefinedNumbering& numbering, Level& next,
                           bool cull_one_regularity, ChildLinkRoom room = {});

// Whether refined node b (local index) makes the midpoint of its edge to `neighbor`: unless the
// neighbour is a refined node numbered before b (which made it).
inline bool makes_midpoint(const uint32_t* block, uint32_t neighbor, uint32_t b) {
    return block[static_cast<int32_t>(neighbor)] > b;  // kNoLocal for none
}

// The vertices the splits of a decided, numbered level create (derive_next_level counts them), in
// canonical order at their first appearance, as Hierarchy::split_level numbers them: f(i, e) for
// edge e of the refined node i (local index) unless the neighbour across e is a refined node
// numbered before i (which made that midpoint).
template <class F>
void for_each_new_vertex(const Level& level, const RefinedNumbering& numbering, F&& f) {
    const uint32_t* block = numbering.block_of();
    const uint32_t* refined = level.refined.data();
    with_links(level, [&](auto links) {
        for (uint32_t b = 0; b < level.refined_count; ++b) {
            const Neighbors node = links.neighbors(refined[b]);
            for (int e = 0; e < 3; ++e) {
                if (makes_midpoint(block, node.nbr[e], b)) f(refined[b], e);
            }
        }
    });
}

// for_each_new_vertex without a branch per edge (whether a neighbour made the midpoint is a coin
// flip): out[k] = make(i, e) for every edge of every refined node, k moved past the new ones only.
// `out` has room for 3 * level.refined_count; returns the count.
template <class T, class Make>
size_t write_new_vertices(const Level& level, const RefinedNumbering& numbering, T* out, Make&& make) {
    const uint32_t* block = numbering.block_of();
    const uint32_t* refined = level.refined.data();
    size_t k = 0;
    with_links(level, [&](auto links) {
        for (uint32_t b = 0; b < level.refined_count; ++b) {
            const uint32_t i = refined[b];
            const Neighbors node = links.neighbors(i);
            for (int e = 0; e < 3; ++e) {
                out[k] = make(i, e);
                k += makes_midpoint(block, node.nbr[e], b);
            }
        }
    });
    return k;
}

// The unrefined edge of a decided leaf with exactly two hanging nodes. Which edge it is follows
// no pattern, so it is looked up by the refined neighbours (bits 0-2) rather than searched for.
inline int unrefined_edge(const Level& level, uint32_t i) {
    const Neighbors node = with_links(level, [i](auto links) { return links.neighbors(i); });
    const uint8_t* state = level.state();
    unsigned refined = 0;
    for (int e = 0; e < 3; ++e) refined |= unsigned((neighbor_state(state, node.nbr[e]) >> 1) & 1) << e;
    // Two edges refined: 6 -> 0, 5 -> 1, 3 -> 2 (the other entries are not asked for).
    constexpr uint32_t kByRefined = 0 << 12 | 1 << 10 | 2 << 6;
    return int((kByRefined >> (2 * refined)) & 3);
}

}  // namespace amc
