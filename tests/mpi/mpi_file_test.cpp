// amc::mpi under mpirun (tests/CMakeLists.txt runs this binary on 2 and 3 ranks): files written by
// P ranks are the serial encoder's bytes and decode to the whole hierarchy; P ranks' files read by Q
// ranks give each its roots' trees exactly; bad input fails on every rank, and nothing is written.
// The first ranks of the world write or read alone through sub-communicators, so one run of 3
// ranks covers every P, Q in 1..3.
#include "coding/format_version.h"
#include "rank_fixtures.h"

#include <amc/codec.h>
#include <amc/mpi.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>

namespace amc {
namespace {

using testing::adaptive_hierarchy;
using testing::cut;
using testing::forest_of;

int world_rank() {
    int r = 0;
    MPI_Comm_rank(MPI_COMM_WORLD, &r);
    return r;
}

int world_size() {
    int s = 0;
    MPI_Comm_size(MPI_COMM_WORLD, &s);
    return s;
}

// The first `ranks` ranks of the world (MPI_COMM_NULL on the others).
struct FirstRanks {
    MPI_Comm comm = MPI_COMM_NULL;
    explicit FirstRanks(int ranks) { MPI_Comm_split(MPI_COMM_WORLD, world_rank() < ranks ? 0 : MPI_UNDEFINED, world_rank(), &comm); }
    ~FirstRanks() {
        if (comm != MPI_COMM_NULL) MPI_Comm_free(&comm);
    }
};

// A directory every rank sees, removed at the end.
struct SharedDirectory {
    std::filesystem::path path;
    SharedDirectory() {
        int pid = int(getpid());
        MPI_Bcast(&pid, 1, MPI_INT, 0, MPI_COMM_WORLD);
        path = std::filesystem::temp_directory_path() / ("amc_mpi_test_" + std::to_string(pid));
        if (world_rank() == 0) std::filesystem::create_directories(path);
        MPI_Barrier(MPI_COMM_WORLD);
    }
    ~SharedDirectory() {
        MPI_Barrier(MPI_COMM_WORLD);
        if (world_rank() == 0) std::filesystem::remove_all(path);
    }
    std::string file(const std::string& name) const { return (path / name).string(); }
};

std::vector<uint8_t> file_bytes(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), {});
}

// Writes `h` with the ranks of `comm` owning `counts` roots in rank order.
void write_with(MPI_Comm comm, const std::string& path, const Hierarchy& h, const std::vector<uint32_t>& counts, uint64_t seed,
                const EncodeOptions& options = {}, mpi::WriteStats* stats = nullptr) {
    int rank = 0;
    MPI_Comm_rank(comm, &rank);
    uint32_t first = 0;
    for (int r = 0; r < rank; ++r) first += counts[size_t(r)];
    mpi::write(comm, path, h.base(), first, forest_of(h, {first, counts[size_t(rank)]}, seed + first), options, stats);
}

TEST(Mpi, RanksWriteTheSerialEncodersFile) {
    const SharedDirectory dir;
    const int p = world_size();
    int files = 0;
    for (uint64_t seed = 0; seed < 10; ++seed) {
        SCOPED_TRACE("seed " + std::to_string(seed));
        const Hierarchy h = adaptive_hierarchy(seed);
        for (bool empty : {false, true}) {  // with `empty`, rank 1 owns no roots
            const std::vector<uint32_t> counts = cut(h.root_count(), uint32_t(p), seed, empty);
            const std::string path = dir.file("h" + std::to_string(seed) + (empty ? "e" : "") + ".amc");
            EncodeOptions options;
            options.predictor = GeometryPredictor(seed % 4);
            if (empty) {  // quantized, the grid agreed on by the ranks
                options.quantize_bits = int(6 + seed);
                options.grid_contexts = seed % 2 == 0;
            }
            mpi::WriteStats stats;
            write_with(MPI_COMM_WORLD, path, h, counts, seed, options, &stats);
            // Every rank checks the file the serial way.
            const std::vector<uint8_t> bytes = file_bytes(path);
            EXPECT_EQ(stats.file_bytes, bytes.size());
            options.keep_base_order = true;
            for (uint32_t c : counts)
                if (c > 0) options.chunk_roots.push_back(c);
            ASSERT_EQ(bytes, encode(h, options));
            const FileInfo info = inspect(bytes.data(), bytes.size());
            EXPECT_EQ(info.chunks.size(), options.chunk_roots.size() > 1 ? options.chunk_roots.size() : 0u);
            if (options.quantize_bits != 0) {
                EXPECT_GT(stats.max_error, 0.0);
            } else {
                const Hierarchy back = decode(bytes.data(), bytes.size());
                ASSERT_TRUE(identical(back, h));
            }
            ++files;
        }
    }
    EXPECT_EQ(files, 20);
    for (const auto& entry : std::filesystem::directory_iterator(dir.path))  // no temporary file left
        EXPECT_EQ(entry.path().extension(), ".amc") << entry.path();
}

// What a reader of roots `first .. first + count - 1` must get: those roots' trees.
void expect_share(const mpi::Share& share, const Hierarchy& h, uint32_t first, uint32_t count) {
    EXPECT_EQ(share.first_root, first);
    EXPECT_EQ(share.file_roots, h.root_count());
    if (count == 0) {
        EXPECT_EQ(share.hierarchy.root_count(), 0u);
        return;
    }
    std::vector<VertexId> base_vertex;
    base_of_roots(h.base(), {RootRange{first, count}}, base_vertex);
    EXPECT_EQ(share.base_vertices, base_vertex);
    EXPECT_TRUE(identical(share.hierarchy, extract_roots(h, {RootRange{first, count}})));
}

// read(comm, path): the ranks' shares, in rank order, cut the file's roots along its chunks
// (a file without chunks is one), each rank reading the head and its own chunks' blocks only.
void expect_along_chunks(MPI_Comm comm, const mpi::Share& share, const Hierarchy& h, const std::vector<uint8_t>& bytes) {
    int q = 0, me = 0;
    MPI_Comm_size(comm, &q);
    MPI_Comm_rank(comm, &me);
    const uint32_t count = share.hierarchy.root_count();
    uint32_t mine[2] = {share.first_root, count};
    std::vector<uint32_t> all(2 * size_t(q));
    MPI_Allgather(mine, 2, MPI_UINT32_T, all.data(), 2, MPI_UINT32_T, comm);
    FileInfo info = inspect(bytes.data(), bytes.size());
    if (info.chunks.empty()) info.chunks.push_back({0, h.root_count(), h.node_count(), 0, 0});
    uint32_t next = 0, chunks_read = 0;
    uint64_t chunk_bytes = 0;
    for (int k = 0; k < q; ++k) {
        const uint32_t first = all[2 * size_t(k)], roots = all[2 * size_t(k) + 1];
        EXPECT_EQ(first, roots == 0 ? h.root_count() : next) << "rank " << k;
        next += roots;
        for (const ChunkInfo& c : info.chunks) {
            const bool inside = c.first_root >= first && c.first_root + c.roots <= first + roots;
            const bool outside = c.first_root + c.roots <= first || c.first_root >= first + roots;
            EXPECT_TRUE(inside || outside) << "rank " << k << " cuts a chunk";
            if (inside && roots > 0 && k == me) {
                ++chunks_read;
                chunk_bytes += c.size;
            }
        }
    }
    EXPECT_EQ(next, h.root_count());
    expect_share(share, h, share.first_root, count);
    if (info.chunks.size() == size_t(q)) {
        EXPECT_EQ(chunks_read, 1u);  // as many readers as chunks: one each
    }
    if (info.chunks.front().size == 0) {  // no chunks: the metadata alone, or all of it
        EXPECT_EQ(share.bytes_read == bytes.size(), count > 0);
    } else {
        EXPECT_EQ(share.bytes_read, info.chunks.front().offset + chunk_bytes);  // the head, then its chunks
    }
}

TEST(Mpi, FilesOfPRanksAreReadByQRanks) {
    const SharedDirectory dir;
    const int ranks = world_size();
    int shares = 0;
    for (uint64_t seed = 20; seed < 24; ++seed) {
        SCOPED_TRACE("seed " + std::to_string(seed));
        const Hierarchy h = adaptive_hierarchy(seed);
        for (int p = 1; p <= ranks; ++p) {
            const std::string path = dir.file("p" + std::to_string(p) + ".amc");
            {
                const FirstRanks writers(p);
                if (writers.comm != MPI_COMM_NULL) write_with(writers.comm, path, h, cut(h.root_count(), uint32_t(p), seed, false), seed);
            }
            MPI_Barrier(MPI_COMM_WORLD);
            for (int q = 1; q <= ranks; ++q) {
                SCOPED_TRACE(std::to_string(p) + " writers, " + std::to_string(q) + " readers");
                const FirstRanks readers(q);
                if (readers.comm == MPI_COMM_NULL) continue;
                const int r = world_rank();
                const mpi::Share along = mpi::read(readers.comm, path);
                expect_along_chunks(readers.comm, along, h, file_bytes(path));
                // Runs of any length, overlapping, one of them empty.
                const uint32_t count = r == 1 ? 0 : 1 + uint32_t((seed + uint64_t(r)) % (h.root_count() - 1));
                const uint32_t start = count == 0 ? 0 : uint32_t((seed * 7 + uint64_t(r)) % (h.root_count() - count + 1));
                const mpi::Share run = mpi::read(readers.comm, path, start, count);
                expect_share(run, h, start, count);
                EXPECT_LE(run.bytes_read, file_bytes(path).size());
                shares += 2;
            }
        }
    }
    EXPECT_GT(shares, 0);
}

// Runs f(), which must throw Error on this rank; returns its message.
template <class F>
std::string error_of(F&& f) {
    try {
        f();
    } catch (const Error& e) {
        return e.what();
    }
    ADD_FAILURE() << "no error";
    return "";
}

TEST(Mpi, BadInputFailsOnEveryRankAndWritesNothing) {
    const SharedDirectory dir;
    const int p = world_size();
    const Hierarchy h = adaptive_hierarchy(5);
    const std::vector<uint32_t> counts = cut(h.root_count(), uint32_t(p), 5, false);
    const std::string path = dir.file("bad.amc");
    const int r = world_rank();
    uint32_t first = 0;
    for (int k = 0; k < r; ++k) first += counts[size_t(k)];
    const Hierarchy forest = forest_of(h, {first, counts[size_t(r)]}, 3);
    // Overlapping roots: the last rank starts one root early.
    std::string message = error_of([&] { mpi::write(MPI_COMM_WORLD, path, h.base(), r == p - 1 ? first - 1 : first, r == p - 1 ? forest_of(h, {first - 1, counts[size_t(r)]}, 3) : forest); });
    EXPECT_NE(message.find("bad.amc"), std::string::npos) << message;
    // Another base mesh on rank 1.
    TriangleMesh other = h.base();
    other.positions[0].y += 1.0;
    message = error_of([&] { mpi::write(MPI_COMM_WORLD, path, r == 1 ? other : h.base(), first, forest); });
    EXPECT_NE(message.find("rank 1"), std::string::npos) << message;
    EXPECT_NE(message.find("base mesh"), std::string::npos) << message;
    // A base vertex no triangle uses: refused as encode() refuses it (a chunked file would not decode).
    TriangleMesh isolated = h.base();
    isolated.positions.push_back({0.0, 0.0, -5.0});
    message = error_of([&] { mpi::write(MPI_COMM_WORLD, path, isolated, first, forest); });
    EXPECT_NE(message.find("not used by any triangle"), std::string::npos) << message;
    // The mixing mode, a numbering, a grid of too many bits.
    EncodeOptions mixed;
    mixed.hierarchy_contexts = HierarchyContexts::mixed;
    message = error_of([&] { mpi::write(MPI_COMM_WORLD, path, h.base(), first, forest, mixed); });
    EXPECT_NE(message.find("mixing mode"), std::string::npos) << message;
    const LeafNumbering numbering;
    EncodeOptions numbered;
    numbered.numbering = &numbering;
    message = error_of([&] { mpi::write(MPI_COMM_WORLD, path, h.base(), first, forest, numbered); });
    EXPECT_NE(message.find("numbering"), std::string::npos) << message;
    EncodeOptions too_fine;
    too_fine.quantize_bits = 31;
    message = error_of([&] { mpi::write(MPI_COMM_WORLD, path, h.base(), first, forest, too_fine); });
    EXPECT_NE(message.find("bad.amc: quantize_bits 31"), std::string::npos) << message;
    // Rank 0 refined twice next to unrefined roots of rank 1 (square: rows of roots meet at a line).
    const TriangleMesh square = make_square(2);
    Hierarchy fine(square);
    refine_uniformly(fine, 2);
    const std::vector<uint32_t> rows = p == 2 ? std::vector<uint32_t>{4, 4} : std::vector<uint32_t>{4, 4, 0};
    uint32_t row_first = 0;
    for (int k = 0; k < r; ++k) row_first += rows[size_t(k)];
    const Hierarchy mine = r == 0 ? extract_roots(fine, {RootRange{0, 4}}) : extract_roots(Hierarchy(square), {RootRange{row_first, rows[size_t(r)]}});
    message = error_of([&] { mpi::write(MPI_COMM_WORLD, path, square, row_first, mine); });
    EXPECT_NE(message.find("rank 1"), std::string::npos) << message;
    EXPECT_FALSE(std::filesystem::exists(path));
    for (const auto& entry : std::filesystem::directory_iterator(dir.path)) ADD_FAILURE() << "left behind: " << entry.path();

    // Reading: a run past the file's roots, a file that is not there, a corrupt chunk.
    write_with(MPI_COMM_WORLD, path, h, counts, 5);
    message = error_of([&] { mpi::read(MPI_COMM_WORLD, path, r == p - 1 ? h.root_count() : 0, 1); });
    EXPECT_NE(message.find("rank " + std::to_string(p - 1)), std::string::npos) << message;
    message = error_of([&] { mpi::read(MPI_COMM_WORLD, dir.file("missing.amc")); });
    EXPECT_NE(message.find("missing.amc"), std::string::npos) << message;
    std::vector<uint8_t> bytes = file_bytes(path);
    const FileInfo info = inspect(bytes.data(), bytes.size());
    ASSERT_GE(info.chunks.size(), 2u);
    MPI_Barrier(MPI_COMM_WORLD);
    if (r == 0) {
        bytes[info.chunks.back().offset + info.chunks.back().size / 2] ^= 0x10;
        std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    }
    MPI_Barrier(MPI_COMM_WORLD);
    message = error_of([&] { mpi::read(MPI_COMM_WORLD, path); });  // the last rank reads the last chunk
    EXPECT_NE(message.find("checksum"), std::string::npos) << message;
    // The other chunks still read.
    const mpi::Share first_roots = mpi::read(MPI_COMM_WORLD, path, 0, info.chunks[0].roots);
    expect_share(first_roots, h, 0, info.chunks[0].roots);
}

}  // namespace
}  // namespace amc

// One GoogleTest run per rank; the process fails when any rank's tests failed.
int main(int argc, char** argv) {
    MPI_Init(&argc, &argv);
    ::testing::InitGoogleTest(&argc, argv);
    int failed = RUN_ALL_TESTS() != 0 ? 1 : 0;
    MPI_Allreduce(MPI_IN_PLACE, &failed, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    MPI_Finalize();
    return failed;
}
