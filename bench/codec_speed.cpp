// Sizes and speeds of complete .amc files, per model (docs/CODEC.md, "Geometry"): each hierarchy
// encoded and decoded RUNS times in turn with the public API, one thread; prints bytes, bits per
// vertex and encode / decode million faces per second as median [min - max], over the process's
// CPU time (on a shared machine wall time mostly measures the other processes); then the
// hierarchy stream alone (encode_hierarchy / decode_hierarchy of the same hierarchy) is decoded as
// often, and "positions" is the faces over the difference of the medians: the time decoding spends
// on everything but the connectivity (base and refinement positions, the file's framing).
// Uses only the public API, so the same source builds against an older library for side-by-side
// runs (scripts/codec_speed_table.sh).
//   codec_speed RUNS BITS model.amh ...      (BITS 0: bit-exact)
#include <amc/codec.h>
#include <amc/hierarchy.h>
#include <amc/hierarchy_coder.h>

#include "bench_common.h"

#include <algorithm>
#include <ctime>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

namespace {

}  // namespace

int main(int argc, char** argv) {
    if (argc < 4) {
        std::fprintf(stderr, "usage: codec_speed RUNS BITS model.amh ...\n");
        return 2;
    }
    const int runs = std::max(1, std::atoi(argv[1]));
    amc::EncodeOptions options;
    options.quantize_bits = std::atoi(argv[2]);
    // PREDICTOR=1, 2, ...: a fixed geometry predictor (amc::GeometryPredictor) instead of automatic.
    if (const char* p = std::getenv("PREDICTOR")) options.predictor = amc::GeometryPredictor(std::atoi(p));
    std::printf("| model | bits | faces | bytes | bits/vertex | encode M faces/s | decode M faces/s | connectivity alone M faces/s | positions M faces/s |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    for (int a = 3; a < argc; ++a) {
        const amc::Hierarchy h = amc::read_hierarchy(argv[a]);
        std::vector<double> encode_rate, decode_rate, hierarchy_rate, decode_seconds_all, hierarchy_seconds_all;
        const std::vector<uint8_t> stream = amc::encode_hierarchy(h);
        std::vector<uint8_t> bytes;
        amc::EncodeStats stats;
        for (int r = 0; r < runs; ++r) {
            double start = cpu_seconds();
            bytes = amc::encode(h, options, &stats);
            const double encode_seconds = cpu_seconds() - start;
            double decode_seconds = 0;
            {  // the decoded hierarchy is freed before the next timing, so each starts alike
                start = cpu_seconds();
                const amc::Hierarchy back = amc::decode(bytes.data(), bytes.size());
                decode_seconds = cpu_seconds() - start;
                if (back.node_count() != h.node_count()) {
                    std::fprintf(stderr, "%s: decoded %u nodes, expected %u\n", argv[a], unsigned(back.node_count()), unsigned(h.node_count()));
                    return 1;
                }
            }
            start = cpu_seconds();
            const amc::Hierarchy alone = amc::decode_hierarchy(h.base(), stream.data(), stream.size());
            const double hierarchy_seconds = cpu_seconds() - start;
            if (alone.node_count() != h.node_count()) return 1;
            decode_seconds_all.push_back(decode_seconds);
            hierarchy_seconds_all.push_back(hierarchy_seconds);
            hierarchy_rate.push_back(double(stats.faces) / hierarchy_seconds * 1e-6);
            encode_rate.push_back(double(stats.faces) / encode_seconds * 1e-6);
            decode_rate.push_back(double(stats.faces) / decode_seconds * 1e-6);
        }
        const Range e = range_of(encode_rate), d = range_of(decode_rate), c = range_of(hierarchy_rate);
        const double positions_seconds = range_of(decode_seconds_all).median - range_of(hierarchy_seconds_all).median;
        std::printf("| %s | %d | %llu | %zu | %.2f | %.2f [%.2f-%.2f] | %.2f [%.2f-%.2f] | %.2f [%.2f-%.2f] | %.1f |\n",
                    std::filesystem::path(argv[a]).stem().string().c_str(), options.quantize_bits,
                    (unsigned long long)stats.faces, bytes.size(), 8.0 * double(bytes.size()) / double(stats.vertices), e.median,
                    e.low, e.high, d.median, d.low, d.high, c.median, c.low, c.high,
                    positions_seconds > 0 ? double(stats.faces) / positions_seconds * 1e-6 : 0.0);
        std::fflush(stdout);
    }
    return 0;
}
