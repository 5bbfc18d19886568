// Predictions of refinement vertices (midpoint, butterfly) and of base vertices (parallelogram);
// see geometry_prediction.h.
#include "coding/geometry/geometry_prediction.h"

#include "coding/geometry/hierarchy_on_grid.h"
#include "common/exact_float.h"

#include <algorithm>
#include <cmath>

namespace amc {

namespace {

template <class Mesh>
Vec3 round_if_single(const Mesh& h, Vec3 p) { return h.single_precision() ? rounded_to_float(p) : p; }

// (i + 1) % 3 at i and (i + 2) % 3 at i + 1, for i in 0..2: local indices without a division.
constexpr int kNext[5] = {1, 2, 0, 1, 2};

// The vertex of node m opposite its edge f.
template <class Mesh>
Vec3 opposite(const Mesh& h, NodeId m, int f) { return h.position(h.vertex(m, kNext[f + 1])); }

// Vertex opposite edge f of node m in the same-level neighbour across f, or the reflection
// (x + y) - z where there is none (computed only then).
template <class Mesh>
Vec3 wing(const Mesh& h, NodeId m, int f, Vec3 x, Vec3 y, Vec3 z) {
    const NodeId r = h.neighbor(m, f);
    return r == kNoNode ? x + y - z : opposite(h, r, h.neighbor_edge(m, f));
}

}  // namespace

std::vector<std::vector<NodeId>> nodes_by_level(const Hierarchy& h) {
    std::vector<std::vector<NodeId>> levels;
    for (NodeId n : h.breadth_first_order()) {
        const size_t l = static_cast<size_t>(h.level(n));
        if (levels.size() <= l) levels.resize(l + 1);
        levels[l].push_back(n);
    }
    return levels;
}

std::vector<std::pair<NodeId, int>> new_vertices_of_level(const Hierarchy& h,
                                                          const std::vector<NodeId>& level_nodes) {
    // A midpoint is shared only with the same-level neighbour across the edge; it was listed
    // before iff that neighbour is refined and comes earlier in level order. A vertex flag is
    // the simplest exact test of that.
    std::vector<bool> seen(h.positions().size(), false);
    std::vector<std::pair<NodeId, int>> out;
    for (NodeId n : level_nodes) {
        if (h.is_leaf(n)) continue;
        for (int e = 0; e < 3; ++e) {
            const VertexId m = h.midpoint(n, e);
            if (seen[m]) continue;
            seen[m] = true;
            out.emplace_back(n, e);
        }
    }
    return out;
}

template <class Mesh>
Vec3 predict_midpoint(const Mesh& h, NodeId n, int e) {
    const Vec3 a = h.position(h.vertex(n, e));
    const Vec3 b = h.position(h.vertex(n, kNext[e]));
    return round_if_single(h, rounded_scaled(0.5, a + b));  // FORMAT.md 5.5 (forest.cpp's placer where a + b is finite)
}

template <class Mesh>
Vec3 predict_butterfly(const Mesh& h, NodeId n, int e) {
    const NodeId q = h.neighbor(n, e);
    if (q == kNoNode) return predict_midpoint(h, n, e);
    const int e1 = kNext[e], e2 = kNext[e + 1];
    const Vec3 a = h.position(h.vertex(n, e));
    const Vec3 b = h.position(h.vertex(n, e1));
    const Vec3 c = h.position(h.vertex(n, e2));
    const int eq = h.neighbor_edge(n, e);  // q's edge eq runs b -> a
    const Vec3 d = opposite(h, q, eq);
    const Vec3 w_bc = wing(h, n, e1, b, c, a);
    const Vec3 w_ca = wing(h, n, e2, c, a, b);
    const Vec3 w_ad = wing(h, q, kNext[eq], a, d, b);
    const Vec3 w_db = wing(h, q, kNext[eq + 1], d, b, a);
    // Every product rounded before it is added (common/exact_float.h): the decoder computes the same.
    const Vec3 p = rounded_scaled(0.5, a + b) + rounded_scaled(0.125, c + d) -
                   rounded_scaled(0.0625, (w_bc + w_ca) + (w_ad + w_db));
    return round_if_single(h, p);
}

template Vec3 predict_midpoint(const Hierarchy&, NodeId, int);
template Vec3 predict_midpoint(const HierarchyOnGrid&, NodeId, int);
template Vec3 predict_butterfly(const Hierarchy&, NodeId, int);
template Vec3 predict_butterfly(const HierarchyOnGrid&, NodeId, int);

NormalFrame normal_frame(const Hierarchy& h, NodeId n, int e, bool unit_normals) {
    const FrameCorners corners = frame_corners(h, n, e);
    return unit_normals ? frame_of<true>(h, corners) : frame_of<false>(h, corners);
}

Vec3 predict_parallelogram(const std::vector<Vec3>& decoded, std::array<int32_t, 3> stencil) {
    const auto valid = [&](int32_t i) { return i >= 0 && static_cast<size_t>(i) < decoded.size(); };
    if (valid(stencil[0]) && valid(stencil[1]) && valid(stencil[2])) {
        return decoded[size_t(stencil[0])] + decoded[size_t(stencil[1])] - decoded[size_t(stencil[2])];
    }
    if (valid(stencil[0])) return decoded[size_t(stencil[0])];
    return Vec3{};
}

}  // namespace amc
