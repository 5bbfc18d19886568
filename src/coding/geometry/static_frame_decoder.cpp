// Geometry modes 3, 4 and 5 over split_level's list: the level decoder's fast paths, with AVX2's
// frames where the processor has them (docs/FORMAT.md 5.6-5.8).

#include "coding/geometry/static_position_internal.h"

#include <atomic>

namespace amc::static_geometry {

namespace {

// ---- mode 4 over split_level's list: the level decoder's fast path --------------------------------
//
// decode_positions<true, true> for a listed level whose tables are narrow (every quantized level),
// decoded with the float64 decoder's streams (StencilStreams: rANS states in the loop's variables,
// raw bits by one load, bounds tests only near the streams' ends) and a table entry per token that
// holds a direct token's signed residual. Each frame stays in axis order, its roles' axes indexed
// per coordinate, instead of being copied into role order. The same tokens, operations and bits.

// A token of a quantized table: its rANS range, and its residual: `value` for a direct token
// (raw_count 0), else the magnitude's leading bits, the sign and the low bits following in the raw
// stream (raw_count of them; magnitudes are below 2^kMaxQuantizationBits).
struct GridEntry {
    int32_t value;
    uint16_t frequency, start;
    uint32_t raw_mask;
    uint32_t raw_count;
};
struct GridTable {
    const uint8_t* index;  // per slot, the entry (RansTable::narrow_view's)
    std::array<GridEntry, 256> entries;
};

// From a narrow table whose tokens fit a quantized space (read_static_tables' token_limit).
void make_grid_table(const RansTable& table, GridTable& out) {
    out.index = table.narrow_view().index;
    size_t i = 0;
    for (int token = 0; token < table.size(); ++token) {
        if (table.frequency(token) == 0) continue;
        GridEntry& e = out.entries[i++];
        e.frequency = uint16_t(table.frequency(token));
        e.start = uint16_t(table.start(token));
        if (token < kDirectTokens) {
            e.value = kDirectValues[token];
            e.raw_count = 0;
            e.raw_mask = 0;
        } else {  // take_large's, with low <= kMaxQuantizationBits - 3
            const int low = 4 + (token - kDirectTokens) / 4 - 3;
            e.value = int32_t(uint32_t(4 | ((token - kDirectTokens) & 3)) << low);
            e.raw_count = uint32_t(1 + low);
            e.raw_mask = (uint32_t{1} << (1 + low)) - 1;
        }
    }
}

// The next token of state State under `table`, as its signed residual.
template <int State>
AMC_ALWAYS_INLINE int64_t grid_token(StencilStreams& s, const GridTable& table) {
    uint32_t& x = s.x[State];
    const uint32_t slot = x & (kRansScale - 1);
    const GridEntry& e = table.entries[table.index[slot]];
    x = uint32_t(e.frequency) * (x >> kRansScaleBits) + slot - e.start;
    if (x < kRansLow) {  // at most two bytes (StencilStreams::residual)
        x = (x << 8) | s.rans_byte();
        if (x < kRansLow) x = (x << 8) | s.rans_byte();
    }
    if (e.raw_count == 0) return e.value;  // most quantized tokens: the branch predicts well
    const uint64_t r = s.raw_peek(s.raw_bits_read) & e.raw_mask;
    s.raw_bits_read += e.raw_count;
    return negated_if(int64_t(uint64_t(uint32_t(e.value)) | r >> 1), (r & 1) != 0);
}

AMC_ALWAYS_INLINE GridPoint grid_point_of(const GridPrediction& g) {
    return {g.p, uint64_t(g.bin) * sizeof(GridTable), -int64_t(g.turn)};
}

// The grid value of a prediction and the next token of state State under its table, among the
// role's tables from `role_tables`.
template <int State>
AMC_ALWAYS_INLINE int64_t grid_point_value(StencilStreams& s, const GridTable* role_tables, uint64_t point, uint64_t table_offset,
                                           int64_t turn_mask) {
    const GridTable& table = *reinterpret_cast<const GridTable*>(reinterpret_cast<const unsigned char*>(role_tables) + table_offset);
    const int64_t r = grid_token<State>(s, table);
    return int64_t(point) + ((r ^ turn_mask) - turn_mask);  // negated_if(r, turn)
}

// Two grid predictions side by side (SSE2's lanes): roles 1 and 2 of a vertex, or role 0 of two
// vertices.
struct GridPointPair {
    uint64_t point[2];
    uint64_t table_offset[2];
    int64_t turn_mask[2];
};

AMC_ALWAYS_INLINE GridPointPair grid_point_pair(const GridScale& grid, double origin0, double x0, double origin1, double x1) {
#if AMC_SSE2
    // grid_prediction_at in each lane, its fields made as masks.
    const __m128d zero = _mm_setzero_pd();
    const __m128d t = rounded(_mm_div_pd(_mm_sub_pd(_mm_set_pd(x1, x0), _mm_set_pd(origin1, origin0)), _mm_set1_pd(grid.step)));
    const __m128d high = _mm_cmpge_pd(t, _mm_set1_pd(grid.top));
    const __m128d inside = _mm_andnot_pd(high, _mm_cmpgt_pd(t, zero));  // not NaN either
    // Where inside, 0 < t + 0.5 < 2^31 (kMaxQuantizationBits): the truncation is uint32_t's floor.
    const __m128i p = _mm_cvttpd_epi32(rounded(_mm_add_pd(t, _mm_set1_pd(0.5))));
    const __m128d f = rounded(_mm_sub_pd(t, _mm_cvtepi32_pd(p)));
    const __m128d bin = _mm_and_pd(inside, _mm_cmpge_pd(_mm_andnot_pd(_mm_set1_pd(-0.0), f), _mm_set1_pd(0.25)));
    const __m128d turn = _mm_and_pd(inside, _mm_cmplt_pd(f, zero));
    const __m128i point = _mm_or_si128(_mm_and_si128(_mm_castpd_si128(inside), _mm_unpacklo_epi32(p, _mm_setzero_si128())),
                                       _mm_and_si128(_mm_castpd_si128(high), _mm_set1_epi64x(int64_t(grid.max))));
    GridPointPair out;
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out.point), point);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out.table_offset),
                     _mm_and_si128(_mm_castpd_si128(bin), _mm_set1_epi64x(int64_t(sizeof(GridTable)))));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out.turn_mask), _mm_castpd_si128(turn));
    return out;
#else
    const GridPoint g0 = grid_point_of(grid_prediction_at(grid, origin0, x0));
    const GridPoint g1 = grid_point_of(grid_prediction_at(grid, origin1, x1));
    return {{g0.point, g1.point}, {g0.table_offset, g1.table_offset}, {g0.turn_mask, g1.turn_mask}};
#endif
}

AMC_ALWAYS_INLINE void set_grid_frame(const NormalFrame& f, const GridScale& grid, const double* origin, GridFrame& g) {
    set_frame(f, g);
    g.first = grid_point_of(grid_prediction_at(grid, origin[g.axis], g.midpoint[g.axis]));
}

#if AMC_SSE2
// A vector of three coordinates per lane: lane 0 to lane0[0..2], lane 1 to lane1[0..2].
AMC_ALWAYS_INLINE void store_lanes(__m128d x, __m128d y, __m128d z, double* lane0, double* lane1) {
    _mm_storel_pd(lane0 + 0, x);
    _mm_storeh_pd(lane1 + 0, x);
    _mm_storel_pd(lane0 + 1, y);
    _mm_storeh_pd(lane1 + 1, y);
    _mm_storel_pd(lane0 + 2, z);
    _mm_storeh_pd(lane1 + 2, z);
}

// set_grid_frame for two vertices at once from frame_pair_lanes (each vertex in one lane):
// set_axis's choice by lane masks, the coordinates stored from the lanes, role 0's grid
// predictions in one pair. The same operations on the same values, so the same frames.
// set_frame for two vertices at once.
AMC_ALWAYS_INLINE void set_frame_pair(const FramePairLanes& l, GridFrame& g0, GridFrame& g1) {
    store_lanes(l.mx, l.my, l.mz, g0.midpoint, g1.midpoint);
    store_lanes(l.nx, l.ny, l.nz, g0.normal, g1.normal);
    // set_axis: the first axis of largest |N_i|, and whether it is positive and finite.
    const __m128d sign = _mm_set1_pd(-0.0);
    const __m128d x = _mm_andnot_pd(sign, l.nx), y = _mm_andnot_pd(sign, l.ny), z = _mm_andnot_pd(sign, l.nz);
    const __m128d y_wins = _mm_cmpgt_pd(y, x);
    const __m128d best = _mm_max_pd(y, x);  // maxpd: y where y > x, else x (NaN as set_axis)
    const __m128d z_wins = _mm_cmpgt_pd(z, best);
    const __m128d largest = _mm_max_pd(z, best);  // z where z > best, else best
    const int has = _mm_movemask_pd(_mm_and_pd(_mm_cmpgt_pd(largest, _mm_setzero_pd()), _mm_cmplt_pd(largest, _mm_set1_pd(HUGE_VAL))));
    const int ys = _mm_movemask_pd(y_wins), zs = _mm_movemask_pd(z_wins);
    g0.has_normal = (has & 1) != 0;
    g1.has_normal = (has & 2) != 0;
    g0.axis = has & 1 ? (zs & 1 ? 2 : ys & 1) : 0;
    g1.axis = has & 2 ? (zs & 2 ? 2 : (ys >> 1) & 1) : 0;
}

AMC_ALWAYS_INLINE void set_grid_frame_pair(const FramePairLanes& l, const GridScale& grid, const double* origin, GridFrame& g0,
                                           GridFrame& g1) {
    set_frame_pair(l, g0, g1);
    const GridPointPair first = grid_point_pair(grid, origin[g0.axis], g0.midpoint[g0.axis], origin[g1.axis], g1.midpoint[g1.axis]);
    g0.first = {first.point[0], first.table_offset[0], first.turn_mask[0]};
    g1.first = {first.point[1], first.table_offset[1], first.turn_mask[1]};
}
#endif

// A decoded vertex's coordinates, x, y, z, written as doubles (through a Vec3's object
// representation, a store by memcpy could alias anything: the compiler then reloaded every value
// it kept in memory after each); the chunk's are copied into Vec3s once made.
using Coordinates = double[3];
static_assert(sizeof(Vec3) == sizeof(Coordinates) && offsetof(Vec3, y) == sizeof(double) && offsetof(Vec3, z) == 2 * sizeof(double),
              "Vec3 is x, y, z");

// Role 0's grid value q0 of a frame whose roles 1 and 2 are the axes a1 and a2: its coordinate,
// written to `p`, and roles 1 and 2's grid predictions (predict_others' line along the normal).
AMC_ALWAYS_INLINE GridPointPair grid_first_role(const GridFrame& f, int64_t q0, const GridScale& grid, const double* origin,
                                                int a1, int a2, Coordinates& p) {
    const int a0 = f.axis;
    const double value = origin[a0] + rounded(static_cast<double>(q0) * grid.step);
    p[a0] = value;
    double second = f.midpoint[a1], third = f.midpoint[a2];
    if (f.has_normal) {
        const double u = rounded((value - f.midpoint[a0]) / f.normal[a0]);
        second = second + rounded(u * f.normal[a1]);
        third = third + rounded(u * f.normal[a2]);
    }
    return grid_point_pair(grid, origin[a1], second, origin[a2], third);
}

// Roles 1 and 2's coordinates (axes a1 and a2) from their grid values.
AMC_ALWAYS_INLINE void set_other_roles(int64_t q1, int64_t q2, const GridScale& grid, const double* origin, int a1, int a2,
                                       Coordinates& p) {
    p[a1] = origin[a1] + rounded(static_cast<double>(q1) * grid.step);
    p[a2] = origin[a2] + rounded(static_cast<double>(q2) * grid.step);
}

// decode_vertex<State, true> over a GridFrame: role r's axis is the frame's axis, then the two
// others in increasing order.
template <int State>
AMC_ALWAYS_INLINE bool decode_grid_vertex(StencilStreams& s, const GridTable* t, const GridFrame& f, const GridScale& grid,
                                          const double* origin, Coordinates& p) {
    const int64_t q0 = grid_point_value<State>(s, t, f.first.point, f.first.table_offset, f.first.turn_mask);
    if (uint64_t(q0) > grid.max) return false;  // also q0 < 0
    const int a1 = f.axis == 0 ? 1 : 0, a2 = f.axis == 2 ? 1 : 2;
    const GridPointPair g = grid_first_role(f, q0, grid, origin, a1, a2, p);
    const int64_t q1 = grid_point_value<1 - State>(s, t + kGridBins, g.point[0], g.table_offset[0], g.turn_mask[0]);
    if (uint64_t(q1) > grid.max) return false;
    const int64_t q2 = grid_point_value<State>(s, t + 2 * kGridBins, g.point[1], g.table_offset[1], g.turn_mask[1]);
    if (uint64_t(q2) > grid.max) return false;
    set_other_roles(q1, q2, grid, origin, a1, a2, p);
    return true;
}

// decode_grid_vertex's work in the grouped order (version 18, FORMAT.md 5.7) over a chunk of
// `count` vertices: their role-0 tokens (vertex i with state i mod 2), each followed by its
// vertex's predictions and bins for roles 1 and 2, which the next token does not wait for (the
// processor overlaps their divisions with the rANS chain), then each vertex's roles 1 and 2
// (states count mod 2 and the other). The chain from one token to the next is the rANS state's
// alone. (Roles 1 and 2's tokens read into an array and their values made in a pass of their own:
// 1.5 % fewer instructions, 1-9 % more time; the chain then runs with nothing beside it.)
AMC_ALWAYS_INLINE bool decode_grid_grouped(StencilStreams& s, const GridTable* t, const GridFrame* frames, size_t count,
                                           const GridScale& level_grid, const double* origin, Coordinates* decoded) {
    const GridScale grid = level_grid;  // a local copy: the stores to `decoded` could alias the caller's
    GridPointPair second[kChunk];
    uint64_t largest = 0;  // of the role-0 grid values as unsigned, where a negative one is above any
    // Role 0's token of vertex k with state `State`, then its value and roles 1 and 2's
    // predictions, which the next token does not wait for.
    auto first = [&](auto state, size_t k) {
        constexpr int State = decltype(state)::value;
        const GridFrame& f = frames[k];
        const int64_t q0 = grid_point_value<State>(s, t, f.first.point, f.first.table_offset, f.first.turn_mask);
        largest = std::max(largest, uint64_t(q0));
        second[k] = grid_first_role(f, q0, grid, origin, f.axis == 0 ? 1 : 0, f.axis == 2 ? 1 : 2, decoded[k]);
    };
    size_t k = 0;
    for (; k + 1 < count; k += 2) {
        first(std::integral_constant<int, 0>{}, k);
        first(std::integral_constant<int, 1>{}, k + 1);
    }
    if (k < count) first(std::integral_constant<int, 0>{}, k);
    if (largest > grid.max) return false;  // also a q0 < 0
    auto roles_1_2 = [&](auto odd) {
        constexpr int S = decltype(odd)::value ? 1 : 0;  // role 1's state: count mod 2
        for (size_t i = 0; i < count; ++i) {
            const GridPointPair& g = second[i];
            const int64_t q1 = grid_point_value<S>(s, t + kGridBins, g.point[0], g.table_offset[0], g.turn_mask[0]);
            const int64_t q2 = grid_point_value<1 - S>(s, t + 2 * kGridBins, g.point[1], g.table_offset[1], g.turn_mask[1]);
            if ((uint64_t(q1) > grid.max) | (uint64_t(q2) > grid.max)) return false;
            const int a0 = frames[i].axis;
            set_other_roles(q1, q2, grid, origin, a0 == 0 ? 1 : 0, a0 == 2 ? 1 : 2, decoded[i]);
        }
        return true;
    };
    return count % 2 == 0 ? roles_1_2(std::false_type{}) : roles_1_2(std::true_type{});
}

// The frames of `count` listed vertices, two at a time with SSE2.
struct PairFrames {
    AMC_ALWAYS_INLINE void operator()(const Hierarchy& h, const FrameCorners* corners, size_t count, const GridScale& grid,
                                      const double* origin, GridFrame* frames) const {
        size_t i = 0;
#if AMC_SSE2
        for (; i + 1 < count; i += 2)
            set_grid_frame_pair(frame_pair_lanes<true>(h, corners[i], corners[i + 1]), grid, origin, frames[i], frames[i + 1]);
#endif
        for (; i < count; ++i) set_grid_frame(frame_of<true>(h, corners[i]), grid, origin, frames[i]);
    }
    AMC_ALWAYS_INLINE bool grouped(StencilStreams& s, const GridTable* t, const GridFrame* frames, size_t count,
                                   const GridScale& grid, const double* origin, Coordinates* decoded) const {
        return decode_grid_grouped(s, t, frames, count, grid, origin, decoded);
    }
};

// The positions a listed chunk's frames read, fetched before its frames are made.
AMC_ALWAYS_INLINE void prefetch_corner_positions(const Hierarchy& h, const FrameCorners* corners, size_t count) {
    const Vec3* positions = h.positions().data();
    for (size_t i = 0; i < count; ++i) {  // a, b and c are always vertices
        const FrameCorners& k = corners[i];
        __builtin_prefetch(positions + k.a);
        __builtin_prefetch(positions + k.b);
        __builtin_prefetch(positions + k.c);
        if (k.d != kNoVertex) __builtin_prefetch(positions + k.d);
    }
}

// A listed fast path's decoded chunk (the vertices from created.first() + begin on) into the
// hierarchy: appended when the level's positions do not exist yet, else set one by one.
AMC_ALWAYS_INLINE void store_listed_chunk(Hierarchy& h, const FromList& created, size_t begin, const Vec3* decoded, size_t count,
                                          bool append, bool near) {
    if (append) {
        HierarchyBuilder::append_positions(h, decoded, count, near);
        return;
    }
    for (size_t k = 0; k < count; ++k) {
        const VertexId v = created.first() + VertexId(begin + k);
        if (near) HierarchyBuilder::set_near_vertex_position(h, v, decoded[k]);
        else HierarchyBuilder::set_new_vertex_position(h, v, decoded[k]);
    }
}

// The fast path's condition: a double-precision hierarchy (every quantized one) and narrow tables.
// Grouped: the tokens in the grouped order (version 18), else vertex after vertex (one loop each,
// so that either compiles as if alone). The frames, and the grouped order's tokens, by
// `make_frames` (PairFrames or QuadFrames).
template <bool Grouped, class MakeFrames>
AMC_ALWAYS_INLINE bool decode_grid_listed_with(Hierarchy& h, const FromList& created, const Quantizer& quantizer,
                                               const StaticTables& tables, const uint8_t* rans_data, size_t rans_size,
                                               const uint8_t* raw_data, size_t raw_size, MakeFrames& make_frames) {
    std::array<GridTable, kMaxStaticTables> t;
    for (size_t k = 0; k < t.size(); ++k) make_grid_table(tables[k], t[k]);
    StencilStreams s;
    if (!open_stencil_streams(rans_data, rans_size, raw_data, raw_size, s)) return false;
    const GridScale grid = grid_scale(&quantizer);
    const double origin[3] = {quantizer.origin.x, quantizer.origin.y, quantizer.origin.z};
    // decode_positions': every grid value lies between the box's corners.
    const bool near = !HierarchyBuilder::is_far(quantizer.origin) &&
                      !HierarchyBuilder::is_far(dequantize(quantizer, {quantizer.max_coordinate(), quantizer.max_coordinate(),
                                                                       quantizer.max_coordinate()}));
    const bool append = created.appends(h);
    // What a chunk reads at most: two rANS bytes and the sign and low bits per coordinate, and the
    // 8 bytes of the last raw load.
    constexpr size_t kChunkRans = 2 * 3 * kChunk, kChunkRaw = 3 * kChunk * (kMaxQuantizationBits - 2) / 8 + 16;
    std::array<GridFrame, kChunk> frames;
    Coordinates coordinates[kChunk];
    Vec3 decoded[kChunk];
    PaddedTails<kChunkRans, kChunkRaw> tails;
    for (size_t begin = 0; begin < created.size(); begin += kChunk) {
        const size_t count = std::min(kChunk, created.size() - begin);
        const FrameCorners* corners = created.corners.next(count);
        prefetch_corner_positions(h, corners, count);
        make_frames(h, corners, count, grid, origin, frames.data());
        tails.pad(s);
        StencilStreams local = s;  // the chunk's copy, which the compiler keeps in registers
        bool ok = true;
        if (Grouped) {
            ok = make_frames.grouped(local, t.data(), frames.data(), count, grid, origin, coordinates);
        } else {
            for (size_t k = 0; k < count && ok; k += 2) {  // token j of the level with state j mod 2
                ok = decode_grid_vertex<0>(local, t.data(), frames[k], grid, origin, coordinates[k]) &&
                     (k + 1 == count || decode_grid_vertex<1>(local, t.data(), frames[k + 1], grid, origin, coordinates[k + 1]));
            }
        }
        s = local;
        if (!ok || tails.overran(s)) return false;
        std::memcpy(decoded, coordinates, count * sizeof(Vec3));
        store_listed_chunk(h, created, begin, decoded, count, append, near);
    }
    return s.ended_cleanly();
}

template <bool Grouped>
bool decode_grid_listed(Hierarchy& h, const FromList& created, const Quantizer& quantizer, const StaticTables& tables,
                        const uint8_t* rans_data, size_t rans_size, const uint8_t* raw_data, size_t raw_size) {
    PairFrames pairs;
    return decode_grid_listed_with<Grouped>(h, created, quantizer, tables, rans_data, rans_size, raw_data, raw_size, pairs);
}

// ---- mode 5 over split_level's list: the level decoder's fast path for bit-exact files ------------
//
// decode_positions<false, true> for a listed level with narrow tables (every bit-exact surface
// level), float64 coordinates in a double-precision hierarchy or float32 in a single-precision one:
// the float64 stencil decoder's streams and table entries (a token's residual modulo 2^64 from one
// entry and one raw load, StencilStreams::residual) and mode 4's frames in axis order (GridFrame
// without its grid prediction, two or four at a time), instead of RoleFrame copies, RansDecoder
// and take(). The same tokens, operations and bits.

// value_of's bit-exact path: the coordinate whose ordered bits are the prediction's
// (coder_prediction's) plus the residual, as the IEEE bits of a double.
template <bool Float32>
AMC_ALWAYS_INLINE uint64_t unit_value_bits(double predicted, uint64_t residual) {
    if (Float32) {
        const uint64_t p = ordered_bits(coder_prediction(predicted, Precision::float32), Precision::float32);
        return bit_cast<uint64_t>(from_ordered_bits(p + residual, Precision::float32));  // modulo 2^32
    }
    return double_bits_of(ordered_of(bit_cast<uint64_t>(std::isfinite(predicted) ? predicted : 0.0)) + residual);
}

// decode_vertex<State, false> over a GridFrame, into p's axes; `largest` takes the largest
// magnitude's bits of the three coordinates (a non-finite one is above every finite one).
template <int State, bool Float32>
AMC_ALWAYS_INLINE void decode_unit_vertex(StencilStreams& s, const StencilTable* t, const GridFrame& f, Coordinates& p,
                                          uint64_t& largest) {
    const std::array<int, 3> axes = unit_role_axes(f);
    const uint64_t b0 = unit_value_bits<Float32>(f.midpoint[axes[0]], s.residual<State>(t[0]));
    const double value = bit_cast<double>(b0);
    double second, third;
    predict_unit_others(f, axes, value, second, third);
    const uint64_t b1 = unit_value_bits<Float32>(second, s.residual<1 - State>(t[1]));
    const uint64_t b2 = unit_value_bits<Float32>(third, s.residual<State>(t[2]));
    p[axes[0]] = value;
    p[axes[1]] = bit_cast<double>(b1);
    p[axes[2]] = bit_cast<double>(b2);
    largest = std::max(largest, std::max(b0 & ~kSign64, std::max(b1 & ~kSign64, b2 & ~kSign64)));
}

// frame_of's midpoint in a single-precision hierarchy, for the frames made in lanes (whose
// normals and axes do not read the midpoint).
AMC_ALWAYS_INLINE void round_midpoints_to_float(GridFrame* frames, size_t count) {
    for (size_t i = 0; i < count; ++i)
        for (double& m : frames[i].midpoint) m = rounded_to_float(m);
}

// The frames of `count` listed vertices without a grid, two at a time with SSE2: mode 5's (unit
// normals), or mode 3's.
template <bool UnitNormals = true>
struct PairUnitFrames {
    AMC_ALWAYS_INLINE void operator()(const Hierarchy& h, const FrameCorners* corners, size_t count, GridFrame* frames) const {
        size_t i = 0;
#if AMC_SSE2
        for (; i + 1 < count; i += 2)
            set_frame_pair(frame_pair_lanes<UnitNormals>(h, corners[i], corners[i + 1]), frames[i], frames[i + 1]);
        if (h.single_precision()) round_midpoints_to_float(frames, i);
#endif
        for (; i < count; ++i) set_frame(frame_of<UnitNormals>(h, corners[i]), frames[i]);
    }
};

template <bool Float32, class MakeFrames>
AMC_ALWAYS_INLINE bool decode_unit_listed_with(Hierarchy& h, const FromList& created, const StaticTables& tables,
                                               const uint8_t* rans_data, size_t rans_size, const uint8_t* raw_data,
                                               size_t raw_size, const MakeFrames& make_frames) {
    std::array<StencilTable, 3> t;
    for (size_t k = 0; k < t.size(); ++k) make_stencil_table(tables[k], t[k]);
    StencilStreams s;
    if (!open_stencil_streams(rans_data, rans_size, raw_data, raw_size, s)) return false;
    const bool append = created.appends(h);
    // What a chunk reads at most: two rANS bytes and the sign and 64 bits per coordinate.
    constexpr size_t kChunkRans = 2 * 3 * kChunk, kChunkRaw = 3 * kChunk * 65 / 8 + 8;
    std::array<GridFrame, kChunk> frames;
    Coordinates coordinates[kChunk];
    Vec3 decoded[kChunk];
    PaddedTails<kChunkRans, kChunkRaw> tails;
    for (size_t begin = 0; begin < created.size(); begin += kChunk) {
        const size_t count = std::min(kChunk, created.size() - begin);
        const FrameCorners* corners = created.corners.next(count);
        prefetch_corner_positions(h, corners, count);
        make_frames(h, corners, count, frames.data());
        uint64_t largest = 0;
        tails.pad(s);
        StencilStreams local = s;  // the chunk's copy, which the compiler keeps in registers
        size_t k = 0;
        for (; k + 1 < count; k += 2) {  // token j of the level with state j mod 2
            decode_unit_vertex<0, Float32>(local, t.data(), frames[k], coordinates[k], largest);
            decode_unit_vertex<1, Float32>(local, t.data(), frames[k + 1], coordinates[k + 1], largest);
        }
        if (k < count) decode_unit_vertex<0, Float32>(local, t.data(), frames[k], coordinates[k], largest);
        s = local;
        if (tails.overran(s)) return false;
        std::memcpy(decoded, coordinates, count * sizeof(Vec3));
        // Every coordinate at most DBL_MAX / 2 in magnitude: finite, and no position is far.
        const bool near = largest <= bit_cast<uint64_t>(kHalfMax);
        if (!near) {  // rare: value_of's refusal of a non-finite coordinate
            for (size_t k = 0; k < count; ++k)
                if (!std::isfinite(decoded[k].x) || !std::isfinite(decoded[k].y) || !std::isfinite(decoded[k].z)) return false;
        }
        store_listed_chunk(h, created, begin, decoded, count, append, near);
    }
    return s.ended_cleanly();
}

// Mode 5's levels, or mode 3's (UnitNormals false: the same streams and roles, the frame's normal
// the sum of the cross products).
template <bool Float32, bool UnitNormals>
bool decode_unit_listed(Hierarchy& h, const FromList& created, const StaticTables& tables, const uint8_t* rans_data,
                        size_t rans_size, const uint8_t* raw_data, size_t raw_size) {
    return decode_unit_listed_with<Float32>(h, created, tables, rans_data, rans_size, raw_data, raw_size,
                                            PairUnitFrames<UnitNormals>{});
}

#if AMC_AVX2_AT_RUN_TIME
// Whether decode_grid_listed may make its frames four at a time (set_wide_frames).
std::atomic<bool> wide_frames_allowed{true};

#pragma GCC push_options
#pragma GCC target("avx2")
// exact_float.h's rounded for AVX's vectors (a template instantiated outside this region would
// pass them in the SSE2 ABI).
inline __m256d rounded(__m256d x) {
    __asm__("" : "+x"(x));
    return x;
}

inline __m256d rounded_product(__m256d u, __m256d v) { return rounded(_mm256_mul_pd(u, v)); }

// frame_pair_lanes<true> for four vertices, one in each lane of every AVX operation: the same IEEE
// operations in the same order (the comparisons ordered, as SSE2's), so the same bits.
struct FrameQuadLanes {
    __m256d mx, my, mz, nx, ny, nz;
};

// Inlined in the quad frame makers: a call of its own passes the lanes through memory. Mode 3's
// normals without UnitNormals.
template <bool UnitNormals = true>
AMC_ALWAYS_INLINE FrameQuadLanes frame_quad_lanes(const Hierarchy& h, const FrameCorners* k) {
    struct Lanes {
        __m256d x, y, z;
    };
    const Vec3* positions = h.positions().data();
    auto load = [positions](VertexId v0, VertexId v1, VertexId v2, VertexId v3) {
        auto pair = [positions](VertexId u, VertexId v, __m128d& x, __m128d& y, __m128d& z) {
            const Vec3& p = positions[u];
            const Vec3& q = positions[v];
            const __m128d xy0 = _mm_loadu_pd(&p.x), xy1 = _mm_loadu_pd(&q.x);
            x = _mm_unpacklo_pd(xy0, xy1);
            y = _mm_unpackhi_pd(xy0, xy1);
            z = _mm_loadh_pd(_mm_load_sd(&p.z), &q.z);
        };
        __m128d x01, y01, z01, x23, y23, z23;
        pair(v0, v1, x01, y01, z01);
        pair(v2, v3, x23, y23, z23);
        return Lanes{_mm256_set_m128d(x23, x01), _mm256_set_m128d(y23, y01), _mm256_set_m128d(z23, z01)};
    };
    auto sub = [](const Lanes& u, const Lanes& v) {
        return Lanes{_mm256_sub_pd(u.x, v.x), _mm256_sub_pd(u.y, v.y), _mm256_sub_pd(u.z, v.z)};
    };
    auto cross = [](const Lanes& u, const Lanes& v) {
        return Lanes{_mm256_sub_pd(rounded_product(u.y, v.z), rounded_product(u.z, v.y)),
                     _mm256_sub_pd(rounded_product(u.z, v.x), rounded_product(u.x, v.z)),
                     _mm256_sub_pd(rounded_product(u.x, v.y), rounded_product(u.y, v.x))};
    };
    auto dot = [&](const Lanes& u) {  // exact_dot(u, u)
        return _mm256_add_pd(_mm256_add_pd(rounded_product(u.x, u.x), rounded_product(u.y, u.y)), rounded_product(u.z, u.z));
    };
    const bool has_d[4] = {k[0].d != kNoVertex, k[1].d != kNoVertex, k[2].d != kNoVertex, k[3].d != kNoVertex};
    const Lanes a = load(k[0].a, k[1].a, k[2].a, k[3].a), b = load(k[0].b, k[1].b, k[2].b, k[3].b),
                c = load(k[0].c, k[1].c, k[2].c, k[3].c);
    const Lanes d = load(has_d[0] ? k[0].d : k[0].a, has_d[1] ? k[1].d : k[1].a, has_d[2] ? k[2].d : k[2].a,
                         has_d[3] ? k[3].d : k[3].a);
    const __m256d half = _mm256_set1_pd(0.5);
    const Lanes mid{rounded_product(_mm256_add_pd(a.x, b.x), half), rounded_product(_mm256_add_pd(a.y, b.y), half),
                    rounded_product(_mm256_add_pd(a.z, b.z), half)};
    const Lanes n1 = cross(sub(b, a), sub(c, a));
    const Lanes n2 = cross(sub(a, b), sub(d, b));
    const __m256d with_d = _mm256_castsi256_pd(
        _mm256_set_epi64x(-int64_t(has_d[3]), -int64_t(has_d[2]), -int64_t(has_d[1]), -int64_t(has_d[0])));
    auto pick = [with_d](__m256d u, __m256d v) {
        return _mm256_or_pd(_mm256_and_pd(with_d, _mm256_add_pd(u, v)), _mm256_andnot_pd(with_d, u));
    };
    if (!UnitNormals) return {mid.x, mid.y, mid.z, pick(n1.x, n2.x), pick(n1.y, n2.y), pick(n1.z, n2.z)};
    const __m256d zero = _mm256_setzero_pd(), infinity = _mm256_set1_pd(HUGE_VAL), one = _mm256_set1_pd(1.0);
    const __m256d l1 = _mm256_sqrt_pd(dot(n1)), l2 = _mm256_sqrt_pd(dot(n2));
    const __m256d r1 = _mm256_div_pd(one, l1), r2 = _mm256_div_pd(one, l2);
    const __m256d v1 = _mm256_and_pd(_mm256_cmp_pd(l1, zero, _CMP_GT_OS), _mm256_cmp_pd(l1, infinity, _CMP_LT_OS));
    const __m256d v2 = _mm256_and_pd(_mm256_cmp_pd(l2, zero, _CMP_GT_OS), _mm256_cmp_pd(l2, infinity, _CMP_LT_OS));
    auto unit = [](const Lanes& u, __m256d r, __m256d valid) {
        return Lanes{_mm256_and_pd(valid, rounded_product(r, u.x)), _mm256_and_pd(valid, rounded_product(r, u.y)),
                     _mm256_and_pd(valid, rounded_product(r, u.z))};
    };
    const Lanes u1 = unit(n1, r1, v1), u2 = unit(n2, r2, v2);
    return {mid.x, mid.y, mid.z, pick(u1.x, u2.x), pick(u1.y, u2.y), pick(u1.z, u2.z)};
}

// A vector of one coordinate per lane: lane j to frames[j].
inline void store_quad(__m256d v, double (GridFrame::*array)[3], int axis, GridFrame* g) {
    const __m128d low = _mm256_castpd256_pd128(v), high = _mm256_extractf128_pd(v, 1);
    _mm_storel_pd(&(g[0].*array)[axis], low);
    _mm_storeh_pd(&(g[1].*array)[axis], low);
    _mm_storel_pd(&(g[2].*array)[axis], high);
    _mm_storeh_pd(&(g[3].*array)[axis], high);
}

// grid_point_pair's grid predictions in four lanes: of `value` from `from` (each lane's origin on
// its axis), to points, table offsets and turn masks.
inline void grid_point_quad(__m256d value, __m256d from, const GridScale& grid, uint64_t* points, uint64_t* offsets,
                            int64_t* turns) {
    const __m256d zero = _mm256_setzero_pd();
    const __m256d t = rounded(_mm256_div_pd(_mm256_sub_pd(value, from), _mm256_set1_pd(grid.step)));
    const __m256d high = _mm256_cmp_pd(t, _mm256_set1_pd(grid.top), _CMP_GE_OS);
    const __m256d inside = _mm256_andnot_pd(high, _mm256_cmp_pd(t, zero, _CMP_GT_OS));
    const __m128i p = _mm256_cvttpd_epi32(rounded(_mm256_add_pd(t, _mm256_set1_pd(0.5))));
    const __m256d f = rounded(_mm256_sub_pd(t, _mm256_cvtepi32_pd(p)));
    const __m256d bin = _mm256_and_pd(inside, _mm256_cmp_pd(_mm256_andnot_pd(_mm256_set1_pd(-0.0), f), _mm256_set1_pd(0.25), _CMP_GE_OS));
    const __m256d turn = _mm256_and_pd(inside, _mm256_cmp_pd(f, zero, _CMP_LT_OS));
    const __m256i point = _mm256_or_si256(_mm256_and_si256(_mm256_castpd_si256(inside), _mm256_cvtepu32_epi64(p)),
                                          _mm256_and_si256(_mm256_castpd_si256(high), _mm256_set1_epi64x(int64_t(grid.max))));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(points), point);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(offsets),
                        _mm256_and_si256(_mm256_castpd_si256(bin), _mm256_set1_epi64x(int64_t(sizeof(GridTable)))));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(turns), _mm256_castpd_si256(turn));
}

// Four vertices' frames by role (lane j: vertex j of the quad): the midpoint's and the normal's
// coordinates and the origin on each role's axis, and all ones where the frame has a normal.
struct QuadRoles {
    __m256d midpoint[3], normal[3], origin[3];
    __m256d with_normal;
};

// The frame's axis of four vertices as lane masks (set_frame's rule: the normal's largest absolute
// coordinate, z before y before x on ties; axis 0 without a finite non-zero normal).
struct QuadAxes {
    __m256d with_normal, on_y, on_z;
};

inline QuadAxes quad_axes(const FrameQuadLanes& l) {
    const __m256d sign = _mm256_set1_pd(-0.0);
    const __m256d x = _mm256_andnot_pd(sign, l.nx), y = _mm256_andnot_pd(sign, l.ny), z = _mm256_andnot_pd(sign, l.nz);
    const __m256d y_wins = _mm256_cmp_pd(y, x, _CMP_GT_OS);
    const __m256d best = _mm256_max_pd(y, x);
    const __m256d z_wins = _mm256_cmp_pd(z, best, _CMP_GT_OS);
    const __m256d largest = _mm256_max_pd(z, best);
    const __m256d with_normal = _mm256_and_pd(_mm256_cmp_pd(largest, _mm256_setzero_pd(), _CMP_GT_OS),
                                              _mm256_cmp_pd(largest, _mm256_set1_pd(HUGE_VAL), _CMP_LT_OS));
    const __m256d on_z = _mm256_and_pd(with_normal, z_wins), on_y = _mm256_andnot_pd(z_wins, _mm256_and_pd(with_normal, y_wins));
    return {with_normal, on_y, on_z};
}

// The four axes as int32 (2 on z, 1 on y, else 0) at `out`, 16-byte aligned.
inline void store_quad_axes(const QuadAxes& a, int32_t* out) {
    const __m256i axis = _mm256_or_si256(_mm256_and_si256(_mm256_castpd_si256(a.on_y), _mm256_set1_epi64x(1)),
                                         _mm256_and_si256(_mm256_castpd_si256(a.on_z), _mm256_set1_epi64x(2)));
    _mm_store_si128(reinterpret_cast<__m128i*>(out),
                    _mm256_castsi256_si128(_mm256_permutevar8x32_epi32(axis, _mm256_setr_epi32(0, 2, 4, 6, 0, 0, 0, 0))));
}

// Role 0's grid predictions of four vertices (grid_point_pair's, four lanes): each lane's midpoint
// coordinate and origin on its axis.
inline void grid_first_quad(const FrameQuadLanes& l, const QuadAxes& a, const GridScale& grid, const double* origin,
                            uint64_t* points, uint64_t* offsets, int64_t* turns) {
    const __m256d value = _mm256_blendv_pd(_mm256_blendv_pd(l.mx, l.my, a.on_y), l.mz, a.on_z);
    const __m256d from = _mm256_blendv_pd(_mm256_blendv_pd(_mm256_set1_pd(origin[0]), _mm256_set1_pd(origin[1]), a.on_y),
                                          _mm256_set1_pd(origin[2]), a.on_z);
    grid_point_quad(value, from, grid, points, offsets, turns);
}

// set_grid_frame_pair for four vertices: set_axis by lane masks, role 0's grid predictions in two
// pairs. Without `Grid`, the frames alone (set_frame's).
template <bool Grid = true>
inline void set_grid_frame_quad(const FrameQuadLanes& l, const GridScale& grid, const double* origin, GridFrame* g) {
    store_quad(l.mx, &GridFrame::midpoint, 0, g);
    store_quad(l.my, &GridFrame::midpoint, 1, g);
    store_quad(l.mz, &GridFrame::midpoint, 2, g);
    store_quad(l.nx, &GridFrame::normal, 0, g);
    store_quad(l.ny, &GridFrame::normal, 1, g);
    store_quad(l.nz, &GridFrame::normal, 2, g);
    const QuadAxes a = quad_axes(l);
    alignas(16) int32_t axes[4];
    store_quad_axes(a, axes);
    const int has = _mm256_movemask_pd(a.with_normal);
    for (int j = 0; j < 4; ++j) {
        g[j].has_normal = ((has >> j) & 1) != 0;
        g[j].axis = axes[j];
    }
    if (!Grid) return;
    uint64_t points[4], offsets[4];
    int64_t turns[4];
    grid_first_quad(l, a, grid, origin, points, offsets, turns);
    for (int j = 0; j < 4; ++j) g[j].first = {points[j], offsets[j], turns[j]};
}

// Role 0's grid predictions and the frame's axes of a chunk's vertices, by vertex: the grouped
// order's decoder reads them so (QuadFrames), where the GridFrame of each took a lane's fields one
// at a time.
struct FirstRoles {
    alignas(32) uint64_t point[kChunk], offset[kChunk];
    alignas(32) int64_t turn[kChunk];
    alignas(16) int32_t axis[kChunk];
    void set(size_t k, const GridFrame& f) {
        point[k] = f.first.point;
        offset[k] = f.first.table_offset;
        turn[k] = f.first.turn_mask;
        axis[k] = f.axis;
    }
};

// set_grid_frame_quad for the grouped order's decoder: vertices k .. k + 3's frames by role in
// `roles`, their role-0 grid predictions and axes in `first`, each made in the lanes and stored
// whole (the same values).
inline void set_grid_roles_quad(const FrameQuadLanes& l, const GridScale& grid, const double* origin, QuadRoles& roles,
                                FirstRoles& first, size_t k) {
    const QuadAxes a = quad_axes(l);
    const __m256d on_y = a.on_y, on_z = a.on_z;
    store_quad_axes(a, first.axis + k);
    grid_first_quad(l, a, grid, origin, first.point + k, first.offset + k, first.turn + k);
    // Role 1's axis is 1 where the frame's is 0 (and without a normal), else 0; role 2's is 1 where
    // the frame's is 2, else 2.
    const __m256d on_x = _mm256_andnot_pd(_mm256_or_pd(on_y, on_z), _mm256_castsi256_pd(_mm256_set1_epi64x(-1)));
    auto by_role = [&](__m256d x, __m256d y, __m256d z, __m256d* role) {
        role[0] = _mm256_blendv_pd(_mm256_blendv_pd(x, y, on_y), z, on_z);
        role[1] = _mm256_blendv_pd(x, y, on_x);
        role[2] = _mm256_blendv_pd(z, y, on_z);
    };
    by_role(l.mx, l.my, l.mz, roles.midpoint);
    by_role(l.nx, l.ny, l.nz, roles.normal);
    by_role(_mm256_set1_pd(origin[0]), _mm256_set1_pd(origin[1]), _mm256_set1_pd(origin[2]), roles.origin);
    roles.with_normal = a.with_normal;
}

// decode_grid_grouped with roles 1 and 2's predictions made four vertices at a time from `roles`
// (QuadFrames'), after every four role-0 tokens: the same operations on the same values in AVX's
// lanes (no fused multiply-add), so the same predictions; the vertices past the last whole four
// (a level's last chunk) one at a time, as decode_grid_grouped.
inline bool decode_grid_grouped_quads(StencilStreams& s, const GridTable* t, const GridFrame* frames, const FirstRoles& firsts,
                                      const QuadRoles* roles, size_t count, const GridScale& level_grid, const double* origin,
                                      Coordinates* decoded) {
    const GridScale grid = level_grid;  // a local copy: the stores to `decoded` could alias the caller's
    alignas(32) uint64_t point1[kChunk], point2[kChunk], offset1[kChunk], offset2[kChunk];
    alignas(32) int64_t turn1[kChunk], turn2[kChunk];
    alignas(32) double first_values[kChunk];  // the whole fours' role-0 coordinates
    uint64_t largest = 0;  // of the role-0 grid values as unsigned, where a negative one is above any
    auto token = [&](auto state, size_t k) {
        constexpr int State = decltype(state)::value;
        const int64_t q0 = grid_point_value<State>(s, t, firsts.point[k], firsts.offset[k], firsts.turn[k]);
        largest = std::max(largest, uint64_t(q0));
        return q0;
    };
    const __m256d step = _mm256_set1_pd(grid.step);
    const size_t fours = count / 4 * 4;
    size_t k = 0;
    for (; k + 3 < count; k += 4) {
        const int64_t q0 = token(std::integral_constant<int, 0>{}, k), q1 = token(std::integral_constant<int, 1>{}, k + 1),
                      q2 = token(std::integral_constant<int, 0>{}, k + 2), q3 = token(std::integral_constant<int, 1>{}, k + 3);
        // A valid grid value is below 2^30 (kMaxQuantizationBits); an invalid one fails the check
        // after the loop, whatever its lane made of it.
        const __m256d q = _mm256_cvtepi32_pd(_mm_setr_epi32(int(q0), int(q1), int(q2), int(q3)));
        const QuadRoles& r = roles[k / 4];
        const __m256d value = _mm256_add_pd(r.origin[0], rounded(_mm256_mul_pd(q, step)));
        _mm256_store_pd(first_values + k, value);
        const __m256d u = rounded(_mm256_div_pd(_mm256_sub_pd(value, r.midpoint[0]), r.normal[0]));
        const __m256d second = _mm256_blendv_pd(r.midpoint[1], _mm256_add_pd(r.midpoint[1], rounded(_mm256_mul_pd(u, r.normal[1]))),
                                                r.with_normal);
        const __m256d third = _mm256_blendv_pd(r.midpoint[2], _mm256_add_pd(r.midpoint[2], rounded(_mm256_mul_pd(u, r.normal[2]))),
                                               r.with_normal);
        grid_point_quad(second, r.origin[1], grid, point1 + k, offset1 + k, turn1 + k);
        grid_point_quad(third, r.origin[2], grid, point2 + k, offset2 + k, turn2 + k);
    }
    for (; k < count; ++k) {
        const int64_t q0 = k % 2 == 0 ? token(std::integral_constant<int, 0>{}, k) : token(std::integral_constant<int, 1>{}, k);
        const GridFrame& f = frames[k];
        const GridPointPair g = grid_first_role(f, q0, grid, origin, f.axis == 0 ? 1 : 0, f.axis == 2 ? 1 : 2, decoded[k]);
        point1[k] = g.point[0];
        point2[k] = g.point[1];
        offset1[k] = g.table_offset[0];
        offset2[k] = g.table_offset[1];
        turn1[k] = g.turn_mask[0];
        turn2[k] = g.turn_mask[1];
    }
    if (largest > grid.max) return false;  // also a q0 < 0
    // Roles 1 and 2's grid values, then the coordinates: the whole fours' in the lanes (the same
    // operations as set_other_roles), each lane's roles put on their axes and stored as x, y, z.
    alignas(16) int32_t second_points[kChunk], third_points[kChunk];
    uint64_t others = 0;  // the largest of roles 1 and 2's grid values as unsigned
    auto roles_1_2 = [&](auto odd) {
        constexpr int S = decltype(odd)::value ? 1 : 0;  // role 1's state: count mod 2
        for (size_t i = 0; i < count; ++i) {
            const int64_t v1 = grid_point_value<S>(s, t + kGridBins, point1[i], offset1[i], turn1[i]);
            const int64_t v2 = grid_point_value<1 - S>(s, t + 2 * kGridBins, point2[i], offset2[i], turn2[i]);
            others = std::max(others, std::max(uint64_t(v1), uint64_t(v2)));
            second_points[i] = int32_t(v1);  // below 2^30 where valid; an invalid one fails below
            third_points[i] = int32_t(v2);
        }
    };
    if (count % 2 == 0) roles_1_2(std::false_type{});
    else roles_1_2(std::true_type{});
    if (others > grid.max) return false;
    for (size_t i = 0; i < fours; i += 4) {
        const QuadRoles& r = roles[i / 4];
        const __m256d first = _mm256_load_pd(first_values + i);
        const __m256d second = _mm256_add_pd(
            r.origin[1], rounded(_mm256_mul_pd(_mm256_cvtepi32_pd(_mm_load_si128(reinterpret_cast<const __m128i*>(second_points + i))), step)));
        const __m256d third = _mm256_add_pd(
            r.origin[2], rounded(_mm256_mul_pd(_mm256_cvtepi32_pd(_mm_load_si128(reinterpret_cast<const __m128i*>(third_points + i))), step)));
        // Role 0 on the frame's axis; role 1 on x, or on y where the axis is x; role 2 on z, or on
        // y where the axis is z.
        const __m256i axis = _mm256_cvtepi32_epi64(_mm_load_si128(reinterpret_cast<const __m128i*>(firsts.axis + i)));
        const __m256d on_x = _mm256_castsi256_pd(_mm256_cmpeq_epi64(axis, _mm256_setzero_si256()));
        const __m256d on_y = _mm256_castsi256_pd(_mm256_cmpeq_epi64(axis, _mm256_set1_epi64x(1)));
        const __m256d on_z = _mm256_castsi256_pd(_mm256_cmpeq_epi64(axis, _mm256_set1_epi64x(2)));
        const __m256d x = _mm256_blendv_pd(second, first, on_x);
        const __m256d y = _mm256_blendv_pd(_mm256_blendv_pd(third, first, on_y), second, on_x);
        const __m256d z = _mm256_blendv_pd(third, first, on_z);
        const __m256d xy02 = _mm256_unpacklo_pd(x, y), xy13 = _mm256_unpackhi_pd(x, y);  // (x0 y0 x2 y2), (x1 y1 x3 y3)
        const __m128d z01 = _mm256_castpd256_pd128(z), z23 = _mm256_extractf128_pd(z, 1);
        double* p = decoded[i];
        _mm_storeu_pd(p, _mm256_castpd256_pd128(xy02));
        _mm_storel_pd(p + 2, z01);
        _mm_storeu_pd(p + 3, _mm256_castpd256_pd128(xy13));
        _mm_storeh_pd(p + 5, z01);
        _mm_storeu_pd(p + 6, _mm256_extractf128_pd(xy02, 1));
        _mm_storel_pd(p + 8, z23);
        _mm_storeu_pd(p + 9, _mm256_extractf128_pd(xy13, 1));
        _mm_storeh_pd(p + 11, z23);
    }
    for (size_t i = fours; i < count; ++i) {  // role 0 is on its axis already (grid_first_role)
        const int a0 = firsts.axis[i];
        set_other_roles(second_points[i], third_points[i], grid, origin, a0 == 0 ? 1 : 0, a0 == 2 ? 1 : 2, decoded[i]);
    }
    return true;
}

// PairFrames four at a time; for the grouped order (by_role), each whole four's frames by role
// and role 0's predictions by vertex for decode_grid_grouped_quads (the last few of a level's
// last chunk as GridFrames, their role 0 copied).
struct QuadFrames {
    bool by_role;
    QuadRoles roles[kChunk / 4];
    FirstRoles firsts;
    void operator()(const Hierarchy& h, const FrameCorners* corners, size_t count, const GridScale& grid, const double* origin,
                    GridFrame* frames) {
        size_t i = 0;
        if (by_role) {
            for (; i + 3 < count; i += 4) set_grid_roles_quad(frame_quad_lanes(h, corners + i), grid, origin, roles[i / 4], firsts, i);
            PairFrames()(h, corners + i, count - i, grid, origin, frames + i);
            for (; i < count; ++i) firsts.set(i, frames[i]);
            return;
        }
        for (; i + 3 < count; i += 4) set_grid_frame_quad(frame_quad_lanes(h, corners + i), grid, origin, frames + i);
        PairFrames()(h, corners + i, count - i, grid, origin, frames + i);
    }
    bool grouped(StencilStreams& s, const GridTable* t, const GridFrame* frames, size_t count, const GridScale& grid,
                 const double* origin, Coordinates* decoded) const {
        return decode_grid_grouped_quads(s, t, frames, firsts, roles, count, grid, origin, decoded);
    }
};

template <bool Grouped>
bool decode_grid_listed_avx2(Hierarchy& h, const FromList& created, const Quantizer& quantizer, const StaticTables& tables,
                             const uint8_t* rans_data, size_t rans_size, const uint8_t* raw_data, size_t raw_size) {
    QuadFrames quads;
    quads.by_role = Grouped;
    return decode_grid_listed_with<Grouped>(h, created, quantizer, tables, rans_data, rans_size, raw_data, raw_size, quads);
}

// PairUnitFrames four at a time.
template <bool UnitNormals = true>
struct QuadUnitFrames {
    void operator()(const Hierarchy& h, const FrameCorners* corners, size_t count, GridFrame* frames) const {
        size_t i = 0;
        for (; i + 3 < count; i += 4)
            set_grid_frame_quad<false>(frame_quad_lanes<UnitNormals>(h, corners + i), GridScale{}, nullptr, frames + i);
        if (h.single_precision()) round_midpoints_to_float(frames, i);
        PairUnitFrames<UnitNormals>()(h, corners + i, count - i, frames + i);
    }
};

template <bool Float32, bool UnitNormals>
bool decode_unit_listed_avx2(Hierarchy& h, const FromList& created, const StaticTables& tables, const uint8_t* rans_data,
                             size_t rans_size, const uint8_t* raw_data, size_t raw_size) {
    return decode_unit_listed_with<Float32>(h, created, tables, rans_data, rans_size, raw_data, raw_size,
                                            QuadUnitFrames<UnitNormals>{});
}
#pragma GCC pop_options
#endif

}  // namespace

// decode_grid_listed, with AVX2's frames where the processor has them.
template <bool Grouped>
bool decode_grid_listed_fastest(Hierarchy& h, const FromList& created, const Quantizer& quantizer, const StaticTables& tables,
                                const uint8_t* rans_data, size_t rans_size, const uint8_t* raw_data, size_t raw_size) {
#if AMC_AVX2_AT_RUN_TIME
    if (has_avx2() && wide_frames_allowed.load(std::memory_order_relaxed))
        return decode_grid_listed_avx2<Grouped>(h, created, quantizer, tables, rans_data, rans_size, raw_data, raw_size);
#endif
    return decode_grid_listed<Grouped>(h, created, quantizer, tables, rans_data, rans_size, raw_data, raw_size);
}

// decode_unit_listed, with AVX2's frames where the processor has them.
template <bool Float32, bool UnitNormals>
bool decode_unit_listed_fastest(Hierarchy& h, const FromList& created, const StaticTables& tables, const uint8_t* rans_data,
                                size_t rans_size, const uint8_t* raw_data, size_t raw_size) {
#if AMC_AVX2_AT_RUN_TIME
    if (has_avx2() && wide_frames_allowed.load(std::memory_order_relaxed))
        return decode_unit_listed_avx2<Float32, UnitNormals>(h, created, tables, rans_data, rans_size, raw_data, raw_size);
#endif
    return decode_unit_listed<Float32, UnitNormals>(h, created, tables, rans_data, rans_size, raw_data, raw_size);
}

// The frames of `count` vertices without a grid (mode 5's), for the encoder as its listed
// decoder makes them: four at a time where the processor has AVX2, else two.
void make_unit_frames(const Hierarchy& h, const FrameCorners* corners, size_t count, GridFrame* frames) {
#if AMC_AVX2_AT_RUN_TIME
    if (has_avx2() && wide_frames_allowed.load(std::memory_order_relaxed)) {
        QuadUnitFrames<>()(h, corners, count, frames);
        return;
    }
#endif
    PairUnitFrames<>()(h, corners, count, frames);
}

template bool decode_grid_listed_fastest<false>(Hierarchy&, const FromList&, const Quantizer&, const StaticTables&, const uint8_t*, size_t,
                                                const uint8_t*, size_t);
template bool decode_grid_listed_fastest<true>(Hierarchy&, const FromList&, const Quantizer&, const StaticTables&, const uint8_t*, size_t,
                                               const uint8_t*, size_t);
template bool decode_unit_listed_fastest<false, false>(Hierarchy&, const FromList&, const StaticTables&, const uint8_t*, size_t,
                                                       const uint8_t*, size_t);
template bool decode_unit_listed_fastest<false, true>(Hierarchy&, const FromList&, const StaticTables&, const uint8_t*, size_t,
                                                      const uint8_t*, size_t);
template bool decode_unit_listed_fastest<true, false>(Hierarchy&, const FromList&, const StaticTables&, const uint8_t*, size_t,
                                                      const uint8_t*, size_t);
template bool decode_unit_listed_fastest<true, true>(Hierarchy&, const FromList&, const StaticTables&, const uint8_t*, size_t,
                                                     const uint8_t*, size_t);

}  // namespace amc::static_geometry

namespace amc {

bool set_wide_frames(bool allowed) {
#if AMC_AVX2_AT_RUN_TIME
    return static_geometry::wide_frames_allowed.exchange(allowed);
#else
    (void)allowed;
    return false;
#endif
}

}  // namespace amc
