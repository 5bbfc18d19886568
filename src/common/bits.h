// Bit tricks shared by the coders.
#pragma once

#include <cstdint>

namespace amc {

// The number of bits of x without leading zeros (0 for 0).
inline int bit_length(uint64_t x) { return x == 0 ? 0 : 64 - __builtin_clzll(x); }

}  // namespace amc
