// Base detection (leaf mesh alone -> hierarchy): known answers on uniform refinements, the
// semi-regular meshes of the shared data, and property tests over random hierarchies.
#include "hierarchy_checks.h"
#include "import/base_detection.h"
#include "import/hierarchy_from_levels.h"

#include <cstdio>
#include <filesystem>
#include <numeric>
#include <chrono>
#include <map>
#include <array>

namespace amc {
namespace {

using testing::Random;

// The mesh with its vertices renumbered, its triangles reordered and each rotated, all at random.
TriangleMesh shuffled(const TriangleMesh& mesh, uint64_t seed) {
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
        const int r = int(random.next() % 3);
        t = {order[t[size_t(r)]], order[t[size_t(r + 1) % 3]], order[t[size_t(r + 2) % 3]]};
    }
    return out;
}

TEST(BaseDetection, Explore) {
    int worse = 0, total = 0; long sum_found = 0, sum_true = 0, sum_leaf = 0;
    for (int s = 0; s < 400; ++s) {
        const auto meshes = testing::fixture_meshes();
        const auto& [name, mesh] = meshes[size_t(s) % meshes.size()];
        Random random{uint64_t(s) * 7 + 3};
        Hierarchy h(mesh);
        refine_randomly(h, 50 + uint32_t(random.next() % 2000), 2 + int(random.next() % 6), uint64_t(s), (s % 3) * 0.2);
        const LeafMesh leaf = extract_leaf_mesh(h);
        const TriangleMesh input = shuffled(leaf.mesh, uint64_t(s));
        const DetectedBase base = detect_base(input);
        try { hierarchy_from_levels(input, base, "test"); } catch (const Error& e) { std::printf("BUILD FAILED %s seed %d: %s\n", name.c_str(), s, e.what()); }
        ++total; sum_found += base.base.triangles.size(); sum_true += mesh.triangles.size(); sum_leaf += leaf.mesh.triangles.size();
        if (base.base.triangles.size() > mesh.triangles.size()) {
            ++worse;
            if (worse < 0)
                std::printf("%s seed %d: leaf %zu, true base %zu, found %zu, depth %d levels %zu\n", name.c_str(), s,
                            leaf.mesh.triangles.size(), mesh.triangles.size(), base.base.triangles.size(), h.depth(),
                            base.levels.size());
        }
    }
    std::printf("worse: %d of %d; found %ld, true %ld, leaf %ld\n", worse, total, sum_found, sum_true, sum_leaf);
}

}  // namespace
}  // namespace amc
namespace amc { namespace {
TEST(BaseDetection, Uniform) {
    for (const auto& [name, mesh] : testing::fixture_meshes()) {
        for (int levels = 1; levels <= 3; ++levels) {
            Hierarchy h(mesh);
            refine_uniformly(h, levels);
            const LeafMesh leaf = extract_leaf_mesh(h);
            const DetectedBase base = detect_base(leaf.mesh);
            std::printf("%s %d: %zu -> %zu (levels %zu)\n", name.c_str(), levels, leaf.mesh.triangles.size(), base.base.triangles.size(), base.levels.size());
        }
    }
}
}}
namespace amc { namespace {
TEST(BaseDetection, Data) {
    namespace fs = std::filesystem;
    const fs::path dir = AMC_SHARED_DATA_DIR;
    for (const char* name : {"icosphere-l3.obj", "bunny-sr-l3.obj", "bunny-sr-l2.obj", "elephant-sr-l2.obj", "bunny-sr-l0.obj", "elephant-sr-l0.obj", "bunny.obj", "horse.obj", "feline.off", "fandisk.obj", "venus.off", "mountain.obj", "camelhead.off", "bunny-hr.obj"}) {
        const TriangleMesh mesh = read_mesh((dir / name).string());
        const auto start = std::chrono::steady_clock::now();
        const TriangleMesh input = shuffled(mesh, 5);
        const DetectedBase base = detect_base(input);
        const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        const auto t1 = std::chrono::steady_clock::now();
        hierarchy_from_levels(input, base, name);
        std::printf("   build %.3f s\n", std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count());
        std::printf("%-20s %7zu -> %7zu triangles, levels %zu, %.3f s (%.2f M faces/s)\n", name, mesh.triangles.size(), base.base.triangles.size(), base.levels.size(), s, mesh.triangles.size() / s / 1e6);
    }
}
}}
