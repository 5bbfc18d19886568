// Logistic context mixing for the hierarchy coder's mixing mode (docs/HIERARCHY_CODER.md, "Contexts
// beyond Table 2"; docs/FORMAT.md section 2): several adaptive bit models each give a probability,
// their stretched values ln(p / (1 - p)) are weighted and summed, and the sum squashed back is
// refined by an adaptive probability map (secondary estimation). As in PAQ/lpaq, all in integers,
// so that encoder and decoder agree bit for bit on every machine.
#pragma once

#include "coding/entropy/arithmetic_coder.h"
#include "common/simd.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

namespace amc {

namespace mixing {

// Probabilities of a one in 12 bits (0..4095); stretched values in [-2047, 2047], units of 1/256.
constexpr int kStretchLimit = 2047;

// squash's knots: 4096 / (1 + e^(-x / 256)) at x = -2048, -1920, ..., 2048 (lpaq1's table).
inline constexpr int16_t kSquashKnots[33] = {1,    2,    3,    6,    10,   16,   27,   45,   73,   120,  194,
                                             310,  488,  747,  1101, 1546, 2047, 2549, 2994, 3348, 3607, 3785,
                                             3901, 3975, 4022, 4050, 4068, 4079, 4085, 4089, 4092, 4093, 4094};

// squash(x) = 4096 / (1 + e^(-x / 256)), interpolated between the knots.
constexpr int squash(int x) {
    if (x > kStretchLimit) return 4095;
    if (x < -kStretchLimit) return 1;
    const int w = x & 127;
    const int k = (x >> 7) + 16;
    return (kSquashKnots[k] * (128 - w) + kSquashKnots[k + 1] * w + 64) >> 7;
}

// The inverse of squash on 12-bit probabilities, built by the compiler (no guarded static).
struct StretchTable {
    std::array<int16_t, 4096> t{};
    constexpr StretchTable() {
        int pi = 0;
        for (int x = -kStretchLimit; x <= kStretchLimit; ++x) {
            const int v = squash(x);
            for (int j = pi; j <= v; ++j) t[size_t(j)] = int16_t(x);
            pi = v + 1;
        }
        for (int j = pi; j < 4096; ++j) t[size_t(j)] = kStretchLimit;
    }
};
inline constexpr StretchTable kStretchTable{};

inline int stretch(int p12) { return kStretchTable.t[size_t(p12)]; }

// A model's 16-bit probability as a 12-bit one, kept inside 1..4095.
inline int p12_of(const BitModel& m) { return std::clamp(int(m.p16() >> 4), 1, 4095); }

// The sum of w[i] * st[i] over i < count (a multiple of 4, at most 64), exactly; |st[i]| < 2^15.
inline int64_t weighted_sum(const int32_t* w, const int* st, int count) {
#if AMC_SSE2
    // madd of w's two int16 halves with (st, 0) and (0, st); madd reads the low half as signed,
    // so where its bit 15 is set it counted lo - 2^16: `borrow` adds those st back, times 2^16.
    const __m128i low_half = _mm_set1_epi32(0xFFFF);
    __m128i high = _mm_setzero_si128(), low = _mm_setzero_si128(), borrow = _mm_setzero_si128();
    for (int i = 0; i < count; i += 4) {
        const __m128i wv = _mm_loadu_si128(reinterpret_cast<const __m128i*>(w + i));
        const __m128i sv = _mm_loadu_si128(reinterpret_cast<const __m128i*>(st + i));
        high = _mm_add_epi32(high, _mm_madd_epi16(wv, _mm_slli_epi32(sv, 16)));
        low = _mm_add_epi32(low, _mm_madd_epi16(wv, _mm_and_si128(sv, low_half)));
        borrow = _mm_add_epi32(borrow, _mm_and_si128(sv, _mm_srai_epi32(_mm_slli_epi32(wv, 16), 31)));
    }
    alignas(16) int32_t h[4], l[4], b[4];
    _mm_store_si128(reinterpret_cast<__m128i*>(h), high);
    _mm_store_si128(reinterpret_cast<__m128i*>(l), low);
    _mm_store_si128(reinterpret_cast<__m128i*>(b), borrow);
    int64_t upper = 0, lower = 0;
    for (int k = 0; k < 4; ++k) {
        upper += int64_t(h[k]) + b[k];
        lower += l[k];
    }
    return upper * 65536 + lower;
#else
    int64_t dot = 0;
    for (int i = 0; i < count; ++i) dot += int64_t(w[i]) * st[i];
    return dot;
#endif
}

// w[i] += (st[i] * err + 2^15) >> 16 for i < count (a multiple of 4); |st[i] * err| < 2^28.
inline void add_scaled(int32_t* w, const int* st, int err, int count) {
#if AMC_SSE2
    // err = a 2^15 + c with 0 <= c < 2^15: st * err = madd((st, 0), (c, a)) + madd((0, st), (c, a)) 2^15.
    const uint32_t c = uint32_t(err) & 0x7FFF, a = uint32_t(err >> 15) & 0xFFFF;
    const __m128i pair = _mm_set1_epi32(int32_t((a << 16) | c));
    const __m128i low_half = _mm_set1_epi32(0xFFFF), half = _mm_set1_epi32(1 << 15);
    for (int i = 0; i < count; i += 4) {
        const __m128i sv = _mm_loadu_si128(reinterpret_cast<const __m128i*>(st + i));
        const __m128i product = _mm_add_epi32(_mm_madd_epi16(_mm_and_si128(sv, low_half), pair),
                                              _mm_slli_epi32(_mm_madd_epi16(_mm_slli_epi32(sv, 16), pair), 15));
        __m128i* wp = reinterpret_cast<__m128i*>(w + i);
        _mm_storeu_si128(wp, _mm_add_epi32(_mm_loadu_si128(wp), _mm_srai_epi32(_mm_add_epi32(product, half), 16)));
    }
#else
    for (int i = 0; i < count; ++i) w[i] += (st[i] * err + (1 << 15)) >> 16;
#endif
}

// Weights of one mixer for `inputs` inputs, chosen among `sets` weight sets by a small context.
// The stretched inputs are read in groups of four: a caller's array holds padded(inputs) values,
// zero past the inputs.
class Mixer {
public:
    static constexpr int padded(int inputs) { return (inputs + 3) / 4 * 4; }
    Mixer(int inputs, int sets, int rate) : Mixer(inputs, sets, rate, nullptr) {}
    // The same, every set starting at the `inputs` weights `start` (1/inputs each when null).
    Mixer(int inputs, int sets, int rate, const int32_t* start)
        : n_(padded(inputs)), rate_(rate), w_(size_t(n_) * size_t(sets), 0) {
        for (size_t s = 0; s < size_t(sets); ++s)
            for (int i = 0; i < inputs; ++i) w_[s * size_t(n_) + size_t(i)] = start ? start[i] : (1 << 16) / inputs;
    }
    // The mixed 12-bit probability of the stretched inputs `st` under weight set `set`.
    int mix(const int* st, int set) {
        set_ = set;
        const int64_t dot = weighted_sum(&w_[size_t(set) * size_t(n_)], st, n_);
        const int x = int(std::clamp<int64_t>(dot >> 16, -kStretchLimit, kStretchLimit));
        p_ = squash(x);
        return p_;
    }
    void update(const int* st, bool bit) {
        const int err = ((int(bit) << 12) - p_) * rate_;
        add_scaled(&w_[size_t(set_) * size_t(n_)], st, err, n_);
    }

private:
    int n_, rate_, set_ = 0, p_ = 2048;
    std::vector<int32_t> w_;
};

// Adaptive probability map: refines a probability by a small context, interpolating between 33
// knots over the stretched domain (lpaq1's APM).
class ProbabilityMap {
public:
    ProbabilityMap(int contexts, int rate) : rate_(rate), t_(size_t(contexts) * 33) {
        for (size_t c = 0; c < size_t(contexts); ++c)
            for (int j = 0; j < 33; ++j) t_[c * 33 + size_t(j)] = uint16_t(squash((j - 16) * 128) * 16);
    }
    int refine(int p12, int context) { return refine_stretched(stretch(p12), context); }
    // refine for the probability whose stretched value is `stretched`.
    int refine_stretched(int stretched, int context) {
        const int s = stretched + 2048;  // 1..4095
        const int lo = s & 127;
        index_ = size_t(context) * 33 + size_t(s >> 7);
        weight_hi_ = lo;
        return (t_[index_] * (128 - lo) + t_[index_ + 1] * lo) >> 11;
    }
    void update(bool bit) {
        const int g = (int(bit) << 16) + (int(bit) << rate_) - int(bit) - int(bit);
        // Both knots move towards the bit, the nearer one more (as lpaq moves the nearer only).
        size_t k = weight_hi_ < 64 ? index_ : index_ + 1;
        t_[k] = uint16_t(t_[k] + ((g - t_[k]) >> rate_));
    }

private:
    int rate_;
    size_t index_ = 0;
    int weight_hi_ = 0;
    std::vector<uint16_t> t_;
};

}  // namespace mixing

}  // namespace amc
