// Making the levels of the level forest: the roots, the scan of a decided level, the next level.
#include "coding/hierarchy/level_forest.h"

#include "coding/hierarchy/level_tables.h"
#include "common/check.h"
#include "common/simd.h"
#include "hierarchy/red_split_kernels.h"

#include <cstring>
#include <type_traits>

namespace amc {

void root_level(const Hierarchy& h, Level& level, bool cull_one_regularity) {
    root_level(h, 0, h.root_count(), level, cull_one_regularity);
}

void root_level(const Hierarchy& h, NodeId first, uint32_t n, Level& level, bool cull_one_regularity) {
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
            const NodeId q = h.neighbor(first + r, e);
            AMC_REQUIRE(q == kNoNode || q - first < n, invalid_input, "root_level: a root is linked outside its range");
            node.nbr[e] = q == kNoNode ? kNoNode : q - first;
            if (q != kNoNode) edges = uint8_t(edges | (h.neighbor_edge(first + r, e) << (2 * e)));
            boundary = uint8_t(boundary | (int(h.is_boundary_edge(first + r, e)) << e));
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

DecidedLevelScan scan_decided_level(Level& level, RefinedNumbering& numbering, uint32_t* closures) {
    const uint32_t n = static_cast<uint32_t>(level.size());
    const uint8_t* state = level.state();
    uint32_t* block = numbering.reset(n);
    uint32_t* refined = level.refined.reserve(n);
    uint32_t count = 0;
    DecidedLevelScan scan;
    uint32_t bad = 0;
    // Masks of 16 nodes from i: refined (bit 1 of the state), complete (bit 4), two or more
    // refined neighbours (bit 3). The pass writes every node's block: kNoLocal, then the refined
    // ones' numbers (no separate fill of the numbering).
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
    const __m128i none = _mm_set1_epi32(-1);
    static_assert(kNoLocal == 0xffffffffu, "the scan writes kNoLocal as all ones");
    for (; i + 16 <= n; i += 16) {
        for (uint32_t k = 0; k < 16; k += 4) _mm_storeu_si128(reinterpret_cast<__m128i*>(block + i + k), none);
        const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i*>(state + i));
        // Shifting 16-bit lanes moves bit b of each byte to bit 7 of the same byte.
        visit(i, uint32_t(_mm_movemask_epi8(_mm_slli_epi16(v, 6))), uint32_t(_mm_movemask_epi8(_mm_slli_epi16(v, 3))),
              uint32_t(_mm_movemask_epi8(_mm_slli_epi16(v, 4))));
    }
#endif
    for (; i < n; i += 16) {
        uint32_t r = 0, c = 0, h = 0;
        for (uint32_t k = 0; k < 16 && i + k < n; ++k) {
            block[i + k] = kNoLocal;
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

uint64_t leaf_faces_of_level(const Level& level) {
    const uint32_t n = static_cast<uint32_t>(level.size());
    if (level.leaves_only()) return n;  // no neighbour of a leaf is refined there
    const uint8_t* state = level.state();
    uint64_t faces = 0;
    uint32_t i = 0;
#if AMC_SSE2
    // Per byte: 1 + refined neighbours for a leaf, 0 for a refined node; summed 16 bytes at a time.
    const __m128i zero = _mm_setzero_si128(), refined_bit = _mm_set1_epi8(char(kRefined)),
                  count_bits = _mm_set1_epi8(char(kRefinedNeighborMask >> 2)), one = _mm_set1_epi8(1);
    __m128i sums = zero;
    for (; i + 16 <= n; i += 16) {
        const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i*>(state + i));
        const __m128i leaf = _mm_cmpeq_epi8(_mm_and_si128(v, refined_bit), zero);
        const __m128i per_node = _mm_add_epi8(_mm_and_si128(_mm_srli_epi16(v, 2), count_bits), one);
        sums = _mm_add_epi64(sums, _mm_sad_epu8(_mm_and_si128(per_node, leaf), zero));
    }
    uint64_t halves[2];
    _mm_storeu_si128(reinterpret_cast<__m128i*>(halves), sums);
    faces = halves[0] + halves[1];
#endif
    for (; i < n; ++i)
        if (!(state[i] & kRefined)) faces += 1 + uint64_t(refined_neighbors(state[i]));
    return faces;
}

namespace {

// A block's twelve link words (four siblings' Neighbors) copied to its nodes' room, 16 bytes a
// node: the fourth word lands in the node's tail, which split_level writes afterwards.
inline void copy_links_to_room(const Neighbors* made, uint32_t* words) {
    static_assert(ChildLinkRoom::kStride == 8, "the room's nodes are eight words apart");
#if AMC_SSE2
    const uint32_t* links = made[0].nbr;  // word 3k + e: child k, edge e (Neighbors' static_assert)
    const __m128i t0 = _mm_loadu_si128(reinterpret_cast<const __m128i*>(links));
    const __m128i t1 = _mm_loadu_si128(reinterpret_cast<const __m128i*>(links + 4));
    const __m128i t2 = _mm_loadu_si128(reinterpret_cast<const __m128i*>(links + 8));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(words), t0);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(words + 8), _mm_or_si128(_mm_srli_si128(t0, 12), _mm_slli_si128(t1, 4)));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(words + 16), _mm_or_si128(_mm_srli_si128(t1, 8), _mm_slli_si128(t2, 8)));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(words + 24), _mm_srli_si128(t2, 4));
#else
    for (int k = 0; k < 4; ++k) std::memcpy(words + 8 * k, made[k].nbr, sizeof(Neighbors));
#endif
}

}  // namespace

uint64_t derive_next_level(const Level& level, const RefinedNumbering& numbering, Level& next,
                           bool cull_one_regularity, ChildLinkRoom room) {
    const uint32_t count = level.refined_count;
    const uint32_t* block = numbering.block_of();
    const uint32_t* refined = level.refined.data();
    next.roots.clear();
    next.flipped.clear();
    next.refined_count = 0;
    if (room.words != nullptr)
        next.set_leaves(size_t(4) * count);
    else
        next.resize_state(size_t(4) * count);
    Neighbors* const out = room.words == nullptr ? next.nbr.reserve(size_t(4) * count) : nullptr;
    // A level in the room is all leaves: no traversal nor derivation reads its block edges.
    BlockEdges* out_edges = room.words == nullptr ? next.edges.reserve(count) : nullptr;
    uint32_t* lowered = room.words == nullptr ? next.lowered.reserve(size_t(2) * count) : nullptr;  // two words a block
    uint32_t lowered_count = 0;
    const NewBlock* const new_blocks = kNewBlocks.of[cull_one_regularity ? 1 : 0];
    uint8_t* out_state = room.words == nullptr ? next.state() : nullptr;
    // Each new vertex has two edge ends: one from each refined node on its edge, or both from one.
    uint64_t counts = 0;  // bits 0-31 the edge ends beyond 3 a block, 32-63 the incomplete nodes
    // In the room, a block's links are made in `made` and copied to its four nodes; no priority
    // is lowered there, as the room's level is all leaves: its priorities are never read.
    auto derive = [&](auto links, auto in_room) {
        Neighbors made[4];
        for (uint32_t b = 0; b < count; ++b) {
            const LevelLinks p = links(refined[b]);
            const uint32_t c = 4 * b;
            Neighbors* const block_links = decltype(in_room)::value ? made : out + c;
            const unsigned linked = red_split_kernels::write_child_links(
                block_links, b, block[static_cast<int32_t>(p.nbr[0])], block[static_cast<int32_t>(p.nbr[1])],
                block[static_cast<int32_t>(p.nbr[2])], p.nbr_edge);  // kNoLocal for none
            if (decltype(in_room)::value) copy_links_to_room(made, room.words + ChildLinkRoom::kStride * c);
            const NewBlock& entry = new_blocks[linked | ((p.flags & 7u) << 3)];
            if (!decltype(in_room)::value) out_edges[b] = {uint8_t(p.nbr_edge & entry.edge_mask), uint8_t(p.flags & 7)};
            counts += entry.counts;
            if (decltype(in_room)::value) continue;
#if AMC_LITTLE_ENDIAN
            std::memcpy(out_state + c, &entry.states, 4);  // byte k: child k
#else
            for (int k = 0; k < 4; ++k) out_state[c + k] = uint8_t(entry.states >> (8 * k));
#endif
            // Both words always, kept by the count (no branch: which blocks have incomplete
            // corners follows no pattern). memcpy: the words are read as the bytes of out's
            // array.
            const char* words = reinterpret_cast<const char*>(block_links);
            std::memcpy(lowered + lowered_count, words + entry.lowered_offset[0], 4);
            std::memcpy(lowered + lowered_count + 1, words + entry.lowered_offset[1], 4);
            lowered_count += entry.lowered_count;
        }
    };
    with_links(level, [&](auto links) {
        if (room.words != nullptr)
            derive(links, std::true_type{});
        else
            derive(links, std::false_type{});
    });
    next.incomplete_count = uint32_t(counts >> 32);
    // Those neighbours may lie in blocks written after theirs: lowered once every state is made.
    for (uint32_t k = 0; k < lowered_count; ++k) {
        uint8_t& s = out_state[lowered[k]];
        s = kLoweredByCulledNeighbor.of[s];
    }
    return (uint64_t(uint32_t(counts)) + uint64_t(3) * count) / 2;
}

}  // namespace amc
