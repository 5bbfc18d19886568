// The round-trip property: the input drives a random hierarchy (base mesh, refinements and
// coarsenings, flipped diagonals, coordinates anywhere in the float or double range, a caller's
// numbering) and the encoder's options (quantization, predictor, the coder's 64 switch
// combinations). The encoder either refuses it as invalid input or writes a file that decodes:
// bit-exactly to the input in the decoder's order, or on the grid within the reported error.
// Files of several chunks and the mixing contexts come up too.
#include "fuzz_targets.h"

#include "coding/hierarchy/coder_switches.h"
#include "coding/geometry/float_coder.h"

#include <amc/codec.h>
#include <amc/refinement.h>

#include <cfloat>
#include <cmath>
#include <cstring>
#include <numeric>
#include <utility>

namespace amc::fuzz {
namespace {

constexpr uint32_t kMaxNodes = 20000;  // the hierarchy a run builds at most
constexpr int kMaxRefinedLevel = 7;

// Any finite value of the precision, from raw bits: infinities and NaNs become the largest
// finite value of their sign, so the extremes come up often.
double any_coordinate(ByteReader& in, bool single) {
    if (single) {
        const uint32_t bits = in.u32();
        float f;
        std::memcpy(&f, &bits, 4);
        if (!std::isfinite(f)) f = std::signbit(f) ? -FLT_MAX : FLT_MAX;
        return f;
    }
    const uint64_t bits = in.u64();
    double d;
    std::memcpy(&d, &bits, 8);
    if (!std::isfinite(d)) d = std::signbit(d) ? -DBL_MAX : DBL_MAX;
    return d;
}

Vec3 any_position(ByteReader& in, bool single) {
    const double x = any_coordinate(in, single), y = any_coordinate(in, single);
    return {x, y, any_coordinate(in, single)};
}

std::vector<uint32_t> any_permutation(ByteReader& in, uint32_t n) {
    std::vector<uint32_t> p(n);
    std::iota(p.begin(), p.end(), 0u);
    for (uint32_t i = n; i > 1; --i) std::swap(p[i - 1], p[in.u32() % i]);
    return p;
}

}  // namespace

void round_trip(const uint8_t* data, size_t size) {
    ByteReader in(data, size);
    const uint8_t flags = in.u8();
    const bool single = flags & 1, wild = flags & 2, numbered = flags & 4;
    const std::vector<TriangleMesh>& bases = stream_bases();
    TriangleMesh base = bases[in.u8() % bases.size()];
    base.single_precision = single;
    for (Vec3& p : base.positions) {
        if (wild) p = any_position(in, single);
        else if (single) p = {float(p.x), float(p.y), float(p.z)};
    }

    Hierarchy h(base);
    refine_at_random(h, in, kMaxNodes, kMaxRefinedLevel, flags & 8);
    if (wild) {
        const std::vector<uint32_t> order = canonical_vertex_order(h);
        for (VertexId v = 0; v < order.size(); ++v)
            if (order[v] != 0xffffffffu && order[v] >= base.positions.size() && (in.u8() & 1))
                h.set_position(v, any_position(in, single));
    }

    EncodeOptions options;
    const uint8_t q = in.u8();
    options.quantize_bits = q < 160 ? 0 : 1 + q % 30;
    options.predictor = GeometryPredictor(in.u8() % 3);
    options.grid_contexts = options.quantize_bits != 0 && (q & 1);  // geometry mode 4 (version 9)
    options.hierarchy = coder_options_from_switches(in.u8() % kCoderSwitchCombinations);
    if (flags & 16) options.hierarchy_contexts = HierarchyContexts::mixed;
    if (flags & 32) options.chunks = 2 + in.u8() % 7;
    options.threads = 1 + (flags >> 6 & 1);
    LeafNumbering numbering;
    if (numbered) {
        const uint32_t faces = uint32_t(extract_leaf_mesh(h).mesh.triangles.size());
        numbering.vertex = any_permutation(in, h.vertex_count());
        numbering.face = any_permutation(in, faces);
        numbering.rotation.resize(faces);
        for (uint8_t& r : numbering.rotation) r = in.u8() % 3;
        options.numbering = &numbering;
    }

    std::vector<uint8_t> file;
    EncodeStats stats;
    try {
        file = encode(h, options, &stats);
    } catch (const Error& e) {
        FUZZ_CHECK(e.code() == ErrorCode::invalid_input);  // refused as input the format can not hold
        return;
    }
    LeafNumbering decoded_numbering;
    DecodeOptions decode_options;
    decode_options.threads = options.threads;
    const Hierarchy decoded = decode(file.data(), file.size(), decode_options, &decoded_numbering);  // throws: a finding
    // The base order depends on the options (a stored numbering codes the base in mode 2 without
    // the encoder's search): the expectation takes the same options.
    const Hierarchy expected = in_decoder_order(h, options);
    if (numbered) {
        FUZZ_CHECK(decoded_numbering.vertex == stats.numbering.vertex && decoded_numbering.face == stats.numbering.face &&
                   decoded_numbering.rotation == stats.numbering.rotation);
    }
    if (options.quantize_bits == 0) {
        FUZZ_CHECK(identical(decoded, expected));
        return;
    }
    // Quantized: the positions snapped to the encoder's grid, each within max_error of the input,
    // then in decoder order (base connectivity mode 2 orders the base by the decoded positions).
    Hierarchy snapped = h;
    snapped.set_single_precision(false);
    const std::vector<uint32_t> order = canonical_vertex_order(snapped);
    std::vector<Vec3> points;
    for (VertexId v = 0; v < order.size(); ++v)
        if (order[v] != 0xffffffffu) points.push_back(snapped.position(v));
    const Quantizer quantizer = make_quantizer(points, options.quantize_bits);
    for (VertexId v = 0; v < order.size(); ++v) {
        if (order[v] == 0xffffffffu) continue;
        const Vec3 p = h.position(v), s = dequantize(quantizer, snap_to_grid(quantizer, p));
        FUZZ_CHECK(std::fabs(p.x - s.x) <= stats.max_error && std::fabs(p.y - s.y) <= stats.max_error &&
                   std::fabs(p.z - s.z) <= stats.max_error);
        snapped.set_position(v, s);
    }
    EncodeOptions on_grid = options;  // the snapped positions are the decoder's: no second snapping
    on_grid.quantize_bits = 0;
    FUZZ_CHECK(identical(decoded, in_decoder_order(snapped, on_grid)));
}

}  // namespace amc::fuzz
