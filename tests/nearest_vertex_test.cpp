// The nearest-vertex search of the position-guided import (src/import/nearest_vertex.h) against
// a brute-force scan: the same vertex for every query, on uniform and strongly graded point sets;
// and, where vertices lie equally near, against the k-d tree whose order the import's answers follow.
#include "import/nearest_vertex.h"
#include "import/spatial_order.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
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

// The import's renumbered leaf mesh takes the input's tree with its ids renamed instead of a build
// over the renumbered points inserted in the input's order: both must answer alike, ties included
// (lattice points: many vertices equally near a query).
TEST(NearestVertex, RenamedTreeAnswersAsABuildOverTheRenumberedPoints) {
    Lcg random{23};
    std::vector<amc::Vec3> points;
    for (int i = 0; i < 40; ++i) {
        for (int j = 0; j < 40; ++j) points.push_back({double(i), double(j), double((i * 7 + j * 3) % 5)});
    }
    std::vector<uint32_t> new_id(points.size());  // input id -> renumbered id
    std::iota(new_id.begin(), new_id.end(), 0u);
    for (size_t i = new_id.size(); i > 1; --i) std::swap(new_id[i - 1], new_id[size_t(random.unit() * double(i))]);
    std::vector<amc::Vec3> renumbered(points.size());
    for (uint32_t v = 0; v < points.size(); ++v) renumbered[new_id[v]] = points[v];
    const amc::NearestVertex input(points);
    const amc::NearestVertex built(renumbered, &new_id);
    const amc::NearestVertex renamed(input, new_id);
    auto usable = [](uint32_t v) { return v % 5 != 2; };
    for (int query = 0; query < 300; ++query) {
        const amc::Vec3 p = {std::floor(41 * random.unit()) - 0.5 * (query % 2), std::floor(41 * random.unit()), 2.0};
        uint32_t a[amc::NearestVertex::kMaxCount], b[amc::NearestVertex::kMaxCount];
        const uint32_t na = built.find_nearest(p, usable, amc::NearestVertex::kMaxCount, a);
        const uint32_t nb = renamed.find_nearest(p, usable, amc::NearestVertex::kMaxCount, b);
        ASSERT_EQ(na, nb) << "query " << query;
        for (uint32_t i = 0; i < na; ++i) EXPECT_EQ(a[i], b[i]) << "query " << query << ", rank " << i;
        EXPECT_EQ(built.find(p, usable), renamed.find(p, usable)) << "query " << query;
    }
}

// Lattice points (many vertices equally near a query), taken into the k-d tree in a shuffled
// order: the search answers as the k-d tree alone does, nearest first and the first found of
// equally near ones, for every count and with a distance limit. Where no two answers tie, the
// Morton tree answers; so that the k-d tree's turn is tested, many queries must tie.
TEST(NearestVertex, EquallyNearVerticesComeInTheKdTreesOrder) {
    Lcg random{31};
    std::vector<amc::Vec3> points;
    for (int i = 0; i < 30; ++i) {
        for (int j = 0; j < 30; ++j) points.push_back({double(i), double(j), double((i * 7 + j * 3) % 4)});
    }
    std::vector<uint32_t> order(points.size());
    std::iota(order.begin(), order.end(), 0u);
    for (size_t i = order.size(); i > 1; --i) std::swap(order[i - 1], order[size_t(random.unit() * double(i))]);
    const amc::NearestVertex nearest(points, &order);
    const amc::NearestVertex::KdTree kd_tree(points, &order);
    auto usable = [](uint32_t v) { return v % 7 != 3; };
    int tied = 0;
    for (int query = 0; query < 400; ++query) {
        const amc::Vec3 p = {std::floor(31 * random.unit()) - 0.5 * (query % 2), std::floor(31 * random.unit()),
                             1.5 + 0.5 * (query % 3)};
        for (uint32_t k : {1u, 2u, 4u, amc::NearestVertex::kMaxCount}) {
            for (double limit : {std::numeric_limits<double>::infinity(), 6.25}) {
                uint32_t a[amc::NearestVertex::kMaxCount], b[amc::NearestVertex::kMaxCount];
                const uint32_t na = nearest.find_nearest(p, usable, k, a, limit);
                const uint32_t nb = kd_tree.find_nearest(p, usable, k, b, limit);
                ASSERT_EQ(na, nb) << "query " << query << ", k " << k;
                for (uint32_t i = 0; i < na; ++i) EXPECT_EQ(a[i], b[i]) << "query " << query << ", k " << k << ", rank " << i;
                // A tie within the answer, or with the first vertex left out of it.
                uint32_t c[amc::NearestVertex::kMaxCount];
                const uint32_t more = kd_tree.find_nearest(p, usable, std::min(k + 1, amc::NearestVertex::kMaxCount), c, limit);
                for (uint32_t i = 1; i < more; ++i) {
                    const amc::Vec3 d0 = points[c[i - 1]] - p, d1 = points[c[i]] - p;
                    if (amc::dot(d0, d0) == amc::dot(d1, d1)) {
                        ++tied;
                        break;
                    }
                }
            }
        }
    }
    EXPECT_GT(tied, 1000);
}

// More points in one grid cell of the Morton order than a bucket holds (a cluster far from the
// rest): the search still finds what a sort finds.
TEST(NearestVertex, CrowdedCellsAreSearchedAsTheRest) {
    Lcg random{41};
    std::vector<amc::Vec3> points;
    for (int i = 0; i < 200; ++i) points.push_back({1e-9 * random.unit(), 1e-9 * random.unit(), 1e-9 * random.unit()});
    for (int i = 0; i < 200; ++i) points.push_back({random.unit(), random.unit(), random.unit()});
    const amc::NearestVertex nearest(points);
    for (int query = 0; query < 300; ++query) {
        const amc::Vec3 p = query % 2 ? amc::Vec3{2e-9 * random.unit(), 1e-9 * random.unit(), 0}
                                      : amc::Vec3{random.unit(), random.unit(), random.unit()};
        auto usable = [](uint32_t v) { return v % 3 != 0; };
        std::vector<uint32_t> sorted;
        for (uint32_t v = 0; v < points.size(); ++v) {
            if (usable(v)) sorted.push_back(v);
        }
        std::stable_sort(sorted.begin(), sorted.end(), [&](uint32_t a, uint32_t b) {
            return amc::dot(points[a] - p, points[a] - p) < amc::dot(points[b] - p, points[b] - p);
        });
        uint32_t found[amc::NearestVertex::kMaxCount];
        const uint32_t n = nearest.find_nearest(p, usable, amc::NearestVertex::kMaxCount, found);
        ASSERT_EQ(n, amc::NearestVertex::kMaxCount);
        for (uint32_t i = 0; i < n; ++i) EXPECT_EQ(found[i], sorted[i]) << "query " << query << ", rank " << i;
    }
}

// The import numbers the leaf vertices in spatial order and hands the tree their codes
// (spatial_vertex_order's), which it then neither computes nor sorts: the same answers.
TEST(NearestVertex, TreeOverTheSpatialOrderTakesItsCodes) {
    Lcg random{77};
    for (bool graded : {false, true}) {
        std::vector<amc::Vec3> points(3000);
        for (amc::Vec3& p : points) {
            p = {random.unit(), random.unit(), 0.01 * random.unit()};
            if (graded) p = std::pow(random.unit(), 3.0) * p;
        }
        std::vector<uint32_t> codes;
        const std::vector<uint32_t> order = amc::detail::spatial_vertex_order(points, &codes);  // spatial -> given
        ASSERT_EQ(codes.size(), points.size());
        ASSERT_TRUE(std::is_sorted(codes.begin(), codes.end()));
        std::vector<amc::Vec3> spatial;
        for (uint32_t v : order) spatial.push_back(points[v]);
        EXPECT_EQ(codes, amc::detail::morton_codes(spatial));
        const amc::NearestVertex nearest(spatial, nullptr, &codes);
        for (int query = 0; query < 500; ++query) {
            const amc::Vec3 p = {1.2 * random.unit() - 0.1, 1.2 * random.unit() - 0.1, 0.02 * random.unit()};
            const uint32_t found = nearest.find(p, [&](uint32_t s) { return order[s] % 3 != 0; });
            ASSERT_NE(found, amc::kNoIndex);
            EXPECT_EQ(order[found], brute_force(points, p, 3)) << "graded " << graded << ", query " << query;
        }
    }
}

// A query is searched first in the subtree of its cell of 32^3 code cells, whose answer stands
// only where no point outside the cell can be as near: points crowd both sides of the cells'
// sides (the codes' cells are unit cubes here), queries lie just inside them, and the answer is
// a brute-force scan's, also where the nearest lies just across a side.
TEST(NearestVertex, NearestAcrossTheSideOfTheQuerysCellIsFound) {
    Lcg random{53};
    std::vector<amc::Vec3> points = {{0, 0, 0}, {1024, 1024, 1024}};  // 1024 cells of size 1
    for (int i = 0; i < 4000; ++i) {
        const double side = 32 * std::floor(1 + 30 * random.unit());
        const double across = 1e-4 * (random.unit() - 0.5);
        amc::Vec3 p = {1024 * random.unit(), 1024 * random.unit(), 1024 * random.unit()};
        (i % 3 == 0 ? p.x : i % 3 == 1 ? p.y : p.z) = side + across;
        points.push_back(p);
    }
    const amc::NearestVertex nearest(points);
    int across = 0;
    for (int query = 0; query < 2000; ++query) {
        const amc::Vec3 near = points[2 + size_t(random.unit() * 4000)];
        const amc::Vec3 p = near + 3e-5 * amc::Vec3{random.unit() - 0.5, random.unit() - 0.5, random.unit() - 0.5};
        const uint32_t found = nearest.find(p, [](uint32_t v) { return v % 3 != 0; });
        const uint32_t expected = brute_force(points, p, 3);
        EXPECT_EQ(found, expected) << "query " << query;
        const amc::Vec3& q = points[expected];
        across += std::floor(q.x / 32) != std::floor(p.x / 32) || std::floor(q.y / 32) != std::floor(p.y / 32) ||
                  std::floor(q.z / 32) != std::floor(p.z / 32);
    }
    EXPECT_GT(across, 100);  // the case the test is for
}

TEST(NearestVertex, NoUsableVertexIsNoIndex) {
    const std::vector<amc::Vec3> points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    const amc::NearestVertex nearest(points);
    EXPECT_EQ(nearest.find({0.1, 0.1, 0}, [](uint32_t) { return false; }), amc::kNoIndex);
    EXPECT_EQ(amc::NearestVertex({}).find({0, 0, 0}, [](uint32_t) { return true; }), amc::kNoIndex);
}

}  // namespace

// Many vertices at one point, equally near a query: the answer is the k-d tree's (the first of
// them in its order), and the use of each is not tested (a tie lowers the search's bound below it;
// each was tested until 2026-12-07, which made the import of such a mesh quadratic: docs/FUZZING.md).
TEST(NearestVertex, ManyVerticesAtOnePointAreNotEachTested) {
    Lcg random{5};
    std::vector<amc::Vec3> points(20000, amc::Vec3{0.25, 0.5, 0.75});
    for (int i = 0; i < 200; ++i) points.push_back({4 + random.unit(), 4 + random.unit(), random.unit()});
    std::vector<uint32_t> order(points.size());
    std::iota(order.begin(), order.end(), 0u);
    for (size_t i = order.size(); i > 1; --i) std::swap(order[i - 1], order[size_t(random.unit() * double(i))]);
    const amc::NearestVertex nearest(points, &order);
    const amc::NearestVertex::KdTree kd_tree(points, &order);
    for (uint32_t k : {1u, 4u}) {
        uint64_t tested = 0;
        auto usable = [&](uint32_t v) { return ++tested, v % 3 != 0; };
        uint32_t a[amc::NearestVertex::kMaxCount], b[amc::NearestVertex::kMaxCount];
        const uint64_t examined = nearest.examined();
        const uint32_t na = nearest.find_nearest({1, 1, 1}, usable, k, a);
        EXPECT_GE(nearest.examined() - examined, 20000u);  // the k-d tree visits them all
        EXPECT_LT(tested, 64u) << "k " << k;
        auto kd_usable = [](uint32_t v) { return v % 3 != 0; };
        ASSERT_EQ(na, kd_tree.find_nearest({1, 1, 1}, kd_usable, k, b));
        for (uint32_t i = 0; i < na; ++i) EXPECT_EQ(a[i], b[i]) << "k " << k << ", rank " << i;
    }
}
