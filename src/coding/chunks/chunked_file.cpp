// Chunk table, seam and chunk blocks of a chunked .amc file (chunked_file.h).
#include "coding/chunks/chunked_file.h"

#include "coding/chunks/chunk_coder.h"
#include "coding/chunks/chunk_merge.h"
#include "coding/chunks/seam.h"
#include "coding/file_metadata.h"
#include "common/check.h"
#include "common/huge_pages.h"
#include "common/parallel.h"
#include "hierarchy/hierarchy_builder.h"

#include <algorithm>
#include <cstddef>
#include <memory>
#include <string>

namespace amc {

uint64_t leaf_face_count(const Hierarchy& h, unsigned threads) {
    constexpr NodeId kRange = NodeId(1) << 16;  // nodes counted per task
    std::vector<uint64_t> faces((size_t(h.node_capacity()) + kRange - 1) / kRange, 0);
    parallel_for(faces.size(), threads, [&](size_t i) {
        const NodeId begin = NodeId(i) * kRange, end = std::min<NodeId>(h.node_capacity(), begin + kRange);
        uint64_t count = 0;  // not faces[i]: the ranges' totals share cache lines, which two threads would trade
        for (NodeId n = begin; n < end; ++n)
            if (h.is_alive(n) && h.is_leaf(n)) count += 1 + uint64_t(h.hanging_node_count(n));
        faces[i] = count;
    });
    uint64_t sum = 0;
    for (uint64_t f : faces) sum += f;
    return sum;
}

ChunkedBlocks encode_chunked(const Hierarchy& h, const std::vector<uint32_t>& root_of, const std::vector<uint64_t>& root_nodes,
                             const std::vector<RootRange>& ranges,
                             const EncodeOptions& options, CoordinateSpace space, unsigned threads, EncodeStats& stats,
                             bool base_raw_bits, ChunkEncoderMemories* kept) {
    std::vector<uint32_t> chunk_of_root(h.root_count());
    for (uint32_t c = 0; c < ranges.size(); ++c)
        for (uint32_t r = ranges[c].first; r < ranges[c].first + ranges[c].count; ++r) chunk_of_root[r] = c;
    std::vector<uint32_t> key_of_vertex;
    const Seam seam(h, chunk_of_root, key_of_vertex);
    std::vector<ChunkCode> codes(ranges.size());
    std::vector<uint64_t> nodes(ranges.size()), own_vertices(ranges.size());
    // Shared: the chunks' nodes are disjoint, and each chunk writes its nodes' entries before it
    // reads them (subforest), so they are not zeroed first; their pages are faulted in by the tasks.
    const std::unique_ptr<NodeId[]> local = written_whole_array<NodeId>(h.node_capacity());
    // Each chunk is copied into a room made resident first (subforest_room, make_resident). The
    // rooms of the chunks the other threads take first (tasks 1 .. threads - 1; this thread, which
    // starts them, takes task 0) are reserved here before they start, so that those copies live in
    // this thread's malloc arena and a worker's arena holds only its level coder's working memory,
    // which glibc then keeps from one encode to the next: a worker that allocated its own copy had
    // its arena trimmed after each encode and faulted ~4,300 fresh pages into it again
    // (docs/BENCHMARKS.md, "Threads and memory"). Each task makes its room resident, so that the
    // threads populate their rooms at once. Which thread takes which chunk changes no byte.
    std::vector<uint64_t> chunk_nodes(ranges.size(), 0);
    for (size_t c = 0; c < ranges.size(); ++c)
        for (uint32_t r = ranges[c].first; r < ranges[c].first + ranges[c].count; ++r) chunk_nodes[c] += root_nodes[r];
    auto room_for = [&](size_t c) {
        // Vertices in proportion to nodes, with some slack (what the room lacks is faulted in).
        const double share = double(chunk_nodes[c]) / double(std::max<size_t>(1, h.node_count()));
        return HierarchyBuilder::subforest_room(h, size_t(chunk_nodes[c]), size_t(1.0625 * share * double(h.positions().size())));
    };
    const size_t made_first = threads > 1 ? std::min<size_t>(threads, ranges.size()) : 1;
    std::vector<SubforestRoom> rooms(ranges.size());
    for (size_t c = 1; c < made_first; ++c) rooms[c] = room_for(c);
    // With `kept`, one memory a thread for the chunks it takes (a task's end gives it back for the
    // next task). Without, each chunk's encoder allocates its own, as before (a memory held through
    // the whole encode only moves where glibc puts the other blocks: "Threads and memory").
    // The seam's code is the last task: the first thread done with its chunk takes it while the
    // others finish theirs.
    RawSideCode seam_code;
    parallel_for(ranges.size() + 1, threads, [&](size_t c) {
        if (c == ranges.size()) {
            seam_code = seam.encode(space, space.quantizer == nullptr);
            return;
        }
        std::unique_ptr<ChunkEncoderMemory> memory = kept != nullptr ? kept->take() : nullptr;
        if (c == 0 || c >= made_first) rooms[c] = room_for(c);
        HierarchyBuilder::make_resident(rooms[c]);
        std::vector<VertexId> vertex_of;
        const Hierarchy chunk = extract_roots(h, {ranges[c]}, root_of, local.get(), &vertex_of, &rooms[c]);
        VertexKeys keys(vertex_of.size(), kNoVertex);
        for (size_t v = 0; v < vertex_of.size(); ++v)
            if (vertex_of[v] != kNoVertex) keys[v] = key_of_vertex[vertex_of[v]];
        codes[c] = encode_chunk(chunk, keys, seam, options.hierarchy, options.predictor, space, options.grid_contexts, options.unit_normals,
                                options.effort, memory.get());
        if (kept != nullptr) kept->give_back(std::move(memory));
        codes[c].bytes.shrink_to_fit();  // held until the file is written: without the slack of its growth
        nodes[c] = chunk.node_count();
        own_vertices[c] = uint64_t(std::count(keys.begin(), keys.end(), kNoVertex));  // neither base nor seam vertices
    });
    ChunkedBlocks out;
    // Bit-exact: the seam's raw bits apart when the file has any there or in its base (version 21);
    // without any, the arithmetic code alone is the block of the older versions.
    out.base_side = space.quantizer == nullptr && (base_raw_bits || !seam_code.raw.empty());
    std::vector<uint8_t> seam_bytes = out.base_side ? seam_code.joined() : seam_code.arithmetic;
    // Table: count, then per chunk its roots, nodes, own vertices and where its block starts,
    // counted from the end of the table block (so the table's own size does not matter).
    std::vector<uint8_t> table;
    put_varint(table, ranges.size());
    uint64_t offset = kBlockOverhead + seam_bytes.size();
    for (size_t c = 0; c < ranges.size(); ++c) {
        put_varint(table, ranges[c].count);
        put_varint(table, nodes[c]);
        put_varint(table, own_vertices[c]);
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
        out.unit_geometry |= code.unit_geometry;
        out.raw_side |= code.raw_side;
        out.stencil_tables |= code.stencil_tables;
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

ChunkTable read_chunk_table(const Block& block, uint8_t version, uint64_t base_triangles, uint64_t nodes, size_t file_size) {
    PayloadReader in(block.payload, block.size, "chunk table block");
    ChunkTable table;
    table.end = block.offset + kBlockOverhead + block.size;
    const uint64_t count = in.varint();
    // Every chunk block takes kBlockOverhead bytes or more of what follows the table.
    AMC_REQUIRE(count >= 2 && count <= base_triangles && count <= (file_size - table.end) / kBlockOverhead, corrupt,
                "chunk table block: bad chunk count " + std::to_string(count));
    const bool lists_vertices = version >= kChunkVerticesVersion;
    uint64_t roots = 0, node_sum = 0, previous_end = 0;
    for (uint64_t c = 0; c < count; ++c) {
        const uint64_t r = in.varint(), n = in.varint(), v = lists_vertices ? in.varint() : 0, offset = in.varint();
        // Each split makes at most three vertices.
        AMC_REQUIRE(r >= 1 && r <= base_triangles - roots && n >= r && (n - r) % 4 == 0 && n <= nodes - node_sum &&
                        v <= (n - r) / 4 * 3,
                    corrupt, "chunk table block: chunk " + std::to_string(c) + " has inconsistent counts");
        // Chunk blocks follow the seam block in order: each starts past the end of the one before.
        AMC_REQUIRE(offset >= previous_end + kBlockOverhead && offset <= file_size - table.end - kBlockOverhead, corrupt,
                    "chunk table block: chunk " + std::to_string(c) + " has a bad offset");
        table.roots.push_back({uint32_t(roots), uint32_t(r)});
        table.nodes.push_back(n);
        if (lists_vertices) table.own_vertices.push_back(v);
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
                         const std::vector<uint32_t>* selected, ChunkTable* table_out, MergedCounts* counts_out) {
    const TriangleMesh& base = *input.base;
    Block block{};
    AMC_REQUIRE(reader.next(block) && block.type == BlockType::chunk_table, corrupt, "expected a chunk table block");
    const size_t file_size = block.offset + kBlockOverhead + block.size + reader.remaining();
    const ChunkTable table = read_chunk_table(block, input.version, base.triangles.size(), nodes, file_size);
    AMC_REQUIRE(reader.next(block) && block.type == BlockType::seam, corrupt, "expected a seam block");
    AMC_REQUIRE(block.offset + kBlockOverhead + block.size == table.end + table.offsets[0], corrupt,
                "chunk table block: chunk 0 does not start after the seam block");
    std::vector<uint32_t> chunk_of_root(base.triangles.size());
    for (uint32_t c = 0; c < table.roots.size(); ++c)
        for (uint32_t r = table.roots[c].first; r < table.roots[c].first + table.roots[c].count; ++r) chunk_of_root[r] = c;
    const Seam seam = Seam::decode(block.payload, block.size, base, chunk_of_root, input.space,
                                   input.vertices - base.positions.size(),
                                   base_raw_side(input.version, input.space.quantizer != nullptr));
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
    // Find every chunk's block through the table (the whole file: one after the other). Their
    // checksums are checked by the threads that decode them.
    std::vector<Block> blocks(chunks.size());
    for (size_t i = 0; i < chunks.size(); ++i) {
        const size_t offset = table.end + size_t(table.offsets[chunks[i]]);
        if (selected != nullptr) reader.seek(offset);
        const bool found = reader.next_unchecked(blocks[i]);
        if (found && (blocks[i].type != BlockType::chunk || blocks[i].offset != offset)) reader.check_checksum(blocks[i]);
        AMC_REQUIRE(found && blocks[i].type == BlockType::chunk && blocks[i].offset == offset, corrupt,
                    "chunk table block: no chunk block at the offset of chunk " + std::to_string(chunks[i]));
    }
    if (table_out != nullptr) *table_out = table;

    std::vector<ChunkJob> jobs(chunks.size());
    for (size_t i = 0; i < chunks.size(); ++i) {
        const uint32_t c = chunks[i];
        jobs[i] = {c, blocks[i], table.roots[c], table.nodes[c],
                   table.own_vertices.empty() ? kUnknownVertices : table.own_vertices[c]};
    }
    ChunkMergeInput merge;
    merge.reader = &reader;
    merge.base = &base;
    merge.seam = &seam;
    merge.space = input.space;
    merge.file_version = input.version;
    merge.whole_file = selected == nullptr;
    merge.vertices = input.vertices;
    merge.file_size = file_size;
    merge.options = input.options;
    merge.zeroed_positions = input.zeroed_positions;
    merge.kept_decoders = input.kept_decoders;
    merge.spare = input.spare;
    MergedCounts counts;
    Hierarchy whole = decode_and_merge_chunks(jobs, merge, counts);
    if (counts_out != nullptr) *counts_out = counts;
    return whole;
}

}  // namespace amc
