// The metadata block: see file_metadata.h.
#include "coding/file_metadata.h"

#include "coding/entropy/arithmetic_coder.h"
#include "coding/hierarchy/hierarchy_stream.h"
#include "common/check.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace amc {

std::vector<uint8_t> write_metadata(const Metadata& m, bool quantized) {
    std::vector<uint8_t> out;
    for (uint64_t v : {m.base_vertices, m.base_triangles, m.nodes, m.vertices, m.faces, m.levels, m.options})
        put_varint(out, v);
    put_varint(out, m.hierarchy_header.size());
    out.insert(out.end(), m.hierarchy_header.begin(), m.hierarchy_header.end());
    if (quantized) {
        out.push_back(uint8_t(m.quantizer.bits));
        put_f64(out, m.quantizer.origin.x);
        put_f64(out, m.quantizer.origin.y);
        put_f64(out, m.quantizer.origin.z);
        put_f64(out, m.quantizer.step);
    }
    return out;
}

Metadata read_metadata(const Block& block, bool quantized) {
    PayloadReader in(block.payload, block.size, "metadata block");
    Metadata m;
    m.base_vertices = in.varint();
    m.base_triangles = in.varint();
    m.nodes = in.varint();
    m.vertices = in.varint();
    m.faces = in.varint();
    m.levels = in.varint();
    m.options = in.varint();
    AMC_REQUIRE(!(m.options & ~(kOptionRootRotations | kOptionChunked | kOptionMixedContexts)), corrupt, "metadata block: unknown options");
    const uint64_t header_size = in.varint();
    AMC_REQUIRE(header_size <= in.remaining(), truncated, "metadata block: hierarchy header is truncated");
    const uint8_t* header = in.bytes(header_size);
    m.hierarchy_header.assign(header, header + header_size);
    if (quantized) {
        m.quantizer.bits = in.u8();
        m.quantizer.origin = {in.f64(), in.f64(), in.f64()};
        m.quantizer.step = in.f64();
        AMC_REQUIRE(m.quantizer.bits >= kMinQuantizationBits && m.quantizer.bits <= kMaxQuantizationBits &&
                        std::isfinite(m.quantizer.step) && m.quantizer.step > 0 && std::isfinite(m.quantizer.origin.x) &&
                        std::isfinite(m.quantizer.origin.y) && std::isfinite(m.quantizer.origin.z),
                    corrupt, "metadata block: bad quantization parameters");
    }
    AMC_REQUIRE(in.remaining() == 0, corrupt, "metadata block has trailing bytes");
    // Counts that no hierarchy has: the refined nodes R = (nodes - T) / 4 create between 1.5 R
    // (every midpoint shared by two of them) and 3 R new vertices, and every level but the last
    // refines at least one node.
    const uint64_t refined = (m.nodes - m.base_triangles) / 4;
    AMC_REQUIRE(m.base_triangles != 0 && m.levels != 0 && m.levels <= kMaxLevel + 1 && m.nodes >= m.base_triangles &&
                    m.vertices >= m.base_vertices && (m.nodes - m.base_triangles) % 4 == 0 &&
                    m.vertices - m.base_vertices <= 3 * refined && 2 * (m.vertices - m.base_vertices) >= 3 * refined &&
                    m.levels - 1 <= refined,
                corrupt, "metadata block: inconsistent counts");
    // Every leaf has one to three faces (1 + its hanging nodes).
    const uint64_t leaves = m.nodes - refined;
    AMC_REQUIRE(m.faces >= leaves && m.faces <= 3 * leaves, corrupt, "metadata block: inconsistent face count");
    return m;
}

void check_counts_against_size(const Metadata& m, uint64_t bytes_after, const DecodeOptions& options) {
    const uint64_t positions = max_decodable_positions(bytes_after);
    auto cannot_hold = [&](uint64_t count, const char* what) {
        return "metadata block: " + std::to_string(count) + " " + what + " can not be coded in the " +
               std::to_string(bytes_after) + " bytes that follow";
    };
    AMC_REQUIRE(m.base_vertices <= positions, corrupt, cannot_hold(m.base_vertices, "base vertices"));
    AMC_REQUIRE(m.vertices - m.base_vertices <= positions, corrupt,
                cannot_hold(m.vertices - m.base_vertices, "refinement vertices"));
    AMC_REQUIRE(m.base_triangles <= 2 * max_decodable_symbols(bytes_after), corrupt,
                cannot_hold(m.base_triangles, "base triangles"));
    HierarchyStreamHeader header;
    if (!(m.options & kOptionChunked))  // a chunked file has one per chunk, none here
        read_hierarchy_stream_header(m.hierarchy_header.data(), m.hierarchy_header.size(), header);
    AMC_REQUIRE(header.symbol_count <= std::min(m.nodes, max_decodable_symbols(bytes_after)), corrupt,
                cannot_hold(header.symbol_count, "hierarchy symbols"));
    AMC_REQUIRE(m.nodes <= options.max_nodes, limit_exceeded,
                "file holds " + std::to_string(m.nodes) + " nodes, more than the limit of " +
                    std::to_string(options.max_nodes) + " (raise it: amc decode --max-nodes, DecodeOptions::max_nodes)");
}

}  // namespace amc
