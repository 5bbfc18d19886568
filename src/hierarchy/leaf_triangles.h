// The triangles of the conforming leaf mesh, in hierarchy vertex ids (paper, Fig. 3): red leaves as
// they are, green closures of one or two hanging nodes. extract_leaf_mesh numbers them canonically;
// the import checks them against its input without that renumbering. Internal.
#pragma once

#include <amc/hierarchy.h>

#include <string>
#include <vector>

namespace amc {

// Calls emit(n, a, b, c, green) for each triangle of the leaves of `breadth_first` (the nodes of
// h in breadth-first order, or any range of node ids when max_level < 0), in that order; with
// max_level >= 0, nodes of that level are taken as leaves (whole, no closure) and finer ones are
// left out.
template <class Nodes, class Emit>
void for_each_leaf_triangle(const Hierarchy& h, const Nodes& breadth_first, int max_level, Emit emit) {
    const bool cut = max_level >= 0;
    for (NodeId n : breadth_first) {
        const bool at_cut = cut && h.level(n) >= max_level;
        if (cut && h.level(n) > max_level) break;  // breadth-first: all later nodes are finer
        if (!h.is_leaf(n) && !at_cut) continue;
        bool hanging[3];
        VertexId mid[3];
        int count = 0;
        for (int e = 0; e < 3; ++e) {
            hanging[e] = !at_cut && h.has_hanging_node(n, e);
            if (hanging[e]) {
                mid[e] = h.midpoint(h.neighbor(n, e), h.neighbor_edge(n, e));
                ++count;
            }
        }
        const VertexId v[3] = {h.vertex(n, 0), h.vertex(n, 1), h.vertex(n, 2)};
        if (count == 0) {
            emit(n, v[0], v[1], v[2], false);
        } else if (count == 1) {
            const int e = hanging[0] ? 0 : hanging[1] ? 1 : 2;
            const VertexId a = v[e], b = v[(e + 1) % 3], c = v[(e + 2) % 3];
            emit(n, a, mid[e], c, true);
            emit(n, mid[e], b, c, true);
        } else if (count == 2) {
            const int u = !hanging[0] ? 0 : !hanging[1] ? 1 : 2;  // the unrefined edge
            const VertexId a = v[u], b = v[(u + 1) % 3], c = v[(u + 2) % 3];
            const VertexId m1 = mid[(u + 1) % 3], m2 = mid[(u + 2) % 3];
            emit(n, m2, m1, c, true);
            if (!h.diagonal_flipped(n)) {  // default diagonal m_{u+1} -- v_u
                emit(n, a, b, m1, true);
                emit(n, a, m1, m2, true);
            } else {  // flipped diagonal m_{u+2} -- v_{u+1}
                emit(n, a, b, m2, true);
                emit(n, b, m1, m2, true);
            }
        } else {
            throw Error("leaf mesh: node " + std::to_string(n) + " has three hanging nodes (closure violated)");
        }
    }
}

}  // namespace amc
