// Shared fixtures and checks of the hierarchy tests: base meshes of several topologies and the
// full set of invariants every hierarchy must satisfy.
#pragma once

#include "random_hierarchies.h"

#include <amc/hierarchy.h>
#include <amc/refinement.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>
#include <utility>
#include <vector>

namespace amc::testing {

// A random refinement of the icosahedron with every vertex projected onto the unit sphere (new
// vertices off their edge's midpoint along the normal, as in a surface remesh).
inline Hierarchy projected_sphere(uint32_t target_leaves, int max_level, uint64_t seed) {
    Hierarchy h(make_icosahedron());
    refine_randomly(h, target_leaves, max_level, seed);
    for (VertexId v = 0; v < h.positions().size(); ++v) {
        const Vec3 p = h.position(v);
        h.set_position(v, (1.0 / std::sqrt(p.x * p.x + p.y * p.y + p.z * p.z)) * p);
    }
    return h;
}

// A curvature-adaptive remesh of the bumpy sphere over 200 base triangles, up to level 5, until
// target_faces leaf triangles (new vertices on the surface, off their edges' midpoints).
inline Hierarchy curved_sphere_remesh(uint32_t target_faces) {
    SurfaceRemeshOptions remesh;
    remesh.base_triangles = 200;
    remesh.max_level = 5;
    remesh.target_faces = target_faces;
    return remesh_adaptively(make_bumpy_sphere(4), remesh);
}

// A torus refined at random, every vertex moved off its place by smooth bumps (new vertices off
// their midpoints, every coordinate bit in use), optionally rounded to float32.
inline Hierarchy bumpy_torus(bool single_precision, uint32_t target_leaves = 600, int max_level = 4) {
    Hierarchy h(make_torus(8, 6, 2.0, 0.7));
    refine_randomly(h, target_leaves, max_level, 3);
    for (VertexId v = 0; v < h.positions().size(); ++v) {
        const Vec3 p = h.position(v);
        Vec3 q{p.x * (1 + 0.01 * std::sin(7 * p.y)), p.y * (1 + 0.01 * std::cos(5 * p.z)), p.z + 0.003 * std::sin(3 * p.x)};
        if (single_precision) q = {double(float(q.x)), double(float(q.y)), double(float(q.z))};
        h.set_position(v, q);
    }
    h.set_single_precision(single_precision);
    return h;
}

// The mesh with its vertices renumbered, its triangles reordered and each rotated, at random
// (positions unchanged); new_index, if given, receives the new number of every old vertex.
inline TriangleMesh shuffled(const TriangleMesh& mesh, uint64_t seed, std::vector<uint32_t>* new_index = nullptr) {
    Random random{seed};
    std::vector<uint32_t> order(mesh.positions.size());
    std::iota(order.begin(), order.end(), 0u);
    for (size_t i = order.size(); i > 1; --i) std::swap(order[i - 1], order[random.next() % i]);
    TriangleMesh out;
    out.single_precision = mesh.single_precision;
    out.positions.resize(mesh.positions.size());
    for (size_t v = 0; v < order.size(); ++v) out.positions[order[v]] = mesh.positions[v];
    out.triangles = mesh.triangles;
    for (size_t i = out.triangles.size(); i > 1; --i) std::swap(out.triangles[i - 1], out.triangles[random.next() % i]);
    for (Triangle& t : out.triangles) {
        const size_t r = size_t(random.next() % 3);
        t = {order[t[r]], order[t[(r + 1) % 3]], order[t[(r + 2) % 3]]};
    }
    if (new_index != nullptr) *new_index = order;
    return out;
}

inline int64_t euler_characteristic(const TriangleMesh& mesh) {
    std::vector<std::pair<uint32_t, uint32_t>> edges;
    for (const Triangle& t : mesh.triangles) {
        for (int e = 0; e < 3; ++e) edges.push_back(std::minmax(t[e], t[(e + 1) % 3]));
    }
    std::sort(edges.begin(), edges.end());
    const int64_t unique_edges = std::unique(edges.begin(), edges.end()) - edges.begin();
    return int64_t(mesh.positions.size()) - unique_edges + int64_t(mesh.triangles.size());
}

// Every invariant of the issue: structure (check_invariants: balance, closure, links, shared
// midpoints, vertex count = base vertices + split edges), a conforming edge-manifold leaf mesh
// with the base mesh's Euler characteristic, and leaf count consistency.
inline ::testing::AssertionResult hierarchy_is_valid(const Hierarchy& h) {
    const std::string problem = check_invariants(h);
    if (!problem.empty()) return ::testing::AssertionFailure() << problem;
    const LeafMesh leaf = extract_leaf_mesh(h);
    try {
        validate_triangle_mesh(leaf.mesh, "leaf mesh");
    } catch (const Error& e) {
        return ::testing::AssertionFailure() << e.what();
    }
    if (euler_characteristic(leaf.mesh) != euler_characteristic(h.base()))
        return ::testing::AssertionFailure() << "Euler characteristic changed";
    if (leaf.mesh.positions.size() != h.vertex_count())
        return ::testing::AssertionFailure() << "leaf mesh does not use every vertex";
    const HierarchyStats stats = compute_stats(h);
    if (stats.faces != leaf.mesh.triangles.size() || stats.leaves != h.leaf_count())
        return ::testing::AssertionFailure() << "face or leaf counts disagree";
    return ::testing::AssertionSuccess();
}

}  // namespace amc::testing
