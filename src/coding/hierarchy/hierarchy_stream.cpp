// Header of the hierarchy stream (layout in hierarchy_stream.h and docs/FORMAT.md).
#include "coding/hierarchy/hierarchy_stream.h"

#include "coding/container.h"
#include "common/check.h"

#include <cstring>
#include <string>

namespace amc {

HierarchyCoderOptions coder_options_from_switches(int switches) {
    HierarchyCoderOptions o;
    o.cull_one_regularity = switches & 1;
    o.cull_hanging_nodes = switches & 2;
    o.uniform_levels = switches & 4;
    o.truncate_stream = switches & 8;
    o.use_contexts = switches & 16;
    o.traversal = (switches & 32) ? Traversal::improved : Traversal::naive;
    return o;
}

int coder_switches(const HierarchyCoderOptions& o) {
    return int(o.cull_one_regularity) | int(o.cull_hanging_nodes) << 1 | int(o.uniform_levels) << 2 |
           int(o.truncate_stream) << 3 | int(o.use_contexts) << 4 | int(o.traversal == Traversal::improved) << 5;
}

namespace {

void check_version(uint8_t version) {
    AMC_REQUIRE(version <= kHierarchyStreamVersion, unsupported_version,
                "hierarchy stream: unsupported version " + std::to_string(version) +
                    " (newer than this build, which reads versions " + std::to_string(kOldestHierarchyStreamVersion) +
                    " to " + std::to_string(kHierarchyStreamVersion) + ")");
    AMC_REQUIRE(version >= kOldestHierarchyStreamVersion, corrupt, "hierarchy stream: unknown version " + std::to_string(version));
}

}  // namespace

std::vector<uint8_t> hierarchy_stream_tag(uint8_t version) {
    std::vector<uint8_t> out(kHierarchyStreamMagic, kHierarchyStreamMagic + 4);
    out.push_back(version);
    return out;
}

size_t read_hierarchy_stream_tag(const uint8_t* data, size_t size, uint8_t& version) {
    if (size < 2 || data[0] != uint8_t(kHierarchyStreamMagic[0]) || data[1] != uint8_t(kHierarchyStreamMagic[1])) return 0;
    AMC_REQUIRE(size >= 4 && std::memcmp(data, kHierarchyStreamMagic, 4) == 0, bad_magic, "hierarchy stream: bad magic");
    AMC_REQUIRE(size >= 5, truncated, "hierarchy stream: truncated before its version");
    version = data[4];
    check_version(version);
    return 5;
}

std::vector<uint8_t> write_hierarchy_stream_header(const HierarchyStreamHeader& header) {
    const HierarchyCoderOptions& o = header.options;
    const uint8_t switches = uint8_t(coder_switches(o) | int(header.orientation_coded) << 6);
    std::vector<uint8_t> out{switches, header.uniform_levels, uint8_t(header.diagonal_rule)};
    if (o.truncate_stream) put_varint(out, header.symbol_count);
    return out;
}

size_t read_hierarchy_stream_header(const uint8_t* data, size_t size, HierarchyStreamHeader& header) {
    AMC_REQUIRE(size >= 3, truncated, "hierarchy stream: header is truncated");
    const uint8_t switches = data[0];
    AMC_REQUIRE(!(switches & 0x80), corrupt, "hierarchy stream: reserved switch bit is set");
    header.options = coder_options_from_switches(switches & 63);
    const HierarchyCoderOptions& o = header.options;
    header.orientation_coded = switches & 64;
    header.uniform_levels = data[1];
    AMC_REQUIRE(header.uniform_levels <= kMaxUniformLevels && (o.uniform_levels || header.uniform_levels == 0),
                corrupt, "hierarchy stream: " + std::to_string(header.uniform_levels) + " uniform levels is out of range");
    AMC_REQUIRE(data[2] < kDiagonalRuleCount, corrupt, "hierarchy stream: unknown diagonal rule " + std::to_string(data[2]));
    header.diagonal_rule = DiagonalRule(data[2]);
    size_t used = 3;
    header.symbol_count = 0;
    if (o.truncate_stream) {
        // At most 9 bytes (63 bits), as the format fixes it.
        const VarintRead read = read_varint(data, size, used, header.symbol_count, 63);
        AMC_REQUIRE(read != VarintRead::truncated, truncated, "hierarchy stream: symbol count is truncated");
        AMC_REQUIRE(read != VarintRead::too_long, corrupt, "hierarchy stream: symbol count is too long");
    }
    return used;
}

size_t read_standalone_stream_header(const uint8_t* data, size_t size, HierarchyStreamHeader& header,
                                     uint8_t untagged_version) {
    header.version = untagged_version;
    const size_t tag_size = read_hierarchy_stream_tag(data, size, header.version);
    if (tag_size == 0) check_version(untagged_version);
    return tag_size + read_hierarchy_stream_header(data + tag_size, size - tag_size, header);
}

}  // namespace amc
