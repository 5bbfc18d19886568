// The library's hierarchy decoder deciding a standalone stream, level after level, without building
// the Hierarchy (decode_phases' decide phase): the baseline the traversal studies time against.
#pragma once

#include "coding/entropy/arithmetic_coder.h"
#include "coding/hierarchy/hierarchy_level_coder.h"
#include "coding/hierarchy/hierarchy_stream.h"

#include <amc/hierarchy.h>
#include <amc/hierarchy_coder.h>

#include <cstdint>
#include <vector>

// Returns the node count decided, so that the caller can check it against the hierarchy.
inline uint64_t decide_library(amc::HierarchyLevelDecoder& coder, const amc::Hierarchy& h, const std::vector<uint8_t>& bytes) {
    amc::HierarchyStreamHeader header;
    const size_t header_size = amc::read_standalone_stream_header(bytes.data(), bytes.size(), header);
    coder.restart(h.base(), header, amc::HierarchyDecodeOptions().max_nodes);
    amc::ArithmeticDecoder decoder(bytes.data() + header_size, bytes.size() - header_size);
    while (!coder.done()) coder.decide_level(decoder);
    return coder.node_count();
}
