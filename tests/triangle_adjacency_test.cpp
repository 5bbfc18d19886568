// The half-edge adjacency of base detection (src/import/triangle_adjacency.h) against a brute-force
// edge map: twins, stars, boundary and edges, on fans small enough to be scanned and large enough
// to be sorted, with vertex ids drawn from a larger range and the triangles in random order.
#include "import/triangle_adjacency.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <map>
#include <set>
#include <utility>
#include <vector>

namespace {

using amc::Triangle;
using amc::detail::kNoHalfEdge;
using amc::detail::TriangleAdjacency;

// A disc: `around` triangles around vertex 3 (ids spread over 0..3 * around + 10), closed or open
// (the last triangle left out), then a strip of triangles outside its rim.
std::vector<Triangle> disc(uint32_t around, bool closed, uint64_t seed) {
    auto rim = [&](uint32_t k) { return 10 + 3 * (k % around); };
    std::vector<Triangle> out;
    for (uint32_t k = 0; k < around - (closed ? 0 : 1); ++k) out.push_back({3, rim(k), rim(k + 1)});
    for (uint32_t k = 0; k + 1 < around; ++k) out.push_back({rim(k + 1), rim(k), rim(k) + 1});
    uint64_t state = seed;
    for (size_t i = out.size(); i > 1; --i) {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        std::swap(out[i - 1], out[(state >> 33) % i]);
    }
    return out;
}

TEST(TriangleAdjacency, MatchesABruteForceEdgeMap) {
    for (uint32_t around : {3u, 6u, 16u, 17u, 40u}) {
        for (bool closed : {true, false}) {
            const std::vector<Triangle> triangles = disc(around, closed, around * 2 + closed);
            const uint32_t vertex_count = 3 * around + 20;
            const TriangleAdjacency adjacency(triangles, vertex_count);
            std::map<std::pair<uint32_t, uint32_t>, uint32_t> half_edge;
            for (uint32_t t = 0; t < triangles.size(); ++t) {
                for (uint32_t k = 0; k < 3; ++k) half_edge[{triangles[t][k], triangles[t][(k + 1) % 3]}] = 3 * t + k;
            }
            std::set<uint32_t> boundary;
            std::vector<uint32_t> star(vertex_count, 0);
            for (const auto& [edge, h] : half_edge) {
                const auto twin = half_edge.find({edge.second, edge.first});
                EXPECT_EQ(adjacency.twin(h), twin == half_edge.end() ? kNoHalfEdge : twin->second) << around;
                if (twin == half_edge.end()) boundary.insert(edge.first), boundary.insert(edge.second);
                ++star[edge.first];
                EXPECT_TRUE(adjacency.has_edge(edge.first, edge.second));
                EXPECT_TRUE(adjacency.has_edge(edge.second, edge.first));
            }
            EXPECT_FALSE(adjacency.has_edge(3, 10 + 3 * (around / 2) + 1)) << around;
            for (uint32_t v = 0; v < vertex_count; ++v) {
                EXPECT_EQ(adjacency.star_size(v), star[v]) << around << " vertex " << v;
                EXPECT_EQ(adjacency.on_boundary(v), boundary.count(v) == 1) << around << " vertex " << v;
                std::multiset<uint32_t> ends(adjacency.ends_begin(v), adjacency.ends_end(v)), expected;
                for (const uint32_t* h = adjacency.outgoing_begin(v); h != adjacency.outgoing_end(v); ++h) {
                    EXPECT_EQ(triangles[*h / 3][*h % 3], v);
                    expected.insert(triangles[*h / 3][(*h % 3 + 1) % 3]);
                }
                EXPECT_EQ(ends, expected) << around << " vertex " << v;
            }
        }
    }
}

}  // namespace
