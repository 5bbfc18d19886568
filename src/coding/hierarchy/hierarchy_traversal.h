// The level-wise traversal shared by the hierarchy encoder and decoder (paper, II-B, II-C, II-E).
//
// Within a level every node is decided exactly once: either a rule implies its state (culled:
// 1-regularity, hanging nodes, uniform levels) or one symbol is coded in the node's context group.
// The encoder answers `code` from the hierarchy it holds; the decoder from the stream. Both see
// the same decisions in the same order, so they agree on every context.
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
// (BlockEdges). The decoder hands the neighbours on to Hierarchy::split_level as they are.
#pragma once

#include "coding/hierarchy/context_groups.h"
#include "coding/format_version.h"
#include "common/compiler.h"
#include "common/huge_pages.h"
#include "common/simd.h"
#include "hierarchy/red_split_kernels.h"

#include <amc/hierarchy.h>
#include <amc/hierarchy_coder.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <vector>

namespace amc {

enum class Fate : uint8_t { coded, uniform, hanging_nodes };

constexpr uint32_t kNoLocal = 0xffffffffu;

// The links of one node.
struct LevelLinks {
    uint32_t nbr[3];   // same-level neighbour across edge e (local index), or kNoLocal
    uint8_t nbr_edge;  // the neighbour's local index of the shared edge, 2 bits per edge (0 if none)
    uint8_t flags;     // bits 0-2: boundary edge
    LevelLinks() {}  // uninitialized: every node's fields are set when its level is made
};
static_assert(sizeof(LevelLinks) == 16, "LevelLinks is meant to be 16 bytes");

struct Neighbors {
    uint32_t nbr[3];  // across edge e: local index, or kNoLocal
};

// What the four children of one refined node p take from p besides their neighbours: p's
// neighbour_edge (2 bits per edge, 0 where the neighbour is not refined) and boundary edges.
struct BlockEdges {
    uint8_t nbr_edge;
    uint8_t boundary;  // bits 0-2
};

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

    size_t size() const { return states_.empty() ? 0 : states_.size() - 1; }
    bool empty() const { return size() == 0; }
    // One state byte a node, preceded by kNoNeighborState: a neighbour index q reads its state at
    // state()[int32_t(q)], which for kNoLocal (-1) is that byte, so the hot loops need no test
    // for a missing neighbour. A new level's states say whether the node is complete and put
    // complete nodes in the improved traversal's bucket 4; with the 1-regularity rule the
    // incomplete ones are decided already and their neighbours' buckets lowered
    // (derive_next_level).
    uint8_t* state() { return states_.data() + 1; }
    const uint8_t* state() const { return states_.data() + 1; }
    void resize_state(size_t n) {
        resize_scratch(states_, n + 1);
        states_[0] = kNoNeighborState;
    }
    bool is_root_level() const { return !roots.empty(); }

private:
    std::vector<uint8_t> states_;
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

// The state of a node once one more of its neighbours is culled by 1-regularity, before any node
// of the level is decided otherwise: an undecided node moves one bucket down, not below 1 (the
// improved traversal's rule; with nothing refined, no other rule can cull it). A table: the
// lowered nodes follow no pattern, and GCC made the test a branch.
struct LoweredByCulledNeighbor {
    uint8_t of[256];
    constexpr LoweredByCulledNeighbor() : of() {
        for (int s = 0; s < 256; ++s) {
            const bool moves = !(s & kDecided) && (s >> kPriorityShift) > 1;
            of[s] = uint8_t(s - (moves ? 1 << kPriorityShift : 0));
        }
    }
};
constexpr LoweredByCulledNeighbor kLoweredByCulledNeighbor{};

inline int refined_neighbors(uint8_t state) { return (state & kRefinedNeighborMask) >> 2; }

inline uint8_t complete_state(const uint32_t nbr[3], uint8_t boundary) {
    return ((nbr[0] != kNoLocal) | (boundary & 1)) & ((nbr[1] != kNoLocal) | ((boundary >> 1) & 1)) &
                   ((nbr[2] != kNoLocal) | ((boundary >> 2) & 1))
               ? kComplete
               : 0;
}

// Level 0: the roots of `h` (root ids are local indices). With `cull_one_regularity`, the
// incomplete roots are decided (not refined) and their neighbours' priorities lowered, as in
// derive_next_level.
inline void root_level(const Hierarchy& h, Level& level, bool cull_one_regularity) {
    const uint32_t n = h.root_count();
    level.flipped.clear();
    level.refined_count = 0;
    level.roots.resize(n);
    level.resize_state(n);
    uint32_t incomplete_count = 0;
    uint8_t* state = level.state();
    for (NodeId r = 0; r < n; ++r) {
        LevelLinks& node = level.roots[r];
        uint8_t boundary = 0, edges = 0;
        for (int e = 0; e < 3; ++e) {
            node.nbr[e] = h.neighbor(r, e);
            if (node.nbr[e] != kNoNode) edges = uint8_t(edges | (h.neighbor_edge(r, e) << (2 * e)));
            boundary = uint8_t(boundary | (int(h.is_boundary_edge(r, e)) << e));
        }
        node.nbr_edge = edges;
        node.flags = boundary;
        const uint8_t complete = complete_state(node.nbr, boundary);
        state[r] = complete ? uint8_t(complete | kFreshPriority) : cull_one_regularity ? kDecided : uint8_t(0);
        incomplete_count += !complete;
    }
    level.incomplete_count = incomplete_count;
    if (!cull_one_regularity || incomplete_count == 0) return;
    for (NodeId r = 0; r < n; ++r) {
        if (state[r] & kComplete) continue;
        for (int e = 0; e < 3; ++e) {
            uint8_t& s = neighbor_state(state, level.roots[r].nbr[e]);
            s = kLoweredByCulledNeighbor.of[s];
        }
    }
}

// What a new block takes from its parent's linked edges (bits 0-2: the edges with a refined
// neighbour) and boundary edges (bits 3-5), in one 16-byte entry; a table without the 1-regularity
// rule and one with it:
//  - the four children's state bytes (byte k: child k). A child is complete when each of its
//    outer edges (red_split::is_outer) has a neighbour or is boundary; the center has none, so it
//    always is. Without the rule every child starts undecided, a complete one in bucket 4
//    (kFreshPriority), an incomplete one in 0. With the rule an incomplete child starts decided
//    (not refined), and a complete one one bucket lower for each incomplete sibling;
//  - with the rule, the neighbours outside the block of its incomplete children across linked
//    edges, whose priority goes down once the rule culls those children, as byte offsets into the
//    block's twelve words of neighbours (red_split::link_word). An incomplete child has at most one
//    such neighbour (its other outer edge is missing), a block at most two (a third would not
//    compile: writing past lowered_offset is no constant expression);
//  - the mask of the linked edges' two-bit neighbour edge indices;
//  - two counts in one word, so that one addition keeps both: the ends the new vertices count
//    beyond 3 (bits 0-31: a vertex on an edge of its own counts 2 ends, one on an edge shared with
//    a refined neighbour 1, so 3 to 6 a block) and the children that are not complete (bits
//    32-63). Neither sum can overflow: a level has fewer than 2^32 nodes, so fewer than 2^30
//    blocks.
struct NewBlock {
    uint32_t states = 0;
    uint8_t lowered_offset[2] = {};
    uint8_t lowered_count = 0;
    uint8_t edge_mask = 0;
    uint64_t counts = 0;
};
static_assert(sizeof(NewBlock) == 16, "NewBlock is meant to be 16 bytes");
struct NewBlocks {
    NewBlock of[2][64];  // [cull_one_regularity][code]
    constexpr NewBlocks() : of() {
        constexpr uint32_t kFresh = kComplete | kFreshPriority;
        for (int culled = 0; culled < 2; ++culled) {
            for (int code = 0; code < 64; ++code) {
                NewBlock& block = of[culled][code];
                bool missing[3] = {};
                for (int e = 0; e < 3; ++e) missing[e] = !(((code >> e) | (code >> (3 + e))) & 1);
                // A child is complete when none of its outer edges is missing (the center has none).
                bool complete[4] = {};
                uint32_t ends = 0, incomplete = 0;
                for (int k = 0; k < 4; ++k) {
                    complete[k] = true;
                    for (int e = 0; e < 3; ++e) complete[k] = complete[k] && !(red_split::is_outer(k, e) && missing[e]);
                    incomplete += !complete[k];
                }
                for (int k = 0; k < 4; ++k) {
                    uint32_t state = complete[k] ? kFresh : culled ? uint32_t(kDecided) : 0u;
                    if (culled && complete[k]) {
                        // One bucket lower for each sibling the rule culls.
                        for (int e = 0; e < 3; ++e) {
                            const int s = red_split::sibling(k, e);
                            if (s >= 0 && !complete[s]) state -= 1u << kPriorityShift;
                        }
                    }
                    block.states |= state << (8 * k);
                }
                for (int e = 0; e < 3; ++e) {
                    const bool linked = (code >> e) & 1;
                    if (linked) block.edge_mask = uint8_t(block.edge_mask | (3 << (2 * e)));
                    ends += linked ? 1 : 2;
                }
                block.counts = (ends - 3) | uint64_t(incomplete) << 32;
                if (!culled) continue;
                // The incomplete children's neighbours across a linked edge lie outside the block.
                for (int f = 0; f < 3; ++f) {
                    if (!((code >> f) & 1)) continue;
                    if (!complete[red_split::first_half_child(f)])
                        block.lowered_offset[block.lowered_count++] = uint8_t(4 * red_split::first_half_word(f));
                    if (!complete[red_split::second_half_child(f)])
                        block.lowered_offset[block.lowered_count++] = uint8_t(4 * red_split::second_half_word(f));
                }
            }
        }
    }
};
constexpr NewBlocks kNewBlocks{};

// How the refined nodes of a decided level become the next level's blocks: each node's block (its
// rank among the refined nodes) or kNoLocal. block_of() has one more entry in front, kNoLocal,
// read for a missing neighbour as block_of()[int32_t(kNoLocal)].
class RefinedNumbering {
public:
    // Null before the first reset (a level decided without a scan refines nothing: never read).
    const uint32_t* block_of() const { return blocks_.data() == nullptr ? nullptr : blocks_.data() + 1; }
    // Room for n nodes, all kNoLocal.
    uint32_t* reset(size_t n) {
        uint32_t* blocks = blocks_.reserve(n + 1);
        std::fill(blocks, blocks + n + 1, kNoLocal);
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

// Numbers the refined nodes of a decided level: level.refined (canonical order) and the
// numbering. When `closures` is given, lists there the leaves with two or three hanging nodes.
// The decisions follow no pattern a branch predictor learns, so the state bytes are read 16 at a
// time as bit masks and only the set bits are visited.
inline DecidedLevelScan scan_decided_level(Level& level, RefinedNumbering& numbering, uint32_t* closures) {
    const uint32_t n = static_cast<uint32_t>(level.size());
    const uint8_t* state = level.state();
    uint32_t* block = numbering.reset(n);
    uint32_t* refined = level.refined.reserve(n);
    uint32_t count = 0;
    DecidedLevelScan scan;
    uint32_t bad = 0;
    // Masks of 16 nodes from i: refined (bit 1 of the state), complete (bit 4), two or more
    // refined neighbours (bit 3).
    auto visit = [&](uint32_t i, uint32_t is_refined, uint32_t complete, uint32_t two_hanging) {
        bad |= is_refined & ~complete;
        for (uint32_t r = is_refined; r != 0; r &= r - 1) {
            const uint32_t j = i + uint32_t(__builtin_ctz(r));
            block[j] = count;
            refined[count++] = j;
        }
        if (closures == nullptr) return;
        for (uint32_t c = two_hanging & ~is_refined; c != 0; c &= c - 1) closures[scan.closures++] = i + uint32_t(__builtin_ctz(c));
    };
    uint32_t i = 0;
#if AMC_SSE2
    for (; i + 16 <= n; i += 16) {
        const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i*>(state + i));
        // Shifting 16-bit lanes moves bit b of each byte to bit 7 of the same byte.
        visit(i, uint32_t(_mm_movemask_epi8(_mm_slli_epi16(v, 6))), uint32_t(_mm_movemask_epi8(_mm_slli_epi16(v, 3))),
              uint32_t(_mm_movemask_epi8(_mm_slli_epi16(v, 4))));
    }
#endif
    for (; i < n; i += 16) {
        uint32_t r = 0, c = 0, h = 0;
        for (uint32_t k = 0; k < 16 && i + k < n; ++k) {
            r |= uint32_t((state[i + k] >> 1) & 1) << k;
            c |= uint32_t((state[i + k] >> 4) & 1) << k;
            h |= uint32_t((state[i + k] >> 3) & 1) << k;
        }
        visit(i, r, c, h);
    }
    level.refined_count = count;
    scan.refined_incomplete = bad != 0;
    return scan;
}

// Level l+1 from level l (every node decided and numbered): the children of the refined nodes in
// canonical order, linked exactly as Hierarchy::split links them. Returns the number of vertices
// the splits create: one per edge of a refined node, shared where the neighbour is refined too.
// Across p's edge e lies p's neighbour q with its index eq of the edge; when q is refined, the
// first half of the edge meets q's child (eq+1)%3 and the second half q's child eq.
// With `cull_one_regularity` the incomplete nodes start decided (not refined) and every other
// node one bucket lower for each incomplete neighbour (NewBlock), as the improved traversal wants
// them: what the culled nodes' decisions would do to their neighbours, in any order.
inline uint64_t derive_next_level(const Level& level, const RefinedNumbering& numbering, Level& next,
                                  bool cull_one_regularity) {
    const uint32_t count = level.refined_count;
    const uint32_t* block = numbering.block_of();
    const uint32_t* refined = level.refined.data();
    next.roots.clear();
    next.flipped.clear();
    next.refined_count = 0;
    next.resize_state(size_t(4) * count);
    Neighbors* out = next.nbr.reserve(size_t(4) * count);
    BlockEdges* out_edges = next.edges.reserve(count);
    uint32_t* lowered = next.lowered.reserve(size_t(2) * count);  // each block writes two words
    uint32_t lowered_count = 0;
    const NewBlock* const new_blocks = kNewBlocks.of[cull_one_regularity ? 1 : 0];
    uint8_t* out_state = next.state();
    // Each new vertex has two edge ends: one from each refined node on its edge, or both from one.
    uint64_t counts = 0;  // bits 0-31 the edge ends beyond 3 a block, 32-63 the incomplete nodes
    with_links(level, [&](auto links) {
        for (uint32_t b = 0; b < count; ++b) {
            const LevelLinks p = links(refined[b]);
            const uint32_t c = 4 * b;
            const unsigned linked = red_split_kernels::write_child_links(
                out + c, b, block[static_cast<int32_t>(p.nbr[0])], block[static_cast<int32_t>(p.nbr[1])],
                block[static_cast<int32_t>(p.nbr[2])], p.nbr_edge);  // kNoLocal for none
            const NewBlock& entry = new_blocks[linked | ((p.flags & 7u) << 3)];
            out_edges[b] = {uint8_t(p.nbr_edge & entry.edge_mask), uint8_t(p.flags & 7)};
            counts += entry.counts;
#if AMC_LITTLE_ENDIAN
            std::memcpy(out_state + c, &entry.states, 4);  // byte k: child k
#else
            for (int k = 0; k < 4; ++k) out_state[c + k] = uint8_t(entry.states >> (8 * k));
#endif
            // Both words always, kept by the count (no branch: which blocks have incomplete
            // corners follows no pattern). memcpy: the words are read as the bytes of out's
            // array.
            const char* words = reinterpret_cast<const char*>(out + c);
            std::memcpy(lowered + lowered_count, words + entry.lowered_offset[0], 4);
            std::memcpy(lowered + lowered_count + 1, words + entry.lowered_offset[1], 4);
            lowered_count += entry.lowered_count;
        }
    });
    next.incomplete_count = uint32_t(counts >> 32);
    // Those neighbours may lie in blocks written after theirs: lowered once every state is made.
    for (uint32_t k = 0; k < lowered_count; ++k) {
        uint8_t& s = out_state[lowered[k]];
        s = kLoweredByCulledNeighbor.of[s];
    }
    return (uint64_t(uint32_t(counts)) + uint64_t(3) * count) / 2;
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

// The culling rules in force (paper II-C): which rule decides an undecided node in state s
// during the traversal, or Fate::coded. (The nodes 1-regularity culls are decided before it:
// root_level and derive_next_level make them so.)
struct CullRules {
    bool one_regularity;
    bool hanging_nodes;
    Fate fate(uint8_t s) const {
        // The count of decided refined neighbours is kept up to date by LevelTraversal.
        if (hanging_nodes && (s & kRefinedNeighborMask) == 3 * kRefinedNeighbor) return Fate::hanging_nodes;
        return Fate::coded;
    }
};

// Context group by the neighbours' kinds, two bits each (edge e at bits 2e): 0 not yet decided,
// 1 not refined (or no neighbour: boundary, coarser region), 3 refined.
struct ContextTable {
    uint8_t group[64];
    constexpr ContextTable() : group() {
        for (int code = 0; code < 64; ++code) {
            int refined = 0, unrefined = 0;
            for (int e = 0; e < 3; ++e) {
                const int kind = (code >> (2 * e)) & 3;
                refined += kind == 3;
                unrefined += kind == 1 || kind == 2;
            }
            group[code] = uint8_t(kContextGroupOf[refined][unrefined]);
        }
    }
};
constexpr ContextTable kContextTable{};

class LevelTraversal {
public:
    // `stream_version`: the hierarchy stream's version (format_version.h), which says when the
    // nodes 1-regularity culls are decided.
    LevelTraversal(const HierarchyCoderOptions& options, uint8_t stream_version) { configure(options, stream_version); }

    // Switches to other options, keeping the working memory.
    void configure(const HierarchyCoderOptions& options, uint8_t stream_version) {
        options_ = options;
        culls_in_turn_ = culls_decided_in_turn(stream_version);
        // What a decided neighbour does to a node's state in the improved traversal: an
        // undecided node outside bucket 0 moves one bucket down (not below 1), or to bucket 0
        // once its three refined neighbours make it culled (a node culled by 1-regularity is in
        // bucket 0 from the outset).
        const CullRules rules{options.cull_one_regularity, options.cull_hanging_nodes};
        for (int s = 0; s < 256; ++s) {
            const int p = s >> kPriorityShift;
            int next = p;
            if (!(s & kDecided) && p != 0 && p <= 4)
                next = rules.fate(uint8_t(s)) != Fate::coded ? 0 : (p > 1 ? p - 1 : 1);
            after_neighbor_decided_[s] = uint8_t((s & ~kPriorityMask) | (next << kPriorityShift));
        }
    }

    // Decides every node of `level` (undecided, canonical order) and records the decisions in
    // the nodes' state; afterwards each state's refined-neighbour count is exact.
    //   code(uint32_t i, int context_group) -> bool   the node's symbol (coded by the caller)
    //   force(uint32_t i, Fate fate, bool refined) -> bool   a decision implied by a rule; returns
    //       the node's actual state (the decoder: `refined`; the encoder: the hierarchy's, so even
    //       an invalid hierarchy keeps the level forest in step with it)
    template <class Code, class Force>
    void run(Level& level, bool uniform_level, Code&& code, Force&& force) {
        with_links(level, [&](auto links) {
            if (culls_in_turn_) {
                run_on<true>(links, level.state(), static_cast<uint32_t>(level.size()), level.incomplete_count,
                             uniform_level, code, force);
            } else {
                run_on<false>(links, level.state(), static_cast<uint32_t>(level.size()), level.incomplete_count,
                              uniform_level, code, force);
            }
        });
    }
    // run for the newest stream version only (culls_in_turn() is false): for hot paths, which
    // then hold no code of older versions (see HierarchyLevelDecoder::decide_level).
    template <class Code, class Force>
    void run_newest(Level& level, bool uniform_level, Code&& code, Force&& force) {
        with_links(level, [&](auto links) {
            run_on<false>(links, level.state(), static_cast<uint32_t>(level.size()), level.incomplete_count,
                          uniform_level, code, force);
        });
    }
    // run for version 1 only (culls_in_turn() is true).
    template <class Code, class Force>
    void run_version1(Level& level, bool uniform_level, Code&& code, Force&& force) {
        with_links(level, [&](auto links) {
            run_on<true>(links, level.state(), static_cast<uint32_t>(level.size()), level.incomplete_count,
                         uniform_level, code, force);
        });
    }
    // Hierarchy stream version 1 (see configure).
    bool culls_in_turn() const { return culls_in_turn_; }

private:
    template <bool kCullsInTurn, class Links, class Code, class Force>
    void run_on(Links links, uint8_t* state, uint32_t n, uint32_t incomplete_count, bool uniform_level, Code& code,
                Force& force) {
        // A copy in a local: the state bytes written below could alias options_.
        const CullRules rules{options_.cull_one_regularity, options_.cull_hanging_nodes};
        if (uniform_level) {
            for (uint32_t i = 0; i < n; ++i) {
                if (force(i, Fate::uniform, true)) {
                    state[i] = uint8_t(state[i] | kDecided | kRefined);
                    add_refined_neighbor(links.neighbors(i), state);
                } else {
                    state[i] = uint8_t(state[i] | kDecided);
                }
            }
            return;
        }
        if (options_.traversal == Traversal::naive) {
            if constexpr (kCullsInTurn) {
                if (rules.one_regularity && incomplete_count != 0) {
                    run_naive_culls_in_turn(links, state, n, code, force);
                    return;
                }
            }
            // (The nodes 1-regularity culls are decided already.)
            for (uint32_t i = 0; i < n; ++i) {
                if (!(state[i] & kDecided)) decide(rules.fate(state[i]), links.neighbors(i), state, i, code, force);
            }
            return;
        }
        // Improved traversal: a bucket queue over priorities 0 (culled: nothing to code) to 4 (no
        // neighbour decided yet); each decided neighbour lowers a node's priority by one. The
        // lowest non-empty bucket goes first, each bucket last in, first out; an entry is stale
        // once its node is decided or has moved to a lower bucket, and is skipped. Every node
        // enters at most five buckets: linear time.
        // The nodes 1-regularity culls (the incomplete ones) are decided first, and a new level's
        // states hold their decisions and the priorities they leave (derive_next_level). The
        // nodes of buckets 1-3 go onto their stacks in reverse canonical order, so that each
        // stack pops in canonical order. Bucket 4 holds every other node in canonical order and
        // never receives another, so it is a cursor. Without the 1-regularity rule every node
        // starts in bucket 4.
        if (!rules.one_regularity) {
            for (uint32_t i = 0; i < n; ++i) state[i] = uint8_t(state[i] | kFreshPriority);
        }
        uint32_t* const bottom[4] = {stacks_[0].reserve(n), stacks_[1].reserve(n), stacks_[2].reserve(n),
                                     stacks_[3].reserve(n)};
        uint32_t* top[4] = {bottom[0], bottom[1], bottom[2], bottom[3]};
        uint8_t transition[256];  // a local copy: the state bytes written below could alias the member
        for (int k = 0; k < 256; ++k) transition[k] = after_neighbor_decided_[k];
        // The pushes of node i's decision into the buckets; returns the lowest bucket pushed to
        // (5 if none) and in `next` the node pushed last into it.
        auto push_neighbors = [&](const Neighbors& node, uint32_t& next) {
            int next_bucket = 5;
            for (int e = 0; e < 3; ++e) {
                const uint32_t q = node.nbr[e];
                const uint8_t s = neighbor_state(state, q);
                const uint8_t t = transition[s];
                if (t == s) continue;  // decided (or no neighbour), or already in bucket 1
                state[q] = t;
                // Last in, first out: q is likely to be decided soon, and its links are usually
                // not in cache yet.
                links.prefetch(q);
                const int bucket = t >> kPriorityShift;
                *top[bucket]++ = q;
                if (bucket <= next_bucket) {
                    next = q;
                    next_bucket = bucket;
                }
            }
            return next_bucket;
        };
        if (rules.one_regularity && incomplete_count != 0) {
            BucketTops tops{{top[0], top[1], top[2], top[3]}};
            if constexpr (kCullsInTurn) {
                tops = push_culled_in_turn(links, state, n, tops);
            } else {
                tops = push_lowered(state, n, tops);
            }
            for (int b = 0; b < 4; ++b) top[b] = tops.at[b];
        }
        uint32_t fresh_cursor = 0;
        constexpr uint8_t kDecidedOrPriority = kDecided | kPriorityMask;
        int current = 0;  // every bucket below this one is empty
        uint32_t i = 0;
        bool culled = false;
        bool popped = false;  // i was taken off its bucket by the previous step
        for (;;) {
            // A node from bucket 0 is culled; from any other bucket it carries a symbol (its
            // priority was set when its fate last changed).
            if (popped) {
                popped = false;
            } else if (current == 0) {
                if (top[0] == bottom[0]) {
                    current = 1;
                    continue;
                }
                i = *--top[0];  // entries of bucket 0 are never stale
                culled = true;
            } else if (current < 4) {
                // Most entries below a bucket's top are stale (every move from bucket 3 to 2
                // leaves one in 3); they are skipped here rather than by the outer loop.
                const uint8_t live = uint8_t(current << kPriorityShift);
                uint32_t* t = top[current];
                uint32_t* const b = bottom[current];
                bool found = false;
                while (t != b) {
                    i = *--t;
                    if ((state[i] & kDecidedOrPriority) == live) {
                        found = true;
                        break;
                    }
                }
                top[current] = t;
                if (!found) {
                    ++current;
                    continue;
                }
                culled = false;
            } else {
                i = next_fresh(state, n, fresh_cursor);
                if (i == n) break;
                fresh_cursor = i + 1;
                culled = false;
            }
            const Neighbors node = links.neighbors(i);
            decide(culled ? rules.fate(state[i]) : Fate::coded, node, state, i, code, force);
            // The last push into the lowest bucket is the next node whenever that bucket is now
            // the lowest non-empty one. Knowing it here, rather than reading it back from the
            // bucket, keeps the stack and the state byte out of the chain of loads from one node
            // to the next.
            uint32_t next = 0;
            const int next_bucket = push_neighbors(node, next);
            if (next_bucket <= current) {
                current = next_bucket;
                --top[current];
                i = next;
                culled = current == 0;
                popped = true;
            }
        }
    }

    struct BucketTops {
        uint32_t* at[4];
    };
    // Pushes the undecided nodes below bucket 4 (those the culled nodes lowered) onto their
    // stacks, in reverse canonical order. Where they are follows no pattern, so the state bytes
    // are read 16 at a time as bit masks and only the set bits are visited. A function of its
    // own, so that GCC allocates run_on's registers for the loop over coded nodes alone.
    AMC_NOIPA static BucketTops push_lowered(const uint8_t* state, uint32_t n, BucketTops tops) {
        constexpr uint8_t kDecidedOrBucket4 = kDecided | kFreshPriority;  // priorities are 0..4
        auto push = [&](uint32_t i) {
            uint32_t*& top = tops.at[state[i] >> kPriorityShift];
            *top++ = i;
        };
        uint32_t i = n;
        for (; i % 16 != 0; --i) {
            if (!(state[i - 1] & kDecidedOrBucket4)) push(i - 1);
        }
#if AMC_SSE2
        const __m128i mask = _mm_set1_epi8(char(kDecidedOrBucket4));
        const __m128i zero = _mm_setzero_si128();
        for (; i != 0; i -= 16) {
            const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i*>(state + i - 16));
            unsigned hits = unsigned(_mm_movemask_epi8(_mm_cmpeq_epi8(_mm_and_si128(v, mask), zero)));
            while (hits != 0) {
                const unsigned j = 31u - unsigned(__builtin_clz(hits));
                push(i - 16 + j);
                hits ^= 1u << j;
            }
        }
#else
        for (; i != 0; --i) {
            if (!(state[i - 1] & kDecidedOrBucket4)) push(i - 1);
        }
#endif
        return tops;
    }

    // Hierarchy stream version 1, improved traversal: the nodes 1-regularity culls went first, one
    // by one in canonical order, each pushing its undecided neighbours one bucket lower as
    // run_on's steps do; a node lowered twice or three times left stale entries behind, and each
    // stack holds its nodes in the order they were lowered. The level's states hold version 2's
    // priorities (derive_next_level): they are put back in bucket 4 and lowered again in that order.
    template <class Links>
    AMC_NOIPA BucketTops push_culled_in_turn(Links links, uint8_t* state, uint32_t n, BucketTops tops) const {
        for (uint32_t i = 0; i < n; ++i) {
            if (!(state[i] & kDecided)) state[i] = uint8_t((state[i] & ~kPriorityMask) | kFreshPriority);
        }
        for (uint32_t i = 0; i < n; ++i) {
            if (!(state[i] & kDecided)) continue;  // decided at the outset: culled by 1-regularity
            const Neighbors node = links.neighbors(i);
            for (int e = 0; e < 3; ++e) {
                const uint32_t q = node.nbr[e];
                const uint8_t s = neighbor_state(state, q);
                const uint8_t t = after_neighbor_decided_[s];
                if (t == s) continue;
                state[q] = t;
                *tops.at[t >> kPriorityShift]++ = q;
            }
        }
        return tops;
    }

    // Hierarchy stream version 1, naive traversal: a node 1-regularity culls is decided in its
    // turn, so the nodes before it see it undecided (context group). The level's states hold it
    // decided (derive_next_level): it is made undecided again first.
    template <class Links, class Code, class Force>
    AMC_NOIPA void run_naive_culls_in_turn(Links links, uint8_t* state, uint32_t n, Code& code, Force& force) const {
        const CullRules rules{options_.cull_one_regularity, options_.cull_hanging_nodes};
        for (uint32_t i = 0; i < n; ++i) {
            if (!(state[i] & kComplete)) state[i] = 0;
        }
        for (uint32_t i = 0; i < n; ++i) {
            if (!(state[i] & kComplete)) {
                state[i] = uint8_t(state[i] | kDecided);  // culled: not refined
                continue;
            }
            decide(rules.fate(state[i]), links.neighbors(i), state, i, code, force);
        }
    }

    // Bucket 4: the first node from `cursor` on that is undecided with no decided neighbour, or n.
    // Most nodes the cursor passes were decided meanwhile; they are skipped 16 at a time.
    static uint32_t next_fresh(const uint8_t* state, uint32_t n, uint32_t cursor) {
        constexpr uint8_t kDecidedOrPriority = kDecided | kPriorityMask;
#if AMC_SSE2
        const __m128i mask = _mm_set1_epi8(char(kDecidedOrPriority));
        const __m128i fresh = _mm_set1_epi8(char(kFreshPriority));
        for (; cursor + 16 <= n; cursor += 16) {
            const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i*>(state + cursor));
            const unsigned hits = unsigned(_mm_movemask_epi8(_mm_cmpeq_epi8(_mm_and_si128(v, mask), fresh)));
            if (hits != 0) return cursor + unsigned(__builtin_ctz(hits));
        }
#endif
        for (; cursor < n; ++cursor) {
            if ((state[cursor] & kDecidedOrPriority) == kFreshPriority) return cursor;
        }
        return n;
    }

    // A node has at most three neighbour edges, so its count of refined neighbours never
    // overflows; the shared kNoNeighborState byte may, harmlessly: adding multiples of 4 keeps its
    // decided, not refined bits.
    static void add_refined_neighbor(const Neighbors& node, uint8_t* state) {
        for (int e = 0; e < 3; ++e) {
            uint8_t& s = neighbor_state(state, node.nbr[e]);
            s = uint8_t(s + kRefinedNeighbor);
        }
    }

    // The context group of a node: its neighbours refined, not refined, not yet decided.
    static int context_group(const Neighbors& node, const uint8_t* state) {
        unsigned code = 0;
        for (int e = 0; e < 3; ++e) {
            const uint32_t q = node.nbr[e];
            // No neighbour (boundary, or a coarser region: see context_groups.h) counts as not
            // refined; a neighbour's kind is its decided and refined bits.
            const unsigned kind = neighbor_state(state, q) & (kDecided | kRefined);
            code |= kind << (2 * e);
        }
        return kContextTable.group[code];
    }

    // Decides node i (links `node`) whose fate is known: codes its symbol or applies the rule,
    // records the decision and counts it at the neighbours.
    template <class Code, class Force>
    static void decide(Fate fate, const Neighbors& node, uint8_t* state, uint32_t i, Code& code, Force& force) {
        const bool refined = fate == Fate::coded ? code(i, context_group(node, state))
                                                 : force(i, fate, fate == Fate::hanging_nodes);
        state[i] = uint8_t(state[i] | kDecided | (refined ? kRefined : 0));
        if (refined) add_refined_neighbor(node, state);
    }

    HierarchyCoderOptions options_;
    bool culls_in_turn_ = false;  // hierarchy stream version 1 (see configure)
    uint8_t after_neighbor_decided_[256];  // state -> state, see the constructor
    std::array<ScratchArray<uint32_t>, 4> stacks_;  // buckets 0-3 (each holds at most one entry per node)
};

}  // namespace amc
