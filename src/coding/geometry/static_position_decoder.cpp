// The static geometry modes' decoder (docs/FORMAT.md 5.6-5.9; static_position_coder.h): the
// tables, the decoders for any hierarchy and space, and the choice of a fast path.

#include "coding/geometry/static_position_internal.h"

#include <type_traits>

namespace amc {

using namespace static_geometry;

namespace {

uint32_t get_gamma(ArithmeticDecoder& decoder, std::array<BitModel, kMaxGammaLength + 1>& models) {
    int length = 0;
    while (length < kMaxGammaLength && decoder.decode(models[size_t(length)])) ++length;
    return (uint32_t{1} << length) | decoder.decode_bits_raw(length);
}

bool get_table(ArithmeticDecoder& decoder, TableModels& models, int limit, RansTable& table) {
    const uint32_t used = get_gamma(decoder, models.count);
    if (used < 2 || used > uint32_t(limit)) return false;  // a table has two symbols at least
    std::vector<int> symbols;
    int previous = -1;
    for (uint32_t i = 0; i < used; ++i) {
        previous += int(get_gamma(decoder, models.gap));
        if (previous >= limit) return false;
        symbols.push_back(previous);
    }
    std::vector<uint32_t> frequencies(size_t(symbols.back()) + 1, 0);
    uint32_t sum = 0;
    for (uint32_t i = 0; i + 1 < used; ++i) {
        const uint32_t f = get_gamma(decoder, models.frequency);
        frequencies[size_t(symbols[i])] = f;
        sum += f;
        if (sum >= kRansScale) return false;
    }
    frequencies[size_t(symbols.back())] = kRansScale - sum;
    return table.assign(frequencies);
}

}  // namespace

bool read_static_tables(ArithmeticDecoder& decoder, CoordinateSpace space, GeometryPredictor mode, StaticTables& tables) {
    if (!is_static_mode(mode) || (has_grid_bins(mode) && space.quantizer == nullptr)) return false;
    TableModels models;
    for (int i = 0; i < static_table_count(mode); ++i)
        if (!get_table(decoder, models, token_limit(space), tables[size_t(i)])) return false;
    return true;
}

namespace {

// One vertex's three coordinates; its first token is coded with rANS state `State` (token j of the
// level with state j mod 2), its second with the other, its third with `State` again.
// Tables: StaticTables, or NarrowTables where every table is narrow.
template <int State, bool Grid, class Tables>
AMC_ALWAYS_INLINE bool decode_vertex(const Chunk& b, size_t i, CoordinateSpace space, const GridScale& grid,
                                     const Tables& tables, RansDecoder& rans, RawBitReader& raw, Vec3& p) {
    const RoleFrame& f = b.frames[i];
    double value[3], second, third;
    if (Grid) {
        const GridPrediction& first = b.first[i];
        if (!grid_value(grid, f.origin[0], first, take_signed(rans.get_with<State>(tables[size_t(first.bin)]), raw), value[0]))
            return false;
        predict_others(f, value[0], second, third);
        const GridPrediction g1 = grid_prediction_at(grid, f.origin[1], second);
        const GridPrediction g2 = grid_prediction_at(grid, f.origin[2], third);
        const int64_t r1 = take_signed(rans.get_with<1 - State>(tables[size_t(kGridBins + g1.bin)]), raw);
        if (!grid_value(grid, f.origin[1], g1, r1, value[1])) return false;
        const int64_t r2 = take_signed(rans.get_with<State>(tables[size_t(2 * kGridBins + g2.bin)]), raw);
        if (!grid_value(grid, f.origin[2], g2, r2, value[2])) return false;
    } else {
        if (!value_of(space, f.axes[0], f.midpoint[0], take(rans.get_with<State>(tables[0]), raw), value[0])) return false;
        predict_others(f, value[0], second, third);
        if (!value_of(space, f.axes[1], second, take(rans.get_with<1 - State>(tables[1]), raw), value[1])) return false;
        if (!value_of(space, f.axes[2], third, take(rans.get_with<State>(tables[2]), raw), value[2])) return false;
    }
    double xyz[3];
    for (int r = 0; r < 3; ++r) xyz[f.axes[r]] = value[r];
    p = {xyz[0], xyz[1], xyz[2]};
    return true;
}

// Mode 4's chunk b in the grouped order (version 18, FORMAT.md 5.7): the role-0 tokens of its
// vertices (vertex i with state i mod 2), then each vertex's roles 1 and 2 (states b.count mod 2
// and the other). Into p[0 .. b.count).
template <class Tables>
bool decode_grid_chunk_grouped(const Chunk& b, const GridScale& grid, const Tables& tables, RansDecoder& rans,
                               RawBitReader& raw, Vec3* p) {
    double value[kChunk][3];  // role order
    for (size_t i = 0; i < b.count; ++i) {
        const GridPrediction& first = b.first[i];
        const int token = i % 2 == 0 ? rans.get_with<0>(tables[size_t(first.bin)]) : rans.get_with<1>(tables[size_t(first.bin)]);
        if (!grid_value(grid, b.frames[i].origin[0], first, take_signed(token, raw), value[i][0])) return false;
    }
    const bool odd = b.count % 2 != 0;
    for (size_t i = 0; i < b.count; ++i) {
        const RoleFrame& f = b.frames[i];
        double second, third;
        predict_others(f, value[i][0], second, third);
        const GridPrediction g1 = grid_prediction_at(grid, f.origin[1], second);
        const GridPrediction g2 = grid_prediction_at(grid, f.origin[2], third);
        const auto& t1 = tables[size_t(kGridBins + g1.bin)];
        const auto& t2 = tables[size_t(2 * kGridBins + g2.bin)];
        const int token1 = odd ? rans.get_with<1>(t1) : rans.get_with<0>(t1);
        const int64_t r1 = take_signed(token1, raw);
        if (!grid_value(grid, f.origin[1], g1, r1, value[i][1])) return false;
        const int token2 = odd ? rans.get_with<0>(t2) : rans.get_with<1>(t2);
        const int64_t r2 = take_signed(token2, raw);
        if (!grid_value(grid, f.origin[2], g2, r2, value[i][2])) return false;
        double xyz[3];
        for (int r = 0; r < 3; ++r) xyz[f.axes[r]] = value[i][r];
        p[i] = {xyz[0], xyz[1], xyz[2]};
    }
    return true;
}

// The decoders own their rANS decoder and raw bit reader, so that the compiler keeps the two rANS
// states in registers. `grouped`: mode 4's tokens in the grouped order (version 18).
template <bool Grid, bool UnitNormals, class Source, class Tables>
bool decode_positions(Hierarchy& h, const Source& created, CoordinateSpace space, const Tables& tables,
                      const uint8_t* rans_data, size_t rans_size, const uint8_t* raw_data, size_t raw_size, bool grouped) {
    RansDecoder rans(rans_data, rans_size);
    RawBitReader raw(raw_data, raw_size);
    // The quantizer copied here: no store to the positions can change it, so its fields stay in
    // registers.
    Quantizer local_quantizer;
    if (space.quantizer != nullptr) {
        local_quantizer = *space.quantizer;
        space.quantizer = &local_quantizer;
    }
    const Quantizer* quantizer = space.quantizer;
    const GridScale grid = grid_scale(quantizer);
    // A grid value origin + rounded(q * step), 0 <= q <= max, lies between the box's corners
    // (both operations round monotonically): when they are near, every position is.
    const bool near = quantizer != nullptr && !HierarchyBuilder::is_far(quantizer->origin) &&
                      !HierarchyBuilder::is_far(dequantize(*quantizer, {quantizer->max_coordinate(), quantizer->max_coordinate(),
                                                                        quantizer->max_coordinate()}));
    auto set = [&h, near](VertexId v, Vec3 p) {
        if (near) HierarchyBuilder::set_near_vertex_position(h, v, p);
        else HierarchyBuilder::set_new_vertex_position(h, v, p);
    };
    // A listed level's positions made as they are decoded, a chunk at a time (split_level did not
    // zero them first), or set where they are.
    const bool append = created.appends(h);
    Vec3 decoded[kChunk];
    Chunk c;
    auto put = [&](size_t i, Vec3 p) {
        if (append) decoded[i] = p;
        else set(c.vertices[i], p);
    };
    for (size_t begin = 0; begin < created.size(); begin += kChunk) {
        gather_chunk(h, created, begin, created.size(), c);
        frame_chunk<Grid, UnitNormals>(h, quantizer, grid, c);
        if (Grid && grouped) {
            Vec3 p[kChunk];
            if (!decode_grid_chunk_grouped(c, grid, tables, rans, raw, p)) return false;
            for (size_t i = 0; i < c.count; ++i) put(i, p[i]);
            if (append) HierarchyBuilder::append_positions(h, decoded, c.count, near);
            continue;
        }
        for (size_t i = 0; i < c.count; i += 2) {
            Vec3 p;
            if (!decode_vertex<0, Grid>(c, i, space, grid, tables, rans, raw, p)) return false;
            put(i, p);
            if (i + 1 == c.count) break;
            if (!decode_vertex<1, Grid>(c, i + 1, space, grid, tables, rans, raw, p)) return false;
            put(i + 1, p);
        }
        if (append) HierarchyBuilder::append_positions(h, decoded, c.count, near);
    }
    return rans.ended_cleanly() && raw.ended_cleanly();
}

using NarrowTables = std::array<RansTable::NarrowView, kMaxStaticTables>;

// Modes 6 and 7: one coordinate against its prediction, with the table of its axis.
template <int State, bool Float64, class Tables>
AMC_ALWAYS_INLINE bool decode_axis(CoordinateSpace space, int axis, double predicted, const Tables& tables, RansDecoder& rans,
                                   RawBitReader& raw, double& value) {
    const Residual r = take(rans.get_with<State>(tables[size_t(axis)]), raw);
    if (!Float64) return value_of(space, axis, predicted, r, value);
    // value_of's bit-exact path for float64, without its tests of the precision.
    const uint64_t p = ordered_bits(std::isfinite(predicted) ? predicted : 0.0, Precision::float64);
    value = from_ordered_bits(r.negative ? p - r.magnitude : p + r.magnitude, Precision::float64);
    return std::isfinite(value);
}

// Vertex i of a chunk: x with rANS state `State` (token j of the level with state j mod 2), y with
// the other, z with `State` again.
template <int State, bool Float64, class Tables>
AMC_ALWAYS_INLINE bool decode_stencil_vertex(CoordinateSpace space, Vec3 predicted, const Tables& tables, RansDecoder& rans,
                                             RawBitReader& raw, Vec3& p) {
    return decode_axis<State, Float64>(space, 0, predicted.x, tables, rans, raw, p.x) &&
           decode_axis<1 - State, Float64>(space, 1, predicted.y, tables, rans, raw, p.y) &&
           decode_axis<State, Float64>(space, 2, predicted.z, tables, rans, raw, p.z);
}

// Modes 6 and 7 over (node, edge) pairs, in chunks: first the chunk's predictions (their stencils'
// loads, independent of the streams), then its coordinates from the streams.
template <bool Butterfly, bool Float64, class Tables>
bool decode_stencil_positions(Hierarchy& h, const std::vector<std::pair<NodeId, int>>& created, CoordinateSpace space,
                              const Tables& tables, const uint8_t* rans_data, size_t rans_size, const uint8_t* raw_data,
                              size_t raw_size) {
    RansDecoder rans(rans_data, rans_size);
    RawBitReader raw(raw_data, raw_size);
    std::array<Vec3, kChunk> predicted;
    std::array<VertexId, kChunk> vertices;
    for (size_t begin = 0; begin < created.size(); begin += kChunk) {
        const size_t count = std::min(kChunk, created.size() - begin);
        for (size_t i = 0; i < count; ++i) {
            const auto [n, e] = created[begin + i];
            predicted[i] = Butterfly ? predict_butterfly(h, n, e) : predict_midpoint(h, n, e);
            vertices[i] = h.midpoint(n, e);
        }
        for (size_t i = 0; i < count; i += 2) {
            Vec3 p;
            if (!decode_stencil_vertex<0, Float64>(space, predicted[i], tables, rans, raw, p)) return false;
            HierarchyBuilder::set_new_vertex_position(h, vertices[i], p);
            if (i + 1 == count) break;
            if (!decode_stencil_vertex<1, Float64>(space, predicted[i + 1], tables, rans, raw, p)) return false;
            HierarchyBuilder::set_new_vertex_position(h, vertices[i + 1], p);
        }
    }
    return rans.ended_cleanly() && raw.ended_cleanly();
}

template <class Tables>
bool decode_stencil_with(Hierarchy& h, const std::vector<std::pair<NodeId, int>>& created, CoordinateSpace space,
                         GeometryPredictor mode, const Tables& tables, const uint8_t* rans_data, size_t rans_size,
                         const uint8_t* raw_data, size_t raw_size) {
    if (space.quantizer != nullptr) return false;  // bit-exact files only (FORMAT.md 5.9)
    const bool butterfly = mode == GeometryPredictor::butterfly_static;
    if (space.precision == Precision::float64)
        return butterfly ? decode_stencil_positions<true, true>(h, created, space, tables, rans_data, rans_size, raw_data, raw_size)
                         : decode_stencil_positions<false, true>(h, created, space, tables, rans_data, rans_size, raw_data, raw_size);
    return butterfly ? decode_stencil_positions<true, false>(h, created, space, tables, rans_data, rans_size, raw_data, raw_size)
                     : decode_stencil_positions<false, false>(h, created, space, tables, rans_data, rans_size, raw_data, raw_size);
}

template <class Source, class Tables>
bool decode_static_with(Hierarchy& h, const Source& created, CoordinateSpace space, GeometryPredictor mode, const Tables& tables,
                        const uint8_t* rans_data, size_t rans_size, const uint8_t* raw_data, size_t raw_size, bool grouped) {
    switch (mode) {
        case GeometryPredictor::normal_frame:
            return decode_positions<false, false>(h, created, space, tables, rans_data, rans_size, raw_data, raw_size, false);
        case GeometryPredictor::unit_normal_frame:
            return decode_positions<false, true>(h, created, space, tables, rans_data, rans_size, raw_data, raw_size, false);
        case GeometryPredictor::normal_frame_grid:
            return space.quantizer != nullptr &&
                   decode_positions<true, true>(h, created, space, tables, rans_data, rans_size, raw_data, raw_size, grouped);
        default:
            return false;
    }
}

template <class Source>
bool decode_static(Hierarchy& h, const Source& created, CoordinateSpace space, GeometryPredictor mode, const StaticTables& tables,
                   const uint8_t* rans_data, size_t rans_size, const uint8_t* raw_data, size_t raw_size, bool grouped) {
    if (!is_static_mode(mode)) return false;
    NarrowTables narrow;
    bool all_narrow = true;
    for (int i = 0; i < static_table_count(mode); ++i) {
        narrow[size_t(i)] = tables[size_t(i)].narrow_view();
        all_narrow = all_narrow && narrow[size_t(i)].index != nullptr;
    }
    if constexpr (std::is_same_v<Source, FromNodes<Hierarchy>>) {
        if (has_stencil_tables(mode)) {
            if (all_narrow && space.quantizer == nullptr && space.precision == Precision::float64 && !h.single_precision()) {
                const std::vector<std::pair<NodeId, int>>& c = created.created;
                return mode == GeometryPredictor::butterfly_static
                           ? decode_stencil_float64<true>(h, c, tables, rans_data, rans_size, raw_data, raw_size)
                           : decode_stencil_float64<false>(h, c, tables, rans_data, rans_size, raw_data, raw_size);
            }
            if (all_narrow)
                return decode_stencil_with(h, created.created, space, mode, narrow, rans_data, rans_size, raw_data, raw_size);
            return decode_stencil_with(h, created.created, space, mode, tables, rans_data, rans_size, raw_data, raw_size);
        }
    } else if (has_stencil_tables(mode)) {
        return false;  // a listed level has frame corners, not the stencils' nodes
    }
    if constexpr (std::is_same_v<Source, FromList>) {
        if (all_narrow && mode == GeometryPredictor::normal_frame_grid && space.quantizer != nullptr && !h.single_precision())
            return grouped ? decode_grid_listed_fastest<true>(h, created, *space.quantizer, tables, rans_data, rans_size, raw_data, raw_size)
                           : decode_grid_listed_fastest<false>(h, created, *space.quantizer, tables, rans_data, rans_size, raw_data, raw_size);
        // Modes 5 and 3 bit-exact (the FE models' middle levels take mode 3).
        if (all_narrow && mode == GeometryPredictor::unit_normal_frame && space.quantizer == nullptr) {
            if (space.precision == Precision::float64 && !h.single_precision())
                return decode_unit_listed_fastest<false, true>(h, created, tables, rans_data, rans_size, raw_data, raw_size);
            if (space.precision == Precision::float32 && h.single_precision())
                return decode_unit_listed_fastest<true, true>(h, created, tables, rans_data, rans_size, raw_data, raw_size);
        }
        if (all_narrow && mode == GeometryPredictor::normal_frame && space.quantizer == nullptr) {
            if (space.precision == Precision::float64 && !h.single_precision())
                return decode_unit_listed_fastest<false, false>(h, created, tables, rans_data, rans_size, raw_data, raw_size);
            if (space.precision == Precision::float32 && h.single_precision())
                return decode_unit_listed_fastest<true, false>(h, created, tables, rans_data, rans_size, raw_data, raw_size);
        }
    }
    if (all_narrow) return decode_static_with(h, created, space, mode, narrow, rans_data, rans_size, raw_data, raw_size, grouped);
    return decode_static_with(h, created, space, mode, tables, rans_data, rans_size, raw_data, raw_size, grouped);
}

}  // namespace

bool decode_static_positions(Hierarchy& h, const std::vector<std::pair<NodeId, int>>& created, CoordinateSpace space,
                             GeometryPredictor mode, const StaticTables& tables, const uint8_t* rans_data, size_t rans_size,
                             const uint8_t* raw_data, size_t raw_size, StaticOrder order) {
    return decode_static(h, FromNodes<Hierarchy>{h, created}, space, mode, tables, rans_data, rans_size, raw_data, raw_size,
                         order == StaticOrder::grouped);
}

bool decode_static_positions(Hierarchy& h, NewVertexCorners& corners, CoordinateSpace space, GeometryPredictor mode,
                             const StaticTables& tables, const uint8_t* rans_data, size_t rans_size, const uint8_t* raw_data,
                             size_t raw_size, StaticOrder order) {
    return decode_static(h, FromList{corners}, space, mode, tables, rans_data, rans_size, raw_data, raw_size,
                         order == StaticOrder::grouped);
}

}  // namespace amc
