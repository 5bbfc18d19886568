// Forests for the octree tests: random connectivities (bricks whose trees are turned at random,
// periodic bricks) and random balanced forests over them.
#pragma once

#include <amc/octree.h>

#include <cstdint>
#include <random>

namespace amc::octree_test {

// Turns tree corners by a random rotation of the square / cube (an orientation-preserving
// symmetry: axes permuted and flipped with determinant +1), so that faces meet with every
// orientation p4est knows.
inline TreeConnectivity turned_brick(int dim, int nx, int ny, int nz, std::mt19937_64& rng) {
    TreeConnectivity brick = brick_connectivity(dim, nx, ny, nz);
    const int corners = 1 << dim;
    std::vector<uint32_t> t2v = brick.tree_to_vertex;
    for (uint32_t t = 0; t < brick.tree_count(); ++t) {
        int perm[3] = {0, 1, 2}, flips = 0;
        for (;;) {
            std::shuffle(perm, perm + dim, rng);
            flips = int(rng() % (1u << dim));
            // Determinant: sign of the permutation times (-1)^flips.
            int inversions = 0;
            for (int i = 0; i < dim; ++i)
                for (int j = i + 1; j < dim; ++j) inversions += perm[i] > perm[j];
            const int flipped = __builtin_popcount(unsigned(flips));
            if ((inversions + flipped) % 2 == 0) break;
        }
        // New corner c sits where old corner g(c) was: bit a of g(c) is bit perm[a] of c, xor flips.
        for (int c = 0; c < corners; ++c) {
            int old = 0;
            for (int a = 0; a < dim; ++a) old |= (((c >> perm[a]) & 1) ^ ((flips >> a) & 1)) << a;
            t2v[size_t(t) * corners + c] = brick.tree_to_vertex[size_t(t) * corners + old];
        }
    }
    return connectivity_from_vertices(dim, brick.vertices, t2v);
}

inline TreeConnectivity random_connectivity(int dim, std::mt19937_64& rng) {
    const int nx = 1 + int(rng() % 3), ny = 1 + int(rng() % 3), nz = dim == 3 ? 1 + int(rng() % 2) : 1;
    switch (rng() % 3) {
        case 0: return brick_connectivity(dim, nx, ny, nz);
        case 1: return brick_connectivity(dim, nx, ny, nz, rng() % 2, rng() % 2, rng() % 2);
        default: return turned_brick(dim, nx, ny, nz, rng);
    }
}

inline OctreeForest random_balanced_forest(int dim, std::mt19937_64& rng, OctreeBalance balance = OctreeBalance::face) {
    const TreeConnectivity conn = random_connectivity(dim, rng);
    const int max_level = dim == 2 ? 2 + int(rng() % 5) : 1 + int(rng() % 3);
    const double p = 0.2 + 0.5 * double(rng() % 100) / 100;
    return balance_octree_forest(random_octree_forest(conn, rng(), p, 1, max_level), balance);
}

}  // namespace amc::octree_test
