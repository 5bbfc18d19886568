// A chunk block: the levels of one chunk, then the seam diagonals (chunk_coder.h).
#include "coding/chunks/chunk_coder.h"

#include "coding/container.h"
#include "coding/geometry/level_geometry.h"
#include "coding/geometry/position_coder.h"
#include "coding/hierarchy/hierarchy_level_coder.h"
#include "common/check.h"

#include <cmath>
#include <memory>

namespace amc {

namespace {

bool has_boundary_edge(const Hierarchy& h, NodeId n) {
    return h.is_boundary_edge(n, 0) || h.is_boundary_edge(n, 1) || h.is_boundary_edge(n, 2);
}

// The seam vertex splitting edge e of n, or Seam::kNotSeam / kUnsplit. Only boundary edges of a
// chunk can lie on the seam; their ends are base or seam vertices, which have keys.
template <class Keys>
int32_t seam_vertex(const Hierarchy& h, const Keys& keys, const Seam& seam, NodeId n, int e) {
    if (!h.is_boundary_edge(n, e)) return Seam::kNotSeam;
    const uint32_t a = keys[h.vertex(n, e)], b = keys[h.vertex(n, (e + 1) % 3)];
    if (a == kNoVertex || b == kNoVertex) return Seam::kNotSeam;
    return seam.find(a, b);
}

// The hanging nodes the seam adds to a leaf of a chunk: one on each of its edges that the seam
// splits (refined on the other side, since the leaf is not). Only boundary edges can lie on the
// seam; testing for them first spares most leaves the lookup of their neighbours.
template <class Keys>
int seam_hanging_count(const Hierarchy& h, const Keys& keys, const Seam& seam, NodeId leaf) {
    if (!has_boundary_edge(h, leaf)) return 0;
    int count = 0;
    for (int e = 0; e < 3; ++e) count += seam_vertex(h, keys, seam, leaf, e) >= 0;
    return count;
}

// Whether the chunk's own hierarchy stream leaves leaf n's diagonal to the chunk block: two
// hanging nodes in the whole hierarchy, fewer in the chunk's (`seam_hanging` of them the seam's).
bool is_seam_closure(const Hierarchy& h, NodeId n, int seam_hanging) {
    if (seam_hanging == 0) return false;
    const int own = h.hanging_node_count(n);
    return own < 2 && own + seam_hanging == 2;
}

// Calls f on the leaves among `level` (a level's nodes, decided) that are seam closures, in level
// order; returns the hanging nodes the seam adds to the level's leaves.
template <class F>
uint64_t for_each_seam_closure(const Hierarchy& h, const std::vector<NodeId>& level, const VertexKeys& keys, const Seam& seam,
                               F&& f) {
    uint64_t seam_hanging = 0;
    for (NodeId n : level) {
        if (!h.is_leaf(n)) continue;
        const int hanging = seam_hanging_count(h, keys, seam, n);
        seam_hanging += uint64_t(hanging);
        if (is_seam_closure(h, n, hanging)) f(n);
    }
    return seam_hanging;
}

}  // namespace

ChunkCode encode_chunk(const Hierarchy& h, const VertexKeys& keys, const Seam& seam, const HierarchyCoderOptions& options,
                       GeometryPredictor fixed_predictor, CoordinateSpace space, bool grid_contexts, bool unit_normals,
                       int effort, ChunkEncoderMemory* memory) {
    ChunkCode out;
    HierarchyLevelEncoder hierarchy(h, options, kHierarchyStreamVersion, nullptr, false, nullptr,
                                    memory != nullptr ? &memory->first_pass : nullptr);
    StaticEncoderBuffers* buffers = memory != nullptr ? &memory->statics : nullptr;
    const std::vector<uint8_t>& header = hierarchy.header();
    put_varint(out.bytes, header.size());
    out.bytes.insert(out.bytes.end(), header.begin(), header.end());
    put_varint(out.bytes, uint64_t(hierarchy.level_count()));
    PositionCoder positions(space);
    BitModel flipped;  // the seam closures' diagonal flags
    uint64_t seam_hanging = 0;  // hanging nodes the seam adds to the chunk's leaves
    for (int l = 0; l < hierarchy.level_count(); ++l) {
        const std::vector<NodeId>& level = hierarchy.level_nodes(l);
        std::vector<std::pair<NodeId, int>> created;  // the chunk's own new vertices
        created.reserve(hierarchy.new_vertices(l).size());
        for (auto [n, e] : hierarchy.new_vertices(l))
            if (seam_vertex(h, keys, seam, n, e) < 0) created.emplace_back(n, e);
        ArithmeticEncoder encoder;
        hierarchy.encode_level(l, encoder);
        seam_hanging += for_each_seam_closure(h, level, keys, seam, [&](NodeId n) { encoder.encode(h.diagonal_flipped(n), flipped); });
        const size_t hierarchy_part = encoder.bytes_so_far();
        // The predictor, as the whole file's encoder picks it (FORMAT.md 3.9, 5.6).
        LevelGeometryCode geometry = choose_level_geometry(h, created, positions, space, fixed_predictor, grid_contexts, unit_normals,
                                                           effort, StaticOrder::grouped, buffers, &encoder);
        const std::vector<uint8_t> payload = finish_level_payload(h, created, geometry, positions, encoder);
        out.static_geometry |= geometry.predictor == GeometryPredictor::normal_frame;
        out.grid_geometry |= geometry.predictor == GeometryPredictor::normal_frame_grid;
        out.unit_geometry |= geometry.predictor == GeometryPredictor::unit_normal_frame;
        out.raw_side |= has_raw_side(payload);
        out.stencil_tables |= has_stencil_tables(geometry.predictor);
        const uint64_t hierarchy_bytes = std::min<uint64_t>(hierarchy_part, payload.size() - 1);
        out.hierarchy_bytes += hierarchy_bytes;
        out.geometry_bytes += payload.size() - 1 - hierarchy_bytes;
        LevelStats stats;
        stats.nodes = level.size();
        stats.new_vertices = created.size();
        stats.bytes = payload.size();
        stats.predictor = geometry.predictor;
        out.levels.push_back(stats);
        put_varint(out.bytes, payload.size());
        out.bytes.insert(out.bytes.end(), payload.begin(), payload.end());
    }
    out.faces = hierarchy.faces() + seam_hanging;
    return out;
}

std::unique_ptr<ChunkEncoderMemory> ChunkEncoderMemories::take() {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        if (!idle_.empty()) {
            std::unique_ptr<ChunkEncoderMemory> memory = std::move(idle_.back());
            idle_.pop_back();
            return memory;
        }
    }
    return std::make_unique<ChunkEncoderMemory>();
}

void ChunkEncoderMemories::give_back(std::unique_ptr<ChunkEncoderMemory> memory) {
    std::lock_guard<std::mutex> lock(mutex_);
    idle_.push_back(std::move(memory));
}

namespace {

// ChunkVertexKeys::key as an index, like the encoder's VertexKeys.
struct KeysOf {
    const ChunkVertexKeys& keys;
    uint32_t operator[](VertexId v) const { return keys.key(v); }
};

// The seam vertex that splits boundary segment (a, b) of a chunk being decoded (LevelSplits::boundary_vertex).
struct SeamSplits {
    const ChunkVertexKeys& keys;
    const Seam& seam;
    uint8_t* used;
    const std::string* where;
    bool found = false;  // some seam vertex was taken since it was last cleared
    static VertexId find(void* context, VertexId a, VertexId b) {
        SeamSplits& self = *static_cast<SeamSplits*>(context);
        const uint32_t ka = self.keys.key(a), kb = self.keys.key(b);
        if (ka == kNoVertex || kb == kNoVertex) return kNoVertex;
        const int32_t s = self.seam.find(ka, kb);
        AMC_REQUIRE(s != Seam::kUnsplit, corrupt, *self.where + ": refines a seam segment the seam block leaves unsplit");
        if (s == Seam::kNotSeam) return kNoVertex;
        self.used[s] = 1;
        self.found = true;
        return self.keys.seam_first + VertexId(s);
    }
};

}  // namespace

void decode_chunk(HierarchyLevelDecoder& hierarchy, const uint8_t* data, size_t size, const ChunkPlace& place,
                  const Seam& seam, CoordinateSpace space, const ChunkDecodeLimits& limits, const std::string& what,
                  ChunkCounts& counts) {
    PayloadReader in(data, size, "chunk block");
    const uint64_t header_size = in.varint();
    AMC_REQUIRE(header_size <= in.remaining(), corrupt, what + ": hierarchy header is longer than the block");
    const uint8_t* header = in.bytes(header_size);
    const uint64_t levels = in.varint();
    AMC_REQUIRE(levels >= 1 && levels <= kMaxLevel + 1, corrupt, what + ": bad level count");
    Hierarchy& h = *place.target;
    hierarchy.restart_in(h, place.first_root, place.roots, header, size_t(header_size), limits.stream_version,
                         limits.max_nodes);
    const KeysOf keys{place.keys};
    std::string where = what;
    SeamSplits seam_splits{place.keys, seam, place.seam_used, &where};
    hierarchy.set_boundary_vertices(&SeamSplits::find, &seam_splits);
    hierarchy.set_slice(place.slice);
    const VertexId seam_first = place.keys.seam_first, seam_count = place.keys.seam_count;
    PositionCoder positions(space);
    BitModel flipped;
    std::vector<std::pair<NodeId, int>> created;
    // The level's nodes with a boundary edge, in id order: only they can meet the seam, and
    // their children with a boundary edge are the next level's.
    std::vector<NodeId> boundary, next_boundary;
    for (NodeId r = place.first_root; r < place.first_root + place.roots; ++r)
        if (has_boundary_edge(h, r)) boundary.push_back(r);
    bool stopped = false;
    uint64_t seam_faces = 0;  // the seam's hanging nodes on the chunk's leaves
    for (uint64_t level = 0; level < levels; ++level) {
        AMC_REQUIRE(!hierarchy.done(), corrupt, what + ": more levels than its hierarchy has");
        stopped = limits.max_level >= 0 && int(level) >= limits.max_level;
        if (stopped) break;  // progressive: stop here
        where = what + ", level " + std::to_string(level);
        const uint64_t length = in.varint();
        AMC_REQUIRE(length >= 1 && length <= in.remaining(), corrupt, where + ": bad length");
        const Block level_block{BlockType::level, in.bytes(length), size_t(length), 0};
        // Chunked files are never in the mixing mode.
        const LevelBlockParts parts =
            split_level_block(level_block, limits.file_version, space.quantizer != nullptr, false, where);
        ArithmeticDecoder decoder(parts.arithmetic, parts.arithmetic_size);
        seam_splits.found = false;
        // Every new vertex gets its decoded position below; a static mode with a frame takes their
        // frame corners from the split, without reading the nodes again.
        const bool listed = has_frame(parts.predictor);
        hierarchy.set_new_vertex_listing(listed, false);
        // The decoder's last chunk writes the decode's last nodes and positions; over its last
        // three levels (the largest, in adaptive hierarchies) its working memory goes back as it
        // dies instead of staying under them (docs/BENCHMARKS.md, "Threads and memory").
        hierarchy.set_lean(place.last && level + 3 >= levels);
        hierarchy.decode_level(decoder);  // the seam vertices it splits off placed already (SeamSplits)
        next_boundary.clear();
        for (const NodeId n : boundary) {
            if (!h.is_leaf(n)) {
                for (int k = 0; k < 4; ++k)
                    if (has_boundary_edge(h, h.child(n, k))) next_boundary.push_back(h.child(n, k));
                continue;
            }
            const int seam_hanging = seam_hanging_count(h, keys, seam, n);
            seam_faces += uint64_t(seam_hanging);
            if (is_seam_closure(h, n, seam_hanging)) h.set_diagonal_flipped(n, decoder.decode(flipped));
        }
        boundary.swap(next_boundary);
        AMC_REQUIRE(!decoder.overran(), corrupt, where + ": hierarchy part is truncated or corrupt");
        if (listed) {  // the seam's vertices are not new: not listed
            decode_listed_level_geometry(h, hierarchy.new_vertex_corners(), parts, decoder, space, where);
            continue;
        }
        if (!seam_splits.found) {  // every new vertex is the chunk's own
            decode_level_geometry(h, hierarchy.new_vertices(), parts, decoder, positions, space, int(level), where);
            continue;
        }
        created.clear();
        for (auto [n, e] : hierarchy.new_vertices())
            if (h.midpoint(n, e) - seam_first >= seam_count) created.emplace_back(n, e);
        decode_level_geometry(h, created, parts, decoder, positions, space, int(level), where);
    }
    hierarchy.set_boundary_vertices(nullptr, nullptr);
    counts.faces = hierarchy.leaf_faces() + seam_faces;
    counts.depth = int(levels) - 1;  // the last level refines nothing (checked below)
    if (stopped) return;
    AMC_REQUIRE(hierarchy.done(), corrupt, what + ": ends before its hierarchy's last level");
    AMC_REQUIRE(in.remaining() == 0, corrupt, what + ": bytes after the last level");
    hierarchy.finish();
}

}  // namespace amc
