// VTU output and input of a leaf mesh: file size and CPU seconds to write and read (read_vtu,
// validation included), binary (zlib) and ASCII, min-max over runs. CPU time, not wall time, so
// that a shared machine's load counts less.
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

using namespace amc;

namespace {

struct MinMax {
    double min = 1e300, max = 0;
    void add(double x) { min = std::min(min, x), max = std::max(max, x); }
};

}  // namespace

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(stderr, "usage: vtu_io_bench FILE.amh [runs] [dir]\n");
        return 2;
    }
    const int runs = argc > 2 ? std::max(1, std::atoi(argv[2])) : 3;
    const std::string dir = argc > 3 ? argv[3] : "/tmp";
    const LeafMesh leaf = extract_leaf_mesh(read_hierarchy(argv[1]));
    const VtuMesh vtu{leaf.mesh, {}, cell_data_arrays(leaf.cells)};
    std::printf("%zu triangles, %zu vertices, %s precision, %d runs (CPU seconds, min-max)\n",
                leaf.mesh.triangles.size(), leaf.mesh.positions.size(),
                leaf.mesh.single_precision ? "single" : "double", runs);
    for (VtuEncoding encoding : {VtuEncoding::binary_zlib, VtuEncoding::ascii}) {
        const std::string path = dir + "/vtu_io_bench.vtu";
        MinMax write, read;
        for (int r = 0; r < runs; ++r) {
            double t0 = cpu_seconds();
            write_vtu(path, vtu, encoding);
            double t1 = cpu_seconds();
            const VtuMesh back = read_vtu(path);
            double t2 = cpu_seconds();
            if (back.mesh.triangles != vtu.mesh.triangles) {
                std::fprintf(stderr, "read back differs\n");
                return 1;
            }
            write.add(t1 - t0);
            read.add(t2 - t1);
        }
        std::printf("%-11s %11ju bytes  write %.2f-%.2f s  read %.2f-%.2f s\n",
                    encoding == VtuEncoding::ascii ? "ascii" : "binary_zlib",
                    static_cast<uintmax_t>(std::filesystem::file_size(path)), write.min, write.max, read.min,
                    read.max);
        std::filesystem::remove(path);
    }
    return 0;
}
