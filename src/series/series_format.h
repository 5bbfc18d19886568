// Constants of the series file (docs/FORMAT.md, section 7): the one place that knows them.
#pragma once

#include <cstddef>
#include <cstdint>

namespace amc {

constexpr char kSeriesMagic[4] = {'A', 'M', 'C', 'S'};
// Versions (FORMAT.md 7.1): a file takes the lowest version that holds what it holds.
constexpr uint8_t kSeriesVersion = 3;         // written for triangle series (3: primed models, FORMAT.md 7.6)
constexpr uint8_t kForestSeriesVersion = 3;   // written for forest series (blocks 4 to 6)
constexpr uint8_t kNewestSeriesVersion = 3;   // read: 1 .. this
constexpr size_t kSeriesHeaderSize = 16;      // magic, version, flags, 2 reserved, keyframe interval, XXH32
constexpr size_t kSeriesBlockOverhead = 9;    // type, u32 length, u32 checksum
constexpr uint8_t kSeriesFlagSinglePrecision = 1;
constexpr uint32_t kMaxSeriesFields = 4096;   // fields in one frame

// Block types: frozen values.
enum class SeriesBlock : uint8_t {
    end = 0,
    base = 1,
    keyframe = 2,
    frame = 3,
    // Version 3: a series of quadtree/octree forests (FORMAT.md 7.10).
    forest_base = 4,
    forest_keyframe = 5,
    forest_frame = 6,
};
inline bool is_forest_block(SeriesBlock b) { return uint8_t(b) >= uint8_t(SeriesBlock::forest_base); }

}  // namespace amc
