// Encode and decode at growing sizes (docs/BENCHMARKS.md, "Scaling"; scripts/scaling_table.sh):
// one step per process, repeated RUNS times on THREADS threads, with its wall and CPU time and
// its memory peak. Public API only; Linux (the peak is read from /proc/self/status).
//
//   scaling_bench make LEAVES OUT.amh                          a model of any size in linear time:
//                                                              random leaves of a torus refined,
//                                                              new vertices on a bumpy torus
//   scaling_bench make-mesh FACES OUT.ply                      a plain irregular mesh of about
//                                                              FACES triangles (make_irregular_torus,
//                                                              seed 1), for `amc encode` as users run it
//   scaling_bench make-strip LENGTH WIDTH OUT.ply              an irregular strip of LENGTH x WIDTH
//                                                              cells (make_irregular_strip, seed 1)
//   scaling_bench encode BITS RUNS THREADS model.amh OUT.amc   encodes (default options, BITS 0:
//                                                              lossless) and writes OUT.amc
//   scaling_bench decode RUNS THREADS FILE.amc                 decodes the file
//
// Prints one line of fields `name=value`: nodes, faces, bytes, bits per face, the median and the
// range of the wall and CPU seconds, M faces/s (CPU), the step's peak (the first run's: the peak
// over what was resident before it) in MiB and bytes per node, the process's peak in MiB, and the
// first run's CPU seconds, how many of them the system's, and its minor page faults (getrusage).
#include "bench_common.h"
#include "process_memory.h"

#include <sys/resource.h>

#include <amc/codec.h>
#include <amc/hierarchy.h>
#include <amc/refinement.h>
#include <amc/mesh_io.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <utility>
#include <string>
#include <vector>

namespace {

// The midpoint of a and b moved onto a torus (radii 1 and 0.35 about the z axis, as make_torus
// makes it) whose tube radius varies smoothly: coordinates with all their bits in use, as a
// remesh of a scanned surface has them.
amc::Vec3 on_bumpy_torus(void*, amc::Vec3 a, amc::Vec3 b) {
    const amc::Vec3 m = 0.5 * (a + b);
    const double u = std::atan2(m.y, m.x), cu = std::cos(u), su = std::sin(u);
    const double radial = m.x * cu + m.y * su - 1.0, v = std::atan2(m.z, radial);
    const double tube = 0.35 * (1 + 0.08 * std::sin(7 * u) * std::sin(5 * v) + 0.03 * std::sin(23 * u + 11 * v));
    return {(1.0 + tube * std::cos(v)) * cu, (1.0 + tube * std::cos(v)) * su, tube * std::sin(v)};
}

struct Timings {
    std::vector<double> wall, cpu;
    double step_peak = 0, process_peak = 0;  // MiB, of the first run
    double first_system = 0;                 // of the first run: system CPU seconds (part of cpu)
    long first_faults = 0;                   // and minor page faults
};

// System CPU seconds and minor page faults of the process so far.
std::pair<double, long> system_and_faults() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return {double(u.ru_stime.tv_sec) + 1e-6 * double(u.ru_stime.tv_usec), u.ru_minflt};
}

// Runs step() `runs` times, each after an untimed clear() that drops the run before's result; the
// peak is the first run's (later runs may find memory the runs before left to the allocator).
template <class Clear, class Step>
Timings run(int runs, Clear&& clear, Step&& step) {
    Timings t;
    for (int r = 0; r < runs; ++r) {
        clear();
        if (r == 0) reset_peak();
        const double before = status_mib("VmRSS");
        const std::pair<double, long> system_start = system_and_faults();
        const Clock::time_point start = Clock::now();
        const double cpu_start = cpu_seconds();
        step();
        t.cpu.push_back(cpu_seconds() - cpu_start);
        t.wall.push_back(seconds_since(start));
        if (r == 0) {
            t.process_peak = status_mib("VmHWM");
            t.step_peak = t.process_peak - before;
            const std::pair<double, long> system_end = system_and_faults();
            t.first_system = system_end.first - system_start.first;
            t.first_faults = system_end.second - system_start.second;
        }
    }
    return t;
}

void print(const char* step, uint64_t nodes, uint64_t faces, size_t bytes, const Timings& t) {
    auto low = [](std::vector<double> v) { return *std::min_element(v.begin(), v.end()); };
    auto high = [](std::vector<double> v) { return *std::max_element(v.begin(), v.end()); };
    const double cpu = median(t.cpu);
    std::printf("step=%s nodes=%llu faces=%llu bytes=%zu bits_per_face=%.3f runs=%zu wall=%.3f wall_low=%.3f "
                "wall_high=%.3f cpu=%.3f cpu_low=%.3f cpu_high=%.3f mfaces_per_s=%.2f step_peak_mib=%.1f "
                "bytes_per_node=%.1f process_peak_mib=%.1f first_cpu=%.3f first_system=%.3f first_faults=%ld\n",
                step, (unsigned long long)nodes, (unsigned long long)faces, bytes, 8.0 * double(bytes) / double(faces),
                t.cpu.size(), median(t.wall), low(t.wall), high(t.wall), cpu, low(t.cpu), high(t.cpu),
                double(faces) / cpu / 1e6, t.step_peak, t.step_peak * 1024 * 1024 / double(nodes), t.process_peak,
                t.cpu.front(), t.first_system, t.first_faults);
}

}  // namespace

int main(int argc, char** argv) {
    const std::string mode = argc > 1 ? argv[1] : "";
    if (mode == "make" && argc == 4) {
        amc::Hierarchy h(amc::make_torus(16, 24, 1.0, 0.35));
        h.set_vertex_placer(on_bumpy_torus, nullptr);
        amc::refine_randomly(h, uint32_t(std::strtoul(argv[2], nullptr, 10)), 14, 1);
        amc::write_hierarchy(argv[3], h);
        return 0;
    }
    if (mode == "make-mesh" && argc == 4) {
        const double cells = std::max(9.0, std::strtod(argv[2], nullptr) / 2);
        const int rings = std::max(3, int(std::lround(std::sqrt(cells))));
        const int segments = std::max(3, int(std::lround(cells / rings)));
        amc::write_mesh(argv[3], amc::make_irregular_torus(rings, segments, 1));
        return 0;
    }
    if (mode == "make-strip" && argc == 5) {
        amc::write_mesh(argv[4], amc::make_irregular_strip(std::atoi(argv[2]), std::atoi(argv[3]), 1));
        return 0;
    }
    if (mode == "encode" && argc == 7) {
        const amc::Hierarchy h = amc::read_hierarchy(argv[5]);
        amc::EncodeOptions options;
        options.quantize_bits = std::atoi(argv[2]);
        options.threads = unsigned(std::atoi(argv[4]));
        std::vector<uint8_t> bytes;
        amc::EncodeStats stats;
        const Timings t = run(
            std::atoi(argv[3]), [&] { std::vector<uint8_t>().swap(bytes); }, [&] { bytes = amc::encode(h, options, &stats); });
        const std::string out = argv[6], temporary = out + ".tmp";
        std::FILE* f = std::fopen(temporary.c_str(), "wb");
        if (f == nullptr || std::fwrite(bytes.data(), 1, bytes.size(), f) != bytes.size() || std::fclose(f) != 0 ||
            std::rename(temporary.c_str(), out.c_str()) != 0) {
            std::fprintf(stderr, "scaling_bench: can not write %s\n", out.c_str());
            return 1;
        }
        print("encode", h.node_count(), stats.faces, bytes.size(), t);
        return 0;
    }
    if (mode == "decode" && argc == 5) {
        const std::vector<char> file = read_exact(argv[4]);
        const uint8_t* data = reinterpret_cast<const uint8_t*>(file.data());
        const amc::FileInfo info = amc::inspect(data, file.size());
        amc::DecodeOptions options;
        options.threads = unsigned(std::atoi(argv[3]));
        options.max_nodes = UINT64_MAX;  // the largest models pass the default limit
        amc::Hierarchy h;
        const Timings t = run(
            std::atoi(argv[2]), [&] { h = amc::Hierarchy(); }, [&] { h = amc::decode(data, file.size(), options); });
        print("decode", h.node_count(), info.faces, file.size(), t);
        return 0;
    }
    std::fprintf(stderr, "usage: scaling_bench make LEAVES OUT.amh | make-mesh FACES OUT.ply | make-strip LENGTH WIDTH OUT.ply | encode BITS RUNS THREADS model.amh OUT.amc | decode RUNS THREADS FILE.amc\n");
    return 2;
}
