// Fuzz targets of the streams inside an .amc file, each decoded alone: the hierarchy stream
// (decode_hierarchy, over base meshes the target provides), the base mesh connectivity and the
// coordinates. Whatever decodes is encoded again and must decode to the same.
#include "fuzz_targets.h"

#include "coding/entropy/arithmetic_coder.h"
#include "coding/base/base_mesh_coder.h"
#include "coding/geometry/float_coder.h"

#include <amc/hierarchy_coder.h>
#include <amc/refinement.h>

#include <algorithm>
#include <cmath>
#include <cstring>

namespace amc::fuzz {

const std::vector<TriangleMesh>& stream_bases() {
    static const std::vector<TriangleMesh> bases = [] {
        TriangleMesh triangle;
        triangle.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
        triangle.triangles = {{0, 1, 2}};
        return std::vector<TriangleMesh>{make_icosahedron(), make_torus(6, 5, 2.0, 0.7), make_square(3), make_l_shape(1),
                                         triangle};
    }();
    return bases;
}

Vec3 base_position(uint32_t v) {
    // Scattered, never three on a line for small v: the angle-guided mode predicts from them.
    return {double(v % 7) + 0.1 * double(v % 3), double(v * 3 % 11) - 0.2 * double(v % 5), double(v * 5 % 13) + 0.05 * v};
}

namespace {

constexpr uint64_t kMaxNodes = uint64_t(1) << 16;

}  // namespace


void hierarchy_stream(const uint8_t* data, size_t size) {
    if (size < 2) return;
    const std::vector<TriangleMesh>& bases = stream_bases();
    const TriangleMesh& base = bases[data[0] % bases.size()];
    HierarchyDecodeOptions options;
    options.max_nodes = kMaxNodes;
    options.max_level = int(data[1] % 10) - 1;
    const uint8_t* stream = data + 2;
    const size_t stream_size = size - 2;
    Hierarchy h;
    try {
        h = decode_hierarchy(base, stream, stream_size, options);
    } catch (const Error&) {
        return;
    }
    FUZZ_CHECK(check_invariants(h).empty());
    // A decoder that reuses memory gives the same, into a hierarchy that held another one.
    Hierarchy reused(bases[(data[0] + 1) % bases.size()]);
    refine_uniformly(reused, 1);
    HierarchyDecoder decoder;
    decoder.decode(base, stream, stream_size, reused, options);  // throws: a finding
    FUZZ_CHECK(identical(reused, h));
    // Encoded again it decodes to itself.
    const std::vector<uint8_t> again = encode_hierarchy(h);
    FUZZ_CHECK(identical(decode_hierarchy(base, again.data(), again.size(), {-1, kMaxNodes}), h));
}

void base_connectivity(const uint8_t* data, size_t size) {
    // Layout: u16 vertex count (the .amc metadata gives it to the decoder), then the stream.
    // Positions come from base_position(): mode 2 reads them while it decodes.
    ByteReader in(data, size);
    const uint32_t low = in.u8();
    const uint32_t n = low | uint32_t(in.u8()) << 8;
    const BasePositionSource source = [](uint32_t v, const BaseStencil&, const std::vector<Vec3>&) { return base_position(v); };
    DecodedBaseMesh decoded;
    try {
        decoded = decode_base_mesh(in.rest(), in.remaining(), n, source);
    } catch (const Error&) {
        return;
    }
    FUZZ_CHECK(decoded.vertex_count == n && decoded.stencils.size() == n && decoded.positions.size() == n);
    for (const Triangle& t : decoded.triangles) {
        FUZZ_CHECK(t[0] < n && t[1] < n && t[2] < n);
        FUZZ_CHECK(t[0] != t[1] && t[1] != t[2] && t[0] != t[2]);
    }
    for (uint32_t i = 0; i < n; ++i) {
        for (int32_t s : decoded.stencils[i]) FUZZ_CHECK(s >= -1 && s < int32_t(i));
    }
    // The .amc decoder allows no isolated vertex (refused on the stream's counts): a stream whose
    // mesh uses every vertex passes that check and decodes the same.
    std::vector<bool> used(n, false);
    for (const Triangle& t : decoded.triangles)
        for (uint32_t v : t) used[v] = true;
    if (std::find(used.begin(), used.end(), false) == used.end()) {
        const DecodedBaseMesh strict = decode_base_mesh(in.rest(), in.remaining(), n, source, 0);  // throws: a finding
        FUZZ_CHECK(strict.triangles == decoded.triangles && strict.stencils == decoded.stencils);
    }
    // Encoded again, the decoder gives the same triangles in the coder's order (fed the positions
    // in that order).
    TriangleMesh mesh;
    mesh.positions = decoded.positions;
    mesh.triangles = decoded.triangles;
    BaseMeshCode code;
    try {
        code = encode_base_connectivity(mesh);
    } catch (const Error&) {
        return;  // the encoder codes base meshes that validate_triangle_mesh accepts; decoded streams need not be
    }
    const BasePositionSource reordered = [&](uint32_t v, const BaseStencil&, const std::vector<Vec3>&) {
        return mesh.positions[code.vertex_order[v]];
    };
    const DecodedBaseMesh again = decode_base_mesh(code.bytes.data(), code.bytes.size(), n, reordered);
    FUZZ_CHECK(again.vertex_count == n && again.triangles.size() == mesh.triangles.size());
    for (size_t t = 0; t < again.triangles.size(); ++t) {
        const Triangle& original = mesh.triangles[code.triangle_order[t]];
        const int r = code.triangle_rotation[t];
        for (int k = 0; k < 3; ++k) FUZZ_CHECK(code.vertex_order[again.triangles[t][k]] == original[(r + k) % 3]);
    }
}

void geometry(const uint8_t* data, size_t size) {
    ByteReader in(data, size);
    const uint8_t mode = in.u8();
    const bool quantized = mode % 3 == 2;
    const Precision precision = mode % 3 == 0 ? Precision::float32 : Precision::float64;
    const int bits = 1 + mode / 3 % 30;
    const uint32_t top = (uint32_t{1} << bits) - 1;
    const size_t n = 1 + in.u8() % 16;
    std::vector<uint64_t> predictions(n);
    for (uint64_t& p : predictions) p = in.u64();
    auto predicted_value = [&](size_t i) {
        double x;
        std::memcpy(&x, &predictions[i % n], 8);
        return x;
    };
    auto predicted_grid = [&](size_t i) { return uint32_t(predictions[i % n]); };
    auto context = [](size_t i) { return int(i * 7 % kGeometryContexts); };

    // Decode until the payload runs out or a value is one the .amc decoder would refuse.
    std::vector<double> values;
    std::vector<uint32_t> grid;
    {
        ArithmeticDecoder decoder(in.rest(), in.remaining());
        FloatResidualModels models(kGeometryContexts);
        for (size_t i = 0; i < kMaxGeometryCoordinates; ++i) {
            if (quantized) {
                const uint32_t q = decode_quantized(decoder, models, context(i), bits, predicted_grid(i));
                FUZZ_CHECK(q <= top);
                if (decoder.overran() || models.saw_invalid_symbol()) break;
                grid.push_back(q);
            } else {
                const double x = decode_coordinate(decoder, models, context(i), precision, predicted_value(i));
                if (decoder.overran() || models.saw_invalid_symbol() || !std::isfinite(x)) break;
                if (precision == Precision::float32) FUZZ_CHECK(double(float(x)) == x);
                values.push_back(x);
            }
        }
    }
    // Encoded again with the same predictions and contexts, they decode bit for bit.
    ArithmeticEncoder encoder;
    FloatResidualModels models(kGeometryContexts);
    for (size_t i = 0; i < grid.size(); ++i)
        encode_quantized(encoder, models, context(i), bits, grid[i], std::min(predicted_grid(i), top));
    for (size_t i = 0; i < values.size(); ++i)
        encode_coordinate(encoder, models, context(i), precision, values[i], predicted_value(i));
    const std::vector<uint8_t> bytes = encoder.finish();
    ArithmeticDecoder decoder(bytes.data(), bytes.size());
    FloatResidualModels fresh(kGeometryContexts);
    for (size_t i = 0; i < grid.size(); ++i)
        FUZZ_CHECK(decode_quantized(decoder, fresh, context(i), bits, predicted_grid(i)) == grid[i]);
    for (size_t i = 0; i < values.size(); ++i) {
        const double x = decode_coordinate(decoder, fresh, context(i), precision, predicted_value(i));
        FUZZ_CHECK(std::memcmp(&x, &values[i], 8) == 0);
    }
    FUZZ_CHECK(!decoder.overran() && !fresh.saw_invalid_symbol());
}

}  // namespace amc::fuzz
