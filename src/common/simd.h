// The one place that chooses the instruction set of the hand-vectorised kernels (level_split.cpp,
// hierarchy/red_split_kernels.h, coding/hierarchy/hierarchy_traversal.h): SSE2 where the compiler
// targets it, else their scalar twins, which compute the same. AMC_SCALAR (CMake option
// AMC_SCALAR) forces the scalar twins and the byte-by-byte forms of the little-endian shortcuts,
// so that CI builds and tests them on x86-64.
#pragma once

#if defined(__SSE2__) && !defined(AMC_SCALAR)
#define AMC_SSE2 1
#include <emmintrin.h>
#else
#define AMC_SSE2 0
#endif

#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__ && !defined(AMC_SCALAR)
#define AMC_LITTLE_ENDIAN 1
#else
#define AMC_LITTLE_ENDIAN 0
#endif
