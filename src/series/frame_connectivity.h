// Inter-frame connectivity (docs/FORMAT.md, section 7.5): a frame's forest coded against the
// previous frame's, level by level in canonical order, one "refined?" symbol per node that the
// refinement rules leave free, in a context that knows the previous frame (was the node there, a
// leaf, refined, with leaf children; did its decided neighbours change; did its parent's
// neighbourhood change). An unchanged region costs next to nothing.
#pragma once

#include "coding/entropy/arithmetic_coder.h"

#include <amc/hierarchy.h>

#include <array>
#include <climits>
#include <cstdint>
#include <vector>

namespace amc {

// Version 2: a refinement indicator from a cell field of the reference (FORMAT.md 7.6): per node
// id of the reference its level L = floor(8 log2(s / M)) (s the largest square over the node's
// cells, or its four leaf children's cells; M the field's mean square), and one threshold per
// class (1: leaves, 2: nodes refined with four leaves), chosen by the encoder.
constexpr int32_t kNoIndicator = INT32_MIN, kZeroIndicator = INT32_MIN + 1, kInfiniteIndicator = INT32_MAX;
constexpr int32_t kMaxIndicatorThreshold = 1 << 14;  // |threshold| (levels of doubles lie within +-8600)
struct Indicator {
    std::vector<int32_t> levels;        // by node id of the reference
    int32_t threshold[2] = {0, 0};      // classes 1 and 2
};
Indicator indicator_levels(const Hierarchy& prev, const std::vector<uint32_t>& first_cell,
                           const std::vector<double>& values);

// Models of a frame's connectivity. Version 1: fresh at the start of each frame. Version 2:
// carried from frame to frame, fresh after a keyframe.
struct FrameConnectivityModels {
    static constexpr int kRefineContextsV1 = 24;  // 4 previous classes x 3 neighbour counts x 2 parent flags
    static constexpr int kIndicatorContexts = 14;  // none, zero, 12 distances to the threshold
    static constexpr int kRefineContextsV2 = 4 * kIndicatorContexts * 3 * 3 * 2;
    std::array<BitModel, kRefineContextsV1> refine_v1{};
    std::array<BitModel, kRefineContextsV2> refine{};
    std::array<BitModel, 3> diagonal{};  // no previous diagonal, previous flag 0, previous flag 1
};

// What the connectivity of a frame carries to the next one (version 2): its models.
struct ConnectivityMemory {
    FrameConnectivityModels models;
    bool primed = false;  // version 3: the fresh refine models were given their prior (FORMAT.md 7.6)
};

struct FrameConnectivityStats {
    uint64_t nodes = 0;          // nodes of the frame
    uint64_t coded_symbols = 0;  // symbols coded (the rest culled)
    uint64_t changed_nodes = 0;  // nodes refined now and not before, or the other way round
    uint64_t removed_nodes = 0;  // nodes of the previous frame that are gone
};

// The node of `prev` at the same place (same root, same child indices) as each node of `out`
// (indexed by node id of `out`; kNoNode where prev has none).
using Counterparts = std::vector<NodeId>;

// Codes `target`'s forest and diagonals against `prev` (a hierarchy over the same base
// triangles) in the given series version and builds in `out` the hierarchy the decoder builds
// (same node and vertex ids; new vertices at edge midpoints). `memory` holds what `prev`'s frame
// left (version 2) and receives what this frame leaves. Throws Error if the bases differ.
// `indicator`: the reference's, or null (version 2).
void encode_frame_connectivity(const Hierarchy& prev, const Hierarchy& target, int version, ConnectivityMemory& memory,
                               const Indicator* indicator, ArithmeticEncoder& encoder, Hierarchy& out,
                               Counterparts& counterparts, FrameConnectivityStats* stats = nullptr);

// Decodes into `out` (reset to prev's base first). Throws Error (corrupt, truncated,
// limit_exceeded) on a stream no encoder writes, or one that builds more than `max_nodes` nodes.
void decode_frame_connectivity(const Hierarchy& prev, int version, ConnectivityMemory& memory,
                               const Indicator* indicator, ArithmeticDecoder& decoder, uint64_t max_nodes,
                               Hierarchy& out, Counterparts& counterparts);

// The counterparts of two hierarchies over the same base triangles (the same walk, without
// coding): what the geometry and field coders of a keyframe or a delta frame need.
Counterparts match_nodes(const Hierarchy& prev, const Hierarchy& next);

// The encoder's thresholds (FORMAT.md 7.9): per class, the one that mispredicts fewest nodes of
// `next` (refined when the level is at least the threshold); `cp` = match_nodes(prev, next).
void fit_indicator_thresholds(const Hierarchy& prev, const Hierarchy& next, const Counterparts& cp, Indicator& indicator);

}  // namespace amc
