// Quadtree and octree forests as p4est, deal.II and t8code use them (issue 28): a coarse mesh of
// quadrilaterals (dim 2) or hexahedra (dim 3), "trees" glued face to face with an orientation,
// and one quadtree or octree per tree. Leaves are stored as p4est stores them: per tree, in
// Morton order, each an Octant with p4est's integer coordinates. docs/OCTREE.md describes the
// model, the coder and its figures; docs/FORMAT.md section 8 the `.amq` file.
//
// Conventions (p4est's, fixed here and nowhere else):
//   - corners of a tree in z-order: corner c sits at (c & 1, (c >> 1) & 1, (c >> 2) & 1);
//   - face f lies on axis f / 2, on its lower (f even) or upper (f odd) side;
//   - the corners of a face are the tree corners on it, in increasing order ("face corners");
//   - children of an octant in z-order: child c is offset by c's bits as a corner;
//   - an octant of level l has coordinates that are multiples of 2^(root_log2 - l), in
//     [0, 2^root_log2); root_log2 is 30 in 2D and 19 in 3D (P4EST_MAXLEVEL, P8EST_MAXLEVEL),
//     and levels go up to 29 and 18 (P4EST_QMAXLEVEL, P8EST_QMAXLEVEL).
//   - tree_to_face = neighbour face + 2 * dim * orientation; the orientation is the face corner of
//     the higher-numbered face of the two that touches face corner 0 of the lower one
//     (p8est_connectivity.h); a boundary face is glued to itself (same tree, same face).
// Balance: a forest is 2:1 balanced by faces when leaves that share (part of) a face differ by at
// most one level; equivalently every refined octant's face neighbours of its own level exist (the
// octree form of the paper's "1-regularity", which the coder uses to cull symbols).
#pragma once

#include <amc/field.h>
#include <amc/mesh.h>

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace amc {

constexpr int octree_root_log2(int dim) { return dim == 2 ? 30 : 19; }
constexpr int octree_max_level(int dim) { return dim == 2 ? 29 : 18; }
constexpr int octree_children(int dim) { return 1 << dim; }
constexpr int octree_faces(int dim) { return 2 * dim; }
constexpr int octree_orientations(int dim) { return dim == 2 ? 2 : 4; }

// The coarse mesh and how its trees touch (p4est_connectivity_t's fields of the same names).
struct TreeConnectivity {
    int dim = 2;
    std::vector<Vec3> vertices;            // may be empty (then the geometry is the unit tree)
    std::vector<uint32_t> tree_to_vertex;  // 2^dim per tree, z-order; empty iff vertices is
    std::vector<uint32_t> tree_to_tree;    // 2 * dim per tree
    std::vector<uint8_t> tree_to_face;     // 2 * dim per tree: face + 2 * dim * orientation

    uint32_t tree_count() const { return uint32_t(tree_to_tree.size() / (2 * dim)); }
};

// nx * ny (* nz) unit trees in lexicographic order (x fastest), vertices at integer positions,
// optionally periodic in each direction. (p4est's own brick orders its trees along a Morton curve.)
TreeConnectivity brick_connectivity(int dim, int nx, int ny, int nz = 1, bool periodic_x = false,
                                    bool periodic_y = false, bool periodic_z = false);
// Glues the trees whose faces share the same vertices (p4est_connectivity_complete's rule); the
// other faces are boundary. Throws Error on a face shared by more than two trees, repeated
// vertices in a tree or (3D) trees glued against their orientation (left-handed; in 2D trees may
// be of either hand, as on p4est's Moebius strip).
TreeConnectivity connectivity_from_vertices(int dim, std::vector<Vec3> vertices,
                                            std::vector<uint32_t> tree_to_vertex);
// Sizes, ranges, symmetry (the neighbour's neighbour is back where we started, with the inverse
// orientation), in range. Throws Error naming `what`.
void validate_connectivity(const TreeConnectivity& conn, const std::string& what);

// A leaf (p4est_quadrant_t's fields): coordinates in [0, 2^root_log2), multiples of the
// octant's length 2^(root_log2 - level); z is 0 in 2D.
struct Octant {
    int32_t x = 0, y = 0, z = 0;
    int8_t level = 0;
};
inline bool operator==(const Octant& a, const Octant& b) {
    return a.x == b.x && a.y == b.y && a.z == b.z && a.level == b.level;
}

struct OctreeForest {
    TreeConnectivity connectivity;
    std::vector<uint64_t> tree_offsets;  // tree_count + 1: leaves of tree t are [offsets[t], offsets[t+1])
    std::vector<Octant> leaves;          // per tree, in Morton order
    // Per-leaf data (solution values, labels): cell fields, one tuple per leaf in `leaves` order,
    // written to VTU as cell data and to p4est files as the quadrants' user data. Names are
    // unique, 1 to 1024 bytes; 1 to 1024 components; coded bit-exact.
    std::vector<Field> leaf_data;

    uint32_t tree_count() const { return connectivity.tree_count(); }
    int dim() const { return connectivity.dim; }
};
bool operator==(const OctreeForest& a, const OctreeForest& b);

// Every tree's leaves tile it exactly, in Morton order, at levels 0 .. octree_max_level, the
// connectivity is valid and every leaf field has one tuple per leaf. Throws Error naming `what`
// and the first bad leaf or field.
void validate_octree_forest(const OctreeForest& forest, const std::string& what);

// Which leaves must be within one level of each other: those sharing a face, or also an edge
// (3D), or also a corner (p4est's P4EST_CONNECT_FACE / P8EST_CONNECT_EDGE / _CORNER). Across the
// coarse mesh, edge and corner neighbours are every tree around the coarse vertex or edge (trees
// that share its vertices: any number, face neighbours or not, as p4est's corner and edge
// connectivity), and those reached by crossing faces one after the other (periodic gluing, and
// connectivities without vertices).
enum class OctreeBalance : uint8_t { face = 1, edge = 2, corner = 3 };

// The smallest refinement of `forest` that is balanced (p4est_balance).
OctreeForest balance_octree_forest(const OctreeForest& forest, OctreeBalance balance);
// "" when balanced, else the first violation in words (tree, octant, neighbour).
std::string octree_balance_violation(const OctreeForest& forest, OctreeBalance balance);

// ---- forests for tests and benchmarks --------------------------------------------------------
// Each maker throws Error(limit_exceeded) naming the count once its forest would have more than
// `max_leaves` leaves (a 3D sphere at level 18 would hold about 10^11: asked of `amc octree make`).
constexpr uint64_t kNoLeafLimit = ~uint64_t{0};
OctreeForest uniform_octree_forest(const TreeConnectivity& conn, int level, uint64_t max_leaves = kNoLeafLimit);
// Refines leaves (recursively, children too) while refine(tree, octant) says so, up to max_level.
OctreeForest refine_octree_forest(const OctreeForest& forest,
                                  const std::function<bool(uint32_t tree, const Octant&)>& refine,
                                  int max_level, uint64_t max_leaves = kNoLeafLimit);
// The point of a tree at reference coordinates u, v, w in [0, 1]: multilinear in its corner
// vertices (the unit cube at the origin when the connectivity has no vertices).
Vec3 tree_point(const TreeConnectivity& conn, uint32_t tree, double u, double v, double w);
// Refined where the octant's box meets the sphere |p - center| = radius (the circle in 2D), up
// to max_level: the classic test of p4est's examples. Not balanced.
OctreeForest sphere_octree_forest(const TreeConnectivity& conn, Vec3 center, double radius, int max_level,
                                  uint64_t max_leaves = kNoLeafLimit);
// A moving front: the curve / surface x + 0.3 sin(4 y) (+ 0.2 cos(3 z)) = t, refined up to
// max_level in a band of about two leaves around it, and graded away from it. Not balanced.
OctreeForest front_octree_forest(const TreeConnectivity& conn, double t, int max_level,
                                 uint64_t max_leaves = kNoLeafLimit);
// Random refinement: uniform down to min_level, then leaves split with probability `p` per level
// until max_level. Not balanced.
OctreeForest random_octree_forest(const TreeConnectivity& conn, uint64_t seed, double p, int min_level, int max_level,
                                  uint64_t max_leaves = kNoLeafLimit);

// Levels and counts.
struct OctreeForestCounts {
    uint64_t leaves = 0, nodes = 0;  // nodes: every octant of every tree, leaves included
    int depth = 0;                   // finest leaf level
};
OctreeForestCounts count_octree_forest(const OctreeForest& forest);

// ---- the coder (docs/OCTREE.md, docs/FORMAT.md section 8) ------------------------------------
struct OctreeEncodeOptions {
    bool cull_by_balance = true;   // skip octants balance forbids to refine; refuses unbalanced forests
    bool uniform_levels = true;    // levels where every octant is refined cost nothing
    bool truncate = true;          // trailing zeros are dropped (a count is stored)
    bool context_groups = true;    // contexts from the face neighbours' states (else one model)
    bool improved_traversal = true;  // priority traversal (else Morton order)
    // Coarse-mesh vertex positions: 0 stores them bit-exact (float64); > 0 snaps every coordinate
    // to the nearest multiple of this step (error at most step / 2), coded as grid differences.
    double vertex_step = 0;
};

struct OctreeEncodeStats {
    uint64_t nodes = 0, leaves = 0;
    uint64_t uniform = 0, culled = 0, truncated = 0, coded = 0;  // nodes by fate
    uint64_t connectivity_bytes = 0, level_bytes = 0, leaf_data_bytes = 0, file_bytes = 0;
};

// The .amq file: version 1 when the forest has no leaf data and the vertices are stored
// bit-exact, else version 2 (docs/FORMAT.md section 8). Throws Error on an invalid forest
// (validate_octree_forest), with cull_by_balance on a forest not balanced by faces, and on a
// vertex_step that is not finite and positive or too small for the positions (grid indices
// beyond 2^52).
std::vector<uint8_t> encode_octree_forest(const OctreeForest& forest, const OctreeEncodeOptions& options = {},
                                          OctreeEncodeStats* stats = nullptr);

// Octants a file may announce per byte after its metadata block (docs/FORMAT.md 8.5, Bounds):
// uniform levels, truncated zeros and bricks cost no bits, so the writer pads a forest that would
// hold more, and a reader refuses more before it allocates anything for the forest.
constexpr uint64_t kOctreeOctantsPerByte = 4096;

struct OctreeDecodeOptions {
    int max_level = -1;              // >= 0: progressive, only levels 0 .. max_level
    uint64_t max_nodes = uint64_t{1} << 26;  // refuse files announcing more octants (about 50 bytes each)
    uint64_t max_leaf_values = uint64_t{1} << 28;  // refuse leaf fields of more values (8 bytes each)
    // Refuse files announcing more octants per byte after their metadata block; 0: no bound (files
    // written before the bound, whose uniform forests of millions of octants may take a few bytes).
    uint64_t max_octants_per_byte = kOctreeOctantsPerByte;
};
// Throws Error (truncated, checksum, corrupt, limit_exceeded, ...) on anything but a file
// encode_octree_forest writes. Progressive decoding (max_level) leaves out the leaf data.
OctreeForest decode_octree_forest(const uint8_t* data, size_t size, const OctreeDecodeOptions& options = {});
// Throws as decode_octree_forest does on a file's first bytes (its 12-byte header; all of a
// shorter file), with the same errors: a reader of a stream refuses what is no .amq file at once.
void check_octree_file_start(const uint8_t* data, size_t size);

// ---- p4est (optional: cmake -DAMC_WITH_P4EST=ON with Debian's libp4est-dev) -------------------
// Without it every function below but octree_p4est_available throws Error.
bool octree_p4est_available();
// A p4est_save file (2D or 3D, told by its first bytes) through p4est_load_ext, and p4est's
// checksum of it. p4est aborts the process on a malformed file: read only files you trust.
// A file saved with data (data_size > 0 bytes per quadrant) gives leaf fields: as `data_layout`
// says (name, type and components of each field, packed in this order, little-endian, their
// sizes adding up to data_size; values ignored), or without a layout one UInt8 field
// "p4est_data" of data_size components. Throws Error when the layout does not fit the file.
OctreeForest read_p4est_file(const std::string& path, uint32_t* checksum = nullptr,
                             const std::vector<Field>& data_layout = {});
// The forest built in p4est (refined from the roots), saved with p4est_save_ext (no
// partition); leaf fields, packed in their order as above, become the quadrants' user data
// (saved with data_size = the bytes of one tuple of each field).
void write_p4est_file(const std::string& path, const OctreeForest& forest);
// The bytes per leaf of the forest's leaf data as p4est user data (0 without leaf data).
size_t octree_leaf_data_bytes(const std::vector<Field>& leaf_data);
// p4est_checksum of the forest built in p4est.
uint32_t octree_p4est_checksum(const OctreeForest& forest);
// A forest made by p4est itself: refined (p4est_refine) where quadrants meet the sphere (circle),
// up to max_level, balanced by p4est_balance, saved with p4est_save_ext. For tests and benchmarks.
void write_p4est_sphere_forest(const std::string& path, const TreeConnectivity& conn, Vec3 center, double radius, int max_level,
                               OctreeBalance balance);
// The smallest balanced refinement as p4est_balance makes it (with p4est's corner and edge
// connectivity completed from the vertices when they glue the trees).
OctreeForest balanced_by_p4est(const OctreeForest& forest, OctreeBalance balance);
// p4est_is_balanced on the forest built in p4est.
bool is_balanced_in_p4est(const OctreeForest& forest, OctreeBalance balance);
// One of p4est's catalogue of connectivities (p4est_connectivity_new_byname): 2D brick23, corner,
// cubed, disk, moebius, periodic, pillow, rotwrap, star, unit; 3D brick235, periodic, rotcubes,
// rotwrap, shell, sphere, twocubes, twowrap, unit.
TreeConnectivity p4est_builtin_connectivity(int dim, const std::string& name);
// The same around front_octree_forest's moving front at time t.
void write_p4est_front_forest(const std::string& path, const TreeConnectivity& conn, double t, int max_level, OctreeBalance balance);

}  // namespace amc
