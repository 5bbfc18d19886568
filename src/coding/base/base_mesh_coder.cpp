// Single-rate coder of the base mesh: the mode dispatch and the explicit mode (FORMAT.md 4.2,
// 4.8); see base_mesh_coder.h.
#include "coding/base/base_mesh_coder.h"

#include "coding/entropy/arithmetic_coder.h"
#include "coding/base/base_angle_coder.h"
#include "coding/base/base_cut_border_coder.h"
#include "coding/base/base_mesh_stream.h"
#include "common/bits.h"
#include "common/check.h"

#include <algorithm>
#include <numeric>
#include <string>

namespace amc {
namespace {

// The explicit mode predicts each vertex by the one before.
std::vector<BaseStencil> explicit_stencils(uint32_t vertex_count) {
    std::vector<BaseStencil> stencils(vertex_count);
    for (uint32_t i = 0; i < vertex_count; ++i) stencils[i] = {static_cast<int32_t>(i) - 1, -1, -1};
    return stencils;
}

DecodedBaseMesh decode_explicit(ArithmeticDecoder& dec, size_t size, uint32_t vertex_count, uint32_t max_isolated) {
    DecodedBaseMesh out;
    out.vertex_count = get_count(dec);
    if (out.vertex_count != vertex_count) fail_base_stream("vertex count differs from the caller's");
    const uint32_t faces = get_count(dec);
    const int bits = bit_length(out.vertex_count == 0 ? 0 : out.vertex_count - 1);
    if (faces > 0 && (out.vertex_count < 3 ||
                      uint64_t{faces} * 3 * static_cast<uint64_t>(bits) > 8 * (uint64_t{size} + 8)))
        fail_base_stream("triangle count exceeds the stream");
    // F triangles use at most 3F vertices: the others are isolated.
    if (out.vertex_count > 3 * uint64_t{faces} + max_isolated)
        fail_base_stream(isolated_refused(out.vertex_count - 3 * uint64_t{faces}, max_isolated, "at least "));
    out.triangles.resize(faces);
    for (Triangle& t : out.triangles) {
        for (uint32_t& v : t) v = get_index(dec, out.vertex_count, "vertex index");
        if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) fail_base_stream("degenerate triangle");
    }
    out.stencils = explicit_stencils(out.vertex_count);
    return out;
}

std::vector<uint8_t> encode_explicit(const TriangleMesh& mesh, BaseMeshCode& code) {
    const uint32_t v = static_cast<uint32_t>(mesh.positions.size());
    ArithmeticEncoder enc;
    enc.encode_bits_raw(uint32_t(BaseConnectivityMode::explicit_triangles), 2);
    put_count(enc, v);
    put_count(enc, static_cast<uint32_t>(mesh.triangles.size()));
    for (const Triangle& t : mesh.triangles)
        for (uint32_t x : t) put_index(enc, x, v);
    code.vertex_order.resize(v);
    std::iota(code.vertex_order.begin(), code.vertex_order.end(), 0u);
    code.triangle_order.resize(mesh.triangles.size());
    std::iota(code.triangle_order.begin(), code.triangle_order.end(), 0u);
    code.triangle_rotation.assign(mesh.triangles.size(), 0);
    code.stencils = explicit_stencils(v);
    return enc.finish();
}

// Mode 0's stencils are read off its own decode rather than tracked by its encoder (it is the
// writer's fallback after modes 2 and 3, and what versions 1-3 wrote).
std::vector<BaseStencil> cut_border_stencils(const TriangleMesh& mesh, const BaseMeshCode& code) {
    return decode_base_mesh(code.bytes.data(), code.bytes.size(), static_cast<uint32_t>(mesh.positions.size()),
                            [&](uint32_t vertex, const BaseStencil&, const std::vector<Vec3>&) {
                                return mesh.positions[code.vertex_order[vertex]];
                            })
        .stencils;
}

// Codes with one mode; false when the mode does not fit the mesh. The encoders track what the
// decoder will do (orders, stencils); tests/base_mesh_coder_test.cpp decodes every mode's
// streams and compares. Mode 2's search runs on up to `threads` threads.
// With `start`, mode 2 from there alone.
bool try_mode(const TriangleMesh& mesh, BaseConnectivityMode mode, BaseMeshCode& code, bool search = true,
              unsigned threads = 1, uint64_t search_budget = kFullBaseSearch, const BaseStart* start = nullptr) {
    try {
        code = BaseMeshCode{};
        code.mode = mode;
        switch (mode) {
            case BaseConnectivityMode::angle:
            case BaseConnectivityMode::angle_windowed:
                code.bytes = start != nullptr ? encode_angle_mode(mesh, code, mode, *start)
                                              : encode_angle_mode(mesh, code, mode, search, threads, search_budget);
                break;
            case BaseConnectivityMode::cut_border: code.bytes = encode_cut_border(mesh, code); break;
            case BaseConnectivityMode::explicit_triangles: code.bytes = encode_explicit(mesh, code); break;
        }
        if (code.vertex_order.size() != mesh.positions.size()) return false;
        if (mode == BaseConnectivityMode::cut_border) code.stencils = cut_border_stencils(mesh, code);
        return code.stencils.size() == mesh.positions.size();
    } catch (const EncoderGaveUp&) {
    } catch (const Error&) {
    }
    return false;
}

void check_encodable(const TriangleMesh& mesh) {
    const size_t v = mesh.positions.size();
    if (v > kMaxBaseCount || mesh.triangles.size() > kMaxBaseCount / 4) throw Error("base mesh coder: mesh too large");
    for (size_t t = 0; t < mesh.triangles.size(); ++t)
        for (uint32_t x : mesh.triangles[t])
            if (x >= v)
                throw Error("base mesh coder: triangle " + std::to_string(t) + " has a vertex index out of range");
}

}  // namespace

BaseMeshCode encode_base_connectivity(const TriangleMesh& mesh, unsigned threads, uint64_t search_budget) {
    check_encodable(mesh);
    BaseMeshCode code;
    if (try_mode(mesh, BaseConnectivityMode::angle, code, true, threads, search_budget)) return code;
    // Long loops (a long strip, millions of triangles) walk mode 2 over its budget; mode 3 stays in it.
    if (try_mode(mesh, BaseConnectivityMode::angle_windowed, code, true, threads, search_budget)) return code;
    // Mode 0 needs no positions: a few bits a vertex where mode 1 spends three indices a triangle.
    if (try_mode(mesh, BaseConnectivityMode::cut_border, code)) return code;
    if (!try_mode(mesh, BaseConnectivityMode::explicit_triangles, code))
        throw Error("base mesh coder: the explicit mode failed");
    return code;
}

BaseMeshCode encode_base_connectivity(const TriangleMesh& mesh, BaseConnectivityMode mode, bool search) {
    check_encodable(mesh);
    BaseMeshCode code;
    if (!try_mode(mesh, mode, code, search))
        throw Error("base mesh coder: the mesh does not fit mode " + std::to_string(int(mode)));
    return code;
}

BaseMeshCode encode_base_connectivity(const TriangleMesh& mesh, const BaseStart& start) {
    check_encodable(mesh);
    BaseMeshCode code;
    if (!try_mode(mesh, BaseConnectivityMode::angle, code, false, 1, 0, &start))
        throw Error("base mesh coder: the mesh does not fit mode 2 from this start");
    return code;
}

BaseConnectivityMode base_connectivity_mode(const uint8_t* data, size_t size) {
    if (data == nullptr && size != 0) fail_base_stream("no data");
    ArithmeticDecoder dec(data, size);
    return BaseConnectivityMode(dec.decode_bits_raw(2));
}

DecodedBaseMesh decode_base_mesh(const uint8_t* data, size_t size, uint32_t vertex_count,
                                 const BasePositionSource& positions, uint32_t max_isolated) {
    if (data == nullptr && size != 0) fail_base_stream("no data", ErrorCode::invalid_input);
    return with_allocation_errors_as_limits("base mesh stream", [&] {
        ArithmeticDecoder dec(data, size);
        const uint32_t mode = dec.decode_bits_raw(2);
        DecodedBaseMesh out;
        if (mode == uint32_t(BaseConnectivityMode::angle) || mode == uint32_t(BaseConnectivityMode::angle_windowed)) {
            out = decode_angle_mode(dec, size, vertex_count, positions, max_isolated, BaseConnectivityMode(mode));
        } else {
            if (mode == uint32_t(BaseConnectivityMode::cut_border)) out = decode_cut_border(dec, size, vertex_count, max_isolated);
            else if (mode == uint32_t(BaseConnectivityMode::explicit_triangles))
                out = decode_explicit(dec, size, vertex_count, max_isolated);
            else fail_base_stream("unknown mode " + std::to_string(mode));
            if (dec.overran()) fail_base_stream("truncated", ErrorCode::truncated);
            // These modes know their connectivity without positions: they are read afterwards.
            out.positions.reserve(std::min<uint32_t>(out.vertex_count, 1u << 20));
            for (uint32_t i = 0; i < out.vertex_count; ++i) out.positions.push_back(positions(i, out.stencils[i], out.positions));
        }
        if (dec.overran()) fail_base_stream("truncated", ErrorCode::truncated);
        return out;
    });
}

}  // namespace amc
