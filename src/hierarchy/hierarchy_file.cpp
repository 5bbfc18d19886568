// The uncompressed hierarchy file (.amh), specified in docs/HIERARCHY.md: base mesh, refinement
// bits in breadth-first order, diagonal overrides and the positions of refinement vertices.
#include "hierarchy/writer_checks.h"

#include <amc/hierarchy.h>

#include "common/check.h"
#include "common/file_io.h"
#include "common/little_endian.h"
#include "coding/hierarchy/level_forest.h"
#include "hierarchy/hierarchy_builder.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace amc {

namespace {

constexpr char kMagic[4] = {'A', 'M', 'C', 'H'};
constexpr uint32_t kVersion = 1;
constexpr uint32_t kFlagSinglePrecision = 1;

unsigned char* put_coordinate(unsigned char* at, double x, bool single) {
    return single ? store_le32(at, bit_cast<uint32_t>(float(x))) : store_le64(at, bit_cast<uint64_t>(x));
}

unsigned char* put_point(unsigned char* at, const Vec3& p, bool single) {
    return put_coordinate(put_coordinate(put_coordinate(at, p.x, single), p.y, single), p.z, single);
}

class Reader {
public:
    Reader(const std::string& bytes, const std::string& what) : bytes_(bytes), what_(what) {}
    [[noreturn]] void fail(const std::string& message, ErrorCode code = ErrorCode::corrupt) const {
        throw_error(code, what_ + ": " + message);
    }
    uint32_t u32() {
        need(4);
        const uint32_t v = load_le32(at());
        pos_ += 4;
        return v;
    }
    // `count` points of three coordinates, the room for all of them checked once.
    void points(Vec3* out, size_t count, bool single) {
        const size_t size = single ? 4 : 8;
        if (count > remaining() / (3 * size)) fail("file is truncated", ErrorCode::truncated);
        const unsigned char* p = at();
        for (size_t i = 0; i < count; ++i, p += 3 * size) {
            out[i].x = coordinate(p, single);
            out[i].y = coordinate(p + size, single);
            out[i].z = coordinate(p + 2 * size, single);
        }
        pos_ += count * 3 * size;
    }
    const char* take(size_t n) {
        need(n);
        const char* p = bytes_.data() + pos_;
        pos_ += n;
        return p;
    }
    size_t remaining() const { return bytes_.size() - pos_; }

private:
    const unsigned char* at() const { return reinterpret_cast<const unsigned char*>(bytes_.data()) + pos_; }
    static double coordinate(const unsigned char* p, bool single) {
        return single ? double(bit_cast<float>(load_le32(p))) : bit_cast<double>(load_le64(p));
    }
    void need(size_t n) const {
        if (bytes_.size() - pos_ < n) fail("file is truncated", ErrorCode::truncated);
    }
    const std::string& bytes_;
    const std::string& what_;
    size_t pos_ = 0;
};

}  // namespace

std::string serialize_hierarchy(const Hierarchy& h) {
    check_before_writing(h, "hierarchy file", true);  // what deserialize_hierarchy checks
    const bool single = h.single_precision();
    const std::vector<NodeId> order = h.breadth_first_order();
    std::vector<uint32_t> flipped;
    for (uint32_t i = 0; i < order.size(); ++i) {
        NodeId n = order[i];
        if (h.is_leaf(n) && h.hanging_node_count(n) == 2 && h.diagonal_flipped(n)) flipped.push_back(i);
    }
    const uint32_t base_vertices = uint32_t(h.base().positions.size());
    const uint32_t new_vertices = h.vertex_count() - base_vertices;

    // The file is written in place: its size is known from the counts.
    const size_t point_size = 3 * (single ? 4 : 8);
    const size_t bit_bytes = (order.size() + 7) / 8;
    const size_t header_size = 4 + 7 * 4;
    std::string out(header_size + size_t(base_vertices) * point_size + size_t(h.root_count()) * 12 + bit_bytes +
                        flipped.size() * 4 + size_t(new_vertices) * point_size,
                    '\0');
    unsigned char* at = reinterpret_cast<unsigned char*>(&out[0]);
    std::memcpy(at, kMagic, 4);
    at += 4;
    for (uint32_t field : {kVersion, single ? kFlagSinglePrecision : 0, base_vertices, h.root_count(),
                           uint32_t(order.size()), uint32_t(flipped.size()), new_vertices})
        at = store_le32(at, field);
    for (const Vec3& p : h.base().positions) at = put_point(at, p, single);
    for (const Triangle& t : h.base().triangles) {
        for (uint32_t v : t) at = store_le32(at, v);
    }
    for (size_t i = 0; i < order.size(); ++i) {
        if (!h.is_leaf(order[i])) at[i / 8] = uint8_t(at[i / 8] | (1u << (i % 8)));
    }
    at += bit_bytes;
    for (uint32_t i : flipped) at = store_le32(at, i);
    // Refinement vertices in canonical order (base vertices are numbered first).
    const std::vector<uint32_t> canonical = canonical_vertex_order(h, order);
    for (size_t v = 0; v < canonical.size(); ++v) {
        if (canonical[v] != kNoVertex && canonical[v] >= base_vertices)
            put_point(at + size_t(canonical[v] - base_vertices) * point_size, h.position(VertexId(v)), single);
    }
    return out;
}

namespace {

// The parse's first check, which read_hierarchy also asks of a file's first bytes alone.
void check_hierarchy_magic(const std::string& bytes, const std::string& what) {
    Reader in(bytes, what);
    if (std::memcmp(in.take(4), kMagic, 4) != 0) in.fail("not a hierarchy file (bad magic)", ErrorCode::bad_magic);
}

Hierarchy parse_hierarchy(const std::string& bytes, const std::string& what) {
    check_hierarchy_magic(bytes, what);
    Reader in(bytes, what);
    in.take(4);
    const uint32_t version = in.u32();
    if (version != kVersion)
        in.fail("unsupported hierarchy file version " + std::to_string(version), ErrorCode::unsupported_version);
    const uint32_t flags = in.u32();
    if (flags & ~kFlagSinglePrecision) in.fail("unknown flags " + std::to_string(flags));
    const bool single = flags & kFlagSinglePrecision;
    const uint32_t base_vertices = in.u32();
    const uint32_t base_triangles = in.u32();
    const uint32_t node_count = in.u32();
    const uint32_t flip_count = in.u32();
    const uint32_t new_vertices = in.u32();

    // Every count is checked against the bytes that remain before anything is allocated.
    const uint64_t coordinate_size = single ? 4 : 8;
    const uint64_t expected = uint64_t(base_vertices) * 3 * coordinate_size + uint64_t(base_triangles) * 12 +
                              (uint64_t(node_count) + 7) / 8 + uint64_t(flip_count) * 4 +
                              uint64_t(new_vertices) * 3 * coordinate_size;
    if (expected != in.remaining())
        in.fail("file size does not match its header (" + std::to_string(in.remaining()) + " bytes after the header, " +
                std::to_string(expected) + " expected)",
            expected > in.remaining() ? ErrorCode::truncated : ErrorCode::corrupt);
    if (base_triangles == 0) in.fail("base mesh has no triangles");
    if (node_count < base_triangles) in.fail("fewer nodes than base triangles");

    TriangleMesh base;
    base.single_precision = single;
    base.positions.resize(base_vertices);
    in.points(base.positions.data(), base_vertices, single);
    base.triangles.resize(base_triangles);
    for (Triangle& t : base.triangles) {
        for (uint32_t& v : t) v = in.u32();
    }
    try {
        validate_triangle_mesh(base, what + " (base mesh)");
    } catch (const Error& e) {
        throw_error(ErrorCode::corrupt, e.what());  // a file whose base breaks the rules is corrupt
    }
    Hierarchy h(std::move(base));

    // Replay the refinement bits; every split must keep balance.
    const uint8_t* bits = reinterpret_cast<const uint8_t*>(in.take((uint64_t(node_count) + 7) / 8));
    // Each refined node adds four: with the counts consistent, the forest is built in room made
    // once for it (at most 8 nodes a byte of the file), not in vectors grown to twice its size.
    uint64_t refined = 0;
    for (uint32_t i = 0; i < node_count; ++i) refined += (bits[i / 8] >> (i % 8)) & 1;
    if (uint64_t(base_triangles) + 4 * refined != node_count)
        in.fail("header announces " + std::to_string(node_count) + " nodes but the refinement bits make " +
                std::to_string(uint64_t(base_triangles) + 4 * refined));
    h.reserve(node_count, uint64_t(base_vertices) + new_vertices);
    // Breadth-first order is level order, each level in canonical order: level by level, the
    // hierarchy coder's level forest (level_forest.h) links the children and a whole level splits
    // in one pass (HierarchyBuilder::split_level, as the decoder builds), with the node and vertex
    // ids split() gives node at a time: node ids in breadth-first order, vertex ids in canonical
    // order. Node at a time, the splits were half of a read.
    Level level, next;
    RefinedNumbering numbering;
    std::vector<uint32_t> closures;
    root_level(h, level, false);
    uint64_t first = 0;                    // the level's first node: its breadth-first index and id
    uint64_t three_hanging = UINT64_MAX;  // the first unrefined node with three hanging nodes
    for (int l = 0; !level.empty(); ++l) {
        const uint32_t n = uint32_t(level.size());
        const uint32_t in_file = uint32_t(std::min<uint64_t>(n, node_count - first));
        uint8_t* state = level.state();
        for (uint32_t i = 0; i < in_file; ++i) {
            const uint64_t k = first + i;
            const bool split = (bits[k / 8] >> (k % 8)) & 1;
            // Hierarchy::can_split: every neighbour there, below the level cap.
            if (split && (!(state[i] & kComplete) || l >= kMaxLevel))
                in.fail("node " + std::to_string(k) + " (level " + std::to_string(l) +
                        ") is refined next to a coarser element: the hierarchy is not balanced");
            state[i] = uint8_t(state[i] | kDecided | (split ? kRefined : 0));
        }
        if (in_file < n) in.fail("refinement bits end before the forest is complete");
        // Each node's refined neighbours (the closure check's hanging nodes).
        with_links(level, [&](auto links) {
            for (uint32_t i = 0; i < n; ++i) {
                if (!(state[i] & kRefined)) continue;
                const Neighbors q = links.neighbors(i);
                for (int e = 0; e < 3; ++e)
                    if (q.nbr[e] != kNoLocal) state[q.nbr[e]] = uint8_t(state[q.nbr[e]] + kRefinedNeighbor);
            }
        });
        closures.resize(n);
        const DecidedLevelScan scan = scan_decided_level(level, numbering, closures.data());
        for (uint32_t c = 0; c < scan.closures && three_hanging == UINT64_MAX; ++c)
            if (refined_neighbors(state[closures[c]]) == 3) three_hanging = first + closures[c];
        const uint64_t made = derive_next_level(level, numbering, next, false);
        uint32_t* parents = level.refined.data();
        for (uint32_t b = 0; b < level.refined_count; ++b) parents[b] += uint32_t(first);
        LevelSplits splits{parents, level.refined_count, next.nbr.data(), next.edges.data()};
        splits.place_new_vertices = false;  // the file's positions follow
        splits.new_vertex_count = made;
        HierarchyBuilder::split_level(h, splits);
        first += n;
        std::swap(level, next);
    }
    if (first != node_count)
        in.fail("header announces " + std::to_string(node_count) + " nodes but the forest has " + std::to_string(first));
    for (size_t i = node_count; i < (uint64_t(node_count) + 7) / 8 * 8; ++i) {
        if ((bits[i / 8] >> (i % 8)) & 1) in.fail("padding bits after the forest are not zero");
    }
    if (three_hanging != UINT64_MAX)
        in.fail("element " + std::to_string(three_hanging) + " has three hanging nodes but is not refined (closure)");
    int64_t previous = -1;
    for (uint32_t i = 0; i < flip_count; ++i) {
        const uint32_t index = in.u32();
        if (int64_t(index) <= previous || index >= node_count)
            in.fail("diagonal override " + std::to_string(i) + " is out of order or range");
        previous = index;
        const NodeId n = NodeId(index);  // node ids are breadth-first indices
        if (!h.is_leaf(n) || h.hanging_node_count(n) != 2)
            in.fail("diagonal override on node " + std::to_string(index) + ", which is not closed by two hanging nodes");
        h.set_diagonal_flipped(n, true);
    }
    if (h.vertex_count() - h.base().positions.size() != new_vertices)
        in.fail("header announces " + std::to_string(new_vertices) + " refinement vertices but the forest makes " +
                std::to_string(h.vertex_count() - h.base().positions.size()));
    // Refinement vertices in canonical order, which is their id order.
    std::vector<Vec3> refinement_positions(new_vertices);
    in.points(refinement_positions.data(), new_vertices, single);
    for (uint32_t i = 0; i < new_vertices; ++i) {
        const Vec3& p = refinement_positions[i];
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
            in.fail("refinement vertex " + std::to_string(i) + " has a non-finite coordinate");
        h.set_position(VertexId(base_vertices + i), p);
    }
    HierarchyBuilder::mark_structure_checked(h);  // replayed under can_split, closure checked above
    return h;
}

}  // namespace

Hierarchy deserialize_hierarchy(const std::string& bytes, const std::string& what) {
    return with_allocation_errors_as_limits(what.c_str(), [&] { return parse_hierarchy(bytes, what); });
}

void write_hierarchy(const std::string& path, const Hierarchy& h) {
    std::string bytes;
    try {
        bytes = serialize_hierarchy(h);
    } catch (const Error& e) {
        throw e.prefixed(path);
    }
    write_file_atomically(path, bytes);
}

Hierarchy read_hierarchy(const std::string& path) {
    return deserialize_hierarchy(read_whole_file(path, [&](const std::string& first) { check_hierarchy_magic(first, path); }),
                                 path);
}

}  // namespace amc
