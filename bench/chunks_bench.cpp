// Chunked .amc files (docs/CODEC.md, "Chunks"): what chunking costs in bytes, per model, and what
// threads buy in encode and decode time. Public API only.
//
//   chunks_bench sizes BITS model.amh ...          bytes with 1 chunk, the default chunks, and 2, 4, 8
//                                                  chunks; every chunked file checked to decode
//                                                  identical to the unchunked one
//   chunks_bench speed RUNS BITS CHUNKS model.amh  wall and CPU time of encode and decode (without and
//                                                  through a DecodeContext) with 1 and
//                                                  with 2 threads (CHUNKS 0: the default count), runs
//                                                  interleaved; median [min - max] and the ratio of
//                                                  each run's pair (on a shared machine the load
//                                                  moves: pairs taken a second apart compare best)
//   chunks_bench speed-threads RUNS BITS model.amh the loop of `speed` (default chunks), each call's
//                                                  CPU time and minor faults per thread (Linux:
//                                                  /proc/self/task): the calling thread, the
//                                                  threads alive after the call (the pool's
//                                                  helpers) and those that ended during it
//   chunks_bench decode-speed RUNS BITS model.amh  decodes only: RUNS pairs of a 1- and a 2-thread
//                                                  decode, 0.2 s apart (for chrt -f: see decode_speed),
//                                                  without and with a DecodeContext
//   chunks_bench decode-rusage RUNS recycle|keep|free file.amc
//                                                  RUNS pairs of a 1- and a 2-thread decode through
//                                                  a DecodeContext each (results recycled or not),
//                                                  or without one (free): wall, user and system
//                                                  time and faults per decode
//   chunks_bench encode-rusage RUNS BITS [context] model.amh
//                                                  RUNS pairs of a 1- and a 2-thread encode (default
//                                                  options), 0.2 s apart: the same per encode
//                                                  (through one EncodeContext a thread count
//                                                  with `context`)
//   chunks_bench vcpu-speeds SECONDS [BITS model.amh]
//                                                  a chain of multiplies, random reads of 32 MiB of
//                                                  fresh memory (mapped, written, read, unmapped) and
//                                                  of 32 MiB kept from the start, with a model then a
//                                                  one-thread decode of its file, back to back on each
//                                                  of the first two processors at once, one thread
//                                                  pinned to each: per second each processor's median
//                                                  CPU time for each and their ratio (under chrt -f)
//   chunks_bench alone-together encode|decode BITS SECONDS model.amh
//                                                  two processes: this one codes on one thread back
//                                                  to back, a forked copy does the same in even
//                                                  seconds and sleeps in odd ones; the median thread
//                                                  CPU time of this one's calls in each kind of second
//                                                  (does a second process doing the same slow it?)
//   chunks_bench repeat encode|decode RUNS THREADS BITS model.amh
//                                                  encodes the model once (default options, one
//                                                  thread; warm_up_encode), then encodes or decodes
//                                                  it RUNS times on THREADS threads: the process to
//                                                  profile (scripts/serial_fraction.sh)
//   chunks_bench decode-file RUNS THREADS [context] file.amc
//                                                  decodes the file RUNS times on THREADS threads
//                                                  (through one DecodeContext with `context`, each
//                                                  result recycled into it) and
//                                                  prints an FNV-1a hash of the decoded nodes and
//                                                  positions (equal on every thread count): the
//                                                  process to count instructions of (callgrind)
#include <amc/codec.h>
#include <amc/hierarchy.h>

#include "bench_common.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <dirent.h>
#include <pthread.h>
#include <sched.h>
#include <signal.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

namespace {

double now() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

std::string name_of(const char* path) { return std::filesystem::path(path).stem().string(); }

// Minor page faults of the whole process so far (every thread's): a decode's fresh memory.
double minor_faults() {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return double(usage.ru_minflt);
}

int sizes(int bits, int argc, char** argv) {
    std::printf("| model | faces | 1 chunk bytes | default: chunks | bytes | cost | 2 chunks | 4 chunks | 8 chunks |\n"
                "|---|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    for (int a = 0; a < argc; ++a) {
        const amc::Hierarchy h = amc::read_hierarchy(argv[a]);
        amc::EncodeOptions options;
        options.quantize_bits = bits;
        options.chunks = 1;
        amc::EncodeStats stats;
        const std::vector<uint8_t> one = amc::encode(h, options, &stats);
        const amc::Hierarchy expected = amc::decode(one.data(), one.size());
        auto chunked = [&](uint32_t chunks, size_t* count) {
            amc::EncodeOptions o = options;
            o.chunks = chunks;
            const std::vector<uint8_t> bytes = amc::encode(h, o);
            if (!amc::identical(amc::decode(bytes.data(), bytes.size()), expected)) {
                std::fprintf(stderr, "%s: %u chunks do not decode to the unchunked hierarchy\n", argv[a], chunks);
                std::exit(1);
            }
            if (count != nullptr) *count = std::max<size_t>(1, amc::inspect(bytes.data(), bytes.size()).chunks.size());
            return double(bytes.size());
        };
        size_t default_count = 0;
        const double base = double(one.size());
        const double by_default = chunked(0, &default_count);
        std::printf("| %s | %lu | %zu | %zu | %.0f | %+.2f %% | %+.2f %% | %+.2f %% | %+.2f %% |\n", name_of(argv[a]).c_str(),
                    (unsigned long)stats.faces, one.size(), default_count, by_default, 100 * (by_default / base - 1),
                    100 * (chunked(2, nullptr) / base - 1), 100 * (chunked(4, nullptr) / base - 1),
                    100 * (chunked(8, nullptr) / base - 1));
        std::fflush(stdout);
    }
    return 0;
}

int speed(int runs, int bits, uint32_t chunks, const char* path) {
    const amc::Hierarchy h = amc::read_hierarchy(path);
    amc::EncodeOptions options;
    options.quantize_bits = bits;
    options.chunks = chunks;
    amc::EncodeStats stats;
    const std::vector<uint8_t> bytes = amc::encode(h, options, &stats);
    const amc::FileInfo info = amc::inspect(bytes.data(), bytes.size());
    std::vector<double> encode_time[2], decode_time[2], encode_cpu[2], decode_cpu[2], encode_ratio, decode_ratio,
        decode_faults[2], kept_time[2], kept_cpu[2], kept_ratio, kept_faults[2];
    amc::DecodeContext contexts[2];  // one a thread count, kept through the runs
    for (int r = 0; r < runs; ++r) {
        double seconds[2][3], cpu[2][3];
        for (unsigned threads : {1u, 2u}) {
            amc::EncodeOptions o = options;
            o.threads = threads;
            double start = now(), cpu_start = cpu_seconds();
            const std::vector<uint8_t> again = amc::encode(h, o);
            seconds[threads - 1][0] = now() - start;
            cpu[threads - 1][0] = cpu_seconds() - cpu_start;
            if (again != bytes) {
                std::fprintf(stderr, "%s: %u threads wrote other bytes\n", path, threads);
                return 1;
            }
            amc::DecodeOptions d;
            d.threads = threads;
            start = now();
            cpu_start = cpu_seconds();
            const double faults_start = minor_faults();
            {
                const amc::Hierarchy back = amc::decode(bytes.data(), bytes.size(), d);
                seconds[threads - 1][1] = now() - start;
                cpu[threads - 1][1] = cpu_seconds() - cpu_start;
                decode_faults[threads - 1].push_back(minor_faults() - faults_start);
                if (back.node_count() != h.node_count()) return 1;
            }
            start = now();
            cpu_start = cpu_seconds();
            const double kept_faults_start = minor_faults();
            {
                const amc::Hierarchy back = amc::decode(contexts[threads - 1], bytes.data(), bytes.size(), d);
                seconds[threads - 1][2] = now() - start;
                cpu[threads - 1][2] = cpu_seconds() - cpu_start;
                kept_faults[threads - 1].push_back(minor_faults() - kept_faults_start);
                if (back.node_count() != h.node_count()) return 1;
            }
        }
        for (int t = 0; t < 2; ++t) {
            encode_time[t].push_back(seconds[t][0]);
            decode_time[t].push_back(seconds[t][1]);
            encode_cpu[t].push_back(cpu[t][0]);
            decode_cpu[t].push_back(cpu[t][1]);
            kept_time[t].push_back(seconds[t][2]);
            kept_cpu[t].push_back(cpu[t][2]);
        }
        encode_ratio.push_back(seconds[0][0] / seconds[1][0]);
        decode_ratio.push_back(seconds[0][1] / seconds[1][1]);
        kept_ratio.push_back(seconds[0][2] / seconds[1][2]);
    }
    std::printf("%s: %lu faces, %zu bytes, %zu chunks, %d runs (wall time, seconds: median [min - max])\n", name_of(path).c_str(),
                (unsigned long)stats.faces, bytes.size(), std::max<size_t>(1, info.chunks.size()), runs);
    auto line = [&](const char* what, std::vector<double>* time, std::vector<double>* cpu, const std::vector<double>& ratio) {
        const Range one = range_of(time[0]), two = range_of(time[1]), r = range_of(ratio);
        const Range cpu_one = range_of(cpu[0]), cpu_two = range_of(cpu[1]);
        std::printf("  %s: 1 thread %.3f [%.3f - %.3f] (%.2f M faces/s), 2 threads %.3f [%.3f - %.3f] (%.2f M faces/s); "
                    "speed-up per run %.2f [%.2f - %.2f]; CPU time 1 thread %.3f [%.3f - %.3f], 2 threads %.3f [%.3f - %.3f]\n",
                    what, one.median, one.low, one.high, stats.faces / one.median / 1e6, two.median, two.low, two.high,
                    stats.faces / two.median / 1e6, r.median, r.low, r.high, cpu_one.median, cpu_one.low, cpu_one.high,
                    cpu_two.median, cpu_two.low, cpu_two.high);
    };
    line("encode", encode_time, encode_cpu, encode_ratio);
    line("decode", decode_time, decode_cpu, decode_ratio);
    line("decode through a DecodeContext", kept_time, kept_cpu, kept_ratio);
    auto faults_line = [](const char* what, std::vector<double>* faults) {
        const Range one = range_of(faults[0]), two = range_of(faults[1]);
        std::printf("  minor page faults per %s: 1 thread %.0f [%.0f - %.0f], 2 threads %.0f [%.0f - %.0f] (median [min - max])\n",
                    what, one.median, one.low, one.high, two.median, two.low, two.high);
    };
    faults_line("decode", decode_faults);
    faults_line("decode through a DecodeContext", kept_faults);
    return 0;
}

// CPU seconds (schedstat: on the processor, faults' kernel time included) and minor faults of
// each live thread of the process, by thread id.
struct ThreadUse {
    double cpu = 0, faults = 0;
};
std::map<int, ThreadUse> thread_use() {
    std::map<int, ThreadUse> use;
    DIR* tasks = opendir("/proc/self/task");
    if (tasks == nullptr) return use;
    while (const dirent* entry = readdir(tasks)) {
        if (entry->d_name[0] == '.') continue;
        const std::string dir = std::string("/proc/self/task/") + entry->d_name;
        ThreadUse u;
        std::ifstream stat(dir + "/stat");
        std::string line, field;
        std::getline(stat, line);
        const size_t name_end = line.rfind(')');
        if (name_end == std::string::npos) continue;
        std::istringstream fields(line.substr(name_end + 2));
        for (int i = 3; i <= 10; ++i) fields >> field;  // field 10: minflt
        u.faults = std::atof(field.c_str());
        std::ifstream schedstat(dir + "/schedstat");
        double nanoseconds = 0;
        schedstat >> nanoseconds;
        u.cpu = 1e-9 * nanoseconds;
        use[std::atoi(entry->d_name)] = u;
    }
    closedir(tasks);
    return use;
}

// What one call cost, per thread: the calling thread, the threads alive after it (helpers), the
// threads that ended during it (the process's totals less the live threads').
struct CallUse {
    double wall = 0, caller_cpu = 0, helper_cpu = 0, ended_cpu = 0, caller_faults = 0, helper_faults = 0, ended_faults = 0;
};
template <class Op>
CallUse measure_call(Op&& op) {
    const int caller = int(getpid());
    const std::map<int, ThreadUse> before = thread_use();
    const double faults_before = minor_faults(), cpu_before = cpu_seconds(), start = now();
    op();
    CallUse use;
    use.wall = now() - start;
    const double cpu = cpu_seconds() - cpu_before, faults = minor_faults() - faults_before;
    for (const auto& [tid, after] : thread_use()) {
        const auto was = before.find(tid);
        const ThreadUse base = was == before.end() ? ThreadUse() : was->second;
        (tid == caller ? use.caller_cpu : use.helper_cpu) += after.cpu - base.cpu;
        (tid == caller ? use.caller_faults : use.helper_faults) += after.faults - base.faults;
    }
    use.ended_cpu = std::max(0.0, cpu - use.caller_cpu - use.helper_cpu);
    use.ended_faults = std::max(0.0, faults - use.caller_faults - use.helper_faults);
    return use;
}

int speed_threads(int runs, int bits, const char* path) {
    const amc::Hierarchy h = amc::read_hierarchy(path);
    amc::EncodeOptions options;
    options.quantize_bits = bits;
    const std::vector<uint8_t> bytes = amc::encode(h, options);
    amc::DecodeContext contexts[2];
    const char* const names[3] = {"encode", "decode", "decode through a DecodeContext"};
    std::vector<CallUse> uses[3][2];
    std::vector<double> ratio[3];
    for (int r = 0; r < runs; ++r) {
        for (unsigned threads : {1u, 2u}) {
            amc::EncodeOptions o = options;
            o.threads = threads;
            amc::DecodeOptions d;
            d.threads = threads;
            uses[0][threads - 1].push_back(measure_call([&] {
                if (amc::encode(h, o) != bytes) std::abort();
            }));
            uses[1][threads - 1].push_back(measure_call([&] { amc::Hierarchy back = amc::decode(bytes.data(), bytes.size(), d); }));
            uses[2][threads - 1].push_back(
                measure_call([&] { amc::Hierarchy back = amc::decode(contexts[threads - 1], bytes.data(), bytes.size(), d); }));
        }
        for (int k = 0; k < 3; ++k) ratio[k].push_back(uses[k][0].back().wall / uses[k][1].back().wall);
    }
    std::printf("%s, %d bits, %d runs (medians; CPU s and minor faults of the calling thread, of the helpers alive after the "
                "call, of the threads that ended in it)\n",
                name_of(path).c_str(), bits, runs);
    for (int k = 0; k < 3; ++k)
        for (int t = 0; t < 2; ++t) {
            auto m = [&](double CallUse::*field) {
                std::vector<double> v;
                for (const CallUse& u : uses[k][t]) v.push_back(u.*field);
                return median(v);
            };
            std::printf("  %s, %d thread%s: wall %.4f s; CPU caller %.4f, helpers %.4f, ended %.4f; faults caller %.0f, helpers "
                        "%.0f, ended %.0f",
                        names[k], t + 1, t ? "s" : "", m(&CallUse::wall), m(&CallUse::caller_cpu), m(&CallUse::helper_cpu),
                        m(&CallUse::ended_cpu), m(&CallUse::caller_faults), m(&CallUse::helper_faults), m(&CallUse::ended_faults));
            if (t == 1) std::printf("; speed-up per run %.2f", median(ratio[k]));
            std::printf("\n");
        }
    return 0;
}

// Decodes only, RUNS rounds of a 1- and a 2-thread decode without a context, then a 1- and a
// 2-thread decode each through its own DecodeContext (kept from round to round), each after a
// pause of 0.2 s: under a real-time policy (chrt -f, so that other sessions' load does not take
// the cores) the pauses keep the process within the kernel's real-time budget (95 % of each
// second by default), which would otherwise stop it for tens of milliseconds in the middle of a run.
int decode_speed(int runs, int bits, const char* path) {
    const amc::Hierarchy h = amc::read_hierarchy(path);
    amc::EncodeOptions options;
    options.quantize_bits = bits;
    const std::vector<uint8_t> bytes = amc::encode(h, options);
    const amc::FileInfo info = amc::inspect(bytes.data(), bytes.size());
    amc::DecodeContext contexts[2];
    std::vector<double> wall[2][2], cpu[2][2], ratio[2], faults[2][2];
    for (int r = 0; r < runs; ++r) {
        for (int kept : {0, 1}) {
            double seconds[2];
            for (unsigned threads : {1u, 2u}) {
                std::this_thread::sleep_for(std::chrono::milliseconds(200));
                amc::DecodeOptions d;
                d.threads = threads;
                const double start = now(), cpu_start = cpu_seconds(), faults_start = minor_faults();
                const amc::Hierarchy back = kept ? amc::decode(contexts[threads - 1], bytes.data(), bytes.size(), d)
                                                 : amc::decode(bytes.data(), bytes.size(), d);
                seconds[threads - 1] = now() - start;
                wall[kept][threads - 1].push_back(seconds[threads - 1]);
                cpu[kept][threads - 1].push_back(cpu_seconds() - cpu_start);
                faults[kept][threads - 1].push_back(minor_faults() - faults_start);
                if (back.node_count() != h.node_count()) return 1;
            }
            ratio[kept].push_back(seconds[0] / seconds[1]);
        }
    }
    for (int kept : {0, 1}) {
        const Range one = range_of(wall[kept][0]), two = range_of(wall[kept][1]), r = range_of(ratio[kept]);
        std::printf("%s, %d bits, %s: %zu bytes, %zu chunks, %d pairs of decodes: wall 1 thread %.4f [%.4f - %.4f] s, 2 threads "
                    "%.4f [%.4f - %.4f] s, speed-up per pair %.2f [%.2f - %.2f]; CPU 1 thread %.4f, 2 threads %.4f s; minor page "
                    "faults 1 thread %.0f, 2 threads %.0f (medians)\n",
                    name_of(path).c_str(), bits, kept ? "with a DecodeContext" : "no context", bytes.size(),
                    std::max<size_t>(1, info.chunks.size()), runs, one.median, one.low, one.high, two.median, two.low, two.high,
                    r.median, r.low, r.high, median(cpu[kept][0]), median(cpu[kept][1]), median(faults[kept][0]),
                    median(faults[kept][1]));
    }
    return 0;
}

// Wall, user and system time and minor faults of each of RUNS pairs of a 1- and a 2-thread call of
// op(threads), 0.2 s apart (for chrt -f), then their medians and the per-pair speed-up. `what`
// names the runs.
template <class Op>
int rusage_pairs(int runs, const std::string& what, Op&& op) {
    std::vector<double> wall[2], user[2], system[2], faults[2], ratio;
    auto seconds = [](const timeval& t) { return double(t.tv_sec) + 1e-6 * double(t.tv_usec); };
    for (int r = 0; r < runs; ++r) {
        for (unsigned threads : {1u, 2u}) {
            std::this_thread::sleep_for(std::chrono::milliseconds(200));
            rusage before{}, after{};
            getrusage(RUSAGE_SELF, &before);
            const double start = now();
            if (!op(threads)) return 1;
            wall[threads - 1].push_back(now() - start);
            getrusage(RUSAGE_SELF, &after);
            user[threads - 1].push_back(seconds(after.ru_utime) - seconds(before.ru_utime));
            system[threads - 1].push_back(seconds(after.ru_stime) - seconds(before.ru_stime));
            faults[threads - 1].push_back(double(after.ru_minflt - before.ru_minflt));
            std::printf("%u thread%s: wall %.4f s, user %.4f s, system %.4f s, %.0f minor faults\n", threads, threads > 1 ? "s" : "",
                        wall[threads - 1].back(), user[threads - 1].back(), system[threads - 1].back(), faults[threads - 1].back());
        }
        ratio.push_back(wall[0].back() / wall[1].back());
    }
    for (int t = 0; t < 2; ++t)
        std::printf("%s, %d thread%s: medians wall %.4f s, user %.4f s, system %.4f s, %.0f minor faults\n", what.c_str(), t + 1,
                    t ? "s" : "", median(wall[t]), median(user[t]), median(system[t]), median(faults[t]));
    const Range r = range_of(ratio);
    std::printf("speed-up per pair %.2f [%.2f - %.2f]\n", r.median, r.low, r.high);
    return 0;
}

// RUNS pairs of a 1- and a 2-thread decode of the file, each through its own DecodeContext (results
// recycled into it or kept by the caller), or without a context (`free`).
int decode_rusage(int runs, const std::string& mode, const char* path) {
    std::ifstream in(path, std::ios::binary);
    const std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    amc::DecodeContext contexts[2];
    const std::string what = name_of(path) + (mode == "recycle" ? ", results recycled" : mode == "free" ? ", no context" : "");
    return rusage_pairs(runs, what, [&](unsigned threads) {
        amc::DecodeOptions d;
        d.threads = threads;
        amc::Hierarchy back = mode == "free" ? amc::decode(bytes.data(), bytes.size(), d)
                                             : amc::decode(contexts[threads - 1], bytes.data(), bytes.size(), d);
        if (mode == "recycle") contexts[threads - 1].recycle(std::move(back));
        return true;
    });
}

// RUNS pairs of a 1- and a 2-thread encode of the model (default options at BITS), each checked
// to write the bytes of the first one; with `kept`, each through its own EncodeContext.
int encode_rusage(int runs, int bits, bool kept, const char* path) {
    const amc::Hierarchy h = amc::read_hierarchy(path);
    amc::EncodeOptions options;
    options.quantize_bits = bits;
    const std::vector<uint8_t> bytes = amc::encode(h, options);
    amc::EncodeContext contexts[2];
    const std::string what = name_of(path) + ", " + std::to_string(bits) + " bits, encode" + (kept ? " with an EncodeContext" : "");
    return rusage_pairs(runs, what, [&](unsigned threads) {
        amc::EncodeOptions o = options;
        o.threads = threads;
        if ((kept ? amc::encode(contexts[threads - 1], h, o) : amc::encode(h, o)) == bytes) return true;
        std::fprintf(stderr, "%s: %u threads wrote other bytes\n", path, threads);
        return false;
    });
}

// The rulers of vcpu-speeds: 300,000 random reads of 32 MiB offered to huge pages, either fresh
// (mapped, written a word a page, read, unmapped: a decode's output and working memory are fresh)
// or kept (mapped and written once; then only read).
struct HugeBuffer {
    static constexpr size_t kBytes = size_t(32) << 20, kHuge = size_t(2) << 20, kCount = kBytes / sizeof(uint64_t);
    void* mapping = nullptr;
    uint64_t* words = nullptr;
    HugeBuffer() {
        mapping = mmap(nullptr, kBytes + kHuge, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
        if (mapping == MAP_FAILED) std::abort();
        words = reinterpret_cast<uint64_t*>((reinterpret_cast<uintptr_t>(mapping) + kHuge - 1) & ~uintptr_t(kHuge - 1));
        madvise(words, kBytes, MADV_HUGEPAGE);
        for (size_t i = 0; i < kCount; i += 512) words[i] = i;
    }
    ~HugeBuffer() { munmap(mapping, kBytes + kHuge); }
    HugeBuffer(const HugeBuffer&) = delete;
    HugeBuffer& operator=(const HugeBuffer&) = delete;
    uint64_t read_at_random(uint64_t seed) const {
        uint64_t x = seed, sum = 0;
        for (int i = 0; i < 300000; ++i) {
            x = x * 6364136223846793005ull + 1442695040888963407ull;
            sum += words[(x >> 20) % kCount];
        }
        return x + sum;
    }
};

// Per processor and second: the median CPU seconds of the rulers and, with a model, of a one-thread
// decode of its file; the two threads run at once, one pinned to each processor.
int vcpu_speeds(double seconds, int bits, const char* path) {
    cpu_set_t allowed;
    CPU_ZERO(&allowed);
    sched_getaffinity(0, sizeof allowed, &allowed);
    std::vector<int> cpus;
    for (int c = 0; c < CPU_SETSIZE && cpus.size() < 2; ++c)
        if (CPU_ISSET(c, &allowed)) cpus.push_back(c);
    if (cpus.size() < 2) {
        std::fprintf(stderr, "vcpu-speeds: needs two processors\n");
        return 1;
    }
    std::vector<uint8_t> bytes;
    if (path != nullptr) {
        amc::EncodeOptions options;
        options.quantize_bits = bits;
        bytes = amc::encode(amc::read_hierarchy(path), options);
    }
    struct Call {
        int second;
        double arithmetic, fresh, kept, decode;
    };
    std::vector<Call> calls[2];
    const double start = now();
    std::vector<std::thread> threads;
    for (int k = 0; k < 2; ++k)
        threads.emplace_back([&, k] {
            cpu_set_t one;
            CPU_ZERO(&one);
            CPU_SET(cpus[k], &one);
            pthread_setaffinity_np(pthread_self(), sizeof one, &one);
            amc::DecodeOptions d;
            d.threads = 1;
            const HugeBuffer kept;
            uint64_t seed = 1;
            while (now() - start < seconds) {
                const double t = now() - start, a0 = thread_seconds();
                for (int i = 0; i < 2000000; ++i) seed = seed * 6364136223846793005ull + 1;
                const double c0 = thread_seconds();
                seed = HugeBuffer().read_at_random(seed);
                const double c1 = thread_seconds();
                seed = kept.read_at_random(seed);
                const double c2 = thread_seconds();
                if (!bytes.empty()) {
                    const amc::Hierarchy back = amc::decode(bytes.data(), bytes.size(), d);
                    seed += back.node_count();
                }
                calls[k].push_back({int(t), c0 - a0, c1 - c0, c2 - c1, thread_seconds() - c2});
            }
            if (seed == 0) std::printf(" ");  // keeps the work
        });
    for (std::thread& t : threads) t.join();
    std::printf("processors %d and %d at once, each second's median CPU seconds on each: a chain of multiplies, fresh memory read, "
                "kept memory read%s; slower over faster\n",
                cpus[0], cpus[1], bytes.empty() ? "" : ", a one-thread decode");
    std::vector<double> arithmetic_ratios, ruler_ratios, kept_ratios, decode_ratios;
    for (int second = 0; second < int(seconds); ++second) {
        std::vector<double> arithmetic[2], ruler[2], kept[2], decode[2];
        for (int k = 0; k < 2; ++k)
            for (const Call& c : calls[k])
                if (c.second == second) {
                    arithmetic[k].push_back(c.arithmetic);
                    ruler[k].push_back(c.fresh);
                    kept[k].push_back(c.kept);
                    decode[k].push_back(c.decode);
                }
        if (ruler[0].empty() || ruler[1].empty()) continue;
        const double a = median(ruler[0]), b = median(ruler[1]), da = median(decode[0]), db = median(decode[1]);
        const double ka = median(kept[0]), kb = median(kept[1]), aa = median(arithmetic[0]), ab = median(arithmetic[1]);
        arithmetic_ratios.push_back(std::max(aa, ab) / std::min(aa, ab));
        ruler_ratios.push_back(std::max(a, b) / std::min(a, b));
        kept_ratios.push_back(std::max(ka, kb) / std::min(ka, kb));
        std::printf("  second %2d: multiplies %.5f %.5f (%.2f), fresh %.5f %.5f (%.2f), kept %.5f %.5f (%.2f)", second, aa, ab,
                    arithmetic_ratios.back(), a, b, ruler_ratios.back(), ka, kb, kept_ratios.back());
        if (!bytes.empty()) {
            decode_ratios.push_back(std::max(da, db) / std::min(da, db));
            std::printf("; decode %.4f %.4f (%.2f), slower where fresh memory is: %s", da, db, decode_ratios.back(),
                        (da > db) == (a > b) ? "yes" : "no");
        }
        std::printf("\n");
    }
    const Range r = range_of(ruler_ratios), kr = range_of(kept_ratios), ar = range_of(arithmetic_ratios);
    std::printf("slower over faster, median [min - max] over %zu seconds: multiplies %.2f [%.2f - %.2f], fresh memory %.2f [%.2f - "
                "%.2f], kept memory %.2f [%.2f - %.2f]",
                ruler_ratios.size(), ar.median, ar.low, ar.high, r.median, r.low, r.high, kr.median, kr.low, kr.high);
    if (!decode_ratios.empty()) {
        const Range dr = range_of(decode_ratios);
        std::printf("; decode: median %.2f [%.2f - %.2f]", dr.median, dr.low, dr.high);
    }
    std::printf("\n");
    return 0;
}

int alone_together(const std::string& what, int bits, double seconds, const char* path) {
    const amc::Hierarchy h = amc::read_hierarchy(path);
    amc::EncodeOptions options;
    options.quantize_bits = bits;
    options.threads = 1;
    const std::vector<uint8_t> bytes = amc::encode(h, options);
    amc::DecodeOptions d;
    d.threads = 1;
    auto call = [&] {
        if (what == "encode") {
            if (amc::encode(h, options) != bytes) std::abort();
        } else {
            const amc::Hierarchy back = amc::decode(bytes.data(), bytes.size(), d);
            if (back.node_count() != h.node_count()) std::abort();
        }
    };
    // now() reads steady_clock, CLOCK_MONOTONIC on Linux: a clock both processes share.
    const double start = std::floor(now()) + 2, end = start + seconds;
    const pid_t other = fork();
    if (other < 0) return 1;
    if (other == 0) {  // the second process: busy in even seconds, starting a call only if it ends within the second
        double last = 0;
        while (now() < end + 1) {
            const double t = now();
            if (long(t) % 2 == 0 && t + last < std::floor(t) + 1) {
                call();
                last = now() - t;
            } else {
                usleep(1000);
            }
        }
        _exit(0);
    }
    std::vector<double> cpu[2];  // [0]: calls within an even second (the other process busy), [1]: odd
    while (now() < start) usleep(1000);
    while (now() < end) {
        const double t0 = now(), c0 = thread_seconds();
        call();
        const double c1 = thread_seconds(), t1 = now();
        if (long(t0) == long(t1)) cpu[long(t0) % 2].push_back(c1 - c0);
    }
    kill(other, SIGTERM);
    waitpid(other, nullptr, 0);
    const Range together = range_of(cpu[0]), alone = range_of(cpu[1]);
    std::printf("%s, %s on one thread, %d bits: CPU seconds a call with another process doing the same %.4f [%.4f - %.4f] (%zu "
                "calls), alone %.4f [%.4f - %.4f] (%zu calls); together / alone %.3f\n",
                name_of(path).c_str(), what.c_str(), bits, together.median, together.low, together.high, cpu[0].size(), alone.median,
                alone.low, alone.high, cpu[1].size(), together.median / alone.median);
    return 0;
}

// The encode before repeat's loop, in a frame of its own (no tail call: it assigns after the call),
// which scripts/serial_fraction.sh leaves out: its cold first pages are no step of the loop's encodes.
[[gnu::noinline]] void warm_up_encode(const amc::Hierarchy& h, amc::EncodeOptions options, std::vector<uint8_t>& bytes) {
    options.threads = 1;  // on one thread: any other thread's work is the loop's
    bytes = amc::encode(h, options);
}

int repeat(const std::string& what, int runs, unsigned threads, int bits, const char* path) {
    const amc::Hierarchy h = amc::read_hierarchy(path);
    amc::EncodeOptions options;
    options.quantize_bits = bits;
    std::vector<uint8_t> bytes;
    warm_up_encode(h, options, bytes);
    options.threads = threads;
    uint64_t check = 0;
    for (int r = 0; r < runs; ++r) {
        if (what == "encode") {
            check += amc::encode(h, options).size();
        } else {
            amc::DecodeOptions d;
            d.threads = threads;
            check += amc::decode(bytes.data(), bytes.size(), d).node_count();
        }
    }
    std::printf("%s: %d %ss on %u threads (%llu)\n", name_of(path).c_str(), runs, what.c_str(), threads, (unsigned long long)check);
    return 0;
}

}  // namespace

// FNV-1a over every node's level, vertices, neighbours, neighbour edges, flags and children, then
// every position's bits: two decodes that agree on it built the same hierarchy.
uint64_t hierarchy_hash(const amc::Hierarchy& h) {
    uint64_t hash = 14695981039346656037ull;
    auto add = [&](const void* data, size_t size) {
        for (size_t i = 0; i < size; ++i) hash = (hash ^ static_cast<const uint8_t*>(data)[i]) * 1099511628211ull;
    };
    for (amc::NodeId n = 0; n < h.node_capacity(); ++n) {
        const int32_t level = h.is_alive(n) ? h.level(n) : -1;
        add(&level, sizeof level);
        if (level < 0) continue;
        for (int i = 0; i < 3; ++i) {
            const uint32_t words[3] = {h.vertex(n, i), h.neighbor(n, i), uint32_t(h.neighbor_edge(n, i))};
            add(words, sizeof words);
        }
        const uint32_t more[3] = {uint32_t(h.is_leaf(n) ? amc::kNoNode : h.child(n, 0)), uint32_t(h.diagonal_flipped(n)),
                                  uint32_t(h.is_boundary_edge(n, 0) | h.is_boundary_edge(n, 1) << 1 | h.is_boundary_edge(n, 2) << 2)};
        add(more, sizeof more);
    }
    add(h.positions().data(), h.positions().size() * sizeof(amc::Vec3));
    return hash;
}

int decode_file(int runs, unsigned threads, bool kept, const char* path) {
    std::ifstream in(path, std::ios::binary);
    const std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    amc::DecodeOptions d;
    d.threads = threads;
    amc::DecodeContext context;
    uint64_t hash = 0;
    for (int r = 0; r < runs; ++r) {
        amc::Hierarchy back = kept ? amc::decode(context, bytes.data(), bytes.size(), d) : amc::decode(bytes.data(), bytes.size(), d);
        const uint64_t h = hierarchy_hash(back);
        if (kept) context.recycle(std::move(back));
        if (r > 0 && h != hash) {
            std::fprintf(stderr, "%s: decode %d built another hierarchy\n", path, r + 1);
            return 1;
        }
        hash = h;
    }
    std::printf("%s: %d decodes on %u threads%s, hierarchy FNV-1a %016llx\n", name_of(path).c_str(), runs, threads,
                kept ? " through one DecodeContext" : "", (unsigned long long)hash);
    return 0;
}

int main(int argc, char** argv) {
    const std::string mode = argc > 1 ? argv[1] : "";
    if (mode == "sizes" && argc >= 4) return sizes(std::atoi(argv[2]), argc - 3, argv + 3);
    if (mode == "speed" && argc == 6)
        return speed(std::max(1, std::atoi(argv[2])), std::atoi(argv[3]), uint32_t(std::atoi(argv[4])), argv[5]);
    if (mode == "speed-threads" && argc == 5) return speed_threads(std::max(1, std::atoi(argv[2])), std::atoi(argv[3]), argv[4]);
    if (mode == "decode-speed" && argc == 5) return decode_speed(std::max(1, std::atoi(argv[2])), std::atoi(argv[3]), argv[4]);
    if (mode == "decode-file" && (argc == 5 || (argc == 6 && std::string(argv[4]) == "context")))
        return decode_file(std::max(1, std::atoi(argv[2])), unsigned(std::atoi(argv[3])), argc == 6, argv[argc - 1]);
    if (mode == "decode-rusage" && argc == 5 &&
        (std::string(argv[3]) == "recycle" || std::string(argv[3]) == "keep" || std::string(argv[3]) == "free"))
        return decode_rusage(std::max(1, std::atoi(argv[2])), argv[3], argv[4]);
    if (mode == "encode-rusage" && (argc == 5 || (argc == 6 && std::string(argv[4]) == "context")))
        return encode_rusage(std::max(1, std::atoi(argv[2])), std::atoi(argv[3]), argc == 6, argv[argc - 1]);
    if (mode == "vcpu-speeds" && (argc == 3 || argc == 5))
        return vcpu_speeds(std::max(2.0, std::atof(argv[2])), argc == 5 ? std::atoi(argv[3]) : 0, argc == 5 ? argv[4] : nullptr);
    if (mode == "alone-together" && argc == 6 && (std::string(argv[2]) == "encode" || std::string(argv[2]) == "decode"))
        return alone_together(argv[2], std::atoi(argv[3]), std::max(4.0, std::atof(argv[4])), argv[5]);
    if (mode == "repeat" && argc == 7 && (std::string(argv[2]) == "encode" || std::string(argv[2]) == "decode"))
        return repeat(argv[2], std::max(1, std::atoi(argv[3])), unsigned(std::atoi(argv[4])), std::atoi(argv[5]), argv[6]);
    std::fprintf(stderr, "usage: chunks_bench sizes BITS model.amh ...\n       chunks_bench speed RUNS BITS CHUNKS model.amh\n"
                         "       chunks_bench speed-threads RUNS BITS model.amh\n"
                         "       chunks_bench decode-speed RUNS BITS model.amh\n"
                         "       chunks_bench decode-file RUNS THREADS [context] file.amc\n"
                         "       chunks_bench decode-rusage RUNS recycle|keep|free file.amc\n"
                         "       chunks_bench encode-rusage RUNS BITS [context] model.amh\n"
                         "       chunks_bench vcpu-speeds SECONDS [BITS model.amh]\n"
                         "       chunks_bench alone-together encode|decode BITS SECONDS model.amh\n"
                         "       chunks_bench repeat encode|decode RUNS THREADS BITS model.amh\n");
    return 2;
}
