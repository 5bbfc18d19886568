// Efforts 3 and 4 (EncodeOptions::effort): the base order as an encoder choice. Mode 2's start triangle
// fixes the decoder's base order (FORMAT.md 4.16), and the roots' order moves the hierarchy's code
// and the level geometry (docs/HIERARCHY_CODER.md, "The base order as an encoder choice"). The
// encoder codes the file at effort 2 in the base coder's order and in the orders of other starts
// and keeps the smallest whole file. Implemented in mesh_codec.cpp, beside encode().
#pragma once

#include "coding/base/base_mesh_coder.h"

#include <amc/codec.h>
#include <amc/hierarchy.h>

#include <cstddef>
#include <cstdint>
#include <iterator>
#include <vector>

namespace amc {

// The efforts that search the base order: from kBaseOrderEffort on, each weighs `starts` start
// triangles and codes in full the `trials` orders whose base blocks (base_blocks_bytes, a small
// part of the encode) are smallest.
constexpr int kBaseOrderEffort = 3;
struct BaseOrderSearch {
    uint32_t starts;
    size_t trials;
};
constexpr BaseOrderSearch kBaseOrderSearches[] = {{16, 4}, {64, 16}};  // efforts 3 and 4
static_assert(kBaseOrderEffort + int(std::size(kBaseOrderSearches)) - 1 == kMaxEffort, "a search for every effort above 2");

// encode() with `base` as the base connectivity code (one of base_order_candidates(), say): a
// study's or a test's way to weigh one order.
std::vector<uint8_t> encode_with_base(const Hierarchy& h, const EncodeOptions& options, const BaseMeshCode& base,
                                      EncodeStats* stats = nullptr);

}  // namespace amc
