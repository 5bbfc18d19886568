// The adaptive position coder of the .amc file: every coordinate under the bit-length models of
// float_coder.h, bit-exact (float32 or float64) or on a quantization grid (FORMAT.md 3.5, 5.4).
// Base vertices and each level's new vertices code under contexts of their own.
#pragma once

#include "coding/container.h"
#include "coding/entropy/arithmetic_coder.h"
#include "coding/entropy/rans_coder.h"
#include "coding/geometry/float_coder.h"
#include "common/check.h"

#include <algorithm>
#include <string>
#include <vector>

namespace amc {

// Geometry contexts: 3 for base vertices, then 3 per level (levels beyond 15 share the last).
constexpr int kBaseGeometryContext = 0;
constexpr int kLevelContextClasses = 16;
constexpr int kGeometryContexts = 3 * (1 + kLevelContextClasses);
inline int level_context(int level) { return 3 * (1 + std::min(level, kLevelContextClasses - 1)); }

class PositionCoder {
public:
    explicit PositionCoder(CoordinateSpace space)
        : precision_(space.precision), quantized_(space.quantizer != nullptr), models_(kGeometryContexts) {
        if (space.quantizer != nullptr) quantizer_ = *space.quantizer;
    }
    // `raw`: the side stream of bit-exact raw bits (float_coder.h); unused when quantized.
    // Encoder: ArithmeticEncoder, or ArithmeticEncoderPair (the same symbols into two codes).
    template <class Encoder>
    void encode(Encoder& encoder, int context, Vec3 actual, Vec3 predicted, RawBitWriter* raw = nullptr) {
        if (!quantized_) {
            encode_position(encoder, models_, context, precision_, actual, predicted, raw);
            return;
        }
        const GridPoint a = quantize(quantizer_, actual), p = quantize(quantizer_, predicted);
        for (int axis = 0; axis < 3; ++axis) encode_quantized(encoder, models_, context + axis, quantizer_.bits, a[axis], p[axis]);
    }
    Vec3 decode(ArithmeticDecoder& decoder, int context, Vec3 predicted, RawBitReader* raw = nullptr) {
        if (!quantized_) return decode_position(decoder, models_, context, precision_, predicted, raw);
        const GridPoint p = quantize(quantizer_, predicted);
        GridPoint a;
        for (int axis = 0; axis < 3; ++axis) a[axis] = decode_quantized(decoder, models_, context + axis, quantizer_.bits, p[axis]);
        return dequantize(quantizer_, a);
    }
    bool quantized() const { return quantized_; }
    bool saw_invalid_symbol() const { return models_.saw_invalid_symbol(); }
    // The bits encode() codes at probability 1/2: a lower bound of its code, whatever the models.
    uint64_t raw_bits(Vec3 actual, Vec3 predicted) const {
        if (!quantized_) return position_raw_bits(precision_, actual, predicted);
        const GridPoint a = quantize(quantizer_, actual), p = quantize(quantizer_, predicted);
        uint64_t bits = 0;
        for (int axis = 0; axis < 3; ++axis) bits += uint64_t(quantized_raw_bits(a[axis], p[axis]));
        return bits;
    }

private:
    Precision precision_;
    bool quantized_;
    Quantizer quantizer_;
    FloatResidualModels models_;
};

// An arithmetic code whose coordinates' raw bits went to a side stream, written as [varint A, the A
// bytes of the code, the raw bits' bytes]: an adaptive level block after its predictor byte (version
// 14), the base geometry block and the seam block of a bit-exact file (version 21; FORMAT.md 3.5,
// 3.6, 3.13).
struct RawSideCode {
    std::vector<uint8_t> arithmetic, raw;
    std::vector<uint8_t> joined() const {
        std::vector<uint8_t> out;
        put_varint(out, arithmetic.size());
        out.insert(out.end(), arithmetic.begin(), arithmetic.end());
        out.insert(out.end(), raw.begin(), raw.end());
        return out;
    }
};
// The two parts of such a payload (`raw`: all that follows the arithmetic part). Throws Error
// (corrupt) naming `what` when A passes the payload's end; `reader`, if given, names the payload in
// PayloadReader's own messages instead.
struct RawSideParts {
    const uint8_t* arithmetic = nullptr;
    size_t arithmetic_size = 0;
    const uint8_t* raw = nullptr;
    size_t raw_size = 0;
};
inline RawSideParts split_raw_side(const uint8_t* payload, size_t size, const std::string& what, const char* reader = nullptr) {
    PayloadReader in(payload, size, reader != nullptr ? reader : what.c_str());
    const uint64_t arithmetic = in.varint();
    AMC_REQUIRE(arithmetic <= in.remaining(), corrupt, what + ": arithmetic part is longer than the block");
    RawSideParts parts;
    parts.arithmetic = in.rest();
    parts.arithmetic_size = size_t(arithmetic);
    parts.raw = in.rest() + arithmetic;
    parts.raw_size = in.remaining() - size_t(arithmetic);
    return parts;
}

}  // namespace amc
