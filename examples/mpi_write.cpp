// Writing one .amc file from MPI ranks and reading it back (docs/MPI.md): the example to copy.
//
//   mpirun -n 4 mpi_write_example step.amc
//
// Every rank holds the whole coarse mesh, as a simulation holds its coarse connectivity: here the
// unit square cut into 2 * 16^2 triangles. Each rank owns a run of those triangles (the roots),
// numbers their vertices its own way and refines them: two levels everywhere, a third in a disc.
// Leaves are then of levels 2 and 3 only, so the forests fit together across rank boundaries as
// the library requires (no leaf next to one two levels finer), and the vertices that two ranks
// both create on a shared edge are edge midpoints of the same base positions, equal bit for bit.
// The ranks write step.amc together; any reader reads it (rank 0 decodes it whole with the serial
// decoder), and the ranks read it back along its chunks, each decoding only its own.
#include <amc/codec.h>
#include <amc/mpi.h>
#include <amc/refinement.h>

#include <cstdio>
#include <fstream>
#include <iterator>
#include <unordered_map>
#include <vector>

namespace {

// The rank's roots as a mesh of its own: its triangles in order, over its own vertex numbering
// (first use first), at the whole mesh's positions.
amc::TriangleMesh my_roots(const amc::TriangleMesh& whole, uint32_t first, uint32_t count) {
    amc::TriangleMesh mine;
    std::unordered_map<uint32_t, uint32_t> local;
    for (uint32_t t = first; t < first + count; ++t) {
        amc::Triangle triangle{};
        for (int k = 0; k < 3; ++k) {
            const uint32_t v = whole.triangles[t][k];
            const auto inserted = local.emplace(v, uint32_t(mine.positions.size()));
            if (inserted.second) mine.positions.push_back(whole.positions[v]);
            triangle[k] = inserted.first->second;
        }
        mine.triangles.push_back(triangle);
    }
    return mine;
}

bool in_disc(const amc::Hierarchy& h, amc::NodeId n) {
    amc::Vec3 c{0, 0, 0};
    for (int k = 0; k < 3; ++k) c = c + (1.0 / 3.0) * h.position(h.vertex(n, k));
    return (c.x - 0.3) * (c.x - 0.3) + (c.y - 0.6) * (c.y - 0.6) < 0.2 * 0.2;
}

}  // namespace

int main(int argc, char** argv) {
    MPI_Init(&argc, &argv);
    int rank = 0, ranks = 1;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &ranks);
    int status = 0;
    try {
        if (argc != 2) throw amc::Error("usage: mpirun -n P mpi_write_example out.amc");
        const std::string path = argv[1];
        const amc::TriangleMesh base = amc::make_square(16);
        const uint32_t roots = uint32_t(base.triangles.size());
        const uint32_t first = uint32_t(uint64_t(roots) * uint64_t(rank) / uint64_t(ranks));
        const uint32_t count = uint32_t(uint64_t(roots) * uint64_t(rank + 1) / uint64_t(ranks)) - first;

        amc::Hierarchy forest(my_roots(base, first, count));
        amc::refine_uniformly(forest, 2);
        for (amc::NodeId n : forest.leaves())
            if (in_disc(forest, n)) forest.split(n);
        // Red-green closure: a leaf between three split ones is split too (a disc is convex, so
        // this never happens across a rank boundary here; the library would refuse it).
        for (bool again = true; again;) {
            again = false;
            for (amc::NodeId n : forest.leaves())
                if (forest.hanging_node_count(n) == 3) {
                    forest.split(n);
                    again = true;
                }
        }

        amc::EncodeOptions options;
        options.quantize_bits = 16;  // or 0 (the default) for bit-exact coordinates
        amc::mpi::WriteStats stats;
        amc::mpi::write(MPI_COMM_WORLD, path, base, first, forest, options, &stats);

        if (rank == 0) {  // an ordinary .amc file: any reader reads it whole
            std::ifstream in(path, std::ios::binary);
            const std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), {});
            const amc::Hierarchy whole = amc::decode(bytes.data(), bytes.size());
            std::printf("%s: %llu bytes from %d ranks, %u roots, %u nodes, largest error %.3g\n", path.c_str(),
                        (unsigned long long)stats.file_bytes, ranks, whole.root_count(), whole.node_count(), stats.max_error);
        }
        const amc::mpi::Share share = amc::mpi::read(MPI_COMM_WORLD, path);  // whole chunks per rank
        std::printf("rank %d: wrote roots %u to %u, read roots %u to %u (%u nodes, %llu bytes read)\n", rank, first,
                    first + count, share.first_root, share.first_root + share.hierarchy.root_count(), share.hierarchy.node_count(),
                    (unsigned long long)share.bytes_read);
        // The file's roots are the base's triangles: this rank read back what it wrote.
        if (share.first_root != first || share.hierarchy.node_count() != forest.node_count()) throw amc::Error("read back other roots");
    } catch (const std::exception& e) {
        std::fprintf(stderr, "rank %d: %s\n", rank, e.what());
        status = 1;
    }
    MPI_Finalize();
    return status;
}
