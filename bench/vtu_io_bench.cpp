// VTU output and input of a leaf mesh: file size, and CPU and wall seconds to write and read
// (read_vtu, validation included), binary (zlib) on one thread and on every core, and ASCII;
// median [min-max] over runs, the thread counts alternating within each run.
//   amc refine --model random --faces 1100000 --max-level 9 -o big.amh
//   vtu_io_bench big.amh [runs=3] [dir=/tmp]
#include <amc/hierarchy.h>
#include <amc/mesh.h>
#include <amc/mesh_io.h>

#include "bench_common.h"

#include <algorithm>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <string>
#include <vector>

using namespace amc;

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(stderr, "usage: vtu_io_bench FILE.amh [runs] [dir]\n");
        return 2;
    }
    const int runs = argc > 2 ? std::max(1, std::atoi(argv[2])) : 3;
    const std::string dir = argc > 3 ? argv[3] : "/tmp";
    const LeafMesh leaf = extract_leaf_mesh(read_hierarchy(argv[1]));
    const VtuMesh vtu{leaf.mesh, {}, cell_data_arrays(leaf.cells)};
    std::printf("%zu triangles, %zu vertices, %s precision, %d runs (seconds, median [min-max])\n",
                leaf.mesh.triangles.size(), leaf.mesh.positions.size(),
                leaf.mesh.single_precision ? "single" : "double", runs);
    struct Way {
        const char* name;
        VtuEncoding encoding;
        unsigned threads;
        std::vector<double> write_cpu, write_wall, read_cpu, read_wall;
        uintmax_t bytes = 0;
    };
    Way ways[] = {{"binary_zlib, 1 thread", VtuEncoding::binary_zlib, 1, {}, {}, {}, {}},
                  {"binary_zlib, all cores", VtuEncoding::binary_zlib, 0, {}, {}, {}, {}},
                  {"ascii", VtuEncoding::ascii, 1, {}, {}, {}, {}}};
    const std::string path = dir + "/vtu_io_bench.vtu";
    for (int r = 0; r < runs; ++r) {
        for (Way& way : ways) {
            const double c0 = cpu_seconds();
            const Clock::time_point w0 = Clock::now();
            write_vtu(path, vtu, way.encoding, way.threads);
            way.write_wall.push_back(seconds_since(w0));
            const double c1 = cpu_seconds();
            const Clock::time_point w1 = Clock::now();
            const VtuMesh back = read_vtu(path, way.threads);
            way.read_wall.push_back(seconds_since(w1));
            way.read_cpu.push_back(cpu_seconds() - c1);
            way.write_cpu.push_back(c1 - c0);
            way.bytes = std::filesystem::file_size(path);
            if (back.mesh.triangles != vtu.mesh.triangles) {
                std::fprintf(stderr, "read back differs\n");
                return 1;
            }
        }
    }
    std::filesystem::remove(path);
    for (const Way& way : ways) {
        const Range wc = range_of(way.write_cpu), ww = range_of(way.write_wall);
        const Range rc = range_of(way.read_cpu), rw = range_of(way.read_wall);
        std::printf("%-22s %11ju bytes  write CPU %.3f [%.3f-%.3f] wall %.3f [%.3f-%.3f]  read CPU %.3f [%.3f-%.3f] wall %.3f [%.3f-%.3f]\n",
                    way.name, way.bytes, wc.median, wc.low, wc.high, ww.median, ww.low, ww.high, rc.median, rc.low, rc.high,
                    rw.median, rw.low, rw.high);
    }
    return 0;
}
