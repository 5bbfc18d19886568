// The static geometry modes' encoder (docs/FORMAT.md 5.6-5.9; static_position_coder.h).

#include "coding/geometry/static_position_internal.h"

namespace amc {

using namespace static_geometry;

namespace {

void put_raw(RawBitWriter& raw, Residual r) {
    if (r.magnitude < 8) return;
    const int low = bit_length(r.magnitude) - 3;
    // The sign and the first value in one put (take_large reads them in one get); put's mask drops
    // the magnitude's three leading bits, which the token holds.
    const uint64_t sign = r.negative ? 1 : 0;
    if (low > 56) {
        raw.put((r.magnitude >> 32) << 1 | sign, low - 31);
        raw.put(r.magnitude & 0xFFFFFFFFull, 32);
        return;
    }
    // Up to 57 bits in one put, the two values of low > 32 side by side as take_large reads them;
    // without a branch on low, which bit-exact residuals put on both sides of 32 by turns.
    const int rot = std::max(low - 32, 0);
    const uint64_t first = (r.magnitude >> (32 & -int(rot > 0))) << 1 | sign;  // the magnitude itself when low <= 32
    const uint64_t first_bits = rot > 0 ? first & ((uint64_t{2} << rot) - 1) : first;
    raw.put(first_bits | (rot > 0 ? (r.magnitude & 0xFFFFFFFFull) << (rot + 1) : 0), low + 1);
}

void put_gamma(ArithmeticEncoder& encoder, std::array<BitModel, kMaxGammaLength + 1>& models, uint32_t v) {
    const int length = bit_length(v) - 1;  // v >= 1
    for (int i = 0; i < length; ++i) encoder.encode(true, models[size_t(i)]);
    if (length < kMaxGammaLength) encoder.encode(false, models[size_t(length)]);
    encoder.encode_bits_raw(v & ((uint32_t{1} << length) - 1), length);
}

void put_table(ArithmeticEncoder& encoder, TableModels& models, const RansTable& table) {
    std::vector<int> used;
    for (int s = 0; s < table.size(); ++s)
        if (table.frequency(s) != 0) used.push_back(s);
    put_gamma(encoder, models.count, uint32_t(used.size()));
    int previous = -1;
    for (int s : used) {
        put_gamma(encoder, models.gap, uint32_t(s - previous));
        previous = s;
    }
    for (size_t i = 0; i + 1 < used.size(); ++i) put_gamma(encoder, models.frequency, table.frequency(used[i]));
}

}  // namespace

// Both without branches: whether a residual is 0, small or large is a coin flip on surfaces.
int static_token(bool negative, uint64_t magnitude) {
    const int small = int(2 * magnitude - 1 + (negative ? 1 : 0)) & -int(magnitude != 0);
    const int k = bit_length(magnitude | 8);
    const int large = kDirectTokens + 4 * (k - 4) + int((magnitude >> (k - 3)) & 3);
    return magnitude < 8 ? small : large;
}

int static_raw_bit_count(uint64_t magnitude) { return magnitude < 8 ? 0 : bit_length(magnitude) - 2; }

template <class Mesh>
StaticLevelEncoder::StaticLevelEncoder(const Mesh& h, const std::vector<std::pair<NodeId, int>>& created,
                                       CoordinateSpace space, GeometryPredictor mode, bool streams, StaticOrder order,
                                       StaticEncoderBuffers* buffers)
    : StaticLevelEncoder(h, created, created.size(), space, mode, order, buffers) {
    if (streams) code_streams();
}

template <class Mesh>
StaticLevelEncoder::StaticLevelEncoder(const Mesh& h, const std::vector<std::pair<NodeId, int>>& created, size_t count,
                                       CoordinateSpace space, GeometryPredictor mode, StaticOrder order,
                                       StaticEncoderBuffers* buffers, size_t stream_byte_limit)
    : mode_(mode), grouped_(has_grid_bins(mode) && order == StaticOrder::grouped), space_(space),
      table_count_(static_table_count(mode)) {
    if (!is_static_mode(mode)) throw Error("StaticLevelEncoder: geometry mode " + std::to_string(int(mode)) + " is not a static mode");
    if (has_grid_bins(mode) && space.quantizer == nullptr) throw Error("geometry mode 4 needs quantized coordinates");
    if (has_stencil_tables(mode) && space.quantizer != nullptr)
        throw Error("geometry modes 6 and 7 need bit-exact coordinates");
    if (buffers != nullptr) {
        StaticEncoderBuffers::Set set = buffers->take();
        buffers_ = buffers;
        symbols_ = std::move(set.symbols);
        symbols_.clear();
        large_ = std::move(set.large);
        large_.clear();
        raw_writer_.adopt(std::move(set.raw));
        rans_ = std::move(set.rans);
        rans_.clear();
        rans_memory_ = std::move(set.rans_memory);
        counts_ = std::move(set.counts);
        for (std::vector<uint64_t>& counts : counts_) counts.clear();  // add() zeroes them
    }
    count = std::min(count, created.size());
    // A sample's raw bits wait in large_ (see the header): the mode choice drops most samples.
    deferred_ = !grouped_ && count < created.size();
    if (stream_byte_limit == SIZE_MAX) {
        add(h, created, 0, count);
    } else {
        // In steps, with the room for the whole count made first (add() reserves by the part before).
        constexpr size_t kStep = 4 * kChunk;
        symbols_.reserve(count);
        if (space.quantizer == nullptr && (deferred_ || grouped_)) large_.reserve(size_t(kStaticRoles) * count);
        for (size_t begin = 0; begin < count && !gave_up_; begin += kStep) {
            add(h, created, begin, std::min(count, begin + kStep));
            if (begin + kStep >= count) break;
            // The raw bits' part first; the tokens' entropy (a pass over the counts) once it is half way.
            const size_t raw_part = kRansStateBytes + size_t(raw_bits_ / 8);
            gave_up_ = raw_part > stream_byte_limit ||
                       (2 * raw_part > stream_byte_limit && stream_bound_below(uint64_t(kStaticRoles) * count) > stream_byte_limit);
        }
        if (gave_up_) return;
    }
    make_tables();
}

StaticLevelEncoder::~StaticLevelEncoder() {
    if (buffers_ == nullptr) return;
    StaticEncoderBuffers::Set set;
    set.symbols = std::move(symbols_);
    set.large = std::move(large_);
    set.raw = coded_ ? std::move(raw_) : raw_writer_.finish();
    set.rans = std::move(rans_);
    set.rans_memory = std::move(rans_memory_);
    set.counts = std::move(counts_);
    try {
        buffers_->give_back(std::move(set));
    } catch (...) {  // no room to keep them: they are freed
    }
}

template <class Mesh>
void StaticLevelEncoder::extend(const Mesh& h, const std::vector<std::pair<NodeId, int>>& created) {
    if (coded_) throw Error("StaticLevelEncoder::extend: the streams are coded already");
    write_deferred_raw_bits(created.size());
    add(h, created, symbols_.size(), created.size());
    make_tables();
}

template <class Mesh>
void StaticLevelEncoder::add(const Mesh& h, const std::vector<std::pair<NodeId, int>>& created, size_t begin, size_t end) {
    if (counts_[0].empty())
        for (int i = 0; i < table_count_; ++i) counts_[size_t(i)].assign(size_t(token_limit(space_)), 0);
    symbols_.resize(end);
    // Room for the raw bits (grown by doubling they were copied again and again), at the rate of
    // the part before (a little more: the writer zero-fills what it reserves as it starts to use
    // it), or at first in float spaces, where nearly every coordinate has some, 64 a coordinate.
    const bool keep_large = grouped_ || deferred_;
    if (begin > 0) {
        const double share = double(end - begin) / double(begin);
        if (keep_large) large_.reserve(large_.size() + size_t(double(large_.size()) * share));
        else raw_writer_.reserve_bits(uint64_t(double(raw_writer_.bits()) * share * 1.125) + 4096);
    } else if (space_.quantizer == nullptr) {
        if (deferred_) large_.reserve(size_t(kStaticRoles) * (end - begin));
        else raw_writer_.reserve_bits(uint64_t(kStaticRoles) * 64 * (end - begin));
    }
    const bool float64 = space_.quantizer == nullptr && space_.precision == Precision::float64;
    // Modes 3 (without a quantizer), 6 and 7 are bit-exact: float64 or float32.
    switch (mode_) {
        case GeometryPredictor::normal_frame:
            if (space_.quantizer != nullptr) {
                if (keep_large) add_vertices<false, false, kGridResiduals, true>(h, created, begin, end);
                else add_vertices<false, false, kGridResiduals, false>(h, created, begin, end);
            } else if (float64) {
                if (keep_large) add_vertices<false, false, kFloat64Residuals, true>(h, created, begin, end);
                else add_vertices<false, false, kFloat64Residuals, false>(h, created, begin, end);
            } else {
                if (keep_large) add_vertices<false, false, kFloat32Residuals, true>(h, created, begin, end);
                else add_vertices<false, false, kFloat32Residuals, false>(h, created, begin, end);
            }
            break;
        case GeometryPredictor::normal_frame_grid:
            if (keep_large) add_vertices<true, true, kGridResiduals, true>(h, created, begin, end);
            else add_vertices<true, true, kGridResiduals, false>(h, created, begin, end);
            break;
        case GeometryPredictor::midpoint_static:
            if (float64) {
                if (keep_large) add_stencil_vertices<false, kFloat64Residuals, true>(h, created, begin, end);
                else add_stencil_vertices<false, kFloat64Residuals, false>(h, created, begin, end);
            } else {
                if (keep_large) add_stencil_vertices<false, kFloat32Residuals, true>(h, created, begin, end);
                else add_stencil_vertices<false, kFloat32Residuals, false>(h, created, begin, end);
            }
            break;
        case GeometryPredictor::butterfly_static:
            if (float64) {
                if (keep_large) add_stencil_vertices<true, kFloat64Residuals, true>(h, created, begin, end);
                else add_stencil_vertices<true, kFloat64Residuals, false>(h, created, begin, end);
            } else {
                if (keep_large) add_stencil_vertices<true, kFloat32Residuals, true>(h, created, begin, end);
                else add_stencil_vertices<true, kFloat32Residuals, false>(h, created, begin, end);
            }
            break;
        default:
            if constexpr (std::is_same_v<Mesh, Hierarchy>) {
                // Bit-exact in the hierarchy's own precision: every bit-exact level.
                if (space_.quantizer == nullptr && float64 != h.single_precision()) {
                    if (float64) {
                        if (keep_large) add_unit_vertices<false, true>(h, created, begin, end);
                        else add_unit_vertices<false, false>(h, created, begin, end);
                    } else {
                        if (keep_large) add_unit_vertices<true, true>(h, created, begin, end);
                        else add_unit_vertices<true, false>(h, created, begin, end);
                    }
                    break;
                }
            }
            if (float64) {
                if (keep_large) add_vertices<true, false, kFloat64Residuals, true>(h, created, begin, end);
                else add_vertices<true, false, kFloat64Residuals, false>(h, created, begin, end);
            } else if (space_.quantizer == nullptr) {
                if (keep_large) add_vertices<true, false, kFloat32Residuals, true>(h, created, begin, end);
                else add_vertices<true, false, kFloat32Residuals, false>(h, created, begin, end);
            } else {
                if (keep_large) add_vertices<true, false, kAnyResiduals, true>(h, created, begin, end);
                else add_vertices<true, false, kAnyResiduals, false>(h, created, begin, end);
            }
            break;
    }
}

template <bool KeepLarge>
AMC_ALWAYS_INLINE void StaticLevelEncoder::take_residual(const Residual& r, int table, uint16_t& symbol, uint64_t& raw_bits) {
    const int token = static_token(r.negative, r.magnitude);
    if (token >= kDirectTokens) {  // the raw bits of a large residual: grouped order keeps them for code_streams
        if (KeepLarge) large_.push_back(r);
        else put_raw(raw_writer_, r);
    }
    symbol = uint16_t(table << kTokenBits | token);
    raw_bits += uint64_t(static_raw_bit_count(r.magnitude));
    ++counts_[size_t(table)][size_t(token)];
}

// The loop of add() for one mode: the frame's kind, the table split and the residuals' kind known when it is compiled.
// A chunk's corners and frames as the decoder makes them (gather_chunk, frame_chunk), then each
// vertex's residuals in role order.
template <bool UnitNormals, bool GridBins, int Residuals, bool KeepLarge, class Mesh>
void StaticLevelEncoder::add_vertices(const Mesh& h, const std::vector<std::pair<NodeId, int>>& created, size_t begin,
                                      size_t end) {
    const CoordinateSpace space = space_;
    const Quantizer* quantizer = space.quantizer;
    const GridScale grid = grid_scale(quantizer);
    uint64_t raw_bits = 0;
    Chunk c;
    for (size_t first = begin; first < end; first += kChunk) {
        gather_chunk(h, FromNodes<Mesh>{h, created}, first, end, c);
        for (size_t i = 0; i < c.count; ++i) __builtin_prefetch(&h.positions()[c.vertices[i]]);
        frame_chunk<GridBins, UnitNormals>(h, quantizer, grid, c);
        for (size_t i = 0; i < c.count; ++i) {
            const RoleFrame& f = c.frames[i];
            const Vec3 p = h.position(c.vertices[i]);
            const double actual[3] = {p.x, p.y, p.z};
            double predicted[3] = {f.midpoint[0], 0, 0};
            predict_others(f, actual[f.axes[0]], predicted[1], predicted[2]);
            std::array<uint16_t, kStaticRoles>& symbols = symbols_[first + i];
            for (int role = 0; role < kStaticRoles; ++role) {
                const int axis = f.axes[role];
                Residual r;
                int table = role;
                if (GridBins) {
                    const GridPrediction g = role == 0 ? c.first[i] : grid_prediction_at(grid, f.origin[role], predicted[role]);
                    r = grid_residual(grid_point_of_grid_value(grid, f.origin[role], actual[axis]), g);
                    table = kGridBins * role + g.bin;
                } else if (Residuals == kFloat64Residuals) {
                    r = float64_residual(actual[axis], predicted[role]);
                } else if (Residuals == kFloat32Residuals) {
                    r = float32_residual(actual[axis], predicted[role]);
                } else if (Residuals == kGridResiduals) {  // residual_of's grid points, with the level's GridScale
                    const uint32_t a = grid_point_of_grid_value(grid, f.origin[role], actual[axis]);
                    const uint32_t q = grid_point_at(grid, f.origin[role], predicted[role]);
                    r = {a < q, a < q ? uint64_t(q - a) : uint64_t(a - q)};
                } else {
                    r = residual_of(space, axis, actual[axis], predicted[role]);
                }
                take_residual<KeepLarge>(r, table, symbols[size_t(role)], raw_bits);
            }
        }
    }
    raw_bits_ += raw_bits;
}

template <bool Butterfly, int Residuals, bool KeepLarge, class Mesh>
void StaticLevelEncoder::add_stencil_vertices(const Mesh& h, const std::vector<std::pair<NodeId, int>>& created, size_t begin,
                                              size_t end) {
    uint64_t raw_bits = 0;
    for (size_t i = begin; i < end; ++i) {
        const auto [n, e] = created[i];
        const Vec3 q = Butterfly ? predict_butterfly(h, n, e) : predict_midpoint(h, n, e);
        const Vec3 p = h.position(h.midpoint(n, e));
        const double actual[3] = {p.x, p.y, p.z}, predicted[3] = {q.x, q.y, q.z};
        std::array<uint16_t, kStaticRoles>& symbols = symbols_[i];
        for (int axis = 0; axis < 3; ++axis) {
            const Residual r = Residuals == kFloat64Residuals   ? float64_residual(actual[axis], predicted[axis])
                               : Residuals == kFloat32Residuals ? float32_residual(actual[axis], predicted[axis])
                                                                : residual_of(space_, axis, actual[axis], predicted[axis]);
            take_residual<KeepLarge>(r, axis, symbols[size_t(axis)], raw_bits);  // never grouped
        }
    }
    raw_bits_ += raw_bits;
}

// The encoder reads a hierarchy or the input's nodes with its grid points (hierarchy_on_grid.h).
template StaticLevelEncoder::StaticLevelEncoder(const Hierarchy&, const std::vector<std::pair<NodeId, int>>&, CoordinateSpace,
                                                GeometryPredictor, bool, StaticOrder, StaticEncoderBuffers*);
template StaticLevelEncoder::StaticLevelEncoder(const HierarchyOnGrid&, const std::vector<std::pair<NodeId, int>>&,
                                                CoordinateSpace, GeometryPredictor, bool, StaticOrder, StaticEncoderBuffers*);
template StaticLevelEncoder::StaticLevelEncoder(const Hierarchy&, const std::vector<std::pair<NodeId, int>>&, size_t,
                                                CoordinateSpace, GeometryPredictor, StaticOrder, StaticEncoderBuffers*, size_t);
template StaticLevelEncoder::StaticLevelEncoder(const HierarchyOnGrid&, const std::vector<std::pair<NodeId, int>>&, size_t,
                                                CoordinateSpace, GeometryPredictor, StaticOrder, StaticEncoderBuffers*, size_t);
template void StaticLevelEncoder::extend(const Hierarchy&, const std::vector<std::pair<NodeId, int>>&);
template void StaticLevelEncoder::extend(const HierarchyOnGrid&, const std::vector<std::pair<NodeId, int>>&);

void StaticLevelEncoder::make_tables() {
    coded_table_bytes_ = SIZE_MAX;
    token_bits_ = 0;
    token_count_ = 0;
    for (int i = 0; i < table_count_; ++i) {
        // The counts up to the largest token seen: the table's size.
        const std::vector<uint64_t>& all = counts_[size_t(i)];
        size_t size = all.size();
        while (size > 0 && all[size - 1] == 0) --size;
        std::vector<uint64_t> c(all.begin(), all.begin() + std::ptrdiff_t(size));
        const bool used = !c.empty();
        if (!used) c.push_back(1);  // a table no token uses still needs a symbol
        tables_[size_t(i)] = RansTable::for_encoding(c);
        for (size_t t = 0; used && t < c.size(); ++t) {
            if (c[t] == 0) continue;
            // Rounded before the sum: a fused multiply-add could tip the mode choice between builds.
            token_bits_ += rounded(double(c[t]) * tables_[size_t(i)].cost_bits(int(t)));
            token_count_ += c[t];
        }
    }
}

void StaticLevelEncoder::write_deferred_raw_bits(size_t level_size) {
    if (!deferred_) return;
    // Room for the level at the sample's rate (a little more, as add() reserves for an extension).
    const double share = symbols_.empty() ? 1.0 : double(level_size) / double(symbols_.size());
    raw_writer_.reserve_bits(uint64_t(double(raw_bits_) * share * 1.125) + 4096);
    for (const Residual& r : large_) put_raw(raw_writer_, r);
    empty_out(large_);
    deferred_ = false;
}

void StaticLevelEncoder::code_streams() {
    if (coded_) return;
    write_deferred_raw_bits(symbols_.size());
    constexpr uint16_t kTokenMask = (1 << kTokenBits) - 1;
    // The rANS stream back to front, straight from the symbol words (rANS codes backwards).
    RansBackwardEncoder rans(kStaticRoles * symbols_.size(), rans_memory_);
    static_assert(sizeof(symbols_[0]) == kStaticRoles * sizeof(uint16_t), "symbol words are contiguous");
    const uint16_t* words = reinterpret_cast<const uint16_t*>(symbols_.data());
    const RansTable::Coding* codings[kMaxStaticTables];
    for (int i = 0; i < table_count_; ++i) codings[i] = tables_[size_t(i)].codings();
    auto coding = [&](uint16_t word) -> const RansTable::Coding& { return codings[word >> kTokenBits][word & kTokenMask]; };
    if (!grouped_) {
        // The symbol words one after the other (vertex after vertex, role after role).
        rans.put_all(kStaticRoles * symbols_.size(), [&](size_t j) -> const RansTable::Coding& { return coding(words[j]); });
    } else {
        // Each run: its role-0 tokens, then each vertex's roles 1 and 2 (FORMAT.md 5.7); the runs backwards.
        for (size_t run = (symbols_.size() + kGridGroup - 1) / kGridGroup; run-- > 0;) {
            const size_t begin = run * kGridGroup, count = std::min(kGridGroup, symbols_.size() - begin);
            const uint16_t* run_words = words + kStaticRoles * begin;
            rans.put_all(kStaticRoles * count, [&](size_t j) -> const RansTable::Coding& {
                if (j < count) return coding(run_words[kStaticRoles * j]);
                const size_t k = j - count;  // vertex k / 2, role 1 + k % 2
                return coding(run_words[kStaticRoles * (k >> 1) + 1 + (k & 1)]);
            });
        }
    }
    rans.finish(rans_);
    // The raw bits front to back, in the tokens' order (written as they came unless grouped).
    RawBitWriter& raw = raw_writer_;
    if (grouped_ && !large_.empty()) {
        raw.reserve_bits(raw_bits_);
        size_t next_large = 0;
        for (size_t begin = 0; begin < symbols_.size(); begin += kGridGroup) {
            const size_t count = std::min(kGridGroup, symbols_.size() - begin);
            size_t large[kGridGroup][kStaticRoles];  // each token's residual in large_, kept in the per-vertex order
            for (size_t i = 0; i < count; ++i)
                for (int role = 0; role < kStaticRoles; ++role) {
                    large[i][role] = next_large;
                    next_large += (symbols_[begin + i][size_t(role)] & kTokenMask) >= kDirectTokens;
                }
            auto put_raw_of = [&](size_t i, int role) {
                if ((symbols_[begin + i][size_t(role)] & kTokenMask) >= kDirectTokens) put_raw(raw, large_[large[i][role]]);
            };
            for (size_t i = 0; i < count; ++i) put_raw_of(i, 0);
            for (size_t i = 0; i < count; ++i)
                for (int role = 1; role < kStaticRoles; ++role) put_raw_of(i, role);
        }
    }
    raw_ = raw.finish();
    empty_out(symbols_);
    empty_out(large_);
    if (buffers_ == nullptr) rans_memory_ = {};
    coded_ = true;
}

void StaticLevelEncoder::write_tables(ArithmeticEncoder& encoder) const {
    TableModels models;
    for (int i = 0; i < table_count_; ++i) put_table(encoder, models, tables_[size_t(i)]);
}

size_t StaticLevelEncoder::estimated_bytes() const {
    if (!coded_) throw Error("StaticLevelEncoder::estimated_bytes: the streams are not coded yet (code_streams)");
    size_t varint = 1;
    for (size_t n = rans_.size(); n >= 128; n >>= 7) ++varint;
    return coded_table_bytes() + varint + rans_.size() + raw_.size();
}

// The rANS stream's bound. Each of its two states starts at L = 2^23 and ends below 256 L; coding
// a symbol of frequency f multiplies x by at least (M / f)(1 - 2^-11) (x / f >= 2^11 there), and
// a byte written divides it by at most 256 / (1 - 2^-11) (x >= 2^19 then). So with H the bits
// sum of log2(M / f) over its N symbols, the K bytes written satisfy 8 K >= H - 16 - 0.001 (N + K),
// and the stream is K + 8 bytes.
size_t StaticLevelEncoder::lower_bound_bytes() const { return table_bytes() + stream_bound_bytes(); }

size_t StaticLevelEncoder::table_bytes() const { return coded_table_bytes() + 1; }

size_t StaticLevelEncoder::coded_table_bytes() const {
    if (coded_table_bytes_ == SIZE_MAX) {
        ArithmeticEncoder tables;
        write_tables(tables);
        coded_table_bytes_ = tables.finish().size();
    }
    return coded_table_bytes_;
}

size_t StaticLevelEncoder::stream_bound_bytes() const {
    const double rans_bits = token_bits_ - 16 - rounded(0.001 * double(token_count_));
    const size_t rans = kRansStateBytes + (rans_bits > 0 ? size_t(rans_bits / 8.01) : 0);
    return rans + size_t(raw_bits_ / 8);
}

// The tokens so far cost at least their empirical entropy under any table (Gibbs' inequality),
// which only grows as tokens are added; the raw bits only grow. The entropy is taken a bit low, so
// that its roundings can not pass the tables' costs.
size_t StaticLevelEncoder::stream_bound_below(uint64_t tokens) const {
    double entropy = 0;
    for (int i = 0; i < table_count_; ++i) {
        const std::vector<uint64_t>& counts = counts_[size_t(i)];
        uint64_t n = 0;
        for (uint64_t c : counts) n += c;
        for (uint64_t c : counts)
            if (c != 0) entropy += rounded(double(c) * std::log2(double(n) / double(c)));
    }
    const double rans_bits = rounded(entropy * (1 - 1e-9)) - 1 - 16 - rounded(0.001 * double(tokens));
    return kRansStateBytes + (rans_bits > 0 ? size_t(rans_bits / 8.01) : 0) + size_t(raw_bits_ / 8);
}

double StaticLevelEncoder::projected_bound_bytes(double scale) const {
    return double(table_bytes()) + projected_stream_bound_bytes(scale);
}

double StaticLevelEncoder::projected_stream_bound_bytes(double scale) const { return rounded(scale * double(stream_bound_bytes())); }

// add_vertices<true, false, kFloat64Residuals or kFloat32Residuals> (mode 5, bit-exact) with the
// frames of decode_unit_listed (GridFrame in axis order, two or four at a time) instead of
// RoleFrame copies: the same predictions, residuals and tokens in the same order.
template <bool Float32, bool KeepLarge>
void StaticLevelEncoder::add_unit_vertices(const Hierarchy& h, const std::vector<std::pair<NodeId, int>>& created, size_t begin,
                                           size_t end) {
    uint64_t raw_bits = 0;
    Chunk c;
    std::array<GridFrame, kChunk> frames;
    for (size_t first = begin; first < end; first += kChunk) {
        gather_chunk(h, FromNodes<Hierarchy>{h, created}, first, end, c);
        for (size_t i = 0; i < c.count; ++i) __builtin_prefetch(&h.positions()[c.vertices[i]]);
        make_unit_frames(h, c.corners, c.count, frames.data());
        for (size_t i = 0; i < c.count; ++i) {
            const GridFrame& f = frames[i];
            const Vec3 p = h.position(c.vertices[i]);
            const double actual[3] = {p.x, p.y, p.z};
            const std::array<int, 3> axes = unit_role_axes(f);
            double second, third;
            predict_unit_others(f, axes, actual[axes[0]], second, third);
            const double predicted[3] = {f.midpoint[axes[0]], second, third};
            std::array<uint16_t, kStaticRoles>& symbols = symbols_[first + i];
            for (int role = 0; role < kStaticRoles; ++role) {
                const double value = actual[axes[role]];
                const Residual r = Float32 ? float32_residual(value, predicted[role]) : float64_residual(value, predicted[role]);
                take_residual<KeepLarge>(r, role, symbols[size_t(role)], raw_bits);
            }
        }
    }
    raw_bits_ += raw_bits;
}

}  // namespace amc
