// How a chunked .amc file cuts the forest (docs/FORMAT.md 3.11): chunks are runs of consecutive
// roots in the decoder's base order, balanced by node count, and each is coded as a hierarchy of
// its own over the base triangles of its roots (edges to other chunks are boundary there). This
// file makes those chunk hierarchies out of a whole one (the encoder); HierarchyBuilder::stitch puts
// decoded chunks back together.
#pragma once

#include <amc/hierarchy.h>

#include <cstdint>
#include <vector>

namespace amc {

struct SubforestRoom;

struct RootRange {
    uint32_t first = 0, count = 0;
};

// The root of each live node's tree (kNoNode for unused ids).
std::vector<uint32_t> root_of_nodes(const Hierarchy& h);

// Live nodes of each root's tree; `root_of` is root_of_nodes(h).
std::vector<uint64_t> nodes_per_root(const Hierarchy& h, const std::vector<uint32_t>& root_of);

// `chunks` runs of consecutive roots (fewer when there are fewer roots), each closing once the
// nodes so far reach its share of the total: chunk k ends at the first root where the running
// count reaches (k + 1) / chunks of all nodes.
std::vector<RootRange> balanced_chunks(const std::vector<uint64_t>& nodes_per_root, uint32_t chunks);

// The base mesh of a set of roots: their triangles in order, over the vertices they use, numbered
// in increasing order of the whole base's ids (base_vertex[i] = the whole base's id of vertex i).
TriangleMesh base_of_roots(const TriangleMesh& base, const std::vector<RootRange>& roots, std::vector<VertexId>& base_vertex);

// The trees of `roots` as a hierarchy of their own over base_of_roots: same forest, positions and
// diagonal flags. `vertex_of` receives, for each vertex id of the result, the id in h.
Hierarchy extract_roots(const Hierarchy& h, const std::vector<RootRange>& roots, std::vector<VertexId>* vertex_of = nullptr);
// The same with root_of_nodes(h) made once by the caller and `local` (h.node_capacity() words) as
// scratch: calls on disjoint roots may share both and run at once. With `room`, the result and
// its replay take its arrays (HierarchyBuilder::subforest_room).
Hierarchy extract_roots(const Hierarchy& h, const std::vector<RootRange>& roots, const std::vector<uint32_t>& root_of,
                        NodeId* local, std::vector<VertexId>* vertex_of, SubforestRoom* room = nullptr);

}  // namespace amc
