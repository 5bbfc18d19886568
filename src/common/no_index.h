// The 32-bit index that points nowhere: no vertex, no triangle, no half-edge, an empty slot.
#pragma once

#include <cstdint>

namespace amc {

constexpr uint32_t kNoIndex = 0xffffffffu;

}  // namespace amc
