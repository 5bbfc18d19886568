#include "coding/hierarchy/bucket_queue.h"

namespace amc {

BucketTops BucketQueue::push_lowered(const uint8_t* state, uint32_t n, BucketTops tops) {
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

}  // namespace amc
