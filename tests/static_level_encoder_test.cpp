// The static geometry modes' level encoder (coding/geometry/static_position_coder.h): an encoder
// made over a sample of a level and extended to the whole level codes the level as one made over
// the whole level does (the encode's mode choice relies on it: docs/CODEC.md, "Encode effort").
#include "hierarchy_checks.h"

#include "coding/geometry/geometry_prediction.h"
#include "coding/geometry/level_geometry.h"
#include "coding/geometry/static_position_coder.h"
#include "common/exact_float.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <random>
#include <string>
#include <vector>

namespace amc {
namespace {

using testing::projected_sphere;

// Whether the listed decoders may make mode 4's and 5's frames four at a time (AVX2), for a scope.
struct WideFramesAllowed {
    bool before;
    explicit WideFramesAllowed(bool allowed) : before(set_wide_frames(allowed)) {}
    ~WideFramesAllowed() { set_wide_frames(before); }
};

// The level with the most new vertices.
NewVertices largest_level(const Hierarchy& h) {
    NewVertices largest;
    for (const std::vector<NodeId>& level : nodes_by_level(h)) {
        NewVertices created = new_vertices_of_level(h, level);
        if (created.size() > largest.size()) largest = std::move(created);
    }
    return largest;
}

void expect_extended_codes_as_whole(const Hierarchy& h, CoordinateSpace space, GeometryPredictor mode) {
    const NewVertices created = largest_level(h);
    ASSERT_GT(created.size(), 100u);
    StaticLevelEncoder whole(h, created, space, mode, false);
    const size_t whole_bound = whole.lower_bound_bytes();
    whole.code_streams();
    for (size_t sample : {size_t(0), size_t(1), created.size() / 8, created.size() - 1, created.size()}) {
        SCOPED_TRACE("mode " + std::to_string(int(mode)) + ", sample " + std::to_string(sample));
        StaticLevelEncoder extended(h, created, sample, space, mode);
        if (sample > 0 && sample < created.size() / 2) {
            EXPECT_NE(extended.lower_bound_bytes(), whole_bound);  // the sample's own tables
        }
        // The projection scales the streams' part of the bound, not the tables'.
        const double tables = extended.projected_bound_bytes(0.0);
        EXPECT_GT(tables, 1.0);
        EXPECT_EQ(extended.projected_bound_bytes(1.0), double(extended.lower_bound_bytes()));
        EXPECT_EQ(extended.projected_bound_bytes(8.0) - tables, 8.0 * (double(extended.lower_bound_bytes()) - tables));
        if (sample == created.size() / 8) {  // a smooth surface: an eighth tells the level's size
            const double projected = extended.projected_bound_bytes(double(created.size()) / double(sample));
            EXPECT_NEAR(projected, double(whole_bound), 0.1 * double(whole_bound));
        }
        extended.extend(h, created);
        EXPECT_EQ(extended.lower_bound_bytes(), whole_bound);
        extended.code_streams();
        EXPECT_EQ(extended.rans_bytes(), whole.rans_bytes());
        EXPECT_EQ(extended.raw_bytes(), whole.raw_bytes());
        EXPECT_EQ(extended.estimated_bytes(), whole.estimated_bytes());
        EXPECT_THROW(extended.extend(h, created), Error);  // the streams are coded
    }
}

TEST(StaticLevelEncoder, ExtendedFromASampleCodesAsMadeOverTheWholeLevel) {
    const Hierarchy h = projected_sphere(6000, 6, 11);
    const Quantizer quantizer = make_quantizer(h.positions(), 12);
    expect_extended_codes_as_whole(h, {Precision::float64, &quantizer}, GeometryPredictor::normal_frame);
    expect_extended_codes_as_whole(h, {Precision::float64, &quantizer}, GeometryPredictor::normal_frame_grid);
    expect_extended_codes_as_whole(h, {Precision::float64, nullptr}, GeometryPredictor::normal_frame);
    expect_extended_codes_as_whole(h, {Precision::float64, nullptr}, GeometryPredictor::unit_normal_frame);
    expect_extended_codes_as_whole(h, {Precision::float64, nullptr}, GeometryPredictor::midpoint_static);
    expect_extended_codes_as_whole(h, {Precision::float64, nullptr}, GeometryPredictor::butterfly_static);
}

// A sample's encoder made with a limit on its streams' bound (the automatic choice drops a mode
// by it: level_geometry.cpp) gives up only where the whole sample's streams' bound passes the limit;
// an encoder that did not give up is the one made without a limit.
TEST(StaticLevelEncoder, ASampleGivesUpOnlyWhereItsStreamsBoundPassesTheLimit) {
    const Hierarchy h = projected_sphere(20000, 6, 5);
    const NewVertices created = largest_level(h);
    const size_t sample = created.size() / 2;
    ASSERT_GT(sample, 2048u);  // several of the encoder's steps
    const CoordinateSpace space{Precision::float64, nullptr};
    for (GeometryPredictor mode : {GeometryPredictor::normal_frame, GeometryPredictor::unit_normal_frame,
                                   GeometryPredictor::midpoint_static, GeometryPredictor::butterfly_static}) {
        SCOPED_TRACE("mode " + std::to_string(int(mode)));
        StaticLevelEncoder unlimited(h, created, sample, space, mode);
        const size_t stream_bound = size_t(unlimited.projected_stream_bound_bytes(1.0));
        int gave_up = 0, kept = 0;
        for (size_t limit : {size_t{0}, size_t{1000}, stream_bound / 4, stream_bound / 2, 2 * stream_bound, SIZE_MAX - 1}) {
            SCOPED_TRACE("limit " + std::to_string(limit));
            StaticLevelEncoder limited(h, created, sample, space, mode, StaticOrder::grouped, nullptr, limit);
            if (limited.gave_up()) {
                ++gave_up;
                EXPECT_GT(stream_bound, limit);
                continue;
            }
            ++kept;
            EXPECT_EQ(limited.lower_bound_bytes(), unlimited.lower_bound_bytes());
            EXPECT_EQ(limited.projected_stream_bound_bytes(3.0), unlimited.projected_stream_bound_bytes(3.0));
        }
        EXPECT_GE(gave_up, 3);
        EXPECT_GE(kept, 2);
    }
}

// Bit-exact residuals of every bit length (0 to 64 bits of ordered float64 bits) decode to the
// positions coded: the raw bits below a large token (a sign and up to 61 bits, in one value or
// two) as the decoder reads them, one read where they fit 57 bits, two beyond.
TEST(StaticLevelEncoder, ResidualsOfEveryBitLengthDecodeBitExactly) {
    Hierarchy h = projected_sphere(6000, 6, 12);
    const NewVertices created = largest_level(h);
    ASSERT_GT(created.size(), 200u);
    std::mt19937_64 rng(5);
    for (size_t i = 0; i < created.size(); ++i) {
        const VertexId v = h.midpoint(created[i].first, created[i].second);
        const Vec3 p = h.position(v);
        double xyz[3] = {p.x, p.y, p.z};
        for (int axis = 0; axis < 3; ++axis) {
            const int length = int((3 * i + size_t(axis)) % 65);  // the offset's bit length
            const uint64_t offset = length == 0 ? 0 : (uint64_t{1} << (length - 1)) | (rng() & ((uint64_t{1} << (length - 1)) - 1));
            const uint64_t bits = ordered_bits(xyz[axis], Precision::float64);
            const double moved = from_ordered_bits(rng() & 1 ? bits + offset : bits - offset, Precision::float64);
            if (std::isfinite(moved)) xyz[axis] = moved;
        }
        h.set_position(v, {xyz[0], xyz[1], xyz[2]});
    }
    const CoordinateSpace space{Precision::float64, nullptr};
    for (GeometryPredictor mode : {GeometryPredictor::normal_frame, GeometryPredictor::unit_normal_frame}) {
        SCOPED_TRACE("mode " + std::to_string(int(mode)));
        StaticLevelEncoder encoder(h, created, space, mode);
        ArithmeticEncoder tables_out;
        encoder.write_tables(tables_out);
        const std::vector<uint8_t> table_bytes = tables_out.finish();
        Hierarchy decoded = h;
        for (const auto& [n, e] : created) decoded.set_position(decoded.midpoint(n, e), Vec3{});
        ArithmeticDecoder tables_in(table_bytes.data(), table_bytes.size());
        StaticTables tables;
        ASSERT_TRUE(read_static_tables(tables_in, space, mode, tables));
        const std::vector<uint8_t>& rans = encoder.rans_bytes();
        const std::vector<uint8_t>& raw = encoder.raw_bytes();
        ASSERT_TRUE(decode_static_positions(decoded, created, space, mode, tables, rans.data(), rans.size(), raw.data(), raw.size(),
                                            StaticOrder::per_vertex));
        for (const auto& [n, e] : created) {
            const VertexId v = h.midpoint(n, e);
            const Vec3 a = h.position(v), b = decoded.position(v);
            ASSERT_TRUE(std::memcmp(&a, &b, sizeof a) == 0) << "vertex " << v;
        }
    }
}

// Mode 4's decoder of split_level's list (the whole-file and chunk decoders' path) and its decoder
// of (node, edge) pairs decode the same positions, with grid residuals of every bit length on a
// 30-bit grid (raw bits up to 28 a coordinate, the list decoder's bound on a chunk's reads), in
// both token orders (a level whose last group has an odd count: its roles 1 and 2 start with state
// 1), and both refuse the streams cut short and the other order's streams.
TEST(StaticLevelEncoder, GridLevelsDecodeAlikeFromTheListAndFromTheNodes) {
    Hierarchy h = projected_sphere(6000, 6, 13);
    const Quantizer quantizer = make_quantizer(h.positions(), 30);
    for (VertexId v = 0; v < h.vertex_count(); ++v) h.set_position(v, dequantize(quantizer, snap_to_grid(quantizer, h.position(v))));
    NewVertices created = largest_level(h);
    if (created.size() % 2 == 0) created.pop_back();  // the last group of an odd count (any part of a level codes alone)
    ASSERT_GT(created.size(), 200u);
    std::mt19937_64 rng(7);
    const int64_t top = int64_t(quantizer.max_coordinate());
    for (size_t i = 0; i < created.size(); ++i) {
        const VertexId v = h.midpoint(created[i].first, created[i].second);
        GridPoint q = snap_to_grid(quantizer, h.position(v));
        for (int axis = 0; axis < 3; ++axis) {
            const int length = int((3 * i + size_t(axis)) % 31);  // the offset's bit length, 0..30
            const int64_t offset = length == 0 ? 0 : int64_t((uint64_t{1} << (length - 1)) | (rng() & ((uint64_t{1} << (length - 1)) - 1)));
            const int64_t moved = rng() & 1 ? int64_t(q[size_t(axis)]) + offset : int64_t(q[size_t(axis)]) - offset;
            q[size_t(axis)] = uint32_t(std::min(top, std::max<int64_t>(0, moved)));
        }
        h.set_position(v, dequantize(quantizer, q));
    }
    // The list decoder appends vertex i's position as vertex first + i, as after split_level (the
    // frames read earlier levels' vertices only).
    const VertexId first = VertexId(h.positions().size());
    std::vector<FrameCorners> corners;
    for (const auto& [n, e] : created) corners.push_back(frame_corners(h, n, e));
    const CoordinateSpace space{Precision::float64, &quantizer};
    const GeometryPredictor mode = GeometryPredictor::normal_frame_grid;
    ASSERT_EQ(created.size() % kGridGroup % 2, 1u);
    std::vector<uint8_t> streams_of[2];
    for (StaticOrder order : {StaticOrder::per_vertex, StaticOrder::grouped}) {
        SCOPED_TRACE(order == StaticOrder::grouped ? "grouped" : "per vertex");
        const StaticOrder other = order == StaticOrder::grouped ? StaticOrder::per_vertex : StaticOrder::grouped;
        StaticLevelEncoder encoder(h, created, space, mode, true, order);
        ArithmeticEncoder tables_out;
        encoder.write_tables(tables_out);
        const std::vector<uint8_t> table_bytes = tables_out.finish();
        ArithmeticDecoder tables_in(table_bytes.data(), table_bytes.size());
        StaticTables tables;
        ASSERT_TRUE(read_static_tables(tables_in, space, mode, tables));
        const std::vector<uint8_t>& rans = encoder.rans_bytes();
        const std::vector<uint8_t>& raw = encoder.raw_bytes();
        ASSERT_GT(raw.size(), 1000u);
        streams_of[int(order)] = rans;
        streams_of[int(order)].insert(streams_of[int(order)].end(), raw.begin(), raw.end());
        Hierarchy zeroed = h;
        for (const auto& [n, e] : created) zeroed.set_position(zeroed.midpoint(n, e), Vec3{});
        auto decode = [&](bool listed, size_t rans_size, size_t raw_size, Hierarchy& out, StaticOrder as) {
            out = zeroed;
            NewVertexCorners list(corners.data(), first, corners.size());
            return listed ? decode_static_positions(out, list, space, mode, tables, rans.data(), rans_size, raw.data(), raw_size, as)
                          : decode_static_positions(out, created, space, mode, tables, rans.data(), rans_size, raw.data(), raw_size, as);
        };
        // From the nodes, and from the list with mode 4's frames (and the grouped order's roles 1
        // and 2's predictions) four at a time (AVX2, where the processor has it) and two at a time:
        // the same positions.
        for (int way = 0; way < 3; ++way) {
            const bool listed = way > 0;
            SCOPED_TRACE(way == 0 ? "nodes" : way == 1 ? "listed, frames four at a time" : "listed, frames in pairs");
            const WideFramesAllowed wide_frames(way != 2);
            Hierarchy decoded;
            ASSERT_TRUE(decode(listed, rans.size(), raw.size(), decoded, order));
            ASSERT_EQ(decoded.positions().size(), listed ? first + created.size() : first);
            for (size_t i = 0; i < created.size(); ++i) {
                const VertexId v = h.midpoint(created[i].first, created[i].second);
                const Vec3 a = h.position(v), b = decoded.positions()[listed ? first + i : v];
                ASSERT_TRUE(std::memcmp(&a, &b, sizeof a) == 0) << "vertex " << v;
            }
            EXPECT_FALSE(decode(listed, rans.size() - 1, raw.size(), decoded, order));
            EXPECT_FALSE(decode(listed, rans.size(), raw.size() - 1, decoded, order));
            EXPECT_FALSE(decode(listed, rans.size(), raw.size() / 2, decoded, order));
            EXPECT_FALSE(decode(listed, rans.size(), raw.size(), decoded, other)) << "read in the other order";
        }
    }
    EXPECT_NE(streams_of[0], streams_of[1]) << "the orders code other streams";
}

// Mode 5's decoder of split_level's list (the bit-exact levels of whole files and chunks) and its
// decoder of (node, edge) pairs decode the same positions, and so do mode 3's (the same listed
// decoder with the frames of mode 3, against the generic decoder of the pairs), float64 and float32, with residuals of
// every bit length up to 63 (narrow tables, as every bit-exact surface level has; raw bits in one
// read and, past 57, in two), float64 coordinates past DBL_MAX / 2 (the chunks whose positions are
// far) and a level whose last chunk has an odd count, with the frames four and two at a time; both
// refuse the streams cut short. The encoder's frames four and two at a time code the same streams.
void expect_unit_levels_decode_alike(Precision precision, GeometryPredictor mode) {
    const bool single = precision == Precision::float32;
    Hierarchy h = projected_sphere(6000, 6, 14);
    if (single) {
        h.set_single_precision(true);
        for (VertexId v = 0; v < h.positions().size(); ++v) h.set_position(v, rounded_to_float(h.position(v)));
    }
    NewVertices created = largest_level(h);
    if (created.size() % 2 == 0) created.pop_back();
    ASSERT_GT(created.size(), 200u);
    std::mt19937_64 rng(9);
    const int lengths = single ? 33 : 64;  // the offsets' bit lengths, 0 .. lengths - 1
    for (size_t i = 0; i < created.size(); ++i) {
        const VertexId v = h.midpoint(created[i].first, created[i].second);
        const Vec3 p = h.position(v);
        double xyz[3] = {p.x, p.y, p.z};
        for (int axis = 0; axis < 3; ++axis) {
            const int length = int((3 * i + size_t(axis)) % size_t(lengths));
            const uint64_t offset = length == 0 ? 0 : (uint64_t{1} << (length - 1)) | (rng() & ((uint64_t{1} << (length - 1)) - 1));
            const uint64_t bits = ordered_bits(xyz[axis], precision);
            const double moved = from_ordered_bits(rng() & 1 ? bits + offset : bits - offset, precision);
            if (std::isfinite(moved) && std::fabs(moved) < 1e300) xyz[axis] = moved;
        }
        if (!single && i % 97 == 5) xyz[i % 3] = i % 2 == 0 ? 1.5e308 : -1.5e308;  // beyond DBL_MAX / 2
        h.set_position(v, {xyz[0], xyz[1], xyz[2]});
    }
    const VertexId first = VertexId(h.positions().size());
    std::vector<FrameCorners> corners;
    for (const auto& [n, e] : created) corners.push_back(frame_corners(h, n, e));
    const CoordinateSpace space{precision, nullptr};
    StaticLevelEncoder encoder(h, created, space, mode);
    ArithmeticEncoder tables_out;
    encoder.write_tables(tables_out);
    const std::vector<uint8_t> table_bytes = tables_out.finish();
    ArithmeticDecoder tables_in(table_bytes.data(), table_bytes.size());
    StaticTables tables;
    ASSERT_TRUE(read_static_tables(tables_in, space, mode, tables));
    for (int k = 0; k < static_table_count(mode); ++k) ASSERT_NE(tables[size_t(k)].narrow_view().index, nullptr) << "table " << k;
    const std::vector<uint8_t>& rans = encoder.rans_bytes();
    const std::vector<uint8_t>& raw = encoder.raw_bytes();
    {  // the encoder makes its frames as the listed decoder does: in pairs, the same streams
        const WideFramesAllowed pairs(false);
        const StaticLevelEncoder paired(h, created, space, mode);
        EXPECT_EQ(paired.rans_bytes(), rans);
        EXPECT_EQ(paired.raw_bytes(), raw);
    }
    Hierarchy zeroed = h;
    for (const auto& [n, e] : created) zeroed.set_position(zeroed.midpoint(n, e), Vec3{});
    auto decode = [&](bool listed, size_t rans_size, size_t raw_size, Hierarchy& out) {
        out = zeroed;
        NewVertexCorners list(corners.data(), first, corners.size());
        return listed ? decode_static_positions(out, list, space, mode, tables, rans.data(), rans_size, raw.data(), raw_size,
                                                StaticOrder::per_vertex)
                      : decode_static_positions(out, created, space, mode, tables, rans.data(), rans_size, raw.data(), raw_size,
                                                StaticOrder::per_vertex);
    };
    for (int way = 0; way < 3; ++way) {
        const bool listed = way > 0;
        SCOPED_TRACE(way == 0 ? "nodes" : way == 1 ? "listed, frames four at a time" : "listed, frames in pairs");
        const WideFramesAllowed wide_frames(way != 2);
        Hierarchy decoded;
        ASSERT_TRUE(decode(listed, rans.size(), raw.size(), decoded));
        ASSERT_EQ(decoded.positions().size(), listed ? first + created.size() : first);
        for (size_t i = 0; i < created.size(); ++i) {
            const VertexId v = h.midpoint(created[i].first, created[i].second);
            const Vec3 a = h.position(v), b = decoded.positions()[listed ? first + i : v];
            ASSERT_TRUE(std::memcmp(&a, &b, sizeof a) == 0) << "vertex " << v;
        }
        EXPECT_FALSE(decode(listed, rans.size() - 1, raw.size(), decoded));
        EXPECT_FALSE(decode(listed, rans.size(), raw.size() - 1, decoded));
        EXPECT_FALSE(decode(listed, rans.size(), raw.size() / 2, decoded));
    }
}

TEST(StaticLevelEncoder, UnitLevelsDecodeAlikeFromTheListAndFromTheNodes) {
    for (Precision precision : {Precision::float64, Precision::float32}) {
        SCOPED_TRACE(precision == Precision::float32 ? "float32" : "float64");
        expect_unit_levels_decode_alike(precision, GeometryPredictor::unit_normal_frame);
    }
}

TEST(StaticLevelEncoder, BitExactModeThreeLevelsDecodeAlikeFromTheListAndFromTheNodes) {
    for (Precision precision : {Precision::float64, Precision::float32}) {
        SCOPED_TRACE(precision == Precision::float32 ? "float32" : "float64");
        expect_unit_levels_decode_alike(precision, GeometryPredictor::normal_frame);
    }
}

}  // namespace
}  // namespace amc
