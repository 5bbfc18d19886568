// Conversion between OctreeForest and p4est's forests and files, compiled twice: for quadtrees
// (p4est_forest_2d.cpp) and, with p4est_to_p8est.h renaming p4est_* to p8est_*, for octrees
// (p4est_forest_3d.cpp). AMC_P4EST_NAME(x) names this dimension's functions.
#include "common/check.h"
#include "octree/p4est_forest.h"

#include <algorithm>
#include <chrono>
#include <cmath>
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

p4est_t* to_forest(const OctreeForest& forest, p4est_connectivity_t* c) {
    Target target{&forest, {}};
    for (const Octant& o : forest.leaves) target.keys.push_back(morton_key(o.x, o.y, o.z));
    p4est_t* p4est = p4est_new_ext(sc_MPI_COMM_WORLD, c, 0, 0, 1, 0, nullptr, &target);
    p4est_refine_ext(p4est, 1, P4EST_QMAXLEVEL, refine_towards, nullptr, nullptr);
    p4est->user_pointer = nullptr;
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

}  // namespace

void AMC_P4EST_NAME(write_p4est_sphere_forest)(const std::string& path, const TreeConnectivity& conn, Vec3 center, double radius,
                                               int max_level, OctreeBalance balance) {
    ensure_p4est_initialized();
    p4est_connectivity_t* c = to_connectivity(conn);
    Sphere sphere{center, radius};
    p4est_t* p4est = p4est_new_ext(sc_MPI_COMM_WORLD, c, 0, 0, 1, 0, nullptr, &sphere);
    p4est_refine_ext(p4est, 1, max_level, refine_at_sphere, nullptr, nullptr);
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

void AMC_P4EST_NAME(write_p4est_file)(const std::string& path, const OctreeForest& forest) {
    ensure_p4est_initialized();
    p4est_connectivity_t* c = to_connectivity(forest.connectivity);
    p4est_t* p4est = to_forest(forest, c);
    p4est_save_ext(path.c_str(), p4est, 0, 0);
    p4est_destroy(p4est);
    p4est_connectivity_destroy(c);
}

OctreeForest AMC_P4EST_NAME(read_p4est_file)(const std::string& path, uint32_t* checksum) {
    ensure_p4est_initialized();
    p4est_connectivity_t* c = nullptr;
    p4est_t* p4est = p4est_load_ext(path.c_str(), sc_MPI_COMM_WORLD, 0, 0, 1, 0, nullptr, &c);
    OctreeForest forest = from_forest(p4est);
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
