// The improved traversal's bucket queue (paper II-E) over a level's state bytes (level_forest.h):
// priorities 0 (culled: nothing to code) to 4 (no neighbour decided yet). Buckets 0-3 are stacks
// of local indices; bucket 4 never receives a node once the level starts, so it is a cursor over
// the level (next_fresh). LevelTraversal::run_on pushes and pops on the raw tops inside its loop,
// the hottest of the coder; this class holds the stacks and the scans over whole levels.
#pragma once

#include "coding/hierarchy/level_forest.h"
#include "common/compiler.h"
#include "common/huge_pages.h"
#include "common/simd.h"

#include <array>
#include <cstdint>

namespace amc {

// The tops of buckets 0-3.
struct BucketTops {
    uint32_t* at[4];
};

class BucketQueue {
public:
    // Empty buckets with room for n entries each (each holds at most one entry per node); returns
    // their bottoms, which are also their tops.
    BucketTops reset(uint32_t n) {
        return {{stacks_[0].reserve(n), stacks_[1].reserve(n), stacks_[2].reserve(n), stacks_[3].reserve(n)}};
    }

    // Pushes the undecided nodes below bucket 4 (those the culled nodes lowered) onto their
    // stacks, in reverse canonical order. Where they are follows no pattern, so the state bytes
    // are read 16 at a time as bit masks and only the set bits are visited. Not inlined, so that
    // GCC allocates run_on's registers for the loop over coded nodes alone.
    AMC_NOIPA static BucketTops push_lowered(const uint8_t* state, uint32_t n, BucketTops tops);

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

    // Gives the buckets' pages back to the system (release_pages) until the next reset.
    void release() {
        for (ScratchArray<uint32_t>& stack : stacks_) stack.release_from(0);
    }
    // Gives the buckets' storage back to the allocator: all of it, or when it is far larger than a
    // level of n nodes needs (ScratchArray::shrink_for).
    void deallocate() {
        for (ScratchArray<uint32_t>& stack : stacks_) stack.deallocate();
    }
    void shrink_for(uint32_t n) {
        for (ScratchArray<uint32_t>& stack : stacks_) stack.shrink_for(n);
    }

private:
    std::array<ScratchArray<uint32_t>, 4> stacks_;
};

}  // namespace amc
