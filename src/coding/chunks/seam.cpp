// The seam block: segment trees on the base edges between chunks (seam.h, FORMAT.md 3.13).
#include "coding/chunks/seam.h"

#include "coding/entropy/arithmetic_coder.h"
#include "coding/geometry/position_coder.h"
#include "common/check.h"
#include "common/exact_float.h"
#include "mesh/vertex_buckets.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>

namespace amc {

namespace {

// Split bits: one model per level (levels beyond 15 share the last).
constexpr int kSplitContexts = 16;
using SplitModels = std::array<BitModel, kSplitContexts>;
BitModel& split_model(SplitModels& models, int level) { return models[size_t(std::min(level, kSplitContexts - 1))]; }

// FORMAT.md 5.5's midpoint of the segment's ends.
Vec3 midpoint_prediction(Vec3 a, Vec3 b, bool single_precision) {
    const Vec3 m = rounded_scaled(0.5, a + b);
    return single_precision ? rounded_to_float(m) : m;
}

}  // namespace

size_t Seam::SegmentTable::slot_of(uint64_t key) const {
    const size_t mask = slots_.size() - 1;
    size_t i = hash_(key) & mask;
    while (slots_[i].first != key && slots_[i].first != kEmpty) i = (i + 1) & mask;
    return i;
}

void Seam::SegmentTable::set(uint64_t key, int32_t value) {
    if (2 * (used_ + 1) > slots_.size()) {  // at most half full, so probes stay short
        std::vector<std::pair<uint64_t, int32_t>> old(std::max<size_t>(16, 2 * slots_.size()), {kEmpty, 0});
        old.swap(slots_);
        for (const auto& slot : old)
            if (slot.first != kEmpty) slots_[slot_of(slot.first)] = slot;
    }
    std::pair<uint64_t, int32_t>& slot = slots_[slot_of(key)];
    used_ += slot.first == kEmpty;
    slot = {key, value};
}

int32_t Seam::SegmentTable::find(uint64_t key) const {
    if (slots_.empty()) return kNotSeam;
    const std::pair<uint64_t, int32_t>& slot = slots_[slot_of(key)];
    return slot.first == key && key != kEmpty ? slot.second : kNotSeam;
}

std::vector<std::pair<uint32_t, int>> seam_edges(const TriangleMesh& base, const std::vector<uint32_t>& chunk_of_root) {
    // The directed edges grouped by their first vertex, each as (second vertex, triangle, edge), in
    // triangle order. The neighbour across (a, b) is the first triangle with (b, a): per vertex b,
    // its edges (b, to) noted by `to`, so that each edge (a, b) finds it at once (a search among
    // b's edges was quadratic in b's valence). A note left by a vertex before b lies outside b's.
    struct Leaving {
        uint32_t to, triangle, edge;
    };
    size_t vertex_end = 0;
    for (const auto& t : base.triangles)
        for (uint32_t v : t) vertex_end = std::max(vertex_end, size_t(v) + 1);
    std::vector<Leaving> leaving;
    const std::vector<size_t> start = bucket_by_vertex(
        vertex_end, 3 * base.triangles.size(), [&](size_t h) { return base.triangles[h / 3][h % 3]; },
        [&](size_t h) { return Leaving{base.triangles[h / 3][(h % 3 + 1) % 3], uint32_t(h / 3), uint32_t(h % 3)}; }, leaving);
    std::vector<uint32_t> across(3 * base.triangles.size(), UINT32_MAX);  // the neighbour across edge e of t: 3 t + e
    std::vector<size_t> leaving_to(vertex_end, SIZE_MAX);
    for (size_t b = 0; b < vertex_end; ++b) {
        const size_t first = start[b], count = start[b + 1] - first;
        for (size_t k = first + count; k-- > first;) leaving_to[leaving[k].to] = k;  // the first edge (b, to) noted last
        for (size_t k = first; k < first + count; ++k) {
            const uint32_t t = leaving[k].triangle, e = (leaving[k].edge + 2) % 3;  // (a, b)
            const size_t found = leaving_to[base.triangles[t][e]];
            if (found - first < count) across[3 * size_t(t) + e] = leaving[found].triangle;
        }
    }
    std::vector<std::pair<uint32_t, int>> edges;
    for (uint32_t t = 0; t < base.triangles.size(); ++t) {
        for (int e = 0; e < 3; ++e) {
            const uint32_t q = across[3 * size_t(t) + size_t(e)];
            if (q == UINT32_MAX || q <= t) continue;
            if (chunk_of_root[q] != chunk_of_root[t]) edges.emplace_back(t, e);
        }
    }
    return edges;
}

Seam::Seam(const Hierarchy& h, const std::vector<uint32_t>& chunk_of_root, std::vector<uint32_t>& key_of_vertex) {
    base_vertices_ = uint32_t(h.base().positions.size());
    single_precision_ = h.single_precision();
    key_of_vertex.assign(h.positions().size(), kNoVertex);
    for (uint32_t v = 0; v < base_vertices_; ++v) key_of_vertex[v] = v;
    // Walks the segment on edge e of n (first side) and edge eq of q (the other side, where the
    // edge runs the other way); either node may be missing where its side is coarser.
    auto walk = [&](auto& self, NodeId n, int e, NodeId q, int eq, int level) -> void {
        const VertexId a = n != kNoNode ? h.vertex(n, e) : h.vertex(q, (eq + 1) % 3);
        const VertexId b = n != kNoNode ? h.vertex(n, (e + 1) % 3) : h.vertex(q, eq);
        const bool n_split = n != kNoNode && !h.is_leaf(n), q_split = q != kNoNode && !h.is_leaf(q);
        Segment segment{n_split || q_split, uint8_t(level), h.position(a), h.position(b), 0};
        const uint64_t key = segment_key(key_of_vertex[a], key_of_vertex[b]);
        if (!segment.split) {
            segments_.set(key, kUnsplit);
            trace_.push_back(segment);
            return;
        }
        const VertexId m = n_split ? h.midpoint(n, e) : h.midpoint(q, eq);
        segment.vertex = uint32_t(positions_.size());
        segments_.set(key, int32_t(segment.vertex));
        key_of_vertex[m] = base_vertices_ + segment.vertex;
        positions_.push_back(h.position(m));
        trace_.push_back(segment);
        // The first half (a, m) is child kFirstHalfChild[e] of n and kSecondHalfChild[eq] of q.
        self(self, n_split ? h.child(n, red_split::kFirstHalfChild[e]) : kNoNode, e,
             q_split ? h.child(q, red_split::kSecondHalfChild[eq]) : kNoNode, eq, level + 1);
        self(self, n_split ? h.child(n, red_split::kSecondHalfChild[e]) : kNoNode, e,
             q_split ? h.child(q, red_split::kFirstHalfChild[eq]) : kNoNode, eq, level + 1);
    };
    for (auto [t, e] : seam_edges(h.base(), chunk_of_root)) {
        const NodeId q = h.neighbor(t, e);
        walk(walk, t, e, q, h.neighbor_edge(t, e), 0);
    }
}

Seam Seam::from_splits(const TriangleMesh& base, const std::vector<uint32_t>& chunk_of_root, std::vector<SeamSplit> splits) {
    Seam seam;
    seam.base_vertices_ = uint32_t(base.positions.size());
    seam.single_precision_ = base.single_precision;
    auto before = [](const SeamSplit& x, const SeamSplit& y) { return x.edge != y.edge ? x.edge < y.edge : x.segment < y.segment; };
    std::sort(splits.begin(), splits.end(), before);
    auto same_bits = [](double x, double y) { return std::memcmp(&x, &y, sizeof x) == 0; };
    for (size_t i = 1; i < splits.size(); ++i) {
        const SeamSplit& x = splits[i - 1];
        const SeamSplit& y = splits[i];
        AMC_REQUIRE(before(x, y) || (same_bits(x.position.x, y.position.x) && same_bits(x.position.y, y.position.y) &&
                                     same_bits(x.position.z, y.position.z)),
                    invalid_input,
                    "the two sides of seam edge " + std::to_string(x.edge) + " give the vertex of its segment " +
                        std::to_string(x.segment) + " different positions");
    }
    std::vector<Vec3> key_positions(base.positions);  // by key: base vertices, then seam vertices
    size_t next = 0;                                   // the first split of the current edge not yet consumed
    auto walk = [&](auto& self, uint32_t edge, uint64_t segment, uint32_t a, uint32_t b, int level) -> void {
        const SeamSplit probe{edge, segment, {}};
        const auto it = std::lower_bound(splits.begin() + std::ptrdiff_t(next), splits.end(), probe, before);
        const bool split = it != splits.end() && it->edge == edge && it->segment == segment;
        Segment s{split, uint8_t(level), key_positions[a], key_positions[b], 0};
        if (!split) {
            seam.segments_.set(segment_key(a, b), kUnsplit);
            seam.trace_.push_back(s);
            return;
        }
        AMC_REQUIRE(level < kMaxLevel, invalid_input, "a seam segment of level " + std::to_string(level) + " is split");
        s.vertex = uint32_t(seam.positions_.size());
        const uint32_t m = seam.base_vertices_ + s.vertex;
        seam.segments_.set(segment_key(a, b), int32_t(s.vertex));
        seam.positions_.push_back(it->position);
        key_positions.push_back(it->position);
        seam.trace_.push_back(s);
        self(self, edge, 2 * segment, a, m, level + 1);
        self(self, edge, 2 * segment + 1, m, b, level + 1);
    };
    const std::vector<std::pair<uint32_t, int>> edges = seam_edges(base, chunk_of_root);
    for (uint32_t i = 0; i < edges.size(); ++i) {
        while (next < splits.size() && splits[next].edge < i) ++next;
        const Triangle& t = base.triangles[edges[i].first];
        walk(walk, i, 1, t[edges[i].second], t[(edges[i].second + 1) % 3], 0);
    }
    return seam;
}

RawSideCode Seam::encode(CoordinateSpace space, bool raw_side) const {
    ArithmeticEncoder encoder;
    RawBitWriter raw;
    SplitModels models;
    PositionCoder positions(space);
    for (const Segment& s : trace_) {
        encoder.encode(s.split, split_model(models, s.level));
        if (s.split)
            positions.encode(encoder, level_context(s.level), positions_[s.vertex],
                             midpoint_prediction(s.a, s.b, single_precision_), raw_side ? &raw : nullptr);
    }
    return RawSideCode{encoder.finish(), raw.finish()};
}

Seam Seam::decode(const uint8_t* data, size_t size, const TriangleMesh& base, const std::vector<uint32_t>& chunk_of_root,
                  CoordinateSpace space, uint64_t max_vertices, bool raw_side) {
    const RawSideParts parts = raw_side ? split_raw_side(data, size, "seam block") : RawSideParts{data, size, nullptr, 0};
    Seam seam;
    seam.base_vertices_ = uint32_t(base.positions.size());
    seam.single_precision_ = base.single_precision;
    // Keys (base vertices, then seam vertices) stay below kNoVertex.
    const uint64_t limit = std::min<uint64_t>({max_vertices, max_decodable_positions(size),
                                               uint64_t(kNoVertex) - 1 - seam.base_vertices_});
    ArithmeticDecoder decoder(parts.arithmetic, parts.arithmetic_size);
    RawBitReader raw(parts.raw, parts.raw_size);
    SplitModels models;
    PositionCoder positions(space);
    std::vector<Vec3> key_positions(base.positions);  // by key: base vertices, then seam vertices
    auto walk = [&](auto& self, uint32_t a, uint32_t b, int level) -> void {
        AMC_REQUIRE(!decoder.overran(), corrupt, "seam block is truncated or corrupt");
        const uint64_t key = segment_key(a, b);
        if (!decoder.decode(split_model(models, level))) {
            seam.segments_.set(key, kUnsplit);
            return;
        }
        AMC_REQUIRE(level < kMaxLevel, corrupt, "seam block splits a segment of level " + std::to_string(level));
        AMC_REQUIRE(seam.positions_.size() < limit, corrupt,
                    "seam block holds more vertices than the file's counts or its " + std::to_string(size) + " bytes allow");
        const Vec3 p = positions.decode(decoder, level_context(level),
                                        midpoint_prediction(key_positions[a], key_positions[b], seam.single_precision_),
                                        raw_side ? &raw : nullptr);
        AMC_REQUIRE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z), corrupt,
                    "seam block is corrupt (non-finite coordinate)");
        const uint32_t m = seam.base_vertices_ + uint32_t(seam.positions_.size());
        seam.segments_.set(key, int32_t(seam.positions_.size()));
        seam.positions_.push_back(p);
        key_positions.push_back(p);
        self(self, a, m, level + 1);
        self(self, m, b, level + 1);
    };
    for (auto [t, e] : seam_edges(base, chunk_of_root)) walk(walk, base.triangles[t][e], base.triangles[t][(e + 1) % 3], 0);
    AMC_REQUIRE(!decoder.overran() && !positions.saw_invalid_symbol(), corrupt, "seam block is truncated or corrupt");
    AMC_REQUIRE(!raw_side || raw.ended_cleanly(), corrupt, "seam block: raw bits are truncated or left over");
    return seam;
}

}  // namespace amc
