// Crafted files: for each count field of each block, a file whose checksums are valid but whose
// count is huge. Each must be refused in under 10 ms of CPU time with under 10 MB allocated
// (docs/FORMAT.md, 3.7: every count is checked against the bytes that can hold it before anything
// is allocated for it). A test binary of its own: it counts every allocation through a global
// operator new.
#include "coding/entropy/arithmetic_coder.h"
#include "coding/base/base_mesh_coder.h"
#include "coding/container.h"
#include "coding/geometry/float_coder.h"
#include "coding/hierarchy/hierarchy_stream.h"
#include "common/bits.h"
#include "octree/octree_file.h"
#include "octree/octree_traversal.h"

#include <amc/codec.h>
#include <amc/hierarchy_coder.h>
#include <amc/octree.h>
#include <amc/refinement.h>

#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <ctime>
#include <functional>
#include <new>
#include <string>

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
#else
constexpr double kMaxMilliseconds = 10.0;
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

}  // namespace
}  // namespace amc
