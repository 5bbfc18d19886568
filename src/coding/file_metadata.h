// The metadata block of the .amc file (docs/FORMAT.md, section 3): the counts of the hierarchy, the
// file's options, the hierarchy stream's header and the quantization grid. The decoder checks the
// counts against each other and against the bytes that follow before it allocates anything.
#pragma once

#include "coding/container.h"
#include "coding/geometry/float_coder.h"

#include <amc/codec.h>

#include <cstdint>
#include <vector>

namespace amc {

// Metadata option bits.
constexpr uint64_t kOptionRootRotations = 1;  // base triangles keep the input's local vertex order
constexpr uint64_t kOptionChunked = 2;        // version 7: chunk blocks instead of level blocks (FORMAT.md 3.11)
constexpr uint64_t kOptionMixedContexts = 4;  // hierarchy symbols in the mixing mode (version 8; FORMAT.md 2.1)

struct Metadata {
    uint64_t base_vertices = 0, base_triangles = 0, nodes = 0, vertices = 0, faces = 0, levels = 0;
    uint64_t options = 0;
    std::vector<uint8_t> hierarchy_header;
    Quantizer quantizer;  // when the file is quantized
};

std::vector<uint8_t> write_metadata(const Metadata& m, bool quantized);

// Throws Error on unknown options, bad quantization parameters and counts no hierarchy has.
Metadata read_metadata(const Block& block, bool quantized);

// Nodes a decoder may allocate up front per byte of the file: more than real files hold (about one
// node per byte; a finite-element hierarchy with exact midpoints about 100), so that they are
// decoded in memory of their final size, while a small file that announces a large hierarchy gets
// no more than its bytes warrant before it is decoded (more grows as the levels are built).
constexpr uint64_t kReservedNodesPerFileByte = 128;
// The nodes of a hierarchy over `base_triangles` roots that a file of `file_size` bytes may have
// allocated up front.
constexpr uint64_t reservable_nodes(uint64_t base_triangles, uint64_t file_size) {
    return base_triangles + kReservedNodesPerFileByte * file_size;
}

// Checks the metadata's counts against the `bytes_after` bytes of the file that follow it, before
// anything is allocated for them: every vertex costs at least max_decodable_positions' share of a
// payload, every base triangle at least half a symbol (FORMAT.md, 3.7), so a file can announce no
// more than its bytes can hold. Then against the caller's node limit.
void check_counts_against_size(const Metadata& m, uint64_t bytes_after, const DecodeOptions& options);

}  // namespace amc
