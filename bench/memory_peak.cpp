// Peak memory of one encode or decode, amcodec against Draco (docs/BENCHMARKS.md, "Memory"). Each
// mode is its own process: it makes its input, resets the kernel's peak counter (clear_refs), then
// does the one step and prints, in MiB, the resident set before it, after it (the result still
// held) and at the peak, and the step's peak over the nodes and the faces; then the resident set
// before and after split into anonymous memory (heap, results) and file pages (the code and
// libraries the step ran, mapped as it faults them in), and the step's CPU time and minor page
// faults. Linux only.
//
//   memory_peak prepare BITS model.amh PREFIX       writes PREFIX.amc (default options) and
//                                                   PREFIX.drc (Draco's default speed 5; BITS 0:
//                                                   positions as they are)
//   memory_peak decode-amc PREFIX.amc THREADS [lean]
//                                                  decode() of the file (read into memory first);
//                                                  `lean`: with DecodeOptions::lean_memory, as
//                                                  `amc decode` decodes
//   memory_peak decode-amc-context PREFIX.amc THREADS
//                                                  the second decode() of the file through one
//                                                  DecodeContext: the step starts with the memory
//                                                  the context kept from the first (printed too)
//   memory_peak decode-draco PREFIX.drc            Draco's DecodeMeshFromBuffer of the file
//   memory_peak encode-amc BITS THREADS model.amh  encode() of the hierarchy
//   memory_peak encode-draco BITS model.amh        Draco's EncodeMeshToBuffer of the leaf mesh
#include "compare_draco.h"
#include "process_memory.h"

#include <amc/codec.h>
#include <amc/hierarchy.h>

#include <draco/compression/decode.h>
#include <draco/compression/encode.h>
#include <draco/mesh/mesh.h>

#include <sys/resource.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

namespace {

void write_file(const std::string& path, const char* data, size_t size) {
    std::ofstream(path + ".tmp", std::ios::binary).write(data, std::streamsize(size));
    std::rename((path + ".tmp").c_str(), path.c_str());
}

// Runs `step` between the peak's reset and the report; step returns the nodes and faces it holds.
template <class Step>
int measure(const char* what, Step&& step) {
    reset_peak();
    const double before = status_mib("VmRSS"), anon_before = status_mib("RssAnon"), file_before = status_mib("RssFile");
    uint64_t nodes = 0, faces = 0;
    rusage start{}, end{};
    getrusage(RUSAGE_SELF, &start);
    step(nodes, faces);
    getrusage(RUSAGE_SELF, &end);
    const double after = status_mib("VmRSS"), peak = status_mib("VmHWM");
    const double anon_after = status_mib("RssAnon"), file_after = status_mib("RssFile");
    const double step_bytes = (peak - before) * 1024 * 1024;
    std::printf("%s: before %.1f MiB, after %.1f MiB, peak %.1f MiB; the step's peak %.1f MiB = %.1f bytes per node "
                "(%llu nodes), %.1f bytes per face (%llu faces)\n",
                what, before, after, peak, peak - before, nodes ? step_bytes / double(nodes) : 0.0, (unsigned long long)nodes,
                faces ? step_bytes / double(faces) : 0.0, (unsigned long long)faces);
    std::printf("  resident before / after: anonymous %.2f / %.2f MiB, files (code, libraries) %.2f / %.2f MiB\n", anon_before,
                anon_after, file_before, file_after);
    auto seconds = [](const timeval& t) { return double(t.tv_sec) + 1e-6 * double(t.tv_usec); };
    std::printf("  the step's CPU time %.4f s (user %.4f, system %.4f), minor page faults %ld\n",
                seconds(end.ru_utime) + seconds(end.ru_stime) - seconds(start.ru_utime) - seconds(start.ru_stime),
                seconds(end.ru_utime) - seconds(start.ru_utime), seconds(end.ru_stime) - seconds(start.ru_stime),
                end.ru_minflt - start.ru_minflt);
    return 0;
}

draco::Encoder draco_encoder(int bits) {
    draco::Encoder encoder;
    encoder.SetSpeedOptions(5, 5);
    if (bits > 0) encoder.SetAttributeQuantization(draco::GeometryAttribute::POSITION, bits);
    return encoder;
}

}  // namespace

int main(int argc, char** argv) {
    const std::string mode = argc > 1 ? argv[1] : "";
    if (mode == "prepare" && argc == 5) {
        const int bits = std::atoi(argv[2]);
        const amc::Hierarchy h = amc::read_hierarchy(argv[3]);
        amc::EncodeOptions options;
        options.quantize_bits = bits;
        const std::vector<uint8_t> amc_bytes = amc::encode(h, options);
        write_file(std::string(argv[4]) + ".amc", reinterpret_cast<const char*>(amc_bytes.data()), amc_bytes.size());
        const auto mesh = amc_bench::make_draco_mesh(amc::extract_leaf_mesh(h).mesh, bits == 0);
        draco::EncoderBuffer buffer;
        if (!draco_encoder(bits).EncodeMeshToBuffer(*mesh, &buffer).ok()) return 1;
        write_file(std::string(argv[4]) + ".drc", buffer.data(), buffer.size());
        return 0;
    }
    if (mode == "decode-amc" && (argc == 4 || (argc == 5 && std::string(argv[4]) == "lean"))) {
        const std::vector<char> bytes = read_exact(argv[2]);
        amc::DecodeOptions options;
        options.threads = unsigned(std::atoi(argv[3]));
        options.lean_memory = argc == 5;
        amc::Hierarchy h;
        const uint8_t* data = reinterpret_cast<const uint8_t*>(bytes.data());
        const uint64_t faces = amc::inspect(data, bytes.size()).faces;
        return measure("decode amc", [&](uint64_t& nodes, uint64_t& face_count) {
            h = amc::decode(data, bytes.size(), options);
            nodes = h.node_count();
            face_count = faces;
        });
    }
    if (mode == "decode-amc-context" && argc == 4) {
        const std::vector<char> bytes = read_exact(argv[2]);
        amc::DecodeOptions options;
        options.threads = unsigned(std::atoi(argv[3]));
        const uint8_t* data = reinterpret_cast<const uint8_t*>(bytes.data());
        const uint64_t faces = amc::inspect(data, bytes.size()).faces;
        amc::DecodeContext context;
        const double without = status_mib("VmRSS");
        amc::decode(context, data, bytes.size(), options);  // the result freed: what stays is the context's
        std::printf("kept by the context after a decode: %.1f MiB\n", status_mib("VmRSS") - without);
        amc::Hierarchy h;
        return measure("decode amc through the context", [&](uint64_t& nodes, uint64_t& face_count) {
            h = amc::decode(context, data, bytes.size(), options);
            nodes = h.node_count();
            face_count = faces;
        });
    }
    if (mode == "decode-draco" && argc == 3) {
        const std::vector<char> bytes = read_exact(argv[2]);
        std::unique_ptr<draco::Mesh> mesh;
        return measure("decode draco", [&](uint64_t&, uint64_t& faces) {
            draco::DecoderBuffer buffer;
            buffer.Init(bytes.data(), bytes.size());
            draco::Decoder decoder;
            auto result = decoder.DecodeMeshFromBuffer(&buffer);
            if (!result.ok()) std::exit(1);
            mesh = std::move(result).value();
            faces = mesh->num_faces();
        });
    }
    if (mode == "encode-amc" && argc == 5) {
        const amc::Hierarchy h = amc::read_hierarchy(argv[4]);
        amc::EncodeOptions options;
        options.quantize_bits = std::atoi(argv[2]);
        options.threads = unsigned(std::atoi(argv[3]));
        std::vector<uint8_t> bytes;
        return measure("encode amc", [&](uint64_t& nodes, uint64_t& faces) {
            amc::EncodeStats stats;
            bytes = amc::encode(h, options, &stats);
            nodes = h.node_count();
            faces = stats.faces;
        });
    }
    if (mode == "encode-draco" && argc == 4) {
        const int bits = std::atoi(argv[2]);
        std::shared_ptr<const draco::Mesh> mesh;
        {
            const amc::Hierarchy h = amc::read_hierarchy(argv[3]);
            mesh = amc_bench::make_draco_mesh(amc::extract_leaf_mesh(h).mesh, bits == 0);
        }
        draco::EncoderBuffer buffer;
        return measure("encode draco", [&](uint64_t&, uint64_t& faces) {
            if (!draco_encoder(bits).EncodeMeshToBuffer(*mesh, &buffer).ok()) std::exit(1);
            faces = mesh->num_faces();
        });
    }
    std::fprintf(stderr,
                 "usage: memory_peak prepare BITS model.amh PREFIX | decode-amc FILE.amc THREADS [lean] | decode-draco FILE.drc |\n"
                 "       encode-amc BITS THREADS model.amh | encode-draco BITS model.amh\n");
    return 2;
}
