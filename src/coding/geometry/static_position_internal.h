// The static geometry modes' shared pieces (docs/FORMAT.md 5.6-5.9), for their encoder
// (static_position_encoder.cpp) and decoders (static_position_decoder.cpp; the fast paths
// static_stencil_decoder.cpp and static_frame_decoder.cpp): tokens and residuals, grid
// predictions, chunks of vertices and their frames, the fast paths' tables and streams.
#pragma once

#include "coding/geometry/static_position_coder.h"

#include "coding/geometry/geometry_prediction.h"
#include "coding/geometry/hierarchy_on_grid.h"
#include "common/bits.h"
#include "common/compiler.h"
#include "common/exact_float.h"
#include "common/little_endian.h"
#include "common/simd.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <utility>
#include <vector>

namespace amc::static_geometry {

constexpr int kDirectTokens = 15;     // tokens 0 .. 14: magnitudes 0 .. 7 with their sign
constexpr int kMaxGammaLength = 12;   // table values are below 2^13
constexpr int kTokensFor64Bits = kDirectTokens + 4 * (64 - 4) + 4;
// StaticLevelEncoder's symbol words: the table above the token's bits.
constexpr int kTokenBits = 9;
static_assert(kTokensFor64Bits <= (1 << kTokenBits) && kMaxStaticTables << kTokenBits <= 0xFFFF, "a symbol fits 16 bits");

// The largest bit length a residual can have in the space.
inline int max_residual_bits(CoordinateSpace space) {
    if (space.quantizer != nullptr) return space.quantizer->bits;
    return space.precision == Precision::float32 ? 32 : 64;
}
// Tokens 0 .. token_limit(space) - 1 are possible.
inline int token_limit(CoordinateSpace space) {
    const int k = max_residual_bits(space);
    return k < 4 ? 2 * ((1 << k) - 1) + 1 : kDirectTokens + 4 * (k - 4) + 4;
}
static_assert(kTokensFor64Bits <= kRansMaxSymbols, "every token fits a table");

// The axes in coding order: the frame's axis, then the two others in increasing order.
inline std::array<int, 3> role_axes(const NormalFrame& f) {
    static constexpr std::array<std::array<int, 3>, 3> kByAxis{{{0, 1, 2}, {1, 0, 2}, {2, 0, 1}}};
    return kByAxis[f.has_normal ? size_t(f.axis) : 0];
}

using Residual = StaticResidual;

// ---- one coordinate: residual against a prediction, and back -----------------------------------

inline Residual residual_of(CoordinateSpace space, int axis, double actual, double predicted) {
    if (space.quantizer != nullptr) {
        const uint32_t a = quantize_coordinate(*space.quantizer, axis, actual);
        const uint32_t p = quantize_coordinate(*space.quantizer, axis, predicted);
        return {a < p, a < p ? uint64_t(p - a) : uint64_t(a - p)};
    }
    const int width = space.precision == Precision::float32 ? 32 : 64;
    const uint64_t mask = width == 64 ? ~uint64_t{0} : 0xFFFFFFFFull;
    const uint64_t r = (ordered_bits(actual, space.precision) -
                        ordered_bits(coder_prediction(predicted, space.precision), space.precision)) & mask;
    const bool negative = (r >> (width - 1)) & 1;
    return {negative, negative ? (uint64_t{0} - r) & mask : r};
}

// residual_of's for float64 coordinates, inline in the encoder's loop (bit-exact files' modes 3 and 5).
AMC_ALWAYS_INLINE Residual float64_residual(double actual, double predicted) {
    const uint64_t r = ordered_bits(actual, Precision::float64) -
                       ordered_bits(std::isfinite(predicted) ? predicted : 0.0, Precision::float64);
    const bool negative = (r >> 63) != 0;
    return {negative, negative ? uint64_t{0} - r : r};
}

// residual_of's for float32 coordinates (a single-precision hierarchy's, bit-exact), inline in the
// encoder's loops as float64_residual.
AMC_ALWAYS_INLINE Residual float32_residual(double actual, double predicted) {
    const uint32_t r = uint32_t(ordered_bits(actual, Precision::float32)) -
                       uint32_t(ordered_bits(coder_prediction(predicted, Precision::float32), Precision::float32));
    const bool negative = (r >> 31) != 0;
    return {negative, negative ? uint64_t(0u - r) : uint64_t(r)};
}

// Branch-free: residual signs are coin flips, which a branch would mispredict half the time.
AMC_ALWAYS_INLINE int64_t negated_if(int64_t x, bool negate) {
    const int64_t m = -int64_t(negate);
    return (x ^ m) - m;
}
// A quantized residual as a signed number (its magnitude is below 2^30).
AMC_ALWAYS_INLINE int64_t signed_value(Residual r) { return negated_if(int64_t(r.magnitude), r.negative); }

// The value a residual gives, or false if it leaves the grid.
AMC_ALWAYS_INLINE bool value_of(CoordinateSpace space, int axis, double predicted, Residual r, double& value) {
    if (space.quantizer != nullptr) {
        const int64_t q = int64_t(quantize_coordinate(*space.quantizer, axis, predicted)) + signed_value(r);
        if (q < 0 || q > int64_t(space.quantizer->max_coordinate())) return false;
        value = dequantize_coordinate(*space.quantizer, axis, uint32_t(q));
        return true;
    }
    const uint64_t mask = space.precision == Precision::float32 ? 0xFFFFFFFFull : ~uint64_t{0};
    const uint64_t p = ordered_bits(coder_prediction(predicted, space.precision), space.precision);
    value = from_ordered_bits((r.negative ? p - r.magnitude : p + r.magnitude) & mask, space.precision);
    return std::isfinite(value);
}

// ---- mode 4: where the prediction falls between grid points ---------------------------------------

// The grid coordinate p = round(t) of a prediction (quantize_coordinate's), t = (x - origin) / step
// in grid steps, and its table bin: 1 when |t - p| >= 1/4, else 0. `turn` when t < p: the residual
// is then coded negated, so that positive points towards the second-nearest grid point. A clamped
// prediction (t <= 0, t >= 2^bits - 1, NaN) has bin 0 and no turn.
struct GridPrediction {
    uint32_t p;
    int bin;
    bool turn;
};

// The grid as the predictions read it, made once a level: the step and the largest grid
// coordinate, also as a double (from Quantizer::bits at every use, a shift, a subtraction and a
// conversion a coordinate). Zero without a quantizer.
struct GridScale {
    double step = 0.0, top = 0.0;
    uint32_t max = 0;
    double inverse_step = 0.0;  // 1 / step, for grid_point_of_grid_value
};
inline GridScale grid_scale(const Quantizer* quantizer) {
    if (quantizer == nullptr) return {};
    return {quantizer->step, static_cast<double>(quantizer->max_coordinate()), quantizer->max_coordinate(), 1.0 / quantizer->step};
}

// Inlined: returned through memory, the small struct stalls the decoder's loop on a store forward.
// `origin`: the quantizer's origin on the axis.
AMC_ALWAYS_INLINE GridPrediction grid_prediction_at(const GridScale& grid, double origin, double x) {
    // quantize_coordinate's steps, its t kept for the bin.
    const double t = rounded((x - origin) / grid.step);
    if (!(t > 0.0)) return {0, 0, false};  // also NaN
    if (t >= grid.top) return {grid.max, 0, false};
    GridPrediction g{static_cast<uint32_t>(t + 0.5), 0, false};  // floor, as in quantize_coordinate
    const double f = rounded(t - static_cast<double>(g.p));
    g.turn = f < 0.0;
    g.bin = std::fabs(f) >= 0.25 ? 1 : 0;  // f is finite: f >= 1/4 or f <= -1/4
    return g;
}

// quantize_coordinate's grid point of x with the level's GridScale (`origin`: the quantizer's on
// the axis): the encoder's actual positions, without the axis selects and Quantizer::bits.
AMC_ALWAYS_INLINE uint32_t grid_point_at(const GridScale& grid, double origin, double x) {
    const double t = (x - origin) / grid.step;
    if (!(t > 0.0)) return 0;  // also NaN
    if (t >= grid.top) return grid.max;
    return static_cast<uint32_t>(t + 0.5);
}

// grid_point_at of an x that is a grid value, origin + rounded(q * step) (the encoder's actual
// positions): q, with a product in place of the division (a fifth of the encoder's coordinate
// loop waited on it). t is then q within a few ulps, far from the half-way points where the two
// could round apart.
AMC_ALWAYS_INLINE uint32_t grid_point_of_grid_value(const GridScale& grid, double origin, double x) {
    const double t = (x - origin) * grid.inverse_step;
    if (!(t > 0.0)) return 0;
    if (t >= grid.top) return grid.max;
    return static_cast<uint32_t>(t + 0.5);
}

// The residual of an actual grid point against a prediction's. Without branches: turns and signs
// are coin flips.
AMC_ALWAYS_INLINE Residual grid_residual(uint32_t actual, const GridPrediction& g) {
    const int64_t s = negated_if(int64_t(actual) - int64_t(g.p), g.turn);
    const int64_t sign = s >> 63;
    return {sign != 0, uint64_t((s ^ sign) - sign)};
}

// `origin`: the quantizer's origin on the axis (dequantize_coordinate's); `residual` signed
// (|residual| < 2^bits).
AMC_ALWAYS_INLINE bool grid_value(const GridScale& grid, double origin, const GridPrediction& g, int64_t residual,
                                  double& value) {
    const int64_t q = int64_t(g.p) + negated_if(residual, g.turn);
    if (q < 0 || q > int64_t(grid.max)) return false;
    value = origin + rounded(static_cast<double>(q) * grid.step);
    return true;
}

// A token from kDirectTokens on, with its raw bits.
AMC_ALWAYS_INLINE Residual take_large(int token, RawBitReader& raw) {
    const int k = 4 + (token - kDirectTokens) / 4;
    const int low = k - 3;
    Residual r;
    uint64_t bits;
    if (low <= 56) {
        // The sign and both values in one read (at most 57 bits): they follow each other, low bit
        // first, the value of low - 32 bits before the value of 32 when low > 32.
        const uint64_t all = raw.get(1 + low);
        r.negative = (all & 1) != 0;
        bits = all >> 1;
        if (low > 32) bits = (bits & ((uint64_t{1} << (low - 32)) - 1)) << 32 | bits >> (low - 32);
    } else {
        const uint64_t sign_and_first = raw.get(1 + low - 32);
        r.negative = (sign_and_first & 1) != 0;
        bits = (sign_and_first >> 1) << 32 | raw.get(32);
    }
    r.magnitude = (uint64_t(4 | ((token - kDirectTokens) & 3)) << low) | bits;
    return r;
}

AMC_ALWAYS_INLINE Residual take(int token, RawBitReader& raw) {
    if (token < kDirectTokens) return {bool((token != 0) & (token % 2 == 0)), uint64_t(token + 1) / 2};
    return take_large(token, raw);
}

// take's residual as a signed number, for quantized coordinates (magnitudes below 2^30): the
// direct tokens' values from a table.
constexpr int8_t kDirectValues[kDirectTokens] = {0, 1, -1, 2, -2, 3, -3, 4, -4, 5, -5, 6, -6, 7, -7};
AMC_ALWAYS_INLINE int64_t take_signed(int token, RawBitReader& raw) {
    if (token < kDirectTokens) return kDirectValues[token];
    return signed_value(take_large(token, raw));
}

// ---- tables ------------------------------------------------------------------------------------

// Elias gamma with adaptive models for the unary length (fresh per level block).
struct TableModels {
    std::array<BitModel, kMaxGammaLength + 1> count, gap, frequency;
};
// ---- chunks of vertices: corners, frames --------------------------------------------------------

// Both sides work in chunks of vertices: first the nodes' corners of a whole chunk, in a short
// loop whose iterations the processor runs many at once, and prefetches of their positions; then
// the chunk's frames (and in mode 4 role 0's grid prediction), which depend only on earlier levels'
// positions, not on the streams; then the chunk's coordinates, from the streams or into tokens.
// Frame by frame, each vertex waited for its cache misses, then the decoder's chain of dependent
// values waited for the frame's square roots and divisions.
constexpr size_t kChunk = 64;  // even: each chunk starts with rANS state 0
static_assert(kChunk == kGridGroup, "the decoder's chunks are mode 4's groups");

// A vertex's frame in role order (role r is axis axes[r]), with the quantizer's origin on those
// axes: the coordinate loop indexes nothing by axis but the vertex it writes.
struct RoleFrame {
    double midpoint[3], normal[3], origin[3];
    int axes[3];
    bool has_normal;
};

struct Chunk {
    size_t begin = 0, count = 0;
    const FrameCorners* corners = nullptr;  // the chunk's: `own`, or the source's list itself
    std::array<FrameCorners, kChunk> own;
    std::array<VertexId, kChunk> vertices;
    std::array<RoleFrame, kChunk> frames;
    std::array<GridPrediction, kChunk> first;  // mode 4: role 0's
};

// Hints the processor to fetch node n of the hierarchy the mesh reads.
AMC_ALWAYS_INLINE void prefetch_node(const Hierarchy& h, NodeId n) { HierarchyBuilder::prefetch(h, n); }
AMC_ALWAYS_INLINE void prefetch_node(const HierarchyOnGrid& h, NodeId n) { HierarchyBuilder::prefetch(h.nodes(), n); }

// Where the vertices and their frame corners come from: (node, edge) pairs, read in the hierarchy,
// or split_level's list (vertices first, first + 1, ...).
// get(c) sets the corners and vertices of chunk c's c.count vertices from c.begin.
template <class Mesh>
struct FromNodes {
    const Mesh& h;
    const std::vector<std::pair<NodeId, int>>& created;
    size_t size() const { return created.size(); }
    bool appends(const Hierarchy&) const { return false; }
    // The encoder visits a level's nodes in the base coder's root order, which is not the input's:
    // nearly every node read misses the cache. So the reads go in stages, each over the whole chunk:
    // the next chunk's nodes are fetched ahead, then this chunk's centre children and neighbours
    // (known from its nodes), then their vertices are read, many misses in flight at once.
    void get(Chunk& c) const {
        const size_t next_end = std::min(created.size(), c.begin + 2 * kChunk);
        for (size_t i = c.begin + c.count; i < next_end; ++i) prefetch_node(h, created[i].first);
        for (size_t i = 0; i < c.count; ++i) {
            const auto [n, e] = created[c.begin + i];
            prefetch_node(h, h.child(n, red_split::kCenter));
            const NodeId q = h.neighbor(n, e);
            if (q != kNoNode) prefetch_node(h, q);
        }
        for (size_t i = 0; i < c.count; ++i) {
            const auto [n, e] = created[c.begin + i];
            c.own[i] = frame_corners(h, n, e);
            c.vertices[i] = h.midpoint(n, e);
        }
        c.corners = c.own.data();
    }
};
struct FromList {
    NewVertexCorners& corners;  // taken in order, a chunk at a time
    size_t size() const { return corners.size(); }
    VertexId first() const { return corners.first(); }
    // The positions do not exist yet (HierarchyBuilder::append_positions).
    bool appends(const Hierarchy& h) const { return first() == h.positions().size(); }
    void get(Chunk& c) const {
        c.corners = corners.next(c.count);  // read where they are: no copy
        for (size_t i = 0; i < c.count; ++i) c.vertices[i] = first() + VertexId(c.begin + i);
    }
};
static_assert(kChunk <= NewVertexCorners::kRun, "a chunk's corners come in one run");

// Chunk c: vertices begin .. end - 1 of `source`, at most kChunk.
template <class Mesh, class Source>
void gather_chunk(const Mesh& h, const Source& source, size_t begin, size_t end, Chunk& c) {
    c.begin = begin;
    c.count = begin < end ? std::min(kChunk, end - begin) : 0;
    source.get(c);
    const Vec3* positions = h.positions().data();
    for (size_t i = 0; i < c.count; ++i) {  // a, b and c are always vertices
        const FrameCorners& k = c.corners[i];
        __builtin_prefetch(positions + k.a);
        __builtin_prefetch(positions + k.b);
        __builtin_prefetch(positions + k.c);
        if (k.d != kNoVertex) __builtin_prefetch(positions + k.d);
    }
}

// Vertex i's frame in role order.
template <bool Grid>
AMC_ALWAYS_INLINE void role_frame(const NormalFrame& frame, const Quantizer* quantizer, const GridScale& grid, Chunk& c,
                                  size_t i) {
    const std::array<int, 3> axes = role_axes(frame);
    RoleFrame& f = c.frames[i];
    // Indexed by axis, without axis_coordinate's selects.
    const double midpoint[3] = {frame.midpoint.x, frame.midpoint.y, frame.midpoint.z};
    const double normal[3] = {frame.normal.x, frame.normal.y, frame.normal.z};
    const double origin[3] = {quantizer != nullptr ? quantizer->origin.x : 0.0, quantizer != nullptr ? quantizer->origin.y : 0.0,
                              quantizer != nullptr ? quantizer->origin.z : 0.0};
    for (int r = 0; r < 3; ++r) {
        f.axes[r] = axes[size_t(r)];
        f.midpoint[r] = midpoint[axes[size_t(r)]];
        f.normal[r] = normal[axes[size_t(r)]];
        f.origin[r] = origin[axes[size_t(r)]];
    }
    f.has_normal = frame.has_normal;
    if (Grid) c.first[i] = grid_prediction_at(grid, f.origin[0], f.midpoint[0]);
}

// The chunk's frames in role order, two at a time where SSE2 computes two frames at once.
template <bool Grid, bool UnitNormals, class Mesh>
AMC_ALWAYS_INLINE void frame_chunk(const Mesh& h, const Quantizer* quantizer, const GridScale& grid, Chunk& c) {
    size_t i = 0;
#if AMC_SSE2
    if (!h.single_precision()) {
        for (; i + 1 < c.count; i += 2) {
            NormalFrame f0, f1;
            frame_pair_of<UnitNormals>(h, c.corners[i], c.corners[i + 1], f0, f1);
            role_frame<Grid>(f0, quantizer, grid, c, i);
            role_frame<Grid>(f1, quantizer, grid, c, i + 1);
        }
    }
#endif
    for (; i < c.count; ++i) role_frame<Grid>(frame_of<UnitNormals>(h, c.corners[i]), quantizer, grid, c, i);
}

// NormalFrame::predict in role order: roles 1 and 2's predictions once role 0's value is known.
AMC_ALWAYS_INLINE void predict_others(const RoleFrame& f, double first_value, double& second, double& third) {
    if (!f.has_normal) {
        second = f.midpoint[1];
        third = f.midpoint[2];
        return;
    }
    const double t = rounded((first_value - f.midpoint[0]) / f.normal[0]);
    second = f.midpoint[1] + rounded(t * f.normal[1]);
    third = f.midpoint[2] + rounded(t * f.normal[2]);
}

// ---- the fast paths' tables and streams ---------------------------------------------------------
//
// The float64 stencil decoder (modes 6 and 7, static_stencil_decoder.cpp) and the listed decoders
// (modes 3-5, static_frame_decoder.cpp) decode with the streams' state in the loop's own variables:
// a token's rANS range and what it gives the residual in one table entry (no arithmetic on the
// token), the raw bits read by one unaligned load at a bit position, without a bounds test where the
// chunk cannot reach the streams' ends.

// A token of one table: its rANS range, and the residual it gives from the raw bits w at the
// stream's position (sign in bit 0, then the low bits): magnitude = high | (w >> shift) & low_mask
// | (w << 31) & swapped_mask, negative = w & sign_mask. The last term is take_large's two raw values
// swapped back when low > 32: the rot = low - 32 bits after the sign are the magnitude's bits 32 and
// up, shift = 1 + rot. A direct token reads no bits (all masks 0) and its high is its residual.
struct StencilEntry {
    uint64_t high;          // the leading one and the two bits below it; a direct token's residual
    uint64_t low_mask;      // 2^min(low, 32) - 1
    uint64_t swapped_mask;  // (2^rot - 1) << 32
    uint16_t frequency, start;
    uint8_t raw_count;  // the sign and the low bits; above kMaxRawRead: two reads (take_large's else)
    uint8_t shift;      // 1 + rot
    uint8_t sign_mask;  // 1, or 0 for a direct token
};
constexpr int kMaxRawRead = 57;
struct StencilTable {
    std::array<StencilEntry, 256> entries;
    std::array<uint8_t, kRansScale> index;  // per slot, the entry (RansTable::narrow_view's), copied beside them
};

// From a narrow table (narrow_view().index != nullptr): its entries are its nonzero frequencies
// in symbol order (RansTable::build_slots).
inline void make_stencil_table(const RansTable& table, StencilTable& out) {
    std::copy_n(table.narrow_view().index, kRansScale, out.index.begin());
    size_t i = 0;
    for (int token = 0; token < table.size(); ++token) {
        if (table.frequency(token) == 0) continue;
        StencilEntry& e = out.entries[i++];
        const uint16_t frequency = uint16_t(table.frequency(token)), start = uint16_t(table.start(token));
        if (token < kDirectTokens) {
            // take()'s direct tokens: magnitude (token + 1) / 2, negative when even and not 0.
            const uint64_t magnitude = uint64_t(token + 1) / 2;
            e = {token != 0 && token % 2 == 0 ? 0 - magnitude : magnitude, 0, 0, frequency, start, 0, 0, 0};
            continue;
        }
        const int low = 4 + (token - kDirectTokens) / 4 - 3;
        const int rot = low > 32 ? low - 32 : 0;
        e.high = uint64_t(4 | ((token - kDirectTokens) & 3)) << low;
        e.low_mask = (uint64_t{1} << std::min(low, 32)) - 1;
        e.swapped_mask = ((uint64_t{1} << rot) - 1) << 32;
        e.frequency = frequency;
        e.start = start;
        e.raw_count = uint8_t(1 + low);
        e.shift = uint8_t(1 + rot);
        e.sign_mask = 1;
    }
}

// The rANS and raw streams of a level, read without bounds tests: each decoder pads the streams'
// tails (PaddedTails) so that its chunks' reads stay inside.
struct StencilStreams {
    uint32_t x[2];
    const uint8_t* rans;
    const uint8_t* rans_end;
    const uint8_t* raw;
    uint64_t raw_bits_read = 0;
    size_t raw_size;

    AMC_ALWAYS_INLINE uint32_t rans_byte() { return *rans++; }
    // kMaxRawRead bits or more from bit `position` of the raw stream on (bit 0 first).
    AMC_ALWAYS_INLINE uint64_t raw_peek(uint64_t position) const {
        return load_le64(raw + size_t(position >> 3)) >> unsigned(position & 7);
    }
    // The next token of state State, under `table`, as the residual it gives modulo 2^64: what
    // it adds to the prediction's ordered bits.
    template <int State>
    AMC_ALWAYS_INLINE uint64_t residual(const StencilTable& table) {
        uint32_t& s = x[State];
        const uint32_t slot = s & (kRansScale - 1);
        const StencilEntry& e = table.entries[table.index[slot]];
        s = uint32_t(e.frequency) * (s >> kRansScaleBits) + slot - e.start;
        // At most two bytes: s >= 2^11 here (s >= L before, a frequency >= 1).
        if (s < kRansLow) {
            s = (s << 8) | rans_byte();
            if (s < kRansLow) s = (s << 8) | rans_byte();
        }
        const uint64_t at = raw_bits_read;
        const uint64_t w = raw_peek(at);
        raw_bits_read += e.raw_count;
        uint64_t negative, magnitude;
        if (e.raw_count <= kMaxRawRead) {
            negative = w & e.sign_mask;
            magnitude = e.high | ((w >> e.shift) & e.low_mask) | ((w << 31) & e.swapped_mask);
        } else {  // take_large's two reads: the sign and low - 32 bits, then 32 bits
            const int first = e.raw_count - 32;
            negative = w & 1;
            magnitude = e.high | ((w >> 1) & ((uint64_t{1} << (first - 1)) - 1)) << 32 |
                        (raw_peek(at + uint64_t(first)) & 0xFFFFFFFFull);
        }
        return (magnitude ^ (0 - negative)) + negative;  // -magnitude when negative
    }
    bool ended_cleanly() const {
        return x[0] == kRansLow && x[1] == kRansLow && rans == rans_end &&
               raw_bits_read <= uint64_t(raw_size) * 8 && uint64_t(raw_size) * 8 - raw_bits_read < 8;
    }
};

// The last bytes of a level's streams, copied with zeros after them once fewer remain than a chunk
// may read (Rans and Raw bytes), so that every chunk reads without a bounds test per byte, as if
// inside the streams: bytes past an end read as 0, and a chunk that went past an end makes the
// level corrupt (overran()).
template <size_t Rans, size_t Raw>
class PaddedTails {
public:
    // Before each chunk: the streams' tails moved here where they are that short.
    void pad(StencilStreams& s) {
        if (!rans_padded_ && size_t(s.rans_end - s.rans) < Rans) {
            const size_t n = size_t(s.rans_end - s.rans);
            std::memcpy(rans_, s.rans, n);
            std::memset(rans_ + n, 0, sizeof rans_ - n);
            s.rans = rans_;
            s.rans_end = rans_ + n;
            rans_padded_ = true;
        }
        const size_t at = size_t(s.raw_bits_read >> 3);  // at most raw_size (overran() after each chunk)
        if (!raw_padded_ && s.raw_size - at < Raw) {
            const size_t n = s.raw_size - at;
            if (n > 0) std::memcpy(raw_, s.raw + at, n);
            std::memset(raw_ + n, 0, sizeof raw_ - n);
            s.raw = raw_;
            s.raw_size = n;
            s.raw_bits_read -= uint64_t(at) * 8;
            raw_padded_ = true;
        }
    }
    // After each chunk: whether it read past a stream's end.
    static bool overran(const StencilStreams& s) { return s.rans > s.rans_end || s.raw_bits_read > uint64_t(s.raw_size) * 8; }

private:
    uint8_t rans_[2 * Rans], raw_[2 * Raw];
    bool rans_padded_ = false, raw_padded_ = false;
};

// The streams of a level with both rANS states read; false where the level is too short for them
// or a state is below L (no encoder ends there).
inline bool open_stencil_streams(const uint8_t* rans_data, size_t rans_size, const uint8_t* raw_data, size_t raw_size,
                          StencilStreams& s) {
    s = StencilStreams{{0, 0}, rans_data, rans_data + rans_size, raw_data, 0, raw_size};
    if (rans_size < kRansStateBytes) return false;
    for (uint32_t& x : s.x) {
        x = load_le32(s.rans);
        s.rans += 4;
        if (x < kRansLow) return false;
    }
    return true;
}

constexpr uint64_t kSign64 = uint64_t{1} << 63;
// ordered_bits and from_ordered_bits for float64 without branches (the signs are coin flips).
AMC_ALWAYS_INLINE uint64_t ordered_of(uint64_t b) { return b ^ (uint64_t(int64_t(b) >> 63) | kSign64); }
AMC_ALWAYS_INLINE uint64_t double_bits_of(uint64_t u) { return u ^ (~uint64_t(int64_t(u) >> 63) | kSign64); }
// Hierarchy::is_far's bound.
constexpr double kHalfMax = 8.98846567431157953865e307;  // DBL_MAX / 2
#if AMC_SSE2
// double_bits_of in each lane: the high word's sign shifted arithmetically over the lane
// (0xF5: words 1, 1, 3, 3); a lane of sign 1 loses it, one of sign 0 is inverted.
AMC_ALWAYS_INLINE __m128d double_lanes_of(__m128i u) {
    const __m128i negative = _mm_shuffle_epi32(_mm_srai_epi32(u, 31), 0xF5);
    const __m128i flip = _mm_andnot_si128(negative, _mm_set1_epi32(-1));  // ~negative: ones where the sign is 0
    return _mm_castsi128_pd(_mm_xor_si128(u, _mm_or_si128(flip, _mm_set1_epi64x(int64_t(kSign64)))));
}
#endif

// A grid prediction as the fast path uses it (grid_prediction_at's, made ready for its token): the
// grid point, its bin's table as a byte offset from the role's first table, and all ones where
// the residual is coded negated (the turn).
struct GridPoint {
    uint64_t point;
    uint64_t table_offset;
    int64_t turn_mask;
};

// A vertex's frame as the fast path reads it: midpoint and normal in axis order, the frame's axis
// (0 without a normal: role_axes') and role 0's grid prediction.
struct GridFrame {
    double midpoint[3], normal[3];
    GridPoint first;
    int axis;
    bool has_normal;
};

// The frame alone (mode 5's listed decoder has no grid).
AMC_ALWAYS_INLINE void set_frame(const NormalFrame& f, GridFrame& g) {
    g.midpoint[0] = f.midpoint.x;
    g.midpoint[1] = f.midpoint.y;
    g.midpoint[2] = f.midpoint.z;
    g.normal[0] = f.normal.x;
    g.normal[1] = f.normal.y;
    g.normal[2] = f.normal.z;
    g.has_normal = f.has_normal;
    g.axis = f.has_normal ? f.axis : 0;
}

// A GridFrame's axes in role order (role_axes'): its axis, then the two others in increasing order.
AMC_ALWAYS_INLINE std::array<int, 3> unit_role_axes(const GridFrame& f) {
    return {f.axis, f.axis == 0 ? 1 : 0, f.axis == 2 ? 1 : 2};
}

// predict_others over a GridFrame: roles 1 and 2's predictions (`axes` from unit_role_axes) once
// role 0's value is known.
AMC_ALWAYS_INLINE void predict_unit_others(const GridFrame& f, const std::array<int, 3>& axes, double first_value, double& second,
                                           double& third) {
    second = f.midpoint[axes[1]];
    third = f.midpoint[axes[2]];
    if (f.has_normal) {
        const double u = rounded((first_value - f.midpoint[axes[0]]) / f.normal[axes[0]]);
        second = second + rounded(u * f.normal[axes[1]]);
        third = third + rounded(u * f.normal[axes[2]]);
    }
}

// The frames of `count` vertices without a grid (mode 5's), for the encoder as its listed
// decoder makes them: four at a time where the processor has AVX2, else two (static_frame_decoder.cpp).
void make_unit_frames(const Hierarchy& h, const FrameCorners* corners, size_t count, GridFrame* frames);

// The fast paths (static_stencil_decoder.cpp, static_frame_decoder.cpp), for decode_static_positions.
template <bool Butterfly>
bool decode_stencil_float64(Hierarchy& h, const std::vector<std::pair<NodeId, int>>& created, const StaticTables& tables,
                            const uint8_t* rans_data, size_t rans_size, const uint8_t* raw_data, size_t raw_size);
template <bool Grouped>
bool decode_grid_listed_fastest(Hierarchy& h, const FromList& created, const Quantizer& quantizer, const StaticTables& tables,
                                const uint8_t* rans_data, size_t rans_size, const uint8_t* raw_data, size_t raw_size);
template <bool Float32, bool UnitNormals>
bool decode_unit_listed_fastest(Hierarchy& h, const FromList& created, const StaticTables& tables, const uint8_t* rans_data,
                                size_t rans_size, const uint8_t* raw_data, size_t raw_size);

}  // namespace amc::static_geometry
