// The one place that chooses the instruction set of the hand-vectorised kernels (level_split.cpp,
// hierarchy/red_split_kernels.h, coding/hierarchy/hierarchy_traversal.h, mode 4's frames in
// static_frame_decoder.cpp): SSE2 where the compiler targets it, else their scalar twins, which
// compute the same; mode 4's frames and roles 1-2 predictions also four at a time with AVX2.
// AMC_SCALAR (CMake option AMC_SCALAR) forces the scalar twins and the byte-by-byte forms of the
// little-endian shortcuts, so that CI builds and tests them on x86-64.
#pragma once

#if defined(__SSE2__) && !defined(AMC_SCALAR)
#define AMC_SSE2 1
#include <emmintrin.h>
#else
#define AMC_SSE2 0
#endif

// AVX2 kernels chosen at run time (GCC on x86-64, where the build targets SSE2 only): compiled
// under `#pragma GCC target("avx2")` and called only where amc::has_avx2() says the processor has it.
// No fused multiply-add (not in the avx2 target), so they compute what their SSE2 twins do.
#if AMC_SSE2 && defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && !defined(__AVX2__)
#define AMC_AVX2_AT_RUN_TIME 1
#include <immintrin.h>
namespace amc {
inline bool has_avx2() {
    static const bool has = __builtin_cpu_supports("avx2");
    return has;
}
}  // namespace amc
#else
#define AMC_AVX2_AT_RUN_TIME 0
#endif

#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__ && !defined(AMC_SCALAR)
#define AMC_LITTLE_ENDIAN 1
#else
#define AMC_LITTLE_ENDIAN 0
#endif
