// The geometry of a level block: see level_geometry.h.
#include "coding/geometry/level_geometry.h"

#include "coding/geometry/geometry_prediction.h"
#include "coding/geometry/hierarchy_on_grid.h"
#include "coding/entropy/rans_coder.h"
#include "common/check.h"
#include "common/exact_float.h"
#include "coding/format_version.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

namespace amc {

namespace {

// Effort below kMaxGeometryEffort, on levels of kSampleShare * kMinSample new vertices or more: the
// static modes are weighed on the first 1/kSampleShare of the level, and only those whose bound
// projected to the level is within kStaticMargin of the smallest are made for the whole level (the
// sample's own bounds favoured mode 3: its three tables against mode 4's six); an adaptive trial is
// dropped when its first 1/kSampleShare, scaled to the level, passes what it must beat by 1/8
// (or its first eighth, quarter or half by 1/4: AdaptiveTrialJudge, whose earliest two tests
// need kMinRateBytes committed in the part they take the rate from).
// Both keep kSampleSlack bytes of room besides, for levels that code to almost nothing.
// Their products are rounded(): a fused multiply-add would make the choice, so the bytes, depend on the build.
constexpr size_t kSampleShare = 8;
constexpr size_t kMinSample = 256;
constexpr double kSampleMargin = 1.125;
constexpr double kSampleSlack = 64;
constexpr double kStaticMargin = 1.02;
constexpr double kEarlyMargin = 1.25;
constexpr size_t kMinRateBytes = 16;

// The static modes the automatic choice weighs, in the order of the choice (after the adaptive
// midpoint and butterfly).
constexpr int kStaticCandidates = 5;
constexpr GeometryPredictor kStaticModes[kStaticCandidates] = {
    GeometryPredictor::normal_frame, GeometryPredictor::normal_frame_grid, GeometryPredictor::unit_normal_frame,
    GeometryPredictor::midpoint_static, GeometryPredictor::butterfly_static};

// An adaptive predictor (1, 2) is taken over a static stencil mode (6, 7) only when it codes the
// level in fewer bytes than the stencil mode's divided by this: a stencil mode decodes the scaling
// torus's coordinates in under half the instructions, for its tables' bytes (CODEC.md, "Geometry
// modes 6 and 7").
constexpr double kStencilPreference = 1.01;

// Clears candidate[i] for the static modes whose lower bound on the first `sample` vertices of
// the level, its streams scaled to the level, passes the smallest by more than kStaticMargin (and
// kSampleSlack bytes); the sample's
// encoders of those left go to on_sample[i], for the whole level to carry on from.
template <class Mesh>
void keep_likely_static_modes(const Mesh& h, const NewVertices& created, CoordinateSpace space, size_t sample,
                              bool candidate[kStaticCandidates], std::unique_ptr<StaticLevelEncoder> on_sample[kStaticCandidates],
                              StaticOrder grid_order, StaticEncoderBuffers* buffers) {
    const double scale = double(created.size()) / double(sample);
    double stream_bound[kStaticCandidates];
    // Bit-exact: mode 5, whose bound was the smallest on every surface level of the corpus, is
    // weighed first; a mode whose streams' bound then passes its limit (modes 3, 6 and 7 within the
    // first half of the sample, by their raw bits and their tokens' entropy so far) fails the test
    // below, whatever the others' bounds (the smallest is at most mode 5's), and is never `first`:
    // it stops there. (Quantized levels: mode 3 against mode 4 passes it only near its sample's end.)
    const int reference = candidate[2] ? 2 : -1;
    size_t stream_byte_limit = SIZE_MAX;
    if (reference >= 0) {
        on_sample[reference] = std::make_unique<StaticLevelEncoder>(h, created, sample, space, kStaticModes[reference], grid_order, buffers);
        const double limit = rounded(kStaticMargin * on_sample[reference]->projected_bound_bytes(scale)) + kSampleSlack;
        // A bound is at least 1 + rounded(scale * streams' bound): past the limit once the streams'
        // bound passes limit / scale.
        stream_byte_limit = size_t(std::floor(limit / scale)) + 1;
    }
    int first = -1;  // the candidate of the smallest streams' bound
    for (int i = 0; i < kStaticCandidates; ++i) {
        if (!candidate[i]) continue;
        if (i != reference) {
            on_sample[i] = std::make_unique<StaticLevelEncoder>(h, created, sample, space, kStaticModes[i], grid_order, buffers,
                                                                stream_byte_limit);
            if (on_sample[i]->gave_up()) {
                candidate[i] = false;
                on_sample[i].reset();
                continue;
            }
        }
        stream_bound[i] = on_sample[i]->projected_stream_bound_bytes(scale);
        if (first < 0 || stream_bound[i] < stream_bound[first]) first = i;
    }
    if (first < 0) return;
    // The tables are coded (to know their bytes) only for the modes that may pass the test: the
    // smallest bound is at most `first`'s, and a bound at least 1 more than its streams' part, so a
    // mode whose streams alone pass `first`'s limit fails the test against the smallest (surface
    // levels: most samples; the same choice as with every bound made).
    const double first_bound = on_sample[first]->projected_bound_bytes(scale);
    const double first_limit = rounded(kStaticMargin * first_bound) + kSampleSlack;
    double bound[kStaticCandidates], smallest = first_bound;
    for (int i = 0; i < kStaticCandidates; ++i) {
        bound[i] = HUGE_VAL;
        if (!candidate[i]) continue;
        if (i == first) bound[i] = first_bound;
        else if (1.0 + stream_bound[i] <= first_limit) bound[i] = on_sample[i]->projected_bound_bytes(scale);
        smallest = std::min(smallest, bound[i]);
    }
    for (int i = 0; i < kStaticCandidates; ++i) {
        candidate[i] = candidate[i] && bound[i] <= rounded(kStaticMargin * smallest) + kSampleSlack;
        if (!candidate[i]) on_sample[i].reset();
    }
}

// The predictors a level block of a file of `file_version` may hold (FORMAT.md 3.6).
bool predictor_allowed(uint8_t predictor, uint8_t file_version, bool quantized) {
    switch (GeometryPredictor(predictor)) {
        case GeometryPredictor::midpoint:
        case GeometryPredictor::butterfly: return true;
        case GeometryPredictor::normal_frame: return file_version >= kStaticGeometryVersion;
        case GeometryPredictor::normal_frame_grid: return file_version >= kGridGeometryVersion && quantized;
        case GeometryPredictor::unit_normal_frame: return file_version >= kUnitFrameVersion;
        case GeometryPredictor::midpoint_static:
        case GeometryPredictor::butterfly_static: return file_version >= kStencilTablesVersion && !quantized;
        default: return false;
    }
}

size_t varint_size(uint64_t value) {
    size_t bytes = 1;
    while (value >= 0x80) {
        value >>= 7;
        ++bytes;
    }
    return bytes;
}

template <class Mesh>
Vec3 predict(const Mesh& h, GeometryPredictor predictor, NodeId n, int e) {
    return predictor == GeometryPredictor::butterfly ? predict_butterfly(h, n, e) : predict_midpoint(h, n, e);
}

template <class Mesh>
void encode_adaptive(const Mesh& h, const NewVertices& created, GeometryPredictor predictor, PositionCoder& positions,
                     ArithmeticEncoder& encoder, RawBitWriter* raw) {
    for (auto [n, e] : created)
        positions.encode(encoder, level_context(h.level(n)), h.position(h.midpoint(n, e)), predict(h, predictor, n, e), raw);
}

// The bytes `predictor` codes the level's positions in (from the models in `positions`), or
// SIZE_MAX once they are known to pass `limit` bytes. Bounds: an arithmetic code of R bits at
// probability 1/2 takes more than R / 8 - 5 bytes (its interval shrinks by 2^-R and grows 256-fold
// a byte, and finish() drops at most 4 zero bytes); a finished code is never much shorter than
// the bytes it committed on the way (8 bytes of margin).
// Only bit-exact coordinates have raw bits enough to be worth the pass that counts them.
// With a `sample` of fewer vertices than the level, that pass covers the sample only, and the
// trial stops when the sample's raw bits scaled to the level pass the limit by kSampleMargin, or
// when AdaptiveTrialJudge says so.
//
// With `level_code` (the level block's arithmetic code holding its hierarchy part), a trial that
// looks like winning codes the level onto a copy of it too, as finish_level_payload would (the
// vertices before, again from `start`'s models), and leaves that coding in `*kept` when it codes
// the whole level.
template <class Mesh>
size_t adaptive_bytes(const Mesh& h, const NewVertices& created, GeometryPredictor predictor, const PositionCoder& start,
                      size_t limit, bool count_raw_bits, size_t sample, const ArithmeticEncoder* level_code,
                      std::unique_ptr<AdaptiveLevelCode>* kept) {
    PositionCoder positions = start;
    const size_t judged = std::min(sample, created.size());
    std::vector<Vec3> predicted(count_raw_bits ? judged : 0);
    auto too_many_raw_bits = [&](uint64_t raw_bits) {
        const double raw_projected = double(raw_bits / 8) * double(created.size()) / double(judged);
        return judged == created.size() ? raw_bits / 8 > limit + 6
                                        : limit != SIZE_MAX && raw_projected > rounded(kSampleMargin * double(limit)) + kSampleSlack;
    };
    uint64_t raw_bits = 0;
    for (size_t i = 0; i < predicted.size(); ++i) {
        const auto [n, e] = created[i];
        predicted[i] = predict(h, predictor, n, e);
        raw_bits += positions.raw_bits(h.position(h.midpoint(n, e)), predicted[i]);
        // The count only grows: once the first vertices' bits fail the test, all of them do
        // (bit-exact surface levels: after about half of the sample).
        if (i % 64 == 63 && too_many_raw_bits(raw_bits)) return SIZE_MAX;
    }
    if (too_many_raw_bits(raw_bits)) return SIZE_MAX;
    ArithmeticEncoder encoder;
    // Bit-exact levels: the raw bits in the side stream (finish_level_payload's layout).
    RawBitWriter raw;
    RawBitWriter* side = positions.quantized() ? nullptr : &raw;
    AdaptiveTrialJudge judge(created.size(), sample, limit);
    // The vertex from which the level's own code is coded alongside: the sample's end (a level
    // without one: its first eighth's), on a bit-exact level that codes in a few dozen bytes (the
    // limit within kSampleSlack: exact midpoints, against the static modes' tables) whose bytes
    // projected there at the rate since half that point stay within the limit. A guess at winning:
    // such codes grow slower than that rate as their models learn (uniform's last level, 122,880
    // vertices, projects 33 bytes against 33 and codes in 27); 12-bit surface trials projected
    // within their limit of thousands of bytes and lost, and so did a 12-bit level of front_1
    // projected at 11 bytes against 22 (BENCHMARKS.md, "One-core encode, twenty-second step").
    const size_t pair_from = level_code == nullptr || side == nullptr ? SIZE_MAX : sample == SIZE_MAX ? created.size() / 8 : judged;
    std::unique_ptr<ArithmeticEncoder> level;
    auto code_vertex = [&](auto& coder, size_t i) {
        const auto [n, e] = created[i];
        positions.encode(coder, level_context(h.level(n)), h.position(h.midpoint(n, e)),
                         i < predicted.size() ? predicted[i] : predict(h, predictor, n, e), side);
    };
    size_t i = 0, half_bytes = 0;
    for (; i < std::min(pair_from, created.size()); ++i) {
        code_vertex(encoder, i);
        const size_t bytes = encoder.bytes_so_far() + raw.bits() / 8;
        if (judge.stops(i + 1, bytes)) return SIZE_MAX;
        if (i + 1 == pair_from / 2) half_bytes = bytes;
    }
    bool paired = i == pair_from && pair_from >= 2;
    if (paired && limit != SIZE_MAX) {
        paired = double(limit) <= kSampleSlack;
        const double bytes = double(encoder.bytes_so_far() + raw.bits() / 8);
        const double rate = (bytes - double(half_bytes)) / double(pair_from - pair_from / 2);
        paired = paired && bytes + rounded(rate * double(created.size() - pair_from)) <= double(limit);
    }
    if (paired) {
        level = std::make_unique<ArithmeticEncoder>(*level_code);
        PositionCoder caught_up = start;  // ends where `positions` is: the same symbols
        RawBitWriter unused;              // the trial's `raw` has these bits already
        for (size_t j = 0; j < i; ++j) {
            const auto [n, e] = created[j];
            caught_up.encode(*level, level_context(h.level(n)), h.position(h.midpoint(n, e)),
                             j < predicted.size() ? predicted[j] : predict(h, predictor, n, e), side != nullptr ? &unused : nullptr);
        }
        ArithmeticEncoderPair pair(encoder, *level);
        for (; i < created.size(); ++i) {
            code_vertex(pair, i);
            if (judge.stops(i + 1, encoder.bytes_so_far() + raw.bits() / 8)) return SIZE_MAX;
        }
    }
    for (; i < created.size(); ++i) {
        code_vertex(encoder, i);
        if (judge.stops(i + 1, encoder.bytes_so_far() + raw.bits() / 8)) return SIZE_MAX;
    }
    const size_t raw_bits_coded = raw.bits();
    const size_t coded = encoder.finish().size();
    if (level != nullptr) *kept = std::make_unique<AdaptiveLevelCode>(AdaptiveLevelCode{std::move(*level), std::move(raw), std::move(positions)});
    return side == nullptr ? coded : coded + varint_size(coded) + (raw_bits_coded + 7) / 8;
}

}  // namespace

bool AdaptiveTrialJudge::checkpoint(size_t done, size_t bytes) {
    // The level's bytes from those of its first `done` vertices at the rate since since_ pass
    // the limit by `margin` (the sample's second sixteenth, its second eighth, its second quarter,
    // then its second half, then each further sample's length: the models learn as they go).
    auto projected_past = [&](double margin) {
        const double rate = double(bytes - since_bytes_) / double(done - since_);
        return limit_ != SIZE_MAX &&
               double(bytes) + rounded(rate * double(count_ - done)) > rounded(margin * double(limit_)) + kSampleSlack;
    };
    bool stop = false;
    if (done == sample_ / 16) {
        next_ = sample_ / 8;
    } else if (done == sample_ / 8 || done == sample_ / 4) {
        // The first tests' rates come from few committed bytes: a level that codes to almost
        // nothing (exact midpoints, 1-3 bytes per sixteenth) would project from its next byte.
        stop = bytes - since_bytes_ >= kMinRateBytes && projected_past(kEarlyMargin);
        next_ = done == sample_ / 8 ? sample_ / 4 : sample_ / 2;
    } else if (done == sample_ / 2) {
        stop = projected_past(kEarlyMargin);
        next_ = sample_;
    } else {
        stop = projected_past(kSampleMargin);
        next_ = done + sample_;
    }
    since_ = done;
    since_bytes_ = bytes;
    return stop;
}

template <class Mesh>
LevelGeometryCode choose_level_geometry(const Mesh& h, const NewVertices& created, const PositionCoder& positions,
                                        CoordinateSpace space, GeometryPredictor choice, bool grid_contexts, bool unit_normals,
                                        int effort, StaticOrder grid_order, StaticEncoderBuffers* buffers,
                                        const ArithmeticEncoder* level_code) {
    const bool automatic = choice == GeometryPredictor::automatic;
    LevelGeometryCode code;
    code.predictor = automatic ? GeometryPredictor::midpoint : choice;
    if (code.predictor == GeometryPredictor::normal_frame_grid && space.quantizer == nullptr)
        throw Error("geometry mode 4 (normal_frame_grid) needs quantized coordinates");
    if (!automatic || created.empty()) {
        if (is_static_mode(code.predictor))
            code.static_code = std::make_unique<StaticLevelEncoder>(h, created, space, code.predictor, true, grid_order, buffers);
        return code;
    }
    // The first of the smallest in the order midpoint, butterfly, normal frame, grid, unit frame,
    // static midpoint, static butterfly, as if every mode were coded to its end. The static modes
    // come first, each coded only when its lower bound leaves it a chance (smallest bound first), so
    // that an adaptive trial stops as soon as its code so far shows it can not be the smallest.
    const size_t sample = effort >= kMaxGeometryEffort || created.size() / kSampleShare < kMinSample ? SIZE_MAX : created.size() / kSampleShare;
    const bool exact = space.quantizer == nullptr;
    bool candidate[kStaticCandidates] = {true, grid_contexts && !exact, unit_normals && exact, exact, exact};
    std::unique_ptr<StaticLevelEncoder> on_sample[kStaticCandidates];
    if (sample != SIZE_MAX) keep_likely_static_modes(h, created, space, sample, candidate, on_sample, grid_order, buffers);
    std::unique_ptr<StaticLevelEncoder> statics[kStaticCandidates];  // in the order of the choice
    size_t static_size[kStaticCandidates], bound[kStaticCandidates];
    for (int i = 0; i < kStaticCandidates; ++i) {
        static_size[i] = bound[i] = SIZE_MAX;
        if (!candidate[i]) continue;
        if (on_sample[i] == nullptr) {
            statics[i] = std::make_unique<StaticLevelEncoder>(h, created, space, kStaticModes[i], false, grid_order, buffers);
        } else {
            on_sample[i]->extend(h, created);
            statics[i] = std::move(on_sample[i]);
        }
        bound[i] = statics[i]->lower_bound_bytes();
    }
    size_t best_static = SIZE_MAX;
    int first_best = kStaticCandidates;  // the first mode of size best_static
    for (int tries = 0; tries < kStaticCandidates; ++tries) {
        int next = -1;  // the untried mode of smallest bound
        for (int i = 0; i < kStaticCandidates; ++i)
            if (statics[i] != nullptr && static_size[i] == SIZE_MAX && bound[i] != SIZE_MAX && (next < 0 || bound[i] < bound[next]))
                next = i;
        if (next < 0 || bound[next] > best_static) break;  // larger than a size known: never the smallest
        // At best a tie with an earlier mode, which the choice keeps (exact-midpoint levels: modes
        // 3, 5 and 6 code the same zero tokens to their bound): not coded.
        const bool never_chosen = bound[next] == best_static && next > first_best;
        if (!never_chosen) {
            statics[next]->code_streams();
            static_size[next] = statics[next]->estimated_bytes();
            if (static_size[next] < best_static || (static_size[next] == best_static && next < first_best)) first_best = next;
            best_static = std::min(best_static, static_size[next]);
        }
        bound[next] = SIZE_MAX;
    }
    const bool count_raw_bits = exact;
    // The smallest static mode (the first of the smallest), and the size an adaptive predictor must
    // stay below to beat it: a stencil mode's size shrunk by kStencilPreference.
    int chosen = -1;
    for (int i = 0; i < kStaticCandidates; ++i)
        if (static_size[i] != SIZE_MAX && (chosen < 0 || static_size[i] < static_size[chosen])) chosen = i;
    const size_t to_beat = chosen < 0 ? SIZE_MAX
                           : has_stencil_tables(kStaticModes[chosen])
                               ? size_t(double(static_size[chosen]) / kStencilPreference)
                               : static_size[chosen];
    // Effort 0 takes a static mode for a sampled level without trying the adaptive predictors.
    const bool adaptive_trials = effort > 0 || sample == SIZE_MAX || best_static == SIZE_MAX;
    std::unique_ptr<AdaptiveLevelCode> midpoint_code, butterfly_code;
    const size_t midpoint = adaptive_trials ? adaptive_bytes(h, created, GeometryPredictor::midpoint, positions, to_beat, count_raw_bits,
                                                             sample, level_code, &midpoint_code)
                                            : SIZE_MAX;
    // The butterfly must be smaller than the midpoint, and than what beats the static mode.
    const size_t butterfly_limit = midpoint == SIZE_MAX ? to_beat : std::min(midpoint - 1, to_beat);
    const size_t butterfly = adaptive_trials ? adaptive_bytes(h, created, GeometryPredictor::butterfly, positions, butterfly_limit,
                                                              count_raw_bits, sample, level_code, &butterfly_code)
                                             : SIZE_MAX;
    size_t best = midpoint;
    code.adaptive_code = std::move(midpoint_code);
    if (butterfly < best) {
        best = butterfly;
        code.predictor = GeometryPredictor::butterfly;
        code.adaptive_code = std::move(butterfly_code);
    }
    // Ties go to the earlier mode: the adaptive ones.
    const bool static_wins = chosen >= 0 && (has_stencil_tables(kStaticModes[chosen])
                                                 ? double(static_size[chosen]) < rounded(double(best) * kStencilPreference)
                                                 : static_size[chosen] < best);
    if (static_wins) {
        code.predictor = kStaticModes[chosen];
        code.static_code = std::move(statics[chosen]);
        code.adaptive_code.reset();
    }
    return code;
}

void check_effort(int effort, const std::string& what) {
    AMC_REQUIRE(effort >= 0 && effort <= kMaxEffort, invalid_input,
                what + ": effort " + std::to_string(effort) + " is not in 0.." + std::to_string(kMaxEffort));
}

template <class Mesh>
std::vector<uint8_t> finish_level_payload(const Mesh& h, const NewVertices& created, LevelGeometryCode& code,
                                          PositionCoder& positions, ArithmeticEncoder& encoder) {
    std::vector<uint8_t> payload{uint8_t(code.predictor)};
    if (is_static_mode(code.predictor)) {
        const StaticLevelEncoder& static_code = *code.static_code;
        static_code.write_tables(encoder);
        const std::vector<uint8_t> coded = encoder.finish();
        put_varint(payload, coded.size());
        payload.insert(payload.end(), coded.begin(), coded.end());
        put_varint(payload, static_code.rans_bytes().size());
        payload.insert(payload.end(), static_code.rans_bytes().begin(), static_code.rans_bytes().end());
        payload.insert(payload.end(), static_code.raw_bytes().begin(), static_code.raw_bytes().end());
        return payload;
    }
    if (positions.quantized() || created.empty()) {  // no raw bits: the layout of every version
        if (code.adaptive_code != nullptr) {
            encoder = std::move(code.adaptive_code->level);
            positions = std::move(code.adaptive_code->positions);
            code.adaptive_code.reset();
        } else {
            encode_adaptive(h, created, code.predictor, positions, encoder, nullptr);
        }
        const std::vector<uint8_t> coded = encoder.finish();
        payload.insert(payload.end(), coded.begin(), coded.end());
        return payload;
    }
    // Bit-exact (version 14): the flag, the arithmetic part's length, the arithmetic part, the raw bits.
    payload[0] |= kRawSideFlag;
    RawBitWriter raw;
    if (code.adaptive_code != nullptr) {
        raw = std::move(code.adaptive_code->raw);
        encoder = std::move(code.adaptive_code->level);
        positions = std::move(code.adaptive_code->positions);
        code.adaptive_code.reset();
    } else {
        encode_adaptive(h, created, code.predictor, positions, encoder, &raw);
    }
    const std::vector<uint8_t> side = RawSideCode{encoder.finish(), raw.finish()}.joined();
    payload.insert(payload.end(), side.begin(), side.end());
    return payload;
}

template LevelGeometryCode choose_level_geometry(const Hierarchy&, const NewVertices&, const PositionCoder&, CoordinateSpace,
                                                 GeometryPredictor, bool, bool, int, StaticOrder, StaticEncoderBuffers*,
                                                 const ArithmeticEncoder*);
template LevelGeometryCode choose_level_geometry(const HierarchyOnGrid&, const NewVertices&, const PositionCoder&,
                                                 CoordinateSpace, GeometryPredictor, bool, bool, int, StaticOrder, StaticEncoderBuffers*,
                                                 const ArithmeticEncoder*);
template std::vector<uint8_t> finish_level_payload(const Hierarchy&, const NewVertices&, LevelGeometryCode&,
                                                   PositionCoder&, ArithmeticEncoder&);
template std::vector<uint8_t> finish_level_payload(const HierarchyOnGrid&, const NewVertices&, LevelGeometryCode&,
                                                   PositionCoder&, ArithmeticEncoder&);

LevelBlockParts split_level_block(const Block& block, uint8_t file_version, bool quantized, bool mixed,
                                  const std::string& where) {
    AMC_REQUIRE(block.size >= 1, corrupt, "level block: bad predictor");
    LevelBlockParts parts;
    parts.raw_side = (block.payload[0] & kRawSideFlag) != 0;
    const uint8_t predictor = block.payload[0] & uint8_t(~kRawSideFlag);
    AMC_REQUIRE(predictor_allowed(predictor, file_version, quantized) &&
                    (!parts.raw_side || (file_version >= kRawSideVersion && !quantized && !is_static_mode(GeometryPredictor(predictor)))),
                corrupt, "level block: bad predictor");
    parts.predictor = GeometryPredictor(predictor);
    parts.order = grouped_grid_order(file_version, mixed) ? StaticOrder::grouped : StaticOrder::per_vertex;
    // A static mode's tables and a version-14 level's raw bits follow a length-prefixed arithmetic part.
    const RawSideParts split = is_static_mode(parts.predictor) || parts.raw_side
                                   ? split_raw_side(block.payload + 1, block.size - 1, where, "level block")
                                   : RawSideParts{block.payload + 1, block.size - 1, block.payload + block.size, 0};
    parts.arithmetic = split.arithmetic;
    parts.arithmetic_size = split.arithmetic_size;
    parts.after_arithmetic = split.raw;
    parts.after_arithmetic_size = split.raw_size;
    return parts;
}

namespace {

// A static mode's tables and streams; `decode(tables, rans, rans_size, raw, raw_size)` decodes the
// positions from them (decode_static_positions).
template <class Decode>
void decode_static_level(const LevelBlockParts& parts, ArithmeticDecoder& decoder, CoordinateSpace space,
                         const std::string& where, Decode&& decode) {
    StaticTables tables;
    AMC_REQUIRE(read_static_tables(decoder, space, parts.predictor, tables) && !decoder.overran(), corrupt,
                where + ": bad geometry tables");
    PayloadReader in(parts.after_arithmetic, parts.after_arithmetic_size, "level block");
    const uint64_t rans_size = in.varint();
    AMC_REQUIRE(rans_size <= in.remaining(), corrupt, where + ": rANS stream is longer than the block");
    const uint8_t* rans = in.rest();
    const uint8_t* raw = rans + rans_size;
    const size_t raw_size = in.remaining() - size_t(rans_size);
    AMC_REQUIRE(decode(tables, rans, size_t(rans_size), raw, raw_size), corrupt, where + " is truncated or corrupt (positions)");
    AMC_REQUIRE(!decoder.overran(), corrupt, where + " is truncated or corrupt");
}

}  // namespace

void decode_listed_level_geometry(Hierarchy& h, NewVertexCorners corners, const LevelBlockParts& parts,
                                  ArithmeticDecoder& decoder, CoordinateSpace space, const std::string& where) {
    AMC_REQUIRE(is_static_mode(parts.predictor), invalid_input, where + ": listed corners need a static geometry mode");
    decode_static_level(parts, decoder, space, where,
                        [&](const StaticTables& tables, const uint8_t* rans, size_t rans_size, const uint8_t* raw, size_t raw_size) {
                            return decode_static_positions(h, corners, space, parts.predictor, tables, rans, rans_size,
                                                           raw, raw_size, parts.order);
                        });
}

namespace {

// The arithmetic-coded modes (midpoint, butterfly) over each (node, edge) that for_each visits.
template <class ForEach>
void decode_arithmetic_level(Hierarchy& h, ForEach&& for_each, const LevelBlockParts& parts, ArithmeticDecoder& decoder,
                             PositionCoder& positions, int level, const std::string& where) {
    RawBitReader raw(parts.after_arithmetic, parts.after_arithmetic_size);
    RawBitReader* side = parts.raw_side ? &raw : nullptr;
    for_each([&](NodeId n, int e) {
        const Vec3 p = positions.decode(decoder, level_context(h.level(n)), predict(h, parts.predictor, n, e), side);
        AMC_REQUIRE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z), corrupt,
                    "level " + std::to_string(level) + " geometry is corrupt (non-finite coordinate)");
        h.set_position(h.midpoint(n, e), p);
    });
    AMC_REQUIRE(!positions.saw_invalid_symbol(), corrupt, where + " is truncated or corrupt");
    AMC_REQUIRE(!decoder.overran(), corrupt, where + " is truncated or corrupt");
    AMC_REQUIRE(side == nullptr || raw.ended_cleanly(), corrupt, where + ": raw bits are truncated or left over");
}

}  // namespace

void decode_level_geometry(Hierarchy& h, const NewVertices& created, const LevelBlockParts& parts, ArithmeticDecoder& decoder,
                           PositionCoder& positions, CoordinateSpace space, int level, const std::string& where) {
    if (is_static_mode(parts.predictor)) {
        decode_static_level(parts, decoder, space, where,
                            [&](const StaticTables& tables, const uint8_t* rans, size_t rans_size, const uint8_t* raw, size_t raw_size) {
                                return decode_static_positions(h, created, space, parts.predictor, tables, rans, rans_size,
                                                               raw, raw_size, parts.order);
                            });
        return;
    }
    auto for_each = [&](auto&& visit) {
        for (auto [n, e] : created) visit(n, e);
    };
    decode_arithmetic_level(h, for_each, parts, decoder, positions, level, where);
}

void decode_walked_level_geometry(Hierarchy& h, const NewVertexEdges& edges, const LevelBlockParts& parts,
                                  ArithmeticDecoder& decoder, PositionCoder& positions, int level, const std::string& where) {
    AMC_REQUIRE(!is_static_mode(parts.predictor), invalid_input, where + ": walked edges need a mode without tables");
    NewVertexEdges walk = edges;
    auto for_each = [&](auto&& visit) {
        std::pair<NodeId, int> run[64];
        for (size_t k; (k = walk.take(run, 64)) > 0;)
            for (size_t i = 0; i < k; ++i) visit(run[i].first, run[i].second);
    };
    decode_arithmetic_level(h, for_each, parts, decoder, positions, level, where);
}

}  // namespace amc
