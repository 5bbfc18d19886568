// The hierarchy stream's header and its adaptive models, shared by encoder and decoder.
// Layout (docs/FORMAT.md, "Hierarchy stream"):
//   tag (a standalone stream only; inside an .amc file the file's version says the stream's):
//   4   magic AMHS
//   u8  version (format_version.h)
//   u8  switches: bit 0 cull 1-regularity, 1 cull hanging nodes, 2 uniform levels, 3 truncate,
//       4 context groups, 5 improved traversal, 6 orientation bits present; bit 7 reserved (0)
//   u8  number of uniformly refined levels U
//   u8  diagonal rule (DiagonalRule)
//   varint  number of coded hierarchy symbols (only when bit 3 is set)
//   ...     arithmetic-coded payload to the end of the stream
#pragma once

#include "coding/entropy/arithmetic_coder.h"
#include "coding/hierarchy/coder_switches.h"
#include "coding/hierarchy/context_groups.h"
#include "coding/format_version.h"

#include <amc/hierarchy_coder.h>

#include <array>
#include <cstdint>
#include <vector>

namespace amc {

constexpr int kMaxUniformLevels = 20;  // 4^20 times the base is far beyond any real mesh

struct HierarchyStreamHeader {
    uint8_t version = kHierarchyStreamVersion;  // not among the header's bytes: from the tag or the file
    HierarchyCoderOptions options;
    uint8_t uniform_levels = 0;
    DiagonalRule diagonal_rule = DiagonalRule::next_after_unrefined;
    bool orientation_coded = false;
    uint64_t symbol_count = 0;
};

// The tag of a standalone stream (encode_hierarchy): magic and version.
constexpr char kHierarchyStreamMagic[4] = {'A', 'M', 'H', 'S'};
std::vector<uint8_t> hierarchy_stream_tag(uint8_t version);
// Reads the tag and returns its size, or 0 for an untagged stream (written before streams had
// one; its first bytes are the switches and U <= 20, never the magic's "AM"). Throws Error on a
// version this build does not read.
size_t read_hierarchy_stream_tag(const uint8_t* data, size_t size, uint8_t& version);

// A standalone stream's tag and header fields (an untagged stream is of `untagged_version`);
// returns the bytes they use: the payload follows. Throws Error as the two readers do.
size_t read_standalone_stream_header(const uint8_t* data, size_t size, HierarchyStreamHeader& header,
                                     uint8_t untagged_version = kHierarchyStreamVersion);

// The header's fields (without the tag), as an .amc file stores them too.
std::vector<uint8_t> write_hierarchy_stream_header(const HierarchyStreamHeader& header);
// Parses the header's fields (header.version is left as it is); returns the bytes it used. Throws
// Error on a malformed header.
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
