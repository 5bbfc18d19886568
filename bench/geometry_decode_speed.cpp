// Decode speed of the geometry modes side by side (docs/CODEC.md, "Geometry mode 4"): each model
// encoded once per mode, then RUNS rounds in which every file is decoded once, in turn, so that a
// change of the machine's load hits all modes alike. Prints per file the median [min - max] of the
// process's CPU time as million faces per second, the user-space cycles of the decoding thread
// (median, where Linux allows reading them) and their ratio to the first mode's.
//   geometry_decode_speed RUNS BITS MODES model.amh ...
// MODES: comma-separated, each 3 (geometry mode 3 forced), 4 (mode 4 forced), auto (the default
// encoder: the automatic choice with grid contexts) or auto-roles (the automatic choice without
// them, the default before); for example auto-roles,auto.
#include <amc/codec.h>
#include <amc/hierarchy.h>

#include "bench_common.h"
#include "cpu_counters.h"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

namespace {

bool parse_mode(const std::string& name, amc::EncodeOptions& options) {
    if (name == "3" || name == "4") {
        options.predictor = amc::GeometryPredictor(std::stoi(name));
    } else if (name == "auto" || name == "auto-roles") {
        options.grid_contexts = name == "auto";
    } else {
        return false;
    }
    return true;
}

struct Coded {
    std::string mode;
    std::vector<uint8_t> bytes;
    std::vector<double> seconds, cycles;
};

}  // namespace

int main(int argc, char** argv) {
    if (argc < 5) {
        std::fprintf(stderr, "usage: geometry_decode_speed RUNS BITS MODES model.amh ...   (MODES e.g. 3,4)\n");
        return 2;
    }
    const int runs = std::max(1, std::atoi(argv[1]));
    const int bits = std::atoi(argv[2]);
    std::vector<std::string> modes;
    std::stringstream list(argv[3]);
    for (std::string m; std::getline(list, m, ',');) modes.push_back(m);
    const Counters counters;
    std::printf("| model | bits | mode | bytes | decode M faces/s (CPU time) | M cycles | cycles / first mode's |\n"
                "|---|---:|---|---:|---:|---:|---:|\n");
    for (int a = 4; a < argc; ++a) {
        const amc::Hierarchy h = amc::read_hierarchy(argv[a]);
        std::vector<Coded> files;
        amc::EncodeStats stats;
        for (const std::string& m : modes) {
            amc::EncodeOptions options;
            options.quantize_bits = bits;
            options.threads = 1;
            if (!parse_mode(m, options)) {
                std::fprintf(stderr, "geometry_decode_speed: unknown mode %s (3, 4, auto, auto-roles)\n", m.c_str());
                return 2;
            }
            files.push_back({m, amc::encode(h, options, &stats), {}, {}});
        }
        amc::DecodeOptions decode_options;
        decode_options.threads = 1;
        for (int r = 0; r < runs; ++r) {
            for (Coded& f : files) {
                double before[kCounters], after[kCounters];
                counters.read_all(before);
                const double start = cpu_seconds();
                {  // freed within the timing, as codec_speed's decode
                    const amc::Hierarchy back = amc::decode(f.bytes.data(), f.bytes.size(), decode_options);
                    if (back.node_count() != h.node_count()) {
                        std::fprintf(stderr, "%s: decoded %u nodes, expected %u\n", argv[a], back.node_count(), h.node_count());
                        return 1;
                    }
                }
                f.seconds.push_back(cpu_seconds() - start);
                counters.read_all(after);
                f.cycles.push_back(after[0] - before[0]);
            }
        }
        const double first_cycles = median(files.front().cycles);
        for (const Coded& f : files) {
            std::vector<double> rate;
            for (double s : f.seconds) rate.push_back(double(stats.faces) / s * 1e-6);
            const Range d = range_of(rate);
            std::printf("| %s | %d | %s | %zu | %.2f [%.2f-%.2f] |", std::filesystem::path(argv[a]).stem().string().c_str(), bits,
                        f.mode.c_str(), f.bytes.size(), d.median, d.low, d.high);
            if (counters.available())
                std::printf(" %.2f | %.3f |\n", median(f.cycles) * 1e-6, median(f.cycles) / first_cycles);
            else
                std::printf(" n/a | n/a |\n");
        }
        std::fflush(stdout);
    }
    return 0;
}
