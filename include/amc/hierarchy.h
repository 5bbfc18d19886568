// The adaptive red-green multiresolution mesh: a base triangle mesh and a forest of quad-trees,
// one per base triangle (paper, section II-A).
//
// A node is a triangle (v0, v1, v2); edge e joins v[e] and v[(e+1)%3]. A refined node has four
// children (a red split): which corners and edge midpoints each one has, and how they link, is
// fixed in <amc/red_split.h> and nowhere else.
//
// Balance: the levels of leaves that share (part of) an edge differ by at most one. Equivalently
// a node may have children only if each of its non-boundary edges has a neighbour of the same
// level (paper: "1-regularity"). Closure: a leaf whose three edges carry hanging nodes is red
// refined. Leaves with one or two hanging nodes are closed by green triangles (leaf_mesh.cpp).
#pragma once

#include <amc/mesh.h>
#include <amc/red_split.h>

#include <atomic>
#include <cstdint>
#include <vector>

namespace amc {

using NodeId = uint32_t;
using VertexId = uint32_t;
constexpr NodeId kNoNode = 0xffffffffu;
constexpr VertexId kNoVertex = 0xffffffffu;  // a dead vertex id in maps over vertex ids
constexpr int kMaxLevel = 30;  // a level cap far beyond any mesh that fits in memory

struct Neighbors;    // internal (src/hierarchy/hierarchy_builder.h)
struct LevelSplits;  // internal (src/hierarchy/hierarchy_builder.h)
struct HierarchySlice;  // internal (src/hierarchy/hierarchy_builder.h)
struct ChildLinkRoom;   // internal (src/hierarchy/hierarchy_builder.h)

class Hierarchy {
public:
    Hierarchy() = default;
    // Builds the forest of unrefined roots over a validated base mesh (validate_triangle_mesh).
    // Root i is base triangle i; root ids are 0 .. base_triangle_count()-1.
    explicit Hierarchy(TriangleMesh base);
    // Becomes Hierarchy(base) while keeping the memory of its nodes and vertices, so that a
    // hierarchy rebuilt again and again (the time steps of a simulation) does not allocate anew.
    void reset(TriangleMesh base);

    // ---- structure -------------------------------------------------------------------------
    const TriangleMesh& base() const { return base_; }
    uint32_t root_count() const { return static_cast<uint32_t>(base_.triangles.size()); }
    // Node ids are stable while a node exists; ids of removed nodes are reused.
    uint32_t node_capacity() const { return static_cast<uint32_t>(nodes_.size()); }
    bool is_alive(NodeId n) const { return n < nodes_.size() && nodes_[n].level != kDeadLevel; }

    bool is_leaf(NodeId n) const { return nodes_[n].first_child == kNoNode; }
    NodeId child(NodeId n, int k) const { return nodes_[n].first_child + static_cast<NodeId>(k); }
    NodeId parent(NodeId n) const { return n < root_count() ? kNoNode : block_parent_[(n - root_count()) / 4]; }
    int level(NodeId n) const { return nodes_[n].level; }
    // 0..3 for children, -1 for roots.
    int child_index(NodeId n) const { return n < root_count() ? -1 : int((n - root_count()) % 4); }
    VertexId vertex(NodeId n, int i) const { return nodes_[n].v[i]; }
    // Same-level neighbour across edge e, or kNoNode (boundary, or the region there is coarser).
    NodeId neighbor(NodeId n, int e) const { return nodes_[n].nbr[e]; }
    // The neighbour's local index of the shared edge (valid when neighbor(n, e) != kNoNode).
    int neighbor_edge(NodeId n, int e) const { return (nodes_[n].nbr_edge >> (2 * e)) & 3; }
    bool is_boundary_edge(NodeId n, int e) const { return (nodes_[n].flags >> e) & 1; }
    // Edge e carries a hanging node: the same-level neighbour there is refined.
    bool has_hanging_node(NodeId n, int e) const {
        NodeId q = nodes_[n].nbr[e];
        return q != kNoNode && nodes_[q].first_child != kNoNode;
    }
    int hanging_node_count(NodeId n) const {
        return int(has_hanging_node(n, 0)) + int(has_hanging_node(n, 1)) + int(has_hanging_node(n, 2));
    }
    // Every non-boundary edge has a same-level neighbour: what balance asks of a refined node.
    bool has_all_neighbors(NodeId n) const {
        const Node& node = nodes_[n];
        // An edge without neighbour must be a boundary edge (flag bits 0-2).
        return ((node.nbr[0] != kNoNode) | (node.flags & 1)) & ((node.nbr[1] != kNoNode) | ((node.flags >> 1) & 1)) &
               ((node.nbr[2] != kNoNode) | ((node.flags >> 2) & 1));
    }
    // A leaf may be split without breaking balance (has_all_neighbors) and below the level cap.
    bool can_split(NodeId n) const {
        return is_leaf(n) && nodes_[n].level < kMaxLevel && has_all_neighbors(n);
    }
    // Midpoint vertex of edge e of a refined node.
    VertexId midpoint(NodeId n, int e) const {
        return nodes_[child(n, red_split::kCenter)].v[red_split::kCenterVertexOfMidpoint[e]];
    }

    // ---- diagonal of a two-hanging-node closure ---------------------------------------------
    // The default rule (documented in docs/HIERARCHY.md): with unrefined edge u, the diagonal
    // joins m_{(u+1)%3} and v_u. A per-node flag selects the other diagonal, m_{(u+2)%3}–v_{(u+1)%3},
    // so hierarchies made by programs with other rules are represented exactly. The flag only
    // matters while the node is a leaf with exactly two hanging nodes.
    bool diagonal_flipped(NodeId n) const { return (nodes_[n].flags >> 3) & 1; }
    void set_diagonal_flipped(NodeId n, bool flipped);

    // ---- counts ------------------------------------------------------------------------------
    uint32_t node_count() const { return live_nodes_; }
    uint32_t leaf_count() const { return live_nodes_ - (live_nodes_ - root_count()) / 4; }
    int depth() const;  // finest level that has nodes
    uint32_t vertex_count() const { return live_vertices_; }

    // ---- geometry ----------------------------------------------------------------------------
    // Vertex positions by id; ids of removed vertices are reused (position of a dead id unused).
    const std::vector<Vec3>& positions() const { return positions_; }
    Vec3 position(VertexId v) const { return positions_[v]; }
    // A base vertex's position is the base mesh's too (base().positions).
    void set_position(VertexId v, Vec3 p) {
        positions_[v] = p;
        if (v < base_.positions.size()) base_.positions[v] = p;
        far_positions_.raise_if(is_far(p));
    }
    bool single_precision() const { return base_.single_precision; }
    // Declares the coordinates float32 (new midpoints rounded to float) or float64; restores the
    // default vertex placer.
    void set_single_precision(bool single) {
        base_.single_precision = single;
        set_vertex_placer(nullptr, nullptr);
    }
    // Called for every vertex that refinement creates, with the edge's end points; the default
    // places new vertices at edge midpoints, 0.5 * (a + b) (computed without overflow where a + b
    // would overflow) rounded to float when the base is single precision.
    // A null placer restores the default.
    using VertexPlacer = Vec3 (*)(void* context, Vec3 a, Vec3 b);
    void set_vertex_placer(VertexPlacer placer, void* context);

    // ---- refinement ----------------------------------------------------------------------------
    // Red-refines leaf n, first refining coarser neighbours as balance requires, then applying the
    // closure (leaves with three hanging nodes are refined) until the hierarchy is valid again.
    // Returns the number of nodes split (0 if n was already refined); appends them to `split_nodes`
    // when given.
    uint32_t refine(NodeId n, std::vector<NodeId>* split_nodes = nullptr);
    // Removes the four children of n if they are leaves and removing them keeps the hierarchy
    // balanced and closed. Returns whether it did.
    bool coarsen(NodeId n);
    bool can_coarsen(NodeId n) const;
    // Splits leaf n with no balancing or closure; requires can_split(n). The building block of
    // refine() and of readers/decoders that replay a stored forest.
    void split(NodeId n);
    // Reserves room for `nodes` nodes and `vertices` vertex ids (a hint for bulk builders, which
    // then grow without reallocation; large reservations may be backed by huge pages).
    void reserve(size_t nodes, size_t vertices);

    // Visits every live node level by level, roots first, children in child order: the canonical
    // breadth-first order that files and coders use.
    std::vector<NodeId> breadth_first_order() const;
    std::vector<NodeId> leaves() const;  // leaves in breadth-first order

private:
    // The decoders' bulk build of a level, split_level (src/hierarchy/hierarchy_builder.h).
    friend struct HierarchyBuilder;
    void split_level(const LevelSplits& splits);
    ChildLinkRoom open_children(HierarchySlice* slice, uint32_t count);

    static constexpr uint8_t kDeadLevel = 0xff;
    // 32 bytes, aligned: a node never straddles two cache lines. Siblings share what their ids
    // already tell: the parent is kept once per block of four (block_parent_), and the child
    // index is the node's place in its block.
    struct alignas(32) Node {
        // Left uninitialized: every path that makes a node sets all its fields, and bulk growth
        // (split_level) would otherwise write every new node twice.
        Node() {}
        VertexId v[3];
        NodeId first_child;
        NodeId nbr[3];
        uint8_t nbr_edge;  // 2 bits per edge
        uint8_t level;
        uint8_t flags;  // bits 0-2: boundary edge; bit 3: diagonal flipped
        uint8_t reserved;  // 0
    };
    // The roots over base_ (vertices below vertex_end, checked), linked, and the base's positions.
    void make_roots(uint64_t vertex_end);
    void link(NodeId a, int ea, NodeId b, int eb);
    static void write_vertices(Node* child, const VertexId corner[3], const VertexId m[3]);
    VertexId new_vertex(Vec3 p);
    NodeId allocate_children(NodeId parent);

    TriangleMesh base_;
    std::vector<Node> nodes_;
    // Nodes past the roots come in blocks of four siblings: block b (nodes root_count() + 4b ..
    // + 3) has parent block_parent_[b].
    std::vector<NodeId> block_parent_;
    std::vector<NodeId> free_blocks_;  // first ids of unused blocks of four
    std::vector<Vec3> positions_;
    std::vector<VertexId> free_vertices_;
    uint32_t live_nodes_ = 0;
    uint32_t live_vertices_ = 0;
    VertexPlacer placer_ = nullptr;
    void* placer_context_ = nullptr;
    // Some position may lie beyond DBL_MAX / 2 (or be NaN), where 0.5 * (a + b) overflows: the
    // default placer then takes its overflow-safe path in split_level too. (Midpoints lie within
    // their ends' range, so only set_position and other placers can set it.) Decoders of chunks
    // set positions of one hierarchy on several threads: an atomic flag, read and set relaxed.
    class FarFlag {
    public:
        FarFlag() = default;
        FarFlag(const FarFlag& other) noexcept : far_(other.get()) {}
        FarFlag& operator=(const FarFlag& other) noexcept {
            far_.store(other.get(), std::memory_order_relaxed);
            return *this;
        }
        bool get() const { return far_.load(std::memory_order_relaxed); }
        void raise_if(bool far) {
            if (far) far_.store(true, std::memory_order_relaxed);
        }

    private:
        std::atomic<bool> far_{false};
    };
    FarFlag far_positions_;
    // The forest passed a reader's checks (HierarchyBuilder::mark_structure_checked): split(),
    // coarsen() and reset() clear it; other changes to the forest are the internal builders',
    // which make hierarchies of their own.
    bool structure_checked_ = false;
    static bool is_far(Vec3 p) {
        constexpr double kHalfMax = 8.98846567431157953865e307;  // DBL_MAX / 2
        return !(p.x <= kHalfMax && p.x >= -kHalfMax && p.y <= kHalfMax && p.y >= -kHalfMax && p.z <= kHalfMax &&
                 p.z >= -kHalfMax);
    }
};

// Structural and geometric equality: same base mesh, same forest, same effective diagonals (flags
// of leaves with two hanging nodes), same positions — compared in canonical order, so node and
// vertex ids may differ.
bool identical(const Hierarchy& a, const Hierarchy& b);

// Canonical vertex numbering: base vertices first, then new vertices in order of first
// appearance over refined nodes in breadth-first order, edges 0, 1, 2. Maps vertex id -> index
// (kNoVertex for dead ids).
std::vector<uint32_t> canonical_vertex_order(const Hierarchy& h);
// The positions of the live vertices in canonical order (vertex_count() of them).
std::vector<Vec3> canonical_positions(const Hierarchy& h);

// ---- the conforming leaf mesh (green closure) ----------------------------------------------

struct LeafMesh {
    TriangleMesh mesh;           // vertices in canonical order
    CellData cells;              // level and red/green flag per triangle
    std::vector<NodeId> source;  // the node each triangle belongs to
};

// The conforming mesh of the leaves, or of the hierarchy cut at `max_level` (nodes of that level
// treated as leaves) when max_level >= 0. Red leaves as they are; leaves with one hanging node
// bisected; leaves with two hanging nodes cut into three by the node's diagonal.
LeafMesh extract_leaf_mesh(const Hierarchy& h, int max_level = -1);

// ---- invariants ----------------------------------------------------------------------------

// Checks every structural invariant (links symmetric, balance, closure, children geometry,
// shared midpoints, counts, the level cap) and returns a description of the first violation, or
// "" if valid.
std::string check_invariants(const Hierarchy& h);
// Checks the positions of the live vertices: finite, and float32 values in a single-precision
// hierarchy (what its files store). Returns a description of the first violation, or "".
std::string check_positions(const Hierarchy& h);

// ---- base order ------------------------------------------------------------------------------

// The same hierarchy over the base mesh reordered: new vertex i is old vertex vertex_order[i];
// new triangle t is old triangle triangle_order[t] with its vertices rotated by rotation[t]
// (new local vertex i = old local vertex (i + rotation[t]) % 3). Throws Error on bad orders.
// `vertex_map`, when given, receives for every vertex id of h its id in the result (kNoVertex for
// dead ids).
Hierarchy reorder_base(const Hierarchy& h, const std::vector<uint32_t>& vertex_order,
                       const std::vector<uint32_t>& triangle_order, const std::vector<uint8_t>& rotation,
                       std::vector<VertexId>* vertex_map = nullptr);

// ---- the hierarchy file (.amh, docs/HIERARCHY.md) -------------------------------------------

std::string serialize_hierarchy(const Hierarchy& h);
// Validates everything; `what` names the source in messages. Throws Error.
Hierarchy deserialize_hierarchy(const std::string& bytes, const std::string& what);
void write_hierarchy(const std::string& path, const Hierarchy& h);
Hierarchy read_hierarchy(const std::string& path);

}  // namespace amc
