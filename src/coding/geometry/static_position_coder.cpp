// The static geometry mode of a level; see static_position_coder.h and docs/FORMAT.md 5.6.
#include "coding/geometry/static_position_coder.h"

#include "common/compiler.h"

#include "coding/geometry/geometry_prediction.h"
#include "common/bits.h"
#include "common/compiler.h"
#include "common/exact_float.h"

#include <cmath>

namespace amc {

namespace {

constexpr int kDirectTokens = 15;     // tokens 0 .. 14: magnitudes 0 .. 7 with their sign
constexpr int kMaxGammaLength = 12;   // table values are below 2^13
constexpr int kTokensFor64Bits = kDirectTokens + 4 * (64 - 4) + 4;

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

double component(Vec3 p, int axis) { return axis == 0 ? p.x : axis == 1 ? p.y : p.z; }
double& component_ref(Vec3& p, int axis) { return axis == 0 ? p.x : axis == 1 ? p.y : p.z; }

// The axes in coding order: the frame's axis, then the two others in increasing order.
std::array<int, 3> role_axes(const NormalFrame& f) {
    if (!f.has_normal) return {0, 1, 2};
    return {f.axis, f.axis == 0 ? 1 : 0, f.axis == 2 ? 1 : 2};
}

struct Residual {
    bool negative;
    uint64_t magnitude;
};

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

// The value a residual gives, or false if it leaves the grid.
AMC_ALWAYS_INLINE bool value_of(CoordinateSpace space, int axis, double predicted, Residual r, double& value) {
    if (space.quantizer != nullptr) {
        const int64_t p = quantize_coordinate(*space.quantizer, axis, predicted);
        const int64_t q = r.negative ? p - int64_t(r.magnitude) : p + int64_t(r.magnitude);
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

// Inlined: returned through memory, the small struct stalls the decoder's loop on a store forward.
AMC_ALWAYS_INLINE GridPrediction grid_prediction(const Quantizer& quantizer, int axis, double x) {
    // quantize_coordinate's steps, its t kept for the bin.
    const double t = rounded((x - component(quantizer.origin, axis)) / quantizer.step);
    if (!(t > 0.0)) return {0, 0, false};  // also NaN
    if (t >= static_cast<double>(quantizer.max_coordinate())) return {quantizer.max_coordinate(), 0, false};
    GridPrediction g{static_cast<uint32_t>(std::floor(t + 0.5)), 0, false};
    const double f = rounded(t - static_cast<double>(g.p));
    g.turn = f < 0.0;
    g.bin = (f >= 0.25 || f <= -0.25) ? 1 : 0;
    return g;
}

AMC_ALWAYS_INLINE Residual grid_residual(const Quantizer& quantizer, int axis, double actual, const GridPrediction& g) {
    const int64_t d = int64_t(quantize_coordinate(quantizer, axis, actual)) - int64_t(g.p);
    const int64_t s = g.turn ? -d : d;
    return {s < 0, uint64_t(s < 0 ? -s : s)};
}

AMC_ALWAYS_INLINE bool grid_value(const Quantizer& quantizer, int axis, const GridPrediction& g, Residual r, double& value) {
    const int64_t s = r.negative ? -int64_t(r.magnitude) : int64_t(r.magnitude);  // magnitude < 2^bits
    const int64_t q = int64_t(g.p) + (g.turn ? -s : s);
    if (q < 0 || q > int64_t(quantizer.max_coordinate())) return false;
    value = dequantize_coordinate(quantizer, axis, uint32_t(q));
    return true;
}

int token_of(Residual r) {
    if (r.magnitude == 0) return 0;
    if (r.magnitude < 8) return int(2 * r.magnitude - 1 + (r.negative ? 1 : 0));
    const int k = bit_length(r.magnitude);
    return kDirectTokens + 4 * (k - 4) + int((r.magnitude >> (k - 3)) & 3);
}

void put_raw(RawBitWriter& raw, Residual r) {
    if (r.magnitude < 8) return;
    const int low = bit_length(r.magnitude) - 3;
    raw.put(r.negative ? 1 : 0, 1);
    if (low > 32) {
        raw.put(r.magnitude >> 32, low - 32);
        raw.put(r.magnitude & 0xFFFFFFFFull, 32);
    } else {
        raw.put(r.magnitude, low);
    }
}

AMC_ALWAYS_INLINE Residual take(int token, RawBitReader& raw) {
    if (token < kDirectTokens) return {token != 0 && token % 2 == 0, uint64_t(token + 1) / 2};
    const int k = 4 + (token - kDirectTokens) / 4;
    const int low = k - 3;
    Residual r;
    r.negative = raw.get(1) != 0;
    uint64_t bits;
    if (low > 32) {
        bits = raw.get(low - 32) << 32;
        bits |= raw.get(32);
    } else {
        bits = raw.get(low);
    }
    r.magnitude = (uint64_t(4 | ((token - kDirectTokens) & 3)) << low) | bits;
    return r;
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

}  // namespace

StaticLevelEncoder::StaticLevelEncoder(const Hierarchy& h, const std::vector<std::pair<NodeId, int>>& created,
                                       CoordinateSpace space, bool grid_bins)
    : table_count_(static_table_count(grid_bins)) {
    if (grid_bins && space.quantizer == nullptr) throw Error("geometry mode 4 needs quantized coordinates");
    std::vector<std::array<int, kStaticRoles>> tokens, table_of;
    std::vector<std::array<Residual, kStaticRoles>> residuals;
    tokens.reserve(created.size());
    table_of.reserve(created.size());
    residuals.reserve(created.size());
    std::array<std::vector<uint64_t>, kMaxStaticTables> counts;
    for (auto [n, e] : created) {
        const NormalFrame frame = normal_frame(h, n, e, grid_bins);
        const std::array<int, 3> axes = role_axes(frame);
        const Vec3 actual = h.position(h.midpoint(n, e));
        const Vec3 others = frame.predict(component(actual, axes[0]));
        std::array<int, kStaticRoles> t{}, table{};
        std::array<Residual, kStaticRoles> r{};
        for (int role = 0; role < kStaticRoles; ++role) {
            const int axis = axes[size_t(role)];
            const double predicted = role == 0 ? component(frame.midpoint, axis) : component(others, axis);
            if (grid_bins) {
                const GridPrediction g = grid_prediction(*space.quantizer, axis, predicted);
                r[size_t(role)] = grid_residual(*space.quantizer, axis, component(actual, axis), g);
                table[size_t(role)] = kGridBins * role + g.bin;
            } else {
                r[size_t(role)] = residual_of(space, axis, component(actual, axis), predicted);
                table[size_t(role)] = role;
            }
            t[size_t(role)] = token_of(r[size_t(role)]);
            std::vector<uint64_t>& c = counts[size_t(table[size_t(role)])];
            if (c.size() <= size_t(t[size_t(role)])) c.resize(size_t(t[size_t(role)]) + 1, 0);
            ++c[size_t(t[size_t(role)])];
        }
        tokens.push_back(t);
        table_of.push_back(table);
        residuals.push_back(r);
    }
    for (int i = 0; i < table_count_; ++i) {
        std::vector<uint64_t>& c = counts[size_t(i)];
        if (c.empty()) c.push_back(1);
        tables_[size_t(i)] = RansTable::from_counts(c);
    }
    RansEncoder rans;
    RawBitWriter raw;
    for (size_t i = 0; i < tokens.size(); ++i) {
        for (int role = 0; role < kStaticRoles; ++role) {
            rans.put(tables_[size_t(table_of[i][size_t(role)])], tokens[i][size_t(role)]);
            put_raw(raw, residuals[i][size_t(role)]);
        }
    }
    rans_ = rans.finish();
    raw_ = raw.finish();
}

void StaticLevelEncoder::write_tables(ArithmeticEncoder& encoder) const {
    TableModels models;
    for (int i = 0; i < table_count_; ++i) put_table(encoder, models, tables_[size_t(i)]);
}

size_t StaticLevelEncoder::estimated_bytes() const {
    ArithmeticEncoder tables;
    write_tables(tables);
    size_t varint = 1;
    for (size_t n = rans_.size(); n >= 128; n >>= 7) ++varint;
    return tables.finish().size() + varint + rans_.size() + raw_.size();
}

bool read_static_tables(ArithmeticDecoder& decoder, CoordinateSpace space, bool grid_bins, StaticTables& tables) {
    if (grid_bins && space.quantizer == nullptr) return false;
    TableModels models;
    for (int i = 0; i < static_table_count(grid_bins); ++i)
        if (!get_table(decoder, models, token_limit(space), tables[size_t(i)])) return false;
    return true;
}

bool decode_static_positions(Hierarchy& h, const std::vector<std::pair<NodeId, int>>& created, CoordinateSpace space,
                             bool grid_bins, const StaticTables& tables, const uint8_t* rans_data, size_t rans_size,
                             const uint8_t* raw_data, size_t raw_size) {
    RansDecoder rans(rans_data, rans_size);
    RawBitReader raw(raw_data, raw_size);
    if (grid_bins) {
        if (space.quantizer == nullptr) return false;
        const Quantizer& quantizer = *space.quantizer;
        for (auto [n, e] : created) {
            const NormalFrame frame = normal_frame(h, n, e, true);
            const std::array<int, 3> axes = role_axes(frame);
            Vec3 p;
            GridPrediction g = grid_prediction(quantizer, axes[0], component(frame.midpoint, axes[0]));
            if (!grid_value(quantizer, axes[0], g, take(rans.get(tables[size_t(g.bin)]), raw), component_ref(p, axes[0])))
                return false;
            const Vec3 others = frame.predict(component(p, axes[0]));
            for (int role = 1; role < kStaticRoles; ++role) {
                const int axis = axes[size_t(role)];
                g = grid_prediction(quantizer, axis, component(others, axis));
                const Residual r = take(rans.get(tables[size_t(kGridBins * role + g.bin)]), raw);
                if (!grid_value(quantizer, axis, g, r, component_ref(p, axis))) return false;
            }
            h.set_position(h.midpoint(n, e), p);
        }
        return rans.ended_cleanly() && raw.ended_cleanly();
    }
    for (auto [n, e] : created) {
        const NormalFrame frame = normal_frame(h, n, e);
        const std::array<int, 3> axes = role_axes(frame);
        Vec3 p;
        double& first = component_ref(p, axes[0]);
        if (!value_of(space, axes[0], component(frame.midpoint, axes[0]), take(rans.get(tables[0]), raw), first)) return false;
        const Vec3 others = frame.predict(first);
        for (int role = 1; role < kStaticRoles; ++role) {
            const int axis = axes[size_t(role)];
            if (!value_of(space, axis, component(others, axis), take(rans.get(tables[size_t(role)]), raw), component_ref(p, axis)))
                return false;
        }
        h.set_position(h.midpoint(n, e), p);
    }
    return rans.ended_cleanly() && raw.ended_cleanly();
}

}  // namespace amc
