// A hierarchy's nodes read with positions held apart from it: a quantized encode of one chunk
// reads the input's nodes and the grid points of its positions (as the decoder will have them)
// without a copy of the nodes to move the positions into. The geometry encoders (predictions,
// static and adaptive level coders) are compiled for Hierarchy and for this view.
#pragma once

#include <amc/hierarchy.h>

#include <vector>

namespace amc {

class HierarchyOnGrid {
public:
    // `positions` by vertex id of h; both outlive the view.
    HierarchyOnGrid(const Hierarchy& h, const std::vector<Vec3>& positions) : h_(h), positions_(positions) {}

    int level(NodeId n) const { return h_.level(n); }
    VertexId vertex(NodeId n, int i) const { return h_.vertex(n, i); }
    NodeId neighbor(NodeId n, int e) const { return h_.neighbor(n, e); }
    int neighbor_edge(NodeId n, int e) const { return h_.neighbor_edge(n, e); }
    VertexId midpoint(NodeId n, int e) const { return h_.midpoint(n, e); }
    NodeId child(NodeId n, int k) const { return h_.child(n, k); }
    const Hierarchy& nodes() const { return h_; }

    const std::vector<Vec3>& positions() const { return positions_; }
    Vec3 position(VertexId v) const { return positions_[v]; }
    // Grid points are reconstructed as doubles, whatever the input's precision.
    bool single_precision() const { return false; }

private:
    const Hierarchy& h_;
    const std::vector<Vec3>& positions_;
};

}  // namespace amc
