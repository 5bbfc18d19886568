// `amc demo`: the main job on the embedded default. A procedural surface, remeshed adaptively by
// mean curvature, stored, compressed bit-exactly and quantized, decoded and checked.
#include "commands.h"

#include <amc/codec.h>
#include <amc/mesh_io.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <vector>

namespace amc::cli {

namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

constexpr int kRuns = 5;  // timed encodes and decodes of each file

double median(std::vector<double> values) {
    std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
    return values[values.size() / 2];
}

}  // namespace

void run_demo(const std::string& out_dir, const GlobalOptions& global) {
    std::filesystem::create_directories(out_dir);
    auto start = std::chrono::steady_clock::now();
    const TriangleMesh reference = make_bumpy_sphere(6);
    SurfaceRemeshOptions options;
    options.base_triangles = 300;
    options.target_faces = 100000;
    options.max_level = 7;
    Hierarchy h = remesh_adaptively(reference, options);
    const double seconds = seconds_since(start);
    const bool loud = global.verbosity > 0;
    if (loud) {
        const HierarchyStats s = compute_stats(h);
        std::printf("%-22s %7s %9s %9s %6s %9s %9s %9s %8s\n", "model", "base_f", "faces", "nodes", "levels", "red",
                    "green", "vertices", "seconds");
        std::printf("%-22s %7u %9u %9u %6u %9u %9u %9u %8.2f\n", "bumpy_sphere_mean", s.base_triangles, s.faces, s.nodes,
                    s.levels, s.red_faces, s.green_faces, s.vertices, seconds);
    }

    const std::string problem = check_invariants(h);
    if (!problem.empty()) throw Error("demo hierarchy is invalid: " + problem);
    const std::string amh = out_dir + "/demo.amh", vtu = out_dir + "/demo.vtu", amc = out_dir + "/demo.amc";
    write_hierarchy(amh, h);
    const LeafMesh leaf = extract_leaf_mesh(h);
    write_mesh(vtu, leaf.mesh, &leaf.cells);
    if (!identical(h, read_hierarchy(amh))) throw Error("demo: hierarchy read back from " + amh + " differs");
    const uint64_t raw = std::filesystem::file_size(amh);

    if (loud)
        std::printf("\n%-12s %10s %8s %10s %10s %12s %10s %10s %s\n", "coding", "bytes", "ratio", "bits/face", "conn b/f",
                    "max error", "enc Mf/s", "dec Mf/s", "check");
    for (int bits : {0, 16, 12}) {
        EncodeOptions encode_options;
        encode_options.quantize_bits = bits;
        encode_options.threads = 1;
        DecodeOptions decode_options;
        decode_options.threads = 1;
        const Hierarchy expected = in_decoder_order(h, encode_options);
        // Each timed kRuns times, its median printed: one run of a few milliseconds is at the mercy
        // of whatever else the machine does. Every run must give the same bytes.
        EncodeStats stats;
        std::vector<uint8_t> bytes;
        std::vector<double> encode_runs, decode_runs;
        Hierarchy back;
        for (int run = 0; run < kRuns; ++run) {
            auto t0 = std::chrono::steady_clock::now();
            std::vector<uint8_t> again = encode(h, encode_options, &stats);
            encode_runs.push_back(seconds_since(t0));
            if (run > 0 && again != bytes) throw Error("demo: two encodes of one hierarchy differ (" + std::to_string(bits) + " bits)");
            bytes = std::move(again);
        }
        for (int run = 0; run < kRuns; ++run) {
            auto t0 = std::chrono::steady_clock::now();
            back = decode(bytes.data(), bytes.size(), decode_options);
            decode_runs.push_back(seconds_since(t0));
        }
        const double encode_seconds = median(encode_runs), decode_seconds = median(decode_runs);
        // Bit-exact: identical to the input in the decoder's base order; quantized: the same
        // connectivity and every coordinate within the reported error.
        bool ok = back.node_count() == expected.node_count() && back.vertex_count() == expected.vertex_count();
        if (bits == 0) {
            ok = ok && identical(back, expected);
        } else {
            const std::vector<Vec3> pa = canonical_positions(back), pb = canonical_positions(expected);
            for (size_t i = 0; ok && i < pa.size(); ++i) {
                const Vec3 d = pa[i] - pb[i];
                ok = std::fabs(d.x) <= stats.max_error && std::fabs(d.y) <= stats.max_error && std::fabs(d.z) <= stats.max_error;
            }
            ok = ok && extract_leaf_mesh(back).mesh.triangles == extract_leaf_mesh(expected).mesh.triangles;
        }
        if (!ok) throw Error("demo: decoded hierarchy differs from the input (" + std::to_string(bits) + " bits)");
        if (bits == 0) write_file_atomically(amc, std::string(bytes.begin(), bytes.end()));
        const std::string name = bits == 0 ? "lossless" : std::to_string(bits) + " bits";
        if (loud)
            std::printf("%-12s %10zu %7.1fx %10.3f %10.3f %12.3g %10.2f %10.2f %s\n", name.c_str(), bytes.size(),
                        double(raw) / double(bytes.size()), 8.0 * bytes.size() / double(stats.faces),
                        8.0 * double(stats.base_connectivity_bytes + stats.hierarchy_bytes) / double(stats.faces),
                        stats.max_error, stats.faces / encode_seconds / 1e6, stats.faces / decode_seconds / 1e6,
                        bits == 0 ? "bit-exact" : "within error");
    }
    if (loud)
        std::printf("(speeds: median of %d encodes and %d decodes on one thread of this machine)\n"
                    "\nwrote %s (%ju bytes, uncompressed), %s and %s\n",
                    kRuns, kRuns, amh.c_str(), uintmax_t(raw), amc.c_str(), vtu.c_str());
}

}  // namespace amc::cli
