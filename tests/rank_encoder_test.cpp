// A chunked file written rank by rank (src/coding/distributed/rank_encoder.h), every rank played by
// this one process: the bytes are exactly the serial encoder's with the ranks' chunks, whatever
// numbering each rank gives its base vertices, and inputs that do not fit together are refused.
// The same steps under mpirun, with MPI moving the bytes: tests/mpi/.
#include "coding/distributed/rank_encoder.h"
#include "coding/distributed/rank_grid.h"
#include "coding/format_version.h"
#include "rank_fixtures.h"

#include <amc/codec.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <optional>

namespace amc {
namespace {

using testing::Random;
using testing::adaptive_hierarchy;
using testing::cut;
using testing::projected_sphere;
using testing::ranks_of;

using Rank = testing::RankForest;

// The file the ranks write together: the steps of rank_encoder.h, each exchange a loop.
std::vector<uint8_t> write_by_ranks(const TriangleMesh& base, const std::vector<Rank>& ranks, const EncodeOptions& options) {
    std::vector<RankChunk> parts;
    std::vector<RootRange> ranges;
    for (size_t r = 0; r < ranks.size(); ++r) {
        parts.push_back(rank_chunk(base, ranks[r].first_root, ranks[r].forest, "rank " + std::to_string(r)));
        ranges.push_back({ranks[r].first_root, ranks[r].forest.root_count()});
    }
    const RankLayout layout = rank_layout(uint32_t(base.triangles.size()), ranges);
    std::optional<Quantizer> grid;
    if (options.quantize_bits != 0) {
        std::vector<RankBox> boxes;
        for (const RankChunk& part : parts) boxes.push_back(rank_box(base, part));
        std::reverse(boxes.begin(), boxes.end());  // in any order
        grid = grid_of_ranks(boxes, options.quantize_bits, "ranks");
    }
    const Quantizer* grid_or_null = grid ? &*grid : nullptr;
    if (layout.chunks.size() == 1) {  // one rank owns every root: a file without chunks
        EncodeOptions whole = options;
        whole.keep_base_order = true;
        whole.chunk_roots = {uint32_t(base.triangles.size())};
        for (size_t r = 0; r < ranks.size(); ++r)
            if (layout.chunk_of_rank[r] == 0) return encode(parts[r].chunk, whole);
    }
    std::vector<SeamSplit> splits;
    for (const RankChunk& part : parts) {
        const std::vector<SeamSplit> mine = seam_splits(part, base, layout);
        splits.insert(splits.end(), mine.begin(), mine.end());
    }
    const Seam seam = rank_seam(base, layout, splits, grid_or_null);
    std::vector<RankCode> codes(layout.chunks.size());
    for (size_t r = 0; r < ranks.size(); ++r) {
        if (grid) snap_to_grid(parts[r], *grid);
        if (layout.chunk_of_rank[r] >= 0)
            codes[size_t(layout.chunk_of_rank[r])] = encode_rank_chunk(parts[r], seam, options, grid_or_null, "rank " + std::to_string(r));
    }
    std::vector<ChunkSummary> summaries;
    for (const RankCode& code : codes) summaries.push_back(code.summary);
    std::vector<uint8_t> file = chunked_file_head(base, seam, summaries, options, grid_or_null);
    for (const RankCode& code : codes) file.insert(file.end(), code.block.begin(), code.block.end());
    const std::vector<uint8_t> end = end_block();
    file.insert(file.end(), end.begin(), end.end());
    return file;
}

TEST(RankEncoder, RanksWriteTheSerialEncodersBytes) {
    int files = 0;
    for (uint64_t seed = 0; seed < 24; ++seed) {
        SCOPED_TRACE("seed " + std::to_string(seed));
        const Hierarchy h = adaptive_hierarchy(seed);
        for (uint32_t p : {1u, 2u, 3u, 5u}) {
            for (bool empty : {false, true}) {
                if (empty && p < 2) continue;
                const std::vector<uint32_t> counts = cut(h.root_count(), p, seed + p, empty);
                EncodeOptions options;
                options.predictor = GeometryPredictor(seed % 4);
                const std::vector<uint8_t> bytes = write_by_ranks(h.base(), ranks_of(h, counts, seed), options);
                options.keep_base_order = true;
                for (uint32_t c : counts)
                    if (c > 0) options.chunk_roots.push_back(c);
                ASSERT_EQ(bytes, encode(h, options)) << p << " ranks";
                const Hierarchy back = decode(bytes.data(), bytes.size());
                ASSERT_TRUE(identical(back, h));
                ++files;
            }
        }
    }
    EXPECT_EQ(files, 24 * 7);
}

// The serial encoder's options for the file the ranks write with `counts` roots.
EncodeOptions serial_options(EncodeOptions options, const std::vector<uint32_t>& counts) {
    options.keep_base_order = true;
    for (uint32_t c : counts)
        if (c > 0) options.chunk_roots.push_back(c);
    return options;
}

TEST(RankEncoder, RanksWriteTheSerialEncodersQuantizedBytes) {
    int files = 0, grid_files = 0;
    for (uint64_t seed = 0; seed < 12; ++seed) {
        SCOPED_TRACE("seed " + std::to_string(seed));
        const Hierarchy h = adaptive_hierarchy(seed);
        for (uint32_t p : {1u, 2u, 3u, 5u}) {
            const std::vector<uint32_t> counts = cut(h.root_count(), p, seed + p, p == 3);
            EncodeOptions options;
            options.quantize_bits = int(4 + (seed * 5 + p) % 20);
            options.grid_contexts = seed % 2 == 0;  // the automatic predictor may take mode 4
            options.predictor = seed % 3 == 0 ? GeometryPredictor::normal_frame_grid : seed % 3 == 1 ? GeometryPredictor::automatic : GeometryPredictor(seed % 4);
            const std::vector<uint8_t> bytes = write_by_ranks(h.base(), ranks_of(h, counts, seed), options);
            ASSERT_EQ(bytes, encode(h, serial_options(options, counts))) << p << " ranks, " << options.quantize_bits << " bits";
            grid_files += bytes[4] == kGroupedGridVersion;
            ++files;
        }
    }
    EXPECT_EQ(files, 12 * 4);
    EXPECT_GT(grid_files, 0);  // level geometry mode 4 (in the grouped order): version 18, chunked or not
    // A surface remesh (vertices on the unit sphere), where the automatic predictor takes mode 4.
    const Hierarchy sphere = projected_sphere(20000, 7, 5);
    EncodeOptions options;
    options.quantize_bits = 12;
    options.grid_contexts = true;
    const std::vector<uint32_t> counts{7, 6, 7};
    const std::vector<uint8_t> bytes = write_by_ranks(sphere.base(), ranks_of(sphere, counts, 1), options);
    EXPECT_EQ(bytes[4], kGroupedGridVersion);  // chunks with mode 4 in the grouped order
    EXPECT_EQ(bytes, encode(sphere, serial_options(options, counts)));
}

// Bit-exact chunks in geometry mode 5 (FORMAT.md 5.8): the ranks' file is version 21 (chunks, the
// base's and the seam's raw bits in side streams), as the serial one.
TEST(RankEncoder, RanksWriteTheSerialEncodersUnitFrameBytes) {
    const Hierarchy sphere = projected_sphere(20000, 7, 5);
    EncodeOptions options;
    options.predictor = GeometryPredictor::unit_normal_frame;
    const std::vector<uint32_t> counts{7, 6, 7};
    const std::vector<uint8_t> bytes = write_by_ranks(sphere.base(), ranks_of(sphere, counts, 1), options);
    EXPECT_EQ(bytes[4], kBaseRawSideVersion);
    EXPECT_EQ(bytes, encode(sphere, serial_options(options, counts)));
    const Hierarchy back = decode(bytes.data(), bytes.size());
    EXPECT_TRUE(identical(back, sphere));
}

// Both zeros at the bottom of the box: the grid's origin keeps the first in canonical vertex
// order, as the serial encoder does for the whole hierarchy numbered that way.
TEST(RankEncoder, TheGridsOriginKeepsTheSerialEncodersZero) {
    int negative = 0, positive = 0;
    for (int pattern = 0; pattern < 8; ++pattern) {
        SCOPED_TRACE("pattern " + std::to_string(pattern));
        // Odd patterns: the base's z at +0 and -0, so a base vertex decides; even ones: the base at
        // z = 1, so the first midpoint at a zero decides, wherever it lies.
        TriangleMesh base = make_square(2);
        for (VertexId v = 0; v < base.positions.size(); ++v) base.positions[v].z = pattern % 2 == 0 ? 1.0 : v % 3 == 2 ? 0.0 : -0.0;
        Hierarchy h(base);
        refine_uniformly(h, 2);
        for (VertexId v = VertexId(base.positions.size()); v < h.positions().size(); ++v) {
            Vec3 p = h.position(v);
            const uint32_t k = (v * 7 + uint32_t(pattern)) % 5;
            p.z = k == 0 ? 0.5 : k == 1 || k == 3 ? -0.0 : 0.0;
            h.set_position(v, p);
        }
        const Hierarchy canonical = extract_roots(h, {RootRange{0, h.root_count()}});
        const std::vector<uint32_t> order = canonical_vertex_order(canonical);
        for (uint32_t v = 0; v < order.size(); ++v) ASSERT_EQ(order[v], v);
        for (const std::vector<uint32_t>& counts : {std::vector<uint32_t>{8}, {3, 5}, {2, 0, 3, 3}, {1, 1, 1, 5}}) {
            EncodeOptions options;
            options.quantize_bits = 10;
            const std::vector<uint8_t> bytes = write_by_ranks(base, ranks_of(h, counts, uint64_t(pattern)), options);
            ASSERT_EQ(bytes, encode(canonical, serial_options(options, counts))) << counts.size() << " ranks";
        }
        ++(std::signbit(make_quantizer(canonical_positions(canonical), 10).origin.z) ? negative : positive);
    }
    EXPECT_GT(negative, 0);  // both zeros end up in the origin
    EXPECT_GT(positive, 0);
}

// The ranks' writer checks its options as encode() does (mpi_file.cpp calls check_rank_options first).
TEST(RankEncoder, EffortOutsideItsRangeIsRefused) {
    for (int effort : {-1, kMaxEffort + 1}) {
        EncodeOptions options;
        options.effort = effort;
        try {
            check_rank_options(options, "ranks.amc");
            ADD_FAILURE() << "effort " << effort << " was taken";
        } catch (const Error& e) {
            EXPECT_EQ(e.code(), ErrorCode::invalid_input);
            EXPECT_NE(std::string(e.what()).find("ranks.amc: effort " + std::to_string(effort)), std::string::npos) << e.what();
        }
    }
    for (int effort = 0; effort <= kMaxEffort; ++effort) {
        EncodeOptions options;
        options.effort = effort;
        EXPECT_NO_THROW(check_rank_options(options, "ranks.amc")) << "effort " << effort;
    }
}

TEST(RankEncoder, RootRangesThatDoNotCutTheBaseAreRefused) {
    EXPECT_THROW(rank_layout(10, {{0, 4}, {5, 5}}), Error);  // a gap
    EXPECT_THROW(rank_layout(10, {{0, 5}, {4, 6}}), Error);  // an overlap
    EXPECT_THROW(rank_layout(10, {{0, 5}, {5, 4}}), Error);  // too few
    EXPECT_THROW(rank_layout(10, {{0, 5}, {5, 6}}), Error);  // too many
    EXPECT_THROW(rank_layout(0, {{0, 0}}), Error);           // nothing to write
    const RankLayout ok = rank_layout(10, {{6, 4}, {0, 0}, {0, 6}});  // any rank order, empty ranks
    EXPECT_EQ(ok.chunk_of_rank, (std::vector<int32_t>{1, -1, 0}));
    // A rank without roots passes an empty forest, whatever the base's precision.
    TriangleMesh single = make_square(2);
    single.single_precision = true;
    EXPECT_EQ(rank_chunk(single, 8, Hierarchy(TriangleMesh{}), "rank 1").chunk.root_count(), 0u);
}

TEST(RankEncoder, ForestsThatDoNotMatchTheBaseAreRefused) {
    const Hierarchy h = adaptive_hierarchy(4);
    const RootRange roots{2, 5};
    const Hierarchy forest = extract_roots(h, {roots});
    EXPECT_NO_THROW(rank_chunk(h.base(), 2, forest, "rank 0"));
    EXPECT_THROW(rank_chunk(h.base(), 3, forest, "rank 0"), Error);                    // other roots
    EXPECT_THROW(rank_chunk(h.base(), h.root_count() - 2, forest, "rank 0"), Error);   // past the end
    // A root rotated: its corners in another order.
    const Hierarchy rotated = reorder_base(forest, [&] {
        std::vector<uint32_t> v(forest.base().positions.size());
        std::iota(v.begin(), v.end(), 0u);
        return v;
    }(), {0, 1, 2, 3, 4}, {0, 1, 0, 0, 0});
    try {
        rank_chunk(h.base(), 2, rotated, "rank 7");
        ADD_FAILURE() << "a rotated root was accepted";
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), ErrorCode::invalid_input);
        EXPECT_NE(std::string(e.what()).find("rank 7"), std::string::npos) << e.what();
    }
    // A base position that is not the whole base's.
    TriangleMesh moved = forest.base();
    moved.positions[0].x += 1e-9;
    EXPECT_THROW(rank_chunk(h.base(), 2, Hierarchy(moved), "rank 0"), Error);
}

TEST(RankEncoder, RanksThatDoNotFitAcrossTheSeamAreRefused) {
    const TriangleMesh base = make_square(2);  // 8 triangles
    Hierarchy fine(base), coarse(base), moved(base);
    refine_uniformly(fine, 2);
    refine_uniformly(moved, 2);
    for (VertexId v = base.positions.size(); v < moved.positions().size(); ++v) {
        Vec3 p = moved.position(v);
        p.z += 0.25;
        moved.set_position(v, p);
    }
    const RankLayout layout = rank_layout(8, {{0, 4}, {4, 4}});
    auto write = [&](const Hierarchy& left, const Hierarchy& right) {
        const RankChunk a = rank_chunk(base, 0, extract_roots(left, {RootRange{0, 4}}), "rank 0");
        const RankChunk b = rank_chunk(base, 4, extract_roots(right, {RootRange{4, 4}}), "rank 1");
        std::vector<SeamSplit> splits = seam_splits(a, base, layout), far = seam_splits(b, base, layout);
        splits.insert(splits.end(), far.begin(), far.end());
        const Seam seam = Seam::from_splits(base, layout.chunk_of_root, splits);
        encode_rank_chunk(a, seam, {}, nullptr, "rank 0");
        encode_rank_chunk(b, seam, {}, nullptr, "rank 1");
    };
    EXPECT_NO_THROW(write(fine, fine));
    // Two levels of refinement against unrefined roots: not balanced across the seam.
    try {
        write(fine, coarse);
        ADD_FAILURE() << "unbalanced ranks were accepted";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("rank 1"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("balanced"), std::string::npos) << e.what();
    }
    // Both sides make the seam's vertices, at different positions.
    try {
        write(fine, moved);
        ADD_FAILURE() << "different seam positions were accepted";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("different positions"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace amc
