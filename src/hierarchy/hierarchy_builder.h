// What the decoders and encoders may do to a Hierarchy beyond its public interface: build a whole
// level in one pass, and fetch nodes ahead. Internal: not part of the installed headers.
#pragma once

#include <amc/hierarchy.h>

#include <cstdint>
#include <vector>

namespace amc {

// The same-level neighbours of a node across its edges 0-2, as local indices of its level
// (kNoNode where it has none). The coder's level forest and split_level share this layout.
struct Neighbors {
    uint32_t nbr[3];
};
static_assert(sizeof(Neighbors) == 12, "split_level reads four siblings' Neighbors as twelve words");

// A whole level's splits: the distinct splittable leaves parents[0..count) of one level, whose
// same-level neighbours are not refined yet, in the order they are split, and the links of the
// nodes they make: children[4 * i + k] for child k of parents[i], with local index 4 * j + k'
// for child k' of parents[j], kNoNode where a child has no neighbour (boundary, or the
// neighbour across the parent's edge is not in `parents` and stays a leaf). They must be the
// links split() makes.
struct LevelSplits {
    const NodeId* parents = nullptr;
    uint32_t count = 0;
    const Neighbors* children = nullptr;
};

struct HierarchyBuilder {
    // Splits level.parents in order with the result of calling split() on each in turn (same
    // node ids, vertex ids and links), in one pass: the bulk form for decoders that replay a
    // stored forest level by level. When no ids are free for reuse (a hierarchy that was only
    // ever refined), child k of parents[i] gets id node_capacity() + 4 * i + k, node_capacity()
    // taken before the call.
    static void split_level(Hierarchy& h, const LevelSplits& level) { h.split_level(level); }
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
