// Effort 3 (EncodeOptions::effort): the base order as an encoder choice. Mode 2's start triangle
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
#include <vector>

namespace amc {

// The effort that searches the base order, the start triangles it weighs, and how many of those
// orders the mixing mode codes in full (the smallest in the paper mode).
constexpr int kBaseOrderEffort = 3;
constexpr uint32_t kBaseOrderStarts = 16;
constexpr size_t kBaseOrderTrials = 4;

// encode() with `base` as the base connectivity code (one of base_order_candidates(), say): a
// study's or a test's way to weigh one order.
std::vector<uint8_t> encode_with_base(const Hierarchy& h, const EncodeOptions& options, const BaseMeshCode& base,
                                      EncodeStats* stats = nullptr);

}  // namespace amc
