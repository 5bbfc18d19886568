// Tests of the coordinate residual coder (float_coder.h) and of the geometry predictions
// (geometry_prediction.h): bit-exact round trips, code sizes, quantization, corrupt streams.
#include "coding/geometry/float_coder.h"
#include "coding/geometry/geometry_prediction.h"

#include <gtest/gtest.h>

#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "amc/hierarchy.h"
#include "amc/refinement.h"

namespace amc {
namespace {

uint64_t bits_of(double x) {
    uint64_t b;
    std::memcpy(&b, &x, sizeof b);
    return b;
}
double double_of(uint64_t b) {
    double x;
    std::memcpy(&x, &b, sizeof x);
    return x;
}
double float_of(uint32_t b) {
    float f;
    std::memcpy(&f, &b, sizeof f);
    return static_cast<double>(f);
}

struct Sample {
    double actual, predicted;
    int context;
};

std::vector<uint8_t> encode_samples(const std::vector<Sample>& samples, Precision precision,
                                    int contexts) {
    FloatResidualModels models(contexts);
    ArithmeticEncoder encoder;
    for (const Sample& s : samples) {
        encode_coordinate(encoder, models, s.context, precision, s.actual, s.predicted);
    }
    return encoder.finish();
}

void expect_round_trip(const std::vector<Sample>& samples, Precision precision, int contexts) {
    const std::vector<uint8_t> bytes = encode_samples(samples, precision, contexts);
    FloatResidualModels models(contexts);
    ArithmeticDecoder decoder(bytes.data(), bytes.size());
    for (size_t i = 0; i < samples.size(); ++i) {
        const double x = decode_coordinate(decoder, models, samples[i].context, precision,
                                           samples[i].predicted);
        ASSERT_EQ(bits_of(x), bits_of(samples[i].actual))
            << "sample " << i << ": " << samples[i].actual << " predicted " << samples[i].predicted;
    }
    EXPECT_FALSE(decoder.overran());
    EXPECT_FALSE(models.saw_invalid_symbol());
}

// Special doubles and random bit patterns (finite), plus near values.
std::vector<double> interesting_doubles(std::mt19937_64& rng, size_t random_count) {
    std::vector<double> v = {0.0,
                             -0.0,
                             1.0,
                             -1.0,
                             DBL_MAX,
                             -DBL_MAX,
                             DBL_MIN,
                             -DBL_MIN,
                             std::numeric_limits<double>::denorm_min(),
                             -std::numeric_limits<double>::denorm_min(),
                             double_of(0x000FFFFFFFFFFFFFull),
                             double_of(0x800FFFFFFFFFFFFFull),
                             1e-300,
                             1e300,
                             0.1,
                             -0.3,
                             3.0e38};
    while (v.size() < random_count) {
        const double x = double_of(rng());
        if (std::isfinite(x)) v.push_back(x);
    }
    return v;
}

TEST(OrderedBits, MonotoneAndInvertible) {
    std::mt19937_64 rng(1);
    std::vector<double> v = interesting_doubles(rng, 2000);
    for (double x : v) {
        EXPECT_EQ(bits_of(from_ordered_bits(ordered_bits(x, Precision::float64), Precision::float64)),
                  bits_of(x));
    }
    for (size_t i = 0; i + 1 < v.size(); ++i) {
        const double a = v[i], b = v[i + 1];
        if (a < b) {
            EXPECT_LT(ordered_bits(a, Precision::float64), ordered_bits(b, Precision::float64));
        } else if (a > b) {
            EXPECT_GT(ordered_bits(a, Precision::float64), ordered_bits(b, Precision::float64));
        }
    }
    EXPECT_LT(ordered_bits(-0.0, Precision::float64), ordered_bits(0.0, Precision::float64));
    EXPECT_EQ(ordered_bits(-0.0, Precision::float32) + 1, ordered_bits(0.0, Precision::float32));
    EXPECT_LT(ordered_bits(-1.0f, Precision::float32), uint64_t{1} << 31);
    EXPECT_LT(ordered_bits(FLT_MAX, Precision::float32), uint64_t{1} << 32);
}

TEST(FloatCoder, DoubleRoundTripRandomPredictions) {
    std::mt19937_64 rng(7);
    const std::vector<double> values = interesting_doubles(rng, 4000);
    std::vector<Sample> samples;
    std::uniform_int_distribution<int> ctx(0, 5);
    for (size_t i = 0; i < values.size(); ++i) {
        const double x = values[i];
        samples.push_back({x, x, ctx(rng)});                                    // exact
        samples.push_back({x, values[(i * 7919) % values.size()], ctx(rng)});   // far
        samples.push_back({x, std::nextafter(x, 0.0), ctx(rng)});               // one ulp
        samples.push_back({x, x * (1 + 1e-9), ctx(rng)});                       // close
        samples.push_back({x, -x, ctx(rng)});                                   // sign flipped
    }
    // Extremes against each other: the residual wraps modulo 2^64.
    samples.push_back({DBL_MAX, -DBL_MAX, 0});
    samples.push_back({-DBL_MAX, DBL_MAX, 0});
    samples.push_back({-0.0, 0.0, 1});
    samples.push_back({0.0, -0.0, 1});
    samples.push_back({1.0, std::numeric_limits<double>::infinity(), 2});   // prediction -> 0
    samples.push_back({1.0, std::numeric_limits<double>::quiet_NaN(), 2});  // prediction -> 0
    expect_round_trip(samples, Precision::float64, 6);
}

TEST(FloatCoder, FloatRoundTripRandomPredictions) {
    std::mt19937 rng(11);
    std::vector<double> values = {0.0, -0.0, FLT_MAX, -FLT_MAX, FLT_MIN, -FLT_MIN,
                                  float_of(1), float_of(0x80000001u), float_of(0x007FFFFFu), 1.0, -2.5};
    while (values.size() < 4000) {
        const double x = float_of(rng());
        if (std::isfinite(x)) values.push_back(x);
    }
    std::vector<Sample> samples;
    for (size_t i = 0; i < values.size(); ++i) {
        const double x = values[i];
        samples.push_back({x, x, 0});
        samples.push_back({x, values[(i * 7919) % values.size()], 1});
        samples.push_back({x, x + 1e-12 * x, 2});  // rounds back to x's float
        samples.push_back({x, -x, 0});
        samples.push_back({x, 1e300, 1});          // clamped to FLT_MAX
        samples.push_back({x, -1e-300, 2});        // rounds to -0.0f
    }
    samples.push_back({FLT_MAX, -FLT_MAX, 0});
    samples.push_back({-FLT_MAX, FLT_MAX, 0});
    expect_round_trip(samples, Precision::float32, 3);
}

TEST(FloatCoder, Float32RejectsNonFloatValues) {
    FloatResidualModels models(1);
    ArithmeticEncoder encoder;
    EXPECT_THROW(encode_coordinate(encoder, models, 0, Precision::float32, 0.1, 0.0), Error);
    EXPECT_THROW(encode_coordinate(encoder, models, 0, Precision::float32, 1e300, 0.0), Error);
    EXPECT_THROW(encode_coordinate(encoder, models, 1, Precision::float64, 0.1, 0.0), Error);
    EXPECT_THROW(FloatResidualModels(0), Error);
}

TEST(FloatCoder, ZeroResidualsAreNearlyFree) {
    for (Precision precision : {Precision::float64, Precision::float32}) {
        std::mt19937 rng(3);
        std::uniform_real_distribution<double> u(-10.0, 10.0);
        std::vector<Sample> samples;
        for (int i = 0; i < 30000; ++i) {
            const double x = double(float(u(rng)));
            samples.push_back({x, x, i % 3});
        }
        const std::vector<uint8_t> bytes = encode_samples(samples, precision, 3);
        const double bits_per_coordinate = 8.0 * double(bytes.size()) / double(samples.size());
        std::printf("[ measured ] residual 0, %s: %.4f bits/coordinate\n",
                    precision == Precision::float32 ? "float32" : "float64", bits_per_coordinate);
        EXPECT_LT(bits_per_coordinate, 0.05);
        expect_round_trip(samples, precision, 3);
    }
}

TEST(FloatCoder, SmallResidualsCostTheirBits) {
    // Predictions off by a few ulps: about log2 of the spread plus the length symbol.
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> u(1.0, 2.0);
    std::uniform_int_distribution<int> off(-100, 100);
    std::vector<Sample> samples;
    for (int i = 0; i < 20000; ++i) {
        const double x = u(rng);
        samples.push_back({x, double_of(bits_of(x) + uint64_t(int64_t(off(rng)))), 0});
    }
    const std::vector<uint8_t> bytes = encode_samples(samples, Precision::float64, 1);
    const double bits_per_coordinate = 8.0 * double(bytes.size()) / double(samples.size());
    std::printf("[ measured ] residual uniform in [-100, 100] ulp: %.3f bits/coordinate "
                "(entropy %.3f)\n", bits_per_coordinate, std::log2(201.0));
    EXPECT_LT(bits_per_coordinate, std::log2(201.0) + 0.6);
    expect_round_trip(samples, Precision::float64, 1);
}

// ---- corrupt and truncated streams ------------------------------------------------------------

TEST(FloatCoder, CorruptStreamsTerminate) {
    std::mt19937_64 rng(9);
    const std::vector<double> values = interesting_doubles(rng, 3000);
    std::vector<Sample> samples;
    for (size_t i = 0; i < values.size(); ++i) samples.push_back({values[i], values[i] * 0.5, int(i % 3)});
    for (Precision precision : {Precision::float64, Precision::float32}) {
        std::vector<Sample> s = samples;
        if (precision == Precision::float32) {
            for (Sample& x : s) x.actual = coder_prediction(x.actual, Precision::float32);
        }
        const std::vector<uint8_t> bytes = encode_samples(s, precision, 3);
        // Truncations: must not crash; short prefixes must be reported as overrun.
        for (size_t len : {size_t{0}, size_t{1}, bytes.size() / 3, bytes.size() / 2, bytes.size() - 20}) {
            FloatResidualModels models(3);
            ArithmeticDecoder decoder(bytes.data(), len);
            for (const Sample& x : s) (void)decode_coordinate(decoder, models, x.context, precision, x.predicted);
            EXPECT_TRUE(decoder.overran()) << len;
        }
        // Garbage bytes: anything may come out, nothing may crash; the quantized path too.
        for (int trial = 0; trial < 20; ++trial) {
            std::vector<uint8_t> garbage(bytes.size());
            for (uint8_t& b : garbage) b = static_cast<uint8_t>(rng());
            FloatResidualModels models(3);
            ArithmeticDecoder decoder(garbage.data(), garbage.size());
            for (const Sample& x : s) (void)decode_coordinate(decoder, models, x.context, precision, x.predicted);
            FloatResidualModels qmodels(1);
            for (int i = 0; i < 1000; ++i) {
                const uint32_t q = decode_quantized(decoder, qmodels, 0, 12, uint32_t(i));
                ASSERT_LT(q, 4096u);
            }
        }
    }
}

TEST(FloatCoder, ImpossibleBitLengthIsFlagged) {
    // All-zero bytes drive every modelled decision to 1 (a one takes the lower part of the
    // range): k = 63 > 32 for float32.
    std::vector<uint8_t> zeros(64, 0x00);
    FloatResidualModels models(1);
    ArithmeticDecoder decoder(zeros.data(), zeros.size());
    (void)decode_coordinate(decoder, models, 0, Precision::float32, 1.0);
    EXPECT_TRUE(models.saw_invalid_symbol());
}

// ---- quantized mode ---------------------------------------------------------------------------

TEST(Quantizer, RoundTripWithinHalfStep) {
    std::mt19937 rng(21);
    std::uniform_real_distribution<double> u(-3.0, 5.0);
    std::vector<Vec3> points(5000);
    for (Vec3& p : points) p = {u(rng), 0.25 * u(rng), 100.0 + u(rng)};
    for (int bits : {1, 8, 12, 16, 24, 30}) {
        const Quantizer quantizer = make_quantizer(points, bits);
        const double error = max_quantization_error(quantizer, points);
        EXPECT_LE(error, quantization_error_bound(quantizer)) << bits;
        EXPECT_LE(quantization_error_bound(quantizer), 0.5 * quantizer.step * (1 + 1e-6) + 1e-12);

        // Closed loop: predictions from reconstructed positions, quantized again.
        FloatResidualModels models(3);
        ArithmeticEncoder encoder;
        std::vector<GridPoint> grid;
        std::vector<Vec3> reconstructed;
        for (size_t i = 0; i < points.size(); ++i) {
            const GridPoint q = quantize(quantizer, points[i]);
            for (uint32_t c : q) ASSERT_LE(c, quantizer.max_coordinate());
            const GridPoint pred = quantize(quantizer, i == 0 ? Vec3{} : reconstructed.back());
            for (int a = 0; a < 3; ++a) encode_quantized(encoder, models, a, bits, q[size_t(a)], pred[size_t(a)]);
            grid.push_back(q);
            reconstructed.push_back(dequantize(quantizer, q));
        }
        const std::vector<uint8_t> bytes = encoder.finish();
        FloatResidualModels dmodels(3);
        ArithmeticDecoder decoder(bytes.data(), bytes.size());
        Vec3 last{};
        for (size_t i = 0; i < points.size(); ++i) {
            const GridPoint pred = quantize(quantizer, last);
            GridPoint q;
            for (int a = 0; a < 3; ++a) q[size_t(a)] = decode_quantized(decoder, dmodels, a, bits, pred[size_t(a)]);
            ASSERT_EQ(q, grid[i]) << "bits " << bits << " point " << i;
            last = dequantize(quantizer, q);
            ASSERT_EQ(last, reconstructed[i]);
        }
        EXPECT_FALSE(decoder.overran());
        EXPECT_FALSE(dmodels.saw_invalid_symbol());
    }
}

TEST(Quantizer, EdgeCases) {
    EXPECT_THROW(make_quantizer(Vec3{}, Vec3{1, 1, 1}, 0), Error);
    EXPECT_THROW(make_quantizer(Vec3{}, Vec3{1, 1, 1}, 31), Error);
    EXPECT_THROW(make_quantizer(Vec3{1, 0, 0}, Vec3{0, 1, 1}, 8), Error);
    EXPECT_THROW(make_quantizer(Vec3{-DBL_MAX, 0, 0}, Vec3{DBL_MAX, 0, 0}, 8), Error);
    const Quantizer flat = make_quantizer(Vec3{2, 2, 2}, Vec3{2, 2, 2}, 10);
    EXPECT_EQ(quantize(flat, Vec3{2, 2, 2}), (GridPoint{0, 0, 0}));
    const Quantizer q = make_quantizer(Vec3{0, 0, 0}, Vec3{1, 1, 1}, 4);
    EXPECT_EQ(quantize(q, Vec3{-5, 0.5, 7}), (GridPoint{0, 8, 15}));
    EXPECT_EQ(quantize_coordinate(q, 0, std::numeric_limits<double>::quiet_NaN()), 0u);
    ArithmeticEncoder encoder;
    FloatResidualModels models(1);
    EXPECT_THROW(encode_quantized(encoder, models, 0, 4, 16, 0), Error);
}

// GridSnap is snap_to_grid: quantize() on a grid whose every point is finite, snap_to_grid's
// steps down where the grid reaches past the largest double.
TEST(Quantizer, GridSnapIsSnapToGrid) {
    std::mt19937_64 rng(7);
    auto coordinate = [&] { return double(rng() % 2001) / 100.0 - 12.0; };
    const Quantizer q = make_quantizer(Vec3{-10, -3, 0.5}, Vec3{7, 4, 2}, 12);
    const GridSnap snap(q);
    for (int i = 0; i < 1000; ++i) {
        const Vec3 p{coordinate(), coordinate(), coordinate()};
        EXPECT_EQ(snap(p), snap_to_grid(q, p));
    }
    Quantizer far;  // its top reconstructs beyond DBL_MAX on x
    far.origin = {1.5e308, 0, 0};
    far.step = 1e306;
    far.bits = 8;
    const Vec3 p{DBL_MAX, 1e300, -1};
    EXPECT_NE(snap_to_grid(far, p), quantize(far, p));
    EXPECT_EQ(GridSnap(far)(p), snap_to_grid(far, p));
}

// ---- predictions over hierarchies ---------------------------------------------------------------

struct GeometryCost {
    double bits_per_coordinate = 0;
    size_t coordinates = 0;
};

enum class Predictor { midpoint, butterfly };

Vec3 predict(Predictor predictor, const Hierarchy& h, NodeId n, int e) {
    return predictor == Predictor::midpoint ? predict_midpoint(h, n, e) : predict_butterfly(h, n, e);
}

// Codes the refinement vertices level by level (context = axis), decodes them into a copy whose
// refinement positions are scrambled first, and checks the copy matches bit for bit.
GeometryCost code_refinement_vertices(const Hierarchy& h, Predictor predictor) {
    const Precision precision = h.single_precision() ? Precision::float32 : Precision::float64;
    const std::vector<std::vector<NodeId>> levels = nodes_by_level(h);
    FloatResidualModels models(3);
    ArithmeticEncoder encoder;
    size_t coordinates = 0;
    for (const std::vector<NodeId>& level : levels) {
        for (const auto& [n, e] : new_vertices_of_level(h, level)) {
            encode_position(encoder, models, 0, precision, h.position(h.midpoint(n, e)), predict(predictor, h, n, e));
            coordinates += 3;
        }
    }
    const std::vector<uint8_t> bytes = encoder.finish();

    Hierarchy decoded = h;
    for (VertexId v = static_cast<VertexId>(h.base().positions.size()); v < decoded.positions().size(); ++v) {
        decoded.set_position(v, Vec3{1e9, -1e9, 12345.0});
    }
    FloatResidualModels dmodels(3);
    ArithmeticDecoder decoder(bytes.data(), bytes.size());
    for (const std::vector<NodeId>& level : levels) {
        for (const auto& [n, e] : new_vertices_of_level(decoded, level)) {
            const Vec3 p = decode_position(decoder, dmodels, 0, precision, predict(predictor, decoded, n, e));
            decoded.set_position(decoded.midpoint(n, e), p);
        }
    }
    EXPECT_FALSE(decoder.overran());
    EXPECT_TRUE(identical(h, decoded));
    GeometryCost cost;
    cost.coordinates = coordinates;
    cost.bits_per_coordinate = coordinates ? 8.0 * double(bytes.size()) / double(coordinates) : 0.0;
    return cost;
}

TEST(GeometryPrediction, NewVerticesFollowCanonicalOrder) {
    for (uint64_t seed : {1u, 2u, 3u}) {
        Hierarchy h(make_l_shape(3));
        refine_randomly(h, 3000, 6, seed, 0.2);
        const std::vector<uint32_t> canonical = canonical_vertex_order(h);
        uint32_t next = static_cast<uint32_t>(h.base().positions.size());
        for (const std::vector<NodeId>& level : nodes_by_level(h)) {
            for (const auto& [n, e] : new_vertices_of_level(h, level)) {
                ASSERT_EQ(canonical[h.midpoint(n, e)], next) << "seed " << seed;
                ++next;
            }
        }
        EXPECT_EQ(next, h.vertex_count());
    }
}

TEST(GeometryPrediction, MidpointPredictsDefaultPlacementExactly) {
    Hierarchy uniform(make_torus(6, 8, 2.0, 0.7));
    refine_uniformly(uniform, 3);
    Hierarchy random(make_square(4));
    refine_randomly(random, 5000, 8, 42, 0.1);
    TriangleMesh single = make_icosahedron();
    for (Vec3& p : single.positions) p = {double(float(p.x)), double(float(p.y)), double(float(p.z))};
    single.single_precision = true;
    Hierarchy single_h(single);
    refine_randomly(single_h, 4000, 7, 5);
    for (const Hierarchy* h : {&uniform, &random, &single_h}) {
        const GeometryCost cost = code_refinement_vertices(*h, Predictor::midpoint);
        std::printf("[ measured ] midpoint positions, midpoint predictor: %.4f bits/coordinate over %zu\n",
                    cost.bits_per_coordinate, cost.coordinates);
        EXPECT_LT(cost.bits_per_coordinate, 0.1);
    }
}

// The hierarchy over the icosahedron with every vertex projected onto the unit sphere.
Hierarchy sphere_hierarchy(bool adaptive, bool single_precision) {
    TriangleMesh base = make_icosahedron();
    for (Vec3& p : base.positions) p = (1.0 / std::sqrt(dot(p, p))) * p;
    if (single_precision) {
        for (Vec3& p : base.positions) p = {double(float(p.x)), double(float(p.y)), double(float(p.z))};
        base.single_precision = true;
    }
    Hierarchy h(base);
    if (adaptive) refine_randomly(h, 6000, 7, 17);
    else refine_uniformly(h, 4);
    for (VertexId v = static_cast<VertexId>(base.positions.size()); v < h.positions().size(); ++v) {
        Vec3 p = h.position(v);
        p = (1.0 / std::sqrt(dot(p, p))) * p;
        if (single_precision) p = {double(float(p.x)), double(float(p.y)), double(float(p.z))};
        h.set_position(v, p);
    }
    return h;
}

TEST(GeometryPrediction, ButterflyBeatsMidpointOnTheSphere) {
    for (bool adaptive : {false, true}) {
        for (bool single : {false, true}) {
            const Hierarchy h = sphere_hierarchy(adaptive, single);
            const GeometryCost mid = code_refinement_vertices(h, Predictor::midpoint);
            const GeometryCost fly = code_refinement_vertices(h, Predictor::butterfly);
            std::printf("[ measured ] sphere (%s, %s): midpoint %.3f, butterfly %.3f bits/coordinate "
                        "over %zu\n", adaptive ? "adaptive" : "uniform", single ? "float32" : "float64",
                        mid.bits_per_coordinate, fly.bits_per_coordinate, mid.coordinates);
            EXPECT_LT(fly.bits_per_coordinate, mid.bits_per_coordinate - 1.0);
        }
    }
}

// A planar lattice: cells x cells squares of [0,1]^2, every square cut by the same diagonal.
TriangleMesh lattice(int cells) {
    TriangleMesh mesh;
    const double h = 1.0 / cells;
    for (int j = 0; j <= cells; ++j) {
        for (int i = 0; i <= cells; ++i) mesh.positions.push_back({i * h, j * h, 0.0});
    }
    const auto id = [&](int i, int j) { return uint32_t(j * (cells + 1) + i); };
    for (int j = 0; j < cells; ++j) {
        for (int i = 0; i < cells; ++i) {
            mesh.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
            mesh.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
        }
    }
    return mesh;
}

TEST(GeometryPrediction, ButterflyReproducesAffineAndQuadraticData) {
    // Affine invariance on an adaptive planar mesh: z = 0 is predicted exactly everywhere,
    // including at boundaries (reflected wings) and next to coarser regions.
    Hierarchy square(make_square(4));
    refine_randomly(square, 3000, 6, 8);
    for (const std::vector<NodeId>& level : nodes_by_level(square)) {
        for (const auto& [n, e] : new_vertices_of_level(square, level)) {
            EXPECT_EQ(predict_butterfly(square, n, e).z, 0.0);
        }
    }
    // On a regular lattice the full 8-point stencil reproduces quadratics: a height field
    // z = f(x, y) is predicted to rounding wherever all eight points exist.
    const auto f = [](double x, double y) { return 0.7 * x * x - 1.3 * x * y + 0.4 * y * y + 0.2 * x - y + 3.0; };
    Hierarchy h(lattice(6));
    refine_uniformly(h, 3);
    for (VertexId v = 0; v < h.positions().size(); ++v) {
        const Vec3 p = h.position(v);
        h.set_position(v, {p.x, p.y, f(p.x, p.y)});
    }
    int full_stencils = 0;
    for (const std::vector<NodeId>& level : nodes_by_level(h)) {
        for (const auto& [n, e] : new_vertices_of_level(h, level)) {
            const NodeId q = h.neighbor(n, e);
            if (q == kNoNode) continue;
            const int eq = h.neighbor_edge(n, e);
            if (h.neighbor(n, (e + 1) % 3) == kNoNode || h.neighbor(n, (e + 2) % 3) == kNoNode ||
                h.neighbor(q, (eq + 1) % 3) == kNoNode || h.neighbor(q, (eq + 2) % 3) == kNoNode) {
                continue;
            }
            const Vec3 p = predict_butterfly(h, n, e);
            const Vec3 m = h.position(h.midpoint(n, e));
            EXPECT_NEAR(p.x, m.x, 1e-14);
            EXPECT_NEAR(p.y, m.y, 1e-14);
            EXPECT_NEAR(p.z, m.z, 1e-13);
            ++full_stencils;
        }
    }
    EXPECT_GT(full_stencils, 1000);
}

#if AMC_SSE2
// The static decoders' two-lane frames (frame_pair_of) against frame_of, bit for bit, in both
// static normal sums: random corners over positions that include zeros of both signs, subnormals,
// values near overflow, infinities, NaN and repeated points (zero normals), d missing in a fifth.
TEST(GeometryPrediction, FramePairsEqualSingleFramesBitForBit) {
    std::mt19937_64 rng(29);
    Hierarchy h(make_l_shape(3));
    refine_randomly(h, 400, 4, 29, 0.2);
    std::vector<double> values = interesting_doubles(rng, 40);
    for (double x : {HUGE_VAL, -HUGE_VAL, std::nan("")}) values.push_back(x);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    const VertexId vertices = VertexId(h.positions().size());
    for (VertexId v = 0; v < vertices; ++v) {
        if (v % 3 == 0) {  // a few special coordinates among ordinary ones
            h.set_position(v, {values[rng() % values.size()], unit(rng), values[rng() % values.size()]});
        } else if (v % 3 == 1) {
            h.set_position(v, h.position(v / 2));  // repeated points
        } else {
            h.set_position(v, {unit(rng), unit(rng), unit(rng)});
        }
    }
    auto same = [](double x, double y) { return bits_of(x) == bits_of(y) || (std::isnan(x) && std::isnan(y)); };
    auto same_frame = [&](const NormalFrame& x, const NormalFrame& y) {
        return same(x.midpoint.x, y.midpoint.x) && same(x.midpoint.y, y.midpoint.y) && same(x.midpoint.z, y.midpoint.z) &&
               same(x.normal.x, y.normal.x) && same(x.normal.y, y.normal.y) && same(x.normal.z, y.normal.z) &&
               x.axis == y.axis && x.has_normal == y.has_normal;
    };
    auto corners = [&] {
        const VertexId d = rng() % 5 == 0 ? kNoVertex : VertexId(rng() % vertices);
        return FrameCorners{VertexId(rng() % vertices), VertexId(rng() % vertices), VertexId(rng() % vertices), d};
    };
    size_t with_normal = 0;
    for (int trial = 0; trial < 20000; ++trial) {
        const FrameCorners k0 = corners(), k1 = corners();
        NormalFrame p0, p1;
        frame_pair_of<true>(h, k0, k1, p0, p1);
        ASSERT_TRUE(same_frame(p0, frame_of<true>(h, k0)) && same_frame(p1, frame_of<true>(h, k1))) << "trial " << trial;
        frame_pair_of<false>(h, k0, k1, p0, p1);
        ASSERT_TRUE(same_frame(p0, frame_of<false>(h, k0)) && same_frame(p1, frame_of<false>(h, k1))) << "trial " << trial;
        with_normal += p0.has_normal;
    }
    EXPECT_GT(with_normal, 1000u);  // the cases above are not all degenerate
    EXPECT_LT(with_normal, 20000u);
}
#endif

TEST(GeometryPrediction, Parallelogram) {
    const std::vector<Vec3> decoded = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    EXPECT_EQ(predict_parallelogram(decoded, {0, 1, 2}), (Vec3{1, 1, -1}));
    EXPECT_EQ(predict_parallelogram(decoded, {2, -1, 0}), (Vec3{0, 0, 1}));
    EXPECT_EQ(predict_parallelogram(decoded, {1, 0, 7}), (Vec3{0, 1, 0}));
    EXPECT_EQ(predict_parallelogram(decoded, {-1, 0, 1}), (Vec3{}));
    EXPECT_EQ(predict_parallelogram({}, {0, 0, 0}), (Vec3{}));
}

}  // namespace
}  // namespace amc
