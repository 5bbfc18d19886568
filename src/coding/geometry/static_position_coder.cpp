// The static geometry mode of a level; see static_position_coder.h and docs/FORMAT.md 5.6.
#include "coding/geometry/static_position_coder.h"

#include "common/compiler.h"

#include "coding/geometry/geometry_prediction.h"
#include "coding/geometry/hierarchy_on_grid.h"
#include "common/bits.h"
#include "common/compiler.h"
#include "common/exact_float.h"
#include "common/little_endian.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <string>
#include <type_traits>

namespace amc {

namespace {

constexpr int kDirectTokens = 15;     // tokens 0 .. 14: magnitudes 0 .. 7 with their sign
constexpr int kMaxGammaLength = 12;   // table values are below 2^13
constexpr int kTokensFor64Bits = kDirectTokens + 4 * (64 - 4) + 4;
// StaticLevelEncoder's symbol words: the table above the token's bits.
constexpr int kTokenBits = 9;
static_assert(kTokensFor64Bits <= (1 << kTokenBits) && kMaxStaticTables << kTokenBits <= 0xFFFF, "a symbol fits 16 bits");

// The largest bit length a residual can have in the space.
int max_residual_bits(CoordinateSpace space) {
    if (space.quantizer != nullptr) return space.quantizer->bits;
    return space.precision == Precision::float32 ? 32 : 64;
}
// Tokens 0 .. token_limit(space) - 1 are possible.
int token_limit(CoordinateSpace space) {
    const int k = max_residual_bits(space);
    return k < 4 ? 2 * ((1 << k) - 1) + 1 : kDirectTokens + 4 * (k - 4) + 4;
}
static_assert(kTokensFor64Bits <= kRansMaxSymbols, "every token fits a table");

// The axes in coding order: the frame's axis, then the two others in increasing order.
std::array<int, 3> role_axes(const NormalFrame& f) {
    static constexpr std::array<std::array<int, 3>, 3> kByAxis{{{0, 1, 2}, {1, 0, 2}, {2, 0, 1}}};
    return kByAxis[f.has_normal ? size_t(f.axis) : 0];
}

using Residual = StaticResidual;

// ---- one coordinate: residual against a prediction, and back -----------------------------------

Residual residual_of(CoordinateSpace space, int axis, double actual, double predicted) {
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
GridScale grid_scale(const Quantizer* quantizer) {
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

void put_raw(RawBitWriter& raw, Residual r) {
    if (r.magnitude < 8) return;
    const int low = bit_length(r.magnitude) - 3;
    // The sign and the first value in one put (take_large reads them in one get); put's mask drops
    // the magnitude's three leading bits, which the token holds.
    const uint64_t sign = r.negative ? 1 : 0;
    if (low > 56) {
        raw.put((r.magnitude >> 32) << 1 | sign, low - 31);
        raw.put(r.magnitude & 0xFFFFFFFFull, 32);
        return;
    }
    // Up to 57 bits in one put, the two values of low > 32 side by side as take_large reads them;
    // without a branch on low, which bit-exact residuals put on both sides of 32 by turns.
    const int rot = std::max(low - 32, 0);
    const uint64_t first = (r.magnitude >> (32 & -int(rot > 0))) << 1 | sign;  // the magnitude itself when low <= 32
    const uint64_t first_bits = rot > 0 ? first & ((uint64_t{2} << rot) - 1) : first;
    raw.put(first_bits | (rot > 0 ? (r.magnitude & 0xFFFFFFFFull) << (rot + 1) : 0), low + 1);
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

void put_gamma(ArithmeticEncoder& encoder, std::array<BitModel, kMaxGammaLength + 1>& models, uint32_t v) {
    const int length = bit_length(v) - 1;  // v >= 1
    for (int i = 0; i < length; ++i) encoder.encode(true, models[size_t(i)]);
    if (length < kMaxGammaLength) encoder.encode(false, models[size_t(length)]);
    encoder.encode_bits_raw(v & ((uint32_t{1} << length) - 1), length);
}

uint32_t get_gamma(ArithmeticDecoder& decoder, std::array<BitModel, kMaxGammaLength + 1>& models) {
    int length = 0;
    while (length < kMaxGammaLength && decoder.decode(models[size_t(length)])) ++length;
    return (uint32_t{1} << length) | decoder.decode_bits_raw(length);
}

void put_table(ArithmeticEncoder& encoder, TableModels& models, const RansTable& table) {
    std::vector<int> used;
    for (int s = 0; s < table.size(); ++s)
        if (table.frequency(s) != 0) used.push_back(s);
    put_gamma(encoder, models.count, uint32_t(used.size()));
    int previous = -1;
    for (int s : used) {
        put_gamma(encoder, models.gap, uint32_t(s - previous));
        previous = s;
    }
    for (size_t i = 0; i + 1 < used.size(); ++i) put_gamma(encoder, models.frequency, table.frequency(used[i]));
}

bool get_table(ArithmeticDecoder& decoder, TableModels& models, int limit, RansTable& table) {
    const uint32_t used = get_gamma(decoder, models.count);
    if (used < 2 || used > uint32_t(limit)) return false;  // a table has two symbols at least
    std::vector<int> symbols;
    int previous = -1;
    for (uint32_t i = 0; i < used; ++i) {
        previous += int(get_gamma(decoder, models.gap));
        if (previous >= limit) return false;
        symbols.push_back(previous);
    }
    std::vector<uint32_t> frequencies(size_t(symbols.back()) + 1, 0);
    uint32_t sum = 0;
    for (uint32_t i = 0; i + 1 < used; ++i) {
        const uint32_t f = get_gamma(decoder, models.frequency);
        frequencies[size_t(symbols[i])] = f;
        sum += f;
        if (sum >= kRansScale) return false;
    }
    frequencies[size_t(symbols.back())] = kRansScale - sum;
    return table.assign(frequencies);
}

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

}  // namespace

// Both without branches: whether a residual is 0, small or large is a coin flip on surfaces.
int static_token(bool negative, uint64_t magnitude) {
    const int small = int(2 * magnitude - 1 + (negative ? 1 : 0)) & -int(magnitude != 0);
    const int k = bit_length(magnitude | 8);
    const int large = kDirectTokens + 4 * (k - 4) + int((magnitude >> (k - 3)) & 3);
    return magnitude < 8 ? small : large;
}

int static_raw_bit_count(uint64_t magnitude) { return magnitude < 8 ? 0 : bit_length(magnitude) - 2; }

template <class Mesh>
StaticLevelEncoder::StaticLevelEncoder(const Mesh& h, const std::vector<std::pair<NodeId, int>>& created,
                                       CoordinateSpace space, GeometryPredictor mode, bool streams, StaticOrder order,
                                       StaticEncoderBuffers* buffers)
    : StaticLevelEncoder(h, created, created.size(), space, mode, order, buffers) {
    if (streams) code_streams();
}

template <class Mesh>
StaticLevelEncoder::StaticLevelEncoder(const Mesh& h, const std::vector<std::pair<NodeId, int>>& created, size_t count,
                                       CoordinateSpace space, GeometryPredictor mode, StaticOrder order,
                                       StaticEncoderBuffers* buffers, size_t stream_byte_limit)
    : mode_(mode), grouped_(has_grid_bins(mode) && order == StaticOrder::grouped), space_(space),
      table_count_(static_table_count(mode)) {
    if (!is_static_mode(mode)) throw Error("StaticLevelEncoder: geometry mode " + std::to_string(int(mode)) + " is not a static mode");
    if (has_grid_bins(mode) && space.quantizer == nullptr) throw Error("geometry mode 4 needs quantized coordinates");
    if (has_stencil_tables(mode) && space.quantizer != nullptr)
        throw Error("geometry modes 6 and 7 need bit-exact coordinates");
    if (buffers != nullptr) {
        StaticEncoderBuffers::Set set = buffers->take();
        buffers_ = buffers;
        symbols_ = std::move(set.symbols);
        symbols_.clear();
        large_ = std::move(set.large);
        large_.clear();
        raw_writer_.adopt(std::move(set.raw));
        rans_ = std::move(set.rans);
        rans_.clear();
        rans_memory_ = std::move(set.rans_memory);
        counts_ = std::move(set.counts);
        for (std::vector<uint64_t>& counts : counts_) counts.clear();  // add() zeroes them
    }
    count = std::min(count, created.size());
    // A sample's raw bits wait in large_ (see the header): the mode choice drops most samples.
    deferred_ = !grouped_ && count < created.size();
    if (stream_byte_limit == SIZE_MAX) {
        add(h, created, 0, count);
    } else {
        // In steps, with the room for the whole count made first (add() reserves by the part before).
        constexpr size_t kStep = 4 * kChunk;
        symbols_.reserve(count);
        if (space.quantizer == nullptr && (deferred_ || grouped_)) large_.reserve(size_t(kStaticRoles) * count);
        for (size_t begin = 0; begin < count && !gave_up_; begin += kStep) {
            add(h, created, begin, std::min(count, begin + kStep));
            if (begin + kStep >= count) break;
            // The raw bits' part first; the tokens' entropy (a pass over the counts) once it is half way.
            const size_t raw_part = kRansStateBytes + size_t(raw_bits_ / 8);
            gave_up_ = raw_part > stream_byte_limit ||
                       (2 * raw_part > stream_byte_limit && stream_bound_below(uint64_t(kStaticRoles) * count) > stream_byte_limit);
        }
        if (gave_up_) return;
    }
    make_tables();
}

StaticLevelEncoder::~StaticLevelEncoder() {
    if (buffers_ == nullptr) return;
    StaticEncoderBuffers::Set set;
    set.symbols = std::move(symbols_);
    set.large = std::move(large_);
    set.raw = coded_ ? std::move(raw_) : raw_writer_.finish();
    set.rans = std::move(rans_);
    set.rans_memory = std::move(rans_memory_);
    set.counts = std::move(counts_);
    try {
        buffers_->give_back(std::move(set));
    } catch (...) {  // no room to keep them: they are freed
    }
}

template <class Mesh>
void StaticLevelEncoder::extend(const Mesh& h, const std::vector<std::pair<NodeId, int>>& created) {
    if (coded_) throw Error("StaticLevelEncoder::extend: the streams are coded already");
    write_deferred_raw_bits(created.size());
    add(h, created, symbols_.size(), created.size());
    make_tables();
}

template <class Mesh>
void StaticLevelEncoder::add(const Mesh& h, const std::vector<std::pair<NodeId, int>>& created, size_t begin, size_t end) {
    if (counts_[0].empty())
        for (int i = 0; i < table_count_; ++i) counts_[size_t(i)].assign(size_t(token_limit(space_)), 0);
    symbols_.resize(end);
    // Room for the raw bits (grown by doubling they were copied again and again), at the rate of
    // the part before (a little more: the writer zero-fills what it reserves as it starts to use
    // it), or at first in float spaces, where nearly every coordinate has some, 64 a coordinate.
    const bool keep_large = grouped_ || deferred_;
    if (begin > 0) {
        const double share = double(end - begin) / double(begin);
        if (keep_large) large_.reserve(large_.size() + size_t(double(large_.size()) * share));
        else raw_writer_.reserve_bits(uint64_t(double(raw_writer_.bits()) * share * 1.125) + 4096);
    } else if (space_.quantizer == nullptr) {
        if (deferred_) large_.reserve(size_t(kStaticRoles) * (end - begin));
        else raw_writer_.reserve_bits(uint64_t(kStaticRoles) * 64 * (end - begin));
    }
    const bool float64 = space_.quantizer == nullptr && space_.precision == Precision::float64;
    // Modes 3 (without a quantizer), 6 and 7 are bit-exact: float64 or float32.
    switch (mode_) {
        case GeometryPredictor::normal_frame:
            if (space_.quantizer != nullptr) {
                if (keep_large) add_vertices<false, false, kGridResiduals, true>(h, created, begin, end);
                else add_vertices<false, false, kGridResiduals, false>(h, created, begin, end);
            } else if (float64) {
                if (keep_large) add_vertices<false, false, kFloat64Residuals, true>(h, created, begin, end);
                else add_vertices<false, false, kFloat64Residuals, false>(h, created, begin, end);
            } else {
                if (keep_large) add_vertices<false, false, kFloat32Residuals, true>(h, created, begin, end);
                else add_vertices<false, false, kFloat32Residuals, false>(h, created, begin, end);
            }
            break;
        case GeometryPredictor::normal_frame_grid:
            if (keep_large) add_vertices<true, true, kGridResiduals, true>(h, created, begin, end);
            else add_vertices<true, true, kGridResiduals, false>(h, created, begin, end);
            break;
        case GeometryPredictor::midpoint_static:
            if (float64) {
                if (keep_large) add_stencil_vertices<false, kFloat64Residuals, true>(h, created, begin, end);
                else add_stencil_vertices<false, kFloat64Residuals, false>(h, created, begin, end);
            } else {
                if (keep_large) add_stencil_vertices<false, kFloat32Residuals, true>(h, created, begin, end);
                else add_stencil_vertices<false, kFloat32Residuals, false>(h, created, begin, end);
            }
            break;
        case GeometryPredictor::butterfly_static:
            if (float64) {
                if (keep_large) add_stencil_vertices<true, kFloat64Residuals, true>(h, created, begin, end);
                else add_stencil_vertices<true, kFloat64Residuals, false>(h, created, begin, end);
            } else {
                if (keep_large) add_stencil_vertices<true, kFloat32Residuals, true>(h, created, begin, end);
                else add_stencil_vertices<true, kFloat32Residuals, false>(h, created, begin, end);
            }
            break;
        default:
            if constexpr (std::is_same_v<Mesh, Hierarchy>) {
                // Bit-exact in the hierarchy's own precision: every bit-exact level.
                if (space_.quantizer == nullptr && float64 != h.single_precision()) {
                    if (float64) {
                        if (keep_large) add_unit_vertices<false, true>(h, created, begin, end);
                        else add_unit_vertices<false, false>(h, created, begin, end);
                    } else {
                        if (keep_large) add_unit_vertices<true, true>(h, created, begin, end);
                        else add_unit_vertices<true, false>(h, created, begin, end);
                    }
                    break;
                }
            }
            if (float64) {
                if (keep_large) add_vertices<true, false, kFloat64Residuals, true>(h, created, begin, end);
                else add_vertices<true, false, kFloat64Residuals, false>(h, created, begin, end);
            } else if (space_.quantizer == nullptr) {
                if (keep_large) add_vertices<true, false, kFloat32Residuals, true>(h, created, begin, end);
                else add_vertices<true, false, kFloat32Residuals, false>(h, created, begin, end);
            } else {
                if (keep_large) add_vertices<true, false, kAnyResiduals, true>(h, created, begin, end);
                else add_vertices<true, false, kAnyResiduals, false>(h, created, begin, end);
            }
            break;
    }
}

template <bool KeepLarge>
AMC_ALWAYS_INLINE void StaticLevelEncoder::take_residual(const Residual& r, int table, uint16_t& symbol, uint64_t& raw_bits) {
    const int token = static_token(r.negative, r.magnitude);
    if (token >= kDirectTokens) {  // the raw bits of a large residual: grouped order keeps them for code_streams
        if (KeepLarge) large_.push_back(r);
        else put_raw(raw_writer_, r);
    }
    symbol = uint16_t(table << kTokenBits | token);
    raw_bits += uint64_t(static_raw_bit_count(r.magnitude));
    ++counts_[size_t(table)][size_t(token)];
}

// The loop of add() for one mode: the frame's kind, the table split and the residuals' kind known when it is compiled.
// A chunk's corners and frames as the decoder makes them (gather_chunk, frame_chunk), then each
// vertex's residuals in role order.
template <bool UnitNormals, bool GridBins, int Residuals, bool KeepLarge, class Mesh>
void StaticLevelEncoder::add_vertices(const Mesh& h, const std::vector<std::pair<NodeId, int>>& created, size_t begin,
                                      size_t end) {
    const CoordinateSpace space = space_;
    const Quantizer* quantizer = space.quantizer;
    const GridScale grid = grid_scale(quantizer);
    uint64_t raw_bits = 0;
    Chunk c;
    for (size_t first = begin; first < end; first += kChunk) {
        gather_chunk(h, FromNodes<Mesh>{h, created}, first, end, c);
        for (size_t i = 0; i < c.count; ++i) __builtin_prefetch(&h.positions()[c.vertices[i]]);
        frame_chunk<GridBins, UnitNormals>(h, quantizer, grid, c);
        for (size_t i = 0; i < c.count; ++i) {
            const RoleFrame& f = c.frames[i];
            const Vec3 p = h.position(c.vertices[i]);
            const double actual[3] = {p.x, p.y, p.z};
            double predicted[3] = {f.midpoint[0], 0, 0};
            predict_others(f, actual[f.axes[0]], predicted[1], predicted[2]);
            std::array<uint16_t, kStaticRoles>& symbols = symbols_[first + i];
            for (int role = 0; role < kStaticRoles; ++role) {
                const int axis = f.axes[role];
                Residual r;
                int table = role;
                if (GridBins) {
                    const GridPrediction g = role == 0 ? c.first[i] : grid_prediction_at(grid, f.origin[role], predicted[role]);
                    r = grid_residual(grid_point_of_grid_value(grid, f.origin[role], actual[axis]), g);
                    table = kGridBins * role + g.bin;
                } else if (Residuals == kFloat64Residuals) {
                    r = float64_residual(actual[axis], predicted[role]);
                } else if (Residuals == kFloat32Residuals) {
                    r = float32_residual(actual[axis], predicted[role]);
                } else if (Residuals == kGridResiduals) {  // residual_of's grid points, with the level's GridScale
                    const uint32_t a = grid_point_of_grid_value(grid, f.origin[role], actual[axis]);
                    const uint32_t q = grid_point_at(grid, f.origin[role], predicted[role]);
                    r = {a < q, a < q ? uint64_t(q - a) : uint64_t(a - q)};
                } else {
                    r = residual_of(space, axis, actual[axis], predicted[role]);
                }
                take_residual<KeepLarge>(r, table, symbols[size_t(role)], raw_bits);
            }
        }
    }
    raw_bits_ += raw_bits;
}

template <bool Butterfly, int Residuals, bool KeepLarge, class Mesh>
void StaticLevelEncoder::add_stencil_vertices(const Mesh& h, const std::vector<std::pair<NodeId, int>>& created, size_t begin,
                                              size_t end) {
    uint64_t raw_bits = 0;
    for (size_t i = begin; i < end; ++i) {
        const auto [n, e] = created[i];
        const Vec3 q = Butterfly ? predict_butterfly(h, n, e) : predict_midpoint(h, n, e);
        const Vec3 p = h.position(h.midpoint(n, e));
        const double actual[3] = {p.x, p.y, p.z}, predicted[3] = {q.x, q.y, q.z};
        std::array<uint16_t, kStaticRoles>& symbols = symbols_[i];
        for (int axis = 0; axis < 3; ++axis) {
            const Residual r = Residuals == kFloat64Residuals   ? float64_residual(actual[axis], predicted[axis])
                               : Residuals == kFloat32Residuals ? float32_residual(actual[axis], predicted[axis])
                                                                : residual_of(space_, axis, actual[axis], predicted[axis]);
            take_residual<KeepLarge>(r, axis, symbols[size_t(axis)], raw_bits);  // never grouped
        }
    }
    raw_bits_ += raw_bits;
}

// The encoder reads a hierarchy or the input's nodes with its grid points (hierarchy_on_grid.h).
template StaticLevelEncoder::StaticLevelEncoder(const Hierarchy&, const std::vector<std::pair<NodeId, int>>&, CoordinateSpace,
                                                GeometryPredictor, bool, StaticOrder, StaticEncoderBuffers*);
template StaticLevelEncoder::StaticLevelEncoder(const HierarchyOnGrid&, const std::vector<std::pair<NodeId, int>>&,
                                                CoordinateSpace, GeometryPredictor, bool, StaticOrder, StaticEncoderBuffers*);
template StaticLevelEncoder::StaticLevelEncoder(const Hierarchy&, const std::vector<std::pair<NodeId, int>>&, size_t,
                                                CoordinateSpace, GeometryPredictor, StaticOrder, StaticEncoderBuffers*, size_t);
template StaticLevelEncoder::StaticLevelEncoder(const HierarchyOnGrid&, const std::vector<std::pair<NodeId, int>>&, size_t,
                                                CoordinateSpace, GeometryPredictor, StaticOrder, StaticEncoderBuffers*, size_t);
template void StaticLevelEncoder::extend(const Hierarchy&, const std::vector<std::pair<NodeId, int>>&);
template void StaticLevelEncoder::extend(const HierarchyOnGrid&, const std::vector<std::pair<NodeId, int>>&);

void StaticLevelEncoder::make_tables() {
    coded_table_bytes_ = SIZE_MAX;
    token_bits_ = 0;
    token_count_ = 0;
    for (int i = 0; i < table_count_; ++i) {
        // The counts up to the largest token seen: the table's size.
        const std::vector<uint64_t>& all = counts_[size_t(i)];
        size_t size = all.size();
        while (size > 0 && all[size - 1] == 0) --size;
        std::vector<uint64_t> c(all.begin(), all.begin() + std::ptrdiff_t(size));
        const bool used = !c.empty();
        if (!used) c.push_back(1);  // a table no token uses still needs a symbol
        tables_[size_t(i)] = RansTable::for_encoding(c);
        for (size_t t = 0; used && t < c.size(); ++t) {
            if (c[t] == 0) continue;
            // Rounded before the sum: a fused multiply-add could tip the mode choice between builds.
            token_bits_ += rounded(double(c[t]) * tables_[size_t(i)].cost_bits(int(t)));
            token_count_ += c[t];
        }
    }
}

void StaticLevelEncoder::write_deferred_raw_bits(size_t level_size) {
    if (!deferred_) return;
    // Room for the level at the sample's rate (a little more, as add() reserves for an extension).
    const double share = symbols_.empty() ? 1.0 : double(level_size) / double(symbols_.size());
    raw_writer_.reserve_bits(uint64_t(double(raw_bits_) * share * 1.125) + 4096);
    for (const Residual& r : large_) put_raw(raw_writer_, r);
    empty_out(large_);
    deferred_ = false;
}

void StaticLevelEncoder::code_streams() {
    if (coded_) return;
    write_deferred_raw_bits(symbols_.size());
    constexpr uint16_t kTokenMask = (1 << kTokenBits) - 1;
    // The rANS stream back to front, straight from the symbol words (rANS codes backwards).
    RansBackwardEncoder rans(kStaticRoles * symbols_.size(), rans_memory_);
    static_assert(sizeof(symbols_[0]) == kStaticRoles * sizeof(uint16_t), "symbol words are contiguous");
    const uint16_t* words = reinterpret_cast<const uint16_t*>(symbols_.data());
    const RansTable::Coding* codings[kMaxStaticTables];
    for (int i = 0; i < table_count_; ++i) codings[i] = tables_[size_t(i)].codings();
    auto coding = [&](uint16_t word) -> const RansTable::Coding& { return codings[word >> kTokenBits][word & kTokenMask]; };
    if (!grouped_) {
        // The symbol words one after the other (vertex after vertex, role after role).
        rans.put_all(kStaticRoles * symbols_.size(), [&](size_t j) -> const RansTable::Coding& { return coding(words[j]); });
    } else {
        // Each run: its role-0 tokens, then each vertex's roles 1 and 2 (FORMAT.md 5.7); the runs backwards.
        for (size_t run = (symbols_.size() + kGridGroup - 1) / kGridGroup; run-- > 0;) {
            const size_t begin = run * kGridGroup, count = std::min(kGridGroup, symbols_.size() - begin);
            const uint16_t* run_words = words + kStaticRoles * begin;
            rans.put_all(kStaticRoles * count, [&](size_t j) -> const RansTable::Coding& {
                if (j < count) return coding(run_words[kStaticRoles * j]);
                const size_t k = j - count;  // vertex k / 2, role 1 + k % 2
                return coding(run_words[kStaticRoles * (k >> 1) + 1 + (k & 1)]);
            });
        }
    }
    rans.finish(rans_);
    // The raw bits front to back, in the tokens' order (written as they came unless grouped).
    RawBitWriter& raw = raw_writer_;
    if (grouped_ && !large_.empty()) {
        raw.reserve_bits(raw_bits_);
        size_t next_large = 0;
        for (size_t begin = 0; begin < symbols_.size(); begin += kGridGroup) {
            const size_t count = std::min(kGridGroup, symbols_.size() - begin);
            size_t large[kGridGroup][kStaticRoles];  // each token's residual in large_, kept in the per-vertex order
            for (size_t i = 0; i < count; ++i)
                for (int role = 0; role < kStaticRoles; ++role) {
                    large[i][role] = next_large;
                    next_large += (symbols_[begin + i][size_t(role)] & kTokenMask) >= kDirectTokens;
                }
            auto put_raw_of = [&](size_t i, int role) {
                if ((symbols_[begin + i][size_t(role)] & kTokenMask) >= kDirectTokens) put_raw(raw, large_[large[i][role]]);
            };
            for (size_t i = 0; i < count; ++i) put_raw_of(i, 0);
            for (size_t i = 0; i < count; ++i)
                for (int role = 1; role < kStaticRoles; ++role) put_raw_of(i, role);
        }
    }
    raw_ = raw.finish();
    empty_out(symbols_);
    empty_out(large_);
    if (buffers_ == nullptr) rans_memory_ = {};
    coded_ = true;
}

void StaticLevelEncoder::write_tables(ArithmeticEncoder& encoder) const {
    TableModels models;
    for (int i = 0; i < table_count_; ++i) put_table(encoder, models, tables_[size_t(i)]);
}

size_t StaticLevelEncoder::estimated_bytes() const {
    if (!coded_) throw Error("StaticLevelEncoder::estimated_bytes: the streams are not coded yet (code_streams)");
    size_t varint = 1;
    for (size_t n = rans_.size(); n >= 128; n >>= 7) ++varint;
    return coded_table_bytes() + varint + rans_.size() + raw_.size();
}

// The rANS stream's bound. Each of its two states starts at L = 2^23 and ends below 256 L; coding
// a symbol of frequency f multiplies x by at least (M / f)(1 - 2^-11) (x / f >= 2^11 there), and
// a byte written divides it by at most 256 / (1 - 2^-11) (x >= 2^19 then). So with H the bits
// sum of log2(M / f) over its N symbols, the K bytes written satisfy 8 K >= H - 16 - 0.001 (N + K),
// and the stream is K + 8 bytes.
size_t StaticLevelEncoder::lower_bound_bytes() const { return table_bytes() + stream_bound_bytes(); }

size_t StaticLevelEncoder::table_bytes() const { return coded_table_bytes() + 1; }

size_t StaticLevelEncoder::coded_table_bytes() const {
    if (coded_table_bytes_ == SIZE_MAX) {
        ArithmeticEncoder tables;
        write_tables(tables);
        coded_table_bytes_ = tables.finish().size();
    }
    return coded_table_bytes_;
}

size_t StaticLevelEncoder::stream_bound_bytes() const {
    const double rans_bits = token_bits_ - 16 - rounded(0.001 * double(token_count_));
    const size_t rans = kRansStateBytes + (rans_bits > 0 ? size_t(rans_bits / 8.01) : 0);
    return rans + size_t(raw_bits_ / 8);
}

// The tokens so far cost at least their empirical entropy under any table (Gibbs' inequality),
// which only grows as tokens are added; the raw bits only grow. The entropy is taken a bit low, so
// that its roundings can not pass the tables' costs.
size_t StaticLevelEncoder::stream_bound_below(uint64_t tokens) const {
    double entropy = 0;
    for (int i = 0; i < table_count_; ++i) {
        const std::vector<uint64_t>& counts = counts_[size_t(i)];
        uint64_t n = 0;
        for (uint64_t c : counts) n += c;
        for (uint64_t c : counts)
            if (c != 0) entropy += rounded(double(c) * std::log2(double(n) / double(c)));
    }
    const double rans_bits = rounded(entropy * (1 - 1e-9)) - 1 - 16 - rounded(0.001 * double(tokens));
    return kRansStateBytes + (rans_bits > 0 ? size_t(rans_bits / 8.01) : 0) + size_t(raw_bits_ / 8);
}

double StaticLevelEncoder::projected_bound_bytes(double scale) const {
    return double(table_bytes()) + projected_stream_bound_bytes(scale);
}

double StaticLevelEncoder::projected_stream_bound_bytes(double scale) const { return rounded(scale * double(stream_bound_bytes())); }

bool read_static_tables(ArithmeticDecoder& decoder, CoordinateSpace space, GeometryPredictor mode, StaticTables& tables) {
    if (!is_static_mode(mode) || (has_grid_bins(mode) && space.quantizer == nullptr)) return false;
    TableModels models;
    for (int i = 0; i < static_table_count(mode); ++i)
        if (!get_table(decoder, models, token_limit(space), tables[size_t(i)])) return false;
    return true;
}

namespace {

// One vertex's three coordinates; its first token is coded with rANS state `State` (token j of the
// level with state j mod 2), its second with the other, its third with `State` again.
// Tables: StaticTables, or NarrowTables where every table is narrow.
template <int State, bool Grid, class Tables>
AMC_ALWAYS_INLINE bool decode_vertex(const Chunk& b, size_t i, CoordinateSpace space, const GridScale& grid,
                                     const Tables& tables, RansDecoder& rans, RawBitReader& raw, Vec3& p) {
    const RoleFrame& f = b.frames[i];
    double value[3], second, third;
    if (Grid) {
        const GridPrediction& first = b.first[i];
        if (!grid_value(grid, f.origin[0], first, take_signed(rans.get_with<State>(tables[size_t(first.bin)]), raw), value[0]))
            return false;
        predict_others(f, value[0], second, third);
        const GridPrediction g1 = grid_prediction_at(grid, f.origin[1], second);
        const GridPrediction g2 = grid_prediction_at(grid, f.origin[2], third);
        const int64_t r1 = take_signed(rans.get_with<1 - State>(tables[size_t(kGridBins + g1.bin)]), raw);
        if (!grid_value(grid, f.origin[1], g1, r1, value[1])) return false;
        const int64_t r2 = take_signed(rans.get_with<State>(tables[size_t(2 * kGridBins + g2.bin)]), raw);
        if (!grid_value(grid, f.origin[2], g2, r2, value[2])) return false;
    } else {
        if (!value_of(space, f.axes[0], f.midpoint[0], take(rans.get_with<State>(tables[0]), raw), value[0])) return false;
        predict_others(f, value[0], second, third);
        if (!value_of(space, f.axes[1], second, take(rans.get_with<1 - State>(tables[1]), raw), value[1])) return false;
        if (!value_of(space, f.axes[2], third, take(rans.get_with<State>(tables[2]), raw), value[2])) return false;
    }
    double xyz[3];
    for (int r = 0; r < 3; ++r) xyz[f.axes[r]] = value[r];
    p = {xyz[0], xyz[1], xyz[2]};
    return true;
}

// Mode 4's chunk b in the grouped order (version 18, FORMAT.md 5.7): the role-0 tokens of its
// vertices (vertex i with state i mod 2), then each vertex's roles 1 and 2 (states b.count mod 2
// and the other). Into p[0 .. b.count).
template <class Tables>
bool decode_grid_chunk_grouped(const Chunk& b, const GridScale& grid, const Tables& tables, RansDecoder& rans,
                               RawBitReader& raw, Vec3* p) {
    double value[kChunk][3];  // role order
    for (size_t i = 0; i < b.count; ++i) {
        const GridPrediction& first = b.first[i];
        const int token = i % 2 == 0 ? rans.get_with<0>(tables[size_t(first.bin)]) : rans.get_with<1>(tables[size_t(first.bin)]);
        if (!grid_value(grid, b.frames[i].origin[0], first, take_signed(token, raw), value[i][0])) return false;
    }
    const bool odd = b.count % 2 != 0;
    for (size_t i = 0; i < b.count; ++i) {
        const RoleFrame& f = b.frames[i];
        double second, third;
        predict_others(f, value[i][0], second, third);
        const GridPrediction g1 = grid_prediction_at(grid, f.origin[1], second);
        const GridPrediction g2 = grid_prediction_at(grid, f.origin[2], third);
        const auto& t1 = tables[size_t(kGridBins + g1.bin)];
        const auto& t2 = tables[size_t(2 * kGridBins + g2.bin)];
        const int token1 = odd ? rans.get_with<1>(t1) : rans.get_with<0>(t1);
        const int64_t r1 = take_signed(token1, raw);
        if (!grid_value(grid, f.origin[1], g1, r1, value[i][1])) return false;
        const int token2 = odd ? rans.get_with<0>(t2) : rans.get_with<1>(t2);
        const int64_t r2 = take_signed(token2, raw);
        if (!grid_value(grid, f.origin[2], g2, r2, value[i][2])) return false;
        double xyz[3];
        for (int r = 0; r < 3; ++r) xyz[f.axes[r]] = value[i][r];
        p[i] = {xyz[0], xyz[1], xyz[2]};
    }
    return true;
}

// The decoders own their rANS decoder and raw bit reader, so that the compiler keeps the two rANS
// states in registers. `grouped`: mode 4's tokens in the grouped order (version 18).
template <bool Grid, bool UnitNormals, class Source, class Tables>
bool decode_positions(Hierarchy& h, const Source& created, CoordinateSpace space, const Tables& tables,
                      const uint8_t* rans_data, size_t rans_size, const uint8_t* raw_data, size_t raw_size, bool grouped) {
    RansDecoder rans(rans_data, rans_size);
    RawBitReader raw(raw_data, raw_size);
    // The quantizer copied here: no store to the positions can change it, so its fields stay in
    // registers.
    Quantizer local_quantizer;
    if (space.quantizer != nullptr) {
        local_quantizer = *space.quantizer;
        space.quantizer = &local_quantizer;
    }
    const Quantizer* quantizer = space.quantizer;
    const GridScale grid = grid_scale(quantizer);
    // A grid value origin + rounded(q * step), 0 <= q <= max, lies between the box's corners
    // (both operations round monotonically): when they are near, every position is.
    const bool near = quantizer != nullptr && !HierarchyBuilder::is_far(quantizer->origin) &&
                      !HierarchyBuilder::is_far(dequantize(*quantizer, {quantizer->max_coordinate(), quantizer->max_coordinate(),
                                                                        quantizer->max_coordinate()}));
    auto set = [&h, near](VertexId v, Vec3 p) {
        if (near) HierarchyBuilder::set_near_vertex_position(h, v, p);
        else HierarchyBuilder::set_new_vertex_position(h, v, p);
    };
    // A listed level's positions made as they are decoded, a chunk at a time (split_level did not
    // zero them first), or set where they are.
    const bool append = created.appends(h);
    Vec3 decoded[kChunk];
    Chunk c;
    auto put = [&](size_t i, Vec3 p) {
        if (append) decoded[i] = p;
        else set(c.vertices[i], p);
    };
    for (size_t begin = 0; begin < created.size(); begin += kChunk) {
        gather_chunk(h, created, begin, created.size(), c);
        frame_chunk<Grid, UnitNormals>(h, quantizer, grid, c);
        if (Grid && grouped) {
            Vec3 p[kChunk];
            if (!decode_grid_chunk_grouped(c, grid, tables, rans, raw, p)) return false;
            for (size_t i = 0; i < c.count; ++i) put(i, p[i]);
            if (append) HierarchyBuilder::append_positions(h, decoded, c.count, near);
            continue;
        }
        for (size_t i = 0; i < c.count; i += 2) {
            Vec3 p;
            if (!decode_vertex<0, Grid>(c, i, space, grid, tables, rans, raw, p)) return false;
            put(i, p);
            if (i + 1 == c.count) break;
            if (!decode_vertex<1, Grid>(c, i + 1, space, grid, tables, rans, raw, p)) return false;
            put(i + 1, p);
        }
        if (append) HierarchyBuilder::append_positions(h, decoded, c.count, near);
    }
    return rans.ended_cleanly() && raw.ended_cleanly();
}

using NarrowTables = std::array<RansTable::NarrowView, kMaxStaticTables>;

// Modes 6 and 7: one coordinate against its prediction, with the table of its axis.
template <int State, bool Float64, class Tables>
AMC_ALWAYS_INLINE bool decode_axis(CoordinateSpace space, int axis, double predicted, const Tables& tables, RansDecoder& rans,
                                   RawBitReader& raw, double& value) {
    const Residual r = take(rans.get_with<State>(tables[size_t(axis)]), raw);
    if (!Float64) return value_of(space, axis, predicted, r, value);
    // value_of's bit-exact path for float64, without its tests of the precision.
    const uint64_t p = ordered_bits(std::isfinite(predicted) ? predicted : 0.0, Precision::float64);
    value = from_ordered_bits(r.negative ? p - r.magnitude : p + r.magnitude, Precision::float64);
    return std::isfinite(value);
}

// Vertex i of a chunk: x with rANS state `State` (token j of the level with state j mod 2), y with
// the other, z with `State` again.
template <int State, bool Float64, class Tables>
AMC_ALWAYS_INLINE bool decode_stencil_vertex(CoordinateSpace space, Vec3 predicted, const Tables& tables, RansDecoder& rans,
                                             RawBitReader& raw, Vec3& p) {
    return decode_axis<State, Float64>(space, 0, predicted.x, tables, rans, raw, p.x) &&
           decode_axis<1 - State, Float64>(space, 1, predicted.y, tables, rans, raw, p.y) &&
           decode_axis<State, Float64>(space, 2, predicted.z, tables, rans, raw, p.z);
}

// Modes 6 and 7 over (node, edge) pairs, in chunks: first the chunk's predictions (their stencils'
// loads, independent of the streams), then its coordinates from the streams.
template <bool Butterfly, bool Float64, class Tables>
bool decode_stencil_positions(Hierarchy& h, const std::vector<std::pair<NodeId, int>>& created, CoordinateSpace space,
                              const Tables& tables, const uint8_t* rans_data, size_t rans_size, const uint8_t* raw_data,
                              size_t raw_size) {
    RansDecoder rans(rans_data, rans_size);
    RawBitReader raw(raw_data, raw_size);
    std::array<Vec3, kChunk> predicted;
    std::array<VertexId, kChunk> vertices;
    for (size_t begin = 0; begin < created.size(); begin += kChunk) {
        const size_t count = std::min(kChunk, created.size() - begin);
        for (size_t i = 0; i < count; ++i) {
            const auto [n, e] = created[begin + i];
            predicted[i] = Butterfly ? predict_butterfly(h, n, e) : predict_midpoint(h, n, e);
            vertices[i] = h.midpoint(n, e);
        }
        for (size_t i = 0; i < count; i += 2) {
            Vec3 p;
            if (!decode_stencil_vertex<0, Float64>(space, predicted[i], tables, rans, raw, p)) return false;
            HierarchyBuilder::set_new_vertex_position(h, vertices[i], p);
            if (i + 1 == count) break;
            if (!decode_stencil_vertex<1, Float64>(space, predicted[i + 1], tables, rans, raw, p)) return false;
            HierarchyBuilder::set_new_vertex_position(h, vertices[i + 1], p);
        }
    }
    return rans.ended_cleanly() && raw.ended_cleanly();
}

// ---- modes 6 and 7 over float64 coordinates: the level decoder's fast path ------------------------
//
// The same stencils, tokens and streams as decode_stencil_positions, decoded with the streams'
// state in the loop's own variables: a token's rANS range and what it gives the residual in one
// table entry (no arithmetic on the token), the raw bits read by one unaligned load at a bit
// position, without a bounds test where the chunk cannot reach the streams' ends, and the
// coordinates' finiteness and farness taken once a chunk from their largest exponent.

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
void make_stencil_table(const RansTable& table, StencilTable& out) {
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
bool open_stencil_streams(const uint8_t* rans_data, size_t rans_size, const uint8_t* raw_data, size_t raw_size,
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

// A grid prediction as the fast path uses it (grid_prediction_at's, made ready for its token): the
// grid point, its bin's table as a byte offset from the role's first table, and all ones where
// the residual is coded negated (the turn).
struct GridPoint {
    uint64_t point;
    uint64_t table_offset;
    int64_t turn_mask;
};

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

template <class Tables>
bool decode_stencil_with(Hierarchy& h, const std::vector<std::pair<NodeId, int>>& created, CoordinateSpace space,
                         GeometryPredictor mode, const Tables& tables, const uint8_t* rans_data, size_t rans_size,
                         const uint8_t* raw_data, size_t raw_size) {
    if (space.quantizer != nullptr) return false;  // bit-exact files only (FORMAT.md 5.9)
    const bool butterfly = mode == GeometryPredictor::butterfly_static;
    if (space.precision == Precision::float64)
        return butterfly ? decode_stencil_positions<true, true>(h, created, space, tables, rans_data, rans_size, raw_data, raw_size)
                         : decode_stencil_positions<false, true>(h, created, space, tables, rans_data, rans_size, raw_data, raw_size);
    return butterfly ? decode_stencil_positions<true, false>(h, created, space, tables, rans_data, rans_size, raw_data, raw_size)
                     : decode_stencil_positions<false, false>(h, created, space, tables, rans_data, rans_size, raw_data, raw_size);
}

template <class Source, class Tables>
bool decode_static_with(Hierarchy& h, const Source& created, CoordinateSpace space, GeometryPredictor mode, const Tables& tables,
                        const uint8_t* rans_data, size_t rans_size, const uint8_t* raw_data, size_t raw_size, bool grouped) {
    switch (mode) {
        case GeometryPredictor::normal_frame:
            return decode_positions<false, false>(h, created, space, tables, rans_data, rans_size, raw_data, raw_size, false);
        case GeometryPredictor::unit_normal_frame:
            return decode_positions<false, true>(h, created, space, tables, rans_data, rans_size, raw_data, raw_size, false);
        case GeometryPredictor::normal_frame_grid:
            return space.quantizer != nullptr &&
                   decode_positions<true, true>(h, created, space, tables, rans_data, rans_size, raw_data, raw_size, grouped);
        default:
            return false;
    }
}

template <class Source>
bool decode_static(Hierarchy& h, const Source& created, CoordinateSpace space, GeometryPredictor mode, const StaticTables& tables,
                   const uint8_t* rans_data, size_t rans_size, const uint8_t* raw_data, size_t raw_size, bool grouped) {
    if (!is_static_mode(mode)) return false;
    NarrowTables narrow;
    bool all_narrow = true;
    for (int i = 0; i < static_table_count(mode); ++i) {
        narrow[size_t(i)] = tables[size_t(i)].narrow_view();
        all_narrow = all_narrow && narrow[size_t(i)].index != nullptr;
    }
    if constexpr (std::is_same_v<Source, FromNodes<Hierarchy>>) {
        if (has_stencil_tables(mode)) {
            if (all_narrow && space.quantizer == nullptr && space.precision == Precision::float64 && !h.single_precision()) {
                const std::vector<std::pair<NodeId, int>>& c = created.created;
                return mode == GeometryPredictor::butterfly_static
                           ? decode_stencil_float64<true>(h, c, tables, rans_data, rans_size, raw_data, raw_size)
                           : decode_stencil_float64<false>(h, c, tables, rans_data, rans_size, raw_data, raw_size);
            }
            if (all_narrow)
                return decode_stencil_with(h, created.created, space, mode, narrow, rans_data, rans_size, raw_data, raw_size);
            return decode_stencil_with(h, created.created, space, mode, tables, rans_data, rans_size, raw_data, raw_size);
        }
    } else if (has_stencil_tables(mode)) {
        return false;  // a listed level has frame corners, not the stencils' nodes
    }
    if constexpr (std::is_same_v<Source, FromList>) {
        if (all_narrow && mode == GeometryPredictor::normal_frame_grid && space.quantizer != nullptr && !h.single_precision())
            return grouped ? decode_grid_listed_fastest<true>(h, created, *space.quantizer, tables, rans_data, rans_size, raw_data, raw_size)
                           : decode_grid_listed_fastest<false>(h, created, *space.quantizer, tables, rans_data, rans_size, raw_data, raw_size);
        // Modes 5 and 3 bit-exact (the FE models' middle levels take mode 3).
        if (all_narrow && mode == GeometryPredictor::unit_normal_frame && space.quantizer == nullptr) {
            if (space.precision == Precision::float64 && !h.single_precision())
                return decode_unit_listed_fastest<false, true>(h, created, tables, rans_data, rans_size, raw_data, raw_size);
            if (space.precision == Precision::float32 && h.single_precision())
                return decode_unit_listed_fastest<true, true>(h, created, tables, rans_data, rans_size, raw_data, raw_size);
        }
        if (all_narrow && mode == GeometryPredictor::normal_frame && space.quantizer == nullptr) {
            if (space.precision == Precision::float64 && !h.single_precision())
                return decode_unit_listed_fastest<false, false>(h, created, tables, rans_data, rans_size, raw_data, raw_size);
            if (space.precision == Precision::float32 && h.single_precision())
                return decode_unit_listed_fastest<true, false>(h, created, tables, rans_data, rans_size, raw_data, raw_size);
        }
    }
    if (all_narrow) return decode_static_with(h, created, space, mode, narrow, rans_data, rans_size, raw_data, raw_size, grouped);
    return decode_static_with(h, created, space, mode, tables, rans_data, rans_size, raw_data, raw_size, grouped);
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

}  // namespace

// add_vertices<true, false, kFloat64Residuals or kFloat32Residuals> (mode 5, bit-exact) with the
// frames of decode_unit_listed (GridFrame in axis order, two or four at a time) instead of
// RoleFrame copies: the same predictions, residuals and tokens in the same order.
template <bool Float32, bool KeepLarge>
void StaticLevelEncoder::add_unit_vertices(const Hierarchy& h, const std::vector<std::pair<NodeId, int>>& created, size_t begin,
                                           size_t end) {
    uint64_t raw_bits = 0;
    Chunk c;
    std::array<GridFrame, kChunk> frames;
    for (size_t first = begin; first < end; first += kChunk) {
        gather_chunk(h, FromNodes<Hierarchy>{h, created}, first, end, c);
        for (size_t i = 0; i < c.count; ++i) __builtin_prefetch(&h.positions()[c.vertices[i]]);
        make_unit_frames(h, c.corners, c.count, frames.data());
        for (size_t i = 0; i < c.count; ++i) {
            const GridFrame& f = frames[i];
            const Vec3 p = h.position(c.vertices[i]);
            const double actual[3] = {p.x, p.y, p.z};
            const std::array<int, 3> axes = unit_role_axes(f);
            double second, third;
            predict_unit_others(f, axes, actual[axes[0]], second, third);
            const double predicted[3] = {f.midpoint[axes[0]], second, third};
            std::array<uint16_t, kStaticRoles>& symbols = symbols_[first + i];
            for (int role = 0; role < kStaticRoles; ++role) {
                const double value = actual[axes[role]];
                const Residual r = Float32 ? float32_residual(value, predicted[role]) : float64_residual(value, predicted[role]);
                take_residual<KeepLarge>(r, role, symbols[size_t(role)], raw_bits);
            }
        }
    }
    raw_bits_ += raw_bits;
}

bool set_wide_frames(bool allowed) {
#if AMC_AVX2_AT_RUN_TIME
    return wide_frames_allowed.exchange(allowed);
#else
    (void)allowed;
    return false;
#endif
}

bool decode_static_positions(Hierarchy& h, const std::vector<std::pair<NodeId, int>>& created, CoordinateSpace space,
                             GeometryPredictor mode, const StaticTables& tables, const uint8_t* rans_data, size_t rans_size,
                             const uint8_t* raw_data, size_t raw_size, StaticOrder order) {
    return decode_static(h, FromNodes<Hierarchy>{h, created}, space, mode, tables, rans_data, rans_size, raw_data, raw_size,
                         order == StaticOrder::grouped);
}

bool decode_static_positions(Hierarchy& h, NewVertexCorners& corners, CoordinateSpace space, GeometryPredictor mode,
                             const StaticTables& tables, const uint8_t* rans_data, size_t rans_size, const uint8_t* raw_data,
                             size_t raw_size, StaticOrder order) {
    return decode_static(h, FromList{corners}, space, mode, tables, rans_data, rans_size, raw_data, raw_size,
                         order == StaticOrder::grouped);
}

}  // namespace amc
