// The static geometry mode of a level (docs/FORMAT.md 5.6): the positions a level creates,
// predicted in the normal frame (geometry_prediction.h), their residuals mapped to tokens coded
// with interleaved rANS under three frequency tables the level block carries (one per role: the
// normal's axis, then the two others), and the bits below each token copied to a raw bit stream.
// Built for decode speed: one table look-up per coordinate instead of a dozen adaptive binary
// decisions, and the noise bits of bit-exact coordinates read 57 at a time.
//
// Token of a residual of sign s (1 = negative) and magnitude m, k = bit length of m:
//   m = 0: token 0;  1 <= m < 8: token 2m - 1 + s;
//   m >= 8: token 15 + 4 (k - 4) + (the two bits below the leading one); raw bits: s, then the
//   k - 3 low bits of m (most significant first, in two values of k - 35 and 32 bits when
//   k - 3 > 32).
//
// Geometry mode 4 (FORMAT.md 5.7, quantized files only) is mode 3 with the frame's normal summed
// from unit normals (the surface remesher's direction) and six tables: each role's residuals split
// by where the prediction t (in grid steps) lies between two grid points. Where the
// surface is flat at the grid's scale the residual is rounding noise: 0 when t is near a grid point,
// 0 or a step towards the second-nearest grid point, about evenly, when t is near half-way (the
// midpoint of two grid points whose sum is odd). The residual's sign is turned so that positive
// points towards the second-nearest grid point.
//
// The encoder is static_position_encoder.cpp, the decoder static_position_decoder.cpp with its fast
// paths in static_stencil_decoder.cpp and static_frame_decoder.cpp; their shared pieces are in
// static_position_internal.h.
#pragma once

#include "coding/entropy/arithmetic_coder.h"
#include "coding/entropy/rans_coder.h"
#include "coding/geometry/float_coder.h"
#include "hierarchy/hierarchy_builder.h"

#include <amc/codec.h>
#include <amc/hierarchy.h>

#include <array>
#include <cstdint>
#include <utility>
#include <vector>

namespace amc {

constexpr int kStaticRoles = 3;
constexpr int kGridBins = 2;  // mode 4: |t - round(t)| below or from 1/4
constexpr int kMaxStaticTables = kStaticRoles * kGridBins;
// Mode 3 uses the first three (one per role), mode 4 all six (table 2 role + bin).
using StaticTables = std::array<RansTable, kMaxStaticTables>;

// The order of a mode-4 level's tokens (FORMAT.md 5.7): vertex after vertex, each vertex's roles
// 0, 1, 2 (versions 9-17), or grouped by runs of kGridGroup vertices, the run's role-0 tokens first,
// then each vertex's roles 1 and 2 (version 18 on): roles 1 and 2's tables depend on role 0's value,
// so in the per-vertex order each token waits for the previous vertex's divisions. Every other mode
// keeps the per-vertex order.
enum class StaticOrder : uint8_t { per_vertex, grouped };
constexpr size_t kGridGroup = 64;

// The static modes: 3 (normal_frame), 4 (normal_frame_grid) and 5 (unit_normal_frame), which
// predict in a frame, and 6 and 7 (midpoint_static, butterfly_static), which predict each axis by
// the adaptive predictors' stencils and code it with the table of its axis (FORMAT.md 5.9).
constexpr bool has_frame(GeometryPredictor p) {
    return p == GeometryPredictor::normal_frame || p == GeometryPredictor::normal_frame_grid ||
           p == GeometryPredictor::unit_normal_frame;
}
constexpr bool has_stencil_tables(GeometryPredictor p) {
    return p == GeometryPredictor::midpoint_static || p == GeometryPredictor::butterfly_static;
}
constexpr bool is_static_mode(GeometryPredictor p) { return has_frame(p) || has_stencil_tables(p); }
// Mode 4 splits each role's table by grid position.
constexpr bool has_grid_bins(GeometryPredictor mode) { return mode == GeometryPredictor::normal_frame_grid; }
// Modes 4 and 5 sum unit normals for the frame (mode 3 sums cross products).
constexpr bool has_unit_normals(GeometryPredictor mode) { return mode != GeometryPredictor::normal_frame; }
// The number of tables of a static mode: 3, or 6 in mode 4.
constexpr int static_table_count(GeometryPredictor mode) { return has_grid_bins(mode) ? kMaxStaticTables : kStaticRoles; }

// The code of one level's new positions in the static mode. `created` are the level's new
// vertices (new_vertices_of_level) with their positions set in h (the decoder's values: on the grid
// when quantized).
// The token of a residual of sign `negative` (1 = negative) and magnitude m (the map above), and how
// many raw bits follow it: the sign and the k - 3 low bits when m >= 8, else none.
int static_token(bool negative, uint64_t magnitude);
int static_raw_bit_count(uint64_t magnitude);

// A residual of the static modes as sign and magnitude.
struct StaticResidual {
    bool negative;
    uint64_t magnitude;
};

// Buffers of StaticLevelEncoders kept from one encoder to the next (an EncodeContext's): an encoder
// made over them takes a set at its start and gives it back at its end, so that the levels and mode
// trials of repeated encodes neither allocate them nor fault their pages in again. One thread at a time.
class StaticEncoderBuffers {
public:
    struct Set {
        std::vector<std::array<uint16_t, kStaticRoles>> symbols;
        std::vector<StaticResidual> large;
        std::vector<uint8_t> raw, rans;
        ScratchArray<uint8_t> rans_memory;
        std::array<std::vector<uint64_t>, kMaxStaticTables> counts;
    };
    Set take() {
        if (free_.empty()) return {};
        Set set = std::move(free_.back());
        free_.pop_back();
        return set;
    }
    void give_back(Set&& set) { free_.push_back(std::move(set)); }

private:
    std::vector<Set> free_;
};

class StaticLevelEncoder {
public:
    // mode: a static mode (is_static_mode); mode 4 needs a quantized space, modes 6 and 7 a
    // bit-exact one. Throws Error otherwise.
    // With `streams` false only the tokens and tables are made, until code_streams(): an encoder
    // weighing modes asks lower_bound_bytes() first.
    // Mesh: Hierarchy or HierarchyOnGrid (hierarchy_on_grid.h), here and below.
    // `order`: mode 4's token order (the other modes have one). With `buffers`, the encoder works
    // in a set of them, given back when it ends.
    template <class Mesh>
    StaticLevelEncoder(const Mesh& h, const std::vector<std::pair<NodeId, int>>& created, CoordinateSpace space,
                       GeometryPredictor mode = GeometryPredictor::normal_frame, bool streams = true,
                       StaticOrder order = StaticOrder::grouped, StaticEncoderBuffers* buffers = nullptr);
    // Over the first `count` of `created` only (no streams): an encoder weighing modes on a sample
    // of a level, which extend() may then carry on over the whole level. It stops short once its
    // streams' bound over the `count` vertices is known to pass `stream_byte_limit` (gave_up(): then
    // good only for being dropped).
    template <class Mesh>
    StaticLevelEncoder(const Mesh& h, const std::vector<std::pair<NodeId, int>>& created, size_t count,
                       CoordinateSpace space, GeometryPredictor mode, StaticOrder order = StaticOrder::grouped,
                       StaticEncoderBuffers* buffers = nullptr, size_t stream_byte_limit = SIZE_MAX);
    ~StaticLevelEncoder();
    StaticLevelEncoder(const StaticLevelEncoder&) = delete;
    StaticLevelEncoder& operator=(const StaticLevelEncoder&) = delete;
    // Adds the rest of `created` (the vector the encoder was made over the first part of) and
    // remakes the tables: the encoder made over all of `created`, without its first part's frames
    // computed again. Before code_streams() only.
    template <class Mesh>
    void extend(const Mesh& h, const std::vector<std::pair<NodeId, int>>& created);
    // Codes the rANS and raw streams (once).
    void code_streams();
    // The tables (three, or six in mode 4), into the level's arithmetic payload after the hierarchy part.
    void write_tables(ArithmeticEncoder& encoder) const;
    const std::vector<uint8_t>& rans_bytes() const { return rans_; }
    const std::vector<uint8_t>& raw_bytes() const { return raw_; }
    // The bytes this mode costs the level's positions: tables (coded alone), both streams and the
    // varint of the rANS length. Needs the streams.
    size_t estimated_bytes() const;
    // At most estimated_bytes(), known before the streams: the tables, the raw bits and the rANS
    // stream's entropy under its tables (the bound's derivation is in the .cpp).
    size_t lower_bound_bytes() const;
    // lower_bound_bytes() with its streams' part scaled by `scale` (the tables not): an encoder
    // made over a sample of a level projects the level's bound with the level's size over the sample's.
    double projected_bound_bytes(double scale) const;
    // Its streams' part alone (known without coding the tables): projected_bound_bytes(scale) is
    // at least 1 more.
    double projected_stream_bound_bytes(double scale) const;
    // Whether the streams' bound passed the limit the encoder was made with before its last vertex.
    bool gave_up() const { return gave_up_; }

private:
    // Tokens, residuals and counts of created[begin, end).
    template <class Mesh>
    void add(const Mesh& h, const std::vector<std::pair<NodeId, int>>& created, size_t begin, size_t end);
    // How add_vertices takes the residuals of modes 3 and 5 (and add_stencil_vertices those of 6
    // and 7): residual_of, float64 or float32 inline, or grid points inline.
    static constexpr int kAnyResiduals = 0, kFloat64Residuals = 1, kGridResiduals = 2, kFloat32Residuals = 3;
    // One residual of table `table`: its token into `symbol`, its count, and its raw bits (if any)
    // to large_ (KeepLarge) or the raw stream; raw_bits adds their number.
    template <bool KeepLarge>
    void take_residual(const StaticResidual& r, int table, uint16_t& symbol, uint64_t& raw_bits);
    // KeepLarge: the raw bits wait in large_ (mode 4's grouped order, or a sample's; see below).
    template <bool UnitNormals, bool GridBins, int Residuals, bool KeepLarge, class Mesh>
    void add_vertices(const Mesh& h, const std::vector<std::pair<NodeId, int>>& created, size_t begin, size_t end);
    // Mode 5 bit-exact in the hierarchy's own precision (float32 in a single-precision one):
    // add_vertices with the listed decoder's frames.
    template <bool Float32, bool KeepLarge>
    void add_unit_vertices(const Hierarchy& h, const std::vector<std::pair<NodeId, int>>& created, size_t begin, size_t end);
    // Modes 6 and 7: each axis against the stencil's prediction, with the table of its axis.
    template <bool Butterfly, int Residuals, bool KeepLarge, class Mesh>
    void add_stencil_vertices(const Mesh& h, const std::vector<std::pair<NodeId, int>>& created, size_t begin, size_t end);
    // A sample's raw bits out of large_ into the raw stream, with room for a level of
    // `level_size` vertices; nothing unless deferred_.
    void write_deferred_raw_bits(size_t level_size);
    // lower_bound_bytes()' parts: the coded tables, and the rANS and raw streams.
    size_t table_bytes() const;
    // The tables coded alone, made once per make_tables() (the bounds and the size ask it up to three times).
    size_t coded_table_bytes() const;
    size_t stream_bound_bytes() const;
    // At most stream_bound_bytes() of an encoder of `tokens` tokens that begins with these (before
    // the tables are made).
    size_t stream_bound_below(uint64_t tokens) const;
    // The tables from the counts, and the tokens' cost under them.
    void make_tables();
    // Empties v, keeping its memory when it goes back to buffers_ (else freeing it now).
    template <class T>
    void empty_out(std::vector<T>& v) {
        if (buffers_ != nullptr) v.clear();
        else v = {};
    }

    GeometryPredictor mode_;
    bool grouped_;  // mode 4 in StaticOrder::grouped
    CoordinateSpace space_;
    StaticTables tables_;
    int table_count_ = kStaticRoles;
    std::array<std::vector<uint64_t>, kMaxStaticTables> counts_;  // per table, of each possible token
    double token_bits_ = 0;  // the tokens' cost under the tables, sum of log2(M / f)
    uint64_t token_count_ = 0;
    // Until the streams are coded: each coordinate's table and token in one word (table_shifted |
    // token). The raw bits of the tokens that have them (from kDirectTokens on): in the per-vertex
    // order, the raw stream's order, they go to `raw_writer_` as the tokens are made; mode 4's
    // grouped order keeps their residuals in `large_` for code_streams to write in its order, and
    // so does an encoder made over a sample (deferred_) until extend() or code_streams(): the
    // automatic choice drops most samples, whose bits would be written for nothing.
    std::vector<std::array<uint16_t, kStaticRoles>> symbols_;
    std::vector<StaticResidual> large_;
    bool deferred_ = false;
    RawBitWriter raw_writer_;
    uint64_t raw_bits_ = 0;
    mutable size_t coded_table_bytes_ = SIZE_MAX;  // coded_table_bytes(), or SIZE_MAX until asked
    bool coded_ = false;
    bool gave_up_ = false;
    std::vector<uint8_t> rans_, raw_;
    ScratchArray<uint8_t> rans_memory_;  // the rANS encoder's
    StaticEncoderBuffers* buffers_ = nullptr;
};

// Reads the tables of static mode `mode` (three, or six in mode 4); false when they are not valid
// for `space` (a frequency sum other than 2^12, a token larger than the space's residuals can be)
// or the mode is not a static mode the space allows.
bool read_static_tables(ArithmeticDecoder& decoder, CoordinateSpace space, GeometryPredictor mode, StaticTables& tables);

// Mode 4's listed decoder makes its frames, and the grouped order's roles 1 and 2 predictions, four
// at a time with AVX2 where the processor has it (simd.h), else in pairs with SSE2: the same values.
// false makes it take the pairs everywhere, so that tests decode both ways; returns the setting before.
bool set_wide_frames(bool allowed);

// Decodes the positions of `created` (in order) and sets them in h. False when the streams are
// corrupt: a grid coordinate out of range, a non-finite coordinate, an overrun, or streams that do
// not end where the last coordinate ends.
// `order`: mode 4's token order (the file's version's: grouped from version 18).
bool decode_static_positions(Hierarchy& h, const std::vector<std::pair<NodeId, int>>& created, CoordinateSpace space,
                             GeometryPredictor mode, const StaticTables& tables, const uint8_t* rans, size_t rans_size, const uint8_t* raw,
                             size_t raw_size, StaticOrder order);
// The same for the vertices corners.first(), corners.first() + 1, ... with their frame corners
// (NewVertexCorners, taken a run at a time from `corners`). Modes with a frame only (has_frame).
bool decode_static_positions(Hierarchy& h, NewVertexCorners& corners, CoordinateSpace space, GeometryPredictor mode,
                             const StaticTables& tables, const uint8_t* rans, size_t rans_size, const uint8_t* raw,
                             size_t raw_size, StaticOrder order);

}  // namespace amc
