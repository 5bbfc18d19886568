// Fields of a series frame (docs/FORMAT.md, section 7.7): point and cell arrays coded value by
// value against a prediction chosen per level: spatial (a new vertex from its edge's end points
// on the coarser level, a cell from the cell before it), temporal (the same vertex or cell in
// the previous frame) or hybrid (temporal plus the spatial change). Bit-exact, or on a grid of
// step 2 * bound so that every value is within the bound.
#pragma once

#include "coding/container.h"
#include "series/frame_state.h"

#include <amc/field.h>

#include <cstdint>
#include <vector>

namespace amc {

// Where a frame's fields live: the frame being coded (`next`, indexed) and the previous one.
struct FieldFrame {
    const FrameState& prev;
    const FrameState& next;
    const Counterparts& cp;
    const std::vector<FrameVertex>& order;  // canonical vertex order of next
    std::vector<uint32_t> index_of_vertex;  // vertex id of next -> canonical index
    std::vector<NodeId> cell_node;          // leaf-mesh triangle -> its node in next
    int levels = 1;                         // node levels of next
    FieldFrame(const FrameState& prev, const FrameState& next, const Counterparts& cp,
               const std::vector<FrameVertex>& order);
    size_t tuples(FieldAssociation a) const { return a == FieldAssociation::point ? order.size() : cell_node.size(); }
};

struct FieldCodeStats {
    uint64_t bytes = 0;
    bool bounded = false;   // coded on a grid (error-bounded)
    double max_error = 0;   // largest |decoded - input| (0 when bit-exact)
    std::vector<uint8_t> predictors;  // per level
};

// Appends the field's record to `out`; `decoded` receives what the decoder will return. bound > 0
// asks for error-bounded coding (float fields; falls back to exact where a value is not finite or
// too large for the grid). Throws Error on a field of the wrong size or with values out of its
// type's range.
void encode_field(const Field& field, double bound, const FieldFrame& frame, std::vector<uint8_t>& out,
                  Field& decoded, FieldCodeStats* stats = nullptr);
// Reads one field record. Throws Error (corrupt, truncated) naming the field.
Field decode_field(PayloadReader& in, const FieldFrame& frame);

}  // namespace amc
