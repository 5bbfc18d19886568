#include "compare_draco.h"

#include "bench_common.h"

#include <draco/compression/decode.h>
#include <draco/compression/encode.h>
#include <draco/compression/mesh/mesh_edgebreaker_decoder.h>
#include <draco/compression/mesh/mesh_edgebreaker_encoder.h>
#include <draco/mesh/mesh.h>

#include <stdexcept>
#include <string>

namespace amc_bench {

namespace {

// Draco's Edgebreaker encoder, measuring its connectivity stage: EncodeConnectivity() is a
// protected virtual of MeshEdgebreakerEncoder in 1.5.5, called once per Encode().
class CountingEdgebreakerEncoder : public draco::MeshEdgebreakerEncoder {
public:
    uint64_t connectivity_bytes = 0;
    double connectivity_seconds = 0;

protected:
    draco::Status EncodeConnectivity() override {
        const size_t before = buffer()->size();
        const Clock::time_point start = Clock::now();
        draco::Status status = draco::MeshEdgebreakerEncoder::EncodeConnectivity();
        connectivity_seconds = seconds_since(start);
        connectivity_bytes = buffer()->size() - before;
        return status;
    }
};

// Its decoder, timing DecodeConnectivity() (the buffer position can not count bytes here: the
// Edgebreaker decoder reads parts of its connectivity from other positions of the buffer).
class TimingEdgebreakerDecoder : public draco::MeshEdgebreakerDecoder {
public:
    double connectivity_seconds = 0;
    double connectivity_cpu_seconds = 0;

protected:
    bool DecodeConnectivity() override {
        const double cpu_start = thread_seconds();
        const Clock::time_point start = Clock::now();
        const bool ok = draco::MeshEdgebreakerDecoder::DecodeConnectivity();
        connectivity_seconds = seconds_since(start);
        connectivity_cpu_seconds = thread_seconds() - cpu_start;
        return ok;
    }
};

draco::Encoder configured_encoder(const DracoSettings& settings) {
    draco::Encoder encoder;
    encoder.SetSpeedOptions(settings.speed, settings.speed);
    if (settings.quantization_bits > 0)
        encoder.SetAttributeQuantization(draco::GeometryAttribute::POSITION, settings.quantization_bits);
    return encoder;
}

void throw_unless_ok(const draco::Status& status, const char* what) {
    if (!status.ok()) throw std::runtime_error(std::string(what) + ": " + status.error_msg_string());
}

}  // namespace

std::shared_ptr<const draco::Mesh> make_draco_mesh(const amc::TriangleMesh& mesh, bool exact) {
    const bool float64 = exact && !mesh.single_precision;
    auto out = std::make_shared<draco::Mesh>();
    const size_t n = mesh.positions.size();
    out->set_num_points(uint32_t(n));
    draco::GeometryAttribute position;
    position.Init(draco::GeometryAttribute::POSITION, nullptr, 3, float64 ? draco::DT_FLOAT64 : draco::DT_FLOAT32, false,
                  float64 ? 3 * sizeof(double) : 3 * sizeof(float), 0);
    const int id = out->AddAttribute(position, true, uint32_t(n));
    draco::PointAttribute* attribute = out->attribute(id);
    for (size_t v = 0; v < n; ++v) {
        const amc::Vec3 p = mesh.positions[v];
        if (float64) {
            const double xyz[3] = {p.x, p.y, p.z};
            attribute->SetAttributeValue(draco::AttributeValueIndex(uint32_t(v)), xyz);
        } else {
            const float xyz[3] = {float(p.x), float(p.y), float(p.z)};
            attribute->SetAttributeValue(draco::AttributeValueIndex(uint32_t(v)), xyz);
        }
    }
    for (const amc::Triangle& t : mesh.triangles)
        out->AddFace({draco::PointIndex(t[0]), draco::PointIndex(t[1]), draco::PointIndex(t[2])});
    return out;
}

// What draco::Encoder::EncodeMeshToBuffer does for an Edgebreaker speed (0..9), with our subclass
// (its Encode() clears what an earlier call left).
struct DracoEncoderState {
    DracoEncoderState(const draco::Mesh& mesh, const DracoSettings& settings)
        : options(configured_encoder(settings).CreateExpertEncoderOptions(mesh)) {
        counting.SetMesh(mesh);
    }
    const draco::EncoderOptions options;
    CountingEdgebreakerEncoder counting;
};

DracoKeptEncoder::DracoKeptEncoder() = default;
DracoKeptEncoder::~DracoKeptEncoder() = default;

DracoEncoded draco_encode(const draco::Mesh& mesh, const DracoSettings& settings, DracoKeptEncoder* kept) {
    DracoEncoded result;
    const Clock::time_point start = Clock::now();
    std::unique_ptr<DracoEncoderState> own;
    std::unique_ptr<DracoEncoderState>& state = kept != nullptr ? kept->state : own;
    if (state == nullptr) state = std::make_unique<DracoEncoderState>(mesh, settings);
    draco::EncoderBuffer buffer;
    throw_unless_ok(state->counting.Encode(state->options, &buffer), "draco encode");
    result.seconds = seconds_since(start);
    result.bytes.assign(buffer.data(), buffer.data() + buffer.size());
    result.connectivity_bytes = state->counting.connectivity_bytes;
    result.connectivity_seconds = state->counting.connectivity_seconds;
    return result;
}

std::vector<char> draco_encode_public(const draco::Mesh& mesh, const DracoSettings& settings) {
    draco::Encoder encoder = configured_encoder(settings);
    draco::EncoderBuffer buffer;
    throw_unless_ok(encoder.EncodeMeshToBuffer(mesh, &buffer), "draco encode (public API)");
    return std::vector<char>(buffer.data(), buffer.data() + buffer.size());
}

DracoDecoded draco_decode(const std::vector<char>& bytes) {
    DracoDecoded result;
    draco::Mesh mesh;
    const Clock::time_point start = Clock::now();
    draco::DecoderBuffer buffer;
    buffer.Init(bytes.data(), bytes.size());
    TimingEdgebreakerDecoder decoder;
    draco::DecoderOptions options;
    throw_unless_ok(decoder.Decode(options, &buffer, &mesh), "draco decode");
    result.seconds = seconds_since(start);
    result.connectivity_seconds = decoder.connectivity_seconds;
    result.connectivity_cpu_seconds = decoder.connectivity_cpu_seconds;

    const draco::PointAttribute* position = mesh.GetNamedAttribute(draco::GeometryAttribute::POSITION);
    if (position == nullptr) throw std::runtime_error("draco decode: no position attribute");
    result.positions.resize(mesh.num_points());
    for (uint32_t p = 0; p < mesh.num_points(); ++p) {
        double xyz[3];
        if (!position->ConvertValue<double>(position->mapped_index(draco::PointIndex(p)), 3, xyz))
            throw std::runtime_error("draco decode: position " + std::to_string(p) + " not convertible");
        result.positions[p] = {xyz[0], xyz[1], xyz[2]};
    }
    result.triangles.resize(mesh.num_faces());
    for (uint32_t f = 0; f < mesh.num_faces(); ++f) {
        const draco::Mesh::Face& face = mesh.face(draco::FaceIndex(f));
        result.triangles[f] = {face[0].value(), face[1].value(), face[2].value()};
    }
    return result;
}

}  // namespace amc_bench
