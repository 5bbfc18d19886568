// Leaf fields of a forest series frame (docs/FORMAT.md 7.12): each field coded either as the .amq
// file codes it (8.6: against the leaf before it, "spatial"), or against the previous frame's
// value at the leaf's place ("temporal": the previous leaf that holds the leaf's first corner —
// the same leaf, its parent when it was refined, its first child when it was coarsened),
// whichever is smaller. Bit-exact.
#pragma once

#include "coding/container.h"

#include <amc/octree.h>

#include <cstdint>
#include <vector>

namespace amc {

// Frozen values.
enum class ForestFieldMode : uint8_t { spatial = 0, temporal = 1 };

// Where each leaf of `next` was in `prev` (null for a keyframe).
struct ForestFieldFrame {
    const OctreeForest* prev = nullptr;
    const OctreeForest* next = nullptr;
    std::vector<uint64_t> prev_leaf;  // per leaf of next: the previous leaf holding its first corner
    std::vector<uint8_t> relation;    // 0 the same leaf, 1 finer than it, 2 coarser
    ForestFieldFrame(const OctreeForest* prev, const OctreeForest& next);
};

// Appends the field's entry (mode, length, payload) to `out`. `field` is a validated leaf field of
// frame.next; the temporal mode is tried when the previous frame has a field of the same name,
// type and components.
void encode_forest_field(const Field& field, const ForestFieldFrame& frame, std::vector<uint8_t>& out);
// Reads one entry; refuses more than max_values values (limit_exceeded). Throws Error (corrupt,
// truncated) naming the field.
Field decode_forest_field(PayloadReader& in, const ForestFieldFrame& frame, uint64_t max_values);

}  // namespace amc
