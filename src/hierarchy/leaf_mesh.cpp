// The conforming leaf mesh, numbered canonically (its triangles: hierarchy/leaf_triangles.h).
#include <amc/hierarchy.h>

#include "hierarchy/hierarchy_builder.h"
#include "hierarchy/leaf_triangles.h"

#include <algorithm>

namespace amc {

LeafMesh extract_leaf_mesh(const Hierarchy& h, int max_level) {
    const std::vector<NodeId> breadth_first = h.breadth_first_order();
    const std::vector<uint32_t> canonical = canonical_vertex_order(h, breadth_first);
    const bool cut = max_level >= 0;
    LeafMesh out;
    out.mesh.single_precision = h.single_precision();
    // Uncut, every vertex is a corner of a leaf or the hanging node of a green closure.
    uint32_t used_vertices = cut ? static_cast<uint32_t>(h.base().positions.size()) : h.vertex_count();
    // A leaf gives one triangle, or two or three when closed: room for a quarter of them closed
    // without growing (the vectors double once where more are).
    const size_t room = size_t(h.leaf_count()) + h.leaf_count() / 4;
    out.mesh.triangles.reserve(room);
    out.cells.level.reserve(room);
    out.cells.is_green.reserve(room);
    out.source.reserve(room);

    for_each_leaf_triangle(h, breadth_first, max_level, [&](NodeId n, VertexId a, VertexId b, VertexId c, bool green) {
        out.mesh.triangles.push_back({canonical[a], canonical[b], canonical[c]});
        out.cells.level.push_back(uint8_t(h.level(n)));
        out.cells.is_green.push_back(green ? 1 : 0);
        out.source.push_back(n);
        // Cut, the vertices used are those of the triangles: every corner and hanging node is one's.
        if (cut) used_vertices = std::max({used_vertices, canonical[a] + 1, canonical[b] + 1, canonical[c] + 1});
    });
    out.mesh.positions.resize(used_vertices);
    for (size_t v = 0; v < canonical.size(); ++v) {
        if (canonical[v] < used_vertices) out.mesh.positions[canonical[v]] = h.position(VertexId(v));
    }
    return out;
}

}  // namespace amc
