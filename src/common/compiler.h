// Function attributes for the coders' hot loops (see docs/HIERARCHY_CODER.md, Speed).
#pragma once

// Keeps a function out of line and out of GCC's interprocedural analysis: what GCC concludes
// about a callee changes how it allocates registers in the caller's loops. Other compilers only
// keep the function out of line.
#if defined(__GNUC__) && !defined(__clang__)
#define AMC_NOIPA __attribute__((noipa))
#else
#define AMC_NOIPA __attribute__((noinline))
#endif

// Inlines a small function into its hot loop even where GCC's size heuristics would not (a small
// struct returned through memory stalls the loop on a store forward).
#if defined(__GNUC__)
#define AMC_ALWAYS_INLINE __attribute__((always_inline)) inline
#else
#define AMC_ALWAYS_INLINE inline
#endif
