// The compressed layout of vtkZLibDataCompressor: an array's bytes cut into blocks of
// `block_size` (the last one may be shorter), each compressed as a zlib stream of its own, so a
// reader can inflate block by block. The header of block counts and sizes is the caller's.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace amc {

// zlib cannot expand data by more than about 1032:1; a block that declares more is a lie.
constexpr uint64_t kZlibMaxExpansion = 1032;

// VTK's block size. Level 1, not VTK's 5: on a 1.43 M-triangle leaf mesh it wrote a smaller file
// in half the CPU time (docs/VTU.md, bench/vtu_io_bench.cpp).
constexpr std::size_t kVtkBlockSize = 32768;
constexpr int kZlibLevel = 1;

struct CompressedBlocks {
    std::vector<uint64_t> compressed_sizes;  // one per block
    std::string bytes;                       // the blocks, one after another
};

// Compresses `size` bytes in blocks of `block_size`, on up to `threads` threads (0: every core;
// the bytes do not depend on it). Throws Error if zlib fails.
CompressedBlocks compress_zlib_blocks(const uint8_t* data, std::size_t size, std::size_t block_size,
                                      int level, unsigned threads = 1);

// Inflates one block: true only if `in` is exactly one complete zlib stream of `out_size` bytes.
bool inflate_zlib_block(const uint8_t* in, std::size_t in_size, uint8_t* out, std::size_t out_size);

}  // namespace amc
