// Base mesh + leaf mesh -> hierarchy: round trips over random hierarchies (shuffled, moved),
// known answers, and every kind of bad input refused with a message naming the culprit.
#include "hierarchy_checks.h"

#include <amc/codec.h>
#include <amc/import.h>
#include <amc/mesh_io.h>
#include <amc/refinement.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>
#include <numeric>
#include <set>

namespace amc {
namespace {

using testing::Random;
using testing::random_hierarchy;
using testing::varied_random_hierarchy;
using testing::shuffled;

// A hierarchy's leaf mesh as a user would hold it: vertices and faces in random order, each
// face's vertices rotated, every non-base vertex moved off its midpoint (by 0.3, `moved_far` 0.5,
// times the length of its shortest edge per coordinate), or placed anywhere (`scattered`).
struct UserLeafMesh {
    TriangleMesh mesh;
    std::vector<uint32_t> leaf_of_base;       // base vertex i is mesh vertex leaf_of_base[i]
    std::vector<uint32_t> user_of_canonical;  // canonical vertex c is mesh vertex user_of_canonical[c]
};

enum class Placement { midpoints, moved, moved_far, scattered };

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
        } else if (v >= v0 && placement == Placement::moved_far) {
            p = p + (0.5 * shortest[v]) * Vec3{unit(), unit(), unit()};
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

TEST(ImportLeafMesh, FiniteElementModelsRoundTrip) {
    std::vector<Hierarchy> models;
    models.push_back(make_l_shape_model(7));
    for (Hierarchy& h : make_moving_front_sequence(3, 7)) models.push_back(std::move(h));
    for (size_t i = 0; i < models.size(); ++i) {
        for (Placement placement : {Placement::midpoints, Placement::moved}) {
            const UserLeafMesh user = user_leaf_mesh(models[i], 40 + i, placement);
            EXPECT_TRUE(imports_back(models[i], user, true)) << "model " << i;
            EXPECT_TRUE(imports_back(models[i], user, false)) << "model " << i;
        }
    }
}

// A curvature-adaptive surface remesh: every new vertex projected onto the reference surface, so
// none lies at its edge midpoint; the leaf-midpoint guide finds them at this size (at 30,000
// faces it misses a few and the import is refused: docs/IMPORT.md, "Limitations").
// DISABLED since the remesher of docs/REMESHER.md landed: it places vertices along the
// elements' normal and then corrects them. On 2026-12-06 the 2,000-face case imports (with and
// without the normal-ray guide) and the 5,000-face case is refused (with it too: vertices the
// correction slid off their lines); each remesh of the 81,920-triangle sphere takes about 100 s
// (the base search), so FandiskMeanDeepRemeshUnmovedImportsWithItsBase tests the guide instead.
TEST(ImportLeafMesh, DISABLED_ProjectedSurfaceRemeshRoundTrip) {
    for (uint32_t faces : {2000u, 5000u}) {
        SurfaceRemeshOptions options;
        options.base_triangles = 500;
        options.max_level = 8;
        options.target_faces = faces;
        const Hierarchy h = remesh_adaptively(make_bumpy_sphere(6), options);
        const UserLeafMesh user = user_leaf_mesh(h, faces, Placement::midpoints);
        EXPECT_TRUE(imports_back(h, user, true)) << faces << " faces";
        EXPECT_TRUE(imports_back(h, user, false)) << faces << " faces";
    }
}

// Uniform refinements are read off the connectivity alone: positions anywhere.
TEST(ImportLeafMesh, UniformRefinementsWithScatteredVerticesRoundTrip) {
    for (const auto& fixture : testing::fixture_meshes()) {
        for (int levels = 1; levels <= 3; ++levels) {
            Hierarchy h(fixture.mesh);
            refine_uniformly(h, levels);
            const UserLeafMesh user = user_leaf_mesh(h, uint64_t(levels), Placement::scattered);
            EXPECT_TRUE(imports_back(h, user, true)) << fixture.name << " levels " << levels;
            EXPECT_TRUE(imports_back(h, user, false)) << fixture.name << " levels " << levels;
        }
    }
}

// Random hierarchies (adaptive refinement and coarsening, green closures of both diagonals, every
// fixture topology, float and double, depth 1 to 7), vertices and faces shuffled, every non-base
// vertex moved off its midpoint: each imports back identical, base matched by index and by position.
TEST(ImportLeafMesh, ManyRandomHierarchiesWithMovedVerticesRoundTrip) {
    for (uint64_t seed = 1; seed <= 200; ++seed) {
        const Hierarchy h = varied_random_hierarchy(seed);
        const UserLeafMesh user = user_leaf_mesh(h, seed, Placement::moved);
        EXPECT_TRUE(imports_back(h, user, seed % 2 == 0)) << "seed " << seed;
    }
}

// How many of 200 random hierarchies (every fixture, depth 1 to 7, 20 to 2,000 leaves, both
// diagonals), their vertices placed as `placement` says, import; each import must be the
// identical hierarchy (never a wrong one), the others are refused with an error.
// What a refusal adds when the input's midpoints had to be guessed (leaf_import.cpp).
const char* const kGuessedMidpointsHint = "too far from their edges' midpoints for the import to find it";

int imported_of_200(Placement placement) {
    int imported = 0;
    for (uint64_t seed = 1; seed <= 200; ++seed) {
        const Hierarchy h = varied_random_hierarchy(seed);
        const UserLeafMesh user = user_leaf_mesh(h, seed, placement);
        try {
            import_leaf_mesh(h.base(), user.mesh, user.leaf_of_base);
        } catch (const Error& e) {
            // The input is valid: a refusal must say that the import, not only the input, may be at fault.
            EXPECT_NE(std::string(e.what()).find(kGuessedMidpointsHint), std::string::npos) << "seed " << seed << ": "
                                                                                           << e.what();
            continue;
        }
        EXPECT_TRUE(imports_back(h, user, true)) << "seed " << seed;
        ++imported;
    }
    return imported;
}

// With every non-base vertex placed anywhere only the connectivity can tell: the uniform grids and
// the anchored inverse refinement. How many import is a known answer of today's method
// (docs/IMPORT.md, "Anchored inverse refinement"), printed and held as a floor.
TEST(ImportLeafMesh, RandomHierarchiesWithScatteredVerticesImportOrAreRefused) {
    const int imported = imported_of_200(Placement::scattered);
    std::printf("[import_leaf_mesh] random hierarchies, vertices scattered: %d of 200 imported\n", imported);
    EXPECT_GE(imported, 94);  // 86 before the anchored way tried other face orders, 78 before a refined node
                              // across a closure (ccaea41, section 2 of docs/IMPORT.md)
}

// Moved by half their shortest edge, the nearest vertex to where a guide expects a hidden midpoint
// is often a finer one: the guided ways' second round, which lets the anchored way's undo steps
// choose among the nearest (docs/IMPORT.md, "Undo steps decide between the nearest"), and the
// repair of picks that the next level contradicts ("The children repair the picks") and the return
// to the level of a pick that a level further down contradicts ("Back to the level of the pick")
// and the coarse picks replaced where another candidate's subtree closes ("Picks certified by their
// subtrees") import more of them. The count is a known answer.
TEST(ImportLeafMesh, RandomHierarchiesMovedFarImportOrAreRefused) {
    const int imported = imported_of_200(Placement::moved_far);
    std::printf("[import_leaf_mesh] random hierarchies, vertices moved by 0.5: %d of 200 imported\n", imported);
    EXPECT_GE(imported, 172);  // 171 before the position searches were bounded, 166 before the picks certified by
                               // their subtrees, 165 before a refined node across a closure (ccaea41), 153 before
                               // the return to the level of a pick, 104 before the
                               // children repaired the picks, 82 without the undo steps
}

// ---- bad input: every kind refused with an error naming the culprit ----------------------------

// The message of the Error that importing throws, or "" when it succeeds.
std::string import_error(const TriangleMesh& base, const TriangleMesh& leaf, const std::vector<uint32_t>& map = {}) {
    try {
        import_leaf_mesh(base, leaf, map, "input.obj");
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

struct BadInputFixture {
    Hierarchy h = random_hierarchy(make_square(3), 300, 5, 11, true, false);
    UserLeafMesh user = user_leaf_mesh(h, 5, Placement::moved);
    // The faces of leaf n in user numbering.
    std::vector<Triangle> faces_of(NodeId n) const {
        const LeafMesh leaf = extract_leaf_mesh(h);
        std::vector<Triangle> out;
        for (size_t i = 0; i < leaf.source.size(); ++i) {
            if (leaf.source[i] != n) continue;
            const Triangle& t = leaf.mesh.triangles[i];
            out.push_back({user.user_of_canonical[t[0]], user.user_of_canonical[t[1]], user.user_of_canonical[t[2]]});
        }
        return out;
    }
    uint32_t user_vertex(VertexId v) const { return user.user_of_canonical[canonical_vertex_order(h)[v]]; }
    // Removes the faces equal (up to rotation) to any of `faces`.
    void remove(const std::vector<Triangle>& faces) {
        auto same = [](const Triangle& a, const Triangle& b) {
            for (int r = 0; r < 3; ++r) {
                if (a[0] == b[r] && a[1] == b[(r + 1) % 3] && a[2] == b[(r + 2) % 3]) return true;
            }
            return false;
        };
        auto& tris = user.mesh.triangles;
        tris.erase(std::remove_if(tris.begin(), tris.end(),
                                  [&](const Triangle& t) {
                                      for (const Triangle& f : faces) {
                                          if (same(t, f)) return true;
                                      }
                                      return false;
                                  }),
                   tris.end());
    }
    std::string error() const { return import_error(h.base(), user.mesh); }
};

TEST(ImportLeafMesh, FixtureImports) {
    BadInputFixture f;
    EXPECT_EQ(f.error(), "");
}

TEST(ImportLeafMesh, RefusesMissingFace) {
    BadInputFixture f;
    f.user.mesh.triangles.erase(f.user.mesh.triangles.begin() + 17);
    const std::string message = f.error();
    EXPECT_NE(message.find("missing face"), std::string::npos) << message;
}

// With every new vertex at its midpoint nothing is guessed: the fault found is the input's alone.
TEST(ImportLeafMesh, RefusalWithExactMidpointsBlamesTheInputAlone) {
    const Hierarchy h = random_hierarchy(make_square(3), 300, 5, 11, true, false);
    UserLeafMesh user = user_leaf_mesh(h, 5, Placement::midpoints);
    user.mesh.triangles.erase(user.mesh.triangles.begin() + 17);
    const std::string message = import_error(h.base(), user.mesh, user.leaf_of_base);
    EXPECT_NE(message.find("missing face"), std::string::npos) << message;
    EXPECT_EQ(message.find(kGuessedMidpointsHint), std::string::npos) << message;
    BadInputFixture moved;  // the same fault among moved vertices: the import may be the one at fault
    moved.user.mesh.triangles.erase(moved.user.mesh.triangles.begin() + 17);
    EXPECT_NE(moved.error().find(kGuessedMidpointsHint), std::string::npos) << moved.error();
}

TEST(ImportLeafMesh, RefusesExtraFace) {
    BadInputFixture f;
    // A triangle hung on a boundary edge of the open square: a vertex outside, one more face.
    std::set<std::pair<uint32_t, uint32_t>> directed;
    for (const Triangle& t : f.user.mesh.triangles) {
        for (int e = 0; e < 3; ++e) directed.insert({t[e], t[(e + 1) % 3]});
    }
    uint32_t a = 0, b = 0;
    for (const auto& [u, v] : directed) {
        if (!directed.count({v, u})) {
            a = u, b = v;
            break;
        }
    }
    f.user.mesh.positions.push_back({2.0, 2.0, 1.0});
    f.user.mesh.triangles.push_back({b, a, uint32_t(f.user.mesh.positions.size() - 1)});
    const std::string message = f.error();
    EXPECT_NE(message.find("face " + std::to_string(f.user.mesh.triangles.size() - 1)), std::string::npos) << message;
}

TEST(ImportLeafMesh, RefusesTJunction) {
    BadInputFixture f;
    // A green bisection replaced by its unsplit triangle: the hanging vertex is left on an edge.
    NodeId green = kNoNode;
    for (NodeId n : f.h.leaves()) {
        if (f.h.hanging_node_count(n) == 1) green = n;
    }
    ASSERT_NE(green, kNoNode);
    f.remove(f.faces_of(green));
    f.user.mesh.triangles.push_back({f.user_vertex(f.h.vertex(green, 0)), f.user_vertex(f.h.vertex(green, 1)),
                                     f.user_vertex(f.h.vertex(green, 2))});
    const std::string message = f.error();
    EXPECT_NE(message.find("T-junction"), std::string::npos) << message;
}

TEST(ImportLeafMesh, RefusesFlippedFace) {
    BadInputFixture f;
    std::swap(f.user.mesh.triangles[5][0], f.user.mesh.triangles[5][1]);
    const std::string message = f.error();
    EXPECT_NE(message.find("orientation"), std::string::npos) << message;
}

TEST(ImportLeafMesh, RefusesWrongBase) {
    BadInputFixture f;
    TriangleMesh moved = f.h.base();
    moved.positions[3].x += 0.01;
    std::string message = import_error(moved, f.user.mesh);
    EXPECT_NE(message.find("base vertex 3"), std::string::npos) << message;
    // Every base vertex present, but the base triangles cut the square along the other diagonals.
    TriangleMesh other = f.h.base();
    Triangle& p = other.triangles[0];
    Triangle& q = other.triangles[1];
    const uint32_t a = p[0], b = p[1], c = p[2], d = q[2];  // (a, b, c), (a, c, d) -> (a, b, d), (b, c, d)
    p = {a, b, d};
    q = {b, c, d};
    message = import_error(other, f.user.mesh);
    EXPECT_NE(message.find("input.obj: the element on vertices ("), std::string::npos) << message;
}

TEST(ImportLeafMesh, RefusesABaseTriangleThatIsNoElement) {
    // The square's two base triangles, unrefined, against a base cut along the other diagonal.
    Hierarchy h(make_square(1));
    TriangleMesh other = h.base();
    const Triangle p = other.triangles[0], q = other.triangles[1];
    other.triangles = {{p[0], p[1], q[2]}, {p[1], p[2], q[2]}};
    const std::string message = import_error(other, extract_leaf_mesh(h).mesh);
    EXPECT_NE(message.find("input.obj: vertex "), std::string::npos) << message;
    EXPECT_NE(message.find("(wrong base?)"), std::string::npos) << message;
}

TEST(ImportLeafMesh, RefusesNonManifoldLeafMesh) {
    BadInputFixture f;
    const Triangle t = f.user.mesh.triangles[0];
    f.user.mesh.positions.push_back({0.5, 0.5, 1.0});
    f.user.mesh.triangles.push_back({t[0], t[1], uint32_t(f.user.mesh.positions.size() - 1)});
    const std::string message = f.error();
    EXPECT_NE(message.find("non-manifold"), std::string::npos) << message;
}

TEST(ImportLeafMesh, RefusesDuplicateVertex) {
    BadInputFixture f;
    const uint32_t v = f.user.mesh.triangles[0][0];
    f.user.mesh.positions.push_back(f.user.mesh.positions[v]);
    f.user.mesh.triangles[0][0] = uint32_t(f.user.mesh.positions.size() - 1);
    const std::string message = f.error();
    EXPECT_NE(message.find("duplicate vertex"), std::string::npos) << message;
    EXPECT_NE(message.find(std::to_string(v)), std::string::npos) << message;
}

// A projection may put two new vertices of a valid refinement on one point: that alone is no
// reason to refuse (only a base vertex matched by position would be ambiguous).
TEST(ImportLeafMesh, TwoNewVerticesAtOnePositionImport) {
    Hierarchy h(make_square(3));
    refine_uniformly(h, 2);
    UserLeafMesh user = user_leaf_mesh(h, 3, Placement::scattered);
    const uint32_t v0 = uint32_t(h.base().positions.size());
    user.mesh.positions[user.user_of_canonical[v0 + 1]] = user.mesh.positions[user.user_of_canonical[v0]];
    EXPECT_TRUE(imports_back(h, user, false));
    // The same position given to a base vertex makes matching by position ambiguous.
    user.mesh.positions[user.user_of_canonical[v0]] = user.mesh.positions[user.leaf_of_base[0]];
    const std::string message = import_error(h.base(), user.mesh);
    EXPECT_NE(message.find("duplicate vertex"), std::string::npos) << message;
    EXPECT_NE(message.find(std::to_string(user.leaf_of_base[0])), std::string::npos) << message;
}

TEST(ImportLeafMesh, RefusesUnusedVertex) {
    BadInputFixture f;
    f.user.mesh.positions.push_back({5, 5, 5});
    const std::string message = f.error();
    EXPECT_NE(message.find("vertex " + std::to_string(f.user.mesh.positions.size() - 1)), std::string::npos)
        << message;
}

TEST(ImportLeafMesh, RefusesUnbalancedRefinement) {
    // The square's lower triangle split, and its child at the shared diagonal split again while the
    // upper triangle stays whole; the upper one closed by a fan over the three vertices on the
    // diagonal. Conforming, but two levels meet across the diagonal.
    Hierarchy h(make_square(1));
    h.split(0);
    const NodeId child = h.child(0, 0);
    ASSERT_FALSE(h.can_split(child));
    h.split(child);  // what refine() would not do
    LeafMesh leaf = extract_leaf_mesh(h);
    const std::vector<uint32_t> canonical = canonical_vertex_order(h);
    std::vector<Triangle> faces;
    for (size_t i = 0; i < leaf.source.size(); ++i) {
        if (leaf.source[i] != 1) faces.push_back(leaf.mesh.triangles[i]);
    }
    // Root 1 is (a, c, d); the diagonal a -> c carries x (level 2) and m (level 1).
    const uint32_t a = canonical[h.vertex(1, 0)], c = canonical[h.vertex(1, 1)], d = canonical[h.vertex(1, 2)];
    const uint32_t m = canonical[h.midpoint(0, 2)];
    const uint32_t x = canonical[h.midpoint(child, 2)];
    faces.push_back({a, x, d});
    faces.push_back({x, m, d});
    faces.push_back({m, c, d});
    leaf.mesh.triangles = faces;
    const std::string message = import_error(h.base(), leaf.mesh);
    EXPECT_NE(message.find("2:1 balance"), std::string::npos) << message;
}

TEST(ImportLeafMesh, RefusesGreenClosureOfThreeHangingNodes) {
    // A node split red whose three neighbours are refined too: its four red triangles replaced by
    // a fan from one edge's vertex over the hexagon, a green closure of three hanging nodes.
    Hierarchy h = random_hierarchy(make_icosahedron(), 400, 4, 3, false, false);
    NodeId target = kNoNode;
    for (NodeId n : h.breadth_first_order()) {
        if (h.is_leaf(n)) continue;
        bool ok = true;
        for (int k = 0; k < 4; ++k) ok = ok && h.is_leaf(h.child(n, k)) && h.hanging_node_count(h.child(n, k)) == 0;
        for (int e = 0; e < 3; ++e) ok = ok && h.neighbor(n, e) != kNoNode && !h.is_leaf(h.neighbor(n, e));
        if (ok) {
            target = n;
            break;
        }
    }
    ASSERT_NE(target, kNoNode);
    LeafMesh leaf = extract_leaf_mesh(h);
    const std::vector<uint32_t> canonical = canonical_vertex_order(h);
    std::vector<Triangle> faces;
    for (size_t i = 0; i < leaf.source.size(); ++i) {
        if (h.parent(leaf.source[i]) != target) faces.push_back(leaf.mesh.triangles[i]);
    }
    uint32_t v[3], m[3];
    for (int i = 0; i < 3; ++i) {
        v[i] = canonical[h.vertex(target, i)];
        m[i] = canonical[h.midpoint(target, i)];
    }
    faces.push_back({m[1], v[2], m[2]});
    faces.push_back({m[1], m[2], v[0]});
    faces.push_back({m[1], v[0], m[0]});
    faces.push_back({m[1], m[0], v[1]});
    leaf.mesh.triangles = faces;
    const std::string message = import_error(h.base(), leaf.mesh);
    EXPECT_NE(message.find("three hanging nodes"), std::string::npos) << message;
}

TEST(ImportLeafMesh, RefusesQuadsInTheFile) {
    const std::string dir = ::testing::TempDir();
    write_mesh(dir + "/import_base.obj", make_square(1));
    try {
        import_leaf_mesh_files(dir + "/import_base.obj", std::string(AMC_TEST_DATA_DIR) + "/bad/obj_quad.obj");
        FAIL() << "a quad was accepted";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("has 4 vertices; only triangle meshes"), std::string::npos) << e.what();
    }
}

// ---- the semi-regular meshes of ../shared/data ----------------------------------------------

void expect_semi_regular(const std::string& base_name, const std::string& leaf_name, int levels) {
    const std::string dir = AMC_SHARED_DATA_DIR;
    if (!std::ifstream(dir + "/" + leaf_name).good()) GTEST_SKIP() << "shared data not found (" << dir << ")";
    const TriangleMesh base = read_mesh(dir + "/" + base_name);
    const TriangleMesh leaf = read_mesh(dir + "/" + leaf_name);
    for (uint64_t seed : {0u, 1u, 2u}) {
        std::vector<uint32_t> new_index;
        const TriangleMesh input = seed == 0 ? leaf : shuffled(leaf, seed, &new_index);
        const ImportedHierarchy imported = import_leaf_mesh(base, input);
        const Hierarchy& h = imported.hierarchy;
        const HierarchyStats stats = compute_stats(h);
        // The uniform forest: every node of the first `levels` levels refined, every leaf red.
        EXPECT_EQ(stats.levels, uint32_t(levels + 1)) << leaf_name;
        EXPECT_EQ(stats.leaves, uint32_t(base.triangles.size()) << (2 * levels)) << leaf_name;
        EXPECT_EQ(stats.green_faces, 0u) << leaf_name;
        // The decoded leaf mesh is the input: every hierarchy vertex at its input position, and
        // the file's bytes decode to the same hierarchy.
        for (size_t i = 0; i < input.positions.size(); ++i) {
            ASSERT_TRUE(h.position(imported.vertex_of_input[i]) == input.positions[i]) << leaf_name << " vertex " << i;
        }
        const std::vector<uint8_t> file = encode(h);
        EXPECT_TRUE(identical(decode(file.data(), file.size()), in_decoder_order(h))) << leaf_name;
    }
}

TEST(ImportLeafMeshSharedData, BunnySemiRegularLevel3OverLevel0) { expect_semi_regular("bunny-sr-l0.obj", "bunny-sr-l3.obj", 3); }

TEST(ImportLeafMeshSharedData, ElephantSemiRegularLevel2OverLevel0) {
    expect_semi_regular("elephant-sr-l0.obj", "elephant-sr-l2.obj", 2);
}

// fandisk remeshed as scripts/corpus.sh makes the corpus's fandisk models (500 base triangles, 10^5
// faces, level 5), or an empty hierarchy when the shared data is missing.
Hierarchy corpus_fandisk_remesh(RefinementCriterion criterion) {
    const std::string dir = AMC_SHARED_DATA_DIR;
    if (!std::ifstream(dir + "/fandisk.obj").good()) return Hierarchy();
    SurfaceRemeshOptions options;
    options.criterion = criterion;
    options.base_triangles = 500;
    options.target_faces = 100000;
    options.max_level = 5;
    return remesh_adaptively(read_mesh(dir + "/fandisk.obj"), options);
}

// The corpus's fandisk_gauss (docs/IMPORT.md, section 4, as scripts/corpus.sh and import_corpus make
// it): its leaf mesh shuffled and moved by 0.3. Its last wrong picks hold each other in place (a
// level-0 truth whose subtree misfits through finer picks, three level-3 picks along a lattice
// line); the joint moves of "Picks certified by their subtrees" import it.
TEST(ImportLeafMeshSharedData, FandiskGaussRemeshMovedImportsWithItsBase) {
    const Hierarchy h = corpus_fandisk_remesh(RefinementCriterion::gauss_curvature);
    if (h.node_count() == 0) GTEST_SKIP() << "shared data not found (" << AMC_SHARED_DATA_DIR << ")";
    EXPECT_TRUE(imports_back(h, user_leaf_mesh(h, 23, Placement::moved), false));
}

// fandisk remeshed by mean curvature to 40,000 faces at up to level 7, as a user's remesh holds it
// (shuffled, every new vertex where the remesher put it): its coarse hidden midpoints lie off the
// midpoints of their edges' leaf vertices by more than the fine leaves' spacing (the sagitta of a
// long chord), where only the normal-ray guide finds them; refused without it.
TEST(ImportLeafMeshSharedData, FandiskMeanDeepRemeshUnmovedImportsWithItsBase) {
    const std::string dir = AMC_SHARED_DATA_DIR;
    if (!std::ifstream(dir + "/fandisk.obj").good()) GTEST_SKIP() << "shared data not found (" << dir << ")";
    SurfaceRemeshOptions options;
    options.base_triangles = 500;
    options.target_faces = 40000;
    options.max_level = 7;
    const Hierarchy h = remesh_adaptively(read_mesh(dir + "/fandisk.obj"), options);
    for (uint64_t seed : {1u, 2u, 3u}) EXPECT_TRUE(imports_back(h, user_leaf_mesh(h, seed, Placement::midpoints), false)) << "seed " << seed;
}

// The corpus's fandisk_mean as a user's remesh holds it: shuffled, its new vertices where the
// remesher projected them (import_corpus --move 0). The anchored way's search stops short of the
// base in this face order (three levels undone) and reaches it in others; import_corpus --move 0
// refused it before the anchored way tried other orders ("no vertex left to split the edge").
TEST(ImportLeafMeshSharedData, FandiskMeanRemeshUnmovedImportsWithItsBase) {
    const Hierarchy h = corpus_fandisk_remesh(RefinementCriterion::mean_curvature);
    if (h.node_count() == 0) GTEST_SKIP() << "shared data not found (" << AMC_SHARED_DATA_DIR << ")";
    EXPECT_TRUE(imports_back(h, user_leaf_mesh(h, 23, Placement::midpoints), false));
}

}  // namespace
}  // namespace amc
