// Crafted files: for each count field of each block, a file whose checksums are valid but whose
// count is huge. Each must be refused in under 10 ms of CPU time with under 10 MB allocated
// (docs/FORMAT.md, 3.7: every count is checked against the bytes that can hold it before anything
// is allocated for it). A test binary of its own: it counts every allocation through a global
// operator new.
#include "padded_series.h"
#include "random_hierarchies.h"

#include "coding/entropy/arithmetic_coder.h"
#include "coding/base/base_mesh_coder.h"
#include "coding/container.h"
#include "coding/distributed/rank_encoder.h"
#include "coding/format_version.h"
#include "coding/geometry/float_coder.h"
#include "coding/hierarchy/hierarchy_stream.h"
#include "common/bits.h"
#include "common/mixing.h"
#include "geometry/closest_point.h"
#include "geometry/reference_surface.h"
#include "geometry/shape_improvement.h"
#include "geometry/surface_quality.h"
#include "import/leaf_detour.h"
#include "mesh/vtu_reader.h"
#include "octree/octree_file.h"
#include "octree/octree_traversal.h"
#include "series/series_format.h"
#include "series/series_framing.h"

#include <amc/codec.h>
#include <amc/hierarchy_coder.h>
#include <amc/import.h>
#include <amc/mesh_io.h>
#include <amc/numbering.h>
#include <amc/octree.h>
#include <amc/refinement.h>
#include <amc/series.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <functional>
#include <new>
#include <optional>
#include <string>
#include <unordered_map>

#include <unistd.h>

namespace {
std::atomic<uint64_t> g_allocated{0};

void* counted_allocation(std::size_t size, std::size_t alignment) {
    g_allocated += size;
    void* p = nullptr;
    if (alignment <= alignof(std::max_align_t)) p = std::malloc(size == 0 ? 1 : size);
    else if (posix_memalign(&p, alignment, size == 0 ? alignment : size) != 0) p = nullptr;
    if (p == nullptr) throw std::bad_alloc();
    return p;
}
}  // namespace

void* operator new(std::size_t size) { return counted_allocation(size, 0); }
void* operator new[](std::size_t size) { return counted_allocation(size, 0); }
void* operator new(std::size_t size, std::align_val_t a) { return counted_allocation(size, std::size_t(a)); }
void* operator new[](std::size_t size, std::align_val_t a) { return counted_allocation(size, std::size_t(a)); }
// The nothrow forms too (std::stable_sort's buffer uses them): otherwise the library's new and this
// file's delete would not pair up.
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
    try { return counted_allocation(size, 0); } catch (const std::bad_alloc&) { return nullptr; }
}
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept {
    try { return counted_allocation(size, 0); } catch (const std::bad_alloc&) { return nullptr; }
}
void* operator new(std::size_t size, std::align_val_t a, const std::nothrow_t&) noexcept {
    try { return counted_allocation(size, std::size_t(a)); } catch (const std::bad_alloc&) { return nullptr; }
}
void* operator new[](std::size_t size, std::align_val_t a, const std::nothrow_t&) noexcept {
    try { return counted_allocation(size, std::size_t(a)); } catch (const std::bad_alloc&) { return nullptr; }
}
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }

namespace amc {
namespace {

constexpr uint64_t kMaxBytes = 10u << 20;
#if defined(__SANITIZE_ADDRESS__)
constexpr double kMaxMilliseconds = 100.0;  // CI runs this binary again under ASan, in a Debug build
constexpr double kSanitizerSlowdown = 10.0;  // a linear-time test's bound there (the fixed code runs ~15-20 times slower)
#else
constexpr double kMaxMilliseconds = 10.0;
constexpr double kSanitizerSlowdown = 1.0;
#endif

double cpu_milliseconds() {
    timespec t;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return 1e3 * double(t.tv_sec) + 1e-6 * double(t.tv_nsec);
}

// Runs `read` on a crafted input: it must throw amc::Error of the `expected` kind, fast and
// without allocating much.
// `must_say`, when given, must occur in the message (the check meant, not another one).
void expect_refused_cheaply(const std::string& what, ErrorCode expected, const std::function<void()>& read,
                            const char* must_say = nullptr) {
    const uint64_t bytes_before = g_allocated.load();
    const double start = cpu_milliseconds();
    bool refused = false;
    ErrorCode code = ErrorCode::invalid_input;
    std::string message;
    try {
        read();
    } catch (const Error& e) {
        refused = true;
        code = e.code();
        message = std::string(error_code_name(e.code())) + ": " + e.what();
    }
    const double milliseconds = cpu_milliseconds() - start;
    const uint64_t allocated = g_allocated.load() - bytes_before;
    EXPECT_TRUE(refused) << what << " was accepted";
    if (refused) {
        EXPECT_EQ(error_code_name(code), std::string(error_code_name(expected))) << what << " (" << message << ")";
        if (must_say) {
            EXPECT_NE(message.find(must_say), std::string::npos) << what << " (" << message << ")";
        }
    }
    EXPECT_LT(allocated, kMaxBytes) << what << " (" << message << ")";
    EXPECT_LT(milliseconds, kMaxMilliseconds) << what << " (" << message << ")";
    std::printf("  %-48s %8.3f ms %9llu bytes  %s\n", what.c_str(), milliseconds, (unsigned long long)allocated,
                message.c_str());
}

// A 256 MB file of zeros (sparse) is no hierarchy or series file: its first bytes say so, and the
// readers by path refused it only after reading it whole (256 MB allocated, until 2026-12-07).
TEST(CraftedFiles, LargeFilesOfAnotherKindAreRefusedAtTheirFirstBytes) {
    const std::string path = (std::filesystem::temp_directory_path() /
                              ("amc_crafted_" + std::to_string(getpid()) + "_zeros.bin")).string();
    std::ofstream(path, std::ios::binary).close();
    std::filesystem::resize_file(path, uint64_t(256) << 20);
    expect_refused_cheaply("read_hierarchy of 256 MB of zeros", ErrorCode::bad_magic, [&] { read_hierarchy(path); },
                           "not a hierarchy file (bad magic)");
    expect_refused_cheaply("SeriesReader::open of 256 MB of zeros", ErrorCode::bad_magic,
                           [&] { SeriesReader::open(path); }, "not an amcodec series file (magic)");
    expect_refused_cheaply("ForestSeriesReader::open of 256 MB of zeros", ErrorCode::bad_magic,
                           [&] { ForestSeriesReader::open(path); }, "not an amcodec series file (magic)");
    std::filesystem::remove(path);
}

// ---- an .amc file taken apart and put together again, with valid checksums --------------------

struct Parts {
    uint8_t version = 0, flags = 0;
    std::vector<std::pair<BlockType, std::vector<uint8_t>>> blocks;  // END excluded
};

Parts take_apart(const std::vector<uint8_t>& file) {
    BlockReader reader(file.data(), file.size());
    Parts parts{reader.version(), reader.flags(), {}};
    Block block{};
    while (reader.next(block) && block.type != BlockType::end)
        parts.blocks.push_back({block.type, std::vector<uint8_t>(block.payload, block.payload + block.size)});
    return parts;
}

std::vector<uint8_t> put_together(const Parts& parts) {
    BlockWriter writer(parts.version, parts.flags);
    for (const auto& [type, payload] : parts.blocks) writer.add(type, payload);
    return writer.finish();
}

std::vector<uint8_t>& payload_of(Parts& parts, BlockType type) {
    for (auto& [t, payload] : parts.blocks)
        if (t == type) return payload;
    throw std::logic_error("no such block");
}

// The metadata block's fields (docs/FORMAT.md, 3.3).
struct Metadata {
    uint64_t base_vertices, base_triangles, nodes, vertices, faces, levels, options;
    std::vector<uint8_t> header;
    std::vector<uint8_t> quantizer;  // the raw bytes after the header
};

Metadata read_metadata(const std::vector<uint8_t>& payload) {
    PayloadReader in(payload.data(), payload.size(), "metadata");
    Metadata m;
    m.base_vertices = in.varint();
    m.base_triangles = in.varint();
    m.nodes = in.varint();
    m.vertices = in.varint();
    m.faces = in.varint();
    m.levels = in.varint();
    m.options = in.varint();
    const uint64_t h = in.varint();
    m.header.assign(in.rest(), in.rest() + h);
    m.quantizer.assign(in.rest() + h, in.rest() + in.remaining());
    return m;
}

std::vector<uint8_t> write_metadata(const Metadata& m, uint64_t header_length) {
    std::vector<uint8_t> out;
    for (uint64_t v : {m.base_vertices, m.base_triangles, m.nodes, m.vertices, m.faces, m.levels, m.options, header_length})
        put_varint(out, v);
    out.insert(out.end(), m.header.begin(), m.header.end());
    out.insert(out.end(), m.quantizer.begin(), m.quantizer.end());
    return out;
}

std::vector<uint8_t> sample_file(int quantize_bits = 0) {
    Hierarchy h(make_icosahedron());
    refine_randomly(h, 300, 4, 3);
    EncodeOptions options;
    options.quantize_bits = quantize_bits;
    return encode(h, options);
}

// The sample file with its metadata changed by `change` (header length as stored unless given).
std::vector<uint8_t> with_metadata(const std::function<void(Metadata&)>& change, int quantize_bits = 0,
                                   uint64_t header_length = UINT64_MAX) {
    Parts parts = take_apart(sample_file(quantize_bits));
    std::vector<uint8_t>& payload = payload_of(parts, BlockType::metadata);
    Metadata m = read_metadata(payload);
    change(m);
    payload = write_metadata(m, header_length == UINT64_MAX ? m.header.size() : header_length);
    return put_together(parts);
}

void expect_decode_refused(const std::string& what, ErrorCode expected, const std::vector<uint8_t>& file) {
    expect_refused_cheaply(what, expected, [&] { decode(file.data(), file.size()); });
}

constexpr uint64_t kHuge[] = {uint64_t(1) << 31, (uint64_t(1) << 32) - 1, uint64_t(1) << 40, ~uint64_t(0) >> 1};

TEST(CraftedFiles, MetadataCountsBeyondTheFile) {
    ASSERT_NO_THROW(decode(sample_file().data(), sample_file().size()));
    for (uint64_t huge : kHuge) {
        const std::string n = " = " + std::to_string(huge);
        expect_decode_refused("base vertices" + n, ErrorCode::corrupt, with_metadata([&](Metadata& m) { m.base_vertices = huge; }));
        expect_decode_refused("base triangles" + n, ErrorCode::corrupt, with_metadata([&](Metadata& m) { m.base_triangles = huge; }));
        expect_decode_refused("nodes" + n, ErrorCode::corrupt, with_metadata([&](Metadata& m) { m.nodes = huge; }));
        expect_decode_refused("vertices" + n, ErrorCode::corrupt, with_metadata([&](Metadata& m) { m.vertices = huge; }));
        expect_decode_refused("faces" + n, ErrorCode::corrupt, with_metadata([&](Metadata& m) { m.faces = huge; }));
        expect_decode_refused("levels" + n, ErrorCode::corrupt, with_metadata([&](Metadata& m) { m.levels = huge; }));
        expect_decode_refused("hierarchy header length" + n, ErrorCode::truncated, with_metadata([](Metadata&) {}, 0, huge));
        // All of them at once, consistent with each other: R refined nodes make 4 R nodes and
        // 1.5 R to 3 R vertices.
        expect_decode_refused("consistent counts, R" + n, ErrorCode::corrupt, with_metadata([&](Metadata& m) {
                                  const uint64_t refined = huge / 16;
                                  m.base_vertices = refined;
                                  m.base_triangles = 2 * refined;
                                  m.nodes = m.base_triangles + 4 * refined;
                                  m.vertices = m.base_vertices + 2 * refined;
                                  m.faces = m.nodes;
                              }));
    }
    // Each bound on its own, the other counts consistent: X more base vertices, roots, or
    // refined nodes (4 nodes, 2 vertices and 3 leaf faces more each) than the bytes can hold.
    for (uint64_t x : {uint64_t(1) << 28, uint64_t(1) << 40}) {
        // 2^28 more roots are refused first by the node limit (limit exceeded); the rest by the bytes.
        auto expect_message = [&](const std::string& what, const std::vector<uint8_t>& file, const std::string& words,
                                  ErrorCode expected = ErrorCode::corrupt) {
            expect_decode_refused(what, expected, file);
            if (x < (uint64_t(1) << 40)) return;
            try {
                decode(file.data(), file.size());
            } catch (const Error& e) {
                EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
            }
        };
        expect_message("base vertices + " + std::to_string(x), with_metadata([&](Metadata& m) {
                           m.base_vertices += x;
                           m.vertices += x;
                       }),
                       "base vertices can not be coded");
        expect_message("base triangles + " + std::to_string(x), with_metadata([&](Metadata& m) {
                           m.base_triangles += x;
                           m.nodes += x;
                           m.faces += x;
                       }),
                       "base triangles can not be coded", x < (uint64_t(1) << 40) ? ErrorCode::limit_exceeded : ErrorCode::corrupt);
        expect_message("refined nodes + " + std::to_string(x), with_metadata([&](Metadata& m) {
                           m.nodes += 4 * x;
                           m.vertices += 2 * x;
                           m.faces += 3 * x;
                       }),
                       "refinement vertices can not be coded");
    }
    // Just under the default node limit (2^26), the counts consistent: the bytes refuse it.
    expect_decode_refused("nodes just under the limit", ErrorCode::corrupt, with_metadata([](Metadata& m) {
                              const uint64_t refined = (uint64_t(1) << 24) - 10;
                              m.nodes = m.base_triangles + 4 * refined;
                              m.vertices = m.base_vertices + 2 * refined;
                              m.faces = m.nodes;
                          }));
    // The caller's limit, below what a valid file holds: refused from the metadata.
    const std::vector<uint8_t> valid = sample_file();
    DecodeOptions small;
    small.max_nodes = 100;
    expect_refused_cheaply("valid file, max_nodes = 100", ErrorCode::limit_exceeded,
                           [&] { decode(valid.data(), valid.size(), small); });
}

TEST(CraftedFiles, HierarchyHeaderCounts) {
    for (uint64_t huge : kHuge) {
        expect_decode_refused("hierarchy symbols = " + std::to_string(huge), ErrorCode::corrupt, with_metadata([&](Metadata& m) {
                                  HierarchyStreamHeader header;
                                  read_hierarchy_stream_header(m.header.data(), m.header.size(), header);
                                  header.options.truncate_stream = true;
                                  header.symbol_count = huge;
                                  m.header = write_hierarchy_stream_header(header);
                              }));
    }
    for (int uniform : {12, 20}) {
        // Uniform levels cost no bits: 4^U times the roots, against the metadata and the limit.
        expect_decode_refused("uniform levels = " + std::to_string(uniform), ErrorCode::limit_exceeded, with_metadata([&](Metadata& m) {
                                  HierarchyStreamHeader header;
                                  read_hierarchy_stream_header(m.header.data(), m.header.size(), header);
                                  header.options.uniform_levels = true;
                                  header.uniform_levels = uint8_t(uniform);
                                  m.header = write_hierarchy_stream_header(header);
                              }));
    }
}

// The issue's files: a quantized file announcing 8 * 10^6 base vertices with an empty base
// geometry block, and 2^31 - 1 base vertices in the explicit mode of the connectivity.
TEST(CraftedFiles, BaseVerticesWithoutTheBytes) {
    for (uint64_t vertices : {uint64_t(8000000), uint64_t(1) << 22, uint64_t(0x7fffffff)}) {
        Parts parts = take_apart(sample_file(12));
        std::vector<uint8_t>& payload = payload_of(parts, BlockType::metadata);
        Metadata m = read_metadata(payload);
        m.vertices += vertices - m.base_vertices;
        m.base_vertices = vertices;
        payload = write_metadata(m, m.header.size());
        payload_of(parts, BlockType::base_geometry).clear();
        ArithmeticEncoder explicit_mode;
        explicit_mode.encode_bits_raw(1, 2);                      // explicit
        explicit_mode.encode_bits_raw(0, bit_length(vertices + 1) - 1);  // gamma(V + 1)
        explicit_mode.encode_bits_raw(uint32_t(vertices + 1), bit_length(vertices + 1));
        explicit_mode.encode_bits_raw(1, 1);                      // F = 0
        payload_of(parts, BlockType::base_connectivity) = explicit_mode.finish();
        expect_decode_refused("base vertices " + std::to_string(vertices) + ", empty geometry", ErrorCode::corrupt,
                              put_together(parts));
    }
}

// The issue's undefined behaviour: decoding a hierarchy without refinement computed nullptr + 4
// (the numbering of refined nodes is never allocated then). Under UBSan (CI's sanitizer build,
// every finding fatal) this test fails if it comes back; elsewhere it checks the round trip.
TEST(CraftedFiles, UnrefinedHierarchiesDecode) {
    for (int bits : {0, 12}) {
        const Hierarchy h(make_icosahedron());
        EncodeOptions options;
        options.quantize_bits = bits;
        const std::vector<uint8_t> file = encode(h, options);
        const Hierarchy back = decode(file.data(), file.size());
        EXPECT_EQ(back.node_count(), h.node_count());
        EXPECT_EQ(back.depth(), 0);
        if (bits == 0) {
            EXPECT_TRUE(identical(back, in_decoder_order(h)));
        }
        DecodeOptions first_level;
        first_level.max_level = 0;
        EXPECT_EQ(decode(file.data(), file.size(), first_level).node_count(), h.node_count());
        const std::vector<uint8_t> stream = encode_hierarchy(h);
        EXPECT_EQ(decode_hierarchy(h.base(), stream.data(), stream.size()).node_count(), h.node_count());
    }
}

// ---- chunked files (sections 3.11-3.14) --------------------------------------------------------

// A valid file of one root a chunk (2,048 chunks, 21,000 seam vertices): decoded on two threads it
// allocates about what one thread does. Until 2026-12-07 each chunk had an array over every seam
// vertex (chunks times seam vertices, the square of the file): 43.8 MB more here (docs/FUZZING.md).
TEST(CraftedFiles, ManyChunksDecodeOnThreadsInTheMemoryOfOne) {
    Hierarchy h(make_square(32));
    refine_uniformly(h, 3);
    EncodeOptions options;
    options.quantize_bits = 12;
    options.chunks = h.root_count();
    options.min_chunk_bytes = 0;
    const std::vector<uint8_t> file = encode(h, options);
    ASSERT_EQ(inspect(file.data(), file.size()).chunks.size(), size_t(h.root_count()));
    uint64_t allocated[2] = {0, 0};
    Hierarchy decoded[2];
    for (unsigned threads : {1u, 2u}) {
        DecodeOptions decode_options;
        decode_options.threads = threads;
        const uint64_t before = g_allocated.load();
        decoded[threads - 1] = decode(file.data(), file.size(), decode_options);
        allocated[threads - 1] = g_allocated.load() - before;
        std::printf("  %u thread(s): %llu bytes allocated\n", threads, (unsigned long long)allocated[threads - 1]);
    }
    EXPECT_TRUE(identical(decoded[0], decoded[1]));
    EXPECT_LT(allocated[1], allocated[0] + (uint64_t(8) << 20));
}

// 2^17 chunks of one root each (`amc encode --chunks N` takes N up to the roots), encoded in time
// linear in them: each chunk's extraction marked its base vertices over the whole base and its
// roots over all roots (3.1 s of CPU here until 2026-12-07, 12 s for 2^18; docs/FUZZING.md). An
// encoder's input, not a file. Under ASan 2^13 chunks: each chunk's encoder maps and zeroes its
// tables afresh there (0.19-0.47 ms a chunk; 62 s for 2^17 in CI's ASan build), whatever the count.
TEST(CraftedFiles, EncodeOfOneRootChunksIsLinear) {
    const Hierarchy h(make_square(kSanitizerSlowdown > 1 ? 64 : 256));
    EncodeOptions options;
    options.quantize_bits = 12;
    options.threads = 1;
    options.chunks = h.root_count();
    options.min_chunk_bytes = 0;
    const double start = cpu_milliseconds();
    const std::vector<uint8_t> file = encode(h, options);
    const double milliseconds = cpu_milliseconds() - start;
    std::printf("  %u one-root chunks encoded (%zu bytes): %.1f ms\n", h.root_count(), file.size(), milliseconds);
    ASSERT_EQ(inspect(file.data(), file.size()).chunks.size(), size_t(h.root_count()));
    options.chunks = 1;
    const std::vector<uint8_t> whole = encode(h, options);
    EXPECT_TRUE(identical(decode(file.data(), file.size()), decode(whole.data(), whole.size())));
    EXPECT_LT(milliseconds, 1500.0 * kSanitizerSlowdown);  // 0.42 s in Release
}

// A chunk table of 2^17 chunks, each an empty block: inspect finds each chunk block's entry
// without a pass over all of them (that pass made inspect quadratic: 12 s of CPU for this 2 MB
// file, and `amc decode --triangles` inspects first). CPU time, as the other crafted files.
TEST(CraftedFiles, InspectOfManyChunksIsLinear) {
    constexpr uint64_t chunks = uint64_t(1) << 17;
    BlockWriter writer(kNewestVersion, 0);
    std::vector<uint8_t> metadata;
    for (uint64_t v : {uint64_t(3), chunks, chunks, uint64_t(3), chunks, uint64_t(1), uint64_t(2), uint64_t(0)})
        put_varint(metadata, v);  // base vertices, triangles, nodes, vertices, faces, levels, chunked, no header
    writer.add(BlockType::metadata, metadata);
    std::vector<uint8_t> table;
    put_varint(table, chunks);
    for (uint64_t c = 0; c < chunks; ++c)
        for (uint64_t v : {uint64_t(1), uint64_t(1), uint64_t(0), kBlockOverhead * (c + 1)}) put_varint(table, v);
    writer.add(BlockType::chunk_table, table);
    writer.add(BlockType::seam, {});
    for (uint64_t c = 0; c < chunks; ++c) writer.add(BlockType::chunk, {});
    const std::vector<uint8_t> file = writer.finish();
    const double start = cpu_milliseconds();
    const FileInfo info = inspect(file.data(), file.size());
    const double milliseconds = cpu_milliseconds() - start;
    std::printf("  inspect of %llu chunks (%zu bytes): %.1f ms\n", (unsigned long long)chunks, file.size(), milliseconds);
    ASSERT_EQ(info.chunks.size(), chunks);
    for (uint64_t c = 0; c < chunks; c += 4099) {
        EXPECT_EQ(info.chunks[c].size, kBlockOverhead);
        EXPECT_EQ(info.chunks[c].first_root, c);
    }
    EXPECT_EQ(info.chunks.back().size, kBlockOverhead);
    EXPECT_LT(milliseconds, 1000.0);  // 0.14 s under ASan (CI)
    // Every root's chunk (amc decode --triangles): each found by a search, not a pass over the
    // chunks (2.9 s of CPU until 2026-12-07).
    std::vector<uint32_t> roots(chunks);
    for (uint32_t r = 0; r < chunks; ++r) roots[r] = chunks - 1 - r;
    const double covering_start = cpu_milliseconds();
    const std::vector<uint32_t> covering = chunks_covering(info, roots);
    const double covering_milliseconds = cpu_milliseconds() - covering_start;
    std::printf("  chunks of %llu roots: %.1f ms\n", (unsigned long long)chunks, covering_milliseconds);
    ASSERT_EQ(covering.size(), chunks);
    for (uint32_t c = 0; c < chunks; ++c) ASSERT_EQ(covering[c], c);
    EXPECT_EQ(chunks_covering(info, {0, 5, 5, 131071}), (std::vector<uint32_t>{0, 5, 131071}));
    EXPECT_LT(covering_milliseconds, 1000.0);
}

// A chunked file (version 13 on) of 813 bytes whose metadata announces 2^26 nodes and 25.2 M
// vertices (within the bytes' bound on coded positions): refused without a thread zeroing the
// announced vertices' positions first (604 MB on two threads until 2026-12-07, docs/FUZZING.md).
TEST(CraftedFiles, ChunkedMetadataCountsBeyondTheFile) {
    Hierarchy h(make_icosahedron());
    refine_randomly(h, 3000, 6, 3);
    EncodeOptions options;
    options.chunks = 2;
    options.min_chunk_bytes = 0;
    Parts parts = take_apart(encode(h, options));
    ASSERT_GE(parts.version, kChunkVerticesVersion);
    std::vector<uint8_t>& payload = payload_of(parts, BlockType::metadata);
    Metadata m = read_metadata(payload);
    const uint64_t refined = ((uint64_t(1) << 26) - m.base_triangles) / 4;
    m.nodes = m.base_triangles + 4 * refined;
    m.vertices = m.base_vertices + (3 * refined + 1) / 2;  // the fewest R refined nodes make
    m.faces = m.nodes - refined;
    payload = write_metadata(m, m.header.size());
    const std::vector<uint8_t> file = put_together(parts);
    for (unsigned threads : {1u, 2u}) {
        DecodeOptions decode_options;
        decode_options.threads = threads;
        expect_refused_cheaply("2^26 nodes in " + std::to_string(file.size()) + " bytes, " + std::to_string(threads) + " thread(s)",
                               ErrorCode::corrupt, [&] { decode(file.data(), file.size(), decode_options); });
    }
}

// A bipyramid of 2^17 sides: two base vertices of valence 2^17.
TriangleMesh bipyramid(uint32_t sides) {
    TriangleMesh mesh;
    for (uint32_t i = 0; i < sides; ++i) {
        const double angle = 2 * 3.141592653589793 * double(i) / double(sides);
        mesh.positions.push_back({std::cos(angle), std::sin(angle), 0});
    }
    mesh.positions.push_back({0, 0, 1});
    mesh.positions.push_back({0, 0, -1});
    for (uint32_t i = 0; i < sides; ++i) {
        mesh.triangles.push_back({i, (i + 1) % sides, sides});
        mesh.triangles.push_back({(i + 1) % sides, i, sides + 1});
    }
    return mesh;
}

// A chunked file over a bipyramid of 2^17 sides (1.8 MB with the base kept in its order): the
// seam's base edges are found in time linear in the base. Each edge's neighbour was searched among
// its end's edges, quadratic in the valence (decode and encode alike) until 2026-12-07
// (docs/FUZZING.md). CPU time, as the other crafted files.
TEST(CraftedFiles, ChunkedFileOverAHighValenceBaseDecodesInLinearTime) {
    const Hierarchy h(bipyramid(uint32_t(1) << 17));
    EncodeOptions options;
    options.quantize_bits = 12;
    options.keep_base_order = true;  // the seam alone: not the base coder (HighValenceBaseEncodesInLinearTime)
    options.chunks = 1;
    const std::vector<uint8_t> whole = encode(h, options);
    options.chunks = 2;
    options.min_chunk_bytes = 0;
    const std::vector<uint8_t> file = encode(h, options);
    ASSERT_EQ(inspect(file.data(), file.size()).chunks.size(), 2u);
    DecodeOptions one_thread;
    one_thread.threads = 1;
    const double start = cpu_milliseconds();
    const Hierarchy chunked = decode(file.data(), file.size(), one_thread);
    const double milliseconds = cpu_milliseconds() - start;
    std::printf("  %zu roots in 2 chunks (%zu bytes): %.1f ms\n", size_t(chunked.root_count()), file.size(), milliseconds);
    EXPECT_TRUE(identical(chunked, decode(whole.data(), whole.size(), one_thread)));
    EXPECT_LT(milliseconds, 3000.0);  // 30 ms, 0.7 s under ASan (CI); 4.4 s in Release before
}

// The same base through the base coder: closing it (make_closed) found each halfedge's twin by a
// pass over its end's halfedges, quadratic in the valence (13 s of CPU to encode this base until
// 2026-12-07, 0.15 s after). An encoder's input, not a file; here beside its decoder's twin above.
TEST(CraftedFiles, HighValenceBaseEncodesInLinearTime) {
    const Hierarchy h(bipyramid(uint32_t(1) << 17));
    EncodeOptions options;
    options.quantize_bits = 12;
    options.threads = 1;
    const double start = cpu_milliseconds();
    const std::vector<uint8_t> file = encode(h, options);
    const double milliseconds = cpu_milliseconds() - start;
    std::printf("  %zu base triangles encoded (%zu bytes): %.1f ms\n", h.base().triangles.size(), file.size(), milliseconds);
    EXPECT_EQ(decode(file.data(), file.size()).root_count(), h.root_count());
    EXPECT_LT(milliseconds, 6000.0);  // 64-68 ms, 1.6 s under ASan (CI); 13 s in Release before
}

// The closed surface of a plate of 2048 x 128 grid cells with a hole through every other cell in
// both directions (31,713 handles, 1.3 M triangles). Each merge of the base coder's conquest (one a
// handle) looked for its tip by a pass over the border loops below the top of the stack, node by
// node, a pass the walk budget did not charge: 3.6 s of CPU for this base's single try until
// 2026-12-07 (which then wrote the explicit mode, 0.37 s after; docs/FUZZING.md). An encoder's
// input, not a file.
TEST(CraftedFiles, BaseOfManyHandlesEncodesInLinearTime) {
    constexpr uint32_t kLength = 2048, kWidth = 128;
    auto id = [](uint32_t i, uint32_t j) { return j * (kLength + 1) + i; };
    TriangleMesh top;
    for (uint32_t j = 0; j <= kWidth; ++j)
        for (uint32_t i = 0; i <= kLength; ++i) top.positions.push_back({double(i), double(j), 0.01 * double((7 * i + 13 * j) % 5)});
    for (uint32_t j = 0; j < kWidth; ++j)
        for (uint32_t i = 0; i < kLength; ++i) {
            if (i % 2 == 1 && j % 2 == 1 && i + 1 < kLength && j + 1 < kWidth) continue;  // a hole
            top.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
            top.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
        }
    // The bottom, a copy turned over one unit below, and a wall under each boundary edge of the top.
    const uint32_t n = uint32_t(top.positions.size());
    TriangleMesh mesh = top;
    for (uint32_t v = 0; v < n; ++v) mesh.positions.push_back(top.positions[v] - Vec3{0, 0, 1});
    for (const Triangle& t : top.triangles) mesh.triangles.push_back({t[0] + n, t[2] + n, t[1] + n});
    std::vector<uint64_t> edges;
    for (const Triangle& t : top.triangles)
        for (int k = 0; k < 3; ++k) edges.push_back(uint64_t(t[k]) << 32 | t[(k + 1) % 3]);
    std::sort(edges.begin(), edges.end());
    for (const Triangle& t : top.triangles)
        for (int k = 0; k < 3; ++k) {
            const uint32_t a = t[k], b = t[(k + 1) % 3];
            if (std::binary_search(edges.begin(), edges.end(), uint64_t(b) << 32 | a)) continue;
            mesh.triangles.push_back({b, a, a + n});
            mesh.triangles.push_back({b, a + n, b + n});
        }
    const double start = cpu_milliseconds();
    const BaseMeshCode code = encode_base_connectivity(mesh, 1, 0);  // the single try
    const double milliseconds = cpu_milliseconds() - start;
    std::printf("  base of %zu triangles coded in mode %d (%zu bytes): %.1f ms\n", mesh.triangles.size(), int(code.mode),
                code.bytes.size(), milliseconds);
    EXPECT_EQ(code.vertex_order.size(), mesh.positions.size());
    EXPECT_LT(milliseconds, 1500.0 * kSanitizerSlowdown);
}

// The caller's numbering of a leaf mesh whose vertices 0 and 1 are the lowest corner of every face
// (a bipyramid of 2^17 sides, its apexes first): found in time linear in the faces. Each face was
// searched among all the faces at its lowest vertex (7 s of CPU here until 2026-12-07;
// docs/FUZZING.md): an encoder's input (encode with a numbering, the importer), not a file.
TEST(CraftedFiles, NumberingOfAVertexLowestInManyFacesIsLinear) {
    TriangleMesh base = bipyramid(uint32_t(1) << 17);
    const uint32_t sides = uint32_t(1) << 17;
    std::vector<uint32_t> renamed(base.positions.size());  // the apexes (last) become 0 and 1
    for (uint32_t v = 0; v < sides; ++v) renamed[v] = v + 2;
    renamed[sides] = 0;
    renamed[sides + 1] = 1;
    std::vector<Vec3> positions(base.positions.size());
    for (uint32_t v = 0; v < positions.size(); ++v) positions[renamed[v]] = base.positions[v];
    base.positions = positions;
    for (Triangle& t : base.triangles)
        for (uint32_t& v : t) v = renamed[v];
    const Hierarchy h(base);
    const LeafMesh leaf = extract_leaf_mesh(h);
    std::vector<VertexId> identity(h.vertex_count());
    for (VertexId v = 0; v < identity.size(); ++v) identity[v] = v;
    const double start = cpu_milliseconds();
    const LeafNumbering numbering = leaf_numbering(h, leaf.mesh, identity);
    const double milliseconds = cpu_milliseconds() - start;
    std::printf("  numbering of %zu faces: %.1f ms\n", leaf.mesh.triangles.size(), milliseconds);
    for (uint32_t j = 0; j < numbering.face.size(); ++j) {
        ASSERT_EQ(numbering.face[j], j);
        ASSERT_EQ(numbering.rotation[j], 0);
    }
    EXPECT_LT(milliseconds, 2000.0);
}

// The leaf mesh of a bipyramid of 2^16 sides refined once (2^18 faces, two vertices of valence
// 2^16): import_mesh finds its base in time linear in it. The level finder searched a block's
// coarse edge for another midpoint in its first vertex's whole star, from every block at an apex:
// 26 s of CPU here (6.9 s at 2^15 sides, 1.9 s at 2^14) until 2026-12-07 (docs/FUZZING.md).
TEST(CraftedFiles, ImportOfAHighValenceLeafMeshIsLinear) {
    Hierarchy refined(bipyramid(uint32_t(1) << 16));
    refine_uniformly(refined, 1);
    const LeafMesh leaf = extract_leaf_mesh(refined);
    const double start = cpu_milliseconds();
    const ImportedHierarchy imported = import_mesh(leaf.mesh, "mesh", 1);  // one thread: cpu_milliseconds counts it all
    const double milliseconds = cpu_milliseconds() - start;
    std::printf("  import of %zu faces: %.1f ms\n", leaf.mesh.triangles.size(), milliseconds);
    EXPECT_EQ(imported.hierarchy.root_count(), refined.root_count());
    EXPECT_EQ(imported.hierarchy.node_count(), refined.node_count());
    EXPECT_LT(milliseconds, 8000.0 * kSanitizerSlowdown);
    // With the base given: each element read at an apex looked its edges up by a scan of the
    // apex's whole fan (5.6 s of CPU here until 2026-12-07).
    const double with_base_start = cpu_milliseconds();
    const ImportedHierarchy with_base = import_leaf_mesh(refined.base(), leaf.mesh);
    const double with_base_milliseconds = cpu_milliseconds() - with_base_start;
    std::printf("  import of %zu faces over their base: %.1f ms\n", leaf.mesh.triangles.size(), with_base_milliseconds);
    EXPECT_EQ(with_base.hierarchy.node_count(), refined.node_count());
    EXPECT_LT(with_base_milliseconds, 3000.0 * kSanitizerSlowdown);
}

// A height field of side x side vertices (spacing 100, heights in [1, 2)) whose positions all have
// the same 64-bit hash_words, the unkeyed hash the importer's position tables used until
// 2026-12-07: the height is solved from the hash's last step (it inverts), the x nudged in its
// last bits until that height lies in [1, 2).
TriangleMesh grid_of_one_position_hash(uint32_t side) {
    auto bits = [](double d) { uint64_t u; std::memcpy(&u, &d, 8); return u; };
    auto real = [](uint64_t u) { double d; std::memcpy(&d, &u, 8); return d; };
    uint64_t inverse_c2 = 0x94d049bb133111ebull;  // Newton's iteration for the inverse mod 2^64
    for (int i = 0; i < 5; ++i) inverse_c2 *= 2 - 0x94d049bb133111ebull * inverse_c2;
    const uint64_t target = 0x0123456789abcdefull, before_multiply = (target ^ (target >> 32)) * inverse_c2;
    TriangleMesh mesh;
    for (uint32_t j = 0; j < side; ++j) {
        for (uint32_t i = 0; i < side; ++i) {
            const double y = 100.0 * j;
            for (uint64_t nudge = 0;; ++nudge) {
                const double x = real(bits(100.0 * i) ^ nudge);
                uint64_t h = bits(x) * kGoldenGamma;
                h = (h ^ (h >> 29) ^ bits(y)) * 0xbf58476d1ce4e5b9ull;
                const double z = real(before_multiply ^ h ^ (h >> 31));
                if (z >= 1.0 && z < 2.0) {
                    mesh.positions.push_back({x, y, z});
                    break;
                }
            }
        }
    }
    for (uint32_t j = 0; j + 1 < side; ++j) {
        for (uint32_t i = 0; i + 1 < side; ++i) {
            const uint32_t a = j * side + i, b = a + 1, c = a + side, d = c + 1;
            mesh.triangles.push_back({a, b, d});
            mesh.triangles.push_back({a, d, c});
        }
    }
    return mesh;
}

// That height field of 40,000 vertices refined once, imported over it: the base's positions and
// the leaf positions' index hashed every vertex into one slot (2.7 s of CPU here until 2026-12-07,
// docs/FUZZING.md; 47 ms since their hash is keyed per process).
TEST(CraftedFiles, ImportOfPositionsOfOneHashIsLinear) {
    const TriangleMesh base = grid_of_one_position_hash(200);
    for (size_t v = 1; v < base.positions.size(); v += 997) {
        const Vec3 p = base.positions[v], q = base.positions[0];
        uint64_t a[3], b[3];
        std::memcpy(a, &p, sizeof a);
        std::memcpy(b, &q, sizeof b);
        ASSERT_EQ(hash_words(a[0], a[1], a[2]), hash_words(b[0], b[1], b[2]));  // the crafting holds
    }
    Hierarchy refined(base);
    refine_uniformly(refined, 1);
    const LeafMesh leaf = extract_leaf_mesh(refined);
    const double start = cpu_milliseconds();
    const ImportedHierarchy imported = import_leaf_mesh(base, leaf.mesh);
    const double milliseconds = cpu_milliseconds() - start;
    std::printf("  import of %zu faces over a base of one position hash: %.1f ms\n", leaf.mesh.triangles.size(),
                milliseconds);
    EXPECT_EQ(imported.hierarchy.node_count(), refined.node_count());
    EXPECT_LT(milliseconds, 1000.0 * kSanitizerSlowdown);
}

// The inverse of an odd number mod 2^64 (Newton's iteration), to solve a multiplicative hash
// for the key that gives a chosen slot.
uint64_t inverse_mod_2_64(uint64_t odd) {
    uint64_t inverse = odd;
    for (int i = 0; i < 5; ++i) inverse *= 2 - odd * inverse;
    return inverse;
}

// Vertex ids 0..count-1, each given out once: at random (take) or as asked (claim), for the
// numberings below that put chosen keys in one slot or run of a table.
class IdPool {
public:
    IdPool(uint32_t count, uint64_t seed) : unused_(count), used_(count, 0), random_{seed} {
        for (uint32_t i = 0; i < count; ++i) unused_[i] = i;
        for (uint32_t i = count; i > 1; --i) std::swap(unused_[i - 1], unused_[random_.below(i)]);
    }
    uint32_t take() {
        while (used_[unused_[next_]]) ++next_;
        used_[unused_[next_]] = 1;
        return unused_[next_];
    }
    bool in_use(uint64_t id) const { return used_[id] != 0; }
    // An id drawn at random from those take has not passed yet (it may be in use).
    uint32_t pick() { return unused_[next_ + random_.below(unused_.size() - next_)]; }
    bool claim(uint64_t id) {
        if (used_[id]) return false;
        used_[id] = 1;
        return true;
    }
    void give_back(uint32_t id) { used_[id] = 0; }
    // The next take draws from the rest at random again (not the id just given back).
    void stir() { std::swap(unused_[next_], unused_[next_ + random_.below(unused_.size() - next_)]); }

private:
    std::vector<uint32_t> unused_;
    std::vector<uint8_t> used_;
    SplitMix64 random_;
    size_t next_ = 0;
};

// The triangulated grid of width x width vertices, vertex v (row v / width) numbered id[v]:
// squares (a, b, d, c) from the lower left, counterclockwise, as triangles (a, b, d) and (a, d, c).
TriangleMesh numbered_grid(uint32_t width, const std::vector<uint32_t>& id) {
    TriangleMesh mesh;
    mesh.positions.resize(id.size());
    for (uint32_t v = 0; v < id.size(); ++v) mesh.positions[id[v]] = {double(v % width), double(v / width), 0};
    for (uint32_t j = 0; j + 1 < width; ++j) {
        for (uint32_t i = 0; i + 1 < width; ++i) {
            const uint32_t a = j * width + i, b = a + 1, c = a + width, d = c + 1;
            mesh.triangles.push_back({id[a], id[b], id[d]});
            mesh.triangles.push_back({id[a], id[d], id[c]});
        }
    }
    return mesh;
}

// A triangulated side x side grid numbered so that one direction of each edge of a perfect
// matching (horizontal pairs) hashes into the first 512 slots of the import's table of directed
// edges (hierarchy_from_levels: open addressing over the next power of two of 6 keys a face), as
// its hash was until 2026-12-07: (k G) ^ (k G >> 29) for k = a << 32 | b. For a given b, the slot
// fixes a modulo 2^(m-3), so a is solved; b is drawn from the unused ids until one fits.
TriangleMesh grid_of_one_edge_run(uint32_t side) {
    const uint32_t vertices = side * side;
    const uint64_t faces = 2ull * (side - 1) * (side - 1);
    uint64_t slots = 16;
    while (slots < 6 * faces) slots *= 2;
    int bits = 0;
    while ((uint64_t(1) << bits) < slots) ++bits;
    const uint64_t mask = slots - 1, residues = uint64_t(1) << (bits - 3);
    const uint64_t inverse = inverse_mod_2_64(kGoldenGamma);
    std::vector<uint32_t> id(vertices, kNoIndex);
    IdPool pool(vertices, 11);
    for (uint32_t v = 0; v + 1 < vertices; v += 2) {  // vertex v + 1 gets a, vertex v gets b
        for (int tries = 0; tries < 8 && id[v] == kNoIndex; ++tries) {
            const uint32_t b = pool.take();
            const uint64_t u = uint64_t(b) * kGoldenGamma;
            for (uint64_t slot = (u ^ (u >> 29)) & 7; slot < 512 && id[v] == kNoIndex; slot += 8) {
                const uint64_t want = ((slot ^ (u & mask)) >> 3) & (residues - 1);
                for (uint64_t a = ((want - (u >> 32)) * inverse) & (residues - 1); a < vertices; a += residues) {
                    if (!pool.claim(a)) continue;
                    id[v + 1] = uint32_t(a);
                    id[v] = b;
                    break;
                }
            }
            if (id[v] == kNoIndex) pool.give_back(b);
            pool.stir();
        }
    }
    for (uint32_t v = 0; v < vertices; ++v)
        if (id[v] == kNoIndex) id[v] = pool.take();
    return numbered_grid(side, id);
}

// That grid (160,000 vertices) imported without a base: the edges of the matching, half the
// vertices, probed one run of slots (3.6-3.8 s of this thread's CPU here until 2026-12-07,
// docs/FUZZING.md); 0.6 s since the table's hash is keyed per process, most of it base detection,
// whose second search a second thread ran: on one thread here (so that this thread's CPU counts
// all of it) 1.4-1.5 s, hence the bound.
TEST(CraftedFiles, ImportOfEdgesInOneProbeRunIsLinear) {
    const TriangleMesh mesh = grid_of_one_edge_run(kSanitizerSlowdown > 1 ? 150 : 400);
    const double start = cpu_milliseconds();
    const ImportedHierarchy imported = import_mesh(mesh, "mesh", 1);
    const double milliseconds = cpu_milliseconds() - start;
    std::printf("  import of a %zu-face grid, a matching's edges in one probe run: %.1f ms\n", mesh.triangles.size(),
                milliseconds);
    EXPECT_EQ(imported.vertex_of_input.size(), mesh.positions.size());
    EXPECT_LT(milliseconds, 3000.0 * kSanitizerSlowdown);
}

// A base of side x side squares (two triangles each) numbered so that the horizontal edges of a
// matching, one on every other square of each inner grid line, key the first 512 slots of the
// seam's table of segments, as its Fibonacci hash did until 2026-12-07: slot = (a G + (b G >> 32))
// mod 2^m for the key a << 32 | b (a < b), so for each b an a < b is solved. With keep_base_order
// and one chunk per row of squares, every inner horizontal edge is a seam edge.
Hierarchy chunk_rows_of_one_seam_run(uint32_t side, EncodeOptions& options) {
    const uint32_t width = side + 1, vertices = width * width;
    const uint64_t keys = uint64_t(side) * (side - 1);  // the seam edges, each one unsplit segment
    uint64_t slots = 16;
    while (slots < 2 * keys) slots *= 2;  // the table is at most half full
    const uint64_t mask = slots - 1;
    const uint64_t inverse = inverse_mod_2_64(kGoldenGamma);
    std::vector<uint32_t> id(vertices, kNoIndex);
    IdPool pool(vertices, 13);
    for (uint32_t j = 1; j < side; ++j) {
        for (uint32_t i = 0; i + 1 <= side; i += 2) {
            const uint32_t first = j * width + i;  // gets a; first + 1 gets b
            for (int tries = 0; tries < 8 && id[first] == kNoIndex; ++tries) {
                const uint32_t b = pool.take();
                const uint64_t high = (uint64_t(b) * kGoldenGamma) >> 32;
                for (uint64_t slot = 0; slot < 512 && id[first] == kNoIndex; ++slot) {
                    const uint64_t a = (((slot - high) & mask) * inverse) & mask;
                    if (a >= b || !pool.claim(a)) continue;
                    id[first] = uint32_t(a);
                    id[first + 1] = b;
                }
                if (id[first] == kNoIndex) pool.give_back(b);
                pool.stir();
            }
        }
    }
    for (uint32_t v = 0; v < vertices; ++v)
        if (id[v] == kNoIndex) id[v] = pool.take();
    options.keep_base_order = true;
    options.chunk_roots.assign(side, 2 * side);
    options.threads = 1;
    return Hierarchy(numbered_grid(width, id));
}

// That base's chunked file: its decoder (and encoder) set every seam segment in the table, a
// matching's (a quarter of the base vertices) in one probe run: super-linear until 2026-12-07
// (docs/FUZZING.md).
TEST(CraftedFiles, SeamSegmentsInOneProbeRunDecodeInLinearTime) {
    EncodeOptions options;
    const Hierarchy h = chunk_rows_of_one_seam_run(kSanitizerSlowdown > 1 ? 100 : 300, options);
    const std::vector<uint8_t> file = encode(h, options);
    DecodeOptions decode_options;
    decode_options.threads = 1;
    const double start = cpu_milliseconds();
    const Hierarchy decoded = decode(file.data(), file.size(), decode_options);
    const double milliseconds = cpu_milliseconds() - start;
    std::printf("  decode of %u roots in %zu chunks, a matching's seam segments in one probe run: %.1f ms\n",
                h.root_count(), options.chunk_roots.size(), milliseconds);
    EXPECT_EQ(decoded.root_count(), h.root_count());
    EXPECT_EQ(decoded.base().triangles, h.base().triangles);  // the base kept in its order
    EXPECT_LT(milliseconds, 1000.0 * kSanitizerSlowdown);
}

// A base of side x side squares numbered so that, in the quarter of its rows that rank 0 owns,
// edge a -> b of each square's bottom (every other square) has a << 32 | b = 0 modulo P, the
// prime bucket count rank 0's table of its directed edges (seam_splits) reaches, where libstdc++
// hashes an integer to itself, as it did until 2026-12-07: for a drawn a, b is solved (the other
// three quarters' vertices leave every residue one or more ids below the vertex count).
TEST(CraftedFiles, RankEdgesInOneBucketSplitTheSeamInLinearTime) {
    const uint32_t side = kSanitizerSlowdown > 1 ? 200 : 480, width = side + 1, vertices = width * width;
    const uint32_t rows = side / 4, owned = 2 * side * rows;
    std::unordered_map<uint64_t, std::pair<NodeId, int>> same_size;  // its bucket count, as the table's
    for (uint64_t k = 0; k < 3ull * owned; ++k) same_size.emplace(k, std::make_pair(NodeId(0), 0));
    const uint64_t buckets = same_size.bucket_count(), shift = (uint64_t(1) << 32) % buckets;
    std::vector<uint32_t> id(vertices, kNoIndex);
    IdPool pool(vertices, 17);
    size_t in_one_bucket = 0;
    for (uint32_t j = 0; j < rows; ++j) {
        for (uint32_t i = 0; i + 1 <= side; i += 2) {
            const uint32_t first = j * width + i;  // gets a; first + 1 gets b
            for (int tries = 0; tries < 64 && id[first] == kNoIndex; ++tries) {
                const uint64_t a = pool.pick();
                if (pool.in_use(a)) continue;
                for (uint64_t b = (buckets - a % buckets * shift % buckets) % buckets; b < vertices; b += buckets) {
                    if (b == a || !pool.claim(b)) continue;
                    pool.claim(a);
                    id[first] = uint32_t(a);
                    id[first + 1] = uint32_t(b);
                    ++in_one_bucket;
                    break;
                }
            }
        }
    }
    for (uint32_t v = 0; v < vertices; ++v)
        if (id[v] == kNoIndex) id[v] = pool.take();
    const TriangleMesh base = numbered_grid(width, id);
    const uint32_t roots = uint32_t(base.triangles.size());
    const RankLayout layout = rank_layout(roots, {{0, owned}, {owned, roots - owned}});
    const Hierarchy forest = extract_roots(Hierarchy(base), {RootRange{0, owned}});
    const double start = cpu_milliseconds();
    const RankChunk part = rank_chunk(base, 0, forest, "rank 0");
    const std::vector<SeamSplit> splits = seam_splits(part, base, layout);
    const double milliseconds = cpu_milliseconds() - start;
    std::printf("  rank 0's %u roots, %zu directed edges in one of %llu buckets: %.1f ms\n", owned, in_one_bucket,
                (unsigned long long)buckets, milliseconds);
    EXPECT_GT(in_one_bucket, size_t(owned) / 5);  // the numbering does what it is meant to
    EXPECT_TRUE(splits.empty());                  // nothing refined: no seam vertex
    EXPECT_LT(milliseconds, 1000.0 * kSanitizerSlowdown);
}

// A half disc of 2^15 roots around one boundary vertex, in clockwise order, refined once with its
// new vertices moved off their edges: the uniform way reads it in time linear in it. Each root at
// that vertex searched its out-edges for the one toward its next corner, since its turn around
// the vertex stops at the boundary at once: 31 s of CPU here until 2026-12-07 (docs/FUZZING.md).
TEST(CraftedFiles, UniformImportAtABoundaryVertexOfManyRootsIsLinear) {
    const uint32_t roots = uint32_t(1) << 15;
    TriangleMesh base;
    base.positions.push_back({0, 0, 0});
    for (uint32_t i = 0; i <= roots; ++i) {
        const double angle = 3.141592653589793 * double(i) / double(roots);
        base.positions.push_back({std::cos(angle), std::sin(angle), 0});
    }
    for (uint32_t i = roots; i-- > 0;) base.triangles.push_back({0, i + 1, i + 2});
    Hierarchy refined(base);
    refine_uniformly(refined, 1);
    LeafMesh leaf = extract_leaf_mesh(refined);
    for (size_t v = base.positions.size(); v < leaf.mesh.positions.size(); ++v) leaf.mesh.positions[v].z = 0.01;
    const double start = cpu_milliseconds();
    const ImportedHierarchy imported = import_leaf_mesh(base, leaf.mesh);
    const double milliseconds = cpu_milliseconds() - start;
    std::printf("  import of %zu faces over %u roots: %.1f ms\n", leaf.mesh.triangles.size(), roots, milliseconds);
    EXPECT_EQ(imported.hierarchy.node_count(), refined.node_count());
    EXPECT_EQ(imported.hierarchy.depth(), 1);
    EXPECT_LT(milliseconds, 3000.0 * kSanitizerSlowdown);
}

// A grid base of side x side squares and one far triangle (every grid vertex then in one Morton
// cell, so that the importer's spatial order is the input's), refined once with its new vertices
// off their midpoints: the uniform way. Each inner base vertex x first asks for its ray toward its
// lower left neighbour y, so the key x << 32 | y is inserted in the ray finder's table; the leaf
// numbers x and y so that the key is 0 modulo the prime bucket count the table reaches (libstdc++
// hashes an integer to itself), for a matching (x in every other row): super-linear until 2026-12-07.
TEST(CraftedFiles, UniformImportOfRaysInOneBucketIsLinear) {
    const uint32_t side = kSanitizerSlowdown > 1 ? 100 : 250, width = side + 1;
    TriangleMesh base = numbered_grid(width, [&] {
        std::vector<uint32_t> identity(size_t(width) * width);
        for (uint32_t v = 0; v < identity.size(); ++v) identity[v] = v;
        return identity;
    }());
    const uint32_t far = uint32_t(base.positions.size());
    base.positions.insert(base.positions.end(), {{1e9, 0, 0}, {1e9 + 1, 0, 0}, {1e9, 1, 0}});
    base.triangles.push_back({far, far + 1, far + 2});
    Hierarchy refined(base);
    refine_uniformly(refined, 1);
    const LeafMesh leaf = extract_leaf_mesh(refined);
    const uint32_t vertices = uint32_t(leaf.mesh.positions.size()), near = vertices - 6;  // the far triangle's last
    std::unordered_map<uint64_t, uint32_t> same_size;  // its bucket count, as the table's (about a key per base vertex)
    for (uint64_t k = 0; k < uint64_t(width) * width; ++k) same_size.emplace(k, 0);
    const uint64_t buckets = same_size.bucket_count(), shift = (uint64_t(1) << 32) % buckets;
    std::vector<uint32_t> id(vertices, kNoIndex);
    IdPool pool(near, 19);
    size_t in_one_bucket = 0;
    for (uint32_t j = 1; j <= side; j += 2) {
        for (uint32_t i = 1; i <= side; ++i) {
            const uint32_t x = j * width + i, y = x - width - 1;  // hierarchy ids: base vertices first
            for (int tries = 0; tries < 64 && id[x] == kNoIndex; ++tries) {
                const uint64_t a = pool.pick();
                if (pool.in_use(a)) continue;
                for (uint64_t b = (buckets - a % buckets * shift % buckets) % buckets; b < near; b += buckets) {
                    if (b == a || !pool.claim(b)) continue;
                    pool.claim(a);
                    id[x] = uint32_t(a);
                    id[y] = uint32_t(b);
                    ++in_one_bucket;
                    break;
                }
            }
        }
    }
    uint32_t far_id = near;
    for (uint32_t v = 0; v < vertices; ++v) {
        if (id[v] != kNoIndex) continue;
        if (leaf.mesh.positions[v].x > 1e8) {
            id[v] = far_id++;
            continue;
        }
        id[v] = pool.take();
    }
    TriangleMesh input;
    input.positions.resize(vertices);
    for (uint32_t v = 0; v < vertices; ++v) input.positions[id[v]] = leaf.mesh.positions[v];
    for (uint32_t v = far + 3; v < vertices; ++v) input.positions[id[v]].z = 0.01;  // new vertices off their midpoints
    for (const Triangle& t : leaf.mesh.triangles) input.triangles.push_back({id[t[0]], id[t[1]], id[t[2]]});
    const double start = cpu_milliseconds();
    const ImportedHierarchy imported = import_leaf_mesh(base, input);
    const double milliseconds = cpu_milliseconds() - start;
    std::printf("  uniform import of %zu faces, %zu rays in one of %llu buckets: %.1f ms\n", input.triangles.size(),
                in_one_bucket, (unsigned long long)buckets, milliseconds);
    EXPECT_GT(in_one_bucket, size_t(side) * side / 3);  // the numbering does what it is meant to
    EXPECT_EQ(imported.hierarchy.node_count(), refined.node_count());
    EXPECT_LT(milliseconds, 1000.0 * kSanitizerSlowdown);
}

// A step coarsening a chain of 2^15 candidates in a row of roots, each freed only by the one
// after it (its third neighbour refined), in time linear in them: each pass over the row freed one,
// 23 s of CPU here until 2026-12-07 (docs/FUZZING.md). A library caller's history, not a file.
TEST(CraftedFiles, CoarseningAChainOfCandidatesIsLinear) {
    const uint32_t width = uint32_t(1) << 14;  // three rows of 2 * width roots
    TriangleMesh base;
    for (uint32_t j = 0; j <= 3; ++j)
        for (uint32_t i = 0; i <= width; ++i) base.positions.push_back({i + 0.5 * j, 0.866 * j, 0});
    const auto vertex = [&](uint32_t i, uint32_t j) { return j * (width + 1) + i; };
    for (uint32_t j = 0; j < 3; ++j)
        for (uint32_t i = 0; i < width; ++i) {
            base.triangles.push_back({vertex(i, j), vertex(i + 1, j), vertex(i, j + 1)});
            base.triangles.push_back({vertex(i + 1, j), vertex(i + 1, j + 1), vertex(i, j + 1)});
        }
    // Every root refined but the middle row's last: that row's others but its first are the chain,
    // each (the last but one first) free once the one after it is a leaf again.
    Hierarchy h(base);
    const NodeId first = 2 * width, last = 4 * width - 1;
    for (NodeId r = 0; r < h.root_count(); ++r)
        if (r != last) h.refine(r);
    const LeafMesh leaf = extract_leaf_mesh(h);
    std::vector<uint32_t> coarsen;
    for (uint32_t e = 0; e < leaf.source.size(); ++e) {
        const NodeId parent = h.parent(leaf.source[e]);
        if (parent > first && parent < last) coarsen.push_back(e);
    }
    const double start = cpu_milliseconds();
    apply_adaptation_step(h, {}, coarsen);
    const double milliseconds = cpu_milliseconds() - start;
    std::printf("  a chain of %u candidates coarsened: %.1f ms\n", last - first - 1, milliseconds);
    for (NodeId r = 0; r < h.root_count(); ++r) ASSERT_EQ(h.is_leaf(r), r > first && r <= last) << "root " << r;
    EXPECT_EQ(check_invariants(h), "");
    EXPECT_LT(milliseconds, 2000.0 * kSanitizerSlowdown);
}

// The leaf mesh of a random refinement of the icosahedron (about 27,000 faces) with every new
// vertex at one point, its centre, imported over its base: refused in time linear in it. Every
// vertex is then equally near each guide, and each guided way's nearest-vertex searches examined
// (and tested) them all: 10.2 s of CPU here until 2026-12-07 (60 s at four times the faces;
// docs/FUZZING.md). A way's searches are now budgeted, and ties no longer test vertices as far.
TEST(CraftedFiles, ImportOfALeafMeshWithItsNewVerticesAtOnePointIsLinear) {
    Hierarchy h(make_icosahedron());
    refine_randomly(h, 20000, 7, 3);
    LeafMesh leaf = extract_leaf_mesh(h);
    uint32_t moved = 0;
    for (Vec3& p : leaf.mesh.positions) {
        bool at_base = false;
        for (const Vec3& b : h.base().positions) at_base |= p.x == b.x && p.y == b.y && p.z == b.z;
        if (!at_base) p = Vec3{0, 0, 0}, ++moved;
    }
    ASSERT_GT(moved, 10000u);
    const double start = cpu_milliseconds();
    std::string message;
    try {
        import_leaf_mesh(h.base(), leaf.mesh);
    } catch (const Error& e) {
        message = e.what();
    }
    const double milliseconds = cpu_milliseconds() - start;
    std::printf("  import of %zu faces, %u vertices at one point: %.1f ms\n", leaf.mesh.triangles.size(), moved,
                milliseconds);
    EXPECT_NE(message.find("have the same position (0, 0, 0) (duplicate vertex)"), std::string::npos) << message;
    EXPECT_LT(milliseconds, 4000.0 * kSanitizerSlowdown);
}

// A random refinement of the icosahedron scaled by 10^-300 beside one far triangle at +-1.7 * 10^308
// (beyond DBL_MAX / 2, where a + b overflows), refined with it: imported with its base as amcodec
// wrote it, by the exact way. That way looked each midpoint up at 0.5 * (a + b), infinite on the
// far triangle's edges, where the placer puts 0.5 * a + 0.5 * b; the guided ways after it find no
// vertex where squared distances underflow (the icosahedron's): refused until 2026-12-07
// (docs/FUZZING.md, "review of far components").
TEST(CraftedFiles, ImportBesideAFarTriangleBeyondHalfOfDblMaxFindsItsMidpoints) {
    for (const double far : {1.7e308, -1.7e308}) {
        TriangleMesh base = make_icosahedron();
        for (Vec3& p : base.positions) p = 1e-300 * p;
        const uint32_t v = uint32_t(base.positions.size());
        base.positions.insert(base.positions.end(), {{far, 0, 0}, {far, 1, 0}, {far, 0, 1}});
        base.triangles.push_back({v, v + 1, v + 2});
        Hierarchy h(base);
        refine_randomly(h, 20000, 7, 3);
        ASSERT_FALSE(h.is_leaf(h.root_count() - 1));  // the far triangle is split: its midpoints are looked up
        const LeafMesh leaf = extract_leaf_mesh(h);
        const ImportedHierarchy imported = import_leaf_mesh(base, leaf.mesh);
        EXPECT_TRUE(identical(imported.hierarchy, h)) << far;
    }
}

// The importer's measure of a candidate's detour across a bipyramid of 2^17 sides, whose poles'
// fans are closed and of valence 2^17: in time linear in the valence. Whether a fan was closed
// was found by looking each apex up among its ends, 1.7 * 10^10 comparisons here (2.1 s of CPU)
// until 2026-12-07 (docs/FUZZING.md); the neighbours are now the index's, each once.
TEST(CraftedFiles, DetourAcrossAFanOfHighValenceIsLinear) {
    const uint32_t sides = uint32_t(1) << 17;
    const TriangleMesh mesh = bipyramid(sides);
    const uint32_t north = sides;  // bipyramid's first apex
    const LeafHalfedges halfedges(mesh);
    LeafDetour detour(halfedges);
    uint32_t candidates[2] = {north, sides / 2 + 1};
    const double start = cpu_milliseconds();
    const uint32_t kept = detour.keep_least_detour(0, sides / 2, 2, candidates, 2);
    const double milliseconds = cpu_milliseconds() - start;
    std::printf("  detour across a fan of %u: %.1f ms\n", sides, milliseconds);
    EXPECT_EQ(kept, 1u);  // 0-north-b has no detour; sides/2 + 1 is two hops from 0, one from b
    EXPECT_EQ(candidates[0], north);
    EXPECT_LT(milliseconds, 300.0 * kSanitizerSlowdown);
}

// 5,000 closest points near the apex of a bipyramid of 2^16 sides, 1e-3 off the middle of a face 1-50 %
// of the way to the rim: the boxes of its long triangles all overlap there, so each query tested a
// share of all of them until 2026-12-07 (docs/REMESHER.md, "Fans of long triangles"); the apexes'
// fans are now searched by their directions from the apex (ClosestPointQuery's direction cones).
TEST(CraftedFiles, ClosestPointsNearAVertexOfHighValenceTestFewTriangles) {
    const uint32_t sides = uint32_t(1) << (kSanitizerSlowdown > 1 ? 13 : 16);
    const TriangleMesh mesh = bipyramid(sides);
    const Vec3 apex = mesh.positions[sides];
    const int kQueries = kSanitizerSlowdown > 1 ? 1000 : 5000;
    const ClosestPointQuery query(mesh);
    uint64_t tested = 0;
    const double start = cpu_milliseconds();
    for (int i = 0; i < kQueries; ++i) {
        const uint32_t face = uint32_t((uint64_t(i) * 2654435761u) % sides);  // upper triangle 2 * face
        const Vec3 a = mesh.positions[face], b = mesh.positions[(face + 1) % sides];
        const Vec3 normal = cross(b - a, apex - a);
        const double t = 0.01 + 0.49 * double(i) / kQueries;
        const Vec3 on = (1 - t) * apex + t * (0.5 * (a + b));
        const Vec3 p = on + (1e-3 / std::sqrt(dot(normal, normal))) * normal;
        const ClosestPointQuery::Hit hit = query.closest(p, tested);
        ASSERT_EQ(hit.triangle, 2 * face) << i;
        ASSERT_NEAR(std::sqrt(hit.distance_squared), 1e-3, 1e-12) << i;
    }
    const double milliseconds = cpu_milliseconds() - start;
    std::printf("  %d closest points near the apex of a bipyramid of %u sides: %.1f ms, %.1f boxes and triangles tested each\n",
                kQueries, sides, milliseconds, double(tested) / kQueries);
    EXPECT_LT(tested, 100u * kQueries);  // 59.6 a query; 21,725 before
    EXPECT_LT(milliseconds, 300.0 * kSanitizerSlowdown);  // 20 ms in Release; 1.45 s before
    // The same points projected along the face's normal (as the remesher places a vertex): the
    // fan's cones prune the lines too (8.6 ms in Release; 1,414 ms with its boxes alone).
    const double lines_start = cpu_milliseconds();
    for (int i = 0; i < kQueries; ++i) {
        const uint32_t face = uint32_t((uint64_t(i) * 2654435761u) % sides);
        const Vec3 a = mesh.positions[face], b = mesh.positions[(face + 1) % sides];
        const Vec3 normal = cross(b - a, apex - a);
        const double t = 0.01 + 0.49 * double(i) / kQueries;
        const Vec3 on = (1 - t) * apex + t * (0.5 * (a + b));
        const Vec3 p = on + (1e-3 / std::sqrt(dot(normal, normal))) * normal;
        const std::optional<ClosestPointQuery::Hit> hit = query.intersect_line(p, normal, 2e-3);
        ASSERT_TRUE(hit.has_value()) << i;
        ASSERT_EQ(hit->triangle, 2 * face) << i;
    }
    const double lines_milliseconds = cpu_milliseconds() - lines_start;
    std::printf("  %d lines through them: %.1f ms\n", kQueries, lines_milliseconds);
    EXPECT_LT(lines_milliseconds, 300.0 * kSanitizerSlowdown);
}

// Closest points and lines 10^-3 above faces of a unit square (the first `square_faces` of `mesh`,
// which may have been moved, with more triangles after them): each finds its face, at that
// distance within `tolerance`. Adds the boxes and triangles the closest points tested to `tested`.
void query_above_square(const TriangleMesh& mesh, uint32_t square_faces, int queries, double tolerance, uint64_t& tested) {
    const ClosestPointQuery query(mesh);
    for (int i = 0; i < queries; ++i) {
        const uint32_t face = uint32_t((uint64_t(i) * 2654435761u) % square_faces);
        const Triangle& t = mesh.triangles[face];
        const Vec3 a = mesh.positions[t[0]], b = mesh.positions[t[1]], c = mesh.positions[t[2]];
        const Vec3 normal = cross(b - a, c - a);
        const Vec3 up = (1 / std::sqrt(dot(normal, normal))) * normal;
        const Vec3 p = (1.0 / 3) * a + (1.0 / 3) * b + (1.0 / 3) * c + 1e-3 * up;
        const ClosestPointQuery::Hit hit = query.closest(p, tested);
        ASSERT_EQ(hit.triangle, face) << i;
        ASSERT_NEAR(std::sqrt(hit.distance_squared), 1e-3, tolerance) << i;
        const std::optional<ClosestPointQuery::Hit> line = query.intersect_line(p, up, 2e-3, 1e-9);
        ASSERT_TRUE(line.has_value()) << i;
        ASSERT_EQ(line->triangle, face) << i;
    }
}

// Closest points and lines 10^-3 above the faces of a unit square of 2 * 256^2 triangles that has
// one more triangle far away (10^15, then 10^300): each query tests a few boxes and triangles. Every
// box was widened by the rounding margin of the mesh's largest coordinate, the far one's, so by
// more than the square (3.6 at 10^15; float infinity at 10^300), and each query tested all of
// them: the guided ways' surface and normal-ray guides of a leaf mesh with a far component took
// time quadratic in it until 2026-12-07 (docs/FUZZING.md, "review of far components").
TEST(CraftedFiles, ClosestPointsBesideAFarTriangleTestFewBoxes) {
    const int cells = kSanitizerSlowdown > 1 ? 64 : 256;
    const int kQueries = 2000;
    for (const double far : {1e15, 1e300}) {
        TriangleMesh mesh = make_square(cells);
        const uint32_t square_faces = uint32_t(mesh.triangles.size()), v = uint32_t(mesh.positions.size());
        mesh.positions.insert(mesh.positions.end(), {{far, 0, 0}, {far, 1, 0}, {far, 0, 1}});
        mesh.triangles.push_back({v, v + 1, v + 2});
        uint64_t tested = 0;
        const double start = cpu_milliseconds();
        query_above_square(mesh, square_faces, kQueries, 1e-12, tested);
        if (HasFatalFailure()) return;
        const double milliseconds = cpu_milliseconds() - start;
        std::printf("  %d closest points and lines beside a triangle %g away: %.1f ms, %.1f boxes and triangles tested each\n",
                    kQueries, far, milliseconds, double(tested) / kQueries);
        EXPECT_LT(tested, 100u * kQueries) << far;  // all 2 * 256^2 triangles and their boxes before
        EXPECT_LT(milliseconds, 300.0 * kSanitizerSlowdown) << far;
    }
}

// Closest points and lines 10^-3 above the faces of a unit square of 2 * 256^2 triangles moved 10^9
// and 10^11 away from the origin (and once with one more triangle 10^15 beyond it): each query tests
// a few boxes and triangles. The boxes were floats of absolute coordinates, whose ulp there (64;
// 8,192) is larger than the square: every box was the whole square and every query tested all of
// them (a leaf mesh at 10^9 imported in 22.6 s instead of 0.3 s) until 2026-12-07 (docs/FUZZING.md,
// "the lead, following the review of far components").
TEST(CraftedFiles, ClosestPointsOnAMeshFarFromTheOriginTestFewBoxes) {
    const int cells = kSanitizerSlowdown > 1 ? 64 : 256;
    const int kQueries = 2000;
    struct Case {
        double offset;
        bool far_triangle;
    };
    for (const Case c : {Case{1e9, false}, Case{1e11, false}, Case{1e9, true}}) {
        TriangleMesh mesh = make_square(cells);
        for (Vec3& p : mesh.positions) p = p + Vec3{c.offset, -c.offset, 0.5 * c.offset};
        const uint32_t square_faces = uint32_t(mesh.triangles.size()), v = uint32_t(mesh.positions.size());
        if (c.far_triangle) {
            mesh.positions.insert(mesh.positions.end(), {{1e15, 0, 0}, {1e15, 1, 0}, {1e15, 0, 1}});
            mesh.triangles.push_back({v, v + 1, v + 2});
        }
        uint64_t tested = 0;
        query_above_square(mesh, square_faces, kQueries, 1e-4, tested);  // coordinates' ulp: 1.5e-5 at 10^11
        if (HasFatalFailure()) return;
        std::printf("  %d closest points and lines on a square %g from the origin%s: %.1f boxes and triangles tested each\n",
                    kQueries, c.offset, c.far_triangle ? " beside a triangle at 1e15" : "", double(tested) / kQueries);
        EXPECT_LT(tested, 100u * kQueries) << c.offset;  // all 2 * 256^2 triangles and their boxes before
    }
}

// The distance between a bipyramid of 2^11 sides without shared vertices and itself (its long
// triangles' boxes all overlap near the apexes, so a closest-point query there tests every one):
// refused as not measured in time linear in the mesh. The measure ran its 4 * 10^6 evaluations at
// about 400 boxes and triangles each (`amc refine --model surface` of the bipyramid measured for
// 31.5 s of CPU, of 2^13 sides 99.6 s) until 2026-12-07 (docs/FUZZING.md). With its vertices
// shared the bipyramid is now measured: its apexes' fans are searched by direction cones.
TEST(CraftedFiles, DistanceToAFanOfLongTrianglesIsNotMeasuredForLong) {
    const uint32_t sides = uint32_t(1) << 11;
    const TriangleMesh fan = testing::without_shared_vertices(bipyramid(sides));
    const double start = cpu_milliseconds();
    const SurfaceDistance d = surface_distance(fan, fan);
    const double milliseconds = cpu_milliseconds() - start;
    std::printf("  distance of a bipyramid of %u sides to itself: %.1f ms, %llu evaluations\n", sides, milliseconds,
                (unsigned long long)d.to_reference.evaluations);
    EXPECT_FALSE(d.complete());
    EXPECT_LT(milliseconds, 2000.0 * kSanitizerSlowdown);
    // An octahedron, whose boxes barely overlap, is measured: 0 to itself.
    TriangleMesh octahedron;
    octahedron.positions = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    octahedron.triangles = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
    const SurfaceDistance same = surface_distance(octahedron, octahedron, 1e-2);
    EXPECT_TRUE(same.complete());
    EXPECT_LT(same.max_upper, 2e-2);
}

// A height field of side x side squares, two triangles each, over [0, 1]^2; `jitter` (a fraction
// of a square) moves the inner vertices off the lattice, so that relaxation has work.
TriangleMesh bumpy_grid(uint32_t side, double jitter = 0) {
    TriangleMesh mesh = make_square(int(side));
    for (Vec3& p : mesh.positions) {
        const double i = std::round(p.x * side), j = std::round(p.y * side);
        const bool inner = i > 0 && j > 0 && i < side && j < side;
        const double dx = inner ? jitter * std::sin(12.9898 * i + 78.233 * j) : 0;
        const double dy = inner ? jitter * std::cos(39.346 * i + 11.135 * j) : 0;
        const double x = (i + dx) / side, y = (j + dy) / side;
        p = {x, y, 0.05 * std::sin(6 * x) * std::cos(5 * y)};
    }
    return mesh;
}

// The remesher's base improvement of a large base (20,000 triangles) on a reference of 40,401
// vertices, in time linear in both: the largest distance of a reference vertex to the base, its
// bound, was a loop over every base triangle for every reference vertex (`amc refine --model
// surface --base-faces 20000` of bunny-hr spent 14 of its 16.5 s there) until 2026-12-07
// (docs/FUZZING.md).
TEST(CraftedFiles, ShapeImprovementOfALargeBaseIsLinear) {
    const TriangleMesh reference = bumpy_grid(200);
    const ReferenceSurface surface(reference);
    TriangleMesh base = bumpy_grid(100, 0.3);
    const std::vector<uint8_t> locked(base.positions.size(), 0);
    const double start = cpu_milliseconds();
    const ShapeImprovementStats stats = improve_shapes(base, surface, reference, locked);
    const double milliseconds = cpu_milliseconds() - start;
    std::printf("  shape improvement of %zu triangles on %zu reference vertices: %.1f ms, %u flips, %u moves\n",
                base.triangles.size(), reference.positions.size(), milliseconds, stats.flips, stats.moves);
    EXPECT_EQ(stats.fold_overs_after, 0u);
    EXPECT_GE(stats.min_quality_after, stats.min_quality_before);
    EXPECT_LT(milliseconds, 1500.0 * kSanitizerSlowdown);
}

// The remesher's base improvement of a bipyramid of 2^13 sides, apexes off its axis, on itself:
// the guard of an apex's move compared each reference vertex its ring owns with every triangle of
// the ring, time the square of the valence, until 2026-12-07; the ring is now searched by a
// ClosestPointQuery, whose apex forms a fan of direction cones (docs/REMESHER.md, "Fans of long
// triangles").
TEST(CraftedFiles, ShapeImprovementAroundAVertexOfHighValenceIsFast) {
    const uint32_t sides = uint32_t(1) << (kSanitizerSlowdown > 1 ? 11 : 13);
    TriangleMesh reference = bipyramid(sides);
    reference.positions[sides] = {0.3, 0.1, 1};
    reference.positions[sides + 1] = {-0.2, 0.1, -1};
    const ReferenceSurface surface(reference);
    TriangleMesh base = reference;
    const std::vector<uint8_t> locked(base.positions.size(), 0);
    const double start = cpu_milliseconds();
    const ShapeImprovementStats stats = improve_shapes(base, surface, reference, locked);
    const double milliseconds = cpu_milliseconds() - start;
    std::printf("  shape improvement of a bipyramid of %u sides on itself: %.1f ms, %u flips, %u moves\n", sides, milliseconds,
                stats.flips, stats.moves);
    EXPECT_EQ(stats.fold_overs_after, 0u);
    EXPECT_GE(stats.min_quality_after, stats.min_quality_before);
    EXPECT_LT(milliseconds, 600.0 * kSanitizerSlowdown);  // 199 ms in Release; 1,932 ms before
}

// A series of 2^17 unchanged frames over a tetrahedron after one keyframe (3.5 MB), read in order
// in time linear in the frames: each frame(k) walked back to the keyframe to find where to start,
// though the reader held frame k - 1 (6.6 s of CPU until 2026-12-07, docs/FUZZING.md; `amc
// series decode` reads every frame so).
TEST(CraftedFiles, SeriesOfManyFramesAfterOneKeyframeReadsInLinearTime) {
    TriangleMesh base;
    base.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    base.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
    const Hierarchy h(base);
    SeriesOptions options;
    options.choose_keyframes = false;
    SeriesWriter writer(h.base(), options);
    const size_t frames = size_t(1) << 17;
    for (size_t k = 0; k < frames; ++k) writer.add_frame(h, double(k));
    writer.close();
    SeriesReader reader(writer.bytes(), "frames.amcs");
    ASSERT_EQ(reader.frame_count(), frames);
    const double start = cpu_milliseconds();
    size_t nodes = 0;
    for (size_t k = 0; k < frames; ++k) nodes += reader.frame(k).hierarchy.node_count();
    const double milliseconds = cpu_milliseconds() - start;
    std::printf("  %zu frames (%zu bytes) read in order: %.1f ms\n", frames, writer.bytes().size(), milliseconds);
    EXPECT_EQ(nodes, 4 * frames);
    EXPECT_FALSE(reader.info(frames - 1).keyframe);
    EXPECT_TRUE(identical(reader.frame(frames / 2).hierarchy, h));  // random access still from the keyframe
    EXPECT_LT(milliseconds, 3000.0 * kSanitizerSlowdown);  // 5.0 s under ASan (CI)
}

// A VTU of 2^15 pieces of one triangle each (ASCII, 13 MB): read in memory linear in its points.
// Each piece reserved exactly its points on top of the earlier ones', so every piece copied all
// the points before it: 38 GB allocated, 8 s of CPU (mostly the kernel's page faults) until
// 2026-12-07 (docs/FUZZING.md).
TEST(CraftedFiles, VtuOfManyPiecesReadsInLinearMemory) {
    const uint32_t pieces = uint32_t(1) << 15;
    std::string vtu = "<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n<UnstructuredGrid>\n";
    for (uint32_t k = 0; k < pieces; ++k) {
        const std::string x = std::to_string(k);
        vtu += "<Piece NumberOfPoints=\"3\" NumberOfCells=\"1\"><Points><DataArray type=\"Float64\" "
               "NumberOfComponents=\"3\" format=\"ascii\">" + x + " 0 0 " + x + " 1 0 " + x + ".5 0 1</DataArray></Points>"
               "<Cells><DataArray type=\"Int32\" Name=\"connectivity\" format=\"ascii\">0 1 2</DataArray>"
               "<DataArray type=\"Int32\" Name=\"offsets\" format=\"ascii\">3</DataArray>"
               "<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">5</DataArray></Cells></Piece>\n";
    }
    vtu += "</UnstructuredGrid>\n</VTKFile>\n";
    const uint64_t allocated_before = g_allocated.load();
    const double start = cpu_milliseconds();
    const VtuMesh mesh = parse_vtu(vtu, "pieces.vtu", 1);
    const double milliseconds = cpu_milliseconds() - start;
    const uint64_t allocated = g_allocated.load() - allocated_before;
    std::printf("  %u pieces (%zu bytes): %.1f ms, %.1f MB allocated\n", pieces, vtu.size(), milliseconds, 1e-6 * double(allocated));
    ASSERT_EQ(mesh.mesh.positions.size(), 3 * size_t(pieces));
    ASSERT_EQ(mesh.mesh.triangles.size(), size_t(pieces));
    EXPECT_EQ(mesh.mesh.positions.back().x, double(pieces - 1) + 0.5);
    EXPECT_EQ(mesh.mesh.triangles.back(), (Triangle{3 * pieces - 3, 3 * pieces - 2, 3 * pieces - 1}));
    EXPECT_LT(allocated, uint64_t(200) << 20);
    EXPECT_LT(milliseconds, 4000.0);
}

// A ParaView collection of 2^15 DataSets (2.3 MB): read in time linear in them. Each DataSet's
// line was counted from the start of the file for a message it would only need on an error: 9.5 s
// of CPU until 2026-12-07 (docs/FUZZING.md; `amc series encode` of a .pvd reads it first).
TEST(CraftedFiles, PvdOfManyDataSetsReadsInLinearTime) {
    const uint32_t entries = uint32_t(1) << 15;
    const std::string path = (std::filesystem::temp_directory_path() /
                              ("amc_crafted_" + std::to_string(getpid()) + "_many.pvd")).string();
    {
        std::ofstream out(path);
        out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n<Collection>\n";
        for (uint32_t k = 0; k < entries; ++k) out << "<DataSet timestep=\"" << k << "\" part=\"0\" file=\"f_" << k << ".vtu\"/>\n";
        out << "</Collection>\n</VTKFile>\n";
    }
    const double start = cpu_milliseconds();
    const std::vector<PvdEntry> read = read_pvd(path);
    const double milliseconds = cpu_milliseconds() - start;
    std::filesystem::remove(path);
    std::printf("  %u DataSets: %.1f ms\n", entries, milliseconds);
    ASSERT_EQ(read.size(), size_t(entries));
    EXPECT_EQ(read.back().file, "f_" + std::to_string(entries - 1) + ".vtu");
    EXPECT_EQ(read.back().time, double(entries - 1));
    EXPECT_LT(milliseconds, 2000.0);
}

// ---- the base connectivity stream's own counts (section 4) -----------------------------------

void put_count(ArithmeticEncoder& encoder, uint64_t x) {
    const uint64_t y = x + 1;
    const int n = bit_length(y);
    encoder.encode_bits_raw(0, n - 1);
    if (n > 32) {
        encoder.encode_bits_raw(uint32_t(y >> 32), n - 32);
        encoder.encode_bits_raw(uint32_t(y), 32);
    } else {
        encoder.encode_bits_raw(uint32_t(y), n);
    }
}

std::vector<uint8_t> cut_border_counts(uint64_t v, uint64_t isolated, uint64_t dummies, uint64_t copies,
                                       uint64_t components, uint64_t merges) {
    ArithmeticEncoder encoder;
    encoder.encode_bits_raw(0, 2);
    for (uint64_t c : {v, isolated, dummies, copies, components, merges}) put_count(encoder, c);
    for (int i = 0; i < 64; ++i) encoder.encode_bits_raw(0x5a5a5a5a, 32);  // some ops' worth of bytes
    return encoder.finish();
}

std::vector<uint8_t> angle_counts(uint64_t isolated, uint64_t dummies, uint64_t copies, uint64_t components, uint64_t merges) {
    ArithmeticEncoder encoder;
    encoder.encode_bits_raw(2, 2);  // mode 2
    encoder.encode_bits_raw(0, 2);  // context set
    encoder.encode_bits_raw(0, 3);  // gate radius
    encoder.encode_bits_raw(0, 1);  // not plain: the counts follow
    for (uint64_t c : {isolated, dummies, copies, components, merges}) put_count(encoder, c);
    for (int i = 0; i < 64; ++i) encoder.encode_bits_raw(0x5a5a5a5a, 32);
    return encoder.finish();
}

std::vector<uint8_t> explicit_counts(uint64_t v, uint64_t f) {
    ArithmeticEncoder encoder;
    encoder.encode_bits_raw(1, 2);
    put_count(encoder, v);
    put_count(encoder, f);
    for (int i = 0; i < 64; ++i) encoder.encode_bits_raw(0x12345678, 32);
    return encoder.finish();
}

TEST(CraftedFiles, BaseConnectivityCounts) {
    // As the .amc decoder calls it: with the base vertices the metadata announces (bounded by
    // the base geometry block: here a block of 64 bytes), which the stream must repeat, and no
    // isolated vertex allowed.
    const uint32_t vertices = uint32_t(max_decodable_positions(64));
    const BasePositionSource origin = [](uint32_t, const BaseStencil&, const std::vector<Vec3>&) { return Vec3{0, 0, 0}; };
    auto refused = [&](const std::string& what, const std::vector<uint8_t>& stream, const char* must_say = nullptr) {
        expect_refused_cheaply(
            what, ErrorCode::corrupt, [&] { decode_base_mesh(stream.data(), stream.size(), vertices, origin, 0); }, must_say);
    };
    const uint64_t big = 0x7ffffffe, fits = vertices;
    refused("V", cut_border_counts(big, 0, 0, 0, 1, 0));
    refused("V as announced", cut_border_counts(fits, 0, 0, 0, 1, 0));
    refused("dummy vertices", cut_border_counts(fits, 0, big, 0, 1, 0));
    refused("vertex copies", cut_border_counts(fits, 0, 0, big, 1, 0));
    refused("components", cut_border_counts(fits, 0, 0, 0, big, 0));
    refused("components, V as announced", cut_border_counts(fits, 0, 0, 0, fits / 3, 0));
    refused("merges", cut_border_counts(fits, 0, 0, 0, 1, big));
    refused("explicit V", explicit_counts(big, 0));
    refused("explicit F", explicit_counts(fits, big));
    // Isolated vertices cost the stream no bits (here 2.3 M of them, 28 MB of stencils): refused
    // on the counts.
    refused("isolated vertices", cut_border_counts(fits, fits, 0, 0, 0, 0), "isolated");
    refused("one isolated vertex", cut_border_counts(fits, 1, 0, 0, 1, 0), "isolated");
    refused("mode 2 isolated vertices", angle_counts(fits, 0, 0, 0, 0), "isolated");
    refused("explicit V without triangles", explicit_counts(fits, 0), "isolated");
    refused("explicit V > 3F", explicit_counts(fits, 5), "isolated");
}

// ---- the other files and streams ---------------------------------------------------------------

TEST(CraftedFiles, NumberingCounts) {
    Hierarchy h(make_icosahedron());
    refine_randomly(h, 200, 3, 4);
    const uint32_t faces = uint32_t(extract_leaf_mesh(h).mesh.triangles.size());
    LeafNumbering numbering;
    for (uint32_t i = 0; i < h.vertex_count(); ++i) numbering.vertex.push_back(i);
    for (uint32_t j = 0; j < faces; ++j) numbering.face.push_back(faces - 1 - j);
    numbering.rotation.assign(faces, 0);
    EncodeOptions options;
    options.numbering = &numbering;
    for (uint64_t huge : kHuge) {
        for (int field = 0; field < 2; ++field) {
            Parts parts = take_apart(encode(h, options));
            std::vector<uint8_t>& payload = payload_of(parts, BlockType::numbering);
            PayloadReader in(payload.data(), payload.size(), "numbering");
            uint64_t counts[2] = {in.varint(), in.varint()};
            counts[field] = huge;
            std::vector<uint8_t> changed;
            put_varint(changed, counts[0]);
            put_varint(changed, counts[1]);
            changed.insert(changed.end(), in.rest(), in.rest() + in.remaining());
            payload = changed;
            const std::vector<uint8_t> file = put_together(parts);
            LeafNumbering out;
            expect_refused_cheaply(std::string(field ? "numbering faces" : "numbering vertices") + " = " + std::to_string(huge),
                                   ErrorCode::corrupt,
                                   [&] { decode(file.data(), file.size(), {}, &out); });
        }
    }
}

TEST(CraftedFiles, HierarchyFileCounts) {
    Hierarchy h(make_icosahedron());
    refine_randomly(h, 200, 3, 4);
    const std::string good = serialize_hierarchy(h);
    // Header words 3-7: base vertices, base triangles, nodes, diagonal overrides, refinement vertices.
    for (int word = 3; word <= 7; ++word) {
        for (uint32_t huge : {uint32_t(1) << 31, ~uint32_t(0)}) {
            std::string bytes = good;
            for (int i = 0; i < 4; ++i) bytes[size_t(4 * word + i)] = char(huge >> (8 * i));
            expect_refused_cheaply(".amh header word " + std::to_string(word) + " = " + std::to_string(huge),
                                   ErrorCode::truncated,
                                   [&] { deserialize_hierarchy(bytes, "crafted.amh"); });
        }
    }
}

TEST(CraftedFiles, HierarchyStreamCounts) {
    // Alone, the stream holds no positions: uniform levels and culls cost no bits, and the
    // caller's limit is what bounds it.
    const TriangleMesh base = make_icosahedron();
    HierarchyDecodeOptions options;
    options.max_nodes = 1 << 16;
    for (int uniform = 8; uniform <= 20; uniform += 4) {
        HierarchyStreamHeader header;
        header.options.uniform_levels = true;
        header.uniform_levels = uint8_t(uniform);
        const std::vector<uint8_t> stream = write_hierarchy_stream_header(header);
        expect_refused_cheaply("stream uniform levels = " + std::to_string(uniform), ErrorCode::limit_exceeded,
                               [&] { decode_hierarchy(base, stream.data(), stream.size(), options); });
    }
}

// ---- .amq files (docs/FORMAT.md 8.2, 8.3, 8.5) --------------------------------------------------

std::vector<uint8_t> octree_file(const OctreeMetadata& meta, const std::vector<uint8_t>& connectivity,
                                 const std::vector<std::vector<uint8_t>>& level_payloads) {
    BlockWriter writer(kOctreeFraming, kOctreeBaseVersion, 0);
    writer.add(uint8_t(OctreeBlock::metadata), write_octree_metadata(meta));
    writer.add(uint8_t(OctreeBlock::connectivity), connectivity);
    for (const auto& p : level_payloads) writer.add(uint8_t(OctreeBlock::level), p);
    return writer.finish();
}

// Every octant of `levels - 1` levels over `trees` trees refined, the last level's leaves
// truncated away: no symbol at all.
OctreeMetadata uniform_forest_metadata(int dim, uint64_t trees, int levels) {
    OctreeMetadata meta;
    meta.dim = dim;
    meta.trees = trees;
    meta.levels = uint64_t(levels);
    meta.uniform_levels = levels - 1;
    meta.switches = kOctreeUniformLevels | kOctreeTruncate | kOctreeCullByBalance;
    meta.count = 0;
    uint64_t level_octants = trees;
    for (int l = 0; l < levels; ++l, level_octants <<= dim) meta.octants += level_octants;
    meta.leaves = meta.octants - (meta.octants - trees) / (uint64_t{1} << dim);
    return meta;
}

void expect_octree_refused(const std::string& what, ErrorCode expected, const std::vector<uint8_t>& file,
                           const char* must_say = nullptr, const OctreeDecodeOptions& options = {}) {
    expect_refused_cheaply(what, expected, [&] { decode_octree_forest(file.data(), file.size(), options); }, must_say);
}

TEST(CraftedFiles, OctreeUniformForestBomb) {
    // A 104-byte file announcing a uniform octree of depth 8 (19.2 M octants, within the default
    // node limit): before the per-byte bound it decoded, asking about 1 GB; now refused on the
    // metadata.
    const std::vector<uint8_t> brick3 = write_octree_connectivity(brick_connectivity(3, 1, 1, 1));
    const OctreeMetadata deep = uniform_forest_metadata(3, 1, 9);
    ASSERT_LE(deep.octants, OctreeDecodeOptions().max_nodes);
    expect_octree_refused("uniform octree of depth 8 in 104 bytes", ErrorCode::limit_exceeded,
                          octree_file(deep, brick3, std::vector<std::vector<uint8_t>>(9)), "octants per byte");
    // A quadtree of depth 12 (22.4 M octants).
    const std::vector<uint8_t> brick2 = write_octree_connectivity(brick_connectivity(2, 1, 1));
    expect_octree_refused("uniform quadtree of depth 12", ErrorCode::limit_exceeded,
                          octree_file(uniform_forest_metadata(2, 1, 13), brick2, std::vector<std::vector<uint8_t>>(13)),
                          "octants per byte");
    // A brick of 4095 x 4096 trees, all leaves (16.8 M roots in a few bytes).
    std::vector<uint8_t> wide = {uint8_t(OctreeConnectivityMode::brick), 0};  // not periodic
    put_varint(wide, 4095);
    put_varint(wide, 4096);
    OctreeMetadata roots = uniform_forest_metadata(2, 4095 * 4096, 1);
    roots.switches = kOctreeTruncate;
    expect_octree_refused("brick of 16.8 M trees, all leaves", ErrorCode::limit_exceeded,
                          octree_file(roots, wide, std::vector<std::vector<uint8_t>>(1)), "octants per byte");
    // Exactly at the bound it decodes, one byte short it is refused (a bound of 64 octants per
    // byte, to keep the forest small).
    OctreeDecodeOptions tight;
    tight.max_octants_per_byte = 64;
    const OctreeMetadata small = uniform_forest_metadata(2, 1, 8);  // 21,845 octants
    std::vector<std::vector<uint8_t>> levels(8);
    const std::vector<uint8_t> unpadded = octree_file(small, brick2, levels);
    const size_t after = unpadded.size() - kFileHeaderSize - kBlockOverhead - write_octree_metadata(small).size();
    const size_t needed = (small.octants + 63) / 64;
    ASSERT_LT(after, needed);
    levels.back().resize(needed - after - 1);
    expect_octree_refused("uniform quadtree one byte short", ErrorCode::limit_exceeded, octree_file(small, brick2, levels),
                          "octants per byte", tight);
    levels.back().resize(needed - after);
    const std::vector<uint8_t> enough = octree_file(small, brick2, levels);
    EXPECT_EQ(decode_octree_forest(enough.data(), enough.size(), tight), uniform_octree_forest(brick_connectivity(2, 1, 1), 7));
    // The bound lifted, the unpadded file decodes too (files written before it).
    tight.max_octants_per_byte = 0;
    EXPECT_EQ(decode_octree_forest(unpadded.data(), unpadded.size(), tight).leaves.size(), small.leaves);
}

// A valid .amq of one leaf and 2^17 leaf fields (2.6 MB): decoded in time linear in its fields.
// Each field's name was compared with every one before it (11.2 s of CPU for this file until
// 2026-12-07; docs/FUZZING.md). CPU time, as the other crafted files.
TEST(CraftedFiles, OctreeManyLeafFieldsDecodeInLinearTime) {
    OctreeForest forest;
    forest.connectivity = brick_connectivity(2, 1, 1);
    forest.tree_offsets = {0, 1};
    forest.leaves = {Octant{}};
    for (uint32_t f = 0; f < 3; ++f) {
        Field field;
        field.name = "f" + std::to_string(f);
        field.association = FieldAssociation::cell;
        field.type = FieldType::int8;
        field.integers = {int64_t(f % 100)};
        forest.leaf_data.push_back(field);
    }
    // A name twice is refused: of three fields, the last block made a copy of the one before.
    const std::vector<uint8_t> three = encode_octree_forest(forest);
    BlockReader reader(three.data(), three.size(), kOctreeFraming);
    std::vector<std::pair<uint8_t, std::vector<uint8_t>>> blocks;
    for (Block b{}; reader.next(b) && uint8_t(b.type) != uint8_t(OctreeBlock::end);)
        blocks.push_back({uint8_t(b.type), std::vector<uint8_t>(b.payload, b.payload + b.size)});
    blocks.back().second = blocks[blocks.size() - 2].second;
    BlockWriter writer(kOctreeFraming, reader.version(), reader.flags());
    for (const auto& [type, payload] : blocks) writer.add(type, payload);
    expect_octree_refused("a leaf field named twice", ErrorCode::corrupt, writer.finish(), "two leaf fields named \"f1\"");

    for (uint32_t f = 3; f < (uint32_t(1) << 17); ++f) {
        Field field = forest.leaf_data.back();
        field.name = "f" + std::to_string(f);
        field.integers = {int64_t(f % 100)};
        forest.leaf_data.push_back(std::move(field));
    }
    const std::vector<uint8_t> file = encode_octree_forest(forest);
    const double start = cpu_milliseconds();
    const OctreeForest back = decode_octree_forest(file.data(), file.size());
    const double milliseconds = cpu_milliseconds() - start;
    std::printf("  %zu leaf fields (%zu bytes): %.1f ms\n", forest.leaf_data.size(), file.size(), milliseconds);
    EXPECT_TRUE(back == forest);
    EXPECT_LT(milliseconds, 5000.0);  // 1.1 s under ASan (CI)
}

// A valid .amq of one leaf and 2^15 leaf fields whose names (240 bytes) all have one std::hash
// (libstdc++'s is an unkeyed Murmur hash: a pair of 8-byte words can flip the top bit of both
// words' mixed values, which the multiply between them keeps and the second cancels; 15 pairs,
// each either way). The decoder's set of names was an unordered_set: 2.3 s of CPU for this file
// until 2026-12-07 (docs/FUZZING.md), 30 ms since with an ordered set, as the encoder's check.
TEST(CraftedFiles, OctreeLeafFieldNamesOfOneHashDecodeInLinearTime) {
    const uint64_t mul = (uint64_t{0xc6a4a793} << 32) + 0x5bd1e995;  // _Hash_bytes's multiplier
    const uint64_t inverse = inverse_mod_2_64(mul);
    auto shift_mix = [](uint64_t v) { return v ^ (v >> 47); };  // its own inverse
    const int pairs = 15;
    uint64_t words[pairs][2][2];  // pair i, either way, its two words
    SplitMix64 random{7};
    for (int i = 0; i < pairs; ++i) {
        for (int j = 0; j < 2; ++j) {
            words[i][0][j] = random.next();
            const uint64_t flipped = (shift_mix(words[i][0][j] * mul) * mul) ^ (uint64_t{1} << 63);
            words[i][1][j] = shift_mix(flipped * inverse) * inverse;
        }
    }
    OctreeForest forest;
    forest.connectivity = brick_connectivity(2, 1, 1);
    forest.tree_offsets = {0, 1};
    forest.leaves = {Octant{}};
    for (uint32_t f = 0; f < (uint32_t{1} << pairs); ++f) {
        Field field;
        for (int i = 0; i < pairs; ++i)
            for (int j = 0; j < 2; ++j) field.name.append(reinterpret_cast<const char*>(&words[i][(f >> i) & 1][j]), 8);
        field.association = FieldAssociation::cell;
        field.type = FieldType::int8;
        field.integers = {int64_t(f % 100)};
        forest.leaf_data.push_back(std::move(field));
    }
    const std::hash<std::string> hash;
    for (size_t f = 1; f < forest.leaf_data.size(); f += 999)
        ASSERT_EQ(hash(forest.leaf_data[f].name), hash(forest.leaf_data[0].name));  // the crafting holds
    const std::vector<uint8_t> file = encode_octree_forest(forest);
    const double start = cpu_milliseconds();
    const OctreeForest back = decode_octree_forest(file.data(), file.size());
    const double milliseconds = cpu_milliseconds() - start;
    std::printf("  %zu leaf fields of one name hash (%zu bytes): %.1f ms\n", forest.leaf_data.size(), file.size(),
                milliseconds);
    EXPECT_TRUE(back == forest);
    EXPECT_LT(milliseconds, 1000.0 * kSanitizerSlowdown);
}

// `trees` quadtrees around one coarse vertex, corner 0 of each.
TreeConnectivity quadtree_fan(uint32_t trees) {
    std::vector<Vec3> vertices = {{0, 0, 0}};
    for (uint32_t i = 0; i < trees; ++i) {
        const double a = 2 * 3.141592653589793 * double(i) / trees, b = 2 * 3.141592653589793 * (i + 0.5) / trees;
        vertices.push_back({std::cos(a), std::sin(a), 0});
        vertices.push_back({1.2 * std::cos(b), 1.2 * std::sin(b), 0});
    }
    std::vector<uint32_t> tree_to_vertex;  // centre, rim vertex i, rim vertex i + 1, the point between them outside
    for (uint32_t i = 0; i < trees; ++i)
        for (uint32_t v : {0u, 1 + 2 * i, 1 + 2 * ((i + 1) % trees), 2 + 2 * i}) tree_to_vertex.push_back(v);
    return connectivity_from_vertices(2, vertices, tree_to_vertex);
}

// An .amq over 4,000 quadtrees around one coarse vertex, each refined once (220 KB), and its
// conforming mesh (`amc octree decode --conforming`): each point named once, in time linear in
// the trees. Each place of a point was searched among all its places, and every place at the
// vertex went around it again: cubic in the trees (8.9 s of CPU here until 2026-12-07,
// docs/FUZZING.md). CPU time, as the other crafted files.
TEST(CraftedFiles, ConformingMeshAroundAVertexOfManyTreesIsLinear) {
    constexpr uint32_t trees = 4000;
    const OctreeForest forest = uniform_octree_forest(quadtree_fan(trees), 1);
    const std::vector<uint8_t> file = encode_octree_forest(forest);
    const OctreeForest decoded = decode_octree_forest(file.data(), file.size());
    const double start = cpu_milliseconds();
    const ConformingLeafMesh mesh = conforming_leaf_mesh(decoded);
    const double milliseconds = cpu_milliseconds() - start;
    std::printf("  conforming mesh of %u trees around a vertex (%zu bytes): %.1f ms\n", trees, file.size(), milliseconds);
    // Per tree: its far corner, one rim vertex, three edge midpoints and its centre; the centre once.
    EXPECT_EQ(mesh.corner_points, 6 * trees + 1);
    EXPECT_EQ(mesh.cell_count(), 8 * size_t(trees));
    EXPECT_LT(milliseconds, 1000.0);
}

// The Morton code of a quadtree lattice point (31 bits an axis).
uint64_t morton_2d(uint64_t x, uint64_t y) {
    uint64_t m = 0;
    for (int b = 0; b < 31; ++b) m |= ((x >> b) & 1) << (2 * b) | ((y >> b) & 1) << (2 * b + 1);
    return m;
}

// One quadtree refined to the finest level at the lattice points whose Morton codes `targets`
// (sorted) lists.
OctreeForest quadtree_refined_at(const std::vector<uint64_t>& targets) {
    OctreeForest forest;
    forest.connectivity = brick_connectivity(2, 1, 1);
    forest.tree_offsets = {0, 1};
    forest.leaves = {Octant{}};
    return refine_octree_forest(
        forest,
        [&](uint32_t, const Octant& o) {
            const uint64_t first = morton_2d(uint64_t(o.x), uint64_t(o.y)), end = first + (uint64_t(1) << (2 * (30 - o.level)));
            const auto it = std::lower_bound(targets.begin(), targets.end(), first);
            return it != targets.end() && *it < end;
        },
        octree_max_level(2));
}

// One quadtree refined to the finest level at 10,000 points (x, y), x even and consecutive, y the
// even one of the two smallest with x * 2^31 + y = 0 mod P, P the bucket count libstdc++'s
// unordered_map has at the forest's corner count: the VTU's corner index (keys x << 31 | y, the
// identity hash) put all of them in one bucket once it had grown to P buckets: 2.4 s of CPU for
// the VTU (30,000 such points, `amc octree decode` of their 74 KB .amq: 136 s) until 2026-12-07,
// docs/FUZZING.md; 0.22 s since the index's hash is keyed per process.
TEST(CraftedFiles, OctreeVtuOfCornersInOneBucketIsLinear) {
    std::unordered_map<uint64_t, uint32_t> sized;  // the bucket count at 400,000 keys, as the VTU's index grows
    for (uint64_t k = 0; k < 400000; ++k) sized.emplace(k, 0);
    const uint64_t buckets = sized.bucket_count();
    std::vector<uint64_t> targets;  // Morton codes, sorted
    for (uint64_t x = uint64_t(1) << 29; targets.size() < 10000; x += 2) {
        uint64_t y = (buckets - ((x << 31) % buckets)) % buckets;
        if (y % 2 == 1) y += buckets;
        targets.push_back(morton_2d(x, y));
    }
    std::sort(targets.begin(), targets.end());
    const OctreeForest forest = quadtree_refined_at(targets);
    std::vector<uint64_t> corners;  // the index's keys
    for (const Octant& o : forest.leaves) {
        const uint64_t length = uint64_t(1) << (30 - o.level);
        for (uint64_t c = 0; c < 4; ++c)
            corners.push_back((uint64_t(o.x) + (c & 1) * length) << 31 | (uint64_t(o.y) + (c >> 1) * length));
    }
    std::sort(corners.begin(), corners.end());
    corners.erase(std::unique(corners.begin(), corners.end()), corners.end());
    std::unordered_map<uint64_t, uint32_t> grown;  // the crafting holds: the index ends at that bucket count
    for (uint64_t k = 0; k < corners.size(); ++k) grown.emplace(k, 0);
    ASSERT_EQ(grown.bucket_count(), buckets) << corners.size() << " corners";
    const std::string path = (std::filesystem::temp_directory_path() /
                              ("amc_crafted_" + std::to_string(getpid()) + "_corners.vtu")).string();
    const double start = cpu_milliseconds();
    write_octree_vtu(path, forest);
    const double milliseconds = cpu_milliseconds() - start;
    std::filesystem::remove(path);
    std::printf("  VTU of %zu leaves, %zu corners, 10,000 of them in one residue of %llu: %.1f ms\n", forest.leaves.size(),
                corners.size(), (unsigned long long)buckets, milliseconds);
    EXPECT_LT(milliseconds, 1000.0 * kSanitizerSlowdown);
}

// One quadtree refined to the finest level at 30,000 even points (x, y) whose key x << 31 | y
// has splitmix64_mix(key) below 256 modulo the slots of the conforming mesh's point table
// (ForestPoints: open addressing over twice the 2 * leaves + 64 places conforming_leaf_mesh
// reserves, rounded up to a power of two), found by trying points in turn: they all probed one run
// of slots, quadratic in them (2.7 s of CPU here until 2026-12-07, docs/FUZZING.md; 60,000 such
// points, `amc octree decode --conforming`: 9.7 s against 2.4 s); keyed per process since.
TEST(CraftedFiles, ConformingMeshOfPointsInOneRunOfSlotsIsLinear) {
    const size_t count = kSanitizerSlowdown > 1 ? 6000 : 30000;
    int slot_bits = kSanitizerSlowdown > 1 ? 20 : 22;
    OctreeForest forest;
    for (int attempt = 0; attempt < 3; ++attempt) {  // until the table's size is the one aimed at
        std::vector<uint64_t> targets;  // Morton codes, sorted
        const uint64_t mask = (uint64_t(1) << slot_bits) - 1, first = uint64_t(1) << 29, span = uint64_t(1) << 24;
        for (uint64_t x = first, y = first; targets.size() < count;) {
            if ((splitmix64_mix(x << 31 | y) & mask) < 256) targets.push_back(morton_2d(x, y));
            y += 2;
            if (y == first + span) y = first, x += 2;
        }
        std::sort(targets.begin(), targets.end());
        forest = quadtree_refined_at(targets);
        int bits = 6;  // ForestPoints starts at 64 slots
        while ((uint64_t(1) << bits) < 2 * (2 * forest.leaves.size() + 64)) ++bits;
        if (bits == slot_bits) break;
        slot_bits = bits;
    }
    const double start = cpu_milliseconds();
    const ConformingLeafMesh mesh = conforming_leaf_mesh(forest);
    const double milliseconds = cpu_milliseconds() - start;
    std::printf("  conforming mesh of %zu leaves, %zu points in one run of 2^%d slots: %.1f ms\n", forest.leaves.size(),
                count, slot_bits, milliseconds);
    EXPECT_GT(mesh.corner_points, forest.leaves.size());
    EXPECT_LT(milliseconds, 1600.0 * kSanitizerSlowdown);  // 0.78 s in Release
}

// 8,000 quadtrees around one coarse vertex, uniform at level 2, tree 0 refined twice more at the
// vertex: corner balance refines every other tree's octant there once. Each refined octant at the
// vertex went around it, finding the same octants again: quadratic in the trees (10.3 s of CPU
// and 2.1 GB here until 2026-12-07, docs/FUZZING.md), as was octree_balance_violation (1.3 s).
TEST(CraftedFiles, CornerBalanceAroundAVertexOfManyTreesIsLinear) {
    constexpr uint32_t trees = 8000;
    const OctreeForest forest = refine_octree_forest(
        uniform_octree_forest(quadtree_fan(trees), 2),
        [](uint32_t tree, const Octant& o) { return tree == 0 && o.x == 0 && o.y == 0 && o.level < 4; }, 4);
    const uint64_t allocated_before = g_allocated.load();
    const double start = cpu_milliseconds();
    const OctreeForest balanced = balance_octree_forest(forest, OctreeBalance::corner);
    const std::string before = octree_balance_violation(forest, OctreeBalance::corner);
    const std::string after = octree_balance_violation(balanced, OctreeBalance::corner);
    const double milliseconds = cpu_milliseconds() - start;
    const uint64_t allocated = g_allocated.load() - allocated_before;
    std::printf("  corner balance of %u trees around a vertex: %.1f ms, %llu bytes allocated\n", trees, milliseconds,
                (unsigned long long)allocated);
    // 16 leaves a tree, 3 more where each octant at the vertex is split, 3 more in tree 0.
    EXPECT_EQ(balanced.leaves.size(), 19 * size_t(trees) + 3);
    EXPECT_EQ(before, "tree 0 octant (0, 0, 0) of level 3 is refined, but its neighbour at offset (0, -1, 0) in tree " +
                          std::to_string(trees - 1) + " lies in a leaf two or more levels coarser");
    EXPECT_EQ(after, "");
    EXPECT_LT(milliseconds, 5000.0);  // 0.12 s; 1.6 s with the octree files under ASan at -O0
    EXPECT_LT(allocated, uint64_t(512) << 20);  // 122 MB; 4.4 GB before
}

TEST(CraftedFiles, OctreeWriterPadsCostlessForests) {
    // A uniform quadtree of depth 10 (1.4 M octants) costs no symbol: the writer pads its last
    // level block so that the file holds at most kOctreeOctantsPerByte octants per byte after the
    // metadata, and it decodes with the default options to the same forest.
    const OctreeForest forest = uniform_octree_forest(brick_connectivity(2, 1, 1), 10);
    OctreeEncodeStats stats;
    const std::vector<uint8_t> file = encode_octree_forest(forest, {}, &stats);
    EXPECT_EQ(stats.uniform, stats.nodes - forest.leaves.size());
    BlockReader reader(file.data(), file.size(), kOctreeFraming);
    Block metadata{};
    ASSERT_TRUE(reader.next(metadata));
    EXPECT_GE(reader.remaining() * kOctreeOctantsPerByte, stats.nodes);
    EXPECT_LT((reader.remaining() - 1) * kOctreeOctantsPerByte, stats.nodes);  // no more than needed
    EXPECT_EQ(decode_octree_forest(file.data(), file.size()), forest);
}

// ---- .amcs series files (docs/FORMAT.md 7.2-7.4, 7.8, 7.10-7.12) --------------------------------

struct SeriesParts {
    std::vector<uint8_t> header;                               // the 16 bytes of 7.1
    std::vector<std::pair<uint8_t, std::vector<uint8_t>>> blocks;  // base, frames (END excluded)
};

SeriesParts take_series_apart(const std::vector<uint8_t>& file) {
    const SeriesScan scan = scan_series_file(file, "series", false, kSeriesFlagSinglePrecision, uint8_t(SeriesBlock::forest_frame));
    SeriesParts parts{std::vector<uint8_t>(file.begin(), file.begin() + kSeriesHeaderSize), {}};
    for (const SeriesBlockView& b : scan.blocks)
        parts.blocks.push_back({b.type, std::vector<uint8_t>(b.payload, b.payload + b.length)});
    return parts;
}

std::vector<uint8_t> put_series_together(const SeriesParts& parts) {
    std::vector<uint8_t> file = parts.header;
    for (const auto& block : parts.blocks) {
        const std::vector<uint8_t> framed = series_block(block.first, block.second);
        file.insert(file.end(), framed.begin(), framed.end());
    }
    const std::vector<uint8_t> end = series_block(uint8_t(SeriesBlock::end), {});
    file.insert(file.end(), end.begin(), end.end());
    return file;
}

// A frame block's payload (7.4; a forest frame, 7.11, has three counts and no geometry section).
struct FramePayload {
    bool forest = false;
    double time = 0;
    std::vector<uint64_t> counts;  // N, Vf, F, L (forest: O, Lv, L)
    uint64_t connectivity_length = 0;
    std::vector<uint8_t> connectivity;
    uint64_t geometry_length = 0;
    std::vector<uint8_t> geometry;
    uint64_t field_count = 0;
    std::vector<uint8_t> fields;  // the field records, as they are
};

FramePayload read_frame_payload(const std::vector<uint8_t>& payload, bool forest) {
    PayloadReader in(payload.data(), payload.size(), "frame");
    FramePayload f;
    f.forest = forest;
    f.time = in.f64();
    for (int i = 0; i < (forest ? 3 : 4); ++i) f.counts.push_back(in.varint());
    f.connectivity_length = in.varint();
    for (uint64_t i = 0; i < f.connectivity_length; ++i) f.connectivity.push_back(in.u8());
    if (!forest) {
        f.geometry_length = in.varint();
        for (uint64_t i = 0; i < f.geometry_length; ++i) f.geometry.push_back(in.u8());
    }
    f.field_count = in.varint();
    f.fields.assign(in.rest(), in.rest() + in.remaining());
    return f;
}

std::vector<uint8_t> write_frame_payload(const FramePayload& f) {
    std::vector<uint8_t> out;
    put_f64(out, f.time);
    for (uint64_t c : f.counts) put_varint(out, c);
    put_varint(out, f.connectivity_length);
    out.insert(out.end(), f.connectivity.begin(), f.connectivity.end());
    if (!f.forest) {
        put_varint(out, f.geometry_length);
        out.insert(out.end(), f.geometry.begin(), f.geometry.end());
    }
    put_varint(out, f.field_count);
    out.insert(out.end(), f.fields.begin(), f.fields.end());
    return out;
}

// Opens the file and decodes every frame.
void read_series(const std::vector<uint8_t>& file, const SeriesReadOptions& options = {}) {
    SeriesReader reader(file, "crafted.amcs", options);
    for (size_t k = 0; k < reader.frame_count(); ++k) reader.frame(k);
}

void read_forest_series(const std::vector<uint8_t>& file, const SeriesReadOptions& options = {}) {
    ForestSeriesReader reader(file, "crafted.amcs", options);
    for (size_t k = 0; k < reader.frame_count(); ++k) reader.frame(k);
}

// Refuses `original` with frame block `block` replaced by a changed payload, as `read` reads it
// (read_series or read_forest_series); `frame` prefixes the case's name.
using SeriesRead = void (*)(const std::vector<uint8_t>&, const SeriesReadOptions&);
auto frame_refusal(const SeriesParts& original, size_t block, std::string frame, SeriesRead read) {
    return [&original, block, frame = std::move(frame), read](const std::string& what, ErrorCode code,
                                                              const FramePayload& changed, const char* must_say) {
        SeriesParts parts = original;
        parts.blocks[block].second = write_frame_payload(changed);
        const std::vector<uint8_t> file = put_series_together(parts);
        expect_refused_cheaply(frame + what, code, [&] { read(file, {}); }, must_say);
    };
}

// What every frame block holds (FORMAT.md 7.4, 7.11): a connectivity length and a field count.
template <class Refused>
void refuse_huge_lengths(const Refused& refused, const FramePayload& f, uint64_t huge) {
    FramePayload connectivity = f;
    connectivity.connectivity_length = huge;
    refused("connectivity length = " + std::to_string(huge), ErrorCode::truncated, connectivity, "connectivity longer");
    FramePayload fields = f;
    fields.field_count = huge;
    refused("field count = " + std::to_string(huge), ErrorCode::corrupt, fields, "fields (at most 4096)");
}

// A small series: a keyframe and a type-3 frame, each with a point and a cell field.
std::vector<uint8_t> small_series() {
    Hierarchy h(make_icosahedron());
    refine_randomly(h, 12, 2, 7);
    SeriesOptions options;
    options.choose_keyframes = false;
    SeriesWriter writer(h.base(), options);
    for (int k = 0; k < 2; ++k) {
        if (k == 1) refine_randomly(h, 8, 3, 9);
        const LeafMesh leaf = extract_leaf_mesh(h);
        Field u{"u", FieldAssociation::point, FieldType::float64, 1, {}, {}};
        for (const Vec3& p : leaf.mesh.positions) u.values.push_back(p.x - 0.5 * p.y);
        Field level{"level", FieldAssociation::cell, FieldType::uint8, 1, {}, {}};
        for (size_t t = 0; t < leaf.mesh.triangles.size(); ++t) level.integers.push_back(leaf.cells.level[t]);
        writer.add_frame(h, double(k), {u, level});
    }
    writer.close();
    return writer.bytes();
}

TEST(CraftedFiles, SeriesBaseCounts) {
    const std::vector<uint8_t> good = small_series();
    ASSERT_NO_THROW(read_series(good));
    for (uint64_t huge : kHuge) {
        for (int field = 0; field < 2; ++field) {  // base vertices V, base triangles T (7.3)
            SeriesParts parts = take_series_apart(good);
            std::vector<uint8_t>& payload = parts.blocks[0].second;
            PayloadReader in(payload.data(), payload.size(), "base");
            uint64_t counts[2] = {in.varint(), in.varint()};
            counts[field] = huge;
            std::vector<uint8_t> changed;
            put_varint(changed, counts[0]);
            put_varint(changed, counts[1]);
            changed.insert(changed.end(), in.rest(), in.rest() + in.remaining());
            payload = changed;
            const std::vector<uint8_t> file = put_series_together(parts);
            expect_refused_cheaply(std::string(field ? "series base triangles" : "series base vertices") + " = " +
                                       std::to_string(huge),
                                   ErrorCode::corrupt, [&] { read_series(file); }, "can not fit");
        }
    }
}

TEST(CraftedFiles, SeriesFrameCounts) {
    const std::vector<uint8_t> good = small_series();
    const SeriesParts original = take_series_apart(good);
    const uint64_t base_triangles = 20;
    const char* const names[] = {"nodes", "vertices", "faces", "levels"};
    for (size_t block = 1; block <= 2; ++block) {
        const FramePayload f = read_frame_payload(original.blocks[block].second, false);
        const auto refused = frame_refusal(original, block, "series frame " + std::to_string(block - 1) + " ", read_series);
        for (uint64_t huge : kHuge) {
            for (int i = 0; i < 4; ++i) {
                FramePayload changed = f;
                changed.counts[size_t(i)] = huge;
                if (i == 0 && (huge - base_triangles) % 4 == 0) changed.counts[0] += 1;  // N - T not divisible by 4
                refused(std::string(names[i]) + " = " + std::to_string(changed.counts[size_t(i)]), ErrorCode::corrupt, changed,
                        "inconsistent counts");
            }
            // Nodes consistent with the other counts (N - T divisible by 4): the node limit.
            FramePayload nodes = f;
            nodes.counts[0] = huge - (huge - base_triangles) % 4;
            refused("nodes = " + std::to_string(nodes.counts[0]) + " (consistent)", ErrorCode::limit_exceeded, nodes, "limit");
            refuse_huge_lengths(refused, f, huge);
            FramePayload geometry = f;
            geometry.geometry_length = huge;
            refused("geometry length = " + std::to_string(huge), ErrorCode::truncated, geometry, "geometry longer");
        }
        // Nodes within the node limit but not within the block's bytes (7.2, Bounds).
        FramePayload nodes = f;
        nodes.counts[0] = SeriesReadOptions().max_nodes - (SeriesReadOptions().max_nodes - base_triangles) % 4;
        refused("nodes = " + std::to_string(nodes.counts[0]), ErrorCode::limit_exceeded, nodes, "per byte");
        // The first field record (7.8): name length, components, payload length.
        PayloadReader in(f.fields.data(), f.fields.size(), "field");
        const uint64_t name_length = in.varint();
        for (uint64_t i = 0; i < name_length + 2; ++i) in.u8();  // name, association, type
        const size_t components_at = f.fields.size() - in.remaining();
        in.varint();
        const uint8_t mode = in.u8();
        if (mode == 1) in.f64();
        for (uint64_t i = 0; i < f.counts[3]; ++i) in.u8();  // a predictor per level
        const size_t payload_length_at = f.fields.size() - in.remaining();
        const uint64_t payload_length = in.varint();
        const size_t after = f.fields.size() - in.remaining();
        const auto with_varint = [&](size_t at, size_t end, uint64_t value) {
            FramePayload changed = f;
            changed.fields.assign(f.fields.begin(), f.fields.begin() + ptrdiff_t(at));
            put_varint(changed.fields, value);
            changed.fields.insert(changed.fields.end(), f.fields.begin() + ptrdiff_t(end), f.fields.end());
            return changed;
        };
        ASSERT_LE(payload_length, in.remaining());
        for (uint64_t huge : kHuge) {
            PayloadReader again(f.fields.data(), f.fields.size(), "field");
            again.varint();
            refused("field name length = " + std::to_string(huge), ErrorCode::corrupt,
                    with_varint(0, f.fields.size() - again.remaining(), huge), "name");
            PayloadReader components(f.fields.data() + components_at, f.fields.size() - components_at, "field");
            components.varint();
            refused("field components = " + std::to_string(huge), ErrorCode::corrupt,
                    with_varint(components_at, f.fields.size() - components.remaining(), huge), "components");
            refused("field payload length = " + std::to_string(huge), ErrorCode::truncated,
                    with_varint(payload_length_at, after, huge), nullptr);
        }
    }
}

// An icosahedron refined uniformly `levels` times, as a keyframe that costs next to nothing: a
// hierarchy stream of uniform levels and no symbol (7.6), positions of mode 2 (7.7), no field.
std::vector<uint8_t> uniform_keyframe_series(int levels) {
    SeriesWriter writer(make_icosahedron());
    writer.close();  // the header and the base block
    SeriesParts parts = take_series_apart(writer.bytes());
    HierarchyStreamHeader header;
    header.options.uniform_levels = true;
    header.uniform_levels = uint8_t(levels);
    FramePayload f;
    f.connectivity = hierarchy_stream_tag(kHierarchyStreamVersion);
    const std::vector<uint8_t> fields = write_hierarchy_stream_header(header);
    f.connectivity.insert(f.connectivity.end(), fields.begin(), fields.end());
    f.connectivity_length = f.connectivity.size();
    const uint64_t power = uint64_t(1) << (2 * levels);
    f.counts = {20 * (4 * power - 1) / 3, 10 * power + 2, 20 * power, uint64_t(levels) + 1};
    f.geometry = {2};  // static, every new vertex at its midpoint
    f.geometry_length = 1;
    parts.blocks.push_back({uint8_t(SeriesBlock::keyframe), write_frame_payload(f)});
    return put_series_together(parts);
}

TEST(CraftedFiles, SeriesCostlessFramesBomb) {
    // A keyframe block of 43 bytes announcing a uniform refinement of depth 10 (28.0 M nodes,
    // within the default node limit): before the per-byte bound it decoded (17.5 s, 4.7 GB
    // allocated); now refused on the frame header.
    const std::vector<uint8_t> bomb = uniform_keyframe_series(10);
    const SeriesParts parts = take_series_apart(bomb);
    const uint64_t nodes = read_frame_payload(parts.blocks[1].second, false).counts[0];
    ASSERT_LE(nodes, SeriesReadOptions().max_nodes);
    expect_refused_cheaply("uniform keyframe of " + std::to_string(nodes) + " nodes in " +
                               std::to_string(parts.blocks[1].second.size() + kSeriesBlockOverhead) + " bytes",
                           ErrorCode::limit_exceeded, [&] { read_series(bomb); }, "per byte");
    // The same file of depth 3 is a valid series: it decodes to the uniform refinement, exactly at
    // the bound, and is refused one node per byte below it.
    const std::vector<uint8_t> small = uniform_keyframe_series(3);
    const SeriesParts small_parts = take_series_apart(small);
    const uint64_t small_nodes = read_frame_payload(small_parts.blocks[1].second, false).counts[0];
    const uint64_t block = small_parts.blocks[1].second.size() + kSeriesBlockOverhead;
    SeriesReadOptions tight;
    tight.max_nodes_per_byte = (small_nodes + block - 1) / block;
    Hierarchy uniform(make_icosahedron());
    refine_uniformly(uniform, 3);
    ASSERT_EQ(uniform.node_count(), small_nodes);
    SeriesReader reader(small, "uniform.amcs", tight);
    EXPECT_TRUE(identical(reader.frame(0).hierarchy, uniform));
    tight.max_nodes_per_byte -= 1;
    expect_refused_cheaply("uniform keyframe one node per byte over", ErrorCode::limit_exceeded,
                           [&] { read_series(small, tight); }, "per byte");
    // An unchanged type-3 frame: the same boundary.
    SeriesOptions options;
    options.choose_keyframes = false;
    SeriesWriter writer(uniform.base(), options);
    const uint64_t keyframe_bytes = writer.add_frame(uniform, 0).bytes;
    const uint64_t frame_bytes = writer.add_frame(uniform, 1).bytes;
    writer.close();
    tight.max_nodes_per_byte = (small_nodes + frame_bytes - 1) / frame_bytes;
    ASSERT_GE(tight.max_nodes_per_byte * keyframe_bytes, small_nodes);  // frame 0 within it too
    SeriesReader unchanged(writer.bytes(), "unchanged.amcs", tight);
    EXPECT_FALSE(unchanged.info(1).keyframe);
    EXPECT_TRUE(identical(unchanged.frame(1).hierarchy, uniform));
    tight.max_nodes_per_byte -= 1;
    expect_refused_cheaply("unchanged type-3 frame one node per byte over", ErrorCode::limit_exceeded,
                           [&] { read_series(writer.bytes(), tight); }, "per byte");
}

TEST(CraftedFiles, SeriesWriterPadsCostlessFrames) {
    // The padded series cost no symbol as a keyframe and next to nothing unchanged: the writers
    // pad both frame blocks to hold at most kSeriesNodesPerByte nodes per byte, no more than
    // needed, and they read back with the default options.
    const test::PaddedSeries series = test::padded_series();
    const uint64_t nodes = series.hierarchy.node_count();
    SeriesReader reader(series.bytes);
    for (size_t k = 0; k < 2; ++k) {
        EXPECT_GE(series.stats[k].bytes * kSeriesNodesPerByte, nodes) << k;
        EXPECT_LT((series.stats[k].bytes - 1) * kSeriesNodesPerByte, nodes) << k;
        EXPECT_TRUE(identical(reader.frame(k).hierarchy, series.hierarchy)) << k;
    }
    const test::PaddedForestSeries forests = test::padded_forest_series();
    ForestSeriesReader forest_reader(forests.bytes);
    for (size_t k = 0; k < 2; ++k) {
        EXPECT_GE(forests.stats[k].bytes * kSeriesNodesPerByte, forests.stats[k].octants) << k;
        EXPECT_LT((forests.stats[k].bytes - 1) * kSeriesNodesPerByte, forests.stats[k].octants) << k;
        EXPECT_EQ(forest_reader.frame(k).forest, forests.forest) << k;
    }
}

// A forest series of two frames over a 2 x 2 brick, with a leaf field.
std::vector<uint8_t> small_forest_series() {
    const TreeConnectivity conn = brick_connectivity(2, 2, 2);
    SeriesOptions options;
    options.choose_keyframes = false;
    ForestSeriesWriter writer(conn, options);
    for (int k = 0; k < 2; ++k) {
        OctreeForest forest = uniform_octree_forest(conn, 2 + k);
        Field phi{"phi", FieldAssociation::cell, FieldType::float64, 1, {}, {}};
        for (size_t i = 0; i < forest.leaves.size(); ++i) phi.values.push_back(0.25 * double(i));
        forest.leaf_data = {phi};
        writer.add_frame(forest, double(k));
    }
    writer.close();
    return writer.bytes();
}

TEST(CraftedFiles, ForestSeriesCounts) {
    const std::vector<uint8_t> good = small_forest_series();
    ASSERT_NO_THROW(read_forest_series(good));
    const SeriesParts original = take_series_apart(good);
    // The forest base (7.10): trees beyond the octant limit, and a brick of 4096 x 4096 trees
    // (within the limit, 16.8 M trees in a few bytes: before the bound, built on opening).
    for (uint64_t trees : {uint64_t(1) << 31, uint64_t(1) << 40, uint64_t(4096) * 4096}) {
        SeriesParts parts = original;
        std::vector<uint8_t> base = {2};
        put_varint(base, trees);
        base.push_back(uint8_t(OctreeConnectivityMode::brick));
        base.push_back(0);  // not periodic
        put_varint(base, trees == uint64_t(4096) * 4096 ? 4096 : trees);
        put_varint(base, trees == uint64_t(4096) * 4096 ? 4096 : 1);
        parts.blocks[0].second = base;
        parts.blocks.resize(1);
        const std::vector<uint8_t> file = put_series_together(parts);
        expect_refused_cheaply("forest base of " + std::to_string(trees) + " trees", ErrorCode::limit_exceeded,
                               [&] { read_forest_series(file); }, trees == uint64_t(4096) * 4096 ? "per byte" : "limit");
    }
    const char* const names[] = {"octants", "leaves", "levels"};
    for (size_t block = 1; block <= 2; ++block) {
        const FramePayload f = read_frame_payload(original.blocks[block].second, true);
        const auto refused =
            frame_refusal(original, block, "forest series frame " + std::to_string(block - 1) + " ", read_forest_series);
        for (uint64_t huge : kHuge) {
            for (int i = 0; i < 3; ++i) {
                FramePayload changed = f;
                changed.counts[size_t(i)] = huge;
                refused(std::string(names[i]) + " = " + std::to_string(huge), ErrorCode::corrupt, changed, "inconsistent counts");
            }
            refuse_huge_lengths(refused, f, huge);
            // The field record (7.12): mode, then its length.
            FramePayload record = f;
            record.fields.resize(1);
            put_varint(record.fields, huge);
            record.fields.insert(record.fields.end(), f.fields.begin() + 1, f.fields.end());
            refused("field record length = " + std::to_string(huge), ErrorCode::truncated, record, nullptr);
        }
        // Octants consistent with the leaves and levels, within the node limit but not the bytes:
        // a uniform quadtree of depth 11 over the 4 trees (22.4 M octants).
        FramePayload deep = f;
        uint64_t octants = 0, level_octants = 4;
        for (int l = 0; l <= 11; ++l, level_octants *= 4) octants += level_octants;
        deep.counts = {octants, 4 + (octants - 4) / 4 * 3, 12};
        ASSERT_LE(octants, SeriesReadOptions().max_nodes);
        refused("octants = " + std::to_string(octants), ErrorCode::limit_exceeded, deep, "per byte");
    }
}

}  // namespace
}  // namespace amc
