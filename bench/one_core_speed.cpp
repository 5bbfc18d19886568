// One-core speed of complete files, amcodec against Draco's default (issue 29's targets;
// docs/BENCHMARKS.md, "One core"). Per model the .amc (default options) and Draco's file (its
// default speed 5; BITS 0: positions as they are) are made once; then each of RUNS rounds times,
// in turn, one amcodec encode, one Draco encode, one amcodec decode and one Draco decode, each on
// one thread, as the process's CPU time (on a shared machine wall time mostly measures the other
// processes). Prints million faces per second as median [min - max] over the rounds, and
// amcodec's speed over Draco's as the median [min - max] of the rounds' ratios: a round's two
// timings are a second apart, so its ratio sees the same machine.
//
//   one_core_speed [context] RUNS BITS model.amh ...
//                                           `context`: amcodec encodes through one
//                                           amc::EncodeContext and Draco through one encoder
//                                           object per model, kept over the rounds
//   one_core_speed decode RUNS file.amc [lean]
//                                           only decodes the file RUNS times on one thread: the
//                                           process to profile or count instructions of (`lean`:
//                                           with DecodeOptions::lean_memory, amc decode's mode)
//   one_core_speed encode RUNS BITS model.amh [EFFORT [context]]
//                                           only encodes the model RUNS times on one thread
//                                           (default options, or EncodeOptions::effort EFFORT;
//                                           `context`: through one amc::EncodeContext), and
//                                           prints the file's size and FNV-1a hash: the
//                                           process to profile; 0 runs reads the model only
#include "compare_draco.h"
#include "bench_common.h"

#include <amc/codec.h>
#include <amc/hierarchy.h>

#include <draco/compression/decode.h>
#include <draco/compression/encode.h>
#include <draco/mesh/mesh.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <vector>

namespace {

draco::Encoder draco_default_encoder(int bits) {
    draco::Encoder encoder;
    encoder.SetSpeedOptions(5, 5);
    if (bits > 0) encoder.SetAttributeQuantization(draco::GeometryAttribute::POSITION, bits);
    return encoder;
}

// Seconds of CPU time `step` takes.
template <class Step>
double timed(Step&& step) {
    const double start = cpu_seconds();
    step();
    return cpu_seconds() - start;
}

int decode_only(int runs, const char* path, bool lean) {
    std::ifstream in(path, std::ios::binary);
    const std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    amc::DecodeOptions options;
    options.threads = 1;
    options.lean_memory = lean;
    const double faces = double(amc::inspect(bytes.data(), bytes.size()).faces);
    std::vector<double> rate;
    for (int r = 0; r < runs; ++r)
        rate.push_back(faces / timed([&] { amc::decode(bytes.data(), bytes.size(), options); }) * 1e-6);
    const Range d = range_of(rate);
    std::printf("%s: decode %.2f [%.2f-%.2f] M faces/s\n", path, d.median, d.low, d.high);
    return 0;
}

int encode_only(int runs, int bits, const char* path, int effort, bool kept) {
    const amc::Hierarchy h = amc::read_hierarchy(path);
    amc::EncodeOptions options;
    options.quantize_bits = bits;
    options.effort = effort;
    options.threads = 1;
    std::vector<double> rate;
    std::vector<uint8_t> bytes;
    amc::EncodeContext context;
    for (int r = 0; r < runs; ++r)
        rate.push_back(double(h.leaf_count()) /
                       timed([&] { bytes = kept ? amc::encode(context, h, options) : amc::encode(h, options); }) * 1e-6);
    uint64_t hash = 14695981039346656037ull;  // FNV-1a: equal files, equal hashes
    for (uint8_t b : bytes) hash = (hash ^ b) * 1099511628211ull;
    if (runs == 0) return 0;
    const Range e = range_of(rate);
    std::printf("%s: %d bits, %zu bytes, FNV-1a %016llx; encode %.2f [%.2f-%.2f] M leaves/s\n", path, bits, bytes.size(),
                (unsigned long long)hash, e.median, e.low, e.high);
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    if ((argc == 4 || (argc == 5 && std::strcmp(argv[4], "lean") == 0)) && std::strcmp(argv[1], "decode") == 0)
        return decode_only(std::max(1, std::atoi(argv[2])), argv[3], argc == 5);
    if (argc >= 5 && argc <= 7 && std::strcmp(argv[1], "encode") == 0 && (argc < 7 || std::strcmp(argv[6], "context") == 0))
        return encode_only(std::max(0, std::atoi(argv[2])), std::atoi(argv[3]), argv[4],
                           argc >= 6 ? std::atoi(argv[5]) : amc::kDefaultEffort, argc == 7);
    const bool kept = argc > 1 && std::strcmp(argv[1], "context") == 0;
    if (kept) {
        --argc;
        ++argv;
    }
    if (argc < 4) {
        std::fprintf(stderr, "usage: one_core_speed [context] RUNS BITS model.amh ... | one_core_speed decode RUNS file.amc [lean] | "
                             "one_core_speed encode RUNS BITS model.amh [EFFORT [context]]\n");
        return 2;
    }
    const int runs = std::max(1, std::atoi(argv[1]));
    const int bits = std::atoi(argv[2]);
    amc::EncodeOptions encode_options;
    encode_options.quantize_bits = bits;
    encode_options.threads = 1;
    amc::DecodeOptions decode_options;
    decode_options.threads = 1;
    std::printf("| model | bits | faces | amcodec bytes | Draco bytes | encode amcodec / Draco, M faces/s | amcodec / Draco | "
                "decode amcodec / Draco, M faces/s | amcodec / Draco |\n|---|---:|---:|---:|---:|---|---:|---|---:|\n");
    for (int a = 3; a < argc; ++a) {
        const amc::Hierarchy h = amc::read_hierarchy(argv[a]);
        const std::shared_ptr<const draco::Mesh> mesh = amc_bench::make_draco_mesh(amc::extract_leaf_mesh(h).mesh, bits == 0);
        const double faces = double(mesh->num_faces());
        const std::vector<uint8_t> amc_bytes = amc::encode(h, encode_options);
        draco::EncoderBuffer draco_file;
        if (!draco_default_encoder(bits).EncodeMeshToBuffer(*mesh, &draco_file).ok()) {
            std::fprintf(stderr, "%s: Draco could not encode it\n", argv[a]);
            return 1;
        }
        std::vector<double> encode_amc, encode_draco, decode_amc, decode_draco, encode_ratio, decode_ratio;
        amc::EncodeContext context;
        draco::Encoder draco_encoder = draco_default_encoder(bits);
        for (int r = 0; r < runs; ++r) {
            const double e_amc = timed([&] { kept ? amc::encode(context, h, encode_options) : amc::encode(h, encode_options); });
            const double e_draco = timed([&] {
                draco::EncoderBuffer buffer;
                const bool ok = kept ? draco_encoder.EncodeMeshToBuffer(*mesh, &buffer).ok()
                                     : draco_default_encoder(bits).EncodeMeshToBuffer(*mesh, &buffer).ok();
                if (!ok) std::exit(1);
            });
            const double d_amc = timed([&] {  // the result freed inside: each decode starts alike
                const amc::Hierarchy back = amc::decode(amc_bytes.data(), amc_bytes.size(), decode_options);
                if (back.node_count() != h.node_count()) std::exit(1);
            });
            const double d_draco = timed([&] {
                draco::DecoderBuffer buffer;
                buffer.Init(draco_file.data(), draco_file.size());
                draco::Decoder decoder;
                auto result = decoder.DecodeMeshFromBuffer(&buffer);
                if (!result.ok() || double(result.value()->num_faces()) != faces) std::exit(1);
            });
            encode_amc.push_back(faces / e_amc * 1e-6);
            encode_draco.push_back(faces / e_draco * 1e-6);
            decode_amc.push_back(faces / d_amc * 1e-6);
            decode_draco.push_back(faces / d_draco * 1e-6);
            encode_ratio.push_back(e_draco / e_amc);
            decode_ratio.push_back(d_draco / d_amc);
        }
        const Range ea = range_of(encode_amc), ed = range_of(encode_draco), er = range_of(encode_ratio);
        const Range da = range_of(decode_amc), dd = range_of(decode_draco), dr = range_of(decode_ratio);
        std::printf("| %s | %d | %.0f | %zu | %zu | %.2f [%.2f-%.2f] / %.2f [%.2f-%.2f] | %.2f [%.2f-%.2f] | "
                    "%.2f [%.2f-%.2f] / %.2f [%.2f-%.2f] | %.2f [%.2f-%.2f] |\n",
                    std::filesystem::path(argv[a]).stem().string().c_str(), bits, faces, amc_bytes.size(), draco_file.size(),
                    ea.median, ea.low, ea.high, ed.median, ed.low, ed.high, er.median, er.low, er.high, da.median, da.low,
                    da.high, dd.median, dd.low, dd.high, dr.median, dr.low, dr.high);
        std::fflush(stdout);
    }
    return 0;
}
