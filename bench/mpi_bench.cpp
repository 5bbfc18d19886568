// amc::mpi write and read times (docs/MPI.md, "Measured"). Under mpirun with P ranks:
//
//   mpirun -n P mpi_bench RUNS model.amh out.amc
//
// Every rank loads the hierarchy and keeps a run of roots balanced by node count (as a simulation
// partitions its elements), then RUNS times: all ranks write out.amc together (amc::mpi::write),
// then read it back in even shares of roots (amc::mpi::read). A time is the slowest rank's, from a
// barrier to the end of the call. Rank 0 checks the file against the serial encoder with the same
// chunks, and prints its size against the serial encoder's defaults (base in the base coder's
// order, one chunk per 10^5 faces) and against one chunk.
#include "coding/chunks/chunk_layout.h"

#include <amc/codec.h>
#include <amc/hierarchy.h>
#include <amc/mpi.h>

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

// The slowest rank's time of f(), from a barrier.
template <class F>
double timed(F&& f) {
    MPI_Barrier(MPI_COMM_WORLD);
    const double start = now();
    f();
    double seconds = now() - start;
    MPI_Allreduce(MPI_IN_PLACE, &seconds, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    return seconds;
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
    if (argc != 4) {
        if (rank == 0) std::fprintf(stderr, "usage: mpirun -n P mpi_bench RUNS model.amh out.amc\n");
        MPI_Finalize();
        return 2;
    }
    const int runs = std::max(1, std::atoi(argv[1]));
    const std::string out = argv[3];
    try {
        const amc::Hierarchy h = amc::read_hierarchy(argv[2]);
        const std::vector<amc::RootRange> parts = amc::balanced_chunks(amc::nodes_per_root(h), uint32_t(ranks));
        const amc::RootRange mine = size_t(rank) < parts.size() ? parts[size_t(rank)] : amc::RootRange{h.root_count(), 0};
        const amc::Hierarchy forest = amc::extract_roots(h, {mine});
        const std::string load_before = load_average();
        std::vector<double> writes, reads;
        uint64_t read_bytes = 0;
        amc::mpi::WriteStats stats;
        for (int r = 0; r < runs; ++r) {
            writes.push_back(timed([&] { amc::mpi::write(MPI_COMM_WORLD, out, h.base(), mine.first, forest, {}, &stats); }));
            reads.push_back(timed([&] { read_bytes = amc::mpi::read(MPI_COMM_WORLD, out).bytes_read; }));
        }
        MPI_Allreduce(MPI_IN_PLACE, &read_bytes, 1, MPI_UINT64_T, MPI_MAX, MPI_COMM_WORLD);
        if (rank == 0) {
            std::ifstream in(out, std::ios::binary);
            const std::vector<uint8_t> file((std::istreambuf_iterator<char>(in)), {});
            amc::EncodeOptions same;
            same.keep_base_order = true;
            for (const amc::RootRange& p : parts) same.chunk_roots.push_back(p.count);
            const bool identical = file == amc::encode(h, same);
            amc::EncodeOptions one;
            one.chunks = 1;
            const size_t serial = amc::encode(h).size(), whole = amc::encode(h, one).size();
            std::printf("| %d | %u | %llu | %zu | %+.2f %% | %+.2f %% | %s | %s | %s | %llu | %llu | %s / %s |\n", ranks, h.root_count(),
                        (unsigned long long)h.node_count(), file.size(), 100.0 * (double(file.size()) / double(serial) - 1.0),
                        100.0 * (double(file.size()) / double(whole) - 1.0),
                        identical ? "yes" : "NO", range(writes).c_str(), range(reads).c_str(),
                        (unsigned long long)stats.seam_vertices, (unsigned long long)read_bytes, load_before.c_str(),
                        load_average().c_str());
        }
    } catch (const std::exception& e) {
        std::fprintf(stderr, "rank %d: %s\n", rank, e.what());
        MPI_Abort(MPI_COMM_WORLD, 1);
    }
    MPI_Finalize();
    return 0;
}
