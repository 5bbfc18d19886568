// Series file framing (docs/FORMAT.md 7.1-7.2).
#include "series/series_framing.h"

#include "coding/container.h"
#include "common/check.h"
#include "common/little_endian.h"
#include "series/series_format.h"

#include <xxhash.h>

#include <amc/series.h>

#include <cstring>

namespace amc {

std::vector<uint8_t> series_header(uint8_t version, uint8_t flags, uint32_t keyframe_interval) {
    std::vector<uint8_t> out(kSeriesMagic, kSeriesMagic + 4);
    out.push_back(version);
    out.push_back(flags);
    out.push_back(0);
    out.push_back(0);
    append_le32(out, keyframe_interval);
    append_le32(out, XXH32(out.data(), 12, 0));
    return out;
}

std::vector<uint8_t> series_block(uint8_t type, const std::vector<uint8_t>& payload) {
    AMC_REQUIRE(payload.size() <= 0xFFFFFFFFu, limit_exceeded, "series: a frame of more than 4 GiB");
    std::vector<uint8_t> out;
    out.reserve(payload.size() + kSeriesBlockOverhead);
    out.push_back(type);
    append_le32(out, uint32_t(payload.size()));
    out.insert(out.end(), payload.begin(), payload.end());
    append_le32(out, XXH32(out.data(), out.size(), 0));
    return out;
}

void check_series_header(const uint8_t* data, size_t size, const std::string& what, uint8_t allowed_flags) {
    AMC_REQUIRE(size >= 4 && std::memcmp(data, kSeriesMagic, 4) == 0, bad_magic, what + ": not an amcodec series file (magic)");
    AMC_REQUIRE(size >= 5, truncated, what + ": truncated header");
    AMC_REQUIRE(data[4] != 0, corrupt, what + ": unknown series version 0");
    AMC_REQUIRE(data[4] <= kNewestSeriesVersion, unsupported_version,
                what + ": unsupported series version " + std::to_string(data[4]) +
                    " (newer than this build, which reads version 1 to " + std::to_string(kNewestSeriesVersion) + ")");
    AMC_REQUIRE(size >= kSeriesHeaderSize, truncated, what + ": truncated header");
    AMC_REQUIRE(XXH32(data, 12, 0) == load_le32(data + 12), checksum, what + ": checksum mismatch in the header");
    AMC_REQUIRE((data[5] & ~allowed_flags) == 0 && data[6] == 0 && data[7] == 0, corrupt, what + ": reserved header bits set");
}

SeriesScan scan_series_file(const std::vector<uint8_t>& bytes, const std::string& what, bool allow_unfinished,
                            uint8_t allowed_flags, uint8_t max_type) {
    const uint8_t* data = bytes.data();
    const size_t size = bytes.size();
    check_series_header(data, size, what, allowed_flags);
    SeriesScan scan;
    scan.version = data[4];
    scan.flags = data[5];
    scan.keyframe_interval = load_le32(data + 8);
    size_t pos = kSeriesHeaderSize;
    while (true) {
        const bool have_base = !scan.blocks.empty();
        const size_t frames = have_base ? scan.blocks.size() - 1 : 0;
        if (pos == size) {
            // Unfinished files are read from their base block on (FORMAT.md 7.2); a header alone has none.
            AMC_REQUIRE(have_base, truncated, what + ": truncated after the header (no base block)");
            AMC_REQUIRE(allow_unfinished, truncated,
                        what + ": unfinished series: no END block after " + std::to_string(frames) +
                            " complete frames (the writer did not close it; read with allow_unfinished / --partial)");
            break;
        }
        const bool fits = size - pos >= kSeriesBlockOverhead && load_le32(data + pos + 1) <= size - pos - kSeriesBlockOverhead;
        if (!fits) {
            AMC_REQUIRE(allow_unfinished && have_base, truncated,
                        what + ": truncated in " + (have_base ? "frame " + std::to_string(frames) : std::string("the base block")) +
                            " at byte " + std::to_string(pos) + " (" + std::to_string(frames) + " complete frames before it" +
                            (have_base ? "; read them with allow_unfinished / --partial)" : ")"));
            scan.ignored = size - pos;
            break;
        }
        const uint8_t type = data[pos];
        const uint32_t length = load_le32(data + pos + 1);
        AMC_REQUIRE(XXH32(data + pos, 5 + size_t(length), 0) == load_le32(data + pos + 5 + length), checksum,
                    what + ": checksum mismatch in the block at byte " + std::to_string(pos) +
                        (have_base ? " (frame " + std::to_string(frames) + ")" : std::string()));
        AMC_REQUIRE(type <= max_type, corrupt, what + ": unknown block type " + std::to_string(type) + " at byte " + std::to_string(pos));
        if (type == uint8_t(SeriesBlock::end) && have_base) {
            AMC_REQUIRE(length == 0, corrupt, what + ": END block with a payload");
            AMC_REQUIRE(pos + kSeriesBlockOverhead == size, corrupt, what + ": bytes after the END block");
            scan.finished = true;
            break;
        }
        scan.blocks.push_back({type, pos, data + pos + 5, length});
        pos += kSeriesBlockOverhead + length;
    }
    return scan;
}

std::vector<uint8_t> padded_frame_payload(const std::vector<uint8_t>& head, std::vector<uint8_t>& connectivity,
                                          const std::vector<uint8_t>& tail, uint64_t nodes) {
    const uint64_t needed = nodes / kSeriesNodesPerByte + (nodes % kSeriesNodesPerByte != 0);
    const auto block_size = [&] {
        std::vector<uint8_t> length;
        put_varint(length, connectivity.size());
        return kSeriesBlockOverhead + head.size() + length.size() + connectivity.size() + tail.size();
    };
    // A longer section may lengthen its varint, so the block never ends up short.
    while (block_size() < needed) connectivity.resize(connectivity.size() + size_t(needed - block_size()), 0);
    std::vector<uint8_t> payload = head;
    put_varint(payload, connectivity.size());
    payload.insert(payload.end(), connectivity.begin(), connectivity.end());
    payload.insert(payload.end(), tail.begin(), tail.end());
    return payload;
}

void check_nodes_per_byte(uint64_t nodes, uint64_t bytes, uint64_t per_byte, const std::string& what) {
    if (per_byte == 0) return;
    const uint64_t needed = nodes / per_byte + (nodes % per_byte != 0);
    AMC_REQUIRE(needed <= bytes, limit_exceeded,
                std::to_string(nodes) + " " + what + " in " + std::to_string(bytes) + " bytes, more than " +
                    std::to_string(per_byte) + " per byte (unpadded files written before 2026-12-02: max_nodes_per_byte = 0)");
}

void check_frame_nodes(uint64_t nodes, uint64_t bytes, uint64_t max, uint64_t per_byte, const std::string& what) {
    AMC_REQUIRE(nodes <= max, limit_exceeded,
                std::to_string(nodes) + " " + what + ", more than the limit (" + std::to_string(max) + ")");
    check_nodes_per_byte(nodes, bytes, per_byte, what);
}

}  // namespace amc
