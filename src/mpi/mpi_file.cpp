// One .amc file written and read by MPI ranks (amc/mpi.h): the steps of
// coding/distributed/rank_encoder.h with the exchanges between them, and MPI-IO. Every step that
// can refuse input runs inside collectively(), which lets all ranks fail together instead of
// leaving some waiting in a collective call.
#include <amc/mpi.h>

#include "coding/chunks/chunked_file.h"
#include "coding/container.h"
#include "coding/distributed/rank_encoder.h"
#include "coding/distributed/rank_grid.h"
#include "coding/file_metadata.h"
#include "common/check.h"
#include "common/little_endian.h"

#include <sys/mman.h>
#include <unistd.h>
#include <xxhash.h>

#include <chrono>
#include <climits>
#include <cstdio>
#include <cstring>
#include <functional>
#include <memory>
#include <optional>

namespace amc::mpi {

namespace {

int rank_of(MPI_Comm comm) {
    int rank = 0;
    MPI_Comm_rank(comm, &rank);
    return rank;
}

int size_of(MPI_Comm comm) {
    int size = 0;
    MPI_Comm_size(comm, &size);
    return size;
}

double seconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Runs `step` (this rank's own work, no MPI call inside) on every rank; when it throws on some,
// every rank throws the error of the lowest of them.
template <class F>
void collectively(MPI_Comm comm, F&& step) {
    ErrorCode code = ErrorCode::invalid_input;
    std::string message;
    bool failed = false;
    try {
        step();
    } catch (const Error& e) {
        code = e.code();
        message = e.what();
        failed = true;
    } catch (const std::bad_alloc&) {
        code = ErrorCode::limit_exceeded;
        message = "out of memory";
        failed = true;
    } catch (const std::exception& e) {
        message = e.what();
        failed = true;
    }
    int first = failed ? rank_of(comm) : INT_MAX;
    MPI_Allreduce(MPI_IN_PLACE, &first, 1, MPI_INT, MPI_MIN, comm);
    if (first == INT_MAX) return;
    int header[2] = {int(code), int(std::min<size_t>(message.size(), 1 << 20))};
    MPI_Bcast(header, 2, MPI_INT, first, comm);
    message.resize(size_t(header[1]));
    MPI_Bcast(message.data(), header[1], MPI_CHAR, first, comm);
    throw Error(ErrorCode(header[0]), message);
}

// Whether every rank saw `ok`.
bool all_ok(MPI_Comm comm, bool ok) {
    int value = ok ? 1 : 0;
    MPI_Allreduce(MPI_IN_PLACE, &value, 1, MPI_INT, MPI_MIN, comm);
    return value == 1;
}

// Collective MPI-IO in pieces of at most 1 GiB (MPI counts are ints): every rank takes part in
// as many calls as the rank with the most to move, with empty pieces once it is done.
constexpr uint64_t kPiece = uint64_t(1) << 30;

template <class Call>
bool in_pieces(MPI_Comm comm, uint64_t size, Call&& call) {
    uint64_t pieces = (size + kPiece - 1) / kPiece;
    MPI_Allreduce(MPI_IN_PLACE, &pieces, 1, MPI_UINT64_T, MPI_MAX, comm);
    bool ok = true;
    for (uint64_t p = 0; p < pieces; ++p) {
        const uint64_t at = std::min(size, p * kPiece), n = std::min(kPiece, size - at);
        ok &= call(at, int(n)) == MPI_SUCCESS;
    }
    return ok;
}

bool write_all(MPI_Comm comm, MPI_File file, uint64_t offset, const std::vector<uint8_t>& bytes) {
    return in_pieces(comm, bytes.size(), [&](uint64_t at, int n) {
        return MPI_File_write_at_all(file, MPI_Offset(offset + at), bytes.data() + at, n, MPI_BYTE, MPI_STATUS_IGNORE);
    });
}

// Reads are independent (each rank its own ranges): Open MPI 4.1.4's collective reads
// (MPI_File_read_at_all with its OMPIO component; ROMIO is right) return a wrong byte to a rank
// whose range overlaps other ranks' ranges (docs/MPI.md, "Not done").
bool read_all(MPI_Comm comm, MPI_File file, uint64_t offset, uint8_t* out, uint64_t size) {
    return in_pieces(comm, size, [&](uint64_t at, int n) {
        MPI_Status status;
        const int rc = MPI_File_read_at(file, MPI_Offset(offset + at), out + at, n, MPI_BYTE, &status);
        int got = 0;
        MPI_Get_count(&status, MPI_BYTE, &got);
        return rc == MPI_SUCCESS && got == n ? MPI_SUCCESS : MPI_ERR_IO;
    });
}

// Every rank's bytes, in rank order.
std::vector<uint8_t> all_gather(MPI_Comm comm, const std::vector<uint8_t>& mine, const std::string& what) {
    const int ranks = size_of(comm);
    std::vector<uint64_t> sizes(size_t(ranks), 0);
    uint64_t size = mine.size();
    MPI_Allgather(&size, 1, MPI_UINT64_T, sizes.data(), 1, MPI_UINT64_T, comm);
    uint64_t total = 0;
    std::vector<int> counts, offsets;
    for (uint64_t s : sizes) {
        offsets.push_back(int(std::min<uint64_t>(total, INT_MAX)));
        counts.push_back(int(std::min<uint64_t>(s, INT_MAX)));
        total += s;
    }
    // The same sizes on every rank: every rank refuses alike.
    AMC_REQUIRE(total <= INT_MAX, limit_exceeded, what + ": more than 2 GiB to exchange between ranks");
    std::vector<uint8_t> out(total);
    MPI_Allgatherv(mine.data(), int(mine.size()), MPI_BYTE, out.data(), counts.data(), offsets.data(), MPI_BYTE, comm);
    return out;
}

template <class T>
std::vector<uint8_t> as_bytes(const std::vector<T>& values) {
    std::vector<uint8_t> bytes(values.size() * sizeof(T));
    if (!bytes.empty()) std::memcpy(bytes.data(), values.data(), bytes.size());
    return bytes;
}

template <class T>
std::vector<T> from_bytes(const std::vector<uint8_t>& bytes) {
    std::vector<T> values(bytes.size() / sizeof(T));
    if (!values.empty()) std::memcpy(values.data(), bytes.data(), values.size() * sizeof(T));
    return values;
}

uint64_t base_hash(const TriangleMesh& base) {
    XXH64_state_t* state = XXH64_createState();
    XXH64_reset(state, 0);
    const uint8_t single = base.single_precision;
    XXH64_update(state, &single, 1);
    XXH64_update(state, base.positions.data(), base.positions.size() * sizeof(Vec3));
    XXH64_update(state, base.triangles.data(), base.triangles.size() * sizeof(Triangle));
    const uint64_t hash = XXH64_digest(state);
    XXH64_freeState(state);
    return hash;
}

// A buffer the size of a whole file of which a reader fills only the parts it needs: address
// space, no memory, for the rest (anonymous pages are not backed until written).
class SparseFile {
public:
    explicit SparseFile(uint64_t size, const std::string& path) : size_(size) {
        if (size == 0) return;
        void* p = mmap(nullptr, size, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0);
        AMC_REQUIRE(p != MAP_FAILED, limit_exceeded, path + ": no address space for a file of " + std::to_string(size) + " bytes");
        data_ = static_cast<uint8_t*>(p);
    }
    ~SparseFile() {
        if (data_ != nullptr) munmap(data_, size_);
    }
    SparseFile(const SparseFile&) = delete;
    SparseFile& operator=(const SparseFile&) = delete;
    uint8_t* data() { return data_; }
    uint64_t size() const { return size_; }

private:
    uint64_t size_ = 0;
    uint8_t* data_ = nullptr;
};

// Where the head of a file ends (rank 0, independent reads): after the seam block of a chunked
// file; after the metadata block of a file without chunks (a rank reads the rest only when it
// reads roots); the whole file whenever the framing looks wrong (then the decoder, which checks
// everything, says what).
uint64_t head_end(MPI_File file, uint64_t size) {
    uint64_t at = kFileHeaderSize, metadata_end = size;
    const uint8_t expected[5] = {uint8_t(BlockType::metadata), uint8_t(BlockType::base_connectivity),
                                 uint8_t(BlockType::base_geometry), uint8_t(BlockType::chunk_table), uint8_t(BlockType::seam)};
    for (uint8_t type : expected) {
        uint8_t framing[5];
        if (size < 5 || at > size - 5) return size;
        if (MPI_File_read_at(file, MPI_Offset(at), framing, 5, MPI_BYTE, MPI_STATUS_IGNORE) != MPI_SUCCESS) return size;
        const uint64_t end = at + kBlockOverhead + load_le32(framing + 1);
        if (type == uint8_t(BlockType::chunk_table) && framing[0] != type) return metadata_end;
        if (framing[0] != type || end > size) return size;
        if (type == uint8_t(BlockType::metadata)) metadata_end = end;
        if (type == uint8_t(BlockType::seam)) return end;
        at = end;
    }
    return size;
}

// The chunks of a file as its head says (all of it for a file without chunks).
struct FileChunks {
    uint32_t roots = 0;
    std::vector<RootRange> ranges;
    std::vector<uint64_t> nodes;    // of each chunk
    std::vector<uint64_t> offsets;  // file offsets of the chunk blocks
};

FileChunks chunks_of(const uint8_t* data, uint64_t size, uint64_t head) {
    BlockReader reader(data, size_t(head));
    Block block{};
    AMC_REQUIRE(reader.next(block) && block.type == BlockType::metadata, corrupt, "expected a metadata block");
    const Metadata meta = read_metadata(block, reader.flags() & kFlagQuantized);
    AMC_REQUIRE(meta.base_triangles <= UINT32_MAX, corrupt, "metadata block: too many base triangles");
    FileChunks out;
    out.roots = uint32_t(meta.base_triangles);
    if (!(meta.options & kOptionChunked)) {
        out.ranges.push_back({0, out.roots});
        out.nodes.push_back(meta.nodes);
        return out;
    }
    for (int skip = 0; skip < 2; ++skip) AMC_REQUIRE(reader.next(block), corrupt, "file ends in its base mesh");
    AMC_REQUIRE(reader.next(block) && block.type == BlockType::chunk_table, corrupt, "expected a chunk table block");
    const ChunkTable table = read_chunk_table(block, reader.version(), meta.base_triangles, meta.nodes, size_t(size));
    out.ranges = table.roots;
    out.nodes = table.nodes;
    for (uint64_t offset : table.offsets) out.offsets.push_back(table.end + offset);
    return out;
}

struct RunRequest {
    bool along_chunks = false;  // whole chunks, balanced by nodes (read(comm, path))
    uint32_t first = 0, count = 0;
};

// The chunks of rank `rank` of `ranks`: runs of whole chunks balanced by node count, as the
// encoder balances roots into chunks; the ranks past the chunk count get none.
RootRange chunks_of_rank(const FileChunks& chunks, int rank, int ranks) {
    const std::vector<RootRange> runs = balanced_chunks(chunks.nodes, uint32_t(ranks));
    return size_t(rank) < runs.size() ? runs[size_t(rank)] : RootRange{uint32_t(chunks.ranges.size()), 0};
}

Share read_run(MPI_Comm comm, const std::string& path, RunRequest run, const DecodeOptions& options) {
    const auto start = std::chrono::steady_clock::now();
    const int rank = rank_of(comm), ranks = size_of(comm);
    const std::string what = path + ": rank " + std::to_string(rank);
    MPI_File file;
    const int rc = MPI_File_open(comm, path.c_str(), MPI_MODE_RDONLY, MPI_INFO_NULL, &file);
    if (!all_ok(comm, rc == MPI_SUCCESS)) {
        if (rc == MPI_SUCCESS) MPI_File_close(&file);
        throw Error(ErrorCode::io, path + ": can not be opened for reading");
    }
    Share share;
    try {
        MPI_Offset size_value = 0;
        MPI_File_get_size(file, &size_value);
        const uint64_t size = uint64_t(size_value);
        uint64_t head = 0;
        if (rank == 0) head = head_end(file, size);
        MPI_Bcast(&head, 1, MPI_UINT64_T, 0, comm);
        std::unique_ptr<SparseFile> bytes;
        collectively(comm, [&] { bytes = std::make_unique<SparseFile>(size, path); });
        AMC_REQUIRE(all_ok(comm, read_all(comm, file, 0, bytes->data(), head)), io, path + ": can not be read");
        share.bytes_read = head;
        // This rank's run and the chunks that hold it.
        FileChunks chunks;
        std::vector<uint32_t> wanted;
        collectively(comm, [&] {
            try {
                chunks = chunks_of(bytes->data(), size, head);
            } catch (const Error& e) {
                throw e.prefixed(path);
            }
            share.file_roots = chunks.roots;
            if (run.along_chunks) {
                const RootRange mine = chunks_of_rank(chunks, rank, ranks);
                run.first = mine.count == 0 ? chunks.roots : chunks.ranges[mine.first].first;
                run.count = 0;
                for (uint32_t c = mine.first; c < mine.first + mine.count; ++c) run.count += chunks.ranges[c].count;
            }
            AMC_REQUIRE(run.first <= chunks.roots && run.count <= chunks.roots - run.first, invalid_input,
                        what + ": roots " + std::to_string(run.first) + " to " + std::to_string(uint64_t(run.first) + run.count) +
                            " (exclusive) are not in the file, which has " + std::to_string(chunks.roots));
            for (uint32_t c = 0; c < chunks.ranges.size() && run.count > 0; ++c) {
                const RootRange r = chunks.ranges[c];
                if (r.first < run.first + run.count && run.first < r.first + r.count) wanted.push_back(c);
            }
        });
        share.first_root = run.first;
        // The chunk blocks, one run of bytes: up to the next chunk's block, or to the end of the last
        // block, whose length its framing tells; the rest of a file without chunks.
        uint64_t begin = 0, end = 0;
        const bool chunked = !chunks.offsets.empty();
        if (!chunked && !wanted.empty()) {
            begin = head;
            end = size;
        }
        if (chunked && !wanted.empty()) {
            begin = chunks.offsets[wanted.front()];
            end = wanted.back() + 1 < chunks.offsets.size() ? chunks.offsets[wanted.back() + 1] : begin;
        }
        const bool last = chunked && !wanted.empty() && wanted.back() + 1 == chunks.offsets.size();
        const uint64_t last_block = last ? chunks.offsets.back() : 0;
        AMC_REQUIRE(all_ok(comm, read_all(comm, file, last_block, bytes->data() + last_block, last ? 5 : 0)), io,
                    path + ": can not be read");
        if (last) end = std::min<uint64_t>(size, last_block + kBlockOverhead + load_le32(bytes->data() + last_block + 1));
        AMC_REQUIRE(all_ok(comm, read_all(comm, file, begin, bytes->data() + begin, end - begin)), io, path + ": can not be read");
        share.bytes_read += end - begin;
        collectively(comm, [&] {
            if (run.count == 0) return;
            try {
                const ChunkDecode decoded = decode_chunks(bytes->data(), size_t(size), wanted, options);
                const RootRange local{run.first - decoded.roots.front(), run.count};
                share.hierarchy = extract_roots(decoded.hierarchy, {local});
                std::vector<VertexId> base_vertex;
                base_of_roots(decoded.hierarchy.base(), {local}, base_vertex);
                for (VertexId v : base_vertex) share.base_vertices.push_back(decoded.base_vertices[v]);
            } catch (const Error& e) {
                throw e.prefixed(path);
            }
        });
    } catch (...) {
        MPI_File_close(&file);
        throw;
    }
    MPI_File_close(&file);
    share.seconds = seconds_since(start);
    return share;
}

}  // namespace

void write(MPI_Comm comm, const std::string& path, const TriangleMesh& base, uint32_t first_root, const Hierarchy& forest,
           const EncodeOptions& options, WriteStats* stats_out) {
    const auto start = std::chrono::steady_clock::now();
    const int rank = rank_of(comm), ranks = size_of(comm);
    const std::string what = path + ": rank " + std::to_string(rank);
    WriteStats stats;
    RankChunk part;
    uint64_t mine[3] = {0, first_root, forest.root_count()};
    collectively(comm, [&] {
        check_rank_options(options, path);
        validate_triangle_mesh(base, path + ": base mesh");
        mine[0] = base_hash(base);
    });
    std::vector<uint64_t> all(3 * size_t(ranks));
    MPI_Allgather(mine, 3, MPI_UINT64_T, all.data(), 3, MPI_UINT64_T, comm);
    RankLayout layout;
    collectively(comm, [&] {
        AMC_REQUIRE(mine[0] == all[0], invalid_input, what + ": its base mesh differs from rank 0's (every rank must hold the same)");
        part = rank_chunk(base, first_root, forest, what);
        std::vector<RootRange> ranges;
        for (int r = 0; r < ranks; ++r) ranges.push_back({uint32_t(all[3 * size_t(r) + 1]), uint32_t(all[3 * size_t(r) + 2])});
        try {
            layout = rank_layout(uint32_t(base.triangles.size()), ranges);
        } catch (const Error& e) {
            throw e.prefixed(path);
        }
    });
    // Quantized files: the grid over every rank's box.
    std::optional<Quantizer> grid;
    if (options.quantize_bits != 0) {
        std::vector<RankBox> boxes(static_cast<size_t>(ranks));
        const RankBox box = rank_box(base, part);
        MPI_Allgather(&box, sizeof(RankBox), MPI_BYTE, boxes.data(), sizeof(RankBox), MPI_BYTE, comm);
        collectively(comm, [&] { grid = grid_of_ranks(boxes, options.quantize_bits, path); });
    }
    const Quantizer* grid_or_null = grid ? &*grid : nullptr;
    // What each rank writes, and where.
    std::vector<uint8_t> head, block, end;
    uint64_t block_offset = 0, file_bytes = 0;
    const int32_t chunk = layout.chunk_of_rank[size_t(rank)];
    if (layout.chunks.size() == 1) {  // one rank owns every root: a file without chunks, as encode writes it
        collectively(comm, [&] {
            if (chunk != 0) return;
            EncodeOptions whole = options;
            whole.keep_base_order = true;
            whole.chunk_roots = {uint32_t(base.triangles.size())};
            EncodeStats encoded;
            block = encode(part.chunk, whole, &encoded);
            stats.max_error = encoded.max_error;
        });
        file_bytes = block.size();
        MPI_Allreduce(MPI_IN_PLACE, &file_bytes, 1, MPI_UINT64_T, MPI_SUM, comm);
    } else {
        std::vector<SeamSplit> splits;
        collectively(comm, [&] { splits = seam_splits(part, base, layout); });
        const std::vector<SeamSplit> every_split = from_bytes<SeamSplit>(all_gather(comm, as_bytes(splits), path));
        Seam seam;
        RankCode code;
        collectively(comm, [&] {
            try {
                seam = rank_seam(base, layout, every_split, grid_or_null);
            } catch (const Error& e) {
                throw e.prefixed(path);
            }
            if (grid) stats.max_error = snap_to_grid(part, *grid);
            if (chunk >= 0) code = encode_rank_chunk(part, seam, options, grid_or_null, what);
        });
        std::vector<ChunkSummary> by_rank(static_cast<size_t>(ranks)), summaries(layout.chunks.size());
        MPI_Allgather(&code.summary, sizeof(ChunkSummary), MPI_BYTE, by_rank.data(), sizeof(ChunkSummary), MPI_BYTE, comm);
        for (int r = 0; r < ranks; ++r)
            if (layout.chunk_of_rank[size_t(r)] >= 0) summaries[size_t(layout.chunk_of_rank[size_t(r)])] = by_rank[size_t(r)];
        uint64_t head_bytes = 0;
        collectively(comm, [&] {
            if (rank != 0) return;
            head = chunked_file_head(base, seam, summaries, options, grid_or_null);
            end = end_block();
            head_bytes = head.size();
        });
        MPI_Bcast(&head_bytes, 1, MPI_UINT64_T, 0, comm);
        // Prefix sums of the block sizes: each chunk block starts where the blocks before it end.
        file_bytes = head_bytes;
        for (size_t c = 0; c < summaries.size(); ++c) {
            if (int32_t(c) == chunk) block_offset = file_bytes;
            file_bytes += summaries[c].block_bytes;
        }
        file_bytes += kBlockOverhead;
        block = std::move(code.block);
        stats.seam_vertices = seam.vertex_count();
    }
    stats.encode_seconds = seconds_since(start);

    // The collective write, to a temporary name that rank 0 renames once every rank has written.
    int pid = int(getpid());
    MPI_Bcast(&pid, 1, MPI_INT, 0, comm);
    const std::string temporary = path + ".tmp" + std::to_string(pid);
    MPI_File file;
    int rc = MPI_File_open(comm, temporary.c_str(), MPI_MODE_CREATE | MPI_MODE_WRONLY, MPI_INFO_NULL, &file);
    if (!all_ok(comm, rc == MPI_SUCCESS)) {
        if (rc == MPI_SUCCESS) MPI_File_close(&file);
        throw Error(ErrorCode::io, path + ": can not be written (" + temporary + " can not be created)");
    }
    bool ok = MPI_File_set_size(file, MPI_Offset(file_bytes)) == MPI_SUCCESS;
    ok &= write_all(comm, file, 0, head);
    ok &= write_all(comm, file, block_offset, block);
    ok &= write_all(comm, file, file_bytes - end.size(), end);
    ok &= MPI_File_close(&file) == MPI_SUCCESS;
    if (!all_ok(comm, ok)) {
        if (rank == 0) std::remove(temporary.c_str());
        throw Error(ErrorCode::io, path + ": can not be written (writing " + temporary + " failed)");
    }
    int renamed = 1;
    if (rank == 0) renamed = std::rename(temporary.c_str(), path.c_str()) == 0;
    MPI_Bcast(&renamed, 1, MPI_INT, 0, comm);
    if (!renamed) {
        if (rank == 0) std::remove(temporary.c_str());
        throw Error(ErrorCode::io, path + ": can not be written (renaming " + temporary + " failed)");
    }
    MPI_Allreduce(MPI_IN_PLACE, &stats.max_error, 1, MPI_DOUBLE, MPI_MAX, comm);
    stats.file_bytes = file_bytes;
    stats.rank_bytes = head.size() + block.size() + end.size();
    stats.write_seconds = seconds_since(start) - stats.encode_seconds;
    if (stats_out != nullptr) *stats_out = stats;
}

Share read(MPI_Comm comm, const std::string& path, uint32_t first_root, uint32_t root_count, const DecodeOptions& options) {
    return read_run(comm, path, RunRequest{false, first_root, root_count}, options);
}

Share read(MPI_Comm comm, const std::string& path, const DecodeOptions& options) {
    return read_run(comm, path, RunRequest{true, 0, 0}, options);
}

}  // namespace amc::mpi
