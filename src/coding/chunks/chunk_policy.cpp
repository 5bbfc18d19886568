// The default chunk count (chunk_policy.h).
#include "coding/chunks/chunk_policy.h"

#include <algorithm>

namespace amc {

uint32_t chunk_count_for(const EncodeOptions& options, uint64_t faces) {
    if (options.chunks != 0) return options.chunks;
    const uint64_t per_chunk = std::max<uint64_t>(1, options.chunk_faces);
    return uint32_t(std::max<uint64_t>(1, std::min<uint64_t>(faces / per_chunk, UINT32_MAX)));
}

uint32_t chunk_count_for_size(const EncodeOptions& options, uint32_t chunks, uint64_t bytes) {
    if (options.min_chunk_bytes == 0 || bytes / chunks >= options.min_chunk_bytes) return chunks;
    const uint64_t fewer = std::max<uint64_t>(1, bytes / options.min_chunk_bytes);
    // Coding again doubles the forest's encode time, for some chunks' bytes: worth it only when it
    // removes a quarter of the chunks or more.
    return 4 * fewer <= 3 * uint64_t(chunks) ? uint32_t(fewer) : chunks;
}

}  // namespace amc
