// Lossless coding of coordinates against a prediction (paper III, "data quantization": Isenburg's
// fast floating-point compression, P. Lindstrom and M. Isenburg, "Fast and efficient compression
// of floating-point data", TVCG 2006), and a uniform quantizer for the lossy-by-choice mode.
//
// Floating-point residuals. The IEEE bits of the actual value A and of the prediction P are mapped
// to unsigned integers that order like the numbers themselves (ordered_bits: negative values have
// all bits inverted, non-negative values get the sign bit set; -0.0 maps just below +0.0). The
// residual r = map(A) - map(P) is taken modulo 2^N (N = 32 for float32, 64 for float64) and read as
// an N-bit two's complement number, so every A is reachable from every P. It is coded as
//   1. k = bit length of |r| (0 .. 32 resp. 64): a binary tree of adaptive BitModels over k
//      (6 resp. 7 levels, most significant bit first), one tree per context;
//   2. if k > 0 the sign of r (1 = negative), one BitModel per context;
//   3. the k - 1 bits of |r| below its leading one: the top kModelledBits of them with adaptive
//      models per context and k (a two-level binary tree), the rest as raw bits, most
//      significant first, in chunks of at most 32; or, when the caller gives a side stream
//      (RawBitWriter / RawBitReader: the adaptive levels of bit-exact files from .amc version 14),
//      there, as one value (two above 32 bits), read by a plain bit reader instead of the range
//      coder (about 21 instructions a bit there).
// The decoder adds the residual to map(P) modulo 2^N and maps back: the value is bit-identical
// (signed zeros, denormals, any finite magnitude). Infinities and NaNs are outside the contract
// (inputs are validated finite) but neither side crashes on them.
//
// Predictions are first made canonical (coder_prediction): a non-finite prediction becomes 0;
// in float32 the prediction is clamped to the float range and rounded to float, so encoder and
// decoder agree on it whatever the prediction's low bits were.
//
// Quantized residuals use the same three steps on the integer difference q - q_pred of grid
// coordinates (k = 0 .. bits, 5-level tree).
//
// Contexts are chosen by the caller (for example 3 * level_class + axis): each context owns its
// own statistics. The symbol layout above is part of any format that uses it: describe it in
// docs/FORMAT.md and pin it with golden bytes before changing it.
#pragma once

#include "coding/entropy/arithmetic_coder.h"
#include "common/exact_float.h"

#include <amc/mesh.h>

#include <array>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <new>
#include <type_traits>
#include <vector>

namespace amc {

class RawBitWriter;
class RawBitReader;

// Written to streams: values are frozen.
enum class Precision : uint8_t { float32 = 0, float64 = 1 };

constexpr uint64_t kFloatSign64 = uint64_t{1} << 63;
constexpr uint32_t kFloatSign32 = uint32_t{1} << 31;
inline double axis_coordinate(Vec3 p, int axis) { return axis == 0 ? p.x : axis == 1 ? p.y : p.z; }

// Defined inline (here and for the quantizer below): the decoders call them for every coordinate.
// Monotone map of the IEEE bits of x to an unsigned integer (N significant bits). For float32, x
// must be a float value (it is converted to float; callers pass exactly representable values).
inline uint64_t ordered_bits(double x, Precision precision) {
    if (precision == Precision::float32) {
        const float f = static_cast<float>(x);
        uint32_t b;
        std::memcpy(&b, &f, sizeof b);
        return (b & kFloatSign32) ? uint32_t(~b) : (b | kFloatSign32);
    }
    uint64_t b;
    std::memcpy(&b, &x, sizeof b);
    return (b & kFloatSign64) ? ~b : (b | kFloatSign64);
}
// Inverse of ordered_bits (u is taken modulo 2^N).
inline double from_ordered_bits(uint64_t u, Precision precision) {
    if (precision == Precision::float32) {
        const uint32_t v = static_cast<uint32_t>(u);
        const uint32_t b = (v & kFloatSign32) ? (v & ~kFloatSign32) : ~v;
        float f;
        std::memcpy(&f, &b, sizeof f);
        return static_cast<double>(f);
    }
    const uint64_t b = (u & kFloatSign64) ? (u & ~kFloatSign64) : ~u;
    double x;
    std::memcpy(&x, &b, sizeof x);
    return x;
}
// The prediction both coder sides actually use: non-finite -> 0; float32: clamped to
// [-FLT_MAX, FLT_MAX] and rounded to float.
inline double coder_prediction(double predicted, Precision precision) {
    double p = std::isfinite(predicted) ? predicted : 0.0;
    if (precision == Precision::float32) {
        if (p > FLT_MAX) p = FLT_MAX;
        if (p < -FLT_MAX) p = -FLT_MAX;
        p = rounded_to_float(p);
    }
    return p;
}

// Adaptive models for `contexts` independent contexts.
class FloatResidualModels {
public:
    static constexpr int kLengthTreeSize = 128;  // nodes 1..127 of a 7-level tree
    static constexpr int kMaxLength = 64;        // largest bit length of a residual
    static constexpr int kModelledBits = 2;      // bits below the leading one with models

    struct Context {
        std::array<BitModel, kLengthTreeSize> length{};
        BitModel sign{};
        // Per bit length k: [0] first bit below the leading one, [1 + first] the second.
        std::array<std::array<BitModel, 3>, kMaxLength + 1> high{};
    };

    // contexts >= 1; throws Error otherwise.
    explicit FloatResidualModels(int contexts);

    int context_count() const { return static_cast<int>(contexts_.size()); }
    // Throws Error for a context outside [0, context_count()).
    Context& context(int c) {
        if (c < 0 || c >= context_count()) context_out_of_range(c);
        Slot& slot = contexts_[static_cast<size_t>(c)];
        if (!made_[static_cast<size_t>(c)]) make(c);
        return *std::launder(reinterpret_cast<Context*>(slot.bytes));
    }

    // Set by the decoding functions when they met a symbol an encoder cannot produce (a bit
    // length too large for the precision, a grid coordinate out of range): the stream is
    // corrupt. Decoding continues with clamped values; check this (and overran()) afterwards.
    bool saw_invalid_symbol() const { return invalid_; }
    void mark_invalid() { invalid_ = true; }

private:
    [[noreturn]] void context_out_of_range(int c) const;
    void make(int c);
    // A context is made when first used: a decode uses a few of them, and the pages of the
    // others (2.6 KB a context) are then never touched (a tenth of a MiB at a decode's peak).
    struct Slot {
        Slot() {}  // uninitialized: make() writes the context
        alignas(Context) unsigned char bytes[sizeof(Context)];
    };
    static_assert(std::is_trivially_copyable_v<Context> && std::is_trivially_destructible_v<Context>,
                  "slots are copied and dropped as bytes");
    std::vector<Slot> contexts_;
    std::vector<uint8_t> made_;
    bool invalid_ = false;
};

// Codes `actual` given `predicted`. In float32, actual must be exactly representable as float
// (throws Error otherwise); the decoded value is then double(float) of the same bits. With `raw`,
// the raw bits go to (come from) that side stream instead of the arithmetic code.
void encode_coordinate(ArithmeticEncoder& encoder, FloatResidualModels& models, int context,
                       Precision precision, double actual, double predicted, RawBitWriter* raw = nullptr);
double decode_coordinate(ArithmeticDecoder& decoder, FloatResidualModels& models, int context,
                         Precision precision, double predicted, RawBitReader* raw = nullptr);

// The three coordinates with contexts first_context + 0, 1, 2 (x, y, z).
void encode_position(ArithmeticEncoder& encoder, FloatResidualModels& models, int first_context,
                     Precision precision, Vec3 actual, Vec3 predicted, RawBitWriter* raw = nullptr);
// The same symbols into both codes of the pair.
void encode_position(ArithmeticEncoderPair& encoder, FloatResidualModels& models, int first_context,
                     Precision precision, Vec3 actual, Vec3 predicted, RawBitWriter* raw = nullptr);
Vec3 decode_position(ArithmeticDecoder& decoder, FloatResidualModels& models, int first_context,
                     Precision precision, Vec3 predicted, RawBitReader* raw = nullptr);

// The bits encode_position codes at probability 1/2 (below the two modelled bits under each
// residual's leading one): a code of them takes at least this many bits, whatever its models.
uint64_t position_raw_bits(Precision precision, Vec3 actual, Vec3 predicted);

// The residual layout above for any sign and magnitude of up to 64 bits, with the 7-level
// bit-length tree: the building block of the series file's field coder (docs/FORMAT.md, series
// section), which codes integer differences and ordered-bit differences with it. The decoder
// clamps a bit length above 64 to 64 and marks the models invalid.
void encode_signed_residual(ArithmeticEncoder& encoder, FloatResidualModels::Context& context, bool negative,
                            uint64_t magnitude);
void decode_signed_residual(ArithmeticDecoder& decoder, FloatResidualModels& models,
                            FloatResidualModels::Context& context, bool& negative, uint64_t& magnitude);
// The fewest symbols a signed residual costs (the bit-length tree's depth): decoders bound value
// counts by the bytes with it.
constexpr int kMinSymbolsPerSignedResidual = 7;

// ---- quantized mode ---------------------------------------------------------------------------

// The fewest symbols a coordinate costs: the bit-length tree's depth, 5 for quantized
// coordinates (6 float32, 7 float64). Decoders bound vertex counts by the bytes with it.
constexpr int kMinSymbolsPerCoordinate = 5;
// At most how many positions (three coordinates each) a payload of `payload_bytes` can hold.
constexpr uint64_t max_decodable_positions(uint64_t payload_bytes) {
    return max_decodable_symbols(payload_bytes) / (3 * kMinSymbolsPerCoordinate);
}

constexpr int kMinQuantizationBits = 1;
constexpr int kMaxQuantizationBits = 30;

// A uniform grid: coordinate x on axis a has grid coordinate q = round((x - origin[a]) / step),
// clamped to [0, 2^bits - 1], and is reconstructed as origin[a] + q * step. One step for all
// axes (the bounding box's largest extent / (2^bits - 1)), so the grid is isotropic.
struct Quantizer {
    Vec3 origin;
    double step = 1.0;
    int bits = 16;
    uint32_t max_coordinate() const { return (uint32_t{1} << bits) - 1; }
};
using GridPoint = std::array<uint32_t, 3>;

// How coordinates are stored: bit-exact in a precision, or on a grid (quantizer set).
struct CoordinateSpace {
    Precision precision = Precision::float64;
    const Quantizer* quantizer = nullptr;
};

// bits in [1, 30]; the box must be finite with box_min <= box_max and its extent finite.
// Throws Error otherwise. A box of zero extent gets step 1.
Quantizer make_quantizer(Vec3 box_min, Vec3 box_max, int bits);
// The bounding box of `points` (at least one point).
Quantizer make_quantizer(const std::vector<Vec3>& points, int bits);

// Grid coordinate of x on axis 0, 1, 2 (NaN -> 0; out-of-box values clamp to the grid).
inline uint32_t quantize_coordinate(const Quantizer& quantizer, int axis, double x) {
    const double t = (x - axis_coordinate(quantizer.origin, axis)) / quantizer.step;
    const double top = static_cast<double>(quantizer.max_coordinate());
    if (!(t > 0.0)) return 0;  // also NaN
    if (t >= top) return quantizer.max_coordinate();
    return static_cast<uint32_t>(t + 0.5);  // floor: t + 0.5 is positive, and conversion truncates
}
inline GridPoint quantize(const Quantizer& quantizer, Vec3 p) {
    return {quantize_coordinate(quantizer, 0, p.x), quantize_coordinate(quantizer, 1, p.y), quantize_coordinate(quantizer, 2, p.z)};
}
inline double dequantize_coordinate(const Quantizer& quantizer, int axis, uint32_t q) {
    return axis_coordinate(quantizer.origin, axis) + rounded(static_cast<double>(q) * quantizer.step);
}
inline Vec3 dequantize(const Quantizer& quantizer, GridPoint q) {
    return {dequantize_coordinate(quantizer, 0, q[0]), dequantize_coordinate(quantizer, 1, q[1]),
            dequantize_coordinate(quantizer, 2, q[2])};
}
// The grid point the encoder stores for a position: quantize()'s, one step lower on an axis where
// that would reconstruct beyond the largest double (a box that reaches DBL_MAX), so that every
// reconstruction is finite.
GridPoint snap_to_grid(const Quantizer& quantizer, Vec3 p);
// snap_to_grid for many points of one quantizer: on a grid whose largest point is finite on every
// axis (make_quantizer's), every grid point is (origin + rounded(q * step) grows with q), and the
// snap is quantize() without a finiteness test per coordinate.
class GridSnap {
public:
    explicit GridSnap(const Quantizer& quantizer) : quantizer_(quantizer) {
        for (int axis = 0; axis < 3; ++axis)
            finite_ = finite_ && std::isfinite(dequantize_coordinate(quantizer, axis, quantizer.max_coordinate()));
    }
    GridPoint operator()(Vec3 p) const { return finite_ ? quantize(quantizer_, p) : snap_to_grid(quantizer_, p); }

private:
    Quantizer quantizer_;
    bool finite_ = true;
};
// A bound on |x - dequantize(quantize(x))| for every x inside the quantizer's box: step / 2
// plus the rounding of the arithmetic.
double quantization_error_bound(const Quantizer& quantizer);
// The largest coordinate error max |x - dequantize(snap_to_grid(x))| over the points.
double max_quantization_error(const Quantizer& quantizer, const std::vector<Vec3>& points);

// Codes the grid coordinate `actual` given the grid coordinate `predicted` (both < 2^bits;
// throws Error otherwise). Predictions in quantized mode come from reconstructed (dequantized)
// positions, quantized again (closed loop), so both sides see the same values.
void encode_quantized(ArithmeticEncoder& encoder, FloatResidualModels& models, int context,
                      int bits, uint32_t actual, uint32_t predicted);
void encode_quantized(ArithmeticEncoderPair& encoder, FloatResidualModels& models, int context,
                      int bits, uint32_t actual, uint32_t predicted);
uint32_t decode_quantized(ArithmeticDecoder& decoder, FloatResidualModels& models, int context,
                          int bits, uint32_t predicted);
// The bits encode_quantized codes at probability 1/2 (as position_raw_bits).
int quantized_raw_bits(uint32_t actual, uint32_t predicted);

}  // namespace amc
