// Fields of a series frame; see field_coder.h and docs/FORMAT.md, section 7.7.
#include "series/field_coder.h"

#include "coding/field_words.h"
#include "coding/geometry/float_coder.h"
#include "common/bits.h"
#include "common/exact_float.h"
#include "common/check.h"

#include <amc/red_split.h>

#include <cmath>
#include <cstring>
#include <limits>

namespace amc {

namespace {

constexpr uint8_t kSpatial = 1, kTemporal = 2, kHybrid = 3;
constexpr uint8_t kExact = 0, kBounded = 1;
constexpr int kFieldContexts = 32;
int value_context(int level, uint32_t component) { return std::min(level, 7) * 4 + int(std::min<uint32_t>(component, 3)); }

// The grid of an error-bounded field: value q * step, step = 2 * bound.
constexpr double kGridLimit = 4611686018427387904.0;  // 2^62: |q| stays far from int64's ends
bool on_grid(double x, double step) { return std::isfinite(x) && std::fabs(x / step) < kGridLimit; }
int64_t grid_index(double x, double step) { return on_grid(x, step) ? std::llround(x / step) : 0; }
double grid_value(int64_t q, double step, FieldType type) {
    const double x = rounded(double(q) * step);
    return type == FieldType::float32 ? rounded_to_float(x) : x;
}

// ---- value domains: what predictions are computed in and residuals taken of ----------------

struct IntegerDomain {  // integer fields, and float fields on a grid (grid indices)
    using V = int64_t;
    bool grid = false;
    double step = 1;
    static V zero() { return 0; }
    static V mean(V a, V b) { return (a & b) + ((a ^ b) >> 1); }  // floor((a + b) / 2), no overflow
    static V hybrid(V t, V now, V before) { return V(uint64_t(t) + (uint64_t(now) - uint64_t(before))); }
    V from_prev(const Field& ref, size_t k) const { return grid ? grid_index(ref.values[k], step) : ref.integers[k]; }
    static void residual(V actual, V predicted, bool& negative, uint64_t& magnitude) {
        const uint64_t d = uint64_t(actual) - uint64_t(predicted);
        negative = d >> 63;
        magnitude = negative ? ~d + 1 : d;
    }
    static V apply(V predicted, bool negative, uint64_t magnitude) {
        return V(negative ? uint64_t(predicted) - magnitude : uint64_t(predicted) + magnitude);
    }
};

struct FloatDomain {  // bit-exact float fields: ordered-bit differences (FORMAT.md 5.3)
    using V = double;
    Precision precision = Precision::float64;
    static V zero() { return 0.0; }
    static V mean(V a, V b) { return rounded(0.5 * (a + b)); }
    static V hybrid(V t, V now, V before) { return t + (now - before); }
    V from_prev(const Field& ref, size_t k) const { return ref.values[k]; }
    int width() const { return precision == Precision::float32 ? 32 : 64; }
    void residual(V actual, V predicted, bool& negative, uint64_t& magnitude) const {
        const uint64_t mask = width() == 32 ? 0xFFFFFFFFull : ~0ull;
        const uint64_t d = (ordered_bits(actual, precision) - ordered_bits(coder_prediction(predicted, precision), precision)) & mask;
        negative = (d >> (width() - 1)) & 1;
        magnitude = negative ? ((~d + 1) & mask) : d;
    }
    V apply(V predicted, bool negative, uint64_t magnitude) const {
        const uint64_t p = ordered_bits(coder_prediction(predicted, precision), precision);
        return from_ordered_bits(negative ? p - magnitude : p + magnitude, precision);
    }
};

// The previous frame's field a field is predicted from: same name, association, type, components.
const Field* find_reference(const FrameState& prev, const Field& f) {
    for (const Field& r : prev.fields)
        if (r.name == f.name && r.association == f.association && r.type == f.type && r.components == f.components)
            return &r;
    return nullptr;
}

// The previous frame's cell a cell of the next frame is predicted from (FORMAT.md 7.7).
std::vector<uint32_t> previous_cells(const FieldFrame& f) {
    const Hierarchy& h = f.next.h;
    const Hierarchy& p = f.prev.h;
    std::vector<uint32_t> out(f.cell_node.size(), 0);
    for (size_t j = 0; j < out.size(); ++j) {
        const NodeId n = f.cell_node[j];
        const uint32_t k = uint32_t(j) - f.next.first_cell[n];
        NodeId q = f.cp[n];
        if (q == kNoNode) {  // a new node: the previous leaf that covered it
            NodeId m = n;
            while (f.cp[m] == kNoNode) m = h.parent(m);
            out[j] = f.prev.first_cell[f.cp[m]];
        } else if (!p.is_leaf(q)) {  // coarsened: the centre leaf below it
            while (!p.is_leaf(q)) q = p.child(q, red_split::kCenter);
            out[j] = f.prev.first_cell[q];
        } else {
            const uint32_t cells = 1 + uint32_t(p.hanging_node_count(q));
            out[j] = f.prev.first_cell[q] + (f.prev.closure[q] == f.next.closure[n] ? k : std::min(k, cells - 1));
        }
    }
    return out;
}

template <class D>
struct Predictions {
    const FieldFrame& f;
    const Field* ref;
    FieldAssociation association;
    uint32_t comps;
    const D& d;
    const std::vector<uint32_t>& prev_cell;
    using V = typename D::V;

    int level(size_t tuple) const {
        return association == FieldAssociation::point ? f.order[tuple].level : f.next.h.level(f.cell_node[tuple]);
    }
    V prev_point(VertexId pv, uint32_t c) const { return d.from_prev(*ref, size_t(f.prev.canonical[pv]) * comps + c); }
    V operator()(uint8_t predictor, size_t i, uint32_t c, const std::vector<V>& cur) const {
        if (association == FieldAssociation::cell) {
            if (predictor == kSpatial) return i > 0 ? cur[(i - 1) * comps + c] : D::zero();
            return d.from_prev(*ref, size_t(prev_cell[i]) * comps + c);
        }
        const FrameVertex& v = f.order[i];
        V spatial;
        if (v.level == 0) {
            spatial = i > 0 ? cur[(i - 1) * comps + c] : D::zero();
        } else {
            const Hierarchy& h = f.next.h;
            const size_t a = f.index_of_vertex[h.vertex(v.node, v.edge)];
            const size_t b = f.index_of_vertex[h.vertex(v.node, (v.edge + 1) % 3)];
            spatial = D::mean(cur[a * comps + c], cur[b * comps + c]);
        }
        if (predictor == kSpatial || v.previous == kNoVertex) return spatial;
        const V t = prev_point(v.previous, c);
        if (predictor == kTemporal) return t;
        if (v.level == 0) return i > 0 ? D::hybrid(t, cur[(i - 1) * comps + c], prev_point(VertexId(i - 1), c)) : t;
        const Hierarchy& p = f.prev.h;
        const NodeId q = f.cp[v.node];
        const V before = D::mean(prev_point(p.vertex(q, v.edge), c), prev_point(p.vertex(q, (v.edge + 1) % 3), c));
        return D::hybrid(t, spatial, before);
    }
};

uint8_t max_predictor(const Field* ref, FieldAssociation a) {
    return ref == nullptr ? kSpatial : a == FieldAssociation::point ? kHybrid : kTemporal;
}

// Chooses a predictor per level (fewest residual bits, ties to the lower number) and codes the
// values; `w` holds the values in the domain.
template <class D>
std::vector<uint8_t> encode_values(const Predictions<D>& predict, const std::vector<typename D::V>& w, size_t tuples,
                                   int levels, uint8_t allowed, std::vector<uint8_t>& predictors) {
    const uint32_t comps = predict.comps;
    std::vector<std::array<uint64_t, 4>> cost(size_t(levels), {0, 0, 0, 0});
    for (size_t i = 0; i < tuples; ++i)
        for (uint32_t c = 0; c < comps; ++c)
            for (uint8_t p = kSpatial; p <= allowed; ++p) {
                bool negative;
                uint64_t magnitude;
                predict.d.residual(w[i * comps + c], predict(p, i, c, w), negative, magnitude);
                cost[size_t(predict.level(i))][p] += uint64_t(bit_length(magnitude)) + 1;
            }
    predictors.assign(size_t(levels), kSpatial);
    for (int l = 0; l < levels; ++l)
        for (uint8_t p = kSpatial + 1; p <= allowed; ++p)
            if (cost[size_t(l)][p] < cost[size_t(l)][predictors[size_t(l)]]) predictors[size_t(l)] = p;
    FloatResidualModels models(kFieldContexts);
    ArithmeticEncoder encoder;
    for (size_t i = 0; i < tuples; ++i) {
        const int l = predict.level(i);
        for (uint32_t c = 0; c < comps; ++c) {
            bool negative;
            uint64_t magnitude;
            predict.d.residual(w[i * comps + c], predict(predictors[size_t(l)], i, c, w), negative, magnitude);
            encode_signed_residual(encoder, models.context(value_context(l, c)), negative, magnitude);
        }
    }
    return encoder.finish();
}

template <class D>
std::vector<typename D::V> decode_values(const Predictions<D>& predict, size_t tuples,
                                         const std::vector<uint8_t>& predictors, const uint8_t* data, size_t size,
                                         const std::string& what) {
    const uint32_t comps = predict.comps;
    std::vector<typename D::V> w(tuples * comps);
    FloatResidualModels models(kFieldContexts);
    ArithmeticDecoder decoder(data, size);
    for (size_t i = 0; i < tuples; ++i) {
        const int l = predict.level(i);
        for (uint32_t c = 0; c < comps; ++c) {
            bool negative;
            uint64_t magnitude;
            decode_signed_residual(decoder, models, models.context(value_context(l, c)), negative, magnitude);
            w[i * comps + c] = predict.d.apply(predict(predictors[size_t(l)], i, c, w), negative, magnitude);
        }
    }
    AMC_REQUIRE(!decoder.overran(), truncated, what + ": the payload ends early");
    AMC_REQUIRE(!models.saw_invalid_symbol(), corrupt, what + ": an invalid residual");
    return w;
}

void put_bytes(std::vector<uint8_t>& out, const void* data, size_t n) {
    const uint8_t* p = static_cast<const uint8_t*>(data);
    out.insert(out.end(), p, p + n);
}

}  // namespace

FieldFrame::FieldFrame(const FrameState& prev_, const FrameState& next_, const Counterparts& cp_,
                       const std::vector<FrameVertex>& order_)
    : prev(prev_), next(next_), cp(cp_), order(order_) {
    const Hierarchy& h = next.h;
    index_of_vertex.assign(h.positions().size(), kNoVertex);
    for (size_t i = 0; i < order.size(); ++i) index_of_vertex[order[i].id] = uint32_t(i);
    for (NodeId n : h.breadth_first_order()) {
        levels = std::max(levels, h.level(n) + 1);
        if (!h.is_leaf(n)) continue;
        for (int k = 0; k <= h.hanging_node_count(n); ++k) cell_node.push_back(n);
    }
}

void encode_field(const Field& field, double bound, const FieldFrame& frame, std::vector<uint8_t>& out,
                  Field& decoded, FieldCodeStats* stats) {
    const std::string what = "field \"" + field.name + "\"";
    AMC_REQUIRE(!field.name.empty() && field.name.size() <= kMaxFieldNameBytes, invalid_input,
                what + ": a name of 1 to 1024 bytes is required");
    AMC_REQUIRE(field.components >= 1 && field.components <= kMaxFieldComponents, invalid_input,
                what + ": components must be 1 to 1024");
    AMC_REQUIRE(uint8_t(field.type) <= uint8_t(FieldType::float64) && uint8_t(field.association) <= 1, invalid_input,
                what + ": unknown type or association");
    const size_t tuples = frame.tuples(field.association);
    const bool is_float = is_float_type(field.type);
    AMC_REQUIRE(field.value_count() == tuples * field.components &&
                    (is_float ? field.integers.empty() : field.values.empty()),
                invalid_input,
                what + ": " + std::to_string(field.value_count()) + " values for " + std::to_string(tuples) + " " +
                    (field.association == FieldAssociation::point ? "points" : "cells") + " of " +
                    std::to_string(field.components) + " components");
    for (int64_t v : field.integers) AMC_REQUIRE(integer_in_range(v, field.type), invalid_input, what + ": a value out of the type's range");
    if (field.type == FieldType::float32)
        for (double v : field.values)
            AMC_REQUIRE(std::isnan(v) || rounded_to_float(v) == v, invalid_input, what + ": a Float32 value that is not a float");

    const Field* ref = find_reference(frame.prev, field);
    const std::vector<uint32_t> prev_cell =
        (ref && field.association == FieldAssociation::cell) ? previous_cells(frame) : std::vector<uint32_t>{};
    const uint8_t allowed = max_predictor(ref, field.association);
    decoded = field;

    // Error-bounded when every value has a grid point within the bound.
    uint8_t mode = kExact;
    std::vector<int64_t> q;
    const double step = 2 * bound;
    if (bound > 0 && is_float && std::isfinite(step)) {
        mode = kBounded;
        q.resize(field.values.size());
        for (size_t i = 0; i < q.size() && mode == kBounded; ++i) {
            const double x = field.values[i];
            if (!on_grid(x, step)) { mode = kExact; break; }
            const int64_t c = grid_index(x, step);
            bool found = false;
            for (int64_t t : {c, c - 1, c + 1})
                if (std::fabs(grid_value(t, step, field.type) - x) <= bound) { q[i] = t; found = true; break; }
            if (!found) mode = kExact;
        }
    }

    out.reserve(out.size() + 32);
    put_varint(out, field.name.size());
    put_bytes(out, field.name.data(), field.name.size());
    out.push_back(uint8_t(field.association));
    out.push_back(uint8_t(field.type));
    put_varint(out, field.components);
    out.push_back(mode);
    if (mode == kBounded) put_f64(out, bound);

    std::vector<uint8_t> predictors, payload;
    double max_error = 0;
    if (!is_float || mode == kBounded) {
        IntegerDomain d;
        d.grid = mode == kBounded;
        d.step = step;
        Predictions<IntegerDomain> predict{frame, ref, field.association, field.components, d, prev_cell};
        payload = encode_values(predict, d.grid ? q : field.integers, tuples, frame.levels, allowed, predictors);
        if (d.grid)
            for (size_t i = 0; i < q.size(); ++i) {
                decoded.values[i] = grid_value(q[i], step, field.type);
                max_error = std::max(max_error, std::fabs(decoded.values[i] - field.values[i]));
            }
    } else {
        FloatDomain d;
        d.precision = precision_of(field.type);
        Predictions<FloatDomain> predict{frame, ref, field.association, field.components, d, prev_cell};
        payload = encode_values(predict, field.values, tuples, frame.levels, allowed, predictors);
    }
    out.insert(out.end(), predictors.begin(), predictors.end());
    put_varint(out, payload.size());
    out.insert(out.end(), payload.begin(), payload.end());
    if (stats) {
        stats->bounded = mode == kBounded;
        stats->max_error = max_error;
        stats->predictors = predictors;
    }
}

Field decode_field(PayloadReader& in, const FieldFrame& frame) {
    Field f;
    const uint64_t name_length = in.varint();
    AMC_REQUIRE(name_length >= 1 && name_length <= kMaxFieldNameBytes && name_length <= in.remaining(), corrupt,
                "field record: name length " + std::to_string(name_length) + " out of range");
    f.name.assign(reinterpret_cast<const char*>(in.bytes(name_length)), size_t(name_length));
    const std::string what = "field \"" + f.name + "\"";
    const uint8_t association = in.u8(), type = in.u8();
    AMC_REQUIRE(association <= 1, corrupt, what + ": unknown association " + std::to_string(association));
    AMC_REQUIRE(type <= uint8_t(FieldType::float64), corrupt, what + ": unknown type " + std::to_string(type));
    f.association = FieldAssociation(association);
    f.type = FieldType(type);
    const uint64_t components = in.varint();
    AMC_REQUIRE(components >= 1 && components <= kMaxFieldComponents, corrupt,
                what + ": " + std::to_string(components) + " components (1 to 1024 allowed)");
    f.components = uint32_t(components);
    const uint8_t mode = in.u8();
    const bool is_float = is_float_type(f.type);
    AMC_REQUIRE(mode == kExact || (mode == kBounded && is_float), corrupt, what + ": unknown mode " + std::to_string(mode));
    double bound = 0;
    if (mode == kBounded) {
        bound = in.f64();
        AMC_REQUIRE(std::isfinite(bound) && bound > 0 && std::isfinite(2 * bound), corrupt, what + ": bad error bound");
    }
    const Field* ref = find_reference(frame.prev, f);
    const uint8_t allowed = max_predictor(ref, f.association);
    std::vector<uint8_t> predictors(size_t(frame.levels));
    for (uint8_t& p : predictors) {
        p = in.u8();
        AMC_REQUIRE(p >= kSpatial && p <= allowed, corrupt,
                    what + ": predictor " + std::to_string(p) + " is unknown or has no previous field to use");
    }
    const uint64_t length = in.varint();
    AMC_REQUIRE(length <= in.remaining(), truncated, what + ": payload longer than the frame");
    const size_t tuples = frame.tuples(f.association);
    AMC_REQUIRE(uint64_t(tuples) * f.components <= max_decodable_symbols(length) / kMinSymbolsPerSignedResidual, corrupt,
                what + ": " + std::to_string(uint64_t(tuples) * f.components) + " values can not fit in " +
                    std::to_string(length) + " bytes");
    const uint8_t* data = in.bytes(length);
    const std::vector<uint32_t> prev_cell =
        (ref && f.association == FieldAssociation::cell) ? previous_cells(frame) : std::vector<uint32_t>{};
    if (!is_float || mode == kBounded) {
        IntegerDomain d;
        d.grid = mode == kBounded;
        d.step = 2 * bound;
        Predictions<IntegerDomain> predict{frame, ref, f.association, f.components, d, prev_cell};
        std::vector<int64_t> w = decode_values(predict, tuples, predictors, data, size_t(length), what);
        if (d.grid) {
            f.values.resize(w.size());
            for (size_t i = 0; i < w.size(); ++i) f.values[i] = grid_value(w[i], d.step, f.type);
        } else {
            for (int64_t v : w) AMC_REQUIRE(integer_in_range(v, f.type), corrupt, what + ": a value out of the type's range");
            f.integers = std::move(w);
        }
    } else {
        FloatDomain d;
        d.precision = precision_of(f.type);
        Predictions<FloatDomain> predict{frame, ref, f.association, f.components, d, prev_cell};
        f.values = decode_values(predict, tuples, predictors, data, size_t(length), what);
    }
    return f;
}

}  // namespace amc
