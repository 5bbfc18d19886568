// What the decoders and encoders may do to a Hierarchy beyond its public interface: build a whole
// level in one pass, and fetch nodes ahead. Internal: not part of the installed headers.
#pragma once

#include <amc/hierarchy.h>

#include <cstdint>
#include <vector>

namespace amc {

struct HierarchyBuilder {
    // Splits the leaves parents[0..count) of h in that order with the result of calling split()
    // on each in turn (same node ids, vertex ids and links), in one pass: the bulk form for
    // decoders that replay a stored forest level by level. The parents must be distinct
    // splittable leaves of one level whose same-level neighbours are not refined yet. The caller
    // gives the links of the new nodes: the twelve words at child_links + 12 * i hold, for child k
    // of parents[i] and its edge e (word 3 * k + e), its same-level neighbour as a local index
    // 4 * j + k' (child k' of parents[j]), or kNoNode where it has none (boundary, or the
    // neighbour across the parent's edge is not in `parents` and stays a leaf). They must be the
    // links split() makes. When no ids are free for reuse (a hierarchy that was only ever
    // refined), child k of parents[i] gets id node_capacity() + 4 * i + k, node_capacity() taken
    // before the call.
    static void split_level(Hierarchy& h, const NodeId* parents, uint32_t count, const uint32_t* child_links) {
        h.split_level(parents, count, child_links);
    }
    // One piece of a hierarchy to stitch (stitch below): a hierarchy over some of the roots, and
    // where its nodes and vertices go in the whole.
    struct StitchPart {
        const Hierarchy* part = nullptr;
        NodeId first_root = 0;  // its root i becomes root first_root + i
        NodeId first_node = 0;  // its node root_count() + j becomes node first_node + j (a multiple of 4 past the roots)
        const VertexId* vertex_id = nullptr;  // its vertex v becomes vertex vertex_id[v]
    };
    // The hierarchy over `base` made of `parts` (their roots cover base's triangles once; their
    // nodes fill first_node.. without gaps; positions[v] is vertex v's position, base vertices
    // first): each part's nodes copied with their ids mapped (on up to `threads` threads, parts
    // being disjoint), then the parts linked across the edges between them, where each had a
    // boundary: the halves of two refined neighbours are linked as split() links them. Throws
    // Error (corrupt) where parts do not fit: a refined node next to a coarser region of another
    // part, a leaf with three hanging nodes.
    static Hierarchy stitch(const TriangleMesh& base, std::vector<Vec3> positions, const std::vector<StitchPart>& parts,
                            unsigned threads);
    // Hints the processor to fetch node n (for traversals that know their next nodes early).
    static void prefetch(const Hierarchy& h, NodeId n) { __builtin_prefetch(h.nodes_.data() + n); }
};

}  // namespace amc
