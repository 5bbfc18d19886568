// The .amc file: base mesh, then one block per level with that level's hierarchy decisions and the
// positions of the vertices its refinement creates (docs/FORMAT.md, section 3). This file only
// orders the stages: metadata (file_metadata.h), base mesh (base/base_stage.h), hierarchy
// (hierarchy/hierarchy_level_coder.h), geometry (geometry/level_geometry.h), numbering
// (numbering/numbering_coder.h).
#include <amc/codec.h>

#include "coding/base/base_stage.h"
#include "coding/base_order_search.h"
#include "coding/chunks/chunk_policy.h"
#include "coding/chunks/chunked_file.h"
#include "coding/container.h"
#include "coding/file_metadata.h"
#include "coding/geometry/hierarchy_on_grid.h"
#include "coding/geometry/level_geometry.h"
#include "coding/hierarchy/hierarchy_level_coder.h"
#include "coding/numbering/numbering_coder.h"
#include "common/check.h"
#include "common/parallel.h"
#include "hierarchy/hierarchy_builder.h"
#include "hierarchy/writer_checks.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <future>
#include <memory>
#include <mutex>
#include <string>
#include <utility>

namespace amc {

namespace {

// The live vertices' positions in id order (the order fixes which of two equal-valued zeros
// std::fmin keeps in the grid's origin, so it stays as files were written). Live: the base's
// vertices and the midpoints of the refined live nodes.
std::vector<Vec3> live_positions(const Hierarchy& h) {
    std::vector<uint8_t> live(h.positions().size(), 0);
    std::fill(live.begin(), live.begin() + std::ptrdiff_t(h.base().positions.size()), uint8_t{1});
    for (NodeId n = 0; n < h.node_capacity(); ++n)
        if (h.is_alive(n) && !h.is_leaf(n))
            for (int e = 0; e < 3; ++e) live[h.midpoint(n, e)] = 1;
    std::vector<Vec3> points;
    points.reserve(h.vertex_count());
    for (size_t v = 0; v < live.size(); ++v)
        if (live[v] != 0) points.push_back(h.position(VertexId(v)));
    return points;
}

// Vertices per task of the passes over all positions below.
constexpr size_t kPositionRange = size_t(1) << 16;

// make_quantizer(points)'s bounding box, the points' ranges on `threads` threads: each range's
// fold, then the ranges' in order, which is the one fold over all points. Inline, for finite
// points what std::fmin / std::fmax give (of two equal values, the first: glibc keeps lo's zero).
std::pair<Vec3, Vec3> bounding_box(const std::vector<Vec3>& points, unsigned threads) {
    auto lower = [](Vec3 lo, Vec3 p) { return Vec3{p.x < lo.x ? p.x : lo.x, p.y < lo.y ? p.y : lo.y, p.z < lo.z ? p.z : lo.z}; };
    auto higher = [](Vec3 hi, Vec3 p) { return Vec3{p.x > hi.x ? p.x : hi.x, p.y > hi.y ? p.y : hi.y, p.z > hi.z ? p.z : hi.z}; };
    const size_t ranges = (points.size() + kPositionRange - 1) / kPositionRange;
    std::vector<std::pair<Vec3, Vec3>> boxes(ranges);
    parallel_for(ranges, threads, [&](size_t i) {
        const size_t begin = i * kPositionRange, end = std::min(points.size(), begin + kPositionRange);
        Vec3 lo = points[begin], hi = points[begin];
        for (size_t v = begin; v < end; ++v) {
            lo = lower(lo, points[v]);
            hi = higher(hi, points[v]);
        }
        boxes[i] = {lo, hi};
    });
    Vec3 lo = boxes[0].first, hi = boxes[0].second;
    for (const auto& box : boxes) {
        lo = lower(lo, box.first);
        hi = higher(hi, box.second);
    }
    return {lo, hi};
}

// The grid of `bits` over the input's positions (checked: without removed ids every id is live).
Quantizer quantizer_of(const Hierarchy& input, int bits, unsigned threads) {
    try {
        if (input.vertex_count() == input.positions().size() && !input.positions().empty()) {
            const auto [lo, hi] = bounding_box(input.positions(), threads);
            return make_quantizer(lo, hi, bits);
        }
        return make_quantizer(live_positions(input), bits);
    } catch (const Error& e) {
        throw_error(e.code(), std::string("encode: ") + e.what() +
                                  " (positions that span more than the double range can only be stored bit-exact)");
    }
}

// Gives every position of h to `set(v, r)` as r, the grid point the decoder reconstructs (the
// predictions are made from those: a closed loop); returns the largest coordinate error,
// max_quantization_error's. On `threads` threads, each range of vertices with its own largest error.
template <class Set>
double snap_positions(const Hierarchy& h, const Quantizer& quantizer, unsigned threads, Set&& set) {
    // std::fmax's result: no error is NaN (check_positions passed: p and r are finite) and fabs
    // gives +0, so the largest is one value whatever the order. Each axis on its own, as maxsd
    // without branches: the nested comparisons' branches were coin flips (8 % of a 12-bit encode).
    auto larger = [](double a, double b) { return b > a ? b : a; };
    const size_t vertices = h.positions().size();
    std::vector<double> worst_in((vertices + kPositionRange - 1) / kPositionRange, 0.0);
    const GridSnap snap(quantizer);
    parallel_for(worst_in.size(), threads, [&](size_t i) {
        double worst_x = 0.0, worst_y = 0.0, worst_z = 0.0;
        for (size_t v = i * kPositionRange; v < std::min(vertices, (i + 1) * kPositionRange); ++v) {
            const Vec3 p = h.position(VertexId(v)), r = dequantize(quantizer, snap(p));
            worst_x = larger(worst_x, std::fabs(r.x - p.x));
            worst_y = larger(worst_y, std::fabs(r.y - p.y));
            worst_z = larger(worst_z, std::fabs(r.z - p.z));
            set(VertexId(v), r);
        }
        worst_in[i] = larger(worst_x, larger(worst_y, worst_z));
    });
    double worst = 0.0;
    for (double w : worst_in) worst = larger(worst, w);
    return worst;
}

// The mixing mode's models, newest first, each with the first file version that holds it
// (format_version.h): a mixed file of version v is in the newest model whose version is <= v.
constexpr std::pair<MixingModel, uint8_t> kMixingModelVersions[] = {
    {MixingModel::seventh, kSeventhMixingVersion}, {MixingModel::sixth, kSixthMixingVersion},   {MixingModel::fifth, kFifthMixingVersion},
    {MixingModel::fourth, kFourthMixingVersion}, {MixingModel::third, kThirdMixingVersion},
    {MixingModel::second, kSecondMixingVersion}, {MixingModel::first, kMixedContextsVersion}};

MixingModel mixing_model_of_file(uint8_t file_version) {
    for (const auto& [model, version] : kMixingModelVersions)
        if (file_version >= version) return model;
    return MixingModel::first;
}

uint8_t first_version_of(MixingModel model) {
    for (const auto& [m, version] : kMixingModelVersions)
        if (m == model) return version;
    return kMixedContextsVersion;
}

// The lowest version that holds what the file holds (format_version.h).
// `mixing`: the mixing mode's model; the seventh only in versions 20 and 21, the sixth only in 19, the fifth
// only in 17, the fourth only in 16 (never chunked; they hold every geometry mode); the third is in versions 11-15.
// `base_side`: the base's (and seam's) raw bits in side streams, only with the seventh model when mixed.
// A base in mode 3 makes version 22, whose bit-exact files have the side streams and whose mixed
// files are in the seventh model (encode() sees to both).
uint8_t file_version(bool stencil_tables, bool raw_side, bool unit_geometry, bool grid_geometry, bool mixed_contexts, MixingModel mixing,
                     bool chunked, bool static_geometry, BaseConnectivityMode base_mode, bool store_numbering, bool base_side) {
    const bool windowed_base = base_mode == BaseConnectivityMode::angle_windowed;
    if (mixed_contexts && mixing >= MixingModel::fourth && !windowed_base)
        return base_side ? kBaseRawSideVersion : first_version_of(mixing);
    // Mixed files keep mode 4's per-vertex order (code_forest): only the others hold the grouped one.
    if (const uint8_t newest = newest_features_version(grid_geometry && !mixed_contexts, stencil_tables, raw_side, chunked,
                                                       base_side, windowed_base))
        return newest;
    return unit_geometry                                 ? kUnitFrameVersion
           : mixed_contexts                              ? kThirdMixingVersion
           : grid_geometry                               ? kGridGeometryVersion
           : static_geometry                             ? kStaticGeometryVersion
           : base_mode == BaseConnectivityMode::angle ? kSearchedBaseVersion
           : store_numbering                          ? kNumberingVersion
                                                      : kBaseVersion;
}

// EncodeOptions::chunk_roots as runs of roots, checked against the root count.
std::vector<RootRange> explicit_chunks(const std::vector<uint32_t>& roots_per_chunk, uint32_t roots) {
    std::vector<RootRange> out;
    uint64_t first = 0;
    for (uint32_t count : roots_per_chunk) {
        AMC_REQUIRE(count >= 1, invalid_input, "encode: chunk " + std::to_string(out.size()) + " of chunk_roots has no roots");
        out.push_back({uint32_t(first), count});
        first += count;
    }
    AMC_REQUIRE(first == roots, invalid_input,
                "encode: chunk_roots add up to " + std::to_string(first) + " roots, the hierarchy has " + std::to_string(roots));
    return out;
}

// The hierarchy/geometry split of a level block is estimated at the coder's byte count when the
// hierarchy part ended (they share one arithmetic code).
void add_level_stats(EncodeStats& stats, size_t nodes, size_t new_vertices, size_t hierarchy_part,
                     const std::vector<uint8_t>& payload) {
    const uint64_t hierarchy_bytes = std::min<uint64_t>(hierarchy_part, payload.size() - 1);
    stats.hierarchy_bytes += hierarchy_bytes;
    stats.geometry_bytes += payload.size() - 1 - hierarchy_bytes;
    stats.framing_bytes += kBlockOverhead + 1;
    LevelStats level_stats;
    level_stats.nodes = nodes;
    level_stats.new_vertices = new_vertices;
    level_stats.bytes = kBlockOverhead + payload.size();
    level_stats.predictor = GeometryPredictor(payload[0] & ~kRawSideFlag);
    stats.per_level.push_back(level_stats);
}

// An EncodeContext's memory for the encode's one-chunk stages (null members: none, each stage's own).
struct EncodeMemory {
    HierarchyLevelEncoder::Memory* first_pass = nullptr;
    StaticEncoderBuffers* statics = nullptr;
    ChunkEncoderMemories* chunks = nullptr;  // a chunked file's, one a thread
};

// The forest after the base mesh: one level block per level, or, in two chunks or more, the chunk
// table, the seam and the chunk blocks (a version-7 file).
struct ForestCode {
    std::vector<std::pair<BlockType, std::vector<uint8_t>>> blocks;
    uint64_t bytes = 0;  // of the blocks, framing included
    bool chunked = false, static_geometry = false, grid_geometry = false, unit_geometry = false, raw_side = false, stencil_tables = false;
    bool base_side = false;  // chunked: the seam's and the base's raw bits in side streams (version 21)
    MixingModel mixing = MixingModel::third;  // the mixing mode's model (when the file is mixed)
    uint64_t faces = 0, levels = 0;          // the metadata's
    std::vector<uint8_t> hierarchy_header;  // the metadata's (none with chunks)
    EncodeStats stats;  // header (the chunk table), hierarchy, geometry and framing bytes, levels, hierarchy
};

// Another code of the mixing mode's forest: in `model`, and in the traversal that is not
// EncodeOptions::hierarchy's when `other_traversal`.
struct MixedAlternative {
    MixingModel model;
    bool other_traversal;
    ForestCode* code;
};

// Codes the forest of `h` (decoder base order, or h read in it by `first_pass`, the one chunk's
// hierarchy coder made over TurnedRoots; positions as the decoder will have them, or those of
// `on_grid` when given: one chunk's input nodes with their grid points) in `chunks`;
// `faces` is the leaf face count when there are several. `positions` holds the models as
// the base geometry left them. The mixing mode (FORMAT.md 2.1) codes the forest as one stream, in
// its written model, and also in each model of `older` into its ForestCode: the same first pass
// and the same geometry (which does not depend on the hierarchy's model; each level's chosen
// once), the hierarchy parts in the models' own arithmetic codes. One chunk is coded in `memory`.
// `base_raw_bits`: the base geometry has raw bits for a side stream (encode_chunked).
ForestCode code_forest(const Hierarchy& h, const std::vector<uint32_t>& root_of, const std::vector<uint64_t>& root_nodes,
                       const std::vector<RootRange>& chunks, uint64_t faces,
                       const EncodeOptions& options, CoordinateSpace space, PositionCoder positions, bool base_raw_bits, unsigned threads,
                       bool want_hierarchy_stats, HierarchyLevelEncoder* first_pass, const HierarchyOnGrid* on_grid,
                       const std::vector<MixedAlternative>& older = {}, EncodeMemory memory = {}) {
    ForestCode out;
    const bool mixed = options.hierarchy_contexts == HierarchyContexts::mixed;
    out.chunked = !mixed && chunks.size() > 1;
    if (out.chunked) {
        ChunkedBlocks parts = encode_chunked(h, root_of, root_nodes, chunks, options, space, threads, out.stats, base_raw_bits,
                                             memory.chunks);
        out.base_side = parts.base_side;
        out.static_geometry = parts.static_geometry;
        out.grid_geometry = parts.grid_geometry;
        out.unit_geometry = parts.unit_geometry;
        out.raw_side = parts.raw_side;
        out.stencil_tables = parts.stencil_tables;
        out.faces = faces;
        out.levels = uint64_t(parts.levels);  // the deepest chunk's: the forest's
        out.blocks = std::move(parts.blocks);
    } else {
        std::unique_ptr<HierarchyLevelEncoder> own;
        if (first_pass == nullptr)
            own = std::make_unique<HierarchyLevelEncoder>(h, options.hierarchy, kHierarchyStreamVersion, nullptr, mixed, nullptr,
                                                          memory.first_pass);
        HierarchyLevelEncoder& hierarchy = first_pass != nullptr ? *first_pass : *own;
        std::vector<std::unique_ptr<HierarchyLevelEncoder>> older_hierarchies;
        std::vector<PositionCoder> older_positions;  // the same models level after level
        // The first pass in the other traversal, for the alternatives that code in it (its last one
        // takes it, the others a copy).
        std::unique_ptr<HierarchyLevelEncoder> other_pass;
        size_t other_users = 0;
        for (const MixedAlternative& alternative : older) other_users += alternative.other_traversal;
        if (mixed && other_users > 0) {
            HierarchyCoderOptions other = options.hierarchy;
            other.traversal = other.traversal == Traversal::naive ? Traversal::improved : Traversal::naive;
            bool older_models = false;
            for (const MixedAlternative& alternative : older)
                older_models |= alternative.other_traversal && alternative.model < MixingModel::sixth;
            other_pass = std::make_unique<HierarchyLevelEncoder>(h, other, kHierarchyStreamVersion, nullptr, true, nullptr,
                                                                 nullptr, older_models);
        }
        if (mixed)
            for (const MixedAlternative& alternative : older) {
                if (!alternative.other_traversal)
                    older_hierarchies.push_back(hierarchy.fork());
                else
                    older_hierarchies.push_back(--other_users == 0 ? std::move(other_pass) : other_pass->fork());
                older_hierarchies.back()->set_mixing_model(alternative.model);
                older_positions.push_back(positions);
            }
        hierarchy.set_mixing_model(kWrittenMixingModel);
        auto start = [&](ForestCode& code, const HierarchyLevelEncoder& coder) {
            code.mixing = coder.mixing_model();
            code.faces = coder.faces();
            code.levels = uint64_t(coder.level_count());
            code.hierarchy_header = coder.header();
        };
        start(out, hierarchy);
        for (size_t k = 0; k < older_hierarchies.size(); ++k) start(*older[k].code, *older_hierarchies[k]);
        // `encoder` holds the level's hierarchy part (coder's).
        auto add_level = [&](ForestCode& code, HierarchyLevelEncoder& coder, int l, const auto& geometry_of, const NewVertices& created,
                             LevelGeometryCode& geometry, PositionCoder& models, ArithmeticEncoder& encoder) {
            const size_t hierarchy_part = encoder.bytes_so_far();
            std::vector<uint8_t> payload = finish_level_payload(geometry_of, created, geometry, models, encoder);
            code.static_geometry |= geometry.predictor == GeometryPredictor::normal_frame;
            code.grid_geometry |= geometry.predictor == GeometryPredictor::normal_frame_grid;
            code.unit_geometry |= geometry.predictor == GeometryPredictor::unit_normal_frame;
            code.raw_side |= has_raw_side(payload);
            code.stencil_tables |= has_stencil_tables(geometry.predictor);
            add_level_stats(code.stats, coder.level_nodes(l).size(), created.size(), hierarchy_part, payload);
            code.blocks.emplace_back(BlockType::level, std::move(payload));
        };
        auto code_level = [&](int l, const auto& geometry_of) {
            const NewVertices& created = hierarchy.new_vertices(l);
            ArithmeticEncoder encoder;
            hierarchy.encode_level(l, encoder);
            // The mixing mode's files share each level's geometry across its models' versions (11-17,
            // which hold mode 4 in the per-vertex order); only the written model's takes a trial's coding.
            LevelGeometryCode geometry =
                choose_level_geometry(geometry_of, created, positions, space, options.predictor, options.grid_contexts,
                                      options.unit_normals, options.effort, mixed ? StaticOrder::per_vertex : StaticOrder::grouped,
                                      memory.statics, &encoder);
            add_level(out, hierarchy, l, geometry_of, created, geometry, positions, encoder);
            for (size_t k = 0; k < older_hierarchies.size(); ++k) {
                ArithmeticEncoder older_encoder;
                older_hierarchies[k]->encode_level(l, older_encoder);
                add_level(*older[k].code, *older_hierarchies[k], l, geometry_of, created, geometry, older_positions[k], older_encoder);
            }
        };
        for (int l = 0; l < hierarchy.level_count(); ++l) {
            if (on_grid != nullptr)
                code_level(l, *on_grid);
            else
                code_level(l, h);
        }
        if (want_hierarchy_stats) out.stats.hierarchy = hierarchy.stats();
        if (want_hierarchy_stats)
            for (size_t k = 0; k < older_hierarchies.size(); ++k) older[k].code->stats.hierarchy = older_hierarchies[k]->stats();
    }
    for (const auto& block : out.blocks) out.bytes += kBlockOverhead + block.second.size();
    for (const MixedAlternative& alternative : older)
        for (const auto& block : alternative.code->blocks) alternative.code->bytes += kBlockOverhead + block.second.size();
    return out;
}

// encode() through `memory` (an EncodeContext's, or none).
// With `given_base`, that base connectivity code instead of the base coder's choice.
std::vector<uint8_t> encode_file(const Hierarchy& input, const EncodeOptions& options, EncodeStats* stats_out, EncodeMemory memory,
                                 const BaseMeshCode* given_base = nullptr) {
    EncodeStats stats;
    check_effort(options.effort, "encode");
    const unsigned threads = resolve_thread_count(options.threads);
    // Whatever is encoded decodes: the decoder's checks first (base mesh, structure, positions).
    check_before_writing(input, "encode", true, threads);
    const bool quantized = options.quantize_bits != 0;
    // Quantized coordinates are reconstructed as doubles on the grid, whatever the input precision.
    const Precision precision = input.single_precision() && !quantized ? Precision::float32 : Precision::float64;
    Quantizer quantizer;
    if (quantized) quantizer = quantizer_of(input, options.quantize_bits, threads);
    const CoordinateSpace space{precision, quantized ? &quantizer : nullptr};

    const bool automatic = options.chunk_roots.empty() && options.chunks == 0;
    // A leaf has at most four faces (itself and three hanging nodes): fewer than two chunks' faces,
    // so one chunk (chunk_count_for), known without the passes over the nodes that count faces and
    // nodes per root.
    const bool few_leaves = automatic && uint64_t(input.leaf_count()) * 2 < std::max<uint64_t>(1, options.chunk_faces);
    const bool one_chunk_asked = options.chunk_roots.empty() ? options.chunks == 1 || few_leaves : options.chunk_roots.size() == 1;
    // Leaf faces do not depend on the order: counted on the input, so that automatic chunks of
    // fewer faces than two chunks' are known to be one before the order is chosen.
    const uint64_t faces = one_chunk_asked ? 0 : leaf_face_count(input, threads);
    const bool one_chunk = one_chunk_asked || (automatic && chunk_count_for(options, faces) == 1);
    const bool mixed = options.hierarchy_contexts == HierarchyContexts::mixed;

    // II-B: code the base mesh first and express the forest in the decoder's base order. One chunk
    // is coded from the input read in that order (TurnedRoots): reorder_base's copy was a quarter
    // of a 10^5-face encode. Chunks are cut from the reordered copy, and a numbering is mapped
    // through it; a forest with free ids (none after reading a file) is copied too.
    const BaseMeshCode base_code = given_base != nullptr ? *given_base : base_code_of(input, space.quantizer, options);
    const bool turned_input = one_chunk && !mixed && options.numbering == nullptr && input.node_count() == input.node_capacity() &&
                              input.vertex_count() == input.positions().size();
    ReorderedInput reordered;  // the whole in base code order, or with turned_input its base alone
    BaseCodeOrder order;
    std::vector<Vec3> grid_positions;  // with turned_input and quantized: the input's on the grid, by vertex id
    const HierarchyOnGrid on_grid(input, grid_positions);
    const TurnedRoots turned{&reordered.hierarchy, &base_code.triangle_order, &order.rotation};
    std::unique_ptr<HierarchyLevelEncoder> first_pass;  // with turned_input: the hierarchy coder's
    if (turned_input) {
        if (quantized) {
            grid_positions.resize(input.positions().size());
            stats.max_error = snap_positions(input, quantizer, threads, [&](VertexId v, Vec3 r) { grid_positions[v] = r; });
        }
        // The first pass reads the forest turned by the base coder's rotations and tallies the
        // diagonal flags both ways (base_code_order's choice); when the roots keep the input's
        // order instead (a rule of absolute local indices), it runs again unturned.
        auto read_in_order = [&](bool keep_rotations) {
            order = base_code_order(base_code, keep_rotations);
            reordered.keep_rotations = keep_rotations;
            std::vector<uint32_t> base_vertex_id;
            TriangleMesh base = HierarchyBuilder::reordered_base_mesh(input.base(), base_code.vertex_order,
                                                                      base_code.triangle_order, order.rotation, base_vertex_id);
            // Base vertex i is the input's vertex_order[i], already on the grid in grid_positions.
            if (quantized)
                for (size_t i = 0; i < base.positions.size(); ++i) base.positions[i] = grid_positions[base_code.vertex_order[i]];
            reordered.hierarchy = Hierarchy(std::move(base));
            if (quantized) reordered.hierarchy.set_single_precision(false);
            first_pass.reset();  // its memory back before the next one takes it
            first_pass = std::make_unique<HierarchyLevelEncoder>(input, options.hierarchy, kHierarchyStreamVersion, nullptr,
                                                                 false, &turned, memory.first_pass);
        };
        read_in_order(false);
        if (keeps_rotations(first_pass->diagonal_exceptions(), first_pass->unturned_diagonal_exceptions(),
                            base_code.triangle_order.size()))
            read_in_order(true);
    } else {
        reordered = in_base_code_order(input, base_code, options.numbering != nullptr, threads);
        if (options.numbering != nullptr)
            stats.numbering = numbering_after_reorder(input, *options.numbering, reordered.hierarchy, reordered.vertex_map);
        if (quantized) {
            reordered.hierarchy.set_single_precision(false);
            Hierarchy& h = reordered.hierarchy;  // it holds exactly the input's live positions
            stats.max_error = snap_positions(h, quantizer, threads, [&h](VertexId v, Vec3 r) { h.set_position(v, r); });
        }
    }
    const Hierarchy& h = !turned_input ? reordered.hierarchy : input;
    const bool store_numbering = options.numbering != nullptr && options.store_numbering;

    // The forest (FORMAT.md 3.6, 3.11), after the base geometry, whose adaptive models the level
    // blocks go on with. Chunks the caller leaves to the encoder are tried first at chunk_faces
    // faces each, then fewer if that code is too small for them (chunk_policy.h).
    // Bit-exact: the raw bits apart (version 21) unless the file ends up without any or in an older
    // mixing model (below); they are the same symbols either way, so `positions` is the same.
    PositionCoder positions(space);
    const RawSideCode base_geometry = encode_base_geometry(reordered.hierarchy, base_code, reordered.keep_rotations, positions, !quantized);
    // Version 22 (a base in mode 3) keeps the side stream of a bit-exact base even without raw bits.
    const bool windowed_base = base_code.mode == BaseConnectivityMode::angle_windowed;
    const bool base_raw_bits = !base_geometry.raw.empty() || (windowed_base && !quantized);
    // The base geometry block of the versions before 21: its raw bits in the arithmetic code.
    std::vector<uint8_t> base_inline;
    auto inline_base = [&]() -> const std::vector<uint8_t>& {
        if (!base_raw_bits) return base_geometry.arithmetic;
        if (base_inline.empty()) {
            PositionCoder again(space);
            base_inline = encode_base_geometry(reordered.hierarchy, base_code, reordered.keep_rotations, again, false).arithmetic;
        }
        return base_inline;
    };
    const std::vector<uint32_t> root_of = one_chunk ? std::vector<uint32_t>() : root_of_nodes(h);
    const std::vector<uint64_t> root_nodes = one_chunk ? std::vector<uint64_t>() : nodes_per_root(h, root_of);
    const std::vector<RootRange> chunks = !options.chunk_roots.empty() ? explicit_chunks(options.chunk_roots, h.root_count())
                                          : one_chunk ? std::vector<RootRange>{RootRange{0, h.root_count()}}
                                                      : balanced_chunks(root_nodes, chunk_count_for(options, faces));
    const bool want_hierarchy_stats = stats_out != nullptr && options.hierarchy_statistics;
    // The mixing mode's forest in its older models, and with choose_traversal in the other traversal.
    ForestCode sixth, fifth, fourth, third, other_seventh;
    // Version 22 (a base in mode 3) holds the seventh model only.
    std::vector<MixedAlternative> older =
        mixed && !windowed_base
            ? std::vector<MixedAlternative>{{MixingModel::sixth, false, &sixth}, {MixingModel::fifth, false, &fifth},
                                            {MixingModel::fourth, false, &fourth}, {MixingModel::third, false, &third}}
            : std::vector<MixedAlternative>();
    if (mixed && options.choose_traversal) older.push_back({kWrittenMixingModel, true, &other_seventh});
    ForestCode forest = code_forest(h, root_of, root_nodes, chunks, faces, options, space, positions, base_raw_bits, threads,
                                    want_hierarchy_stats, first_pass.get(), turned_input && quantized ? &on_grid : nullptr, older, memory);
    const uint32_t fewer = automatic && forest.chunked ? chunk_count_for_size(options, uint32_t(chunks.size()), forest.bytes)
                                                       : uint32_t(chunks.size());
    if (fewer < chunks.size())
        forest = code_forest(h, root_of, root_nodes, balanced_chunks(root_nodes, fewer), faces, options, space, positions,
                             base_raw_bits, threads, want_hierarchy_stats, nullptr, nullptr, {}, memory);
    // An older model of the mixing mode where it codes the file smaller (small files, whose new
    // tables have little to learn from, or creased ones, by a few bytes): every file at most as
    // large as each older model's. A tie keeps the newer model, then the asked traversal. The
    // seventh model's base block is version 21's (bit-exact), the older ones' that of their versions.
    if (!older.empty()) {
        const uint64_t newest_base = base_raw_bits ? base_geometry.joined().size() : base_geometry.arithmetic.size();
        uint64_t best = forest.bytes + newest_base;
        for (const MixedAlternative& alternative : older) {
            const uint64_t bytes =
                alternative.code->bytes + (alternative.model == kWrittenMixingModel ? newest_base : inline_base().size());
            if (bytes < best) {
                best = bytes;
                forest = std::move(*alternative.code);
            }
        }
    }

    Metadata meta;
    meta.base_vertices = h.base().positions.size();
    meta.base_triangles = h.root_count();
    meta.nodes = h.node_count();
    meta.vertices = h.vertex_count();
    meta.faces = forest.faces;
    meta.levels = forest.levels;
    meta.hierarchy_header = forest.hierarchy_header;
    meta.quantizer = quantizer;
    meta.options = (reordered.keep_rotations ? kOptionRootRotations : 0) | (forest.chunked ? kOptionChunked : 0) |
                   (mixed ? kOptionMixedContexts : 0);

    // The version in the header depends on the level modes chosen.
    std::vector<std::pair<BlockType, std::vector<uint8_t>>> blocks;
    blocks.emplace_back(BlockType::metadata, write_metadata(meta, quantized));
    stats.header_bytes = kFileHeaderSize + kBlockOverhead + blocks.back().second.size() + forest.stats.header_bytes;
    blocks.emplace_back(BlockType::base_connectivity, base_code.bytes);
    stats.base_connectivity_bytes = base_code.bytes.size();
    // Version 21 (bit-exact): the base's raw bits apart when it or the seam has some, with the
    // seventh mixing model when mixed; an older model's version holds them in the arithmetic code.
    const bool base_side =
        forest.chunked ? forest.base_side : base_raw_bits && (!mixed || forest.mixing == mixing_model_of_file(kBaseRawSideVersion));
    std::vector<uint8_t> base_block = base_side ? base_geometry.joined() : inline_base();
    stats.base_geometry_bytes = base_block.size();
    blocks.emplace_back(BlockType::base_geometry, std::move(base_block));
    stats.hierarchy_bytes = forest.stats.hierarchy_bytes;
    stats.geometry_bytes = forest.stats.geometry_bytes;
    stats.framing_bytes = forest.stats.framing_bytes;
    stats.per_level = std::move(forest.stats.per_level);
    for (auto& block : forest.blocks) blocks.push_back(std::move(block));
    if (store_numbering) {
        blocks.emplace_back(BlockType::numbering, encode_numbering(stats.numbering, extract_leaf_mesh(h).mesh.triangles));
        stats.numbering_bytes = blocks.back().second.size();
        stats.framing_bytes += kBlockOverhead;
    }
    BlockWriter writer(file_version(forest.stencil_tables, forest.raw_side, forest.unit_geometry, forest.grid_geometry, mixed, forest.mixing,
                                    forest.chunked, forest.static_geometry,
                                    base_code.mode, store_numbering, base_side),
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
    stats.levels = int(meta.levels);
    if (stats_out != nullptr) {
        stats.hierarchy = forest.stats.hierarchy;
        *stats_out = stats;
    }
    return out;
}

// encode_file(), at effort 3 with the base order chosen (base_order_search.h): the file in the
// base coder's order first, then in each candidate's, several at once on `threads` threads; the
// smallest is kept, of equal ones the earliest, so the bytes do not depend on the threads.
// `chosen`, when given, gets the kept base code.
std::vector<uint8_t> encode_choosing_base(const Hierarchy& input, const EncodeOptions& options, EncodeStats* stats_out,
                                          EncodeMemory memory, BaseMeshCode* chosen = nullptr) {
    check_effort(options.effort, "encode");
    const bool fixed_order = options.keep_base_order || (options.numbering != nullptr && options.store_numbering);
    if (options.effort < kBaseOrderEffort && chosen == nullptr) return encode_file(input, options, stats_out, memory);
    const unsigned threads = resolve_thread_count(options.threads);
    EncodeOptions at_two = options;
    at_two.effort = std::min(options.effort, kMaxGeometryEffort);
    std::unique_ptr<Quantizer> quantizer;
    if (options.quantize_bits != 0) quantizer = std::make_unique<Quantizer>(quantizer_of(input, options.quantize_bits, threads));
    const TriangleMesh base = base_as_decoded(input, quantizer.get());  // what every order codes
    BaseMeshCode own = base_code_of(input, base, at_two);
    EncodeStats best_stats;
    std::vector<uint8_t> best = encode_file(input, at_two, stats_out != nullptr ? &best_stats : nullptr, memory, &own);
    std::vector<BaseMeshCode> trials;  // coded in full, in the rank of their base blocks' bytes
    if (options.effort >= kBaseOrderEffort && !fixed_order) {
        const BaseOrderSearch search = kBaseOrderSearches[options.effort - kBaseOrderEffort];
        std::vector<BaseMeshCode> candidates = base_order_candidates(base, own, search.starts, threads);
        std::vector<std::pair<uint64_t, size_t>> ranked(candidates.size());
        parallel_for(candidates.size(), threads,
                     [&](size_t c) { ranked[c] = {base_blocks_bytes(base, quantizer.get(), candidates[c]), c}; });
        std::sort(ranked.begin(), ranked.end());
        for (size_t k = 0; k < std::min(search.trials, ranked.size()); ++k) trials.push_back(std::move(candidates[ranked[k].second]));
    }
    // The trials at once, each on the threads left to it. The caller's memory serves one at a time:
    // a worker takes a memory for each trial and gives it back (one that threw stops, keeping its).
    const unsigned workers = unsigned(std::max<size_t>(1, std::min<size_t>(trials.size(), threads)));
    at_two.threads = threads / workers;
    std::mutex mutex;
    std::vector<EncodeMemory> free_memory(workers);
    free_memory[0] = memory;
    size_t kept = trials.size();  // none: the base coder's order
    parallel_for(trials.size(), workers, [&](size_t i) {
        EncodeMemory mine;
        {
            std::lock_guard<std::mutex> lock(mutex);
            mine = free_memory.back();
            free_memory.pop_back();
        }
        EncodeStats stats;
        std::vector<uint8_t> file = encode_file(input, at_two, stats_out != nullptr ? &stats : nullptr, mine, &trials[i]);
        std::lock_guard<std::mutex> lock(mutex);
        free_memory.push_back(mine);
        if (file.size() > best.size() || (file.size() == best.size() && (kept == trials.size() || kept < i))) return;
        best = std::move(file);
        best_stats = std::move(stats);
        kept = i;
    });
    if (stats_out != nullptr) *stats_out = std::move(best_stats);
    if (chosen != nullptr) *chosen = kept < trials.size() ? std::move(trials[kept]) : std::move(own);
    return best;
}

}  // namespace

std::vector<uint8_t> encode(const Hierarchy& input, const EncodeOptions& options, EncodeStats* stats_out) {
    return encode_choosing_base(input, options, stats_out, {});
}

std::vector<uint8_t> encode_with_base(const Hierarchy& h, const EncodeOptions& options, const BaseMeshCode& base, EncodeStats* stats) {
    return encode_file(h, options, stats, {}, &base);
}

struct EncodeContext::Kept {
    HierarchyLevelEncoder::Memory first_pass;
    StaticEncoderBuffers statics;
    ChunkEncoderMemories chunks;
};

EncodeContext::EncodeContext() : kept_(std::make_unique<Kept>()) {}
EncodeContext::~EncodeContext() = default;
EncodeContext::EncodeContext(EncodeContext&&) noexcept = default;
EncodeContext& EncodeContext::operator=(EncodeContext&&) noexcept = default;

void EncodeContext::release() {
    if (kept_ != nullptr) kept_ = std::make_unique<Kept>();
}

std::vector<uint8_t> encode(EncodeContext& context, const Hierarchy& h, const EncodeOptions& options, EncodeStats* stats) {
    if (context.kept_ == nullptr) context.kept_ = std::make_unique<EncodeContext::Kept>();  // moved from
    return encode_choosing_base(h, options, stats, {&context.kept_->first_pass, &context.kept_->statics, &context.kept_->chunks});
}

namespace {

// How far a partial file got (decode_partial); null for a whole file.
struct PartialProgress {
    int levels_decoded = 0, levels_in_file = 0;
    bool complete = false;
};

// The chunks a reader asked for (decode_chunks); null for the whole file.
struct ChunkRequest {
    std::vector<uint32_t> chunks;
    ChunkDecode* result;
};

// A chunked file (version 7) after its base mesh: chunk table, seam, chunks, then the numbering
// block, if any, and END.
Hierarchy decode_chunked_file(BlockReader& reader, const Metadata& meta, const TriangleMesh& base, CoordinateSpace space,
                              const DecodeOptions& options, LeafNumbering* numbering, PartialProgress* partial,
                              const ChunkRequest* request, std::future<std::vector<Vec3>>* zeroed_positions,
                              ChunkDecoders* kept_decoders, Hierarchy* spare) {
    AMC_REQUIRE(reader.version() >= kChunkedVersion, corrupt, "metadata block: chunks in a version-" + std::to_string(reader.version()) + " file");
    if (partial != nullptr) {
        partial->levels_in_file = int(meta.levels);
        // Chunks decode once all of them have arrived; before that a partial file gives its base.
        BlockReader probe = reader;
        Block block{};
        bool complete = false;
        while (!complete && probe.next_block_arrived() && probe.next(block)) complete = block.type == BlockType::end;
        if (!complete) return Hierarchy(base);
    }
    const ChunkedDecodeInput input{&base, space, reader.version(), meta.vertices, options, zeroed_positions,
                                   kept_decoders, spare};
    ChunkTable table;
    MergedCounts counts;
    Hierarchy h = decode_chunked(reader, input, meta.nodes, request != nullptr ? &request->chunks : nullptr, &table, &counts);
    if (request != nullptr) {
        for (uint32_t c : request->chunks)
            for (uint32_t r = table.roots[c].first; r < table.roots[c].first + table.roots[c].count; ++r)
                request->result->roots.push_back(r);
        base_of_roots(base, [&] {
            std::vector<RootRange> ranges;
            for (uint32_t c : request->chunks) ranges.push_back(table.roots[c]);
            return ranges;
        }(), request->result->base_vertices);
        return h;
    }
    if (options.max_level >= 0) return h;
    Block block{};
    AMC_REQUIRE(reader.next(block), corrupt, "file ends after its chunks");
    if (block.type == BlockType::numbering) {
        if (numbering != nullptr)
            *numbering = decode_numbering(block.payload, block.size, extract_leaf_mesh(h).mesh.triangles, h.vertex_count());
        AMC_REQUIRE(reader.next(block), corrupt, "file ends after its numbering block");
    }
    AMC_REQUIRE(block.type == BlockType::end, corrupt, std::string("unexpected ") + block_type_name(uint8_t(block.type)) + " block after the chunks");
    AMC_REQUIRE(h.node_count() == meta.nodes && h.vertex_count() == meta.vertices && uint64_t(counts.depth + 1) == meta.levels &&
                    counts.faces == meta.faces,
                corrupt, "decoded hierarchy does not match the metadata");
    if (partial != nullptr) {
        partial->complete = true;
        partial->levels_decoded = int(meta.levels);
    }
    return h;
}

Hierarchy decode_file(const uint8_t* data, size_t size, const DecodeOptions& options, LeafNumbering* numbering,
                      PartialProgress* partial = nullptr, const ChunkRequest* request = nullptr,
                      ChunkDecoders* kept_decoders = nullptr, Hierarchy* spare = nullptr) {
    if (numbering != nullptr) *numbering = {};
    AMC_REQUIRE(data != nullptr || size == 0, invalid_input, "no data");
    BlockReader reader(data, size);
    const bool quantized = reader.flags() & kFlagQuantized;
    const Precision precision = (reader.flags() & kFlagSinglePrecision) ? Precision::float32 : Precision::float64;
    AMC_REQUIRE(!(quantized && precision == Precision::float32), corrupt, "file header: quantized and float32 flags together");
    AMC_REQUIRE(!(quantized && reader.version() == kBaseRawSideVersion), corrupt,
                "file header: a quantized file of version " + std::to_string(kBaseRawSideVersion) + " (bit-exact only)");
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
    // Several threads decode a whole chunked file into slices of its hierarchy, whose positions
    // another thread zeroes meanwhile, where the file's size warrants its counts (as for slices:
    // plan_merge).
    std::future<std::vector<Vec3>> zeroed_positions;
    if ((meta.options & kOptionChunked) && reader.version() >= kChunkVerticesVersion && partial == nullptr &&
        request == nullptr && options.max_level < 0 && resolve_thread_count(options.threads) > 1 &&
        meta.nodes <= reservable_nodes(meta.base_triangles, size))
        zeroed_positions = start_zeroed_positions(size_t(meta.vertices));
    const Block connectivity_block = expect(BlockType::base_connectivity);
    const Block geometry_block = expect(BlockType::base_geometry);
    const CoordinateSpace space{precision, quantized ? &meta.quantizer : nullptr};
    PositionCoder positions(space);
    const TriangleMesh base =
        decode_base(connectivity_block, geometry_block, meta, reader.version(), precision == Precision::float32, positions);
    AMC_REQUIRE(!(meta.options & kOptionMixedContexts) || reader.version() >= kMixedContextsVersion, corrupt,
                "metadata block: mixed hierarchy contexts in a version-" + std::to_string(reader.version()) + " file");
    AMC_REQUIRE(!((meta.options & kOptionMixedContexts) && (meta.options & kOptionChunked)), corrupt,
                "metadata block: mixed hierarchy contexts in a chunked file");
    if (meta.options & kOptionChunked)
        return decode_chunked_file(reader, meta, base, space, options, numbering, partial, request, &zeroed_positions,
                                   kept_decoders, spare);
    if (request != nullptr) {  // a file without chunks is one chunk
        AMC_REQUIRE(request->chunks.size() == 1 && request->chunks[0] == 0, invalid_input,
                    "the file has no chunks: only chunk 0, the whole file, can be decoded");
        for (uint32_t r = 0; r < base.triangles.size(); ++r) request->result->roots.push_back(r);
        for (uint32_t v = 0; v < base.positions.size(); ++v) request->result->base_vertices.push_back(v);
    }

    HierarchyLevelDecoder hierarchy(base, meta.hierarchy_header.data(), meta.hierarchy_header.size(),
                                    hierarchy_stream_version_of_file(reader.version()),
                                    std::min<uint64_t>(meta.nodes, options.max_nodes));
    if (meta.options & kOptionMixedContexts)
        hierarchy.use_mixed_contexts(mixing_model_of_file(reader.version()));
    // The decode peaks at the last level built, whose nodes come on top of the working memory of
    // the levels before: there that memory goes back to the system.
    hierarchy.set_lean_at_end(options.lean_memory);
    hierarchy.set_single_stream(true);
    Hierarchy& h = hierarchy.hierarchy();
    // The metadata's counts let the hierarchy grow in place, as far as the file's size warrants,
    // or the uniform levels, which are built whatever the stream holds (a file of uniform levels
    // is tiny: grown level by level, its old arrays raised glibc's thresholds, and with them
    // the freed memory it keeps).
    const uint64_t reserved_nodes = std::min<uint64_t>(
        meta.nodes, std::max<uint64_t>(reservable_nodes(meta.base_triangles, size),
                                       hierarchy.uniform_node_count(options.max_level)));
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
        // Level blocks: every version before chunks, and the unchunked files of the mixing mode and
        // of version 9 on.
        AMC_REQUIRE(block.type == BlockType::level &&
                        (reader.version() < kChunkedVersion || (meta.options & kOptionMixedContexts) ||
                         reader.version() >= kGridGeometryVersion),
                    corrupt,
                    "unexpected block between level blocks");
        AMC_REQUIRE(!hierarchy.done(), corrupt, "level block after the last level");
        if (options.max_level >= 0 && level >= options.max_level) return std::move(h);  // progressive: stop here
        const std::string where = "level " + std::to_string(level) + " block";
        const LevelBlockParts parts = split_level_block(block, reader.version(), space.quantizer != nullptr,
                                                        (meta.options & kOptionMixedContexts) != 0, where);
        ArithmeticDecoder decoder(parts.arithmetic, parts.arithmetic_size);
        // Every new vertex gets its decoded position below; a static mode with a frame takes their
        // frame corners from the split, without reading the nodes again; the arithmetic modes
        // walk the split's parents for their edges (a list would be 8 bytes a vertex at the peak).
        const bool listed = has_frame(parts.predictor), walked = !is_static_mode(parts.predictor);
        hierarchy.set_new_vertex_listing(listed || walked, false, listed);
        // The refined nodes R of a level create at least 1.5 R vertices, whose positions are in
        // this block: it bounds R before the next level is allocated.
        hierarchy.decode_level(decoder, 2 * max_decodable_positions(block.size - 1) / 3);
        if (listed)
            decode_listed_level_geometry(h, hierarchy.new_vertex_corners(), parts, decoder, space, where);
        else if (walked)
            decode_walked_level_geometry(h, hierarchy.new_vertex_edges(), parts, decoder, positions, level, where);
        else
            decode_level_geometry(h, hierarchy.new_vertices(), parts, decoder, positions, space, level, where);
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
    Hierarchy h = with_allocation_errors_as_limits("decode", [&] { return decode_file(data, size, options, numbering); });
    // Decoders build only what balance and closure allow, and the amc_decode fuzz target holds
    // every decoded hierarchy to check_invariants: writers need not walk it again.
    HierarchyBuilder::mark_structure_checked(h);
    return h;
}

struct DecodeContext::Kept {
    ChunkDecoders chunk_decoders;
    Hierarchy spare;  // recycle()'s: its storage taken by the next decode
};

DecodeContext::DecodeContext() : kept_(std::make_unique<Kept>()) {}
DecodeContext::~DecodeContext() = default;
DecodeContext::DecodeContext(DecodeContext&&) noexcept = default;
DecodeContext& DecodeContext::operator=(DecodeContext&&) noexcept = default;

void DecodeContext::release() {
    if (kept_ == nullptr) return;
    kept_->chunk_decoders.clear();
    kept_->spare = Hierarchy();
}

void DecodeContext::recycle(Hierarchy&& done) {
    if (kept_ == nullptr) kept_ = std::make_unique<Kept>();  // moved from
    kept_->spare = std::move(done);
}

Hierarchy decode(DecodeContext& context, const uint8_t* data, size_t size, const DecodeOptions& options,
                 LeafNumbering* numbering) {
    if (context.kept_ == nullptr) context.kept_ = std::make_unique<DecodeContext::Kept>();  // moved from
    ChunkDecoders* kept = &context.kept_->chunk_decoders;
    Hierarchy* spare = &context.kept_->spare;
    Hierarchy h = with_allocation_errors_as_limits(
        "decode", [&] { return decode_file(data, size, options, numbering, nullptr, nullptr, kept, spare); });
    HierarchyBuilder::mark_structure_checked(h);  // as decode without a context
    return h;
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

ChunkDecode decode_chunks(const uint8_t* data, size_t size, const std::vector<uint32_t>& chunks, const DecodeOptions& options) {
    ChunkDecode result;
    const ChunkRequest request{chunks, &result};
    result.hierarchy = with_allocation_errors_as_limits(
        "decode", [&] { return decode_file(data, size, options, nullptr, nullptr, &request); });
    return result;
}

std::vector<uint32_t> chunks_covering(const FileInfo& info, const std::vector<uint32_t>& base_triangles) {
    std::vector<uint32_t> out;
    for (uint32_t t : base_triangles) {
        AMC_REQUIRE(t < info.base_triangles, invalid_input,
                    "base triangle " + std::to_string(t) + " is not in the file (it has " + std::to_string(info.base_triangles) + ")");
        // The last chunk starting at or before t (first roots increase): a search, not a pass per triangle.
        const auto after = std::upper_bound(info.chunks.begin(), info.chunks.end(), t,
                                            [](uint32_t root, const ChunkInfo& chunk) { return root < chunk.first_root; });
        out.push_back(after == info.chunks.begin() ? 0 : uint32_t(after - info.chunks.begin()) - 1);
    }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
}

Hierarchy in_decoder_order(const Hierarchy& h, const EncodeOptions& options) {
    if (options.effort >= kBaseOrderEffort) {
        BaseMeshCode chosen;
        encode_choosing_base(h, options, nullptr, {}, &chosen);
        return in_base_code_order(h, chosen, false).hierarchy;
    }
    std::unique_ptr<Quantizer> quantizer;
    if (options.quantize_bits != 0)
        quantizer = std::make_unique<Quantizer>(make_quantizer(live_positions(h), options.quantize_bits));
    return in_base_code_order(h, base_code_of(h, quantizer.get(), options), false).hierarchy;
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
    size_t table_start = 0;  // the last chunk table's first entry in info.chunks
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
        if (block.type == BlockType::chunk_table) {
            const ChunkTable table = read_chunk_table(block, info.version, info.base_triangles, info.nodes, size);
            table_start = info.chunks.size();
            for (size_t c = 0; c < table.roots.size(); ++c)
                info.chunks.push_back({table.roots[c].first, table.roots[c].count, table.nodes[c], table.end + table.offsets[c], 0});
        }
        if (block.type == BlockType::chunk) {
            // A table's offsets increase (read_chunk_table): a search, not a pass over every chunk per block.
            const auto chunk = std::lower_bound(info.chunks.begin() + std::ptrdiff_t(table_start), info.chunks.end(),
                                                uint64_t(block.offset),
                                                [](const ChunkInfo& c, uint64_t offset) { return c.offset < offset; });
            if (chunk != info.chunks.end() && chunk->offset == block.offset) chunk->size = entry.size;
        }
        info.blocks.push_back(entry);
    }
    return info;
}

}  // namespace amc
