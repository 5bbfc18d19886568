// Conversion between OctreeForest and p4est's forests and files, compiled twice: for quadtrees
// (p4est_forest_2d.cpp) and, with p4est_to_p8est.h renaming p4est_* to p8est_*, for octrees
// (p4est_forest_3d.cpp). AMC_P4EST_NAME(x) names this dimension's functions.
#include "common/check.h"
#include "octree/octree_leaf_data.h"
#include "octree/p4est_forest.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <vector>

namespace amc {
namespace {

constexpr int kDim = AMC_P4EST_DIM;

uint64_t morton_key(int32_t x, int32_t y, int32_t z) {
    uint64_t key = 0;
    for (int b = P4EST_MAXLEVEL - 1; b >= 0; --b) {
        if (kDim == 3) key = (key << 1) | ((uint32_t(z) >> b) & 1);
        key = (key << 1) | ((uint32_t(y) >> b) & 1);
        key = (key << 1) | ((uint32_t(x) >> b) & 1);
    }
    return key;
}

p4est_connectivity_t* to_connectivity(const TreeConnectivity& conn) {
    const int faces = 2 * kDim, corners = 1 << kDim;
    p4est_connectivity_t* c = p4est_connectivity_new(p4est_topidx_t(conn.vertices.size()), p4est_topidx_t(conn.tree_count()),
#if AMC_P4EST_DIM == 3
                                                     0, 0,
#endif
                                                     0, 0);
    for (size_t v = 0; v < conn.vertices.size(); ++v) {
        c->vertices[3 * v] = conn.vertices[v].x;
        c->vertices[3 * v + 1] = conn.vertices[v].y;
        c->vertices[3 * v + 2] = conn.vertices[v].z;
    }
    if (!conn.vertices.empty())
        for (size_t i = 0; i < size_t(conn.tree_count()) * corners; ++i) c->tree_to_vertex[i] = p4est_topidx_t(conn.tree_to_vertex[i]);
    for (size_t i = 0; i < size_t(conn.tree_count()) * faces; ++i) {
        c->tree_to_tree[i] = p4est_topidx_t(conn.tree_to_tree[i]);
        c->tree_to_face[i] = int8_t(conn.tree_to_face[i]);
    }
    if (!p4est_connectivity_is_valid(c)) {
        p4est_connectivity_destroy(c);
        throw_error(ErrorCode::invalid_input, "p4est refuses the connectivity (p4est_connectivity_is_valid)");
    }
    // p4est's corner (and edge) connectivity, which its edge and corner balance use, from the
    // vertices, when they say all there is (no periodic gluing, which completing would lose).
    if (!conn.vertices.empty()) {
        bool glued_by_vertices = false;
        try {
            const TreeConnectivity glued = connectivity_from_vertices(kDim, conn.vertices, conn.tree_to_vertex);
            glued_by_vertices = glued.tree_to_tree == conn.tree_to_tree && glued.tree_to_face == conn.tree_to_face;
        } catch (const Error&) {
        }
        if (glued_by_vertices) p4est_connectivity_complete(c);
    }
    return c;
}

TreeConnectivity from_connectivity(const p4est_connectivity_t* c) {
    const int faces = 2 * kDim, corners = 1 << kDim;
    TreeConnectivity conn;
    conn.dim = kDim;
    if (c->num_vertices > 0 && c->tree_to_vertex) {
        for (p4est_topidx_t v = 0; v < c->num_vertices; ++v)
            conn.vertices.push_back({c->vertices[3 * v], c->vertices[3 * v + 1], c->vertices[3 * v + 2]});
        for (size_t i = 0; i < size_t(c->num_trees) * corners; ++i) conn.tree_to_vertex.push_back(uint32_t(c->tree_to_vertex[i]));
    }
    for (size_t i = 0; i < size_t(c->num_trees) * faces; ++i) {
        conn.tree_to_tree.push_back(uint32_t(c->tree_to_tree[i]));
        conn.tree_to_face.push_back(uint8_t(c->tree_to_face[i]));
    }
    return conn;
}

// The quadrants' user data, leaf after leaf (data_size bytes each).
std::vector<uint8_t> user_data_of(p4est_t* p4est) {
    std::vector<uint8_t> out;
    for (p4est_topidx_t t = p4est->first_local_tree; t <= p4est->last_local_tree; ++t) {
        const p4est_tree_t* tree = p4est_tree_array_index(p4est->trees, t);
        for (size_t i = 0; i < tree->quadrants.elem_count; ++i) {
            const p4est_quadrant_t* q = p4est_quadrant_array_index(const_cast<sc_array_t*>(&tree->quadrants), i);
            const uint8_t* data = static_cast<const uint8_t*>(q->p.user_data);
            out.insert(out.end(), data, data + p4est->data_size);
        }
    }
    return out;
}

void set_user_data(p4est_t* p4est, const std::vector<uint8_t>& bytes) {
    size_t leaf = 0;
    for (p4est_topidx_t t = p4est->first_local_tree; t <= p4est->last_local_tree; ++t) {
        p4est_tree_t* tree = p4est_tree_array_index(p4est->trees, t);
        for (size_t i = 0; i < tree->quadrants.elem_count; ++i, ++leaf) {
            p4est_quadrant_t* q = p4est_quadrant_array_index(&tree->quadrants, i);
            std::memcpy(q->p.user_data, bytes.data() + leaf * p4est->data_size, p4est->data_size);
        }
    }
}

// The data size a p4est_save file was written with: the header after the connectivity starts
// with the u64 words P4EST_ONDISK_FORMAT, sizeof (p4est_qcoord_t), sizeof (p4est_quadrant_t),
// data_size (p4est_save_ext in p4est.c).
size_t saved_data_size(const std::string& path) {
    std::FILE* f = std::fopen(path.c_str(), "rb");
    AMC_REQUIRE(f, io, path + ": can not open");
    std::vector<uint8_t> bytes;
    uint8_t buffer[65536];
    for (size_t got; (got = std::fread(buffer, 1, sizeof buffer, f)) > 0;) bytes.insert(bytes.end(), buffer, buffer + got);
    std::fclose(f);
    const uint64_t header[3] = {uint64_t(P4EST_ONDISK_FORMAT), sizeof(p4est_qcoord_t), sizeof(p4est_quadrant_t)};
    for (size_t at = 0; at + 4 * 8 <= bytes.size(); at += 4) {  // the header is aligned
        if (std::memcmp(bytes.data() + at, header, sizeof header) != 0) continue;
        uint64_t size;
        std::memcpy(&size, bytes.data() + at + sizeof header, 8);
        AMC_REQUIRE(size < (uint64_t{1} << 20), corrupt, path + ": a p4est data size of " + std::to_string(size) + " bytes");
        return size_t(size);
    }
    throw_error(ErrorCode::corrupt, path + ": no p4est_save header found");
}

OctreeForest from_forest(p4est_t* p4est) {
    OctreeForest forest;
    forest.connectivity = from_connectivity(p4est->connectivity);
    forest.tree_offsets.push_back(0);
    for (p4est_topidx_t t = p4est->first_local_tree; t <= p4est->last_local_tree; ++t) {
        const p4est_tree_t* tree = p4est_tree_array_index(p4est->trees, t);
        for (size_t i = 0; i < tree->quadrants.elem_count; ++i) {
            const p4est_quadrant_t* q = p4est_quadrant_array_index(const_cast<sc_array_t*>(&tree->quadrants), i);
            Octant o;
            o.x = q->x;
            o.y = q->y;
#if AMC_P4EST_DIM == 3
            o.z = q->z;
#endif
            o.level = q->level;
            forest.leaves.push_back(o);
        }
        forest.tree_offsets.push_back(forest.leaves.size());
    }
    return forest;
}

// p4est refines towards this forest: a quadrant is split while a finer leaf starts inside it.
struct Target {
    const OctreeForest* forest;
    std::vector<uint64_t> keys;
};

int refine_towards(p4est_t* p4est, p4est_topidx_t tree, p4est_quadrant_t* q) {
    const Target& target = *static_cast<const Target*>(p4est->user_pointer);
    const OctreeForest& f = *target.forest;
#if AMC_P4EST_DIM == 3
    const uint64_t key = morton_key(q->x, q->y, q->z);
#else
    const uint64_t key = morton_key(q->x, q->y, 0);
#endif
    const auto begin = target.keys.begin() + f.tree_offsets[tree], end = target.keys.begin() + f.tree_offsets[tree + 1];
    const auto it = std::upper_bound(begin, end, key);  // the leaf covering the quadrant's first corner
    return it != begin && f.leaves[size_t(it - target.keys.begin()) - 1].level > q->level;
}

// The forest in p4est, its leaf fields as the quadrants' user data.
p4est_t* to_forest(const OctreeForest& forest, p4est_connectivity_t* c) {
    Target target{&forest, {}};
    for (const Octant& o : forest.leaves) target.keys.push_back(morton_key(o.x, o.y, o.z));
    const size_t data_size = octree_leaf_data_bytes(forest.leaf_data);
    p4est_t* p4est = p4est_new_ext(sc_MPI_COMM_WORLD, c, 0, 0, 1, data_size, nullptr, &target);
    p4est_refine_ext(p4est, 1, P4EST_QMAXLEVEL, refine_towards, nullptr, nullptr);
    p4est->user_pointer = nullptr;
    if (data_size > 0) set_user_data(p4est, pack_leaf_data(forest.leaf_data, forest.leaves.size()));
    return p4est;
}

struct Sphere {
    Vec3 center;
    double radius;
};

// Refine where the quadrant's box meets the sphere, p4est's way: corners by p4est_qcoord_to_vertex.
int refine_at_sphere(p4est_t* p4est, p4est_topidx_t tree, p4est_quadrant_t* q) {
    const Sphere& s = *static_cast<const Sphere*>(p4est->user_pointer);
    const p4est_qcoord_t len = P4EST_QUADRANT_LEN(q->level);
    double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
    for (int c = 0; c < (1 << kDim); ++c) {
        double xyz[3];
        p4est_qcoord_to_vertex(p4est->connectivity, tree, q->x + ((c & 1) ? len : 0), q->y + ((c & 2) ? len : 0),
#if AMC_P4EST_DIM == 3
                               q->z + ((c & 4) ? len : 0),
#endif
                               xyz);
        for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], xyz[a]), hi[a] = std::max(hi[a], xyz[a]);
    }
    const double center[3] = {s.center.x, s.center.y, s.center.z};
    double near = 0, far = 0;
    for (int a = 0; a < 3; ++a) {
        const double n = std::max(lo[a], std::min(hi[a], center[a])) - center[a];
        const double f = std::max(std::abs(lo[a] - center[a]), std::abs(hi[a] - center[a]));
        near += n * n;
        far += f * f;
    }
    return near <= s.radius * s.radius && s.radius * s.radius <= far;
}


// The corners of a quadrant placed by p4est (p4est_qcoord_to_vertex).
int quadrant_corners(p4est_t* p4est, p4est_topidx_t tree, const p4est_quadrant_t* q, double xyz[8][3]) {
    const p4est_qcoord_t len = P4EST_QUADRANT_LEN(q->level);
    for (int c = 0; c < (1 << kDim); ++c)
        p4est_qcoord_to_vertex(p4est->connectivity, tree, q->x + ((c & 1) ? len : 0), q->y + ((c & 2) ? len : 0),
#if AMC_P4EST_DIM == 3
                               q->z + ((c & 4) ? len : 0),
#endif
                               xyz[c]);
    return 1 << kDim;
}

// front_octree_forest's rule, p4est's way: refine within a band of about two quadrants around
// x + 0.3 sin(4 y) + 0.2 cos(3 z) = t.
int refine_at_front(p4est_t* p4est, p4est_topidx_t tree, p4est_quadrant_t* q) {
    const double t = *static_cast<const double*>(p4est->user_pointer);
    double xyz[8][3];
    const int n = quadrant_corners(p4est, tree, q, xyz);
    double mid[3] = {0, 0, 0};
    for (int i = 0; i < n; ++i)
        for (int a = 0; a < 3; ++a) mid[a] += xyz[i][a] / n;
    double size = 0;
    for (int a = 0; a < 3; ++a) size += (xyz[n - 1][a] - xyz[0][a]) * (xyz[n - 1][a] - xyz[0][a]);
    const double phi = mid[0] + 0.3 * std::sin(4 * mid[1]) + 0.2 * std::cos(3 * mid[2]) - t;
    return std::abs(phi) < 1.2 * std::sqrt(size);
}

// p4est refines the roots with `refine` up to max_level, balances and saves.
void write_refined_by_p4est(const std::string& path, const TreeConnectivity& conn, p4est_refine_t refine, void* user, int max_level,
                            OctreeBalance balance) {
    ensure_p4est_initialized();
    p4est_connectivity_t* c = to_connectivity(conn);
    p4est_t* p4est = p4est_new_ext(sc_MPI_COMM_WORLD, c, 0, 0, 1, 0, nullptr, user);
    p4est_refine_ext(p4est, 1, max_level, refine, nullptr, nullptr);
#if AMC_P4EST_DIM == 3
    p4est_balance(p4est, balance == OctreeBalance::face ? P8EST_CONNECT_FACE : balance == OctreeBalance::edge ? P8EST_CONNECT_EDGE
                                                                                                           : P8EST_CONNECT_FULL,
                  nullptr);
#else
    p4est_balance(p4est, balance == OctreeBalance::face ? P4EST_CONNECT_FACE : P4EST_CONNECT_FULL, nullptr);
#endif
    p4est->user_pointer = nullptr;
    p4est_save_ext(path.c_str(), p4est, 0, 0);
    p4est_destroy(p4est);
    p4est_connectivity_destroy(c);
}

}  // namespace

void AMC_P4EST_NAME(write_p4est_sphere_forest)(const std::string& path, const TreeConnectivity& conn, Vec3 center, double radius,
                                               int max_level, OctreeBalance balance) {
    Sphere sphere{center, radius};
    write_refined_by_p4est(path, conn, refine_at_sphere, &sphere, max_level, balance);
}

void AMC_P4EST_NAME(write_p4est_front_forest)(const std::string& path, const TreeConnectivity& conn, double t, int max_level,
                                              OctreeBalance balance) {
    write_refined_by_p4est(path, conn, refine_at_front, &t, max_level, balance);
}

void AMC_P4EST_NAME(write_p4est_file)(const std::string& path, const OctreeForest& forest) {
    ensure_p4est_initialized();
    p4est_connectivity_t* c = to_connectivity(forest.connectivity);
    p4est_t* p4est = to_forest(forest, c);
    p4est_save_ext(path.c_str(), p4est, p4est->data_size > 0, 0);
    p4est_destroy(p4est);
    p4est_connectivity_destroy(c);
}

OctreeForest AMC_P4EST_NAME(read_p4est_file)(const std::string& path, uint32_t* checksum, const std::vector<Field>& data_layout) {
    ensure_p4est_initialized();
    const size_t data_size = saved_data_size(path);
    p4est_connectivity_t* c = nullptr;
    p4est_t* p4est = p4est_load_ext(path.c_str(), sc_MPI_COMM_WORLD, data_size, data_size > 0, 1, 0, nullptr, &c);
    OctreeForest forest = from_forest(p4est);
    if (data_size > 0) {
        try {
            forest.leaf_data = unpack_leaf_data(user_data_of(p4est).data(), forest.leaves.size(), data_size, data_layout, path);
        } catch (...) {
            p4est_destroy(p4est);
            p4est_connectivity_destroy(c);
            throw;
        }
    }
    if (checksum) *checksum = p4est_checksum(p4est);
    p4est_destroy(p4est);
    p4est_connectivity_destroy(c);
    return forest;
}

void AMC_P4EST_NAME(time_p4est_save_load)(const OctreeForest& forest, const std::string& path, double* save_seconds,
                                           double* load_seconds) {
    ensure_p4est_initialized();
    p4est_connectivity_t* c = to_connectivity(forest.connectivity);
    p4est_t* p4est = to_forest(forest, c);
    auto t0 = std::chrono::steady_clock::now();
    p4est_save_ext(path.c_str(), p4est, 0, 0);
    *save_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    p4est_destroy(p4est);
    p4est_connectivity_t* loaded_c = nullptr;
    t0 = std::chrono::steady_clock::now();
    p4est_t* loaded = p4est_load_ext(path.c_str(), sc_MPI_COMM_WORLD, 0, 0, 1, 0, nullptr, &loaded_c);
    *load_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    p4est_destroy(loaded);
    p4est_connectivity_destroy(loaded_c);
    p4est_connectivity_destroy(c);
}

OctreeForest AMC_P4EST_NAME(balanced_by_p4est)(const OctreeForest& forest, OctreeBalance balance) {
    ensure_p4est_initialized();
    p4est_connectivity_t* c = to_connectivity(forest.connectivity);
    p4est_t* p4est = to_forest(forest, c);
#if AMC_P4EST_DIM == 3
    p4est_balance(p4est, balance == OctreeBalance::face ? P8EST_CONNECT_FACE : balance == OctreeBalance::edge ? P8EST_CONNECT_EDGE
                                                                                                           : P8EST_CONNECT_FULL,
                  nullptr);
#else
    p4est_balance(p4est, balance == OctreeBalance::face ? P4EST_CONNECT_FACE : P4EST_CONNECT_FULL, nullptr);
#endif
    OctreeForest out = from_forest(p4est);
    out.connectivity = forest.connectivity;
    p4est_destroy(p4est);
    p4est_connectivity_destroy(c);
    return out;
}

bool AMC_P4EST_NAME(is_balanced_in_p4est)(const OctreeForest& forest, OctreeBalance balance) {
    ensure_p4est_initialized();
    p4est_connectivity_t* c = to_connectivity(forest.connectivity);
    p4est_t* p4est = to_forest(forest, c);
#if AMC_P4EST_DIM == 3
    const bool balanced = p4est_is_balanced(p4est, balance == OctreeBalance::face   ? P8EST_CONNECT_FACE
                                                   : balance == OctreeBalance::edge ? P8EST_CONNECT_EDGE
                                                                                    : P8EST_CONNECT_FULL);
#else
    const bool balanced = p4est_is_balanced(p4est, balance == OctreeBalance::face ? P4EST_CONNECT_FACE : P4EST_CONNECT_FULL);
#endif
    p4est_destroy(p4est);
    p4est_connectivity_destroy(c);
    return balanced;
}

TreeConnectivity AMC_P4EST_NAME(p4est_builtin_connectivity)(const std::string& name) {
    ensure_p4est_initialized();
    p4est_connectivity_t* c = p4est_connectivity_new_byname(name.c_str());
    AMC_REQUIRE(c != nullptr, invalid_input, "p4est has no connectivity named \"" + name + "\"");
    TreeConnectivity conn = from_connectivity(c);
    p4est_connectivity_destroy(c);
    return conn;
}

uint32_t AMC_P4EST_NAME(p4est_checksum_of)(const OctreeForest& forest) {
    ensure_p4est_initialized();
    p4est_connectivity_t* c = to_connectivity(forest.connectivity);
    p4est_t* p4est = to_forest(forest, c);
    const uint32_t sum = p4est_checksum(p4est);
    p4est_destroy(p4est);
    p4est_connectivity_destroy(c);
    return sum;
}

}  // namespace amc
