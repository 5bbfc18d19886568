// What the decoders and encoders may do to a Hierarchy beyond its public interface: build a whole
// level in one pass, and fetch nodes ahead. Internal: not part of the installed headers.
#pragma once

#include "common/compiler.h"

#include <amc/hierarchy.h>

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace amc {

// The same-level neighbours of a node across its edges 0-2, as local indices of its level
// (kNoNode where it has none). The coder's level forest and split_level share this layout.
struct Neighbors {
    uint32_t nbr[3];
};
static_assert(sizeof(Neighbors) == 12, "split_level reads four siblings' Neighbors as twelve words");

// What the four children of one refined node p take from p besides their neighbours: p's
// neighbour_edge (2 bits per edge) on the edges whose neighbour is refined too (0 on the others)
// and p's boundary edges (bits 0-2). The coder's level forest keeps one per block of four siblings
// and split_level reads them as they are.
struct BlockEdges {
    uint8_t nbr_edge;
    uint8_t boundary;
};

// The four vertices the normal frame of a new vertex reads (coding/geometry/geometry_prediction.h):
// a and b, the ends of the split edge e of node n (a = v[e], b = v[(e + 1) % 3]), c, n's vertex
// opposite the edge, and d, the vertex opposite the edge in n's same-level neighbour across it
// (kNoVertex when there is none).
struct FrameCorners {
    VertexId a, b, c, d;
};

// The frame corners of the vertices a level's split made, ids first, first + 1, ... in the order
// split_level made them, for decoders that take a run of vertices at a time (the static geometry
// decoders): walked from the split parents in the built hierarchy, so that no list of a level's
// corners (16 bytes a vertex, a tenth of a decode's peak) is kept; or read from a list.
class NewVertexCorners {
public:
    static constexpr size_t kRun = 64;  // at most this many vertices a call of next()
    NewVertexCorners() = default;
    // The `count` vertices from `first` that splitting parents[0..parent_count) of h in this order
    // made: edge e of parent p made the next id when that id is p's midpoint on e (an earlier
    // parent's midpoint or a seam vertex is an older id).
    NewVertexCorners(const Hierarchy& h, const NodeId* parents, uint32_t parent_count, VertexId first, size_t count)
        : h_(&h), parents_(parents), parent_count_(parent_count), first_(first), count_(count), next_vertex_(first) {}
    // `count` corners listed: vertex first + k's at list[k].
    NewVertexCorners(const FrameCorners* list, VertexId first, size_t count) : list_(list), first_(first), count_(count) {}
    size_t size() const { return count_; }
    VertexId first() const { return first_; }
    // The corners of the next n (at most kRun) vertices, valid until the next call. Throws Error
    // when the parents made fewer vertices than announced.
    const FrameCorners* next(size_t n);

private:
    const Hierarchy* h_ = nullptr;
    const NodeId* parents_ = nullptr;
    uint32_t parent_count_ = 0;
    const FrameCorners* list_ = nullptr;
    VertexId first_ = 0;
    size_t count_ = 0;
    size_t taken_ = 0;  // vertices handed out
    // The walk: the next parent, the next vertex id, and run_'s corners (made_ of them, of which
    // the last next() handed out handed_; a parent's last two may be left for the next run).
    uint32_t parent_ = 0;
    VertexId next_vertex_ = 0;
    size_t made_ = 0, handed_ = 0;
    FrameCorners run_[kRun + 2];
};

// Where split_level writes when decoders of several chunks build one hierarchy at once, each on
// its own thread: the chunk's run of node ids and of vertex ids, made beforehand (open_slices),
// filled from the front; the hierarchy's sizes and counts stay as open_slices set them.
struct HierarchySlice {
    NodeId next_node = 0, node_end = 0;
    VertexId next_vertex = 0, vertex_end = 0;
    std::string owner = "a chunk";  // what fills it, in errors
};

// The arrays subforest() fills (HierarchyBuilder::subforest_room).
struct SubforestRoom {
    Hierarchy arrays;  // node, block and position arrays (adopt_storage)
    std::vector<NodeId> old_of;
    std::vector<VertexId> vertex_of;
    size_t nodes = 0, vertices = 0;  // the entries HierarchyBuilder::make_resident populates
};

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
    // When set (with `children`), child_edges[i] is what the children of parents[i] take from it
    // (BlockEdges): their tails need not be found from their links.
    const BlockEdges* child_edges = nullptr;
    // When set, asked for the vertex splitting each boundary edge (a, b) of a parent: an
    // existing vertex's id (placed already: no new vertex), or kNoVertex for a new one. The
    // chunk decoder's seam vertices (chunk_coder.h).
    VertexId (*boundary_vertex)(void* context, VertexId a, VertexId b) = nullptr;
    void* boundary_context = nullptr;
    // False: the new vertices' positions are left at zero, for a decoder that sets every one of
    // them next (their midpoints would be read and computed for nothing).
    bool place_new_vertices = true;
    // With place_new_vertices false and no slice: not even zeroed. positions() keeps its size
    // until the caller appends the new vertices' positions in id order (append_positions), before
    // anything reads them: zeroing a level's positions to overwrite them wrote each twice.
    bool append_new_positions = false;
    // When known, the number of new vertices the splits create (used without boundary_vertex): a
    // level decoder counted them already. A hint for the room to reserve: a hierarchy's end grows
    // as it must anyway; a slice's room is checked by counting.
    uint64_t new_vertex_count = kUnknownCount;
    static constexpr uint64_t kUnknownCount = ~uint64_t{0};
    // When set, the children and new vertices go to the slice's next ids (throws Error when they
    // do not fit), not to the end of the hierarchy.
    HierarchySlice* slice = nullptr;
    // When set (`children` null), the children's links, as `children` would hold them, are in
    // their own nodes already: written into the room HierarchyBuilder::open_children made.
    bool links_in_place = false;
};

// canonical_vertex_order (hierarchy.h) over h.breadth_first_order() made already, for callers
// that walk that order too (the leaf mesh): one pass over the nodes instead of two.
std::vector<uint32_t> canonical_vertex_order(const Hierarchy& h, const std::vector<NodeId>& breadth_first);

// The room of the nodes the next split_level makes, opened before it (HierarchyBuilder::
// open_children): node j of the room (child j % 4 of parents[j / 4]) has its three link words at
// words + kStride * j. A level's links written there need no array of their own.
struct ChildLinkRoom {
    static constexpr size_t kStride = 8;  // words a node
    uint32_t* words = nullptr;
};

struct HierarchyBuilder {
    // Splits level.parents in order with the result of calling split() on each in turn (same
    // node ids, vertex ids and links), in one pass: the bulk form for decoders that replay a
    // stored forest level by level. When no ids are free for reuse (a hierarchy that was only
    // ever refined), child k of parents[i] gets id node_capacity() + 4 * i + k, node_capacity()
    // taken before the call.
    static void split_level(Hierarchy& h, const LevelSplits& level) {
        // Written only when set: threads that fill slices of one hierarchy at once (never a
        // checked one) only read it.
        if (h.structure_checked_) h.structure_checked_ = false;
        h.split_level(level);
    }
    // Makes the nodes of the `count` blocks of four that the next split_level (with
    // links_in_place) fills: at the hierarchy's end (grown, contents unset; node_capacity() counts
    // them from now) or at `slice`'s next node. Only for a hierarchy that was only ever refined.
    // Throws Error when the slice does not hold them.
    static ChildLinkRoom open_children(Hierarchy& h, HierarchySlice* slice, uint32_t count) {
        return h.open_children(slice, count);
    }
    // The next `count` positions of vertices split_level made with append_new_positions (ids
    // positions().size() on), within the room it reserved. `near`: none is Hierarchy::is_far.
    static void append_positions(Hierarchy& h, const Vec3* positions, size_t count, bool near) {
        h.positions_.insert(h.positions_.end(), positions, positions + count);
        if (!near)
            for (size_t k = 0; k < count; ++k) h.far_positions_.raise_if(Hierarchy::is_far(positions[k]));
    }
    // Stitching hierarchies of disjoint root sets into one (hierarchy_stitch.cpp): the decoder of
    // chunked files decodes the chunks of the whole over its roots, each as if its roots were the
    // whole base (their links to other chunks cut), in order or each into its slice at once.
    // Appends vertices at `positions` (ids vertex_count() on), placed before any split.
    static void append_vertices(Hierarchy& h, const std::vector<Vec3>& positions);
    // A link between two roots across their edges ea and eb.
    struct RootLink {
        NodeId a;
        int ea;
        NodeId b;
        int eb;
    };
    // Cuts the root edges `edges` (root, edge; both sides listed): boundary edges without
    // neighbour, as a hierarchy over part of the base sees them. Returns the links cut, once each.
    static std::vector<RootLink> cut_root_links(Hierarchy& h, const std::vector<std::pair<NodeId, int>>& edges);
    // Restores links that cut_root_links cut.
    static void relink_roots(Hierarchy& h, const std::vector<RootLink>& links);
    // Gives `h` (roots and vertices, nothing split) `nodes` nodes and `vertices` vertices, those
    // past its own not yet written: the slices (HierarchySlice) of decoders that fill them on
    // several threads, each writing, and so first touching, its own. `zeroed`, when it holds
    // `vertices` positions (made on another thread), becomes the positions' storage; otherwise
    // they are zeroed here.
    static void open_slices(Hierarchy& h, size_t nodes, size_t vertices, std::vector<Vec3> zeroed = {});
    // Gives `h` (its roots only, as constructed) the node, block and position arrays of `spare`, a
    // hierarchy its owner is done with, where they hold more: a decode into `h` then writes memory
    // that is resident already instead of faulting fresh pages in. `spare` is left empty.
    static void adopt_storage(Hierarchy& h, Hierarchy&& spare);
    // Renames the vertex ids of the nodes in [begin, end): v becomes rename(v).
    template <class Rename>
    static void stitch_rename_vertices(Hierarchy& whole, NodeId begin, NodeId end, Rename rename) {
        for (NodeId n = begin; n < end; ++n) {
            Hierarchy::Node& node = whole.nodes_[n];
            for (int e = 0; e < 3; ++e) node.v[e] = rename(node.v[e]);
        }
    }
    // The whole's positions (base vertices first), replacing those it has, once every part is in.
    static void stitch_positions(Hierarchy& whole, std::vector<Vec3> positions);
    // Completes the whole once every part is in and the root links across the seams are there:
    // `seam` lists the root edges (root, edge) that a part saw as boundary and the whole does not;
    // the halves of two refined neighbours are linked as split() links them, level by level.
    // Throws Error (corrupt) where parts do not fit: a refined node next to a coarser region of
    // another part, a leaf with three hanging nodes.
    static void stitch_seams(Hierarchy& whole, std::vector<std::pair<NodeId, int>> seam);
    // reorder_base (hierarchy.h) on up to `threads` threads: the same ids whatever their number.
    static Hierarchy reorder_base(const Hierarchy& h, const std::vector<uint32_t>& vertex_order,
                                  const std::vector<uint32_t>& triangle_order, const std::vector<uint8_t>& rotation,
                                  std::vector<VertexId>* vertex_map, unsigned threads);
    // Its base mesh: vertex i is old vertex vertex_order[i] (new_id receives the inverse), triangle
    // t old triangle triangle_order[t] turned by rotation[t]. Throws Error when the orders are not
    // permutations of the base's.
    static TriangleMesh reordered_base_mesh(const TriangleMesh& old_base, const std::vector<uint32_t>& vertex_order,
                                            const std::vector<uint32_t>& triangle_order, const std::vector<uint8_t>& rotation,
                                            std::vector<uint32_t>& new_id);
    // Its work once the orders are checked: the result over `base` (the reordered base mesh), old
    // base vertex v being base_vertex_id[v].
    static Hierarchy reordered(const Hierarchy& h, TriangleMesh base, const std::vector<uint32_t>& triangle_order,
                               const std::vector<uint8_t>& rotation, const std::vector<uint32_t>& base_vertex_id,
                               std::vector<VertexId>* vertex_map, unsigned threads);
    // set_position for a vertex that is not a base vertex, inlined into the geometry decoders'
    // loops (set_position's base test and call cost them 4 % of a decode's instructions; GCC left
    // the static decoder's second call per pair out of line).
    AMC_ALWAYS_INLINE static void set_new_vertex_position(Hierarchy& h, VertexId v, Vec3 p) {
        h.positions_[v] = p;
        h.far_positions_.raise_if(Hierarchy::is_far(p));
    }
    // The same for a position that a decoder knows to be near (not Hierarchy::is_far): a grid
    // point of a box whose corners are near. Without the test, a sixth of a grid level's stores.
    AMC_ALWAYS_INLINE static void set_near_vertex_position(Hierarchy& h, VertexId v, Vec3 p) { h.positions_[v] = p; }
    static bool is_far(Vec3 p) { return Hierarchy::is_far(p); }
    // The trees of `roots` (ids in h, in this order) as a hierarchy of their own over `base`, their
    // triangles in that order (its vertex i being h's base_vertex[i]), as replaying their splits
    // breadth-first with split() makes it: the same node and vertex ids, links and boundary flags,
    // diagonal flags on leaves. root_of[q] is the root of h's node q and root_in[r - root_in_first]
    // marks the roots taken (none outside its span); local[q] (one word per node of h) receives
    // the result's id of each node taken and is read only for them, so calls on disjoint roots may
    // share it at once. `vertex_of` receives each vertex's id in h. With `room` (subforest_room's),
    // its arrays are those of the result and of the replay.
    static Hierarchy subforest(const Hierarchy& h, TriangleMesh base, const std::vector<NodeId>& roots,
                               const std::vector<VertexId>& base_vertex, const std::vector<uint32_t>& root_of,
                               const std::vector<uint8_t>& root_in, uint32_t root_in_first, NodeId* local,
                               std::vector<VertexId>* vertex_of, SubforestRoom* room = nullptr);
    // Room for a subforest of h of `nodes` nodes and about `vertices` vertices, reserved (not yet
    // resident: make_resident below) in the calling thread's malloc arena, also when
    // another thread fills it.
    static SubforestRoom subforest_room(const Hierarchy& h, size_t nodes, size_t vertices);
    // Makes the room's entries for its nodes and vertices resident (populate_pages: on the
    // project's VM several times cheaper than subforest()'s writes faulting them in). Any thread
    // may call it, so that the thread that fills a room populates it while others fill theirs.
    static void make_resident(SubforestRoom& room);
    // The reader of a hierarchy file has made every structural check check_invariants makes (its
    // forest replayed with split() under can_split, the closure checked): writers may skip them
    // while nothing changes the forest (writer_checks.h).
    static void mark_structure_checked(Hierarchy& h) { h.structure_checked_ = true; }
    static bool structure_checked(const Hierarchy& h) { return h.structure_checked_; }
    // Takes back the splits of parents[from..] (in the order split() made them, the last first)
    // in a hierarchy that was only ever split (no ids free for reuse, so each split's children and
    // new vertices are the last ids): the same nodes, vertices, links and sizes as before them.
    // The import's local trials (src/import/pick_backtrack.cpp) undo their splits this way
    // instead of restoring a copy of the hierarchy.
    static void undo_splits(Hierarchy& h, const std::vector<NodeId>& parents, size_t from);
    // Node n's neighbour edge indices, 2 bits per edge (Hierarchy::neighbor_edge's), in one byte:
    // a decoder that reads several of them looks them up by the byte.
    static unsigned neighbor_edges(const Hierarchy& h, NodeId n) { return h.nodes_[n].nbr_edge; }
    // Hints the processor to fetch node n (for traversals that know their next nodes early).
    static void prefetch(const Hierarchy& h, NodeId n) { __builtin_prefetch(h.nodes_.data() + n); }
};

// The (parent, edge) of each of the `count` vertices from `first` that splitting
// parents[0..parent_count) of h in this order made, in id order: NewVertexCorners' walk, for the
// geometry modes that predict from the parent's edge (midpoint, butterfly), where a list of the
// pairs would take 8 bytes a vertex at a decode's peak. Taken a run at a time, as
// NewVertexCorners' corners. Its reads of the centre children (in the level just made) cost time
// where the level is large: a tenth of uniform's lossless decode when it came alone
// (docs/BENCHMARKS.md).
class NewVertexEdges {
public:
    NewVertexEdges(const Hierarchy& h, const NodeId* parents, uint32_t parent_count, VertexId first, size_t count)
        : h_(&h), parents_(parents), parent_count_(parent_count), next_vertex_(first), end_(VertexId(first + count)) {}
    // Writes the next vertices' (parent, edge), at most n, to out; returns how many (0 at the
    // end). Throws Error when the parents made fewer vertices than announced.
    size_t take(std::pair<NodeId, int>* out, size_t n);

private:
    const Hierarchy* h_;
    const NodeId* parents_;
    uint32_t parent_count_;
    uint32_t parent_ = 0;  // the next parent
    int edge_ = 0;         // its next edge
    VertexId next_vertex_, end_;
};

}  // namespace amc
