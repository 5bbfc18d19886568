// Inter-frame connectivity (docs/FORMAT.md, section 7.5): a frame's forest coded against the
// previous frame's, level by level in canonical order, one "refined?" symbol per node that the
// refinement rules leave free, in a context that knows the previous frame (was the node there, a
// leaf, refined, with leaf children; did its decided neighbours change; did its parent's
// neighbourhood change). An unchanged region costs next to nothing.
#pragma once

#include "coding/arithmetic_coder.h"

#include <amc/hierarchy.h>

#include <array>
#include <cstdint>
#include <vector>

namespace amc {

// Models of one frame's connectivity, all fresh at the start of each frame.
struct FrameConnectivityModels {
    static constexpr int kRefineContexts = 24;  // 4 previous classes x 3 neighbour counts x 2 parent flags
    std::array<BitModel, kRefineContexts> refine{};
    std::array<BitModel, 3> diagonal{};  // no previous diagonal, previous flag 0, previous flag 1
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
// triangles) and builds in `out` the hierarchy the decoder builds (same node and vertex ids; new
// vertices at edge midpoints). Throws Error if the bases differ.
void encode_frame_connectivity(const Hierarchy& prev, const Hierarchy& target, ArithmeticEncoder& encoder,
                               Hierarchy& out, Counterparts& counterparts, FrameConnectivityStats* stats = nullptr);

// Decodes into `out` (reset to prev's base first). Throws Error (corrupt, truncated,
// limit_exceeded) on a stream no encoder writes, or one that builds more than `max_nodes` nodes.
void decode_frame_connectivity(const Hierarchy& prev, ArithmeticDecoder& decoder, uint64_t max_nodes, Hierarchy& out,
                               Counterparts& counterparts);

// The counterparts of two hierarchies over the same base triangles (the same walk, without
// coding): what the geometry and field coders of a keyframe or a delta frame need.
Counterparts match_nodes(const Hierarchy& prev, const Hierarchy& next);

}  // namespace amc
