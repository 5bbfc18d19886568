// compare_bench: the general-purpose peers for connectivity: byte compressors (zstd, xz) over the
// raw 32-bit index buffer, and meshoptimizer's index codec. All in-process, one thread.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace amc_bench {

// zstd at `level` (19 is `zstd -19`), single-shot API. Throws std::runtime_error on failure.
std::vector<uint8_t> zstd_compress(const void* data, size_t size, int level);
std::vector<uint8_t> zstd_decompress(const std::vector<uint8_t>& compressed);

// xz (.xz container, CRC64), preset 9 as `xz -9`, through liblzma's buffer API.
std::vector<uint8_t> xz_compress(const void* data, size_t size, uint32_t preset);
std::vector<uint8_t> xz_decompress(const std::vector<uint8_t>& compressed, size_t decompressed_size);

// meshoptimizer 0.18: meshopt_optimizeVertexCache (reorders faces, which the codec needs to do
// well; vertex ids stay) then meshopt_encodeIndexBuffer at format version 1. The decoder must be
// told the index count, as meshoptimizer expects.
std::vector<uint8_t> meshopt_encode(const std::vector<uint32_t>& indices, size_t vertex_count);
std::vector<uint32_t> meshopt_decode(const std::vector<uint8_t>& encoded, size_t index_count);

}  // namespace amc_bench
