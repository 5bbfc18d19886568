// base_coder_bench: the base-mesh connectivity coder (src/coding/base/base_mesh_coder.h) beside Draco's
// Edgebreaker on plain triangle meshes: connectivity bits per vertex and decode speed in faces per
// second (median of --runs, one thread). Draco is timed inside DecodeConnectivity() (as in
// compare_bench), amcodec over the whole decode_base_mesh() call with the positions handed over. See docs/BASE_CODER.md.
//
//   base_coder_bench [--runs N] mesh.obj mesh.off ...
#include "bench_common.h"
#include "compare_draco.h"

#include "coding/base/base_mesh_coder.h"

#include <amc/codec.h>
#include <amc/hierarchy.h>
#include <amc/mesh.h>
#include <amc/mesh_io.h>

#include <draco/compression/decode.h>
#include <draco/compression/mesh/mesh_edgebreaker_decoder.h>
#include <draco/mesh/mesh.h>

#include <ctime>

#include <algorithm>
#include <cstdio>
#include <stdexcept>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <string>
#include <vector>

namespace {

// Draco's Edgebreaker decoder, timing DecodeConnectivity() in CPU time.
class CpuTimedEdgebreakerDecoder : public draco::MeshEdgebreakerDecoder {
public:
    double connectivity_seconds = 0;

protected:
    bool DecodeConnectivity() override {
        const double start = thread_seconds();
        const bool ok = draco::MeshEdgebreakerDecoder::DecodeConnectivity();
        connectivity_seconds = thread_seconds() - start;
        return ok;
    }
};

struct DracoSeconds {
    double connectivity = 0, whole = 0;
};
DracoSeconds draco_decode_seconds(const std::vector<char>& bytes, size_t faces) {
    const double start = thread_seconds();
    draco::DecoderBuffer buffer;
    buffer.Init(bytes.data(), bytes.size());
    CpuTimedEdgebreakerDecoder decoder;
    draco::Mesh mesh;
    if (!decoder.Decode(draco::DecoderOptions(), &buffer, &mesh).ok() || mesh.num_faces() != faces)
        throw std::runtime_error("draco decode failed");
    return {decoder.connectivity_seconds, thread_seconds() - start};
}

struct Row {
    std::string name;
    size_t vertices = 0, faces = 0;
    size_t amc_bytes = 0, single_try_bytes = 0, mode0_bytes = 0, draco_best_bytes = 0, draco_default_bytes = 0;
    double amc_decode = 0, draco_best_decode = 0, amc_encode = 0;
    // The whole mesh at 16 bits: an .amc file of the mesh as a base without refinement, and
    // Draco's best setting with 16-bit positions.
    size_t amc_file_bytes = 0, draco_file_bytes = 0;
    double amc_file_decode = 0, draco_file_decode = 0;
};

double bits_per_vertex(size_t bytes, size_t vertices) { return vertices ? 8.0 * double(bytes) / double(vertices) : 0; }

Row measure(const std::string& path, int runs) {
    const amc::TriangleMesh mesh = amc::read_mesh(path);
    Row row;
    row.name = std::filesystem::path(path).stem().string();
    row.vertices = mesh.positions.size();
    row.faces = mesh.triangles.size();

    row.amc_encode = 1e30;
    row.amc_decode = 1e30;
    row.draco_best_decode = 1e30;
    amc::BaseMeshCode code;
    for (int r = 0; r < runs; ++r) {
        const double start = thread_seconds();
        code = amc::encode_base_connectivity(mesh);
        row.amc_encode = std::min(row.amc_encode, thread_seconds() - start);
    }
    std::vector<amc::Vec3> in_decoder_order(mesh.positions.size());
    for (size_t i = 0; i < in_decoder_order.size(); ++i) in_decoder_order[i] = mesh.positions[code.vertex_order[i]];
    for (int r = 0; r < runs; ++r) {
        const double start = thread_seconds();
        const amc::DecodedBaseMesh decoded = amc::decode_base_mesh(
            code.bytes.data(), code.bytes.size(), uint32_t(mesh.positions.size()),
            [&](uint32_t vertex, const amc::BaseStencil&, const std::vector<amc::Vec3>&) { return in_decoder_order[vertex]; });
        row.amc_decode = std::min(row.amc_decode, thread_seconds() - start);
        if (decoded.triangles.size() != mesh.triangles.size()) throw std::runtime_error(path + ": decoded triangle count differs");
    }
    row.amc_bytes = code.bytes.size();
    // Mode 2 as format version 4's encoder wrote it: no search of starts and radii.
    row.single_try_bytes = code.mode == amc::BaseConnectivityMode::angle
                               ? amc::encode_base_connectivity(mesh, amc::BaseConnectivityMode::angle, false).bytes.size()
                               : code.bytes.size();
    try {
        row.mode0_bytes = amc::encode_base_connectivity(mesh, amc::BaseConnectivityMode::cut_border).bytes.size();
    } catch (const amc::Error&) {
    }

    const auto draco_mesh = amc_bench::make_draco_mesh(mesh, false);
    for (const int speed : {0, 5}) {
        const amc_bench::DracoEncoded encoded = amc_bench::draco_encode(*draco_mesh, {speed, 14});
        if (speed == 5) {
            row.draco_default_bytes = encoded.connectivity_bytes;
            continue;
        }
        row.draco_best_bytes = encoded.connectivity_bytes;
        for (int r = 0; r < runs; ++r)
            row.draco_best_decode = std::min(row.draco_best_decode, draco_decode_seconds(encoded.bytes, mesh.triangles.size()).connectivity);
    }

    const amc_bench::DracoEncoded draco_file = amc_bench::draco_encode(*draco_mesh, {0, 16});
    row.draco_file_bytes = draco_file.bytes.size();
    row.draco_file_decode = 1e30;
    for (int r = 0; r < runs; ++r)
        row.draco_file_decode = std::min(row.draco_file_decode, draco_decode_seconds(draco_file.bytes, mesh.triangles.size()).whole);
    amc::EncodeOptions options;
    options.quantize_bits = 16;
    const std::vector<uint8_t> file = amc::encode(amc::Hierarchy(mesh), options);
    row.amc_file_bytes = file.size();
    row.amc_file_decode = 1e30;
    for (int r = 0; r < runs; ++r) {
        const double start = thread_seconds();
        const amc::Hierarchy back = amc::decode(file.data(), file.size());
        row.amc_file_decode = std::min(row.amc_file_decode, thread_seconds() - start);
        if (back.root_count() != mesh.triangles.size()) throw std::runtime_error(path + ": decoded file differs");
    }
    return row;
}

}  // namespace

int main(int argc, char** argv) {
    int runs = 5;
    std::vector<std::string> files;
    for (int i = 1; i < argc; ++i) {
        if (std::strcmp(argv[i], "--runs") == 0 && i + 1 < argc) runs = std::max(1, std::atoi(argv[++i]));
        else files.push_back(argv[i]);
    }
    if (files.empty()) {
        std::fprintf(stderr, "usage: base_coder_bench [--runs N] mesh.obj ...\n");
        return 2;
    }
    std::printf("| mesh | V | F | amc bytes | amc bits/vertex | version 4's encoder bits/vertex | mode 0 bits/vertex | Draco best bits/vertex | Draco default bits/vertex "
                "| amc / Draco best | amc decode Mfaces/s | Draco best decode Mfaces/s | amc encode Mfaces/s "
                "| 16-bit file: amc bytes | Draco best bytes | amc decode Mfaces/s | Draco decode Mfaces/s |\n");
    std::printf("|---|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|\n");
    int status = 0;
    for (const std::string& file : files) {
        try {
            const Row r = measure(file, runs);
            const double f = double(r.faces) * 1e-6;
            std::printf("| %s | %zu | %zu | %zu | %.3f | %.3f | %.3f | %.3f | %.3f | %.3f | %.2f | %.2f | %.2f | %zu | %zu | %.2f | %.2f |\n", r.name.c_str(), r.vertices,
                        r.faces, r.amc_bytes, bits_per_vertex(r.amc_bytes, r.vertices),
                        bits_per_vertex(r.single_try_bytes, r.vertices), bits_per_vertex(r.mode0_bytes, r.vertices),
                        bits_per_vertex(r.draco_best_bytes, r.vertices), bits_per_vertex(r.draco_default_bytes, r.vertices),
                        double(r.amc_bytes) / double(r.draco_best_bytes), f / r.amc_decode, f / r.draco_best_decode,
                        f / r.amc_encode, r.amc_file_bytes, r.draco_file_bytes, f / r.amc_file_decode, f / r.draco_file_decode);
            std::fflush(stdout);
        } catch (const std::exception& e) {
            std::fprintf(stderr, "%s: %s\n", file.c_str(), e.what());
            status = 1;
        }
    }
    return status;
}
