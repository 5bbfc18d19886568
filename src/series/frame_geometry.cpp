// Positions of a series frame; see frame_geometry.h and docs/FORMAT.md, section 7.6.
#include "series/frame_geometry.h"

#include "coding/geometry/float_coder.h"
#include "coding/geometry/geometry_prediction.h"
#include "common/bits.h"
#include "common/check.h"

#include <cmath>
#include <cstring>

namespace amc {

namespace {

constexpr uint8_t kMidpoint = 1, kButterfly = 2;
constexpr int kPersistingContext = 0;  // contexts 0-2: persisting vertices of a moving mesh
int new_vertex_context(int vertex_level) { return 3 * std::min(vertex_level, 16); }  // levels 1.. -> 3..48
constexpr int kGeometryContexts = 51;

Vec3 predict(const Hierarchy& h, uint8_t predictor, const FrameVertex& v) {
    return predictor == kButterfly ? predict_butterfly(h, v.node, v.edge) : predict_midpoint(h, v.node, v.edge);
}

double axis(Vec3 p, int a) { return a == 0 ? p.x : a == 1 ? p.y : p.z; }

// Bits a residual would take, roughly (its bit lengths): how the encoder picks a predictor.
uint64_t residual_bits(Vec3 actual, Vec3 predicted, Precision precision) {
    uint64_t bits = 0;
    for (int a = 0; a < 3; ++a) {
        const uint64_t d = ordered_bits(axis(actual, a), precision) -
                           ordered_bits(coder_prediction(axis(predicted, a), precision), precision);
        const uint64_t m = (d >> 63) ? ~d + 1 : d;
        bits += uint64_t(bit_length(precision == Precision::float32 ? uint32_t(m) : m)) + 1;
    }
    return bits;
}

bool same_bits(Vec3 a, Vec3 b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// The midpoint prediction as the decoder turns it into a position (a zero residual).
Vec3 midpoint_position(const Hierarchy& h, const FrameVertex& v, Precision precision) {
    const Vec3 p = predict_midpoint(h, v.node, v.edge);
    return {coder_prediction(p.x, precision), coder_prediction(p.y, precision), coder_prediction(p.z, precision)};
}

}  // namespace

std::vector<uint8_t> encode_frame_geometry(const Hierarchy& prev, const std::vector<FrameVertex>& order,
                                           const std::vector<Vec3>& positions, int version, Hierarchy& out,
                                           FrameGeometryMode* mode_out) {
    const Precision precision = out.single_precision() ? Precision::float32 : Precision::float64;
    AMC_REQUIRE(positions.size() == order.size(), invalid_input, "series frame: position count mismatch");
    FrameGeometryMode mode = FrameGeometryMode::static_mesh;
    for (size_t i = 0; i < order.size(); ++i) {
        out.set_position(order[i].id, positions[i]);
        if (order[i].previous != kNoVertex && !same_bits(prev.position(order[i].previous), positions[i]))
            mode = FrameGeometryMode::moving;
    }
    if (version >= 2 && mode == FrameGeometryMode::static_mesh) {
        bool at_midpoints = true;
        for (size_t i = 0; at_midpoints && i < order.size(); ++i)
            if (order[i].previous == kNoVertex && order[i].level > 0)
                at_midpoints = same_bits(positions[i], midpoint_position(out, order[i], precision));
        if (at_midpoints) {
            if (mode_out) *mode_out = FrameGeometryMode::at_midpoints;
            return {uint8_t(FrameGeometryMode::at_midpoints)};
        }
    }
    // Predictor per vertex level, from the final positions (predictions only read earlier vertices).
    const int levels = vertex_level_count(order);
    std::vector<uint64_t> cost[2] = {std::vector<uint64_t>(size_t(levels), 0), std::vector<uint64_t>(size_t(levels), 0)};
    for (const FrameVertex& v : order) {
        if (v.level == 0 || v.previous != kNoVertex) continue;
        const Vec3 p = out.position(v.id);
        cost[0][v.level] += residual_bits(p, predict(out, kMidpoint, v), precision);
        cost[1][v.level] += residual_bits(p, predict(out, kButterfly, v), precision);
    }
    std::vector<uint8_t> bytes{uint8_t(mode)};
    for (int l = 1; l < levels; ++l) bytes.push_back(cost[1][size_t(l)] < cost[0][size_t(l)] ? kButterfly : kMidpoint);

    FloatResidualModels models(kGeometryContexts);
    ArithmeticEncoder encoder;
    for (const FrameVertex& v : order) {
        if (v.previous != kNoVertex) {
            if (mode == FrameGeometryMode::moving)
                encode_position(encoder, models, kPersistingContext, precision, out.position(v.id),
                                prev.position(v.previous));
            continue;
        }
        encode_position(encoder, models, new_vertex_context(v.level), precision, out.position(v.id),
                        predict(out, bytes[v.level], v));
    }
    const std::vector<uint8_t> payload = encoder.finish();
    bytes.insert(bytes.end(), payload.begin(), payload.end());
    if (mode_out) *mode_out = mode;
    return bytes;
}

void decode_frame_geometry(const Hierarchy& prev, const std::vector<FrameVertex>& order, const uint8_t* data,
                           size_t size, int version, Hierarchy& out) {
    const Precision precision = out.single_precision() ? Precision::float32 : Precision::float64;
    AMC_REQUIRE(size >= 1, truncated, "geometry section: shorter than its header");
    if (version >= 2 && data[0] == uint8_t(FrameGeometryMode::at_midpoints)) {
        AMC_REQUIRE(size == 1, corrupt, "geometry section: bytes after mode 2");
        for (const FrameVertex& v : order) {
            const Vec3 p = v.previous != kNoVertex ? prev.position(v.previous) : midpoint_position(out, v, precision);
            AMC_REQUIRE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z), corrupt,
                        "geometry section: a non-finite coordinate");
            out.set_position(v.id, p);
        }
        return;
    }
    const int levels = vertex_level_count(order);
    AMC_REQUIRE(size >= size_t(levels), truncated, "geometry section: shorter than its header");
    AMC_REQUIRE(data[0] <= 1, corrupt, "geometry section: unknown mode " + std::to_string(data[0]));
    const FrameGeometryMode mode = FrameGeometryMode(data[0]);
    for (int l = 1; l < levels; ++l)
        AMC_REQUIRE(data[l] == kMidpoint || data[l] == kButterfly, corrupt,
                    "geometry section: unknown predictor " + std::to_string(data[l]) + " for level " +
                        std::to_string(l - 1));
    uint64_t coded = 0;
    for (const FrameVertex& v : order) coded += v.previous == kNoVertex || mode == FrameGeometryMode::moving;
    AMC_REQUIRE(coded <= max_decodable_positions(size - size_t(levels)), truncated,
                "geometry section: " + std::to_string(coded) + " positions can not fit in " +
                    std::to_string(size - size_t(levels)) + " bytes");
    FloatResidualModels models(kGeometryContexts);
    ArithmeticDecoder decoder(data + levels, size - size_t(levels));
    for (const FrameVertex& v : order) {
        Vec3 p;
        if (v.previous != kNoVertex) {
            p = prev.position(v.previous);
            if (mode == FrameGeometryMode::moving)
                p = decode_position(decoder, models, kPersistingContext, precision, p);
        } else {
            p = decode_position(decoder, models, new_vertex_context(v.level), precision, predict(out, data[v.level], v));
        }
        AMC_REQUIRE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z), corrupt,
                    "geometry section: a non-finite coordinate");
        out.set_position(v.id, p);
    }
    AMC_REQUIRE(!decoder.overran(), truncated, "geometry section: the payload ends early");
    AMC_REQUIRE(!models.saw_invalid_symbol(), corrupt, "geometry section: an invalid residual");
}

}  // namespace amc
