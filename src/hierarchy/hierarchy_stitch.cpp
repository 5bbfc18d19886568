// Stitching hierarchies of disjoint root sets into one (hierarchy_builder.h): the decoder of
// chunked .amc files decodes the chunks over the whole's roots with the links between chunks cut,
// or each alone, copied into its slice of the whole as soon as it is decoded, its vertices renamed
// once all are in; then links the seams.
#include "hierarchy/hierarchy_builder.h"

#include "common/check.h"
#include "common/huge_pages.h"

#include <utility>

namespace amc {

Hierarchy HierarchyBuilder::stitch_frame(const TriangleMesh& base, size_t nodes) {
    Hierarchy h(base);  // the roots, linked across every base edge
    const size_t roots = h.root_count();
    AMC_REQUIRE(nodes >= roots && (nodes - roots) % 4 == 0 && nodes < kNoNode, corrupt, "hierarchy too large to stitch");
    reserve_huge(h.nodes_, nodes);
    h.nodes_.resize(nodes);  // Node() writes nothing: the parts' copies are the first writes
    reserve_huge(h.block_parent_, (nodes - roots) / 4);
    h.block_parent_.resize((nodes - roots) / 4);
    return h;
}

void HierarchyBuilder::stitch_part(Hierarchy& h, const StitchPart& p) {
    const Hierarchy& s = *p.part;
    const NodeId r = s.root_count(), roots = h.root_count();
    auto id = [&](NodeId n) { return n == kNoNode ? kNoNode : n < r ? p.first_root + n : p.first_node + (n - r); };
    for (NodeId i = 0; i < r; ++i) {  // the roots keep the whole base's links
        Hierarchy::Node& root = h.nodes_[p.first_root + i];
        root.first_child = id(s.nodes_[i].first_child);
        root.flags = uint8_t((root.flags & 7u) | (s.nodes_[i].flags & 8u));
    }
    for (NodeId j = r; j < s.node_capacity(); ++j) {
        const Hierarchy::Node& from = s.nodes_[j];
        Hierarchy::Node& to = h.nodes_[p.first_node + (j - r)];
        for (int e = 0; e < 3; ++e) {
            to.v[e] = p.vertex_id[from.v[e]];
            to.nbr[e] = id(from.nbr[e]);
        }
        to.first_child = id(from.first_child);
        to.nbr_edge = from.nbr_edge;
        to.level = from.level;
        to.flags = from.flags;  // seam edges are still boundary edges: linked by stitch_seams
        to.reserved = 0;
    }
    const size_t first_block = (p.first_node - roots) / 4;
    for (size_t b = 0; b < s.block_parent_.size(); ++b) h.block_parent_[first_block + b] = id(s.block_parent_[b]);
}

void HierarchyBuilder::append_vertices(Hierarchy& h, const std::vector<Vec3>& positions) {
    AMC_REQUIRE(h.positions_.size() + positions.size() < kNoVertex, limit_exceeded, "too many vertices");
    for (const Vec3& p : positions) h.far_positions_ |= Hierarchy::is_far(p);
    h.positions_.insert(h.positions_.end(), positions.begin(), positions.end());
    h.live_vertices_ = uint32_t(h.positions_.size());
}

std::vector<HierarchyBuilder::RootLink> HierarchyBuilder::cut_root_links(Hierarchy& h,
                                                                        const std::vector<std::pair<NodeId, int>>& edges) {
    std::vector<RootLink> links;
    for (const auto& edge : edges) {
        const NodeId a = edge.first, b = h.nodes_[a].nbr[edge.second];
        if (b == kNoNode) continue;  // its other side was listed first
        const int eb = h.neighbor_edge(a, edge.second);
        links.push_back({a, edge.second, b, eb});
        for (const auto& [n, e] : {std::pair<NodeId, int>(a, edge.second), std::pair<NodeId, int>(b, eb)}) {
            Hierarchy::Node& node = h.nodes_[n];
            node.nbr[e] = kNoNode;
            node.nbr_edge = uint8_t(node.nbr_edge & ~(3u << (2 * e)));  // as Hierarchy(base) leaves an edge without neighbour
            node.flags = uint8_t(node.flags | (1u << e));
        }
    }
    return links;
}

void HierarchyBuilder::relink_roots(Hierarchy& h, const std::vector<RootLink>& links) {
    for (const RootLink& l : links) {
        h.link(l.a, l.ea, l.b, l.eb);
        h.nodes_[l.a].flags = uint8_t(h.nodes_[l.a].flags & ~(1u << l.ea));
        h.nodes_[l.b].flags = uint8_t(h.nodes_[l.b].flags & ~(1u << l.eb));
    }
}

void HierarchyBuilder::stitch_positions(Hierarchy& h, std::vector<Vec3> positions) {
    AMC_REQUIRE(positions.size() >= h.base().positions.size() && positions.size() < kNoVertex, corrupt,
                "hierarchy too large to stitch");
    for (const Vec3& p : positions) h.far_positions_ |= Hierarchy::is_far(p);
    h.positions_ = std::move(positions);
    h.live_vertices_ = uint32_t(h.positions_.size());
}

void HierarchyBuilder::stitch_seams(Hierarchy& h, std::vector<std::pair<NodeId, int>> seam) {
    h.live_nodes_ = uint32_t(h.nodes_.size());

    // The root edges on the seams, then the halves of each, level by level (a node's links are
    // complete before its children are linked).
    std::vector<std::pair<NodeId, int>> next;
    while (!seam.empty()) {
        next.clear();
        for (const auto& seam_edge : seam) {
            const NodeId n = seam_edge.first;  // plain names: AMC_REQUIRE's lambda cannot capture a structured binding
            const int e = seam_edge.second;
            const NodeId q = h.nodes_[n].nbr[e];
            if (h.is_leaf(n)) {
                AMC_REQUIRE(h.hanging_node_count(n) < 3, corrupt, "chunks do not fit together: a leaf with three hanging nodes");
                continue;
            }
            AMC_REQUIRE(q != kNoNode, corrupt,
                        "chunks do not fit together: a node of level " + std::to_string(h.level(n)) +
                            " is refined next to a coarser region of another chunk");
            const NodeId first = h.child(n, red_split::kFirstHalfChild[e]), second = h.child(n, red_split::kSecondHalfChild[e]);
            h.nodes_[first].flags &= uint8_t(~(1u << e));
            h.nodes_[second].flags &= uint8_t(~(1u << e));
            if (!h.is_leaf(q)) {
                const int eq = h.neighbor_edge(n, e);
                h.link(first, e, h.child(q, red_split::kSecondHalfChild[eq]), eq);
                h.link(second, e, h.child(q, red_split::kFirstHalfChild[eq]), eq);
            }
            next.emplace_back(first, e);
            next.emplace_back(second, e);
        }
        std::swap(seam, next);
    }
}

}  // namespace amc
