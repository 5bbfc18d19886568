// Geometry modes 6 and 7 over float64 coordinates: the level decoder's fast path (docs/FORMAT.md 5.9).
// The same stencils, tokens and streams as decode_stencil_positions (static_position_decoder.cpp),
// with the fast paths' streams (static_position_internal.h), and the coordinates' finiteness and
// farness taken once a chunk from their largest exponent.
#include "coding/geometry/static_position_internal.h"

namespace amc::static_geometry {

namespace {

// Per byte of a node's neighbour edge indices (HierarchyBuilder::neighbor_edges) and edge f: the
// local index of the vertex opposite edge f in the neighbour across it (wing(), geometry_prediction.cpp).
struct OppositeIndices {
    uint8_t of[256][4];
    constexpr OppositeIndices() : of() {
        constexpr int kNext[5] = {1, 2, 0, 1, 2};
        for (int byte = 0; byte < 256; ++byte)
            for (int f = 0; f < 3; ++f) of[byte][f] = uint8_t(kNext[((byte >> (2 * f)) & 3) + 1]);
    }
};
constexpr OppositeIndices kOpposite;

// A stencil point's three coordinates, and the same IEEE operations in the same order as
// predict_butterfly's Vec3 arithmetic.
#if AMC_SSE2
// x and y in one SSE2 register, z in the low lane of another, each lane rounded alike.
struct Lanes {
    __m128d xy, z;
};
// The positions read as an array of doubles: GCC then forms the index 3v once and addresses both
// loads from it (from &positions[v], it makes the address twice).
static_assert(sizeof(Vec3) == 3 * sizeof(double), "a Vec3 is its three coordinates");
AMC_ALWAYS_INLINE Lanes point_at(const Vec3* positions, VertexId v) {
    const double* coordinates = &positions->x;
    const size_t k = size_t(v) * 3;
    return {_mm_loadu_pd(coordinates + k), _mm_load_sd(coordinates + k + 2)};
}
AMC_ALWAYS_INLINE Lanes operator+(Lanes u, Lanes v) { return {_mm_add_pd(u.xy, v.xy), _mm_add_pd(u.z, v.z)}; }
AMC_ALWAYS_INLINE Lanes operator-(Lanes u, Lanes v) { return {_mm_sub_pd(u.xy, v.xy), _mm_sub_pd(u.z, v.z)}; }
// s * v, each product rounded (no fused multiply-add with the sum it feeds: exact_float.h).
AMC_ALWAYS_INLINE Lanes scaled(double s, Lanes v) {
    const __m128d k = _mm_set1_pd(s);
    return {rounded(_mm_mul_pd(k, v.xy)), rounded(_mm_mul_pd(k, v.z))};
}
// ordered_of of each lane, 0 taken for a non-finite one.
AMC_ALWAYS_INLINE __m128i ordered_lanes(__m128d v) {
    const __m128d magnitude = _mm_andnot_pd(_mm_set1_pd(-0.0), v);
    const __m128d finite = _mm_cmplt_pd(magnitude, _mm_set1_pd(HUGE_VAL));  // false for NaN
    const __m128i b = _mm_castpd_si128(_mm_and_pd(v, finite));
    // Each lane's sign spread over its 64 bits: its high word shifted arithmetically, then copied
    // to both words (0xF5: words 1, 1, 3, 3).
    const __m128i negative = _mm_shuffle_epi32(_mm_srai_epi32(b, 31), 0xF5);
    return _mm_xor_si128(b, _mm_or_si128(negative, _mm_set1_epi64x(int64_t(kSign64))));
}
AMC_ALWAYS_INLINE void store_ordered(Lanes v, uint64_t (&p)[3]) {
    _mm_storeu_si128(reinterpret_cast<__m128i*>(p), ordered_lanes(v.xy));
    _mm_storel_epi64(reinterpret_cast<__m128i*>(p + 2), ordered_lanes(v.z));
}
#else
using Lanes = Vec3;
AMC_ALWAYS_INLINE Vec3 point_at(const Vec3* positions, VertexId v) { return positions[v]; }
AMC_ALWAYS_INLINE Vec3 scaled(double s, Vec3 v) { return rounded_scaled(s, v); }
AMC_ALWAYS_INLINE void store_ordered(Vec3 v, uint64_t (&p)[3]) {
    const double xyz[3] = {v.x, v.y, v.z};
    for (int k = 0; k < 3; ++k) p[k] = ordered_of(bit_cast<uint64_t>(std::isfinite(xyz[k]) ? xyz[k] : 0.0));
}
#endif

// The ordered bits of predict_butterfly's (or predict_midpoint's) prediction for edge e of node n,
// its non-finite coordinates taken as 0 (coder_prediction), for a float64 hierarchy. Each stencil
// vertex is read from the nodes as it is needed; a wing whose neighbour is missing is its
// reflection (predict_butterfly's), the midpoint predicts where n has no neighbour across e.
template <bool Butterfly>
AMC_ALWAYS_INLINE void stencil_prediction(const Hierarchy& h, const Vec3* positions, NodeId n, int e, uint64_t (&p)[3]) {
    static constexpr int kNext[5] = {1, 2, 0, 1, 2};
    const int e1 = kNext[e], e2 = kNext[e + 1];
    const VertexId a = h.vertex(n, e), b = h.vertex(n, e1);
    Lanes predicted = scaled(0.5, point_at(positions, a) + point_at(positions, b));
    const NodeId q = Butterfly ? h.neighbor(n, e) : kNoNode;
    if (q != kNoNode) {
        const uint8_t* const n_opposite = kOpposite.of[HierarchyBuilder::neighbor_edges(h, n)];
        const uint8_t* const q_opposite = kOpposite.of[HierarchyBuilder::neighbor_edges(h, q)];
        const int eq = h.neighbor_edge(n, e);
        const VertexId c = h.vertex(n, e2), d = h.vertex(q, n_opposite[e]);
        const Lanes cd = point_at(positions, c) + point_at(positions, d);
        // The vertex opposite edge f of node m in the neighbour across it, else x + y - z (read
        // again there: few registers stay live over the wings).
        auto wing = [&](NodeId m, int f, const uint8_t* opposite, VertexId x, VertexId y, VertexId z) {
            const NodeId r = h.neighbor(m, f);
            if (r != kNoNode) return point_at(positions, h.vertex(r, opposite[f]));
            return point_at(positions, x) + point_at(positions, y) - point_at(positions, z);
        };
        const Lanes wings_n = wing(n, e1, n_opposite, b, c, a) + wing(n, e2, n_opposite, c, a, b);
        const Lanes wings_q = wing(q, kNext[eq], q_opposite, a, d, b) + wing(q, kNext[eq + 1], q_opposite, d, b, a);
        predicted = predicted + scaled(0.125, cd) - scaled(0.0625, wings_n + wings_q);
    }
    store_ordered(predicted, p);
}

// Adds the residuals of `count` vertices to their predictions' ordered bits, token j of the level
// with state j mod 2: x and z with the vertex's parity, y with the other.
AMC_ALWAYS_INLINE void add_residuals(StencilStreams& streams, const std::array<StencilTable, 3>& t, uint64_t (*predicted)[3],
                                     size_t count) {
    StencilStreams s = streams;  // a local copy: its fields stay in registers
    size_t i = 0;
    for (; i + 1 < count; i += 2) {
        predicted[i][0] += s.residual<0>(t[0]);
        predicted[i][1] += s.residual<1>(t[1]);
        predicted[i][2] += s.residual<0>(t[2]);
        predicted[i + 1][0] += s.residual<1>(t[0]);
        predicted[i + 1][1] += s.residual<0>(t[1]);
        predicted[i + 1][2] += s.residual<1>(t[2]);
    }
    if (i < count) {
        predicted[i][0] += s.residual<0>(t[0]);
        predicted[i][1] += s.residual<1>(t[1]);
        predicted[i][2] += s.residual<0>(t[2]);
    }
    streams = s;
}

}  // namespace

template <bool Butterfly>
bool decode_stencil_float64(Hierarchy& h, const std::vector<std::pair<NodeId, int>>& created, const StaticTables& tables,
                            const uint8_t* rans_data, size_t rans_size, const uint8_t* raw_data, size_t raw_size) {
    std::array<StencilTable, 3> t;
    for (size_t k = 0; k < 3; ++k) make_stencil_table(tables[k], t[k]);
    StencilStreams streams;
    if (!open_stencil_streams(rans_data, rans_size, raw_data, raw_size, streams)) return false;
    // What a chunk reads at most: two rANS bytes and the sign and 64 bits per coordinate.
    constexpr size_t kChunkRans = 2 * 3 * kChunk, kChunkRaw = 3 * kChunk * 65 / 8 + 8;
    PaddedTails<kChunkRans, kChunkRaw> tails;
    uint64_t predicted[kChunk][3];
    std::array<VertexId, kChunk> vertices;
    // split_level numbers a level's new vertices in the order `created` lists them (the listed
    // frame modes read them so too), seam vertices aside: a chunk whose first and last vertex
    // are where that puts them has all of its vertices there.
    auto midpoint = [&h, &created](size_t i) { return h.midpoint(created[i].first, created[i].second); };
    const VertexId first = created.empty() ? 0 : midpoint(0);
    for (size_t begin = 0; begin < created.size(); begin += kChunk) {
        const size_t count = std::min(kChunk, created.size() - begin);
        const bool consecutive = midpoint(begin) == first + begin && midpoint(begin + count - 1) == first + begin + count - 1;
        const Vec3* positions = h.positions().data();
        for (size_t i = 0; i < count; ++i) {
            const auto [n, e] = created[begin + i];
            stencil_prediction<Butterfly>(h, positions, n, e, predicted[i]);
            if (!consecutive) vertices[i] = h.midpoint(n, e);
        }
#if AMC_SSE2
        __m128d near_xy = _mm_castsi128_pd(_mm_set1_epi32(-1)), near_z = near_xy;
        const __m128d half_max = _mm_set1_pd(kHalfMax);
#else
        uint64_t largest_magnitude = 0;
#endif
        tails.pad(streams);
        add_residuals(streams, t, predicted, count);
        if (tails.overran(streams)) return false;
        // from_ordered_bits of each sum, and whether every coordinate of the chunk is at most
        // DBL_MAX / 2 in magnitude (not Hierarchy::is_far, and finite), in the bits of each lane.
        auto vertex = [&](size_t i) { return consecutive ? VertexId(first + begin + i) : vertices[i]; };
#if AMC_SSE2
        // Two vertices at a time: their z in one register.
        const __m128d sign = _mm_set1_pd(-0.0);
        auto near_lanes = [&](__m128d v) { return _mm_cmple_pd(_mm_andnot_pd(sign, v), half_max); };
        auto xy_at = [&](size_t i) { return double_lanes_of(_mm_loadu_si128(reinterpret_cast<const __m128i*>(predicted[i]))); };
        auto put = [&](size_t i, __m128d xy, double z) {
            Vec3 p;
            _mm_storeu_pd(&p.x, xy);
            p.z = z;
            HierarchyBuilder::set_near_vertex_position(h, vertex(i), p);
        };
        size_t i = 0;
        for (; i + 1 < count; i += 2) {
            const __m128d xy0 = xy_at(i), xy1 = xy_at(i + 1);
            const __m128d z = double_lanes_of(_mm_set_epi64x(int64_t(predicted[i + 1][2]), int64_t(predicted[i][2])));
            near_xy = _mm_and_pd(near_xy, _mm_and_pd(near_lanes(xy0), near_lanes(xy1)));
            near_z = _mm_and_pd(near_z, near_lanes(z));
            put(i, xy0, _mm_cvtsd_f64(z));
            put(i + 1, xy1, _mm_cvtsd_f64(_mm_unpackhi_pd(z, z)));
        }
        if (i < count) {
            const __m128d xy = xy_at(i), z = double_lanes_of(_mm_set1_epi64x(int64_t(predicted[i][2])));
            near_xy = _mm_and_pd(near_xy, near_lanes(xy));
            near_z = _mm_and_pd(near_z, near_lanes(z));
            put(i, xy, _mm_cvtsd_f64(z));
        }
        const bool near = _mm_movemask_pd(_mm_and_pd(near_xy, near_z)) == 3;
#else
        for (size_t i = 0; i < count; ++i) {
            Vec3 p;
            double* xyz[3] = {&p.x, &p.y, &p.z};
            for (int k = 0; k < 3; ++k) {
                const uint64_t b = double_bits_of(predicted[i][k]);
                largest_magnitude = std::max(largest_magnitude, b & ~kSign64);
                *xyz[k] = bit_cast<double>(b);
            }
            HierarchyBuilder::set_near_vertex_position(h, vertex(i), p);
        }
        const bool near = largest_magnitude <= bit_cast<uint64_t>(kHalfMax);
#endif
        if (!near) {  // rare: which coordinates, then
            for (size_t i = 0; i < count; ++i) {
                const Vec3 p = h.position(vertex(i));
                if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) return false;
                HierarchyBuilder::set_new_vertex_position(h, vertex(i), p);  // Hierarchy::is_far's flag
            }
        }
    }
    return streams.ended_cleanly();
}

template bool decode_stencil_float64<false>(Hierarchy&, const std::vector<std::pair<NodeId, int>>&, const StaticTables&, const uint8_t*,
                                            size_t, const uint8_t*, size_t);
template bool decode_stencil_float64<true>(Hierarchy&, const std::vector<std::pair<NodeId, int>>&, const StaticTables&, const uint8_t*,
                                           size_t, const uint8_t*, size_t);

}  // namespace amc::static_geometry
