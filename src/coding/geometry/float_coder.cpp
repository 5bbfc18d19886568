// Residual coding of coordinates (Lindstrom & Isenburg 2006) and the uniform quantizer; see
// float_coder.h for the bitstream.
#include "coding/geometry/float_coder.h"

#include "coding/entropy/rans_coder.h"
#include "common/bits.h"
#include "common/compiler.h"
#include "common/exact_float.h"
#include "common/little_endian.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

namespace amc {

namespace {

int width_bits(Precision precision) { return precision == Precision::float32 ? 32 : 64; }
uint64_t width_mask(Precision precision) {
    return precision == Precision::float32 ? 0xFFFFFFFFull : ~uint64_t{0};
}
// Levels of the bit-length tree: enough for k = 0 .. width.
int tree_depth(Precision precision) { return precision == Precision::float32 ? 6 : 7; }
constexpr int kQuantizedTreeDepth = 5;  // k = 0 .. 30 < 32
static_assert(kMinSymbolsPerCoordinate <= kQuantizedTreeDepth && kQuantizedTreeDepth < 6,
              "kMinSymbolsPerCoordinate is the shallowest tree");

// Every model of FloatResidualModels has the default window (its contexts are made from
// Context{}): the coders fold it into their code (BitModel::update_with_limit).
constexpr int kWindowLog2 = BitModel::kDefaultLimitLog2;

// The `count` (1 .. 61) low bits of `magnitude` in a side stream: one value of up to 32 bits, or
// the bits above the low 32 and then the low 32 (as geometry mode 3's raw bits, FORMAT.md 5.6).
void put_side_raw_bits(RawBitWriter& raw, uint64_t magnitude, int count) {
    if (count > 32) {
        raw.put(magnitude >> 32, count - 32);
        raw.put(magnitude & 0xFFFFFFFFull, 32);
    } else {
        raw.put(magnitude, count);
    }
}
AMC_ALWAYS_INLINE uint64_t get_side_raw_bits(RawBitReader& raw, int count) {
    if (count > 32) {
        const uint64_t high = raw.get(count - 32);
        return high << 32 | raw.get(32);
    }
    return raw.get(count);
}

// A residual as sign and magnitude; magnitude has at most kMaxLength bits.
// The raw bits go to `raw` when given (FORMAT.md 5.2: version 14's side stream), else to the coder.
// Encoder: ArithmeticEncoder or ArithmeticEncoderPair.
template <class Encoder>
void encode_residual(Encoder& encoder, FloatResidualModels::Context& ctx, int depth,
                     bool negative, uint64_t magnitude, RawBitWriter* raw = nullptr) {
    const int k = bit_length(magnitude);
    int node = 1;
    for (int i = depth - 1; i >= 0; --i) {
        const int bit = (k >> i) & 1;
        encoder.template encode_with_limit<kWindowLog2>(bit != 0, ctx.length[node]);
        node = 2 * node + bit;
    }
    if (k == 0) return;
    encoder.template encode_with_limit<kWindowLog2>(negative, ctx.sign);
    int remaining = k - 1;  // bits below the leading one
    if (remaining > 0) {
        const bool first = (magnitude >> (remaining - 1)) & 1;
        encoder.template encode_with_limit<kWindowLog2>(first, ctx.high[k][0]);
        --remaining;
        if (remaining > 0) {
            const bool second = (magnitude >> (remaining - 1)) & 1;
            encoder.template encode_with_limit<kWindowLog2>(second, ctx.high[k][1 + int(first)]);
            --remaining;
        }
    }
    if (raw != nullptr && remaining > 0) {
        put_side_raw_bits(*raw, magnitude, remaining);
        return;
    }
    while (remaining > 0) {
        const int chunk = remaining > 32 ? remaining - 32 : remaining;  // high chunk first
        remaining -= chunk;
        encoder.encode_bits_raw(static_cast<uint32_t>(magnitude >> remaining) &
                                    static_cast<uint32_t>((uint64_t{1} << chunk) - 1),
                                chunk);
    }
}

// Decodes sign and magnitude; k is clamped to max_length (marking the stream invalid).
void decode_residual(ArithmeticDecoder& decoder, FloatResidualModels& models,
                     FloatResidualModels::Context& ctx, int depth, int max_length,
                     bool& negative, uint64_t& magnitude, RawBitReader* raw = nullptr) {
    int node = 1;
    for (int i = 0; i < depth; ++i) node = 2 * node + int(decoder.decode_with_limit<kWindowLog2>(ctx.length[node]));
    int k = node - (1 << depth);
    negative = false;
    magnitude = 0;
    if (k > max_length) {
        models.mark_invalid();
        k = max_length;
    }
    if (k == 0) return;
    negative = decoder.decode_with_limit<kWindowLog2>(ctx.sign);
    magnitude = 1;
    int remaining = k - 1;
    if (remaining > 0) {
        const bool first = decoder.decode_with_limit<kWindowLog2>(ctx.high[k][0]);
        magnitude = (magnitude << 1) | uint64_t(first);
        --remaining;
        if (remaining > 0) {
            const bool second = decoder.decode_with_limit<kWindowLog2>(ctx.high[k][1 + int(first)]);
            magnitude = (magnitude << 1) | uint64_t(second);
            --remaining;
        }
    }
    if (raw != nullptr && remaining > 0) {
        magnitude = (magnitude << remaining) | get_side_raw_bits(*raw, remaining);
        return;
    }
    while (remaining > 0) {
        const int chunk = remaining > 32 ? remaining - 32 : remaining;
        remaining -= chunk;
        magnitude = (magnitude << chunk) | decoder.decode_bits_raw(chunk);
    }
}

// encode_residual's raw bits: those below the leading one and the two modelled after it.
int raw_bit_count(uint64_t magnitude) { return std::max(0, bit_length(magnitude) - 3); }

// A coordinate's residual: the ordered bits' difference as sign and magnitude.
struct CoordinateResidual {
    bool negative;
    uint64_t magnitude;
};
CoordinateResidual coordinate_residual(Precision precision, double actual, double predicted) {
    const uint64_t mask = width_mask(precision);
    const uint64_t r = (ordered_bits(actual, precision) - ordered_bits(coder_prediction(predicted, precision), precision)) & mask;
    const bool negative = (r & (uint64_t{1} << (width_bits(precision) - 1))) != 0;
    return {negative, negative ? ((uint64_t{0} - r) & mask) : r};
}

[[noreturn]] AMC_NOIPA void refuse_bits(int bits, const char* where) {
    throw Error(std::string(where) + ": quantization bits " + std::to_string(bits) + " outside [1, 30]");
}
// Inline, with the message out of line: the coders check once a coordinate.
inline void check_bits(int bits, const char* where) {
    if (bits < kMinQuantizationBits || bits > kMaxQuantizationBits) refuse_bits(bits, where);
}

template <class Encoder>
void encode_coordinate_with(Encoder& encoder, FloatResidualModels& models, int context,
                            Precision precision, double actual, double predicted, RawBitWriter* raw) {
    FloatResidualModels::Context& ctx = models.context(context);
    if (precision == Precision::float32 && !std::isnan(actual)) {
        const bool in_range = !std::isfinite(actual) || std::fabs(actual) <= FLT_MAX;
        if (!in_range || rounded_to_float(actual) != actual ||
            std::signbit(static_cast<float>(actual)) != std::signbit(actual)) {
            throw Error("encode_coordinate: " + std::to_string(actual) +
                        " is not a single precision value");
        }
    }
    const CoordinateResidual r = coordinate_residual(precision, actual, predicted);
    encode_residual(encoder, ctx, tree_depth(precision), r.negative, r.magnitude, raw);
}

template <class Encoder>
void encode_position_with(Encoder& encoder, FloatResidualModels& models, int first_context, Precision precision, Vec3 actual,
                          Vec3 predicted, RawBitWriter* raw) {
    encode_coordinate_with(encoder, models, first_context + 0, precision, actual.x, predicted.x, raw);
    encode_coordinate_with(encoder, models, first_context + 1, precision, actual.y, predicted.y, raw);
    encode_coordinate_with(encoder, models, first_context + 2, precision, actual.z, predicted.z, raw);
}

template <class Encoder>
void encode_quantized_with(Encoder& encoder, FloatResidualModels& models, int context,
                           int bits, uint32_t actual, uint32_t predicted) {
    check_bits(bits, "encode_quantized");
    FloatResidualModels::Context& ctx = models.context(context);
    const uint32_t top = (uint32_t{1} << bits) - 1;
    if (actual > top || predicted > top) {
        throw Error("encode_quantized: grid coordinate outside [0, 2^" + std::to_string(bits) +
                    ")");
    }
    const bool negative = actual < predicted;
    const uint64_t magnitude = negative ? predicted - actual : actual - predicted;
    encode_residual(encoder, ctx, kQuantizedTreeDepth, negative, magnitude);
}

}  // namespace

void encode_signed_residual(ArithmeticEncoder& encoder, FloatResidualModels::Context& context, bool negative,
                            uint64_t magnitude) {
    encode_residual(encoder, context, 7, negative, magnitude);
}

void decode_signed_residual(ArithmeticDecoder& decoder, FloatResidualModels& models,
                            FloatResidualModels::Context& context, bool& negative, uint64_t& magnitude) {
    decode_residual(decoder, models, context, 7, FloatResidualModels::kMaxLength, negative, magnitude);
}

// ---- the monotone map ------------------------------------------------------------------------

// ---- models -----------------------------------------------------------------------------------

FloatResidualModels::FloatResidualModels(int contexts) {
    if (contexts < 1) {
        throw Error("FloatResidualModels: context count " + std::to_string(contexts) + " < 1");
    }
    contexts_.resize(static_cast<size_t>(contexts));
    made_.assign(static_cast<size_t>(contexts), 0);
}

void FloatResidualModels::make(int c) {
    // A fresh context copied, not 324 BitModel constructors (the table made whole at once cost a
    // fifth of the amc_decode fuzz target's time, instrumented).
    static const Context kFresh{};
    ::new (static_cast<void*>(contexts_[static_cast<size_t>(c)].bytes)) Context(kFresh);
    made_[static_cast<size_t>(c)] = 1;
}

void FloatResidualModels::context_out_of_range(int c) const {
    throw Error("FloatResidualModels: context " + std::to_string(c) + " outside [0, " + std::to_string(context_count()) + ")");
}

// ---- floating-point residuals -------------------------------------------------------------------

void encode_coordinate(ArithmeticEncoder& encoder, FloatResidualModels& models, int context, Precision precision, double actual,
                       double predicted, RawBitWriter* raw) {
    encode_coordinate_with(encoder, models, context, precision, actual, predicted, raw);
}

void encode_position(ArithmeticEncoder& encoder, FloatResidualModels& models, int first_context, Precision precision, Vec3 actual,
                     Vec3 predicted, RawBitWriter* raw) {
    encode_position_with(encoder, models, first_context, precision, actual, predicted, raw);
}
void encode_position(ArithmeticEncoderPair& encoder, FloatResidualModels& models, int first_context, Precision precision,
                     Vec3 actual, Vec3 predicted, RawBitWriter* raw) {
    encode_position_with(encoder, models, first_context, precision, actual, predicted, raw);
}

double decode_coordinate(ArithmeticDecoder& decoder, FloatResidualModels& models, int context,
                         Precision precision, double predicted, RawBitReader* raw) {
    FloatResidualModels::Context& ctx = models.context(context);
    bool negative;
    uint64_t magnitude;
    decode_residual(decoder, models, ctx, tree_depth(precision), width_bits(precision), negative,
                    magnitude, raw);
    const uint64_t mask = width_mask(precision);
    const uint64_t p = ordered_bits(coder_prediction(predicted, precision), precision);
    const uint64_t a = (negative ? p - magnitude : p + magnitude) & mask;
    return from_ordered_bits(a, precision);
}

uint64_t position_raw_bits(Precision precision, Vec3 actual, Vec3 predicted) {
    return uint64_t(raw_bit_count(coordinate_residual(precision, actual.x, predicted.x).magnitude)) +
           uint64_t(raw_bit_count(coordinate_residual(precision, actual.y, predicted.y).magnitude)) +
           uint64_t(raw_bit_count(coordinate_residual(precision, actual.z, predicted.z).magnitude));
}

Vec3 decode_position(ArithmeticDecoder& decoder, FloatResidualModels& models, int first_context,
                     Precision precision, Vec3 predicted, RawBitReader* raw) {
    Vec3 p;
    p.x = decode_coordinate(decoder, models, first_context + 0, precision, predicted.x, raw);
    p.y = decode_coordinate(decoder, models, first_context + 1, precision, predicted.y, raw);
    p.z = decode_coordinate(decoder, models, first_context + 2, precision, predicted.z, raw);
    return p;
}

// ---- quantized mode ---------------------------------------------------------------------------

Quantizer make_quantizer(Vec3 box_min, Vec3 box_max, int bits) {
    check_bits(bits, "make_quantizer");
    double extent = 0.0;
    for (int axis = 0; axis < 3; ++axis) {
        const double lo = axis_coordinate(box_min, axis), hi = axis_coordinate(box_max, axis);
        if (!std::isfinite(lo) || !std::isfinite(hi) || !(lo <= hi)) {
            throw Error("make_quantizer: invalid bounding box");
        }
        const double e = hi - lo;
        if (!std::isfinite(e)) throw Error("make_quantizer: bounding box extent overflows");
        if (e > extent) extent = e;
    }
    Quantizer q;
    q.origin = box_min;
    q.bits = bits;
    q.step = extent > 0.0 ? extent / static_cast<double>(q.max_coordinate()) : 1.0;
    if (q.step == 0.0) q.step = std::numeric_limits<double>::denorm_min();
    // Every grid point must be a finite double: o + (2^bits - 1) * step may round past DBL_MAX
    // when the box reaches it (the decoder refuses non-finite coordinates). The largest step not
    // above this one that keeps the top grid point finite on every axis: finiteness falls off
    // monotonically with the step, so a bisection over the positive doubles' bit patterns finds
    // it (one ulp at a time could take up to 2^52 steps).
    auto top_is_finite = [&q](double step) {
        Quantizer t = q;
        t.step = step;
        for (int axis = 0; axis < 3; ++axis)
            if (!std::isfinite(dequantize_coordinate(t, axis, t.max_coordinate()))) return false;
        return true;
    };
    if (!top_is_finite(q.step)) {
        uint64_t finite_bits = 0;  // step 0 keeps every grid point at the finite origin
        uint64_t infinite_bits = bit_cast<uint64_t>(q.step);
        while (infinite_bits - finite_bits > 1) {
            const uint64_t middle = finite_bits + (infinite_bits - finite_bits) / 2;
            (top_is_finite(bit_cast<double>(middle)) ? finite_bits : infinite_bits) = middle;
        }
        q.step = bit_cast<double>(finite_bits);
    }
    return q;
}

Quantizer make_quantizer(const std::vector<Vec3>& points, int bits) {
    if (points.empty()) throw Error("make_quantizer: no points");
    Vec3 lo = points[0], hi = points[0];
    for (const Vec3& p : points) {
        lo = {std::fmin(lo.x, p.x), std::fmin(lo.y, p.y), std::fmin(lo.z, p.z)};
        hi = {std::fmax(hi.x, p.x), std::fmax(hi.y, p.y), std::fmax(hi.z, p.z)};
    }
    return make_quantizer(lo, hi, bits);
}

GridPoint snap_to_grid(const Quantizer& quantizer, Vec3 p) {
    GridPoint q = quantize(quantizer, p);
    for (int axis = 0; axis < 3; ++axis) {
        while (q[size_t(axis)] > 0 && !std::isfinite(dequantize_coordinate(quantizer, axis, q[size_t(axis)]))) --q[size_t(axis)];
    }
    return q;
}

double quantization_error_bound(const Quantizer& quantizer) {
    // (x - o) / step, the rounding, q * step and o + q * step each round once: a few ulps of the
    // largest magnitude involved.
    const Vec3 o = quantizer.origin;
    const double magnitude = std::fmax(std::fabs(o.x), std::fmax(std::fabs(o.y), std::fabs(o.z))) +
                             rounded(static_cast<double>(quantizer.max_coordinate() + 1.0) * quantizer.step);
    return rounded(0.5 * quantizer.step) + rounded(4.0 * DBL_EPSILON * magnitude);
}

double max_quantization_error(const Quantizer& quantizer, const std::vector<Vec3>& points) {
    double worst = 0.0;
    for (const Vec3& p : points) {
        const Vec3 r = dequantize(quantizer, snap_to_grid(quantizer, p));
        worst = std::fmax(worst, std::fabs(r.x - p.x));
        worst = std::fmax(worst, std::fabs(r.y - p.y));
        worst = std::fmax(worst, std::fabs(r.z - p.z));
    }
    return worst;
}

void encode_quantized(ArithmeticEncoder& encoder, FloatResidualModels& models, int context, int bits, uint32_t actual,
                      uint32_t predicted) {
    encode_quantized_with(encoder, models, context, bits, actual, predicted);
}
void encode_quantized(ArithmeticEncoderPair& encoder, FloatResidualModels& models, int context, int bits, uint32_t actual,
                      uint32_t predicted) {
    encode_quantized_with(encoder, models, context, bits, actual, predicted);
}

int quantized_raw_bits(uint32_t actual, uint32_t predicted) {
    return raw_bit_count(actual < predicted ? predicted - actual : actual - predicted);
}

uint32_t decode_quantized(ArithmeticDecoder& decoder, FloatResidualModels& models, int context,
                          int bits, uint32_t predicted) {
    check_bits(bits, "decode_quantized");
    FloatResidualModels::Context& ctx = models.context(context);
    const uint32_t top = (uint32_t{1} << bits) - 1;
    if (predicted > top) predicted = top;
    bool negative;
    uint64_t magnitude;
    decode_residual(decoder, models, ctx, kQuantizedTreeDepth, bits, negative, magnitude);
    const int64_t value = negative ? int64_t(predicted) - int64_t(magnitude)
                                   : int64_t(predicted) + int64_t(magnitude);
    if (value < 0 || value > int64_t(top)) {
        models.mark_invalid();
        return value < 0 ? 0 : top;
    }
    return static_cast<uint32_t>(value);
}

}  // namespace amc
