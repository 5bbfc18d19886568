// Test helpers for crafted .amc files: a file's blocks written again under another version and
// flags, each level block edited on the way, and the error a decoder reports for the result.
#pragma once

#include "coding/base/base_mesh_coder.h"
#include "coding/container.h"
#include "coding/file_metadata.h"
#include "coding/format_version.h"
#include "coding/geometry/geometry_prediction.h"
#include "coding/geometry/position_coder.h"

#include <amc/codec.h>

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace amc::testing {

// try_decode's error, or "" when the bytes decode.
inline std::string decode_error(const std::vector<uint8_t>& bytes) {
    const DecodeResult r = try_decode(bytes.data(), bytes.size());
    return r.ok ? "" : r.error;
}

// The base geometry block of a bit-exact file of version 21 or later (its raw bits in a side
// stream, FORMAT.md 3.5) as the versions before write it: the same positions coded again with their
// raw bits in the arithmetic code. Files without root rotations (option bit 0) only.
inline std::vector<uint8_t> base_geometry_before_side_streams(const std::vector<uint8_t>& bytes) {
    BlockReader reader(bytes.data(), bytes.size());
    Block metadata, connectivity, geometry;
    if (!reader.next(metadata) || !reader.next(connectivity) || !reader.next(geometry)) throw std::logic_error("no base mesh");
    const Metadata meta = read_metadata(metadata, false);
    if (meta.options & kOptionRootRotations) throw std::logic_error("root rotations are not rewritten");
    DecodeOptions base_only;
    base_only.max_level = 0;
    const Hierarchy decoded = decode(bytes.data(), bytes.size(), base_only);
    const CoordinateSpace space{(bytes[5] & kFlagSinglePrecision) ? Precision::float32 : Precision::float64, nullptr};
    PositionCoder positions(space);
    ArithmeticEncoder encoder;
    decode_base_mesh(
        connectivity.payload, connectivity.size, uint32_t(meta.base_vertices),
        [&](uint32_t i, const BaseStencil& stencil, const std::vector<Vec3>& previous) {
            const Vec3 p = decoded.position(i);
            positions.encode(encoder, kBaseGeometryContext, p, predict_parallelogram(previous, stencil));
            return p;
        },
        0);
    return encoder.finish();
}

// The file's blocks rewritten with `version` and `flags` (checksums made anew), each level block
// passed through `edit`; a bit-exact file of version 21 or later rewritten as an older version gets
// the older base geometry block (its seam block, if any, is left as it is).
template <class Edit>
std::vector<uint8_t> rewritten(const std::vector<uint8_t>& bytes, uint8_t version, uint8_t flags, Edit&& edit) {
    const bool quantized = (bytes[5] & kFlagQuantized) != 0;
    const bool older_base = base_raw_side(bytes[4], quantized) && !base_raw_side(version, quantized);
    BlockReader reader(bytes.data(), bytes.size());
    BlockWriter writer(version, flags);
    Block block;
    while (reader.next(block)) {
        if (block.type == BlockType::end) break;
        std::vector<uint8_t> payload(block.payload, block.payload + block.size);
        if (block.type == BlockType::level) edit(payload);
        if (block.type == BlockType::base_geometry && older_base) payload = base_geometry_before_side_streams(bytes);
        writer.add(block.type, payload);
    }
    return writer.finish();
}

}  // namespace amc::testing
