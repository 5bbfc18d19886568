// Logistic context mixing for the hierarchy coder's mixing mode (docs/HIERARCHY_CODER.md, "Contexts
// beyond Table 2"; docs/FORMAT.md section 2): several adaptive bit models each give a probability,
// their stretched values ln(p / (1 - p)) are weighted and summed, and the sum squashed back is
// refined by an adaptive probability map (secondary estimation). As in PAQ/lpaq, all in integers,
// so that encoder and decoder agree bit for bit on every machine.
#pragma once

#include "coding/entropy/arithmetic_coder.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

namespace amc {

namespace mixing {

// Probabilities of a one in 12 bits (0..4095); stretched values in [-2047, 2047], units of 1/256.
constexpr int kStretchLimit = 2047;

// squash(x) = 4096 / (1 + e^(-x / 256)), interpolated between 33 knots (lpaq1's table).
inline int squash(int x) {
    static constexpr int16_t kKnots[33] = {1,    2,    3,    6,    10,   16,   27,   45,   73,   120,  194,
                                           310,  488,  747,  1101, 1546, 2047, 2549, 2994, 3348, 3607, 3785,
                                           3901, 3975, 4022, 4050, 4068, 4079, 4085, 4089, 4092, 4093, 4094};
    if (x > kStretchLimit) return 4095;
    if (x < -kStretchLimit) return 1;
    const int w = x & 127;
    const int k = (x >> 7) + 16;
    return (kKnots[k] * (128 - w) + kKnots[k + 1] * w + 64) >> 7;
}

// The inverse of squash on 12-bit probabilities.
struct StretchTable {
    std::array<int16_t, 4096> t;
    StretchTable() {
        int pi = 0;
        for (int x = -kStretchLimit; x <= kStretchLimit; ++x) {
            const int v = squash(x);
            for (int j = pi; j <= v; ++j) t[size_t(j)] = int16_t(x);
            pi = v + 1;
        }
        for (int j = pi; j < 4096; ++j) t[size_t(j)] = kStretchLimit;
    }
};

inline int stretch(int p12) {
    static const StretchTable table;
    return table.t[size_t(p12)];
}

// A model's 16-bit probability as a 12-bit one, kept inside 1..4095.
inline int p12_of(const BitModel& m) { return std::clamp(int(m.p16() >> 4), 1, 4095); }

// Weights of one mixer for `inputs` inputs, chosen among `sets` weight sets by a small context.
class Mixer {
public:
    Mixer(int inputs, int sets, int rate) : n_(inputs), rate_(rate), w_(size_t(inputs) * size_t(sets), (1 << 16) / inputs) {}
    // The same, every set starting at the `inputs` weights `start`.
    Mixer(int inputs, int sets, int rate, const int32_t* start) : n_(inputs), rate_(rate), w_(size_t(inputs) * size_t(sets)) {
        for (size_t s = 0; s < size_t(sets); ++s) std::copy_n(start, inputs, &w_[s * size_t(inputs)]);
    }
    // The mixed 12-bit probability of the stretched inputs `st` under weight set `set`.
    int mix(const int* st, int set) {
        set_ = set;
        const int32_t* w = &w_[size_t(set) * size_t(n_)];
        int64_t dot = 0;
        for (int i = 0; i < n_; ++i) dot += int64_t(w[i]) * st[i];
        const int x = int(std::clamp<int64_t>(dot >> 16, -kStretchLimit, kStretchLimit));
        p_ = squash(x);
        return p_;
    }
    void update(const int* st, bool bit) {
        const int err = ((int(bit) << 12) - p_) * rate_;
        int32_t* w = &w_[size_t(set_) * size_t(n_)];
        for (int i = 0; i < n_; ++i) w[i] += (st[i] * err + (1 << 15)) >> 16;
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
    int refine(int p12, int context) {
        const int s = stretch(p12) + 2048;  // 1..4095
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
