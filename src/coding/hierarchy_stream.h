// The hierarchy stream's header and its adaptive models, shared by encoder and decoder.
// Layout (docs/FORMAT.md, "Hierarchy stream"):
//   u8  switches: bit 0 cull 1-regularity, 1 cull hanging nodes, 2 uniform levels, 3 truncate,
//       4 context groups, 5 improved traversal, 6 orientation bits present; bit 7 reserved (0)
//   u8  number of uniformly refined levels U
//   u8  diagonal rule (DiagonalRule)
//   varint  number of coded hierarchy symbols (only when bit 3 is set)
//   ...     arithmetic-coded payload to the end of the stream
#pragma once

#include "coding/arithmetic_coder.h"
#include "coding/context_groups.h"

#include <amc/hierarchy_coder.h>

#include <array>
#include <cstdint>
#include <vector>

namespace amc {

constexpr int kMaxUniformLevels = 20;  // 4^20 times the base is far beyond any real mesh

struct HierarchyStreamHeader {
    HierarchyCoderOptions options;
    uint8_t uniform_levels = 0;
    DiagonalRule diagonal_rule = DiagonalRule::next_after_unrefined;
    bool orientation_coded = false;
    uint64_t symbol_count = 0;
};

std::vector<uint8_t> write_hierarchy_stream_header(const HierarchyStreamHeader& header);
// Parses the header; returns the bytes it used. Throws Error on a malformed header.
size_t read_hierarchy_stream_header(const uint8_t* data, size_t size, HierarchyStreamHeader& header);

// Every model of the hierarchy coder has the default window: the coders pass it as a constant.
constexpr int kHierarchyModelLimit = BitModel::kDefaultLimitLog2;

// One adaptive model per context group (or one shared model without contexts), and one for the
// orientation bits.
struct HierarchyModels {
    std::array<BitModel, kContextGroupCount> groups{};
    BitModel orientation{};
    BitModel& for_group(int group, bool use_contexts) { return groups[use_contexts ? group : 0]; }
};

}  // namespace amc
