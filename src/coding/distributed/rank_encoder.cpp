// The steps of a chunked .amc file written rank by rank (rank_encoder.h).
#include "coding/distributed/rank_encoder.h"

#include "coding/base/base_stage.h"
#include "coding/container.h"
#include "coding/distributed/rank_grid.h"
#include "coding/file_metadata.h"
#include "coding/format_version.h"
#include "coding/geometry/level_geometry.h"
#include "coding/geometry/position_coder.h"
#include "common/check.h"
#include "common/keyed_hash.h"
#include "hierarchy/writer_checks.h"

#include <algorithm>
#include <cstring>
#include <numeric>
#include <unordered_map>

namespace amc {

namespace {

bool same_bits(Vec3 a, Vec3 b) { return std::memcmp(&a.x, &b.x, sizeof(double)) == 0 && std::memcmp(&a.y, &b.y, sizeof(double)) == 0 && std::memcmp(&a.z, &b.z, sizeof(double)) == 0; }

uint64_t directed(uint32_t a, uint32_t b) { return (uint64_t(a) << 32) | b; }

// Quantized coordinates are float64 on the grid, whatever the input precision (as in encode()).
CoordinateSpace space_of(const TriangleMesh& base, const Quantizer* grid) {
    return CoordinateSpace{base.single_precision && grid == nullptr ? Precision::float32 : Precision::float64, grid};
}

// A block framed as BlockWriter frames it: type, length, payload, checksum.
std::vector<uint8_t> framed(BlockType type, const std::vector<uint8_t>& payload) {
    BlockWriter writer(kChunkedVersion, 0);
    writer.add(type, payload);
    std::vector<uint8_t> file = writer.finish();
    return std::vector<uint8_t>(file.begin() + std::ptrdiff_t(kFileHeaderSize), file.end() - std::ptrdiff_t(kBlockOverhead));
}

}  // namespace

void check_rank_options(const EncodeOptions& options, const std::string& what) {
    AMC_REQUIRE(options.quantize_bits == 0 || (options.quantize_bits >= kMinQuantizationBits && options.quantize_bits <= kMaxQuantizationBits),
                invalid_input,
                what + ": quantize_bits " + std::to_string(options.quantize_bits) + " is not 0 (bit-exact) or " +
                    std::to_string(kMinQuantizationBits) + " to " + std::to_string(kMaxQuantizationBits));
    AMC_REQUIRE(options.numbering == nullptr, invalid_input,
                what + ": a numbering is not written by ranks (its block codes one permutation of the whole leaf mesh, "
                       "which no rank holds; docs/MPI.md)");
    AMC_REQUIRE(options.hierarchy_contexts == HierarchyContexts::paper, invalid_input,
                what + ": the mixing mode is not written by ranks (it codes the whole forest as one stream, "
                       "ranks write one chunk each; docs/MPI.md)");
    check_effort(options.effort, what);
}

RankChunk rank_chunk(const TriangleMesh& base, uint32_t first_root, const Hierarchy& forest, const std::string& what) {
    const TriangleMesh& local = forest.base();
    const uint64_t count = local.triangles.size();
    AMC_REQUIRE(first_root <= base.triangles.size() && count <= base.triangles.size() - first_root, invalid_input,
                what + ": roots " + std::to_string(first_root) + " to " + std::to_string(first_root + count) +
                    " (exclusive) are not in the base mesh, which has " + std::to_string(base.triangles.size()) + " triangles");
    RankChunk out;
    out.first_root = first_root;
    if (count == 0) return out;
    AMC_REQUIRE(local.single_precision == base.single_precision, invalid_input,
                what + ": the forest's base and the whole base differ in precision (float32 against float64)");
    check_before_writing(forest, what, true);
    std::vector<VertexId> global(local.positions.size(), kNoVertex), local_of(base.positions.size(), kNoVertex);
    for (uint32_t i = 0; i < count; ++i) {
        for (int k = 0; k < 3; ++k) {
            const VertexId l = local.triangles[i][k], g = base.triangles[first_root + i][k];
            const std::string corner = what + ": corner " + std::to_string(k) + " of root " + std::to_string(first_root + i);
            AMC_REQUIRE(g < base.positions.size(), invalid_input, corner + " is not a vertex of the base mesh");
            if (global[l] == kNoVertex && local_of[g] == kNoVertex) {
                AMC_REQUIRE(same_bits(local.positions[l], base.positions[g]), invalid_input,
                            corner + ": its position differs from base vertex " + std::to_string(g) + "'s");
                global[l] = g;
                local_of[g] = l;
            }
            AMC_REQUIRE(global[l] == g && local_of[g] == l, invalid_input,
                        corner + ": the forest's base triangles do not have the base mesh's corners (forest vertex " +
                            std::to_string(l) + " against base vertex " + std::to_string(g) + ")");
        }
    }
    // The chunk's base vertices in the whole base's order (base_of_roots), then its trees as the
    // serial encoder extracts them from the whole hierarchy.
    std::vector<uint32_t> vertex_order(local.positions.size());
    std::iota(vertex_order.begin(), vertex_order.end(), 0u);
    std::sort(vertex_order.begin(), vertex_order.end(), [&](uint32_t a, uint32_t b) { return global[a] < global[b]; });
    std::vector<uint32_t> triangle_order(count);
    std::iota(triangle_order.begin(), triangle_order.end(), 0u);
    const Hierarchy reordered = reorder_base(forest, vertex_order, triangle_order, std::vector<uint8_t>(count, 0));
    out.chunk = extract_roots(reordered, {RootRange{0, uint32_t(count)}});
    for (uint32_t v : vertex_order) out.base_vertex.push_back(global[v]);
    return out;
}

RankLayout rank_layout(uint32_t roots, const std::vector<RootRange>& ranges) {
    AMC_REQUIRE(roots > 0, invalid_input, "the base mesh has no triangles");
    RankLayout out;
    out.chunk_of_rank.assign(ranges.size(), -1);
    std::vector<uint32_t> ranks;
    for (uint32_t r = 0; r < ranges.size(); ++r)
        if (ranges[r].count > 0) ranks.push_back(r);
    std::sort(ranks.begin(), ranks.end(), [&](uint32_t a, uint32_t b) { return ranges[a].first < ranges[b].first; });
    uint64_t next = 0;
    for (uint32_t r : ranks) {
        AMC_REQUIRE(ranges[r].first == next, invalid_input,
                    "the ranks' roots do not cut the base mesh's " + std::to_string(roots) + " triangles into runs: rank " +
                        std::to_string(r) + " starts at root " + std::to_string(ranges[r].first) + " where root " +
                        std::to_string(next) + " is expected");
        out.chunk_of_rank[r] = int32_t(out.chunks.size());
        out.chunks.push_back(ranges[r]);
        next += ranges[r].count;
    }
    AMC_REQUIRE(next == roots, invalid_input,
                "the ranks own " + std::to_string(next) + " roots, the base mesh has " + std::to_string(roots) + " triangles");
    out.chunk_of_root.resize(roots);
    for (uint32_t c = 0; c < out.chunks.size(); ++c)
        std::fill_n(out.chunk_of_root.begin() + out.chunks[c].first, out.chunks[c].count, c);
    return out;
}

std::vector<SeamSplit> seam_splits(const RankChunk& part, const TriangleMesh& base, const RankLayout& layout) {
    std::vector<SeamSplit> out;
    const Hierarchy& h = part.chunk;
    const uint32_t first = part.first_root, count = h.root_count();
    if (count == 0) return out;
    // The rank's root edges by their ends in the whole base, to find the far side of a seam edge.
    // Keyed: the caller numbers the base vertices, and the identity hash let the edges of a
    // matching share one bucket (docs/FUZZING.md).
    std::unordered_map<uint64_t, std::pair<NodeId, int>, KeyedWordHash> own_edge;
    for (uint32_t i = 0; i < count; ++i)
        for (int e = 0; e < 3; ++e)
            own_edge.emplace(directed(base.triangles[first + i][e], base.triangles[first + i][(e + 1) % 3]), std::make_pair(i, e));
    // Segment `s` of edge `i` from the edge's first end, on node n's edge e; `reversed`: the edge
    // runs the other way on n (the far side), so its halves swap.
    auto walk = [&](auto& self, uint32_t i, NodeId n, int e, bool reversed, uint64_t s) -> void {
        if (h.is_leaf(n)) return;
        out.push_back({i, s, h.position(h.midpoint(n, e))});
        const NodeId from_first = h.child(n, reversed ? red_split::kSecondHalfChild[e] : red_split::kFirstHalfChild[e]);
        const NodeId to_second = h.child(n, reversed ? red_split::kFirstHalfChild[e] : red_split::kSecondHalfChild[e]);
        self(self, i, from_first, e, reversed, 2 * s);
        self(self, i, to_second, e, reversed, 2 * s + 1);
    };
    const std::vector<std::pair<uint32_t, int>> edges = seam_edges(base, layout.chunk_of_root);
    for (uint32_t i = 0; i < edges.size(); ++i) {
        const uint32_t t = edges[i].first;
        const int e = edges[i].second;
        if (t >= first && t - first < count) {
            walk(walk, i, t - first, e, false, 1);
            continue;
        }
        const auto it = own_edge.find(directed(base.triangles[t][(e + 1) % 3], base.triangles[t][e]));
        if (it != own_edge.end()) walk(walk, i, it->second.first, it->second.second, true, 1);
    }
    return out;
}

Seam rank_seam(const TriangleMesh& base, const RankLayout& layout, std::vector<SeamSplit> splits, const Quantizer* grid) {
    if (grid == nullptr) return Seam::from_splits(base, layout.chunk_of_root, std::move(splits));
    Seam::from_splits(base, layout.chunk_of_root, splits);  // the two sides agree before snapping
    snap_to_grid(splits, *grid);
    return Seam::from_splits(snapped_base(base, *grid), layout.chunk_of_root, std::move(splits));
}

RankCode encode_rank_chunk(const RankChunk& part, const Seam& seam, const EncodeOptions& options, const Quantizer* grid,
                           const std::string& what) {
    const Hierarchy& h = part.chunk;
    const uint32_t base_vertices = seam.base_vertex_count();
    // Seam keys (seam.h), level by level as the decoder assigns them.
    VertexKeys keys(h.positions().size(), kNoVertex);
    for (size_t v = 0; v < part.base_vertex.size(); ++v) keys[v] = part.base_vertex[v];
    auto seam_vertex = [&](NodeId n, int e) {
        if (!h.is_boundary_edge(n, e)) return Seam::kNotSeam;
        const uint32_t a = keys[h.vertex(n, e)], b = keys[h.vertex(n, (e + 1) % 3)];
        return a == kNoVertex || b == kNoVertex ? Seam::kNotSeam : seam.find(a, b);
    };
    for (NodeId n : h.breadth_first_order()) {
        const std::string where = what + ": a node of level " + std::to_string(h.level(n));
        if (!h.is_leaf(n)) {
            for (int e = 0; e < 3; ++e) {
                const int32_t s = seam_vertex(n, e);
                AMC_REQUIRE(s != Seam::kUnsplit, invalid_input, where + " is refined, the seam says its edge is not split");
                if (s >= 0) keys[h.midpoint(n, e)] = base_vertices + uint32_t(s);
            }
            continue;
        }
        // A leaf: what the other side hangs on its seam edges (FORMAT.md 3.15, putting chunks together).
        int hanging = h.hanging_node_count(n);
        for (int e = 0; e < 3; ++e) {
            const int32_t s = seam_vertex(n, e);
            if (s < 0) continue;
            ++hanging;
            const uint32_t a = keys[h.vertex(n, e)], b = keys[h.vertex(n, (e + 1) % 3)], m = base_vertices + uint32_t(s);
            AMC_REQUIRE(seam.find(a, m) == Seam::kUnsplit && seam.find(m, b) == Seam::kUnsplit, invalid_input,
                        where + " lies next to a region of another rank refined two levels finer (not balanced across the seam)");
        }
        AMC_REQUIRE(hanging < 3, invalid_input, where + " has three hanging nodes with those of its neighbours across the seam");
    }
    ChunkCode code = encode_chunk(h, keys, seam, options.hierarchy, options.predictor, space_of(h.base(), grid), options.grid_contexts, options.unit_normals, options.effort);
    RankCode out;
    out.block = framed(BlockType::chunk, code.bytes);
    out.summary.roots = h.root_count();
    out.summary.nodes = h.node_count();
    for (uint32_t key : keys) out.summary.own_vertices += key == kNoVertex;
    out.summary.faces = code.faces;
    out.summary.block_bytes = out.block.size();
    out.summary.levels = uint32_t(h.depth() + 1);
    out.summary.static_geometry = code.static_geometry;
    out.summary.grid_geometry = code.grid_geometry;
    out.summary.unit_geometry = code.unit_geometry;
    out.summary.raw_side = code.raw_side;
    out.summary.stencil_tables = code.stencil_tables;
    return out;
}

std::vector<uint8_t> chunked_file_head(const TriangleMesh& base, const Seam& seam, const std::vector<ChunkSummary>& chunks,
                                       const EncodeOptions& options, const Quantizer* grid) {
    EncodeOptions base_options = options;
    base_options.keep_base_order = true;
    const BaseMeshCode base_code = base_code_of(Hierarchy(base), grid, base_options);
    const Hierarchy roots(grid != nullptr ? snapped_base(base, *grid) : base);  // as encode() codes the base's positions
    const CoordinateSpace space = space_of(base, grid);
    Metadata meta;
    meta.base_vertices = base.positions.size();
    meta.base_triangles = base.triangles.size();
    meta.vertices = meta.base_vertices + seam.vertex_count();
    for (const ChunkSummary& c : chunks) {
        meta.nodes += c.nodes;
        meta.vertices += c.own_vertices;
        meta.faces += c.faces;
        meta.levels = std::max<uint64_t>(meta.levels, c.levels);
    }
    meta.options = kOptionChunked;
    if (grid != nullptr) meta.quantizer = *grid;
    // Bit-exact: the base's and the seam's raw bits apart when either has some (version 21), as
    // encode() writes them.
    const bool exact = grid == nullptr;
    PositionCoder positions(space);
    const RawSideCode base_geometry = encode_base_geometry(roots, base_code, false, positions, exact);
    const RawSideCode seam_code = seam.encode(space, exact);
    const bool windowed_base = base_code.mode == BaseConnectivityMode::angle_windowed;  // version 22: side streams
    const bool base_side = exact && (!base_geometry.raw.empty() || !seam_code.raw.empty() || windowed_base);
    const std::vector<uint8_t> seam_bytes = base_side ? seam_code.joined() : seam_code.arithmetic;
    std::vector<uint8_t> table;
    put_varint(table, chunks.size());
    uint64_t offset = kBlockOverhead + seam_bytes.size();
    for (const ChunkSummary& c : chunks) {
        put_varint(table, c.roots);
        put_varint(table, c.nodes);
        put_varint(table, c.own_vertices);
        put_varint(table, offset);
        offset += c.block_bytes;
    }
    bool raw_side = false, stencil_tables = false, grid_geometry = false;
    for (const ChunkSummary& c : chunks) {
        raw_side |= c.raw_side != 0;
        stencil_tables |= c.stencil_tables != 0;
        grid_geometry |= c.grid_geometry != 0;  // chunks code mode 4 in the grouped order
    }
    BlockWriter writer(newest_features_version(grid_geometry, stencil_tables, raw_side, true, base_side, windowed_base), grid != nullptr ? kFlagQuantized : base.single_precision ? kFlagSinglePrecision : 0);
    writer.add(BlockType::metadata, write_metadata(meta, grid != nullptr));
    writer.add(BlockType::base_connectivity, base_code.bytes);
    writer.add(BlockType::base_geometry, base_side ? base_geometry.joined() : base_geometry.arithmetic);
    writer.add(BlockType::chunk_table, table);
    writer.add(BlockType::seam, seam_bytes);
    std::vector<uint8_t> out = writer.finish();
    out.resize(out.size() - kBlockOverhead);  // END comes after the chunks
    return out;
}

std::vector<uint8_t> end_block() {
    std::vector<uint8_t> file = BlockWriter(kChunkedVersion, 0).finish();
    return std::vector<uint8_t>(file.end() - std::ptrdiff_t(kBlockOverhead), file.end());
}

}  // namespace amc
