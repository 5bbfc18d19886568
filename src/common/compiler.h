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
