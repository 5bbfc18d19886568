// Base meshes of several topologies and the random hierarchies over them that the tests share,
// without GoogleTest, so that a bench program can make the same hierarchies (bench/angle_labels).
#pragma once

#include <amc/hierarchy.h>
#include <amc/refinement.h>

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace amc::testing {

// A tiny generator whose output is the same on every platform (std distributions are not).
struct Random {
    uint64_t state;
    uint64_t next() {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        return state >> 33;
    }
};

// The same triangles with every corner its own vertex: the same surface without a vertex of high
// valence (ClosestPointQuery keeps no fan for it).
inline TriangleMesh without_shared_vertices(const TriangleMesh& mesh) {
    TriangleMesh apart;
    for (const Triangle& t : mesh.triangles) {
        const uint32_t base = static_cast<uint32_t>(apart.positions.size());
        for (uint32_t v : t) apart.positions.push_back(mesh.positions[v]);
        apart.triangles.push_back({base, base + 1, base + 2});
    }
    return apart;
}

struct NamedMesh {
    std::string name;
    TriangleMesh mesh;
};

// Closed genus 0, closed genus 1, open (one boundary loop), non-convex open domain.
inline std::vector<NamedMesh> fixture_meshes() {
    return {{"icosahedron", make_icosahedron()},
            {"torus", make_torus(6, 5, 2.0, 0.7)},
            {"square", make_square(3)},
            {"l_shape", make_l_shape(1)}};
}

// refine_randomly over `base` (coarsening a fifth of the time), float32 coordinates when `single`,
// and with `flips` each node's diagonal flipped at random.
inline Hierarchy random_hierarchy(TriangleMesh base, uint32_t leaves, int max_level, uint64_t seed, bool flips, bool single) {
    base.single_precision = single;
    if (single) {
        for (Vec3& p : base.positions) p = {double(float(p.x)), double(float(p.y)), double(float(p.z))};
    }
    Hierarchy h(std::move(base));
    refine_randomly(h, leaves, max_level, seed, 0.2);
    if (flips) {
        Random random{seed * 7 + 1};
        for (NodeId n = 0; n < h.node_capacity(); ++n) {
            if (h.is_alive(n) && random.next() % 2) h.set_diagonal_flipped(n, true);
        }
    }
    return h;
}

// Seed `seed` of the import tests' random hierarchies: every fixture topology, float and double,
// both diagonals, 20 to 2,019 leaves, depth 1 to 7.
inline Hierarchy varied_random_hierarchy(uint64_t seed) {
    const std::vector<NamedMesh> fixtures = fixture_meshes();
    Random random{seed * 13 + 5};
    const uint32_t leaves = 20 + uint32_t(random.next() % 2000);
    const int max_level = 1 + int(random.next() % 7);
    return random_hierarchy(fixtures[seed % fixtures.size()].mesh, leaves, max_level, seed, seed % 2 == 0, seed % 3 == 0);
}

}  // namespace amc::testing
