// Floating-point arithmetic that the encoder and the decoder must carry out alike, bit for bit,
// however the library is compiled (docs/CODEC.md, "Bit exactness").
//
// C++ lets a compiler contract a * b + c into one fused multiply-add, which rounds once where the
// source rounds twice: GCC does so by default in its GNU dialects and with -ffp-contract=fast,
// wherever the processor has FMA (-march=native, -mfma, aarch64). And GCC 12's SLP vectorizer
// drops the round trip double -> float -> double of neighbouring coordinates. A value passed
// through `rounded` is opaque to the optimiser: the operation that made it has been carried out
// and rounded to its type, so no later operation fuses with it and no conversion folds it away.
// It costs nothing but the freedom to fuse: the value stays in its register.
#pragma once

#include <amc/mesh.h>

#include "common/compiler.h"

#if defined(__FAST_MATH__)
#error "amcodec must not be built with -ffast-math (or -fassociative-math): its coders need IEEE arithmetic"
#endif

namespace amc {

template <class T>
inline T rounded(T x) {
#if defined(__GNUC__) && defined(__x86_64__)
    __asm__("" : "+x"(x));  // an SSE register, where x is already
#elif defined(__GNUC__) && defined(__aarch64__)
    __asm__("" : "+w"(x));  // a SIMD&FP register, where x is already
#elif defined(__GNUC__)
    __asm__("" : "+m"(x));  // through memory (also drops x87 excess precision)
#else
    volatile T stored = x;
    x = stored;
#endif
    return x;
}

// s * v with each product rounded on its own.
inline Vec3 rounded_scaled(double s, Vec3 v) { return {rounded(s * v.x), rounded(s * v.y), rounded(s * v.z)}; }

// x rounded to float32 and back, each coordinate on its own.
inline double rounded_to_float(double x) { return static_cast<double>(rounded(static_cast<float>(x))); }
inline Vec3 rounded_to_float(Vec3 p) { return {rounded_to_float(p.x), rounded_to_float(p.y), rounded_to_float(p.z)}; }

// mesh.h's dot and cross with every product rounded before it is added: IEEE binary64 in exactly
// the order written, for the decisions both sides of a coder take on positions.
inline double exact_dot(Vec3 a, Vec3 b) { return rounded(a.x * b.x) + rounded(a.y * b.y) + rounded(a.z * b.z); }
AMC_ALWAYS_INLINE Vec3 exact_cross(Vec3 a, Vec3 b) {  // the static decoders compute one per vertex
    return {rounded(a.y * b.z) - rounded(a.z * b.y), rounded(a.z * b.x) - rounded(a.x * b.z),
            rounded(a.x * b.y) - rounded(a.y * b.x)};
}

}  // namespace amc
