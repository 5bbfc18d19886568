// What the series coder keeps of a decoded frame to code the next one against (both sides keep
// the same), and the frame's vertex order with what each vertex was in the previous frame.
#pragma once

#include "series/frame_connectivity.h"

#include <amc/field.h>
#include <amc/hierarchy.h>

#include <cstdint>
#include <vector>

namespace amc {

struct FrameState {
    Hierarchy h;                       // the frame as decoded (node and vertex ids of the decoder)
    std::vector<uint32_t> canonical;   // vertex id -> canonical index
    std::vector<uint32_t> first_cell;  // node id -> its first triangle in the leaf mesh (leaves only)
    std::vector<uint8_t> closure;      // node id -> hanging-edge mask | diagonal flag << 3 (leaves only)
    std::vector<Field> fields;         // as decoded: point fields in canonical order, cells in leaf order
    ConnectivityMemory memory;         // what the next frame's connectivity starts from (version 2)
};

// Fills canonical, first_cell and closure from h.
void index_frame(FrameState& state);

// The state before a keyframe: the base mesh unrefined, no fields.
FrameState initial_state(const TriangleMesh& base);

// A vertex of the frame in canonical order: level 0 for base vertices, l + 1 for the vertices
// that refining level l creates (midpoint of `edge` of `node`); `previous` is the same vertex in
// the previous frame (a vertex id there), or kNoVertex for a new one.
struct FrameVertex {
    VertexId id;
    VertexId previous;
    NodeId node;  // kNoNode for base vertices
    uint8_t edge;
    uint8_t level;
};
std::vector<FrameVertex> frame_vertex_order(const Hierarchy& h, const Hierarchy& prev, const Counterparts& cp);

// Levels of vertices (1 + the deepest level that creates vertices; at least 1 for the base).
inline int vertex_level_count(const std::vector<FrameVertex>& order) {
    return order.empty() ? 1 : order.back().level + 1;
}

}  // namespace amc
