// Test helpers for crafted .amc files: a file's blocks written again under another version and
// flags, each level block edited on the way, and the error a decoder reports for the result.
#pragma once

#include "coding/container.h"

#include <amc/codec.h>

#include <cstdint>
#include <string>
#include <vector>

namespace amc::testing {

// try_decode's error, or "" when the bytes decode.
inline std::string decode_error(const std::vector<uint8_t>& bytes) {
    const DecodeResult r = try_decode(bytes.data(), bytes.size());
    return r.ok ? "" : r.error;
}

// The file's blocks rewritten with `version` and `flags` (checksums made anew), each level block
// passed through `edit`.
template <class Edit>
std::vector<uint8_t> rewritten(const std::vector<uint8_t>& bytes, uint8_t version, uint8_t flags, Edit&& edit) {
    BlockReader reader(bytes.data(), bytes.size());
    BlockWriter writer(version, flags);
    Block block;
    while (reader.next(block)) {
        if (block.type == BlockType::end) break;
        std::vector<uint8_t> payload(block.payload, block.payload + block.size);
        if (block.type == BlockType::level) edit(payload);
        writer.add(block.type, payload);
    }
    return writer.finish();
}

}  // namespace amc::testing
