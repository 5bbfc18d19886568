// Hashes for tables whose keys an input chooses (a mesh's positions): any unkeyed mix, however
// strong, can be inverted or searched offline for keys that share one slot, so these mix in a key
// drawn once per process. Only for tables whose iteration order reaches no output.
#pragma once

#include "common/mixing.h"

#include <cstddef>
#include <cstdint>

namespace amc {

// Random, drawn at the first call (std::random_device, else the clock and an address).
uint64_t process_hash_key();

// Three words (a position's coordinates as bits), each absorbed through splitmix64's finaliser,
// the first with the key: no word can be chosen to cancel another's effect without knowing it.
inline uint64_t keyed_hash_words(uint64_t key, uint64_t a, uint64_t b, uint64_t c) {
    return splitmix64_mix(splitmix64_mix(splitmix64_mix(a ^ key) ^ b) ^ c);
}

// For std::unordered_map and std::unordered_set of 64-bit keys an input sets: libstdc++ hashes an
// integer to itself and its bucket counts are known primes, so keys of one residue share a bucket.
struct KeyedWordHash {
    uint64_t key = process_hash_key();
    size_t operator()(uint64_t word) const { return size_t(splitmix64_mix(word ^ key)); }
};

}  // namespace amc
