// zlib blocks through zlib's one-shot compress2 and uncompress2.
#include "mesh/zlib_blocks.h"

#include <zlib.h>

#include <algorithm>

#include "amc/mesh.h"
#include "common/parallel.h"

namespace amc {

CompressedBlocks compress_zlib_blocks(const uint8_t* data, std::size_t size, std::size_t block_size,
                                      int level, unsigned threads) {
    // Blocks are independent zlib streams: runs of them (about 1 MiB of input) are compressed on
    // several threads and joined in order.
    const std::size_t blocks = size == 0 ? 0 : (size - 1) / block_size + 1;
    const std::size_t per_task = std::max<std::size_t>(1, (std::size_t{1} << 20) / block_size);
    std::vector<CompressedBlocks> parts((blocks + per_task - 1) / per_task);
    parallel_for(parts.size(), resolve_thread_count(threads), [&](std::size_t t) {
        CompressedBlocks& part = parts[t];
        std::vector<Bytef> buffer(compressBound(static_cast<uLong>(block_size)));
        for (std::size_t b = t * per_task; b < std::min(blocks, (t + 1) * per_task); ++b) {
            const std::size_t begin = b * block_size, length = std::min(block_size, size - begin);
            uLongf compressed = static_cast<uLongf>(buffer.size());
            if (compress2(buffer.data(), &compressed, data + begin, static_cast<uLong>(length), level) != Z_OK) {
                throw Error(ErrorCode::limit_exceeded, "zlib compression failed (out of memory)");
            }
            part.compressed_sizes.push_back(compressed);
            part.bytes.append(reinterpret_cast<const char*>(buffer.data()), compressed);
        }
    });
    CompressedBlocks out;
    std::size_t total = 0;
    for (const CompressedBlocks& part : parts) total += part.bytes.size();
    out.compressed_sizes.reserve(blocks);
    out.bytes.reserve(total);
    for (const CompressedBlocks& part : parts) {
        out.compressed_sizes.insert(out.compressed_sizes.end(), part.compressed_sizes.begin(), part.compressed_sizes.end());
        out.bytes += part.bytes;
    }
    return out;
}

bool inflate_zlib_block(const uint8_t* in, std::size_t in_size, uint8_t* out, std::size_t out_size) {
    uLongf produced = static_cast<uLongf>(out_size);
    uLong consumed = static_cast<uLong>(in_size);
    // uncompress2 wants a non-null buffer even for zero bytes.
    Bytef empty = 0;
    const int status = uncompress2(out_size ? out : &empty, &produced, in, &consumed);
    return status == Z_OK && produced == out_size && consumed == in_size;
}

}  // namespace amc
