// Corner and edge neighbours of the coarse mesh through shared vertices; see tree_corners.h.
#include "octree/tree_corners.h"

#include <algorithm>

namespace amc {

namespace {

// Vertices that name points: the faces they glue (connectivity_from_vertices) are glued so in
// `conn` too (which may glue more: periodic faces). p4est's shell and sphere reuse vertices of a
// reference patch for trees far apart (and keep their edges and corners in tree_to_edge,
// tree_to_corner); there vertices say nothing about corners.
bool vertices_name_points(const TreeConnectivity& conn) {
    if (conn.vertices.empty()) return false;
    try {
        const TreeConnectivity glued = connectivity_from_vertices(conn.dim, conn.vertices, conn.tree_to_vertex);
        const int faces = 2 * conn.dim;
        for (size_t i = 0; i < glued.tree_to_tree.size(); ++i) {
            const bool boundary = glued.tree_to_tree[i] == i / faces && glued.tree_to_face[i] == i % faces;
            if (!boundary && (glued.tree_to_tree[i] != conn.tree_to_tree[i] || glued.tree_to_face[i] != conn.tree_to_face[i]))
                return false;
        }
        return true;
    } catch (const Error&) {
        return false;
    }
}

}  // namespace

TreeCorners::TreeCorners(const TreeConnectivity& conn) : dim_(conn.dim), conn_(&conn) {
    if (!vertices_name_points(conn)) return;
    const int corners = 1 << dim_;
    at_vertex_.resize(conn.vertices.size());
    for (uint32_t t = 0; t < conn.tree_count(); ++t) {
        for (int k = 0; k < corners; ++k) at_vertex_[conn.tree_to_vertex[size_t(t) * corners + k]].push_back({t, uint8_t(k)});
        if (dim_ != 3) continue;
        for (int axis = 0; axis < 3; ++axis)
            for (int k = 0; k < corners; ++k) {
                if (k & (1 << axis)) continue;  // k: the edge's low end
                const uint32_t a = conn.tree_to_vertex[size_t(t) * corners + k];
                const uint32_t b = conn.tree_to_vertex[size_t(t) * corners + (k | (1 << axis))];
                at_edge_[{std::min(a, b), std::max(a, b)}].push_back({t, uint32_t(axis), uint32_t(k)});
            }
    }
}

TreeCorners::Around TreeCorners::around(int level, const int32_t c[3]) const {
    const int32_t n = int32_t(1) << level;
    Around out;
    for (int a = 0; a < dim_; ++a) {
        if (c[a] >= 0 && c[a] < n) {
            out.inside_axis = a;
            continue;
        }
        ++out.out_axes;
        if (c[a] >= n) out.corner |= 1 << a;
    }
    return out;
}

TreeCorners::Meeting TreeCorners::meeting(uint32_t tree, int level, const int32_t c[3], bool point) const {
    if (at_vertex_.empty()) return {UINT32_MAX, UINT32_MAX, 0};  // nothing is around anything
    const int corners = 1 << dim_;
    const Around at = around(level, c);
    const uint32_t a = conn_->tree_to_vertex[size_t(tree) * corners + at.corner];
    if (at.out_axes == dim_) return {a, UINT32_MAX, 0};
    const uint32_t b = conn_->tree_to_vertex[size_t(tree) * corners + (at.corner | (1 << at.inside_axis))];
    // The place counted from the lower vertex, as neighbours() turns it for trees the other way round.
    const int32_t along = c[at.inside_axis], n = int32_t(1) << level;
    return {std::min(a, b), std::max(a, b), uint32_t(a < b ? along : (point ? n : n - 1) - along)};
}

void TreeCorners::neighbours(uint32_t tree, int level, const int32_t c[3], std::vector<Place>& out) const {
    if (at_vertex_.empty()) return;
    const int32_t n = int32_t(1) << level;
    const int corners = 1 << dim_;
    const Around at = around(level, c);
    const int out_axes = at.out_axes, inside_axis = at.inside_axis, corner = at.corner;
    const auto at_corner = [&](uint32_t t, int k, int32_t along_axis, int32_t along) {
        Place p{t, {0, 0, 0}};
        for (int a = 0; a < dim_; ++a) p.c[a] = a == along_axis ? along : ((k >> a) & 1) ? n - 1 : 0;
        out.push_back(p);
    };
    if (out_axes == dim_) {  // a coarse vertex
        const uint32_t v = conn_->tree_to_vertex[size_t(tree) * corners + corner];
        for (const auto& tk : at_vertex_[v])
            if (tk.first != tree || tk.second != corner) at_corner(tk.first, tk.second, -1, 0);
    } else if (dim_ == 3 && out_axes == 2) {  // a coarse edge along inside_axis, at c[inside_axis]
        const uint32_t a = conn_->tree_to_vertex[size_t(tree) * corners + corner];
        const uint32_t b = conn_->tree_to_vertex[size_t(tree) * corners + (corner | (1 << inside_axis))];
        const auto it = at_edge_.find({std::min(a, b), std::max(a, b)});
        if (it == at_edge_.end()) return;
        for (const auto& e : it->second) {
            const uint32_t t = e[0];
            const int axis = int(e[1]), low = int(e[2]);
            if (t == tree && axis == inside_axis && low == corner) continue;
            const bool same_direction = conn_->tree_to_vertex[size_t(t) * corners + low] == a;
            at_corner(t, low, axis, same_direction ? c[inside_axis] : n - 1 - c[inside_axis]);
        }
    }
}

}  // namespace amc
