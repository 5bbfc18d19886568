// Chunk table, seam and chunk blocks of a chunked .amc file (chunked_file.h).
#include "coding/chunks/chunked_file.h"

#include "coding/chunks/chunk_coder.h"
#include "coding/chunks/seam.h"
#include "coding/file_metadata.h"
#include "common/check.h"
#include "common/parallel.h"
#include "hierarchy/hierarchy_builder.h"

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <memory>
#include <mutex>
#include <string>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace amc {

namespace {

// Returns the free pages of the heap to the system: glibc keeps blocks below its mapping
// threshold (which grows as large blocks are freed) in the process after they are freed.
void give_back_free_memory() {
#if defined(__GLIBC__)
    malloc_trim(0);
#endif
}

}  // namespace

uint32_t chunk_count_for(const EncodeOptions& options, uint64_t faces) {
    if (options.chunks != 0) return options.chunks;
    const uint64_t per_chunk = std::max<uint64_t>(1, options.chunk_faces);
    return uint32_t(std::max<uint64_t>(1, std::min<uint64_t>(faces / per_chunk, UINT32_MAX)));
}

uint64_t leaf_face_count(const Hierarchy& h, unsigned threads) {
    constexpr NodeId kRange = NodeId(1) << 16;  // nodes counted per task
    std::vector<uint64_t> faces((size_t(h.node_capacity()) + kRange - 1) / kRange, 0);
    parallel_for(faces.size(), threads, [&](size_t i) {
        const NodeId begin = NodeId(i) * kRange, end = std::min<NodeId>(h.node_capacity(), begin + kRange);
        for (NodeId n = begin; n < end; ++n)
            if (h.is_alive(n) && h.is_leaf(n)) faces[i] += 1 + uint64_t(h.hanging_node_count(n));
    });
    uint64_t sum = 0;
    for (uint64_t f : faces) sum += f;
    return sum;
}

ChunkedBlocks encode_chunked(const Hierarchy& h, const std::vector<RootRange>& ranges, const EncodeOptions& options,
                             CoordinateSpace space, unsigned threads, EncodeStats& stats) {
    std::vector<uint32_t> chunk_of_root(h.root_count());
    for (uint32_t c = 0; c < ranges.size(); ++c)
        for (uint32_t r = ranges[c].first; r < ranges[c].first + ranges[c].count; ++r) chunk_of_root[r] = c;
    std::vector<uint32_t> key_of_vertex;
    const Seam seam(h, chunk_of_root, key_of_vertex);
    std::vector<ChunkCode> codes(ranges.size());
    std::vector<uint64_t> nodes(ranges.size());
    parallel_for(ranges.size(), threads, [&](size_t c) {
        std::vector<VertexId> vertex_of;
        const Hierarchy chunk = extract_roots(h, {ranges[c]}, &vertex_of);
        VertexKeys keys(vertex_of.size(), kNoVertex);
        for (size_t v = 0; v < vertex_of.size(); ++v)
            if (vertex_of[v] != kNoVertex) keys[v] = key_of_vertex[vertex_of[v]];
        codes[c] = encode_chunk(chunk, keys, seam, options.hierarchy, options.predictor, space, options.grid_contexts);
        codes[c].bytes.shrink_to_fit();  // held until the file is written: without the slack of its growth
        nodes[c] = chunk.node_count();
    });
    ChunkedBlocks out;
    std::vector<uint8_t> seam_bytes = seam.encode(space);
    // Table: count, then per chunk its roots, nodes and where its block starts, counted from the
    // end of the table block (so the table's own size does not matter).
    std::vector<uint8_t> table;
    put_varint(table, ranges.size());
    uint64_t offset = kBlockOverhead + seam_bytes.size();
    for (size_t c = 0; c < ranges.size(); ++c) {
        put_varint(table, ranges[c].count);
        put_varint(table, nodes[c]);
        put_varint(table, offset);
        offset += kBlockOverhead + codes[c].bytes.size();
    }
    out.blocks.emplace_back(BlockType::chunk_table, std::move(table));
    stats.header_bytes += kBlockOverhead + out.blocks.back().second.size();
    stats.geometry_bytes += seam_bytes.size();
    stats.framing_bytes += kBlockOverhead;
    out.blocks.emplace_back(BlockType::seam, std::move(seam_bytes));
    for (ChunkCode& code : codes) {
        out.static_geometry |= code.static_geometry;
        out.grid_geometry |= code.grid_geometry;
        out.levels = std::max(out.levels, int(code.levels.size()));
        stats.hierarchy_bytes += code.hierarchy_bytes;
        stats.geometry_bytes += code.geometry_bytes;
        stats.framing_bytes += kBlockOverhead;
        if (stats.per_level.size() < code.levels.size()) stats.per_level.resize(code.levels.size());
        for (size_t l = 0; l < code.levels.size(); ++l) {
            LevelStats& s = stats.per_level[l];
            s.nodes += code.levels[l].nodes;
            s.new_vertices += code.levels[l].new_vertices;
            s.bytes += code.levels[l].bytes;
            s.predictor = code.levels[l].predictor;  // the last chunk's
        }
        out.blocks.emplace_back(BlockType::chunk, std::move(code.bytes));
    }
    return out;
}

ChunkTable read_chunk_table(const Block& block, uint64_t base_triangles, uint64_t nodes, size_t file_size) {
    PayloadReader in(block.payload, block.size, "chunk table block");
    ChunkTable table;
    table.end = block.offset + kBlockOverhead + block.size;
    const uint64_t count = in.varint();
    // Every chunk block takes kBlockOverhead bytes or more of what follows the table.
    AMC_REQUIRE(count >= 2 && count <= base_triangles && count <= (file_size - table.end) / kBlockOverhead, corrupt,
                "chunk table block: bad chunk count " + std::to_string(count));
    uint64_t roots = 0, node_sum = 0, previous_end = 0;
    for (uint64_t c = 0; c < count; ++c) {
        const uint64_t r = in.varint(), n = in.varint(), offset = in.varint();
        AMC_REQUIRE(r >= 1 && r <= base_triangles - roots && n >= r && (n - r) % 4 == 0 && n <= nodes - node_sum, corrupt,
                    "chunk table block: chunk " + std::to_string(c) + " has inconsistent counts");
        // Chunk blocks follow the seam block in order: each starts past the end of the one before.
        AMC_REQUIRE(offset >= previous_end + kBlockOverhead && offset <= file_size - table.end - kBlockOverhead, corrupt,
                    "chunk table block: chunk " + std::to_string(c) + " has a bad offset");
        table.roots.push_back({uint32_t(roots), uint32_t(r)});
        table.nodes.push_back(n);
        table.offsets.push_back(offset);
        roots += r;
        node_sum += n;
        previous_end = offset;
    }
    AMC_REQUIRE(roots == base_triangles && node_sum == nodes, corrupt,
                "chunk table block: the chunks do not add up to the file's roots and nodes");
    AMC_REQUIRE(in.remaining() == 0, corrupt, "chunk table block has trailing bytes");
    return table;
}

Hierarchy decode_chunked(BlockReader& reader, const ChunkedDecodeInput& input, uint64_t nodes,
                         const std::vector<uint32_t>* selected, ChunkTable* table_out, uint64_t* faces_out) {
    const TriangleMesh& base = *input.base;
    Block block{};
    AMC_REQUIRE(reader.next(block) && block.type == BlockType::chunk_table, corrupt, "expected a chunk table block");
    const size_t file_size = block.offset + kBlockOverhead + block.size + reader.remaining();
    const ChunkTable table = read_chunk_table(block, base.triangles.size(), nodes, file_size);
    AMC_REQUIRE(reader.next(block) && block.type == BlockType::seam, corrupt, "expected a seam block");
    AMC_REQUIRE(block.offset + kBlockOverhead + block.size == table.end + table.offsets[0], corrupt,
                "chunk table block: chunk 0 does not start after the seam block");
    std::vector<uint32_t> chunk_of_root(base.triangles.size());
    for (uint32_t c = 0; c < table.roots.size(); ++c)
        for (uint32_t r = table.roots[c].first; r < table.roots[c].first + table.roots[c].count; ++r) chunk_of_root[r] = c;
    const Seam seam = Seam::decode(block.payload, block.size, base, chunk_of_root, input.space,
                                   input.vertices - base.positions.size());
    std::vector<uint32_t> chunks;
    if (selected != nullptr) {
        chunks = *selected;
        for (size_t i = 0; i < chunks.size(); ++i)
            AMC_REQUIRE(chunks[i] < table.roots.size() && (i == 0 || chunks[i] > chunks[i - 1]), invalid_input,
                        "chunk " + std::to_string(chunks[i]) + " is not in the file (it has " +
                            std::to_string(table.roots.size()) + " chunks), or the chunks are not in increasing order");
    } else {
        for (uint32_t c = 0; c < table.roots.size(); ++c) chunks.push_back(c);
    }
    // Find every chunk's block through the table (the whole file: one after the other).
    std::vector<Block> blocks(chunks.size());
    for (size_t i = 0; i < chunks.size(); ++i) {
        const size_t offset = table.end + size_t(table.offsets[chunks[i]]);
        if (selected != nullptr) reader.seek(offset);
        AMC_REQUIRE(reader.next(blocks[i]) && blocks[i].type == BlockType::chunk && blocks[i].offset == offset, corrupt,
                    "chunk table block: no chunk block at the offset of chunk " + std::to_string(chunks[i]));
    }
    if (table_out != nullptr) *table_out = table;

    // The result: the base of the selected roots; their nodes in chunk order, each chunk's in a
    // slice as long as the chunk table says; its vertices the base, the seam vertices the chunks
    // use (in seam order), then each chunk's own vertices.
    const unsigned threads = resolve_thread_count(input.options.threads);
    const size_t n = chunks.size();
    std::vector<RootRange> ranges;
    for (uint32_t c : chunks) ranges.push_back(table.roots[c]);
    std::vector<VertexId> union_vertex;  // result base vertex -> file base vertex
    const TriangleMesh union_base = selected == nullptr ? base : base_of_roots(base, ranges, union_vertex);
    std::vector<VertexId> base_id(base.positions.size(), kNoVertex);
    for (VertexId v = 0; v < union_vertex.size(); ++v) base_id[union_vertex[v]] = v;
    if (selected == nullptr)
        for (VertexId v = 0; v < base_id.size(); ++v) base_id[v] = v;
    const uint32_t file_base = uint32_t(base.positions.size());
    // Until every chunk is decoded, a chunk names seam vertex s seam_start + s and its own vertex
    // k own_start + k; rename below makes them final.
    const uint64_t seam_start = union_base.positions.size(), own_start = seam_start + seam.vertex_count();
    std::vector<HierarchyBuilder::StitchPart> parts(n);
    std::vector<NodeId> slice_end(n);
    uint64_t whole_nodes = union_base.triangles.size();
    for (size_t i = 0; i < n; ++i) {
        parts[i].first_root = i == 0 ? 0 : parts[i - 1].first_root + table.roots[chunks[i - 1]].count;
        parts[i].first_node = NodeId(whole_nodes);
        whole_nodes += table.nodes[chunks[i]] - table.roots[chunks[i]].count;
        slice_end[i] = NodeId(std::min<uint64_t>(whole_nodes, kNoNode));
    }
    // The whole is made first, so that each chunk is copied into it as soon as it is decoded and
    // the chunk's memory serves the next one; the table's counts are trusted that far only when
    // they are no more than a whole file's decoder reserves up front for the file's size. Beyond
    // that (a file of uniform levels, or a crafted one), and when a progressive decode stops
    // early, every chunk is decoded first and the whole is made from what they hold.
    const bool whole_first = input.options.max_level < 0 &&
                             whole_nodes <= union_base.triangles.size() + kReservedNodesPerFileByte * uint64_t(file_size);
    Hierarchy whole;
    if (whole_first) whole = HierarchyBuilder::stitch_frame(union_base, size_t(whole_nodes));

    std::vector<std::unique_ptr<HierarchyLevelDecoder>> decoder_of(n), idle;
    std::mutex idle_mutex;
    // Each decoder builds its chunks in room for the largest one, reserved once: no growth and no
    // slack (the table's counts are trusted as far as the whole's are).
    uint64_t largest_chunk = 0;
    for (uint32_t c : chunks) largest_chunk = std::max(largest_chunk, table.nodes[c]);
    std::atomic<size_t> started{0};  // chunks whose decoding has begun
    std::vector<VertexKeys> keys(n);
    std::vector<uint32_t> own(n);                    // vertices that are neither base nor seam vertices
    std::vector<std::vector<Vec3>> own_positions(n);  // their positions, when their place is not known yet
    std::vector<std::vector<uint32_t>> seam_used(n);  // the seam vertices each chunk holds
    std::vector<uint32_t> live(n);                    // nodes past the roots
    std::vector<uint64_t> faces(n);                   // of each chunk's leaves in the whole leaf mesh
    // The whole's positions: the base's, the seam's, then each chunk's own vertices in chunk order.
    // A whole file uses every seam vertex and has the metadata's vertex count, so each chunk's own
    // positions have their place once the chunks before it are counted: written there directly
    // (always on one thread), or set aside until then. Otherwise (some chunks, or the whole made
    // late) all are set aside and placed once every chunk is in, after the seam vertices they use.
    const bool positions_first = whole_first && selected == nullptr;
    std::vector<Vec3> positions;
    std::vector<uint64_t> first_own(n);
    std::vector<uint8_t> counted(n, 0), aside(n, 0);
    size_t placed = 0;  // chunks whose place in `positions` is known
    uint64_t next_own = own_start;
    std::mutex placed_mutex;
    auto place_counted = [&] {  // under placed_mutex: the places of the chunks counted in order
        for (; placed < n && counted[placed]; ++placed) {
            first_own[placed] = next_own;
            next_own += own[placed];
            AMC_REQUIRE(next_own <= positions.size(), corrupt, "the chunks hold more vertices than the metadata says");
            if (aside[placed]) {
                std::vector<Vec3>& own_of = own_positions[placed];
                std::copy(own_of.begin(), own_of.end(), positions.begin() + ptrdiff_t(first_own[placed]));
                std::vector<Vec3>().swap(own_of);
            }
        }
    };
    if (positions_first) {
        AMC_REQUIRE(input.vertices >= own_start && input.vertices < kNoVertex, corrupt,
                    "the metadata's vertex count does not fit the base and the seam");
        positions.reserve(size_t(input.vertices));
        positions = union_base.positions;
        for (uint32_t s = 0; s < seam.vertex_count(); ++s) positions.push_back(seam.position(s));
        positions.resize(size_t(input.vertices));
    }
    // Chunk i, decoded into h, into the whole (its nodes and positions; its seam vertices noted).
    auto copy_into_whole = [&](size_t i, const Hierarchy& h) {
        const VertexKeys& key = keys[i];
        own[i] = uint32_t(std::count(key.begin(), key.end(), kNoVertex));
        AMC_REQUIRE(own_start + own[i] < kNoVertex, limit_exceeded, "too many vertices");
        bool direct = false;
        if (positions_first) {
            std::lock_guard<std::mutex> lock(placed_mutex);
            counted[i] = 1;
            place_counted();
            direct = placed > i;
        }
        if (!direct) own_positions[i].reserve(own[i]);
        std::vector<VertexId> id(key.size());
        uint32_t k = 0;
        for (size_t v = 0; v < id.size(); ++v) {
            if (key[v] == kNoVertex) {
                id[v] = VertexId(own_start + k);
                if (direct)
                    positions[size_t(first_own[i] + k)] = h.position(VertexId(v));
                else
                    own_positions[i].push_back(h.position(VertexId(v)));
                ++k;
            } else if (key[v] < file_base) {
                id[v] = base_id[key[v]];
            } else {
                id[v] = VertexId(seam_start + (key[v] - file_base));
                seam_used[i].push_back(key[v] - file_base);
            }
        }
        parts[i].part = &h;
        parts[i].vertex_id = id.data();
        live[i] = h.node_capacity() - h.root_count();
        AMC_REQUIRE(parts[i].first_node + live[i] == slice_end[i], corrupt,
                    "chunk " + std::to_string(chunks[i]) + " does not hold the nodes the chunk table says");
        HierarchyBuilder::stitch_part(whole, parts[i]);
        parts[i].part = nullptr;
        parts[i].vertex_id = nullptr;
        VertexKeys().swap(keys[i]);
        if (!direct) {
            std::lock_guard<std::mutex> lock(placed_mutex);
            aside[i] = 1;
            if (placed > i) {  // placed meanwhile, before its positions were aside
                std::copy(own_positions[i].begin(), own_positions[i].end(), positions.begin() + ptrdiff_t(first_own[i]));
                std::vector<Vec3>().swap(own_positions[i]);
            }
        }
    };
    parallel_for(n, threads, [&](size_t i) {
        ++started;
        const uint32_t c = chunks[i];
        {
            std::lock_guard<std::mutex> lock(idle_mutex);
            if (!idle.empty()) {
                decoder_of[i] = std::move(idle.back());
                idle.pop_back();
            }
        }
        if (decoder_of[i] == nullptr) {
            decoder_of[i] = std::make_unique<HierarchyLevelDecoder>();
            if (whole_first) decoder_of[i]->hierarchy().reserve(size_t(largest_chunk), 0);
        }
        std::vector<VertexId> base_vertex;
        const TriangleMesh chunk_base = base_of_roots(base, {table.roots[c]}, base_vertex);
        ChunkDecodeLimits limits;
        limits.max_nodes = std::min(table.nodes[c], input.options.max_nodes);
        limits.max_level = input.options.max_level;
        limits.file_version = input.version;
        limits.stream_version = hierarchy_stream_version_of_file(input.version);
        Hierarchy& h = decode_chunk(*decoder_of[i], blocks[i].payload, blocks[i].size, chunk_base, base_vertex, seam,
                                    input.space, limits, "chunk " + std::to_string(c), keys[i], faces[i]);
        AMC_REQUIRE(input.options.max_level >= 0 || h.node_count() == table.nodes[c], corrupt,
                    "chunk " + std::to_string(c) + " does not hold the nodes the chunk table says");
        if (!whole_first) return;
        if (started.load() < n) {  // a chunk still to begin takes this decoder, memory and all
            copy_into_whole(i, h);
            std::lock_guard<std::mutex> lock(idle_mutex);
            idle.push_back(std::move(decoder_of[i]));
            return;
        }
        // None will: its working memory goes before the copy, which is where the decode peaks.
        const Hierarchy last = std::move(h);
        decoder_of[i].reset();
        give_back_free_memory();
        copy_into_whole(i, last);
    });
    if (!whole_first) {  // slices as long as the chunks are
        whole_nodes = union_base.triangles.size();
        for (size_t i = 0; i < n; ++i) {
            const Hierarchy& h = decoder_of[i]->hierarchy();
            parts[i].first_node = NodeId(whole_nodes);
            whole_nodes += h.node_capacity() - h.root_count();
            AMC_REQUIRE(whole_nodes < kNoNode, limit_exceeded, "too many nodes");
            slice_end[i] = NodeId(whole_nodes);
        }
        whole = HierarchyBuilder::stitch_frame(union_base, size_t(whole_nodes));
        parallel_for(n, threads, [&](size_t i) {
            copy_into_whole(i, decoder_of[i]->hierarchy());
            decoder_of[i].reset();
        });
    }
    idle.clear();

    // The final vertex ids: the seam vertices some chunk holds, then each chunk's own.
    std::vector<VertexId> seam_id(seam.vertex_count(), kNoVertex);
    for (const std::vector<uint32_t>& used : seam_used)
        for (uint32_t s : used) seam_id[s] = 0;
    if (positions_first) {
        for (uint32_t s = 0; s < seam_id.size(); ++s) {
            AMC_REQUIRE(seam_id[s] == 0, corrupt, "seam block: vertex " + std::to_string(s) + " is in no chunk");
            seam_id[s] = VertexId(seam_start + s);
        }
        AMC_REQUIRE(placed == n && next_own == positions.size(), corrupt, "the chunks hold fewer vertices than the metadata says");
    } else {
        positions = union_base.positions;
        for (uint32_t s = 0; s < seam_id.size(); ++s) {
            if (seam_id[s] == kNoVertex) continue;
            seam_id[s] = VertexId(positions.size());
            positions.push_back(seam.position(s));
        }
        uint64_t vertices = positions.size();
        for (size_t i = 0; i < n; ++i) vertices += own[i];
        AMC_REQUIRE(vertices < kNoVertex, limit_exceeded, "too many vertices");
        next_own = positions.size();
        positions.resize(size_t(vertices));
        std::fill(counted.begin(), counted.end(), uint8_t(1));
        place_counted();
    }
    parallel_for(n, threads, [&](size_t i) {
        HierarchyBuilder::stitch_rename_vertices(whole, parts[i].first_node, parts[i].first_node + live[i], [&](VertexId v) {
            return v < seam_start ? v : v < own_start ? seam_id[v - seam_start] : VertexId(first_own[i] + (v - own_start));
        });
    });
    // The root edges between two chunks: boundary edges to each chunk, not to the whole.
    std::vector<uint32_t> part_of_root(union_base.triangles.size());
    for (size_t i = 0; i < n; ++i)
        for (NodeId r = 0; r < table.roots[chunks[i]].count; ++r) part_of_root[parts[i].first_root + r] = uint32_t(i);
    std::vector<std::pair<NodeId, int>> seam_edges;
    for (NodeId r = 0; r < part_of_root.size(); ++r)
        for (int e = 0; e < 3; ++e)
            if (!whole.is_boundary_edge(r, e) && part_of_root[whole.neighbor(r, e)] != part_of_root[r]) seam_edges.emplace_back(r, e);
    HierarchyBuilder::stitch_seams(whole, std::move(positions), std::move(seam_edges));
    if (faces_out != nullptr) {
        *faces_out = 0;
        for (uint64_t f : faces) *faces_out += f;
    }
    return whole;
}

}  // namespace amc
