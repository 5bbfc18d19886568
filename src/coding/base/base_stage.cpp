// The base mesh in the .amc file: see base_stage.h.
#include "coding/base/base_stage.h"

#include "coding/entropy/arithmetic_coder.h"
#include "coding/geometry/geometry_prediction.h"
#include "coding/hierarchy/hierarchy_level_coder.h"
#include "common/check.h"
#include "common/exact_float.h"
#include "common/parallel.h"
#include "hierarchy/hierarchy_builder.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

namespace amc {

namespace {

// What a stored rotation costs in the encoder's estimate: log2 3, as it has always been rounded.
constexpr double kRotationBits = 1.585;

// A base triangle's rotation (0, 1, 2): "is it 0?", then "is it 1?".
struct RotationModels {
    BitModel zero, one;
};
void encode_rotation(ArithmeticEncoder& encoder, RotationModels& models, uint8_t rotation) {
    encoder.encode(rotation == 0, models.zero);
    if (rotation != 0) encoder.encode(rotation == 1, models.one);
}
uint8_t decode_rotation(ArithmeticDecoder& decoder, RotationModels& models) {
    if (decoder.decode(models.zero)) return 0;
    return decoder.decode(models.one) ? 1 : 2;
}

}  // namespace

TriangleMesh base_as_decoded(const Hierarchy& h, const Quantizer* quantizer) {
    TriangleMesh base = h.base();
    if (quantizer != nullptr)
        for (Vec3& p : base.positions) p = dequantize(*quantizer, snap_to_grid(*quantizer, p));
    return base;
}

// The base of a refined hierarchy gets a small search: on the corpus the full one (2^20
// triangles) took half of a 12-bit encode and gained nothing, the base order it picks moving the
// rest of the file by as much as it saves in the base (docs/BASE_CODER.md, Encode time). That still
// searches bases of up to about 11 triangles whole; a hierarchy of which the base is at least half
// (a plain mesh imported over nearly itself, say) is mostly base and gets it all. A base too large
// for that budget to try one start in every rotation and radius (above about 180 triangles) gets
// the single try: the search of 2^16 triangles moved the files of such bases (500 and 998) by less
// than 0.06 % either way, at a fifth of their 10^5-face encode (docs/BASE_CODER.md, Encode time).
uint64_t base_search_budget(const Hierarchy& h) {
    constexpr uint64_t kRefinedBudget = uint64_t{1} << 13;
    if (2 * uint64_t{h.root_count()} >= h.node_count()) return kFullBaseSearch;
    return one_start_search_budget(h.root_count()) <= kRefinedBudget ? kRefinedBudget : 0;
}

// The base connectivity of a file. Mode 2's search (FORMAT.md 4.16) starts the conquest away from
// the input's first triangle, which moves the decoder's base order away from the input's; a stored
// numbering pays for that more than the search saves (tests/numbering_test.cpp: 134 bytes instead
// of 92 for the canonical order), so with one the encoder makes version 4's single try.
BaseMeshCode base_code_of(const Hierarchy& h, const TriangleMesh& base, const EncodeOptions& options) {
    if (options.keep_base_order) return encode_base_connectivity(base, BaseConnectivityMode::explicit_triangles);
    if (options.numbering != nullptr && options.store_numbering) {
        try {
            return encode_base_connectivity(base, BaseConnectivityMode::angle, false);
        } catch (const Error&) {  // mode 2 does not fit this start: the usual choice
        }
    }
    return encode_base_connectivity(base, resolve_thread_count(options.threads), base_search_budget(h));
}

std::vector<BaseMeshCode> base_order_candidates(const TriangleMesh& base, const BaseMeshCode& own, uint32_t count,
                                                unsigned threads) {
    const size_t triangles = base.triangles.size();
    auto first_of = [&](uint32_t k) { return uint32_t(uint64_t{k} * triangles / count); };
    std::vector<BaseMeshCode> codes(count);
    std::vector<uint8_t> coded(count, 0);
    parallel_for(count, threads, [&](size_t k) {
        if (k > 0 && first_of(uint32_t(k)) == first_of(uint32_t(k - 1))) return;  // fewer triangles than starts
        BaseStart start;
        start.first = first_of(uint32_t(k));
        try {
            codes[k] = encode_base_connectivity(base, start);
            coded[k] = 1;
        } catch (const Error&) {  // mode 2 does not fit from there: the other starts may
        }
    });
    auto same_order = [](const BaseMeshCode& a, const BaseMeshCode& b) {
        return a.triangle_order == b.triangle_order && a.triangle_rotation == b.triangle_rotation && a.vertex_order == b.vertex_order;
    };
    std::vector<BaseMeshCode> out;
    for (uint32_t k = 0; k < count; ++k) {
        if (coded[k] == 0 || same_order(codes[k], own)) continue;
        bool seen = false;
        for (const BaseMeshCode& other : out) seen |= same_order(codes[k], other);
        if (!seen) out.push_back(std::move(codes[k]));
    }
    return out;
}

bool keeps_rotations(const DiagonalExceptions& rotated, const DiagonalExceptions& unrotated, size_t triangles) {
    if (rotated.fewest() == 0) return false;
    const double rotated_bits = binary_entropy_bits(rotated.fewest(), rotated.leaves);
    // Products rounded (exact_float.h): however it is compiled, the encoder makes the same choice.
    const double kept_bits = binary_entropy_bits(unrotated.fewest(), unrotated.leaves) + rounded(kRotationBits * double(triangles));
    return kept_bits < rotated_bits;
}

BaseCodeOrder base_code_order(const Hierarchy& input, const BaseMeshCode& base_code, unsigned threads) {
    std::vector<uint8_t> rotation_of_root(input.root_count(), 0);
    for (size_t t = 0; t < base_code.triangle_order.size() && t < base_code.triangle_rotation.size(); ++t)
        if (base_code.triangle_order[t] < rotation_of_root.size())
            rotation_of_root[base_code.triangle_order[t]] = base_code.triangle_rotation[t];
    const DiagonalExceptions rotated = diagonal_exceptions(input, rotation_of_root, threads);
    // Without rotations every node keeps its local vertex order: the input's exceptions.
    const bool keep = rotated.fewest() != 0 &&
                      keeps_rotations(rotated, diagonal_exceptions(input, threads), base_code.triangle_order.size());
    return base_code_order(base_code, keep);
}

BaseCodeOrder base_code_order(const BaseMeshCode& base_code, bool keep_rotations) {
    BaseCodeOrder order;
    order.keep_rotations = keep_rotations;
    order.rotation = keep_rotations ? std::vector<uint8_t>(base_code.triangle_order.size(), 0) : base_code.triangle_rotation;
    return order;
}

ReorderedInput in_base_code_order(const Hierarchy& input, const BaseMeshCode& base_code, bool want_vertex_map,
                                  unsigned threads) {
    BaseCodeOrder order = base_code_order(input, base_code, threads);
    ReorderedInput r;
    r.keep_rotations = order.keep_rotations;
    r.hierarchy = HierarchyBuilder::reorder_base(input, base_code.vertex_order, base_code.triangle_order, order.rotation,
                                                 want_vertex_map ? &r.vertex_map : nullptr, threads);
    return r;
}

namespace {

// The base geometry block of `base_vertices` positions, decoder vertex i at position_of(i).
template <class PositionOf>
RawSideCode base_geometry_code(size_t base_vertices, PositionOf&& position_of, const BaseMeshCode& base_code, bool keep_rotations,
                               PositionCoder& positions, bool raw_side) {
    ArithmeticEncoder encoder;
    if (keep_rotations) {
        RotationModels models;
        for (uint8_t r : base_code.triangle_rotation) encode_rotation(encoder, models, r);
    }
    RawBitWriter raw;
    std::vector<Vec3> decoded;
    decoded.reserve(base_vertices);
    for (uint32_t i = 0; i < base_vertices; ++i) {
        const Vec3 p = position_of(i);
        positions.encode(encoder, kBaseGeometryContext, p, predict_parallelogram(decoded, base_code.stencils[i]),
                         raw_side ? &raw : nullptr);
        decoded.push_back(p);
    }
    return RawSideCode{encoder.finish(), raw.finish()};
}

}  // namespace

RawSideCode encode_base_geometry(const Hierarchy& h, const BaseMeshCode& base_code, bool keep_rotations, PositionCoder& positions,
                                 bool raw_side) {
    return base_geometry_code(
        h.base().positions.size(), [&h](uint32_t i) { return h.position(i); }, base_code, keep_rotations, positions, raw_side);
}

uint64_t base_blocks_bytes(const TriangleMesh& base, const Quantizer* quantizer, const BaseMeshCode& base_code) {
    const bool quantized = quantizer != nullptr;
    PositionCoder positions(CoordinateSpace{base.single_precision && !quantized ? Precision::float32 : Precision::float64, quantizer});
    const RawSideCode code = base_geometry_code(
        base.positions.size(), [&](uint32_t i) { return base.positions[base_code.vertex_order[i]]; }, base_code, false, positions,
        !quantized);
    return base_code.bytes.size() + (quantized ? code.arithmetic.size() : code.joined().size());
}

TriangleMesh decode_base(const Block& connectivity, const Block& geometry, const Metadata& meta, uint8_t file_version,
                         bool single_precision, PositionCoder& positions) {
    AMC_REQUIRE(meta.base_vertices <= max_decodable_positions(geometry.size), corrupt,
                "metadata block: " + std::to_string(meta.base_vertices) + " base vertices can not be coded in the " +
                    std::to_string(geometry.size) + " bytes of the base geometry block");
    AMC_REQUIRE(meta.base_vertices <= UINT32_MAX, limit_exceeded, "metadata block: too many base vertices");
    const BaseConnectivityMode mode = base_connectivity_mode(connectivity.payload, connectivity.size);
    AMC_REQUIRE(mode != BaseConnectivityMode::angle || file_version >= kAngleBaseVersion, corrupt,
                "base connectivity block: mode 2 in a version-" + std::to_string(file_version) + " file");
    AMC_REQUIRE(mode != BaseConnectivityMode::angle_windowed || file_version >= kWindowedTipVersion, corrupt,
                "base connectivity block: mode 3 in a version-" + std::to_string(file_version) + " file");

    TriangleMesh base;
    base.single_precision = single_precision;
    // Version 21's bit-exact files: the positions' raw bits after the arithmetic code (FORMAT.md 3.5).
    const bool side = base_raw_side(file_version, positions.quantized());
    const RawSideParts parts = side ? split_raw_side(geometry.payload, geometry.size, "base geometry block")
                                    : RawSideParts{geometry.payload, geometry.size, nullptr, 0};
    ArithmeticDecoder decoder(parts.arithmetic, parts.arithmetic_size);
    RawBitReader raw(parts.raw, parts.raw_size);
    std::vector<uint8_t> rotations;
    if (meta.options & kOptionRootRotations) {
        RotationModels models;
        for (uint64_t t = 0; t < meta.base_triangles; ++t) {
            rotations.push_back(decode_rotation(decoder, models));
            AMC_REQUIRE(!decoder.overran(), corrupt, "base geometry block is truncated or corrupt");
        }
    }
    // The base connectivity decoder reads the base positions as it creates the vertices
    // (FORMAT.md 3.5); the overrun check a vertex (15 symbols or more) stops a block that ends
    // early at once.
    DecodedBaseMesh decoded = decode_base_mesh(
        connectivity.payload, connectivity.size, uint32_t(meta.base_vertices),
        [&](uint32_t, const BaseStencil& stencil, const std::vector<Vec3>& previous) {
            AMC_REQUIRE(!decoder.overran(), corrupt, "base geometry block is truncated or corrupt");
            const Vec3 p =
                positions.decode(decoder, kBaseGeometryContext, predict_parallelogram(previous, stencil), side ? &raw : nullptr);
            AMC_REQUIRE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z), corrupt,
                        "base geometry is corrupt (non-finite coordinate)");
            return p;
        },
        0);  // an .amc base mesh uses every vertex (validate_triangle_mesh): none isolated
    AMC_REQUIRE(decoded.vertex_count == meta.base_vertices && decoded.triangles.size() == meta.base_triangles, corrupt,
                "base connectivity does not match the metadata");
    AMC_REQUIRE(!decoder.overran() && !positions.saw_invalid_symbol(), corrupt, "base geometry block is truncated or corrupt");
    AMC_REQUIRE(!side || raw.ended_cleanly(), corrupt, "base geometry block: raw bits are truncated or left over");
    base.triangles = std::move(decoded.triangles);
    base.positions = std::move(decoded.positions);
    // Undo the base coder's rotations: decoded (o[r], o[r+1], o[r+2]) back to o.
    for (size_t t = 0; t < rotations.size(); ++t) {
        const Triangle d = base.triangles[t];
        for (int i = 0; i < 3; ++i) base.triangles[t][(i + rotations[t]) % 3] = d[i];
    }
    try {
        validate_triangle_mesh(base, "decoded base mesh");
    } catch (const Error& e) {
        throw_error(ErrorCode::corrupt, e.what());  // a file whose base breaks the rules is corrupt
    }
    return base;
}

}  // namespace amc
