// Stitching hierarchies of disjoint root sets into one (hierarchy_builder.h): the decoder of
// chunked .amc files decodes the chunks over the whole's roots with the links between chunks cut,
// one after the other or each into its slice of the whole at once; then links the seams.
#include "hierarchy/hierarchy_builder.h"

#include "common/check.h"
#include "common/huge_pages.h"

#include <algorithm>
#include <utility>

namespace amc {

void HierarchyBuilder::open_slices(Hierarchy& h, size_t nodes, size_t vertices, std::vector<Vec3> zeroed) {
    const size_t roots = h.root_count();
    AMC_REQUIRE(h.nodes_.size() == roots && h.free_blocks_.empty() && h.free_vertices_.empty(), invalid_input,
                "open_slices: the hierarchy is refined already");
    AMC_REQUIRE(nodes >= roots && (nodes - roots) % 4 == 0 && nodes < kNoNode && vertices >= h.positions_.size() &&
                    vertices < kNoVertex,
                corrupt, "hierarchy too large to decode in slices");
    reserve_huge(h.nodes_, nodes);
    h.nodes_.resize(nodes);  // Node() writes nothing: the slices' decoders are the first to write
    reserve_huge(h.block_parent_, (nodes - roots) / 4);
    h.block_parent_.resize((nodes - roots) / 4);
    if (zeroed.size() == vertices) {
        std::copy(h.positions_.begin(), h.positions_.end(), zeroed.begin());
        h.positions_.swap(zeroed);
    } else {
        reserve_huge(h.positions_, vertices);
        h.positions_.resize(vertices);
    }
    h.live_nodes_ = uint32_t(nodes);
    h.live_vertices_ = uint32_t(vertices);
}

void HierarchyBuilder::adopt_storage(Hierarchy& h, Hierarchy&& spare) {
    AMC_REQUIRE(h.nodes_.size() == h.root_count() && h.free_blocks_.empty() && h.free_vertices_.empty(), invalid_input,
                "adopt_storage: the hierarchy is refined already");
    auto adopt = [](auto& into, auto& from) {
        if (from.capacity() <= into.capacity()) return;
        from.assign(into.begin(), into.end());
        into.swap(from);
    };
    adopt(h.nodes_, spare.nodes_);
    adopt(h.block_parent_, spare.block_parent_);
    adopt(h.positions_, spare.positions_);
    spare = Hierarchy();
}

void HierarchyBuilder::append_vertices(Hierarchy& h, const std::vector<Vec3>& positions) {
    AMC_REQUIRE(h.positions_.size() + positions.size() < kNoVertex, limit_exceeded, "too many vertices");
    for (const Vec3& p : positions) h.far_positions_.raise_if(Hierarchy::is_far(p));
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
    for (const Vec3& p : positions) h.far_positions_.raise_if(Hierarchy::is_far(p));
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
