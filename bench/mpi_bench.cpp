// amc::mpi write and read times (docs/MPI.md, "Measured"). Under mpirun with P ranks:
//
//   mpirun -n P mpi_bench RUNS model.amh out.amc [BITS]
//
// Every rank loads the hierarchy and keeps a run of roots balanced by node count (as a simulation
// partitions its elements), then RUNS times: all ranks write out.amc together (amc::mpi::write;
// quantized to BITS when given), then read it back twice: in even shares of roots (each rank
// decodes every chunk its share touches) and along the chunks (amc::mpi::read(comm, path): whole
// chunks per rank). A time is the slowest rank's, from a barrier to the end of the call: wall
// clock, and CPU time (the process's, which under load means more than wall clock). Rank 0 checks
// the file against the serial encoder with the same chunks, and prints its size against the serial
// encoder's defaults (base in the base coder's order, one chunk per 10^5 faces) and against one
// chunk.
#include "coding/chunks/chunk_layout.h"

#include <amc/codec.h>
#include <amc/hierarchy.h>
#include <amc/mpi.h>

#include <time.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace {

double now() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

double cpu_now() {
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

// The slowest rank's time of f(), from a barrier: wall clock, and CPU time into `cpu`.
template <class F>
double timed(F&& f, std::vector<double>* cpu = nullptr) {
    MPI_Barrier(MPI_COMM_WORLD);
    const double start = now(), cpu_start = cpu_now();
    f();
    double seconds[2] = {now() - start, cpu_now() - cpu_start};
    MPI_Allreduce(MPI_IN_PLACE, seconds, 2, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    if (cpu != nullptr) cpu->push_back(seconds[1]);
    return seconds[0];
}

// The most and the sum of the ranks' bytes read.
std::string bytes_read(uint64_t mine) {
    uint64_t most = mine, sum = mine;
    MPI_Allreduce(MPI_IN_PLACE, &most, 1, MPI_UINT64_T, MPI_MAX, MPI_COMM_WORLD);
    MPI_Allreduce(MPI_IN_PLACE, &sum, 1, MPI_UINT64_T, MPI_SUM, MPI_COMM_WORLD);
    return std::to_string(most) + " / " + std::to_string(sum);
}

std::string range(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    char text[96];
    std::snprintf(text, sizeof text, "%.3f [%.3f-%.3f]", v[v.size() / 2], v.front(), v.back());
    return text;
}

std::string load_average() {
    std::ifstream in("/proc/loadavg");
    std::string one, five;
    in >> one >> five;
    return one + " / " + five;
}

}  // namespace

int main(int argc, char** argv) {
    MPI_Init(&argc, &argv);
    int rank = 0, ranks = 1;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &ranks);
    if (argc != 4 && argc != 5) {
        if (rank == 0) std::fprintf(stderr, "usage: mpirun -n P mpi_bench RUNS model.amh out.amc [BITS]\n");
        MPI_Finalize();
        return 2;
    }
    const int runs = std::max(1, std::atoi(argv[1]));
    const std::string out = argv[3];
    try {
        const amc::Hierarchy h = amc::read_hierarchy(argv[2]);
        const std::vector<amc::RootRange> parts = amc::balanced_chunks(amc::nodes_per_root(h, amc::root_of_nodes(h)), uint32_t(ranks));
        const amc::RootRange mine = size_t(rank) < parts.size() ? parts[size_t(rank)] : amc::RootRange{h.root_count(), 0};
        const amc::Hierarchy forest = amc::extract_roots(h, {mine});
        amc::EncodeOptions options;
        options.quantize_bits = argc == 5 ? std::atoi(argv[4]) : 0;
        const uint32_t even_first = uint32_t(uint64_t(h.root_count()) * uint64_t(rank) / uint64_t(ranks));
        const uint32_t even_count = uint32_t(uint64_t(h.root_count()) * uint64_t(rank + 1) / uint64_t(ranks)) - even_first;
        const std::string load_before = load_average();
        std::vector<double> writes, write_cpu, evens, even_cpu, alongs, along_cpu;
        uint64_t even_bytes = 0, along_bytes = 0;
        amc::mpi::WriteStats stats;
        for (int r = 0; r < runs; ++r) {
            writes.push_back(timed([&] { amc::mpi::write(MPI_COMM_WORLD, out, h.base(), mine.first, forest, options, &stats); }, &write_cpu));
            evens.push_back(timed([&] { even_bytes = amc::mpi::read(MPI_COMM_WORLD, out, even_first, even_count).bytes_read; }, &even_cpu));
            alongs.push_back(timed([&] { along_bytes = amc::mpi::read(MPI_COMM_WORLD, out).bytes_read; }, &along_cpu));
        }
        const std::string even_read = bytes_read(even_bytes), along_read = bytes_read(along_bytes);
        if (rank == 0) {
            std::ifstream in(out, std::ios::binary);
            const std::vector<uint8_t> file((std::istreambuf_iterator<char>(in)), {});
            amc::EncodeOptions same = options;
            same.keep_base_order = true;
            for (const amc::RootRange& p : parts) same.chunk_roots.push_back(p.count);
            const bool identical = file == amc::encode(h, same);
            amc::EncodeOptions one = options;
            one.chunks = 1;
            const size_t serial = amc::encode(h, options).size(), whole = amc::encode(h, one).size();
            std::printf("| %d | %d | %zu | %+.2f %% | %+.2f %% | %s | %s | %s | %llu | %s | %s | %s | %s | %s | %s | %s / %s |\n", ranks,
                        options.quantize_bits, file.size(), 100.0 * (double(file.size()) / double(serial) - 1.0),
                        100.0 * (double(file.size()) / double(whole) - 1.0), identical ? "yes" : "NO", range(writes).c_str(),
                        range(write_cpu).c_str(), (unsigned long long)stats.seam_vertices, range(evens).c_str(), range(even_cpu).c_str(),
                        even_read.c_str(), range(alongs).c_str(), range(along_cpu).c_str(), along_read.c_str(), load_before.c_str(),
                        load_average().c_str());
        }
    } catch (const std::exception& e) {
        std::fprintf(stderr, "rank %d: %s\n", rank, e.what());
        MPI_Abort(MPI_COMM_WORLD, 1);
    }
    MPI_Finalize();
    return 0;
}
