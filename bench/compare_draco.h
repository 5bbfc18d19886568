// compare_bench: Draco (Debian's libdraco 1.5.5) as a peer. Files are made by Draco's own Edgebreaker
// mesh encoder, subclassed only to count the bytes its EncodeConnectivity() writes and to time it;
// the file is byte-identical to what draco::Encoder::EncodeMeshToBuffer writes (checked per run
// of the benchmark with draco_encode_public).
#pragma once

#include <amc/mesh.h>

#include <cstdint>
#include <memory>
#include <vector>

namespace draco {
class Mesh;
}

namespace amc_bench {

struct DracoSettings {
    // Encoder and decoder speed, 0..10. 0-4 select the valence Edgebreaker (best connectivity),
    // 5 (the C++ API default) the standard Edgebreaker; lower speeds also try costlier position
    // predictors.
    int speed = 5;
    int quantization_bits = 0;  // 0: positions stored as they are (lossless)
};

// A leaf mesh as a Draco mesh: one point per vertex, a position attribute. Positions are float32
// when `exact` is false (Draco quantizes only float32) and keep the source precision otherwise
// (float64 unless the mesh is single precision), so that lossless really is lossless.
std::shared_ptr<const draco::Mesh> make_draco_mesh(const amc::TriangleMesh& mesh, bool exact);

struct DracoEncoded {
    std::vector<char> bytes;          // the complete Draco file
    uint64_t connectivity_bytes = 0;  // what EncodeConnectivity() wrote
    double seconds = 0;               // the whole encode (Draco mesh in, file out)
    double connectivity_seconds = 0;  // inside EncodeConnectivity()
};
// Draco's encoder object kept over the encodes of one mesh at one setting, as a caller coding a
// series keeps it (compare_bench --kept-encoders; amcodec's side keeps an EncodeContext): made at
// the first encode through it, within its time, and used again by the next ones.
struct DracoEncoderState;
class DracoKeptEncoder {
public:
    DracoKeptEncoder();
    ~DracoKeptEncoder();
    DracoKeptEncoder(const DracoKeptEncoder&) = delete;
    DracoKeptEncoder& operator=(const DracoKeptEncoder&) = delete;
    std::unique_ptr<DracoEncoderState> state;
};

// Throws std::runtime_error with Draco's message on failure. With `kept`, through its encoder
// (always the same mesh and settings).
DracoEncoded draco_encode(const draco::Mesh& mesh, const DracoSettings& settings, DracoKeptEncoder* kept = nullptr);

// The same settings through the public draco::Encoder, for the identity check.
std::vector<char> draco_encode_public(const draco::Mesh& mesh, const DracoSettings& settings);

struct DracoDecoded {
    std::vector<amc::Vec3> positions;
    std::vector<amc::Triangle> triangles;
    double seconds = 0;               // the whole decode (file in, Draco mesh out)
    double connectivity_seconds = 0;  // inside DecodeConnectivity()
    double connectivity_cpu_seconds = 0;  // the same as this thread's CPU time
};
DracoDecoded draco_decode(const std::vector<char>& bytes);

}  // namespace amc_bench
