// Octree forests (issue 28): size per leaf of the .amq file against one raw bit per octant, the
// file p4est_save writes (built with AMC_WITH_P4EST; else p4est's per-leaf layout, 12 bytes per
// leaf in 2D and 16 in 3D, written here) and that file through xz -9 (liblzma preset 9); encode
// and decode speeds in leaves per second, and p4est_save_ext / p4est_load_ext's with p4est; the
// conforming triangle / tetrahedron meshes of the same forests (cells per leaf, extraction speed).
// Prints a Markdown table (docs/OCTREE.md). Usage: octree_bench [--runs N] [--quick]
#include <amc/mesh_io.h>
#include <amc/octree.h>

#ifdef AMC_HAVE_P4EST
#include "octree/p4est_forest.h"

#include <filesystem>
#include <fstream>
#include <iterator>
#endif

#include <lzma.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

using namespace amc;

namespace {

struct Case {
    std::string name;
    OctreeForest forest;
};

// p4est_save's per-leaf layout: per tree its leaf count (8 bytes), per leaf x, y, (z), level as
// int32 (p4est_qcoord_t), native byte order; p4est's header and connectivity left out.
std::vector<uint8_t> p4est_layout(const OctreeForest& f) {
    std::vector<uint8_t> out;
    auto put = [&out](const void* p, size_t n) { out.insert(out.end(), (const uint8_t*)p, (const uint8_t*)p + n); };
    for (uint32_t t = 0; t < f.tree_count(); ++t) {
        const uint64_t count = f.tree_offsets[t + 1] - f.tree_offsets[t];
        put(&count, 8);
        for (uint64_t i = f.tree_offsets[t]; i < f.tree_offsets[t + 1]; ++i) {
            const Octant& o = f.leaves[i];
            const int32_t level = o.level;
            put(&o.x, 4);
            put(&o.y, 4);
            if (f.dim() == 3) put(&o.z, 4);
            put(&level, 4);
        }
    }
    return out;
}

size_t xz9_size(const std::vector<uint8_t>& data) {
    std::vector<uint8_t> out(lzma_stream_buffer_bound(data.size()));
    size_t pos = 0;
    if (lzma_easy_buffer_encode(9, LZMA_CHECK_CRC64, nullptr, data.data(), data.size(), out.data(), &pos, out.size()) != LZMA_OK)
        return 0;
    return pos;
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

int main(int argc, char** argv) {
    int runs = 5;
    bool quick = false;
    for (int i = 1; i < argc; ++i) {
        if (!std::strcmp(argv[i], "--runs") && i + 1 < argc) runs = std::max(1, std::atoi(argv[++i]));
        else if (!std::strcmp(argv[i], "--quick")) quick = true;
        else {
            std::fprintf(stderr, "usage: octree_bench [--runs N] [--quick]\n");
            return 2;
        }
    }
    const int q = quick ? 3 : 0;  // levels fewer in --quick mode
    const TreeConnectivity square = brick_connectivity(2, 1, 1), bricks2 = brick_connectivity(2, 4, 2);
    const TreeConnectivity cube = brick_connectivity(3, 1, 1, 1), bricks3 = brick_connectivity(3, 2, 2, 1);
    std::vector<Case> cases;
#ifdef AMC_HAVE_P4EST
    // The forests p4est itself makes: refined by p4est_refine around the circle / sphere or the
    // front, balanced by p4est_balance, saved by p4est_save; read back through p4est_load.
    const std::string made = (std::filesystem::temp_directory_path() / "octree_bench_made.p4est").string();
    auto add = [&](std::string name, auto&& write, OctreeBalance b) {
        write(b);
        cases.push_back({name + (b == OctreeBalance::face ? ", face" : ", corner"), read_p4est_file(made)});
    };
    for (OctreeBalance b : {OctreeBalance::face, OctreeBalance::corner}) {
        add("2D circle L" + std::to_string(13 - q), [&](OctreeBalance x) { write_p4est_sphere_forest(made, square, {0.5, 0.5, 0}, 0.35, 13 - q, x); }, b);
        add("2D front 4x2 L" + std::to_string(11 - q), [&](OctreeBalance x) { write_p4est_front_forest(made, bricks2, 2.1, 11 - q, x); }, b);
        add("3D sphere L" + std::to_string(8 - q / 2),
            [&](OctreeBalance x) { write_p4est_sphere_forest(made, cube, {0.5, 0.5, 0.5}, 0.35, 8 - q / 2, x); }, b);
        add("3D front 2x2x1 L" + std::to_string(7 - q / 2), [&](OctreeBalance x) { write_p4est_front_forest(made, bricks3, 1.1, 7 - q / 2, x); },
            b);
    }
    std::filesystem::remove(made);
    const char* made_by = "p4est (p4est_refine, p4est_balance)";
#else
    auto add = [&](std::string name, OctreeForest f, OctreeBalance b) {
        cases.push_back({name + (b == OctreeBalance::face ? ", face" : ", corner"), balance_octree_forest(f, b)});
    };
    for (OctreeBalance b : {OctreeBalance::face, OctreeBalance::corner}) {
        add("2D circle L" + std::to_string(13 - q), sphere_octree_forest(square, {0.5, 0.5, 0}, 0.35, 13 - q), b);
        add("2D front 4x2 L" + std::to_string(11 - q), front_octree_forest(bricks2, 2.1, 11 - q), b);
        add("3D sphere L" + std::to_string(8 - q / 2), sphere_octree_forest(cube, {0.5, 0.5, 0.5}, 0.35, 8 - q / 2), b);
        add("3D front 2x2x1 L" + std::to_string(7 - q / 2), front_octree_forest(bricks3, 1.1, 7 - q / 2), b);
    }
    const char* made_by = "amcodec (sphere_octree_forest, front_octree_forest, balance_octree_forest)";
#endif
    // Random forests (amcodec's generator): refinement independent from octant to octant.
    cases.push_back({"2D random L" + std::to_string(11 - q) + ", face",
                     balance_octree_forest(random_octree_forest(square, 7, 0.45, 4, 11 - q), OctreeBalance::face)});
    cases.push_back({"3D random L" + std::to_string(7 - q / 2) + ", face",
                     balance_octree_forest(random_octree_forest(cube, 7, 0.3, 2, 7 - q / 2), OctreeBalance::face)});
    std::printf("Adaptive forests made by %s; random forests by amcodec.\n\n", made_by);

#ifdef AMC_HAVE_P4EST
    const char* p4est_column = "p4est_save file";
#else
    const char* p4est_column = "p4est layout";
#endif
    std::printf("| forest | leaves | octants | .amq bytes | bits/leaf | bits/octant | 1 bit/octant (bytes) | x smaller | "
                "%s (bytes) | x smaller | + xz -9 (bytes) | x smaller | encode Mleaves/s | decode Mleaves/s | "
                "p4est save Mleaves/s | p4est load Mleaves/s |\n",
                p4est_column);
    std::printf("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|---|---|---|\n");
    for (const Case& c : cases) {
        OctreeEncodeStats stats;
        std::vector<uint8_t> bytes = encode_octree_forest(c.forest, {}, &stats);
        std::vector<double> enc, dec;
        for (int r = 0; r < runs; ++r) {
            auto t0 = std::chrono::steady_clock::now();
            bytes = encode_octree_forest(c.forest);
            enc.push_back(seconds_since(t0));
            t0 = std::chrono::steady_clock::now();
            const OctreeForest back = decode_octree_forest(bytes.data(), bytes.size());
            dec.push_back(seconds_since(t0));
            if (!(back == c.forest)) {
                std::fprintf(stderr, "%s: round trip failed\n", c.name.c_str());
                return 1;
            }
        }
        std::sort(enc.begin(), enc.end());
        std::sort(dec.begin(), dec.end());
        const double leaves = double(stats.leaves);
        const double raw = std::ceil(double(stats.nodes) / 8);
        std::vector<uint8_t> p4 = p4est_layout(c.forest);
        std::string p4est_speeds = "- | -";
#ifdef AMC_HAVE_P4EST
        {
            const std::string path = (std::filesystem::temp_directory_path() / "octree_bench.p4est").string();
            std::vector<double> save, load;
            for (int r = 0; r < runs; ++r) {
                double s = 0, l = 0;
                if (c.forest.dim() == 2) time_p4est_save_load_2d(c.forest, path, &s, &l);
                else time_p4est_save_load_3d(c.forest, path, &s, &l);
                save.push_back(s);
                load.push_back(l);
            }
            std::sort(save.begin(), save.end());
            std::sort(load.begin(), load.end());
            std::ifstream in(path, std::ios::binary);
            p4.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
            std::filesystem::remove(path);
            char buf[96];
            std::snprintf(buf, sizeof buf, "%.2f-%.2f | %.2f-%.2f", double(stats.leaves) / save.back() / 1e6,
                          double(stats.leaves) / save.front() / 1e6, double(stats.leaves) / load.back() / 1e6,
                          double(stats.leaves) / load.front() / 1e6);
            p4est_speeds = buf;
        }
#endif
        const size_t xz = xz9_size(p4);
        std::printf("| %s | %llu | %llu | %zu | %.3f | %.3f | %.0f | %.1f | %zu | %.0f | %zu | %.1f | %.2f-%.2f | %.2f-%.2f | %s |\n",
                    c.name.c_str(), (unsigned long long)stats.leaves, (unsigned long long)stats.nodes, bytes.size(),
                    8.0 * bytes.size() / leaves, 8.0 * bytes.size() / double(stats.nodes), raw, raw / bytes.size(), p4.size(),
                    double(p4.size()) / bytes.size(), xz, double(xz) / bytes.size(), leaves / enc.back() / 1e6,
                    leaves / enc.front() / 1e6, leaves / dec.back() / 1e6, leaves / dec.front() / 1e6, p4est_speeds.c_str());
        std::fflush(stdout);
    }
    std::printf("\n%d runs per forest; speeds: slowest-fastest run, one core.\n", runs);

    // Per-leaf data: a smooth Float64 value without symmetries (which xz would find as repeats:
    // the forests are symmetric) and an Int32 label (inside or outside the circle / sphere) on the
    // first 2D and 3D forests.
    std::printf("\n| forest + leaf data | leaves | .amq bytes | data bytes/leaf | %s with data (bytes) | x smaller | + xz -9 "
                "(bytes) | x smaller |\n|---|---:|---:|---:|---:|---:|---:|---:|\n",
                p4est_column);
    for (size_t k : {size_t(0), size_t(2)}) {
        if (k >= cases.size()) continue;
        OctreeForest f = cases[k].forest;
        const int d = f.dim(), root = octree_root_log2(d);
        Field u, label;
        u.name = "u", label.name = "inside";
        u.association = label.association = FieldAssociation::cell;
        u.type = FieldType::float64, label.type = FieldType::int32;
        for (uint32_t t = 0; t < f.tree_count(); ++t)
            for (uint64_t i = f.tree_offsets[t]; i < f.tree_offsets[t + 1]; ++i) {
                const Octant& o = f.leaves[i];
                const double h = std::ldexp(0.5, -o.level);
                const Vec3 c = tree_point(f.connectivity, t, std::ldexp(double(o.x), -root) + h, std::ldexp(double(o.y), -root) + h,
                                          d == 3 ? std::ldexp(double(o.z), -root) + h : 0.0);
                const double r = std::sqrt((c.x - 0.5) * (c.x - 0.5) + (c.y - 0.5) * (c.y - 0.5) + (d == 3 ? (c.z - 0.5) * (c.z - 0.5) : 0.0));
                u.values.push_back(std::exp(-3 * (c.x - 0.31) * (c.x - 0.31) - 2 * (c.y - 0.47) * (c.y - 0.47) - c.z * c.z) +
                                   0.1 * c.x * c.y);
                label.integers.push_back(r < 0.35 ? 1 : 0);
            }
        f.leaf_data = {u, label};
        OctreeEncodeStats stats;
        const std::vector<uint8_t> bytes = encode_octree_forest(f, {}, &stats);
        std::vector<uint8_t> p4 = p4est_layout(f);
#ifdef AMC_HAVE_P4EST
        {
            const std::string path = (std::filesystem::temp_directory_path() / "octree_bench_data.p4est").string();
            write_p4est_file(path, f);
            std::ifstream in(path, std::ios::binary);
            p4.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
            std::filesystem::remove(path);
        }
#else
        // The layout with the data: data_size more bytes per leaf.
        p4.resize(p4.size() + f.leaves.size() * octree_leaf_data_bytes(f.leaf_data), 0);
#endif
        const size_t xz = xz9_size(p4);
        std::printf("| %s + u (Float64), inside (Int32) | %zu | %zu | %.2f | %zu | %.1f | %zu | %.1f |\n", cases[k].name.c_str(),
                    f.leaves.size(), bytes.size(), double(stats.leaf_data_bytes) / double(f.leaves.size()), p4.size(),
                    double(p4.size()) / double(bytes.size()), xz, double(xz) / double(bytes.size()));
    }

    // Conforming leaf meshes (conforming_leaf_mesh): triangles / tetrahedra without hanging nodes.
    std::printf("\n| forest, conforming | leaves | cells | cells/leaf | points | added points | extraction Mleaves/s |\n"
                "|---|---:|---:|---:|---:|---:|---|\n");
    for (const Case& c : cases) {
        ConformingLeafMesh mesh;
        std::vector<double> times;
        for (int r = 0; r < runs; ++r) {
            mesh = {};
            const auto t0 = std::chrono::steady_clock::now();
            mesh = conforming_leaf_mesh(c.forest);
            times.push_back(seconds_since(t0));
        }
        std::sort(times.begin(), times.end());
        const double leaves = double(c.forest.leaves.size());
        std::printf("| %s | %zu | %zu (%s) | %.2f | %zu | %zu | %.2f-%.2f |\n", c.name.c_str(), c.forest.leaves.size(), mesh.cell_count(),
                    mesh.dim == 2 ? "triangles" : "tetrahedra", double(mesh.cell_count()) / leaves, mesh.points.size(),
                    mesh.points.size() - mesh.corner_points, leaves / times.back() / 1e6, leaves / times.front() / 1e6);
        std::fflush(stdout);
    }
    return 0;
}
