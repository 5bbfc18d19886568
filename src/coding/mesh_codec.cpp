// The .amc file: base mesh, then one block per level with that level's hierarchy decisions and the
// positions of the vertices its refinement creates (docs/FORMAT.md, section 3).
#include <amc/codec.h>

#include "coding/entropy/arithmetic_coder.h"
#include "coding/base/base_mesh_coder.h"
#include "coding/container.h"
#include "coding/geometry/float_coder.h"
#include "coding/geometry/geometry_prediction.h"
#include "coding/hierarchy/hierarchy_level_coder.h"
#include "coding/numbering/numbering_coder.h"
#include "coding/geometry/static_position_coder.h"
#include "common/check.h"
#include "hierarchy/writer_checks.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>

namespace amc {

namespace {

// Geometry contexts: 3 for base vertices, then 3 per level (levels beyond 15 share the last).
constexpr int kLevelContextClasses = 16;
constexpr int kGeometryContexts = 3 * (1 + kLevelContextClasses);
int level_context(int level) { return 3 * (1 + std::min(level, kLevelContextClasses - 1)); }

// Codes positions, bit-exact (float32 or float64) or on a quantization grid.
class PositionCoder {
public:
    PositionCoder(Precision precision, const Quantizer* quantizer)
        : precision_(precision), quantized_(quantizer != nullptr), models_(kGeometryContexts) {
        if (quantizer != nullptr) quantizer_ = *quantizer;
    }
    void encode(ArithmeticEncoder& encoder, int context, Vec3 actual, Vec3 predicted) {
        if (!quantized_) {
            encode_position(encoder, models_, context, precision_, actual, predicted);
            return;
        }
        const GridPoint a = quantize(quantizer_, actual), p = quantize(quantizer_, predicted);
        for (int axis = 0; axis < 3; ++axis) encode_quantized(encoder, models_, context + axis, quantizer_.bits, a[axis], p[axis]);
    }
    Vec3 decode(ArithmeticDecoder& decoder, int context, Vec3 predicted) {
        if (!quantized_) return decode_position(decoder, models_, context, precision_, predicted);
        const GridPoint p = quantize(quantizer_, predicted);
        GridPoint a;
        for (int axis = 0; axis < 3; ++axis) a[axis] = decode_quantized(decoder, models_, context + axis, quantizer_.bits, p[axis]);
        return dequantize(quantizer_, a);
    }
    bool saw_invalid_symbol() const { return models_.saw_invalid_symbol(); }

private:
    Precision precision_;
    bool quantized_;
    Quantizer quantizer_;
    FloatResidualModels models_;
};

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

Vec3 predict(const Hierarchy& h, GeometryPredictor predictor, NodeId n, int e) {
    return predictor == GeometryPredictor::butterfly ? predict_butterfly(h, n, e) : predict_midpoint(h, n, e);
}

// Metadata option bits.
constexpr uint64_t kOptionRootRotations = 1;  // base triangles keep the input's local vertex order

struct Metadata {
    uint64_t base_vertices = 0, base_triangles = 0, nodes = 0, vertices = 0, faces = 0, levels = 0;
    uint64_t options = 0;
    std::vector<uint8_t> hierarchy_header;
    Quantizer quantizer;
};

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
    AMC_REQUIRE(!(m.options & ~kOptionRootRotations), corrupt, "metadata block: unknown options");
    const uint64_t header_size = in.varint();
    AMC_REQUIRE(header_size <= in.remaining(), truncated, "metadata block: hierarchy header is truncated");
    m.hierarchy_header.assign(in.rest(), in.rest() + header_size);
    for (uint64_t i = 0; i < header_size; ++i) in.u8();
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

// Checks the metadata's counts against the `bytes_after` bytes of the file that follow it, before
// anything is allocated for them: every vertex costs at least max_decodable_positions' share of a
// payload, every base triangle at least half a symbol (FORMAT.md, 3.7), so a file can announce no
// more than its bytes can hold. Then against the caller's node limit.
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
    read_hierarchy_stream_header(m.hierarchy_header.data(), m.hierarchy_header.size(), header);
    AMC_REQUIRE(header.symbol_count <= std::min(m.nodes, max_decodable_symbols(bytes_after)), corrupt,
                cannot_hold(header.symbol_count, "hierarchy symbols"));
    AMC_REQUIRE(m.nodes <= options.max_nodes, limit_exceeded,
                "file holds " + std::to_string(m.nodes) + " nodes, more than the limit of " +
                    std::to_string(options.max_nodes) + " (raise it: amc decode --max-nodes, DecodeOptions::max_nodes)");
}

std::vector<Vec3> all_positions(const Hierarchy& h) {
    std::vector<Vec3> points;
    const std::vector<uint32_t> canonical = canonical_vertex_order(h);
    for (size_t v = 0; v < canonical.size(); ++v) {
        if (canonical[v] != 0xffffffffu) points.push_back(h.position(VertexId(v)));
    }
    return points;
}

// The base mesh with the positions the decoder reconstructs: the base coder predicts from them.
TriangleMesh base_as_decoded(const Hierarchy& h, const Quantizer* quantizer) {
    TriangleMesh base = h.base();
    if (quantizer != nullptr)
        for (Vec3& p : base.positions) p = dequantize(*quantizer, snap_to_grid(*quantizer, p));
    return base;
}

// The base connectivity of a file. Mode 2's search (FORMAT.md 4.16) starts the conquest away from
// the input's first triangle, which moves the decoder's base order away from the input's; a stored
// numbering pays for that more than the search saves (tests/numbering_test.cpp: 134 bytes instead
// of 92 for the canonical order), so with one the encoder makes version 4's single try.
BaseMeshCode base_code_of(const Hierarchy& h, const Quantizer* quantizer, const EncodeOptions& options) {
    const TriangleMesh base = base_as_decoded(h, quantizer);
    if (options.numbering != nullptr && options.store_numbering) {
        try {
            return encode_base_connectivity(base, BaseConnectivityMode::angle, false);
        } catch (const Error&) {  // mode 2 does not fit this start: the usual choice
        }
    }
    return encode_base_connectivity(base);
}

// The input over the base mesh in the base coder's order. The base coder may rotate each
// triangle's vertices. The default diagonal rule does not care, but hierarchies made under a rule
// of absolute local indices would pay orientation bits: then storing each root's rotation
// (log2 3 bits) to keep the input's local order may be cheaper (`keep_rotations`).
// `vertex_map` receives the input's vertex ids in the result.
Hierarchy in_base_code_order(const Hierarchy& input, const BaseMeshCode& base_code, bool& keep_rotations,
                             std::vector<VertexId>* vertex_map = nullptr) {
    keep_rotations = false;
    Hierarchy h = reorder_base(input, base_code.vertex_order, base_code.triangle_order, base_code.triangle_rotation, vertex_map);
    const DiagonalExceptions rotated = diagonal_exceptions(h);
    if (rotated.fewest() == 0) return h;
    std::vector<VertexId> kept_map;
    Hierarchy kept = reorder_base(input, base_code.vertex_order, base_code.triangle_order,
                                  std::vector<uint8_t>(base_code.triangle_order.size(), 0), &kept_map);
    const DiagonalExceptions unrotated = diagonal_exceptions(kept);
    const double rotated_bits = binary_entropy_bits(rotated.fewest(), rotated.leaves);
    const double kept_bits =
        binary_entropy_bits(unrotated.fewest(), unrotated.leaves) + 1.585 * double(base_code.triangle_order.size());
    if (kept_bits >= rotated_bits) return h;
    keep_rotations = true;
    if (vertex_map != nullptr) *vertex_map = std::move(kept_map);
    return kept;
}

// The caller's numbering of the input's leaf mesh, re-expressed against the leaf mesh of `h`, the
// input reordered (vertex_map: input vertex id -> id in h).
LeafNumbering numbering_after_reorder(const Hierarchy& input, const LeafNumbering& numbering, const Hierarchy& h,
                                      const std::vector<VertexId>& vertex_map) {
    const TriangleMesh caller = renumber_leaf_mesh(extract_leaf_mesh(input), numbering);
    const std::vector<uint32_t> canonical = canonical_vertex_order(input);
    std::vector<VertexId> id_of_leaf_vertex(input.vertex_count());
    for (VertexId v = 0; v < canonical.size(); ++v) {
        if (canonical[v] != kNoVertex) id_of_leaf_vertex[canonical[v]] = v;
    }
    std::vector<VertexId> vertex_of_input(numbering.vertex.size());
    for (size_t i = 0; i < numbering.vertex.size(); ++i) vertex_of_input[i] = vertex_map[id_of_leaf_vertex[numbering.vertex[i]]];
    return leaf_numbering(h, caller, vertex_of_input);
}

}  // namespace

std::vector<uint8_t> encode(const Hierarchy& input, const EncodeOptions& options, EncodeStats* stats_out) {
    EncodeStats stats;
    // Whatever is encoded decodes: the decoder's checks first (base mesh, structure, positions).
    check_before_writing(input, "encode", true);
    const bool quantized = options.quantize_bits != 0;
    // Quantized coordinates are reconstructed as doubles on the grid, whatever the input precision.
    const Precision precision = input.single_precision() && !quantized ? Precision::float32 : Precision::float64;

    Quantizer quantizer;
    if (quantized) {
        const std::vector<Vec3> points = all_positions(input);
        try {
            quantizer = make_quantizer(points, options.quantize_bits);
        } catch (const Error& e) {
            throw_error(e.code(), std::string("encode: ") + e.what() +
                                      " (positions that span more than the double range can only be stored bit-exact)");
        }
        stats.max_error = max_quantization_error(quantizer, points);
    }
    // II-B: code the base mesh first and express the forest in the decoder's base order.
    const BaseMeshCode base_code = base_code_of(input, quantized ? &quantizer : nullptr, options);
    bool keep_rotations = false;
    std::vector<VertexId> vertex_map;
    Hierarchy h = in_base_code_order(input, base_code, keep_rotations, options.numbering ? &vertex_map : nullptr);
    const bool store_numbering = options.numbering != nullptr && options.store_numbering;
    if (options.numbering != nullptr) stats.numbering = numbering_after_reorder(input, *options.numbering, h, vertex_map);
    if (quantized) {
        h.set_single_precision(false);
        // Closed loop: predictions are made from what the decoder will have.
        for (VertexId v = 0; v < h.positions().size(); ++v) h.set_position(v, dequantize(quantizer, snap_to_grid(quantizer, h.position(v))));
    }

    HierarchyLevelEncoder hierarchy(h, options.hierarchy);
    Metadata meta;
    meta.base_vertices = h.base().positions.size();
    meta.base_triangles = h.root_count();
    meta.nodes = h.node_count();
    meta.vertices = h.vertex_count();
    meta.faces = hierarchy.stats().faces;  // counted by the coder's first pass
    meta.levels = uint64_t(hierarchy.level_count());
    meta.hierarchy_header = hierarchy.header();
    meta.quantizer = quantizer;
    meta.options = keep_rotations ? kOptionRootRotations : 0;

    // The blocks are made first: the version in the header depends on the level modes chosen.
    std::vector<std::pair<BlockType, std::vector<uint8_t>>> blocks;
    blocks.emplace_back(BlockType::metadata, write_metadata(meta, quantized));
    stats.header_bytes = kFileHeaderSize + kBlockOverhead + blocks.back().second.size();
    blocks.emplace_back(BlockType::base_connectivity, base_code.bytes);
    stats.base_connectivity_bytes = base_code.bytes.size();

    PositionCoder positions(precision, quantized ? &quantizer : nullptr);
    {
        ArithmeticEncoder encoder;
        if (keep_rotations) {
            RotationModels models;
            for (uint8_t r : base_code.triangle_rotation) encode_rotation(encoder, models, r);
        }
        std::vector<Vec3> decoded;
        for (uint32_t i = 0; i < meta.base_vertices; ++i) {
            const Vec3 p = h.position(i);
            positions.encode(encoder, 0, p, predict_parallelogram(decoded, base_code.stencils[i]));
            decoded.push_back(p);
        }
        blocks.emplace_back(BlockType::base_geometry, encoder.finish());
        stats.base_geometry_bytes = blocks.back().second.size();
    }

    const CoordinateSpace space{precision, quantized ? &quantizer : nullptr};
    bool static_geometry = false;
    for (int l = 0; l < hierarchy.level_count(); ++l) {
        const std::vector<NodeId>& level = hierarchy.level_nodes(l);
        const std::vector<std::pair<NodeId, int>> created = new_vertices_of_level(h, level);
        // Pick the predictor of this level: try each on a copy of the models when automatic.
        GeometryPredictor predictor = options.predictor == GeometryPredictor::automatic ? GeometryPredictor::midpoint : options.predictor;
        std::unique_ptr<StaticLevelEncoder> static_code;
        if (predictor == GeometryPredictor::normal_frame || (options.predictor == GeometryPredictor::automatic && !created.empty()))
            static_code = std::make_unique<StaticLevelEncoder>(h, created, space);
        if (options.predictor == GeometryPredictor::automatic && !created.empty()) {
            size_t best = SIZE_MAX;
            for (GeometryPredictor candidate : {GeometryPredictor::midpoint, GeometryPredictor::butterfly}) {
                PositionCoder trial = positions;
                ArithmeticEncoder encoder;
                for (auto [n, e] : created)
                    trial.encode(encoder, level_context(h.level(n)), h.position(h.midpoint(n, e)), predict(h, candidate, n, e));
                const size_t size = encoder.finish().size();
                if (size < best) {
                    best = size;
                    predictor = candidate;
                }
            }
            if (static_code->estimated_bytes() < best) predictor = GeometryPredictor::normal_frame;
        }
        std::vector<uint8_t> payload{uint8_t(predictor)};
        ArithmeticEncoder encoder;
        hierarchy.encode_level(l, encoder);
        const size_t hierarchy_part = encoder.bytes_so_far();
        if (predictor == GeometryPredictor::normal_frame) {
            // Mode 3: the arithmetic payload (hierarchy, tables) with its length, the rANS stream
            // with its length, the raw bits.
            static_geometry = true;
            static_code->write_tables(encoder);
            const std::vector<uint8_t> coded = encoder.finish();
            put_varint(payload, coded.size());
            payload.insert(payload.end(), coded.begin(), coded.end());
            put_varint(payload, static_code->rans_bytes().size());
            payload.insert(payload.end(), static_code->rans_bytes().begin(), static_code->rans_bytes().end());
            payload.insert(payload.end(), static_code->raw_bytes().begin(), static_code->raw_bytes().end());
        } else {
            for (auto [n, e] : created)
                positions.encode(encoder, level_context(h.level(n)), h.position(h.midpoint(n, e)), predict(h, predictor, n, e));
            const std::vector<uint8_t> coded = encoder.finish();
            payload.insert(payload.end(), coded.begin(), coded.end());
        }
        // The hierarchy/geometry split of a level block is estimated at the coder's byte count
        // when the hierarchy part ended (they share one arithmetic code).
        const uint64_t hierarchy_bytes = std::min<uint64_t>(hierarchy_part, payload.size() - 1);
        stats.hierarchy_bytes += hierarchy_bytes;
        stats.geometry_bytes += payload.size() - 1 - hierarchy_bytes;
        stats.framing_bytes += kBlockOverhead + 1;
        LevelStats level_stats;
        level_stats.nodes = level.size();
        level_stats.new_vertices = created.size();
        level_stats.bytes = kBlockOverhead + payload.size();
        level_stats.predictor = predictor;
        stats.per_level.push_back(level_stats);
        blocks.emplace_back(BlockType::level, std::move(payload));
    }
    if (store_numbering) {
        blocks.emplace_back(BlockType::numbering, encode_numbering(stats.numbering, extract_leaf_mesh(h).mesh.triangles));
        stats.numbering_bytes = blocks.back().second.size();
        stats.framing_bytes += kBlockOverhead;
    }
    const uint8_t version = static_geometry                                   ? kStaticGeometryVersion
                            : base_code.mode == BaseConnectivityMode::angle ? kSearchedBaseVersion
                            : store_numbering                             ? kNumberingVersion
                                                                          : kBaseVersion;
    BlockWriter writer(version,
                       uint8_t((precision == Precision::float32 ? kFlagSinglePrecision : 0) | (quantized ? kFlagQuantized : 0)));
    for (const auto& block : blocks) writer.add(block.first, block.second);
    std::vector<uint8_t> out = writer.finish();
    stats.framing_bytes += 3 * kBlockOverhead + kBlockOverhead;  // base blocks and END
    stats.total_bytes = out.size();
    stats.faces = meta.faces;
    stats.vertices = meta.vertices;
    stats.nodes = meta.nodes;
    stats.base_vertices = meta.base_vertices;
    stats.base_triangles = meta.base_triangles;
    stats.levels = hierarchy.level_count();
    if (stats_out != nullptr) {
        stats.hierarchy = hierarchy.stats();  // replays the coded symbols: only when asked for
        *stats_out = stats;
    }
    return out;
}

namespace {

// Nodes reserved up front per byte of the file: more than real files hold (about one node per
// byte; a finite-element hierarchy with exact midpoints about 100), so that they are decoded in
// memory of their final size, while a small file that announces a large hierarchy gets no more
// than its bytes warrant before it is decoded (more grows as the levels are built).
constexpr uint64_t kReservedNodesPerFileByte = 128;

// How far a partial file got (decode_partial); null for a whole file.
struct PartialProgress {
    int levels_decoded = 0, levels_in_file = 0;
    bool complete = false;
};

Hierarchy decode_file(const uint8_t* data, size_t size, const DecodeOptions& options, LeafNumbering* numbering,
                      PartialProgress* partial = nullptr) {
    if (numbering != nullptr) *numbering = {};
    AMC_REQUIRE(data != nullptr || size == 0, invalid_input, "no data");
    BlockReader reader(data, size);
    const bool quantized = reader.flags() & kFlagQuantized;
    const Precision precision = (reader.flags() & kFlagSinglePrecision) ? Precision::float32 : Precision::float64;
    AMC_REQUIRE(!(quantized && precision == Precision::float32), corrupt, "file header: quantized and float32 flags together");
    Block block{};
    auto expect = [&](BlockType type) {
        AMC_REQUIRE(partial == nullptr || reader.next_block_arrived(), truncated,
                    std::string("file ends before its ") + block_type_name(uint8_t(type)) +
                        " block: a partial file decodes once the base mesh has arrived");
        AMC_REQUIRE(reader.next(block) && block.type == type, corrupt,
                    std::string("expected a ") + block_type_name(uint8_t(type)) + " block");
        return block;
    };
    const Metadata meta = read_metadata(expect(BlockType::metadata), quantized);
    check_counts_against_size(meta, reader.remaining(), options);
    const Block connectivity_block = expect(BlockType::base_connectivity);
    const Block geometry_block = expect(BlockType::base_geometry);
    AMC_REQUIRE(meta.base_vertices <= max_decodable_positions(geometry_block.size), corrupt,
                "metadata block: " + std::to_string(meta.base_vertices) + " base vertices can not be coded in the " +
                    std::to_string(geometry_block.size) + " bytes of the base geometry block");

    AMC_REQUIRE(meta.base_vertices <= UINT32_MAX, limit_exceeded, "metadata block: too many base vertices");
    AMC_REQUIRE(base_connectivity_mode(connectivity_block.payload, connectivity_block.size) != BaseConnectivityMode::angle ||
                    reader.version() >= kAngleBaseVersion,
                corrupt, "base connectivity block: mode 2 in a version-" + std::to_string(reader.version()) + " file");

    TriangleMesh base;
    base.single_precision = precision == Precision::float32;
    PositionCoder positions(precision, quantized ? &meta.quantizer : nullptr);
    {
        ArithmeticDecoder decoder(geometry_block.payload, geometry_block.size);
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
            connectivity_block.payload, connectivity_block.size, uint32_t(meta.base_vertices),
            [&](uint32_t, const BaseStencil& stencil, const std::vector<Vec3>& previous) {
                AMC_REQUIRE(!decoder.overran(), corrupt, "base geometry block is truncated or corrupt");
                const Vec3 p = positions.decode(decoder, 0, predict_parallelogram(previous, stencil));
                AMC_REQUIRE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z), corrupt,
                            "base geometry is corrupt (non-finite coordinate)");
                return p;
            },
            0);  // an .amc base mesh uses every vertex (validate_triangle_mesh): none isolated
        AMC_REQUIRE(decoded.vertex_count == meta.base_vertices && decoded.triangles.size() == meta.base_triangles, corrupt,
                    "base connectivity does not match the metadata");
        AMC_REQUIRE(!decoder.overran() && !positions.saw_invalid_symbol(), corrupt,
                    "base geometry block is truncated or corrupt");
        base.triangles = std::move(decoded.triangles);
        base.positions = std::move(decoded.positions);
        // Undo the base coder's rotations: decoded (o[r], o[r+1], o[r+2]) back to o.
        for (size_t t = 0; t < rotations.size(); ++t) {
            const Triangle d = base.triangles[t];
            for (int i = 0; i < 3; ++i) base.triangles[t][(i + rotations[t]) % 3] = d[i];
        }
    }
    try {
        validate_triangle_mesh(base, "decoded base mesh");
    } catch (const Error& e) {
        throw_error(ErrorCode::corrupt, e.what());  // a file whose base breaks the rules is corrupt
    }

    HierarchyLevelDecoder hierarchy(base, meta.hierarchy_header.data(), meta.hierarchy_header.size(),
                                    hierarchy_stream_version_of_file(reader.version()),
                                    std::min<uint64_t>(meta.nodes, options.max_nodes));
    Hierarchy& h = hierarchy.hierarchy();
    // The metadata's counts let the hierarchy grow in place, as far as the file's size warrants.
    const uint64_t reserved_nodes = std::min<uint64_t>(meta.nodes, meta.base_triangles + kReservedNodesPerFileByte * size);
    h.reserve(reserved_nodes, std::min<uint64_t>(meta.vertices, meta.base_vertices + reserved_nodes));
    int level = 0;
    Block numbering_block{};
    bool has_numbering = false;
    if (partial != nullptr) partial->levels_in_file = int(meta.levels);
    // A partial file ends at the first block that has not arrived whole.
    while ((partial == nullptr || reader.next_block_arrived()) && reader.next(block)) {
        if (block.type == BlockType::end) break;
        if (block.type == BlockType::numbering) {
            AMC_REQUIRE(hierarchy.done() && !has_numbering, corrupt, "numbering block out of place");
            numbering_block = block;
            has_numbering = true;
            continue;
        }
        AMC_REQUIRE(!has_numbering, corrupt, "level block after the numbering block");
        AMC_REQUIRE(block.type == BlockType::level, corrupt, "unexpected block between level blocks");
        AMC_REQUIRE(!hierarchy.done(), corrupt, "level block after the last level");
        if (options.max_level >= 0 && level >= options.max_level) return std::move(h);  // progressive: stop here
        const uint8_t last_predictor = reader.version() >= kStaticGeometryVersion ? 3 : 2;
        AMC_REQUIRE(block.size >= 1 && block.payload[0] >= 1 && block.payload[0] <= last_predictor, corrupt,
                    "level block: bad predictor");
        const GeometryPredictor predictor = GeometryPredictor(block.payload[0]);
        const std::string where = "level " + std::to_string(level) + " block";
        // Mode 3: [arithmetic length, arithmetic payload, rANS length, rANS stream, raw bits].
        PayloadReader parts(block.payload + 1, block.size - 1, "level block");
        size_t arithmetic_size = block.size - 1;
        if (predictor == GeometryPredictor::normal_frame) {
            const uint64_t size = parts.varint();
            AMC_REQUIRE(size <= parts.remaining(), corrupt, where + ": arithmetic part is longer than the block");
            arithmetic_size = size_t(size);
        }
        ArithmeticDecoder decoder(parts.rest(), arithmetic_size);
        const std::vector<NodeId> nodes = hierarchy.level_nodes();
        // The refined nodes R of a level create at least 1.5 R vertices, whose positions are in
        // this block: it bounds R before the next level is allocated.
        hierarchy.decode_level(decoder, 2 * max_decodable_positions(block.size - 1) / 3);
        const std::vector<std::pair<NodeId, int>> created = new_vertices_of_level(h, nodes);
        if (predictor == GeometryPredictor::normal_frame) {
            StaticTables tables;
            const CoordinateSpace space{precision, quantized ? &meta.quantizer : nullptr};
            AMC_REQUIRE(read_static_tables(decoder, space, tables) && !decoder.overran(), corrupt, where + ": bad geometry tables");
            for (size_t i = 0; i < arithmetic_size; ++i) parts.u8();
            const uint64_t rans_size = parts.varint();
            AMC_REQUIRE(rans_size <= parts.remaining(), corrupt, where + ": rANS stream is longer than the block");
            const uint8_t* rans = parts.rest();
            const uint8_t* raw = rans + rans_size;
            const size_t raw_size = parts.remaining() - size_t(rans_size);
            AMC_REQUIRE(decode_static_positions(h, created, space, tables, rans, size_t(rans_size), raw, raw_size), corrupt,
                        where + " is truncated or corrupt (positions)");
        } else {
            for (auto [n, e] : created) {
                const Vec3 p = positions.decode(decoder, level_context(h.level(n)), predict(h, predictor, n, e));
                AMC_REQUIRE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z), corrupt,
                            "level " + std::to_string(level) + " geometry is corrupt (non-finite coordinate)");
                h.set_position(h.midpoint(n, e), p);
            }
            AMC_REQUIRE(!positions.saw_invalid_symbol(), corrupt, where + " is truncated or corrupt");
        }
        AMC_REQUIRE(!decoder.overran(), corrupt, where + " is truncated or corrupt");
        ++level;
        if (partial != nullptr) partial->levels_decoded = level;
    }
    if (!hierarchy.done()) {
        if (options.max_level >= 0 && level >= options.max_level) return std::move(h);
        if (partial != nullptr) return std::move(h);
        throw_error(ErrorCode::truncated, "file ends before the last level");
    }
    if (partial != nullptr) partial->complete = true;
    hierarchy.finish();
    AMC_REQUIRE(h.node_count() == meta.nodes && h.vertex_count() == meta.vertices && uint64_t(level) == meta.levels,
                corrupt, "decoded hierarchy does not match the metadata");
    if (has_numbering && numbering != nullptr)
        *numbering = decode_numbering(numbering_block.payload, numbering_block.size, extract_leaf_mesh(h).mesh.triangles,
                                      h.vertex_count());
    return std::move(h);  // out of the level decoder: a copy would cost a third of the decode
}

}  // namespace

Hierarchy decode(const uint8_t* data, size_t size, const DecodeOptions& options, LeafNumbering* numbering) {
    return with_allocation_errors_as_limits("decode", [&] { return decode_file(data, size, options, numbering); });
}

PartialDecode decode_partial(const uint8_t* data, size_t size, const DecodeOptions& options) {
    PartialDecode result;
    PartialProgress progress;
    result.hierarchy = with_allocation_errors_as_limits(
        "decode", [&] { return decode_file(data, size, options, &result.numbering, &progress); });
    result.levels = progress.levels_in_file;
    result.complete = progress.complete;
    result.level = result.complete ? progress.levels_decoded - 1 : progress.levels_decoded;
    return result;
}

Hierarchy in_decoder_order(const Hierarchy& h, const EncodeOptions& options) {
    std::unique_ptr<Quantizer> quantizer;
    if (options.quantize_bits != 0)
        quantizer = std::make_unique<Quantizer>(make_quantizer(all_positions(h), options.quantize_bits));
    bool keep_rotations = false;
    return in_base_code_order(h, base_code_of(h, quantizer.get(), options), keep_rotations);
}

DecodeResult try_decode(const uint8_t* data, size_t size, const DecodeOptions& options) noexcept {
    DecodeResult result;
    try {
        result.hierarchy = decode(data, size, options, &result.numbering);
        result.ok = true;
    } catch (const Error& e) {
        result.code = e.code();
        result.error = e.what();
    } catch (const std::exception& e) {  // nothing else is thrown; should it be, it is still a value
        result.code = ErrorCode::invalid_input;
        result.error = e.what();
    }
    return result;
}

FileInfo inspect(const uint8_t* data, size_t size) {
    AMC_REQUIRE(data != nullptr || size == 0, invalid_input, "no data");
    BlockReader reader(data, size);
    FileInfo info;
    info.version = reader.version();
    info.single_precision = reader.flags() & kFlagSinglePrecision;
    const bool quantized = reader.flags() & kFlagQuantized;
    Block block{};
    int level = 0;
    while (reader.next(block)) {
        FileBlock entry;
        entry.type = uint8_t(block.type);
        entry.name = block_type_name(entry.type);
        entry.offset = block.offset;
        entry.size = block.size + kBlockOverhead;
        if (block.type == BlockType::metadata) {
            const Metadata meta = read_metadata(block, quantized);
            info.base_vertices = meta.base_vertices;
            info.base_triangles = meta.base_triangles;
            info.nodes = meta.nodes;
            info.vertices = meta.vertices;
            info.faces = meta.faces;
            info.levels = int(meta.levels);
            info.quantize_bits = quantized ? meta.quantizer.bits : 0;
        }
        if (block.type == BlockType::level) entry.level = level++;
        info.blocks.push_back(entry);
    }
    return info;
}

}  // namespace amc
