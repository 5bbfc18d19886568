// A hierarchy's leaf mesh as a user holds it (import_bench, import_corpus): vertices and faces
// shuffled, faces rotated, every non-base vertex moved off its position.
#pragma once

#include <amc/mesh.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <vector>

namespace bench {

// A tiny generator whose output is the same on every platform.
struct Random {
    uint64_t state;
    uint64_t next() {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        return state >> 33;
    }
};

// Vertices renumbered and faces reordered and rotated at random; every vertex from
// `base_vertices` on moved by up to `move` times the length of its shortest edge in each
// coordinate. user_of_leaf (if given) receives the new number of each vertex.
inline amc::TriangleMesh user_leaf_mesh(const amc::TriangleMesh& leaf, uint32_t base_vertices, double move, uint64_t seed,
                                        std::vector<uint32_t>* user_of_leaf = nullptr) {
    Random random{seed};
    const uint32_t n = uint32_t(leaf.positions.size());
    std::vector<uint32_t> order(n);
    std::iota(order.begin(), order.end(), 0u);
    for (uint32_t i = n; i > 1; --i) std::swap(order[i - 1], order[random.next() % i]);
    std::vector<double> shortest(n, 1e300);
    for (const amc::Triangle& t : leaf.triangles) {
        for (int e = 0; e < 3; ++e) {
            const amc::Vec3 d = leaf.positions[t[e]] - leaf.positions[t[(e + 1) % 3]];
            const double length = std::sqrt(amc::dot(d, d));
            shortest[t[e]] = std::min(shortest[t[e]], length);
            shortest[t[(e + 1) % 3]] = std::min(shortest[t[(e + 1) % 3]], length);
        }
    }
    auto unit = [&] { return double(random.next() % 2000001) / 1000000.0 - 1.0; };
    amc::TriangleMesh out;
    out.single_precision = leaf.single_precision;
    out.positions.resize(n);
    for (uint32_t v = 0; v < n; ++v) {
        amc::Vec3 p = leaf.positions[v];
        if (v >= base_vertices && move > 0) p = p + (move * shortest[v]) * amc::Vec3{unit(), unit(), unit()};
        if (out.single_precision) p = {double(float(p.x)), double(float(p.y)), double(float(p.z))};
        out.positions[order[v]] = p;
    }
    out.triangles = leaf.triangles;
    for (size_t i = out.triangles.size(); i > 1; --i) std::swap(out.triangles[i - 1], out.triangles[random.next() % i]);
    for (amc::Triangle& t : out.triangles) {
        const int r = int(random.next() % 3);
        t = {order[t[r]], order[t[(r + 1) % 3]], order[t[(r + 2) % 3]]};
    }
    if (user_of_leaf) *user_of_leaf = order;
    return out;
}

}  // namespace bench
