// Base mesh connectivity coder (paper II-B): exact round trips over meshes of every topology the
// coder must handle, compression rates on the shared base meshes, and corrupt streams.
#include "coding/base/base_mesh_closing.h"
#include "coding/base/base_mesh_coder.h"
#include "coding/base/base_stage.h"

#include "coding/entropy/arithmetic_coder.h"
#include "coding/container.h"

#include <amc/codec.h>
#include <amc/hierarchy.h>
#include <amc/mesh.h>
#include <amc/mesh_io.h>
#include <amc/refinement.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <random>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace amc {
namespace {

TriangleMesh concatenate(const TriangleMesh& a, const TriangleMesh& b) {
    TriangleMesh m = a;
    const uint32_t offset = static_cast<uint32_t>(a.positions.size());
    m.positions.insert(m.positions.end(), b.positions.begin(), b.positions.end());
    for (Triangle t : b.triangles) m.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
    return m;
}

// Removes the listed triangles and any vertex left unused.
TriangleMesh remove_triangles(const TriangleMesh& mesh, std::set<size_t> drop) {
    TriangleMesh m;
    std::vector<uint32_t> index(mesh.positions.size(), UINT32_MAX);
    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
        if (drop.count(t)) continue;
        Triangle n;
        for (int k = 0; k < 3; ++k) {
            uint32_t& i = index[mesh.triangles[t][k]];
            if (i == UINT32_MAX) {
                i = static_cast<uint32_t>(m.positions.size());
                m.positions.push_back(mesh.positions[mesh.triangles[t][k]]);
            }
            n[k] = i;
        }
        m.triangles.push_back(n);
    }
    return m;
}

// Random edge flips that keep the mesh valid and every valence >= 3: an irregular mesh.
TriangleMesh randomly_flipped(TriangleMesh mesh, int flips, uint32_t seed) {
    std::mt19937 rng(seed);
    for (int f = 0; f < flips; ++f) {
        const size_t t1 = rng() % mesh.triangles.size();
        const int k = static_cast<int>(rng() % 3);
        const uint32_t a = mesh.triangles[t1][k], b = mesh.triangles[t1][(k + 1) % 3],
                       c = mesh.triangles[t1][(k + 2) % 3];
        size_t t2 = SIZE_MAX;
        uint32_t d = 0;
        std::vector<int> valence(mesh.positions.size(), 0);
        std::set<std::pair<uint32_t, uint32_t>> edges;
        for (size_t t = 0; t < mesh.triangles.size(); ++t) {
            const Triangle& tri = mesh.triangles[t];
            for (int e = 0; e < 3; ++e) {
                edges.insert(std::minmax(tri[e], tri[(e + 1) % 3]));
                if (tri[e] == b && tri[(e + 1) % 3] == a) {
                    t2 = t;
                    d = tri[(e + 2) % 3];
                }
            }
        }
        if (t2 == SIZE_MAX || c == d || edges.count(std::minmax(c, d))) continue;
        for (const auto& e : edges) {
            ++valence[e.first];
            ++valence[e.second];
        }
        if (valence[a] <= 3 || valence[b] <= 3) continue;
        mesh.triangles[t1] = {c, a, d};
        mesh.triangles[t2] = {d, b, c};
    }
    return mesh;
}

// The decoder's position source for a mesh coded with `code`: the mesh's own positions.
BasePositionSource positions_of(const TriangleMesh& mesh, const BaseMeshCode& code) {
    return [&mesh, &code](uint32_t vertex, const BaseStencil&, const std::vector<Vec3>&) {
        return mesh.positions[code.vertex_order[vertex]];
    };
}

DecodedBaseMesh decode_with_own_positions(const BaseMeshCode& code, const TriangleMesh& mesh) {
    return decode_base_mesh(code.bytes.data(), code.bytes.size(), static_cast<uint32_t>(mesh.positions.size()),
                            positions_of(mesh, code));
}

// Round trip with the encoder's choice of mode, or with `mode`; returns bits per vertex. Meshes
// `validate_triangle_mesh` refuses reach the coder only through its own API (`valid` false).
double check_round_trip(const TriangleMesh& mesh, const std::string& name,
                        BaseConnectivityMode mode = BaseConnectivityMode::angle, bool chosen = true, bool valid = true) {
    if (valid && !mesh.triangles.empty()) validate_triangle_mesh(mesh, name);
    const int failures_before = ::testing::UnitTest::GetInstance()->current_test_info()->result()->total_part_count();
    const BaseMeshCode code = chosen ? encode_base_connectivity(mesh) : encode_base_connectivity(mesh, mode);
    EXPECT_EQ(code.mode, mode) << name;
    EXPECT_EQ(code.vertex_order.size(), mesh.positions.size()) << name;
    EXPECT_EQ(code.triangle_order.size(), mesh.triangles.size()) << name;
    EXPECT_EQ(code.triangle_rotation.size(), mesh.triangles.size()) << name;
    if (::testing::UnitTest::GetInstance()->current_test_info()->result()->total_part_count() != failures_before) return 0;
    const DecodedBaseMesh dec = decode_with_own_positions(code, mesh);
    EXPECT_EQ(dec.vertex_count, mesh.positions.size()) << name;
    EXPECT_EQ(dec.triangles.size(), mesh.triangles.size()) << name;
    EXPECT_EQ(dec.stencils, code.stencils) << name;
    // The stream's first two raw bits are the mode.
    if (!code.bytes.empty()) {
        EXPECT_EQ(code.bytes[0] >> 6, int(mode)) << name;
    }
    if (::testing::UnitTest::GetInstance()->current_test_info()->result()->total_part_count() != failures_before) return 0;
    // Orders are permutations.
    std::vector<uint32_t> vo = code.vertex_order, to = code.triangle_order;
    std::sort(vo.begin(), vo.end());
    std::sort(to.begin(), to.end());
    for (size_t i = 0; i < vo.size(); ++i) EXPECT_EQ(vo[i], i) << name;
    for (size_t i = 0; i < to.size(); ++i) EXPECT_EQ(to[i], i) << name;
    for (size_t t = 0; t < dec.triangles.size(); ++t) {
        const Triangle& o = mesh.triangles[code.triangle_order[t]];
        const int r = code.triangle_rotation[t];
        EXPECT_LT(r, 3);
        if (r >= 3) return 0;
        for (int k = 0; k < 3; ++k) {
            EXPECT_EQ(code.vertex_order[dec.triangles[t][k]], o[(r + k) % 3]) << name << " triangle " << t;
        }
        if (::testing::UnitTest::GetInstance()->current_test_info()->result()->total_part_count() != failures_before) return 0;
    }
    for (size_t i = 0; i < dec.stencils.size(); ++i) {
        for (int32_t s : dec.stencils[i]) EXPECT_LT(s, static_cast<int32_t>(i)) << name;
        EXPECT_TRUE(dec.positions[i] == mesh.positions[code.vertex_order[i]]) << name;
    }
    const double bpv = mesh.positions.empty() ? 0 : 8.0 * code.bytes.size() / mesh.positions.size();
    std::printf("[base mesh coder] %-24s V=%6zu F=%6zu bytes=%6zu  %.3f bits/vertex\n", name.c_str(),
                mesh.positions.size(), mesh.triangles.size(), code.bytes.size(), bpv);
    return bpv;
}

TEST(BaseMeshCoder, FixtureMeshes) {
    check_round_trip(make_icosahedron(), "icosahedron");
    check_round_trip(make_torus(6, 5, 2.0, 0.7), "torus");
    check_round_trip(make_torus(24, 16, 2.0, 0.7), "torus-24x16");
    check_round_trip(make_square(3), "square");
    check_round_trip(make_square(10), "square-10");
    check_round_trip(make_l_shape(1), "l_shape");
    check_round_trip(make_l_shape(4), "l_shape-4");
    check_round_trip(make_bumpy_sphere(2), "bumpy_sphere");
}

TEST(BaseMeshCoder, SeveralComponents) {
    check_round_trip(concatenate(make_icosahedron(), make_torus(6, 5, 2.0, 0.7)), "icosahedron+torus");
    check_round_trip(concatenate(make_square(2), concatenate(make_l_shape(1), make_icosahedron())),
                     "square+l_shape+icosahedron");
}

TEST(BaseMeshCoder, HolesAndHandles) {
    const TriangleMesh torus = make_torus(12, 8, 2.0, 0.7);
    check_round_trip(remove_triangles(torus, {5}), "torus-one-hole");
    check_round_trip(remove_triangles(torus, {5, 40, 41, 90}), "torus-three-holes");
    // Genus 2: two tori glued along a removed triangle pair each (a tube between them).
    TriangleMesh two = concatenate(torus, torus);
    check_round_trip(remove_triangles(two, {3, 3 + torus.triangles.size()}), "two-tori-holes");
}

TEST(BaseMeshCoder, IrregularMeshes) {
    check_round_trip(randomly_flipped(make_torus(16, 12, 2.0, 0.7), 300, 1), "flipped-torus");
    check_round_trip(randomly_flipped(make_bumpy_sphere(3), 600, 2), "flipped-sphere");
    check_round_trip(randomly_flipped(make_square(8), 100, 3), "flipped-square");
}

TEST(BaseMeshCoder, TinyAndNonManifold) {
    TriangleMesh one;
    one.positions.resize(3);
    one.triangles = {{0, 1, 2}};
    check_round_trip(one, "single-triangle");
    TriangleMesh bowtie;
    bowtie.positions.resize(5);
    bowtie.triangles = {{0, 1, 2}, {0, 3, 4}};
    check_round_trip(bowtie, "bowtie");
    // Two icosahedra touching at one vertex: both fans closed.
    TriangleMesh twins = concatenate(make_icosahedron(), make_icosahedron());
    for (Triangle& t : twins.triangles)
        for (uint32_t& v : t)
            if (v == 12) v = 0;
    twins.positions.erase(twins.positions.begin() + 12);
    for (Triangle& t : twins.triangles)
        for (uint32_t& v : t)
            if (v > 12) --v;
    check_round_trip(twins, "icosahedra-touching");
    // Three fans around one vertex of an open square.
    TriangleMesh fans;
    fans.positions.resize(7);
    fans.triangles = {{0, 1, 2}, {0, 3, 4}, {0, 5, 6}, {0, 2, 3}};
    check_round_trip(fans, "fans");
    TriangleMesh empty;
    check_round_trip(empty, "empty");
}

// The closed mesh the cut-border coders walk: every halfedge has a twin running the other way, the
// input's triangles keep their corners (as fan copies), one dummy vertex per boundary loop.
void check_closed(const TriangleMesh& mesh, uint32_t loops, const std::string& name) {
    const ClosedMesh cm = make_closed(mesh);
    ASSERT_EQ(cm.real_triangles, mesh.triangles.size()) << name;
    ASSERT_EQ(cm.twin.size(), 3 * cm.triangles.size()) << name;
    EXPECT_EQ(cm.dummies, loops) << name;
    EXPECT_EQ(uint32_t(std::count(cm.original.begin(), cm.original.end(), kNoVertex)), loops) << name;
    for (uint32_t t = 0; t < cm.real_triangles; ++t)
        for (int k = 0; k < 3; ++k) EXPECT_EQ(cm.original[cm.triangles[t][k]], mesh.triangles[t][k]) << name;
    for (uint32_t h = 0; h < cm.twin.size(); ++h) {
        const uint32_t twin = cm.twin[h];
        ASSERT_LT(twin, cm.twin.size()) << name << " halfedge " << h;
        EXPECT_EQ(cm.twin[twin], h) << name << " halfedge " << h;
        EXPECT_EQ(cm.corner_vertex(twin), cm.corner_vertex(ClosedMesh::next_halfedge(h))) << name << " halfedge " << h;
        EXPECT_EQ(cm.corner_vertex(ClosedMesh::next_halfedge(twin)), cm.corner_vertex(h)) << name << " halfedge " << h;
    }
}

TEST(BaseMeshCoder, ClosingGivesEveryHalfedgeItsTwin) {
    check_closed(make_icosahedron(), 0, "icosahedron");
    check_closed(make_square(3), 1, "square");
    check_closed(remove_triangles(make_torus(12, 8, 2.0, 0.7), {5, 40, 41, 90}), 3, "torus-three-holes");
    TriangleMesh one;
    one.positions.resize(3);
    one.triangles = {{0, 1, 2}};
    check_closed(one, 1, "single-triangle");
    TriangleMesh fans;  // three fans around vertex 0: two boundary loops through its copies
    fans.positions.resize(7);
    fans.triangles = {{0, 1, 2}, {0, 3, 4}, {0, 5, 6}, {0, 2, 3}};
    check_closed(fans, 2, "fans");
    TriangleMesh flipped;  // a halfedge twice
    flipped.positions.resize(4);
    flipped.triangles = {{0, 1, 2}, {0, 1, 3}};
    EXPECT_THROW(make_closed(flipped), EncoderGaveUp);
}

// Mode 2 closes a mesh whose edges each have at most one halfedge per direction (fans split, holes
// filled); a halfedge twice (two triangles on an edge in the same direction) leaves it the explicit mode.
TEST(BaseMeshCoder, ModeTwoNeedsConsistentlyOrientedEdges) {
    TriangleMesh bowtie;
    bowtie.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {0, -1, 0}};
    bowtie.triangles = {{0, 1, 2}, {0, 3, 4}};
    EXPECT_EQ(encode_base_connectivity(bowtie).mode, BaseConnectivityMode::angle);
    TriangleMesh flipped;
    flipped.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}};
    flipped.triangles = {{0, 1, 2}, {0, 1, 3}};
    EXPECT_THROW(encode_base_connectivity(flipped, BaseConnectivityMode::angle), Error);
    EXPECT_EQ(encode_base_connectivity(flipped).mode, BaseConnectivityMode::explicit_triangles);
    flipped.triangles[1] = {1, 0, 3};  // oriented: a strip of two
    EXPECT_EQ(encode_base_connectivity(flipped).mode, BaseConnectivityMode::angle);
}

// Where mode 2 can not code a mesh the writer falls back to mode 0 (a few bits a vertex) before
// the explicit mode's three indices a triangle (FORMAT.md 4.16). Through `amc` that is a mesh whose
// walk passes the budget at every radius (millions of triangles); through the coder's own API a
// vertex of two triangles does it in a few: a two-sided triangle, which mode 2 does not close.
TEST(BaseMeshCoder, ModeZeroWhereModeTwoCanNot) {
    TriangleMesh pillow;
    pillow.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    pillow.triangles = {{0, 1, 2}, {0, 2, 1}};
    EXPECT_THROW(encode_base_connectivity(pillow, BaseConnectivityMode::angle), Error);
    check_round_trip(pillow, "pillow", BaseConnectivityMode::cut_border, true, false);
    const TriangleMesh with_torus = concatenate(randomly_flipped(make_torus(40, 30, 2.0, 0.7), 800, 4), pillow);
    const double bits =
        check_round_trip(with_torus, "flipped-torus+pillow", BaseConnectivityMode::cut_border, true, false);
    const size_t explicit_bytes =
        encode_base_connectivity(with_torus, BaseConnectivityMode::explicit_triangles).bytes.size();
    EXPECT_LT(bits * with_torus.positions.size() / 8, explicit_bytes / 8.0);
    EXPECT_LT(bits, 4.0);
}

// A long strip keeps a border loop as long as itself: mode 2's nearest-tip scans of the whole loop
// pass the walk budget at 9,000 triangles, mode 3's window (FORMAT.md 4.17) stays far below it,
// and where both fit (a shorter strip) mode 3 codes about as small.
TEST(BaseMeshCoder, ModeThreeWhereModeTwoWalksTooFar) {
    const TriangleMesh strip = make_irregular_strip(1500, 3, 1);
    EXPECT_THROW(encode_base_connectivity(strip, BaseConnectivityMode::angle), Error);
    const double bits = check_round_trip(strip, "irregular-strip", BaseConnectivityMode::angle_windowed);
    EXPECT_LT(bits, 1.2);
    const TriangleMesh shorter = make_irregular_strip(400, 3, 1);
    const double two = check_round_trip(shorter, "short strip mode 2", BaseConnectivityMode::angle, false);
    const double three = check_round_trip(shorter, "short strip mode 3", BaseConnectivityMode::angle_windowed, false);
    EXPECT_LT(three, two * 1.02);
}

// Mode 0's decoder scans the whole loop for each new gate, as long as the strip here: quadratic in
// the triangles, so the encoder refuses a mode-0 stream scanning more than 64 nodes a triangle plus
// 2^24, and a short strip still fits.
// Mode 0's loops are splay trees (base_cut_border.h): a strip, whose loop is as long as the
// strip, codes and decodes in it (until 2026-12-08 its decode was quadratic and the encoder
// refused it). Named apart from the sanitizers' BaseMeshCoder suite: 160,000 triangles.
TEST(LargeBaseMesh, ModeZeroCodesLongLoops) {
    const double bits = check_round_trip(make_irregular_strip(20000, 4, 1), "long strip mode 0",
                                         BaseConnectivityMode::cut_border, false);
    EXPECT_LT(bits, 2.5);  // mode 1 would spend three 17-bit indices a triangle
}

// The encoder gives up only where the decoder would refuse. Named apart from the BaseMeshCoder
// suite, which .ci/run repeats under the sanitizers: a second of work in Release.
TEST(LargeBaseMesh, MillionTriangleTorusStaysInModeTwo) {
    // At 10^6 triangles an irregular mesh's conquest walks about 13 border nodes a triangle,
    // under the decoder's budget of 16 (FORMAT.md 4.14).
    const double bits = check_round_trip(make_irregular_torus(700, 715, 1), "irregular-torus-1M");
    EXPECT_LT(bits, 2.0);
}

// Mode 0 (what format versions 1-3 wrote) and the explicit mode still round-trip: their
// decoders stay.
TEST(BaseMeshCoder, EveryModeRoundTrips) {
    const TriangleMesh torus = make_torus(12, 8, 2.0, 0.7);
    TriangleMesh bowtie;
    bowtie.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {0, -1, 0}};
    bowtie.triangles = {{0, 1, 2}, {0, 3, 4}};
    const std::vector<std::pair<std::string, TriangleMesh>> meshes = {
        {"icosahedron", make_icosahedron()},
        {"l_shape-4", make_l_shape(4)},
        {"torus-three-holes", remove_triangles(torus, {5, 40, 41, 90})},
        {"icosahedron+torus", concatenate(make_icosahedron(), make_torus(6, 5, 2.0, 0.7))},
        {"flipped-sphere", randomly_flipped(make_bumpy_sphere(2), 200, 4)},
        {"bowtie", bowtie},
    };
    for (const auto& [name, mesh] : meshes) {
        for (BaseConnectivityMode mode : {BaseConnectivityMode::angle, BaseConnectivityMode::angle_windowed,
                                          BaseConnectivityMode::cut_border, BaseConnectivityMode::explicit_triangles})
            check_round_trip(mesh, name + " mode " + std::to_string(int(mode)), mode, false);
    }
}

// Mode 2's encoder searches start triangles and gate radii (FORMAT.md 4.16): never longer than
// version 4's single try from the first input triangle, shorter on some of these meshes, and
// it does start elsewhere; the single try still round-trips.
TEST(BaseMeshCoder, ModeTwoSearchNeverLoses) {
    const TriangleMesh torus = make_torus(12, 8, 2.0, 0.7);
    const std::vector<std::pair<std::string, TriangleMesh>> meshes = {
        {"torus-three-holes", remove_triangles(torus, {5, 40, 41, 90})},
        {"icosahedron+torus", concatenate(make_icosahedron(), make_torus(6, 5, 2.0, 0.7))},
        {"flipped-sphere", randomly_flipped(make_bumpy_sphere(2), 200, 4)},
        {"flipped-torus", randomly_flipped(make_torus(16, 12, 2.0, 0.7), 300, 1)},
        {"flipped-square", randomly_flipped(make_square(8), 100, 3)},
    };
    int shorter = 0, elsewhere = 0;
    for (const auto& [name, mesh] : meshes) {
        const BaseMeshCode searched = encode_base_connectivity(mesh, BaseConnectivityMode::angle);
        const BaseMeshCode single = encode_base_connectivity(mesh, BaseConnectivityMode::angle, false);
        EXPECT_LE(searched.bytes.size(), single.bytes.size()) << name;
        EXPECT_EQ(single.triangle_order.front(), 0u) << name << ": the single try starts at the first triangle";
        shorter += searched.bytes.size() < single.bytes.size();
        elsewhere += searched.triangle_order.front() != 0;
        const DecodedBaseMesh dec = decode_with_own_positions(single, mesh);
        ASSERT_EQ(dec.triangles.size(), mesh.triangles.size()) << name;
        for (size_t t = 0; t < dec.triangles.size(); ++t) {
            const Triangle& o = mesh.triangles[single.triangle_order[t]];
            for (int k = 0; k < 3; ++k)
                EXPECT_EQ(single.vertex_order[dec.triangles[t][k]], o[(single.triangle_rotation[t] + k) % 3]) << name;
        }
    }
    EXPECT_GT(shorter, 0) << "the search never found a shorter stream";
    EXPECT_GT(elsewhere, 0) << "the search never started elsewhere";
}

// The search codes no more candidates than its budget allows: below five candidates' worth it is
// the single try; a larger budget never codes longer than a smaller one (its candidates come
// first in the same order); and the kept code does not depend on the threads.
TEST(BaseMeshCoder, ModeTwoSearchFollowsItsBudget) {
    const std::vector<std::pair<std::string, TriangleMesh>> meshes = {
        {"flipped-sphere", randomly_flipped(make_bumpy_sphere(2), 200, 4)},
        {"flipped-torus", randomly_flipped(make_torus(16, 12, 2.0, 0.7), 300, 1)},
        {"icosahedron+torus", concatenate(make_icosahedron(), make_torus(6, 5, 2.0, 0.7))},
    };
    int budget_mattered = 0;
    for (const auto& [name, mesh] : meshes) {
        const BaseMeshCode single = encode_base_connectivity(mesh, BaseConnectivityMode::angle, false);
        EXPECT_EQ(encode_base_connectivity(mesh, 1, 0).bytes, single.bytes) << name;
        const uint64_t closed = mesh.triangles.size();  // at least; a few candidates' worth of it
        const BaseMeshCode few = encode_base_connectivity(mesh, 1, 3 * closed * 8);
        const BaseMeshCode full = encode_base_connectivity(mesh, 1);
        EXPECT_LE(few.bytes.size(), single.bytes.size()) << name;
        EXPECT_LE(full.bytes.size(), few.bytes.size()) << name;
        budget_mattered += full.bytes.size() < few.bytes.size();
        const BaseMeshCode threaded = encode_base_connectivity(mesh, 2);
        EXPECT_EQ(threaded.bytes, full.bytes) << name;
        EXPECT_EQ(threaded.triangle_order, full.triangle_order) << name;
        EXPECT_EQ(threaded.vertex_order, full.vertex_order) << name;
    }
    EXPECT_GT(budget_mattered, 0) << "a few candidates did as well as the full search everywhere";
}

// Inside an .amc encode the search of a refined hierarchy's base codes at most 2^13 triangles,
// whatever the hierarchy's size, and nothing beyond the single try when that can not try one start
// in every rotation and radius (above about 180 triangles, such as a base of 600); a hierarchy that
// is at least half base gets the full budget.
TEST(BaseMeshCoder, SearchBudgetFollowsTheHierarchy) {
    Hierarchy unrefined(make_torus(40, 30, 2.0, 0.7));
    EXPECT_EQ(base_search_budget(unrefined), kFullBaseSearch);
    Hierarchy mostly_base(make_torus(40, 30, 2.0, 0.7));
    for (NodeId root = 0; root < 100; ++root) mostly_base.refine(root);
    ASSERT_GT(mostly_base.node_count(), mostly_base.root_count());
    EXPECT_EQ(base_search_budget(mostly_base), kFullBaseSearch);
    Hierarchy small(make_icosahedron());
    refine_uniformly(small, 2);
    EXPECT_EQ(base_search_budget(small), uint64_t{1} << 13);
    Hierarchy large(make_icosahedron());
    refine_uniformly(large, 7);
    EXPECT_EQ(base_search_budget(large), uint64_t{1} << 13);
    Hierarchy medium_base(make_torus(20, 15, 2.0, 0.7));  // 600 triangles
    refine_uniformly(medium_base, 1);
    ASSERT_GT(one_start_search_budget(medium_base.root_count()), uint64_t{1} << 13);
    EXPECT_EQ(base_search_budget(medium_base), 0u);
    Hierarchy large_base(make_torus(40, 30, 2.0, 0.7));  // 2,400 triangles
    refine_uniformly(large_base, 1);
    ASSERT_GT(one_start_search_budget(large_base.root_count()), uint64_t{1} << 13);
    EXPECT_EQ(base_search_budget(large_base), 0u);
    const BaseMeshCode single = encode_base_connectivity(large_base.base(), BaseConnectivityMode::angle, false);
    EXPECT_EQ(encode_base_connectivity(large_base.base(), 1, base_search_budget(large_base)).bytes, single.bytes);
}

// A mode-2 stream whose header claims more than the mesh can hold is refused before anything is
// sized by it (FORMAT.md 4.10), quickly.
TEST(BaseMeshCoder, HugeCountsAreRefused) {
    struct Claim {
        uint32_t isolated, dummies, copies, components, merges;
        const char* what;
        const char* expected;  // in the error message
    };
    const uint32_t v = 1000;
    const Claim claims[] = {
        {v + 1, 0, 0, 1, 0, "isolated vertices", "isolated"},
        {0, 0x7FFFFFFE, 0, 1, 0, "dummies", "dummy count"},
        {0, 0, 2 * v + 1, 1, 0, "copies", "copy count"},
        {0, 0, 0, 0x7FFFFFFE, 0, "components", "inconsistent counts"},
        {0, 0, 0, 1, 0x7FFFFFFE, "merges", "merge count"},
        {0, 0, 0, 0, 0, "no component with triangles", "inconsistent counts"},
    };
    for (const Claim& c : claims) {
        ArithmeticEncoder enc;
        enc.encode_bits_raw(uint32_t(BaseConnectivityMode::angle), 2);
        enc.encode_bits_raw(0, 2);  // context set
        enc.encode_bits_raw(5, 3);  // gate radius
        enc.encode_bits_raw(0, 1);  // not plain: the counts follow
        for (uint32_t x : {c.isolated, c.dummies, c.copies, c.components, c.merges}) {
            const int n = 64 - __builtin_clzll(uint64_t{x} + 1);
            enc.encode_bits_raw(0, n - 1);
            enc.encode_bits_raw(x + 1, n);
        }
        for (int i = 0; i < 64; ++i) enc.encode_bits_raw(0x5A5A5A5A, 32);  // arbitrary operations
        const std::vector<uint8_t> bytes = enc.finish();
        const auto start = std::chrono::steady_clock::now();
        std::string message;
        try {
            decode_base_mesh(bytes.data(), bytes.size(), v,
                             [](uint32_t, const BaseStencil&, const std::vector<Vec3>&) { return Vec3{}; });
        } catch (const Error& e) {
            message = e.what();
        }
        EXPECT_NE(message.find(c.expected), std::string::npos) << c.what << ": " << message;
        EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 0.5) << c.what;
    }
    // The caller's vertex count is exact: a stream of another mesh is refused.
    const TriangleMesh ico = make_icosahedron();
    const BaseMeshCode code = encode_base_connectivity(ico);
    for (uint32_t wrong : {11u, 13u, 0xFFFFFFFFu})
        EXPECT_THROW(decode_base_mesh(code.bytes.data(), code.bytes.size(), wrong, positions_of(ico, code)), Error) << wrong;
}

// The decoder order of mode 2 follows the geometry: the same connectivity with other positions
// is conquered in another order, and the position source is read in vertex order, once per
// vertex, while the connectivity is decoded.
TEST(BaseMeshCoder, ModeTwoReadsPositionsAsItGoes) {
    const TriangleMesh sphere = make_bumpy_sphere(2);
    TriangleMesh moved = sphere;
    std::mt19937 rng(3);
    for (Vec3& p : moved.positions) p = p + 0.2 * Vec3{double(rng() % 100) / 100, double(rng() % 100) / 100, 0};
    const BaseMeshCode a = encode_base_connectivity(sphere), b = encode_base_connectivity(moved);
    EXPECT_NE(a.vertex_order, b.vertex_order);
    std::vector<uint32_t> asked;
    const DecodedBaseMesh dec = decode_base_mesh(
        b.bytes.data(), b.bytes.size(), uint32_t(moved.positions.size()),
        [&](uint32_t vertex, const BaseStencil&, const std::vector<Vec3>& decoded) {
            EXPECT_EQ(decoded.size(), vertex);
            asked.push_back(vertex);
            return moved.positions[b.vertex_order[vertex]];
        });
    ASSERT_EQ(asked.size(), moved.positions.size());
    for (uint32_t i = 0; i < asked.size(); ++i) EXPECT_EQ(asked[i], i);
    EXPECT_EQ(dec.positions.size(), moved.positions.size());
}

// The base order of mode 2 depends on the positions the decoder sees, so a quantized file is
// decoded in the order of its quantized base, which in_decoder_order(h, options) reproduces.
TEST(BaseMeshCoder, QuantizedFilesFollowTheQuantizedBaseOrder) {
    Hierarchy h(randomly_flipped(make_bumpy_sphere(2), 150, 5));
    refine_randomly(h, 600, 3, 8);
    const Hierarchy lossless = in_decoder_order(h);
    int reordered = 0;
    for (int bits : {3, 4, 6, 8, 12}) {
        EncodeOptions options;
        options.quantize_bits = bits;
        const std::vector<uint8_t> bytes = encode(h, options);
        const Hierarchy back = decode(bytes.data(), bytes.size());
        const Hierarchy expected = in_decoder_order(h, options);
        EXPECT_EQ(extract_leaf_mesh(back).mesh.triangles, extract_leaf_mesh(expected).mesh.triangles) << bits;
        if (extract_leaf_mesh(expected).mesh.triangles != extract_leaf_mesh(lossless).mesh.triangles) ++reordered;
    }
    EXPECT_GT(reordered, 0) << "no quantization changed the base order: the test shows nothing";
}

// Mode 2 came with version 4: a file of an earlier version holding it is refused. Version 5 holds
// the same streams (its encoder searches more), so the blocks of a version-5 file make a valid
// version-4 file.
TEST(BaseMeshCoder, ModeTwoNeedsVersionFour) {
    Hierarchy h(make_torus(6, 5, 2.0, 0.7));
    refine_randomly(h, 100, 2, 3);
    EncodeOptions quantized;  // bit-exact adaptive levels would make version 14 (raw side streams)
    quantized.quantize_bits = 16;
    const std::vector<uint8_t> bytes = encode(h, quantized);
    BlockReader reader(bytes.data(), bytes.size());
    ASSERT_EQ(reader.version(), kSearchedBaseVersion);
    for (uint8_t version : {kBaseVersion, kNumberingVersion, kAngleBaseVersion, kSearchedBaseVersion}) {
        BlockWriter writer(version, reader.flags());
        BlockReader blocks(bytes.data(), bytes.size());
        Block block;
        while (blocks.next(block))
            if (block.type != BlockType::end) writer.add(block.type, std::vector<uint8_t>(block.payload, block.payload + block.size));
        const std::vector<uint8_t> file = writer.finish();
        if (version >= kAngleBaseVersion) {
            if (version == kSearchedBaseVersion) {
                EXPECT_EQ(file, bytes);
            }
            EXPECT_NO_THROW(decode(file.data(), file.size())) << int(version);
        } else {
            EXPECT_THROW(decode(file.data(), file.size()), Error) << int(version);
        }
    }
}

TEST(BaseMeshCoder, SharedDataMeshes) {
    namespace fs = std::filesystem;
    const fs::path dir = AMC_SHARED_DATA_DIR;
    if (!fs::is_directory(dir)) GTEST_SKIP() << "no shared data at " << dir;
    const std::set<std::string> coarse = {"bunny-base.obj",   "horse-base.obj",
                                          "rocker-arm-base.obj", "venus-coarse.off",
                                          "rabbit-coarse.off", "elephant-sr-l0.obj"};
    std::vector<fs::path> files;
    for (const auto& entry : fs::directory_iterator(dir)) {
        const std::string ext = entry.path().extension().string();
        if (ext == ".obj" || ext == ".off" || ext == ".ply") files.push_back(entry.path());
    }
    std::sort(files.begin(), files.end());
    for (const fs::path& file : files) {
        TriangleMesh mesh;
        try {
            mesh = read_mesh(file.string());
        } catch (const Error& e) {
            std::printf("[base mesh coder] %-24s skipped: %s\n", file.filename().c_str(), e.what());
            continue;
        }
        const double bpv = check_round_trip(mesh, file.filename().string());
        // Issue 30's target: at most 2 bits per vertex on the coarse irregular bases (mode 2
        // with the search of version 5 reaches 1.10-1.84, docs/BASE_CODER.md; version 4's encoder
        // 1.25-1.99, mode 0 2.5-2.95): 1.9 leaves a margin the search keeps.
        if (coarse.count(file.filename().string())) {
            EXPECT_LE(bpv, 1.9) << file;
        }
    }
}

// Every truncation and random bit flips: an Error or a well-formed result, never a crash.
void check_corruption(const TriangleMesh& mesh, const BaseMeshCode& code) {
    const uint32_t vertex_count = static_cast<uint32_t>(mesh.positions.size());
    auto try_decode = [&](const std::vector<uint8_t>& data) {
        try {
            const DecodedBaseMesh d = decode_base_mesh(data.data(), data.size(), vertex_count, positions_of(mesh, code));
            EXPECT_EQ(d.vertex_count, vertex_count);
            EXPECT_EQ(d.stencils.size(), d.vertex_count);
            EXPECT_EQ(d.positions.size(), d.vertex_count);
            for (const Triangle& t : d.triangles) {
                for (uint32_t v : t) EXPECT_LT(v, d.vertex_count);
            }
            for (size_t i = 0; i < d.stencils.size(); ++i) {
                for (int32_t s : d.stencils[i]) EXPECT_LT(s, static_cast<int32_t>(i));
            }
        } catch (const Error&) {
        }
    };
    const std::vector<uint8_t>& bytes = code.bytes;
    for (size_t n = 0; n < bytes.size(); ++n) try_decode(std::vector<uint8_t>(bytes.begin(), bytes.begin() + n));
    std::mt19937 rng(7);
    for (int i = 0; i < 2000; ++i) {
        std::vector<uint8_t> data = bytes;
        const int flips = 1 + static_cast<int>(rng() % 3);
        for (int f = 0; f < flips; ++f) data[rng() % data.size()] ^= uint8_t(1u << (rng() % 8));
        try_decode(data);
    }
    std::vector<uint8_t> longer = bytes;
    longer.insert(longer.end(), {0xFF, 0x00, 0x55});
    try_decode(longer);
}

TEST(BaseMeshCoder, CorruptStreams) {
    const TriangleMesh torus = make_torus(8, 6, 2.0, 0.7);
    const TriangleMesh mesh = concatenate(remove_triangles(torus, {3, 20}), make_square(2));
    TriangleMesh bowtie;
    bowtie.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {0, -1, 0}};
    bowtie.triangles = {{0, 1, 2}, {0, 3, 4}};
    for (BaseConnectivityMode mode : {BaseConnectivityMode::angle, BaseConnectivityMode::angle_windowed,
                                      BaseConnectivityMode::cut_border, BaseConnectivityMode::explicit_triangles}) {
        const BaseMeshCode code = encode_base_connectivity(mesh, mode);
        check_corruption(mesh, code);
        check_corruption(bowtie, encode_base_connectivity(bowtie, mode));
        EXPECT_THROW(decode_base_mesh(code.bytes.data(), code.bytes.size(), 10, positions_of(mesh, code)), Error);
    }
}

}  // namespace
}  // namespace amc

