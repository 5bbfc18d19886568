// zlib blocks through zlib's one-shot compress2 and uncompress2.
#include "mesh/zlib_blocks.h"

#include <zlib.h>

#include <algorithm>

#include "amc/mesh.h"

namespace amc {

CompressedBlocks compress_zlib_blocks(const uint8_t* data, std::size_t size, std::size_t block_size,
                                      int level) {
    CompressedBlocks out;
    std::vector<Bytef> buffer(compressBound(static_cast<uLong>(block_size)));
    for (std::size_t begin = 0; begin < size; begin += block_size) {
        const std::size_t length = std::min(block_size, size - begin);
        uLongf compressed = static_cast<uLongf>(buffer.size());
        if (compress2(buffer.data(), &compressed, data + begin, static_cast<uLong>(length), level) != Z_OK) {
            throw Error(ErrorCode::limit_exceeded, "zlib compression failed (out of memory)");
        }
        out.compressed_sizes.push_back(compressed);
        out.bytes.append(reinterpret_cast<const char*>(buffer.data()), compressed);
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
