// The framing of the series file (docs/FORMAT.md 7.1-7.2), shared by the triangle and the forest
// series: the header, checksummed blocks, and the scan a reader makes of the whole file before it
// decodes anything.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace amc {

// The 16-byte header of a file of `version`.
std::vector<uint8_t> series_header(uint8_t version, uint8_t flags, uint32_t keyframe_interval);
// One block: type, length, payload, XXH32 of the three.
std::vector<uint8_t> series_block(uint8_t type, const std::vector<uint8_t>& payload);

struct SeriesBlockView {
    uint8_t type;
    size_t offset;  // of the block in the file
    const uint8_t* payload;
    uint32_t length;
};

struct SeriesScan {
    uint8_t version = 0, flags = 0;
    uint32_t keyframe_interval = 0;
    std::vector<SeriesBlockView> blocks;  // the base block, then the frames (the END block left out)
    bool finished = false;                // the END block is there
    uint64_t ignored = 0;                 // bytes of an incomplete block at the end (allow_unfinished)
};

// Checks the header (magic, version, checksum, reserved bits; `allowed_flags` may be set) and the
// length and checksum of every block, in order, up to the END block (empty, last). Block types
// beyond `max_type` are refused; what the blocks hold is the caller's. An incomplete last block or
// a missing END block is refused (truncated) unless `allow_unfinished`, and then only after the
// first block. Throws Error naming `what`.
SeriesScan scan_series_file(const std::vector<uint8_t>& bytes, const std::string& what, bool allow_unfinished,
                            uint8_t allowed_flags, uint8_t max_type);
// The header's checks alone, scan_series_file's first: on a file's first bytes (kSeriesHeaderSize
// or more, or all of a shorter file) they throw what the scan of the whole file would.
void check_series_header(const uint8_t* data, size_t size, const std::string& what, uint8_t allowed_flags);

// A frame block's payload: `head` (time and counts), the connectivity section (its length as a
// varint, then its bytes) and `tail`. The connectivity section, which ends with an arithmetic-coded
// payload, is first padded with zeros until the block (framing included) holds at most
// kSeriesNodesPerByte of the frame's `nodes` (or octants) per byte (FORMAT.md 7.2, Bounds); zeros
// are what the decoder reads past a payload's end, so the symbols stay the same.
std::vector<uint8_t> padded_frame_payload(const std::vector<uint8_t>& head, std::vector<uint8_t>& connectivity,
                                          const std::vector<uint8_t>& tail, uint64_t nodes);

// The reader's side of that bound: refuses (limit_exceeded) `nodes` in `bytes` bytes beyond
// `per_byte` nodes per byte (0: no bound). `what` names the nodes ("nodes", "octants", "trees").
void check_nodes_per_byte(uint64_t nodes, uint64_t bytes, uint64_t per_byte, const std::string& what);

// A frame's node count (`what`: "nodes", "octants") against the reader's limits: at most `max`, and
// at most `per_byte` per byte of the frame's `bytes`.
void check_frame_nodes(uint64_t nodes, uint64_t bytes, uint64_t max, uint64_t per_byte, const std::string& what);

// Where a reader starts decoding to reach frame `k`: the keyframe at or before it, or the frame after
// `current` (the frame the reader holds, -1 none) when that lies between the two.
template <class FrameInfo>
size_t first_frame_to_decode(const std::vector<FrameInfo>& frames, size_t k, long long current) {
    // Back from k, stopping at `current` too: reading the frames in order then costs a step each,
    // where walking to the keyframe every time was quadratic in the frames after it (docs/FUZZING.md).
    for (size_t i = k;; --i) {
        if ((long long)i == current) return i + 1;
        if (frames[i].keyframe) return i;
    }
}

}  // namespace amc
