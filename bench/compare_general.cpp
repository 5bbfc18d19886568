#include "compare_general.h"

#include <lzma.h>
#include <meshoptimizer.h>
#include <zstd.h>

#include <stdexcept>
#include <string>

namespace amc_bench {

std::vector<uint8_t> zstd_compress(const void* data, size_t size, int level) {
    std::vector<uint8_t> out(ZSTD_compressBound(size));
    ZSTD_CCtx* context = ZSTD_createCCtx();
    // The zstd command line adds a content checksum by default; so do we, for the same bytes.
    ZSTD_CCtx_setParameter(context, ZSTD_c_compressionLevel, level);
    ZSTD_CCtx_setParameter(context, ZSTD_c_checksumFlag, 1);
    const size_t written = ZSTD_compress2(context, out.data(), out.size(), data, size);
    ZSTD_freeCCtx(context);
    if (ZSTD_isError(written)) throw std::runtime_error(std::string("zstd: ") + ZSTD_getErrorName(written));
    out.resize(written);
    return out;
}

std::vector<uint8_t> zstd_decompress(const std::vector<uint8_t>& compressed) {
    const unsigned long long size = ZSTD_getFrameContentSize(compressed.data(), compressed.size());
    if (size == ZSTD_CONTENTSIZE_ERROR || size == ZSTD_CONTENTSIZE_UNKNOWN)
        throw std::runtime_error("zstd: frame without content size");
    std::vector<uint8_t> out(size);
    const size_t read = ZSTD_decompress(out.data(), out.size(), compressed.data(), compressed.size());
    if (ZSTD_isError(read)) throw std::runtime_error(std::string("zstd: ") + ZSTD_getErrorName(read));
    out.resize(read);
    return out;
}

std::vector<uint8_t> xz_compress(const void* data, size_t size, uint32_t preset) {
    std::vector<uint8_t> out(lzma_stream_buffer_bound(size));
    size_t written = 0;
    const lzma_ret ret = lzma_easy_buffer_encode(preset, LZMA_CHECK_CRC64, nullptr, static_cast<const uint8_t*>(data), size,
                                                 out.data(), &written, out.size());
    if (ret != LZMA_OK) throw std::runtime_error("xz: encoder error " + std::to_string(int(ret)));
    out.resize(written);
    return out;
}

std::vector<uint8_t> xz_decompress(const std::vector<uint8_t>& compressed, size_t decompressed_size) {
    std::vector<uint8_t> out(decompressed_size);
    uint64_t memory_limit = UINT64_MAX;
    size_t in_pos = 0, out_pos = 0;
    const lzma_ret ret = lzma_stream_buffer_decode(&memory_limit, 0, nullptr, compressed.data(), &in_pos, compressed.size(),
                                                   out.data(), &out_pos, out.size());
    if (ret != LZMA_OK) throw std::runtime_error("xz: decoder error " + std::to_string(int(ret)));
    out.resize(out_pos);
    return out;
}

std::vector<uint8_t> meshopt_encode(const std::vector<uint32_t>& indices, size_t vertex_count) {
    std::vector<uint32_t> optimized(indices.size());
    meshopt_optimizeVertexCache(optimized.data(), indices.data(), indices.size(), vertex_count);
    meshopt_encodeIndexVersion(1);
    std::vector<uint8_t> out(meshopt_encodeIndexBufferBound(indices.size(), vertex_count));
    const size_t written = meshopt_encodeIndexBuffer(out.data(), out.size(), optimized.data(), optimized.size());
    if (written == 0) throw std::runtime_error("meshopt: encoder buffer too small");
    out.resize(written);
    return out;
}

std::vector<uint32_t> meshopt_decode(const std::vector<uint8_t>& encoded, size_t index_count) {
    std::vector<uint32_t> out(index_count);
    const int ret = meshopt_decodeIndexBuffer(out.data(), index_count, sizeof(uint32_t), encoded.data(), encoded.size());
    if (ret != 0) throw std::runtime_error("meshopt: decoder error " + std::to_string(ret));
    return out;
}

}  // namespace amc_bench
