// Where a hierarchy decode's time goes: deciding every node (traversal, arithmetic decoding,
// deriving each next level) and building the Hierarchy, timed apart on the models of coder_bench.
// Besides wall time it reads the processor's counters for this thread in user space (cycles,
// instructions, branch misses) where Linux allows it: unlike time, they hardly move when other
// virtual machines load the host, so two builds can be compared with few runs.
//
//   decode_phases [--nodes N] [--runs R] [--reuse] [--naive] [--model surface|random|fe] [FILE.amh...]
//
// Without --model: surface, random and fe, in that order (see make_bench_hierarchy). Hierarchy
// files named instead (the corpus of docs/BENCHMARKS.md) are decoded in place of the models.
//
// --reuse keeps one decoder, and the hierarchy it decodes into, from run to run (as
// amc::HierarchyDecoder does): no fresh memory. Without it every run starts from nothing and
// frees its hierarchy within the build time.
//
// --naive codes the models with the naive (canonical order) traversal instead of the improved
// one (the default): what the priority order costs to decode.
#include "bench_common.h"
#include "cpu_counters.h"
#include "coding/hierarchy/hierarchy_level_coder.h"

#include <amc/hierarchy.h>
#include <amc/hierarchy_coder.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>
#include <vector>

namespace {

struct Sample {
    double ms[2];                    // decide, build
    double counts[2][kCounters];     // per phase
};

// The smallest and the median value of one figure of the samples (at least one).
struct Spread {
    double min, median;
};
template <class Figure>
Spread spread(const std::vector<Sample>& samples, Figure figure) {
    std::vector<double> values;
    for (const Sample& s : samples) values.push_back(figure(s));
    return {*std::min_element(values.begin(), values.end()), median(values)};
}

void report(const char* name, const amc::Hierarchy& h, int runs, bool reuse, const amc::HierarchyCoderOptions& options,
            const Counters& counters) {
    const std::vector<uint8_t> bytes = amc::encode_hierarchy(h, options);
    std::vector<Sample> samples;
    amc::HierarchyLevelDecoder kept;
    for (int r = 0; r < runs; ++r) {
        Sample s{};
        double c0[kCounters], c1[kCounters], c2[kCounters];
        counters.read_all(c0);
        const Clock::time_point t0 = Clock::now();
        amc::HierarchyStreamHeader header;
        const size_t header_size = amc::read_standalone_stream_header(bytes.data(), bytes.size(), header);
        std::optional<amc::HierarchyLevelDecoder> fresh;
        amc::HierarchyLevelDecoder& coder = reuse ? kept : fresh.emplace();
        coder.restart(h.base(), header, amc::HierarchyDecodeOptions().max_nodes);
        amc::ArithmeticDecoder decoder(bytes.data() + header_size, bytes.size() - header_size);
        while (!coder.done()) coder.decide_level(decoder);
        coder.finish();
        const Clock::time_point t1 = Clock::now();
        counters.read_all(c1);
        coder.hierarchy().reserve(coder.node_count(), coder.vertex_count());
        coder.build_decided_levels();
        if (coder.hierarchy().node_count() != h.node_count()) {
            std::fprintf(stderr, "decode_phases: %s decoded to %u nodes, not %u\n", name, coder.hierarchy().node_count(),
                         h.node_count());
            std::exit(1);
        }
        if (!reuse) amc::Hierarchy freed = std::move(coder.hierarchy());  // freeing it is part of building it
        const Clock::time_point t2 = Clock::now();
        counters.read_all(c2);
        s.ms[0] = std::chrono::duration<double, std::milli>(t1 - t0).count();
        s.ms[1] = std::chrono::duration<double, std::milli>(t2 - t1).count();
        for (int k = 0; k < kCounters; ++k) {
            s.counts[0][k] = c1[k] - c0[k];
            s.counts[1][k] = c2[k] - c1[k];
        }
        samples.push_back(s);
    }
    const double nodes = h.node_count();
    std::printf("%s: %u nodes, %zu bytes, %d runs%s%s (min / median)\n", name, h.node_count(), bytes.size(), runs,
                options.traversal == amc::Traversal::naive ? ", naive traversal" : "", reuse ? ", reusing the decoder" : "");
    const Spread total = spread(samples, [](const Sample& s) { return s.ms[0] + s.ms[1]; });
    std::printf("  decode  %7.1f / %7.1f ms   %5.1f / %5.1f M nodes/s\n", total.min, total.median, nodes / total.min / 1e3,
                nodes / total.median / 1e3);
    const char* const phases[2] = {"decide", "build"};
    for (int p = 0; p < 2; ++p) {
        const Spread ms = spread(samples, [p](const Sample& s) { return s.ms[p]; });
        std::printf("  %-7s %7.1f / %7.1f ms", phases[p], ms.min, ms.median);
        if (counters.available()) {
            for (int k = 0; k < kCounters; ++k) {
                const Spread c = spread(samples, [p, k](const Sample& s) { return s.counts[p][k]; });
                std::printf("   %s %.2f / %.2f M", kCounterNames[k], c.min / 1e6, c.median / 1e6);
            }
        }
        std::printf("\n");
    }
}

}  // namespace

int main(int argc, char** argv) {
    long nodes = 1000000;
    int runs = 15;
    bool reuse = false;
    amc::HierarchyCoderOptions options;
    std::string model;  // all three when empty
    std::vector<std::string> files;
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        if (arg == "--reuse") {
            reuse = true;
        } else if (arg == "--naive") {
            options.traversal = amc::Traversal::naive;
        } else if (arg == "--model" && i + 1 < argc) {
            model = argv[++i];
            if (model != "surface" && model != "random" && model != "fe") {
                std::fprintf(stderr, "decode_phases: --model is surface, random or fe, not %s\n", model.c_str());
                return 2;
            }
        } else if ((arg == "--nodes" || arg == "--runs") && i + 1 < argc) {
            const long value = std::strtol(argv[++i], nullptr, 10);
            if (value <= 0) {
                std::fprintf(stderr, "decode_phases: %s needs a positive number\n", arg.c_str());
                return 2;
            }
            if (arg == "--nodes") nodes = std::min(value, 20000000L);  // a few GB at most
            else runs = int(std::min(value, 1000L));
        } else if (!arg.empty() && arg[0] != '-') {
            files.push_back(arg);
        } else {
            std::fprintf(stderr, "usage: decode_phases [--nodes N] [--runs R] [--reuse] [--naive] [--model surface|random|fe] [FILE.amh...]\n");
            return 2;
        }
    }
    const Counters counters;
    if (!counters.available()) std::printf("(no hardware counters here: wall time only)\n");
    if (!files.empty()) {
        for (const std::string& file : files) report(file.c_str(), amc::read_hierarchy(file), runs, reuse, options, counters);
        return 0;
    }
    // The models of coder_bench.
    if (model.empty() || model == "surface")
        report("surface", make_bench_hierarchy(BenchModel::surface, nodes), runs, reuse, options, counters);
    if (model.empty() || model == "random")
        report("random", make_bench_hierarchy(BenchModel::random, nodes), runs, reuse, options, counters);
    if (model.empty() || model == "fe")
        report("fe", make_bench_hierarchy(BenchModel::fe, nodes), runs, reuse, options, counters);
}
