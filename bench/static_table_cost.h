// What one slot of a static binary table costs, as the level-synchronous studies (level_parallel_study,
// phased_study) count it for interleaved rANS: the slot's symbols at its rounded probability, and
// the table's own bits (2 a slot, 12 more for a slot that codes a probability).
#pragma once

#include "coding/entropy/rans_coder.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

// Bits of a slot's n0 zeros and n1 ones; adds the slot's table bits to *table_bits.
inline double static_slot_bits(uint64_t n0, uint64_t n1, double* table_bits) {
    constexpr uint32_t scale = amc::kRansScale;
    *table_bits += 2;
    if (n0 == 0 || n1 == 0) return 0;
    *table_bits += 12;
    uint32_t f1 = uint32_t(std::lround(double(n1) / double(n0 + n1) * scale));
    f1 = std::min(std::max(f1, 1u), scale - 1);
    const uint32_t f0 = scale - f1;
    return double(n0) * -std::log2(double(f0) / scale) + double(n1) * -std::log2(double(f1) / scale);
}
