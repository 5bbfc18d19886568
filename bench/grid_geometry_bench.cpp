// Complete quantized files with and without geometry mode 4 (docs/FORMAT.md 5.7), beside Draco's
// best setting (speed 0 = `-cl 10`) on the same quantization grid (2^bits - 1 steps over the largest
// side of the bounding box: the maximum errors agree, docs/BENCHMARKS.md), for issue 30's target of
// files 2x smaller than Draco's best at 12 and 16 bits. Sizes are exact; decode times are the best
// of --runs (CPU-bound, one thread; on a shared host compare the two amcodec columns only).
//
//   grid_geometry_bench [--runs N] corpus/*.amh
#include "compare_draco.h"

#include <amc/codec.h>
#include <amc/hierarchy.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

namespace {

double best_decode_ms(const std::vector<uint8_t>& file, int runs) {
    double best = 1e300;
    for (int r = 0; r < runs; ++r) {
        const auto start = std::chrono::steady_clock::now();
        const amc::Hierarchy back = amc::decode(file.data(), file.size());
        best = std::min(best, std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
        if (back.node_count() == 0) std::fprintf(stderr, "empty decode\n");
    }
    return best;
}

}  // namespace

int main(int argc, char** argv) {
    int runs = 3;
    std::vector<std::string> inputs;
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        if (arg == "--runs" && i + 1 < argc) runs = std::max(1, std::stoi(argv[++i]));
        else inputs.push_back(arg);
    }
    std::printf("| model | bits | Draco best bytes | amcodec bytes (mode 3 only) | grid (mode 4, the default) | geometry change | "
                "Draco / amcodec | Draco / grid | decode ms, mode 3 | grid |\n");
    std::printf("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    for (const std::string& path : inputs) {
        const amc::Hierarchy h = amc::read_hierarchy(path);
        const std::string name = std::filesystem::path(path).stem().string();
        const amc::TriangleMesh leaf = amc::extract_leaf_mesh(h).mesh;
        const auto draco_input = amc_bench::make_draco_mesh(leaf, false);
        for (int bits : {12, 16}) {
            const amc_bench::DracoEncoded draco = amc_bench::draco_encode(*draco_input, {0, bits});
            amc::EncodeOptions roles;
            roles.quantize_bits = bits;
            roles.grid_contexts = false;  // mode 3 only, the default before grid contexts
            amc::EncodeOptions grid = roles;
            grid.grid_contexts = true;  // the default
            amc::EncodeStats a, b;
            const std::vector<uint8_t> file_a = amc::encode(h, roles, &a);
            const std::vector<uint8_t> file_b = amc::encode(h, grid, &b);
            if (!amc::identical(amc::decode(file_a.data(), file_a.size()), amc::decode(file_b.data(), file_b.size()))) {
                std::fprintf(stderr, "%s: mode 4 decodes differently from mode 3\n", name.c_str());
                return 1;
            }
            const double geometry_a = double(a.geometry_bytes + a.base_geometry_bytes);
            const double geometry_b = double(b.geometry_bytes + b.base_geometry_bytes);
            std::printf("| %s | %d | %zu | %zu | %zu | %+.1f%% | %.2f | %.2f | %.0f | %.0f |\n", name.c_str(), bits, draco.bytes.size(),
                        file_a.size(), file_b.size(), 100.0 * (geometry_b - geometry_a) / geometry_a,
                        double(draco.bytes.size()) / double(file_a.size()), double(draco.bytes.size()) / double(file_b.size()),
                        best_decode_ms(file_a, runs), best_decode_ms(file_b, runs));
            std::fflush(stdout);
        }
    }
    return 0;
}
