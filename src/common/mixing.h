// 64-bit mixing: splitmix64's generator (the same numbers on every platform, so seeded models and
// tests are reproducible anywhere) and its finaliser, and the hash of three 64-bit words.
#pragma once

#include <cstddef>
#include <cstdint>

namespace amc {

inline constexpr uint64_t kGoldenGamma = 0x9e3779b97f4a7c15ull;  // 2^64 / golden ratio, odd

// splitmix64's finaliser: every input bit moves every output bit.
inline uint64_t splitmix64_mix(uint64_t z) {
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

struct SplitMix64 {
    uint64_t state;
    uint64_t next() { return splitmix64_mix(state += kGoldenGamma); }
    size_t below(size_t n) { return size_t(next() % n); }  // the modulo's bias, n / 2^64, is negligible
    double unit() { return double(next() >> 11) * 0x1.0p-53; }  // uniform in [0, 1)
};

// Three words (a position's coordinates as bits) into one hash for open-addressed tables.
inline uint64_t hash_words(uint64_t a, uint64_t b, uint64_t c) {
    uint64_t h = a * kGoldenGamma;
    h = (h ^ (h >> 29) ^ b) * 0xbf58476d1ce4e5b9ull;
    h = (h ^ (h >> 31) ^ c) * 0x94d049bb133111ebull;
    return h ^ (h >> 32);
}

}  // namespace amc
