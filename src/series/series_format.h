// Constants of the series file (docs/FORMAT.md, section 7): the one place that knows them.
#pragma once

#include <cstddef>
#include <cstdint>

namespace amc {

constexpr char kSeriesMagic[4] = {'A', 'M', 'C', 'S'};
constexpr uint8_t kSeriesVersion = 2;         // written
constexpr uint8_t kNewestSeriesVersion = 2;   // read: 1 .. this
constexpr size_t kSeriesHeaderSize = 16;      // magic, version, flags, 2 reserved, keyframe interval, XXH32
constexpr size_t kSeriesBlockOverhead = 9;    // type, u32 length, u32 checksum
constexpr uint8_t kSeriesFlagSinglePrecision = 1;
constexpr uint32_t kMaxSeriesFields = 4096;   // fields in one frame

// Block types: frozen values.
enum class SeriesBlock : uint8_t { end = 0, base = 1, keyframe = 2, frame = 3 };

}  // namespace amc
