// The nearest-vertex search of the position-guided import (src/import/nearest_vertex.h) against
// a brute-force scan: the same vertex for every query, on uniform and strongly graded point sets.
#include "import/nearest_vertex.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <vector>

namespace {

struct Lcg {
    uint64_t state;
    double unit() {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        return double(state >> 11) * (1.0 / 9007199254740992.0);
    }
};

uint32_t brute_force(const std::vector<amc::Vec3>& points, amc::Vec3 p, uint32_t skip_every) {
    uint32_t best = amc::kNoIndex;
    double best_distance = 0;
    for (uint32_t v = 0; v < points.size(); ++v) {
        if (v % skip_every == 0) continue;
        const amc::Vec3 d = points[v] - p;
        const double distance = amc::dot(d, d);
        if (best == amc::kNoIndex || distance < best_distance) {
            best = v;
            best_distance = distance;
        }
    }
    return best;
}

TEST(NearestVertex, FindsTheNearestUsableVertexAsABruteForceScanDoes) {
    Lcg random{5};
    for (size_t count : {size_t(1), size_t(7), size_t(17), size_t(300), size_t(5000)}) {
        for (bool graded : {false, true}) {
            // Graded: points crowd towards the origin (cube-law radii), as in an adaptive mesh.
            std::vector<amc::Vec3> points(count);
            for (amc::Vec3& p : points) {
                p = {random.unit(), random.unit(), 0.01 * random.unit()};
                if (graded) p = std::pow(random.unit(), 3.0) * p;
            }
            const amc::NearestVertex nearest(points);
            for (int query = 0; query < 500; ++query) {
                const amc::Vec3 p = {1.2 * random.unit() - 0.1, 1.2 * random.unit() - 0.1, 0.02 * random.unit()};
                const uint32_t skip_every = 3;  // every third vertex is not usable
                EXPECT_EQ(nearest.find(p, [&](uint32_t v) { return v % skip_every != 0; }),
                          brute_force(points, p, skip_every))
                    << count << " points, graded " << graded << ", query " << query;
            }
        }
    }
}

TEST(NearestVertex, FindsTheKNearestUsableVerticesInOrderAsASortDoes) {
    Lcg random{11};
    for (size_t count : {size_t(2), size_t(9), size_t(300), size_t(5000)}) {
        std::vector<amc::Vec3> points(count);
        for (amc::Vec3& p : points) p = {random.unit(), random.unit(), 0.01 * random.unit()};
        const amc::NearestVertex nearest(points);
        for (int query = 0; query < 200; ++query) {
            const amc::Vec3 p = {random.unit(), random.unit(), 0.01 * random.unit()};
            auto usable = [](uint32_t v) { return v % 4 != 1; };
            std::vector<uint32_t> sorted;
            for (uint32_t v = 0; v < count; ++v) {
                if (usable(v)) sorted.push_back(v);
            }
            std::stable_sort(sorted.begin(), sorted.end(), [&](uint32_t a, uint32_t b) {
                return amc::dot(points[a] - p, points[a] - p) < amc::dot(points[b] - p, points[b] - p);
            });
            for (uint32_t k : {1u, 2u, 4u, amc::NearestVertex::kMaxCount}) {
                uint32_t found[amc::NearestVertex::kMaxCount];
                const uint32_t n = nearest.find_nearest(p, usable, k, found);
                ASSERT_EQ(n, std::min<size_t>(k, sorted.size())) << count << " points, k " << k;
                for (uint32_t i = 0; i < n; ++i) EXPECT_EQ(found[i], sorted[i]) << count << " points, k " << k << ", rank " << i;
            }
        }
    }
}

TEST(NearestVertex, NoUsableVertexIsNoIndex) {
    const std::vector<amc::Vec3> points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    const amc::NearestVertex nearest(points);
    EXPECT_EQ(nearest.find({0.1, 0.1, 0}, [](uint32_t) { return false; }), amc::kNoIndex);
    EXPECT_EQ(amc::NearestVertex({}).find({0, 0, 0}, [](uint32_t) { return true; }), amc::kNoIndex);
}

}  // namespace
