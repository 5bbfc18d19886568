// Base mesh + leaf mesh -> hierarchy: round trips over random hierarchies (shuffled, moved),
// known answers, and every kind of bad input refused with a message naming the culprit.
#include "hierarchy_checks.h"

#include <amc/import.h>

#include <cmath>
#include <numeric>

namespace amc {
namespace {

using testing::Random;

// A hierarchy's leaf mesh as a user would hold it: vertices and faces in random order, each
// face's vertices rotated, every non-base vertex moved off its midpoint (by `move` times the
// length of its shortest edge, in a random direction), or placed anywhere (`scatter`).
struct UserLeafMesh {
    TriangleMesh mesh;
    std::vector<uint32_t> leaf_of_base;       // base vertex i is mesh vertex leaf_of_base[i]
    std::vector<uint32_t> user_of_canonical;  // canonical vertex c is mesh vertex user_of_canonical[c]
};

enum class Placement { midpoints, moved, scattered };

UserLeafMesh user_leaf_mesh(const Hierarchy& h, uint64_t seed, Placement placement) {
    const LeafMesh leaf = extract_leaf_mesh(h);
    Random random{seed};
    const uint32_t n = uint32_t(leaf.mesh.positions.size());
    const uint32_t v0 = uint32_t(h.base().positions.size());
    std::vector<uint32_t> order(n);
    std::iota(order.begin(), order.end(), 0u);
    for (uint32_t i = n; i > 1; --i) std::swap(order[i - 1], order[random.next() % i]);  // canonical -> user
    std::vector<double> shortest(n, INFINITY);
    for (const Triangle& t : leaf.mesh.triangles) {
        for (int e = 0; e < 3; ++e) {
            const Vec3 d = leaf.mesh.positions[t[e]] - leaf.mesh.positions[t[(e + 1) % 3]];
            const double length = std::sqrt(dot(d, d));
            shortest[t[e]] = std::min(shortest[t[e]], length);
            shortest[t[(e + 1) % 3]] = std::min(shortest[t[(e + 1) % 3]], length);
        }
    }
    auto unit = [&] { return double(random.next() % 2000001) / 1000000.0 - 1.0; };
    UserLeafMesh out;
    out.mesh.single_precision = leaf.mesh.single_precision;
    out.mesh.positions.resize(n);
    for (uint32_t v = 0; v < n; ++v) {
        Vec3 p = leaf.mesh.positions[v];
        if (v >= v0 && placement == Placement::moved) {
            p = p + (0.3 * shortest[v]) * Vec3{unit(), unit(), unit()};
        } else if (v >= v0 && placement == Placement::scattered) {
            p = Vec3{unit(), unit(), unit()};
        }
        if (out.mesh.single_precision) p = {double(float(p.x)), double(float(p.y)), double(float(p.z))};
        out.mesh.positions[order[v]] = p;
    }
    out.mesh.triangles = leaf.mesh.triangles;
    for (size_t i = out.mesh.triangles.size(); i > 1; --i)
        std::swap(out.mesh.triangles[i - 1], out.mesh.triangles[random.next() % i]);
    for (Triangle& t : out.mesh.triangles) {
        const int r = int(random.next() % 3);
        t = {order[t[r]], order[t[(r + 1) % 3]], order[t[(r + 2) % 3]]};
    }
    for (uint32_t b = 0; b < v0; ++b) out.leaf_of_base.push_back(order[b]);
    out.user_of_canonical = order;
    return out;
}

// The import must give back the hierarchy (up to numbering) with the user's positions, and map
// every input vertex to the hierarchy vertex of the same element.
::testing::AssertionResult imports_back(const Hierarchy& original, const UserLeafMesh& user, bool by_index) {
    ImportedHierarchy imported;
    try {
        imported = import_leaf_mesh(original.base(), user.mesh, by_index ? user.leaf_of_base : std::vector<uint32_t>{});
    } catch (const Error& e) {
        return ::testing::AssertionFailure() << e.what();
    }
    const Hierarchy& h = imported.hierarchy;
    const std::string problem = check_invariants(h);
    if (!problem.empty()) return ::testing::AssertionFailure() << problem;
    Hierarchy expected = original;
    const std::vector<uint32_t> canonical = canonical_vertex_order(original);
    for (VertexId v = 0; v < canonical.size(); ++v) {
        if (canonical[v] != 0xffffffffu) expected.set_position(v, user.mesh.positions[user.user_of_canonical[canonical[v]]]);
    }
    if (!identical(h, expected)) return ::testing::AssertionFailure() << "the imported hierarchy differs";
    // Input vertex i is the vertex at canonical index c of both hierarchies.
    const std::vector<uint32_t> imported_canonical = canonical_vertex_order(h);
    for (uint32_t c = 0; c < user.user_of_canonical.size(); ++c) {
        if (imported_canonical[imported.vertex_of_input[user.user_of_canonical[c]]] != c)
            return ::testing::AssertionFailure() << "input vertex " << user.user_of_canonical[c] << " maps to the wrong vertex";
    }
    return ::testing::AssertionSuccess();
}

Hierarchy random_hierarchy(TriangleMesh base, uint32_t leaves, int max_level, uint64_t seed, bool flips, bool single) {
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

TEST(ImportLeafMesh, ExactMidpointsRoundTrip) {
    for (const auto& fixture : testing::fixture_meshes()) {
        for (uint64_t seed = 1; seed <= 6; ++seed) {
            const Hierarchy h = random_hierarchy(fixture.mesh, 600, 6, seed, seed % 2 == 0, seed % 3 == 0);
            const UserLeafMesh user = user_leaf_mesh(h, seed, Placement::midpoints);
            EXPECT_TRUE(imports_back(h, user, true)) << fixture.name << " seed " << seed;
            EXPECT_TRUE(imports_back(h, user, false)) << fixture.name << " seed " << seed;
        }
    }
}

TEST(ImportLeafMesh, MovedVerticesRoundTrip) {
    for (const auto& fixture : testing::fixture_meshes()) {
        for (uint64_t seed = 1; seed <= 6; ++seed) {
            const Hierarchy h = random_hierarchy(fixture.mesh, 600, 6, seed, seed % 2 == 0, seed % 3 == 0);
            const UserLeafMesh user = user_leaf_mesh(h, seed, Placement::moved);
            EXPECT_TRUE(imports_back(h, user, true)) << fixture.name << " seed " << seed;
        }
    }
}

}  // namespace
}  // namespace amc
