// compare_bench: amcodec side by side with Draco, meshoptimizer, zstd and xz on the leaf meshes of a
// corpus of hierarchies (.amh): connectivity sizes (the paper's Table 3), complete meshes at 12 and
// 16 bits and lossless, encode and decode speeds (median of --runs, one thread, all in one
// process), and a check of every decoded result against its input. See docs/BENCHMARKS.md.
// With --kept-encoders, amcodec's complete files are encoded through one EncodeContext and Draco's
// through one encoder object per model and mode, kept over the runs (as a caller coding a series
// keeps them); without it every encode starts afresh.
// With --faults FILE, every timed encode of a complete mesh (amcodec's and Draco's) writes a line
// "coder model bits minor-page-faults seconds" there: the fresh pages an encode took in this
// process (docs/BENCHMARKS.md, "One-core encode, twenty-first step").
// A mesh file (OBJ, OFF, PLY, VTU) is a model as users have it: imported over the coarsest base
// found in it (import_mesh), which for an irregular mesh is mostly the mesh itself.
//
//   compare_bench [--runs N] [--kept-encoders] [--faults FILE] [--csv FILE] [--markdown FILE] corpus/*.amh mesh.obj ...
#include "bench_common.h"
#include "compare_check.h"
#include "compare_draco.h"
#include "compare_general.h"
#include "compare_report.h"

#include <amc/codec.h>
#include <amc/hierarchy.h>
#include <amc/hierarchy_coder.h>
#include <amc/import.h>
#include <amc/mesh_io.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include <sys/resource.h>

namespace amc_bench {

namespace {

FILE* fault_log = nullptr;  // --faults

// step(), and with --faults its minor page faults and seconds as a line of the log.
template <class Step>
void logged_encode(const char* coder, const std::string& model, int bits, Step&& step) {
    if (fault_log == nullptr) {
        step();
        return;
    }
    rusage before, after;
    getrusage(RUSAGE_THREAD, &before);
    const Clock::time_point start = Clock::now();
    step();
    const double seconds = seconds_since(start);
    getrusage(RUSAGE_THREAD, &after);
    std::fprintf(fault_log, "%s %s %d %ld %.6f\n", coder, model.c_str(), bits, after.ru_minflt - before.ru_minflt, seconds);
}

// Runs `step` `runs` times and returns the median time; `step` keeps its last output itself.
// `release`, untimed before each step, gives back the output of the step before: a decode then
// reuses that memory, as a program that decodes file after file does, instead of having fresh
// pages faulted in while the last output is still held (12-16 us a 4 KiB page on the project's VM:
// on uniform that set the 12-bit figure, docs/BENCHMARKS.md "One core").
template <class Step, class Release>
double median_seconds(int runs, Step&& step, Release&& release) {
    std::vector<double> samples;
    for (int r = 0; r < runs; ++r) {
        release();
        const Clock::time_point start = Clock::now();
        step();
        samples.push_back(seconds_since(start));
    }
    return median(samples);
}
template <class Step>
double median_seconds(int runs, Step&& step) {
    return median_seconds(runs, step, [] {});
}

struct Model {
    std::string name;
    amc::Hierarchy hierarchy;
    amc::Hierarchy expected;  // as the .amc decoder returns it (in_decoder_order)
    amc::TriangleMesh leaf;   // the conforming leaf mesh every peer codes
    std::vector<uint32_t> indices;
};

Result make_result(const Model& m, const std::string& coder, const std::string& payload) {
    Result r;
    r.model = m.name;
    r.faces = m.leaf.triangles.size();
    r.vertices = m.leaf.positions.size();
    r.nodes = m.hierarchy.node_count();
    r.base_triangles = m.hierarchy.root_count();
    r.coder = coder;
    r.payload = payload;
    return r;
}

std::string check_text(const MeshCheck& check) { return check.ok ? "ok" : check.problem; }

// The payload id of a complete mesh with positions quantized to `bits` (0: lossless).
std::string mesh_payload(int bits) { return bits == 0 ? "mesh-lossless" : "mesh-" + std::to_string(bits); }

// ---- general-purpose coders over the index buffer ----------------------------------------------

void measure_general_coders(const Model& m, int runs, std::vector<Result>& out) {
    const size_t raw_size = m.indices.size() * sizeof(uint32_t);
    Result raw = make_result(m, "raw", "connectivity");
    raw.bytes = raw_size;
    raw.check = "computed";
    out.push_back(raw);

    struct ByteCoder {
        const char* id;
        std::vector<uint8_t> (*encode)(const void*, size_t);
        std::vector<uint8_t> (*decode)(const std::vector<uint8_t>&, size_t);
    };
    const ByteCoder byte_coders[] = {
        {"zstd-19", [](const void* d, size_t n) { return zstd_compress(d, n, 19); },
         [](const std::vector<uint8_t>& c, size_t) { return zstd_decompress(c); }},
        {"xz-9", [](const void* d, size_t n) { return xz_compress(d, n, 9); },
         [](const std::vector<uint8_t>& c, size_t n) { return xz_decompress(c, n); }},
    };
    for (const ByteCoder& coder : byte_coders) {
        Result r = make_result(m, coder.id, "connectivity");
        std::vector<uint8_t> packed, unpacked;
        r.encode_seconds = median_seconds(runs, [&] { packed = coder.encode(m.indices.data(), raw_size); });
        r.decode_seconds = median_seconds(runs, [&] { unpacked = coder.decode(packed, raw_size); }, [&] { unpacked = {}; });
        r.bytes = packed.size();
        const bool same = unpacked.size() == raw_size && std::memcmp(unpacked.data(), m.indices.data(), raw_size) == 0;
        r.check = same ? "ok" : "decoded index buffer differs";
        out.push_back(r);
    }

    const size_t vertex_count = m.leaf.positions.size();
    for (const bool with_zstd : {false, true}) {
        Result r = make_result(m, with_zstd ? "meshopt+zstd" : "meshopt", "connectivity");
        std::vector<uint8_t> packed;
        std::vector<uint32_t> indices;
        r.encode_seconds = median_seconds(runs, [&] {
            packed = meshopt_encode(m.indices, vertex_count);
            if (with_zstd) packed = zstd_compress(packed.data(), packed.size(), 19);
        });
        r.decode_seconds = median_seconds(
            runs,
            [&] {
                indices = with_zstd ? meshopt_decode(zstd_decompress(packed), m.indices.size()) : meshopt_decode(packed, m.indices.size());
            },
            [&] { indices = {}; });
        r.bytes = packed.size();
        std::vector<amc::Triangle> faces(indices.size() / 3);
        for (size_t f = 0; f < faces.size(); ++f) faces[f] = {indices[3 * f], indices[3 * f + 1], indices[3 * f + 2]};
        r.check = check_text(check_same_faces(m.leaf.triangles, faces));
        out.push_back(r);
    }
}

// ---- Draco ----------------------------------------------------------------------------------

double largest_extent(const amc::TriangleMesh& mesh) {
    amc::Vec3 lo = mesh.positions.at(0), hi = lo;
    for (const amc::Vec3& p : mesh.positions) {
        lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
        hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
    }
    return std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
}

void measure_draco(const Model& m, int runs, bool kept_encoders, std::vector<Result>& out) {
    const auto lossy_input = make_draco_mesh(m.leaf, false);
    const auto exact_input = make_draco_mesh(m.leaf, true);
    const double extent = largest_extent(m.leaf);
    for (const int speed : {5, 0}) {
        const std::string coder = speed == 0 ? "draco-best" : "draco-default";
        Result connectivity = make_result(m, coder, "connectivity");
        std::vector<double> connectivity_encode, connectivity_decode;
        std::vector<std::string> problems;
        std::string note;  // what a mode's check tolerated, for the connectivity row
        DracoDecoded lossless;  // the checked lossless decode, the reference for the quantized ones
        bool lossless_ok = false;
        for (const int bits : {0, 16, 12}) {
            const DracoSettings settings{speed, bits};
            const draco::Mesh& input = bits == 0 ? *exact_input : *lossy_input;
            Result r = make_result(m, coder, mesh_payload(bits));
            DracoEncoded encoded;
            DracoDecoded decoded;
            std::vector<double> encode_times, decode_times;
            try {
                {
                    DracoKeptEncoder kept;  // given back before the decodes are timed
                    for (int run = 0; run < runs; ++run) {
                        logged_encode(coder.c_str(), m.name, bits,
                                      [&] { encoded = draco_encode(input, settings, kept_encoders ? &kept : nullptr); });
                        encode_times.push_back(encoded.seconds);
                        connectivity_encode.push_back(encoded.connectivity_seconds);
                    }
                }
                for (int run = 0; run < runs; ++run) {
                    decoded = {};  // as median_seconds' release
                    decoded = draco_decode(encoded.bytes);
                    decode_times.push_back(decoded.seconds);
                    connectivity_decode.push_back(decoded.connectivity_seconds);
                }
            } catch (const std::exception& e) {
                r.check = e.what();
                problems.push_back(r.payload + ": " + r.check);
                out.push_back(r);
                continue;
            }
            r.bytes = encoded.bytes.size();
            r.connectivity_bytes = encoded.connectivity_bytes;
            r.encode_seconds = median(encode_times);
            r.decode_seconds = median(decode_times);
            MeshCheck check;
            if (bits == 0) {
                check = check_decoded_mesh(m.leaf, decoded.positions, decoded.triangles);
                lossless_ok = check.ok;
                lossless = decoded;
            } else {
                // Draco quantizes over the largest side of the bounding box in 2^bits - 1 steps; a
                // vertex moves by half a step, plus float32 rounding: one step is the bound checked.
                const double step = extent / double((1u << bits) - 1);
                check = lossless_ok ? check_same_mesh_within(lossless.positions, lossless.triangles, decoded.positions,
                                                             decoded.triangles, step,
                                                             "the lossless decode of the same connectivity code")
                                    : MeshCheck{false, "no checked lossless decode to compare with"};
            }
            r.max_error = check.max_error;
            r.check = check_text(check);
            if (check.ok && check.split_vertices > 0) {
                r.note = std::to_string(check.split_vertices) + " more vertices decoded than coded (Draco splits vertices whose faces form several fans)";
                note = r.note;
            }
            if (check.ok && bits == 12 && encoded.bytes != draco_encode_public(input, settings))
                r.check = "file differs from draco::Encoder::EncodeMeshToBuffer's";
            if (r.check != "ok") problems.push_back(r.payload + ": " + r.check);
            // The connectivity code does not depend on the positions: the same in every mode.
            if (connectivity.bytes == 0) connectivity.bytes = encoded.connectivity_bytes;
            if (connectivity.bytes != encoded.connectivity_bytes) problems.push_back(r.payload + ": connectivity size differs");
            out.push_back(r);
        }
        connectivity.encode_seconds = median(connectivity_encode);
        connectivity.decode_seconds = median(connectivity_decode);
        connectivity.check = problems.empty() ? "ok" : problems.front();
        connectivity.note = note;
        out.push_back(connectivity);
    }
}

// ---- amcodec ----------------------------------------------------------------------------------

struct AmcMode {
    const char* coder;
    amc::HierarchyCoderOptions options;
};

std::vector<AmcMode> amc_connectivity_modes() {
    // The naive coder: every switch off.
    const amc::HierarchyCoderOptions none{false, false, false, false, false, amc::Traversal::naive};
    amc::HierarchyCoderOptions paper_naive;  // the paper's complete method ...
    paper_naive.traversal = amc::Traversal::naive;
    amc::HierarchyCoderOptions paper_improved;
    paper_improved.traversal = amc::Traversal::improved;
    return {{"naive-hierarchy", none},
            {"amc-paper-naive", paper_naive},
            {"amc-paper-improved", paper_improved},
            {"amc-best", amc::EncodeOptions{}.hierarchy}};
}

void measure_amcodec(const Model& m, int runs, bool kept_encoders, std::vector<Result>& out) {
    const amc::TriangleMesh expected_leaf = amc::extract_leaf_mesh(m.expected).mesh;
    uint64_t base_connectivity_bytes = 0;

    // Complete files, default options: lossless, 16 and 12 bits.
    for (const int bits : {0, 16, 12}) {
        Result r = make_result(m, "amc-best", mesh_payload(bits));
        amc::EncodeOptions options;
        options.quantize_bits = bits;
        options.threads = 1;  // one core, as Draco (the base search and checks would take both)
        amc::DecodeOptions decode_options;
        decode_options.threads = 1;
        amc::EncodeStats stats;
        std::vector<uint8_t> file;
        amc::Hierarchy back;
        {
            amc::EncodeContext context;  // its memory given back before the decodes are timed
            r.encode_seconds = median_seconds(runs, [&] {
                logged_encode("amc-best", m.name, bits, [&] {
                    file = kept_encoders ? amc::encode(context, m.hierarchy, options, &stats) : amc::encode(m.hierarchy, options, &stats);
                });
            });
        }
        r.decode_seconds = median_seconds(runs, [&] { back = amc::decode(file.data(), file.size(), decode_options); }, [&] { back = {}; });
        r.bytes = file.size();
        r.max_error = stats.max_error;
        // In the file, hierarchy symbols and positions share one arithmetic code per level; the
        // library counts the hierarchy part up to the byte where it ended.
        r.connectivity_bytes = stats.base_connectivity_bytes + stats.hierarchy_bytes;
        base_connectivity_bytes = stats.base_connectivity_bytes;
        if (bits == 0) {
            r.check = amc::identical(back, m.expected) ? "ok" : "decoded hierarchy not identical to the input";
        } else {
            // The same conforming mesh (canonical vertex order on both sides: the base order depends
            // on the quantized base positions), every coordinate within the error the encoder reported.
            const amc::TriangleMesh got = amc::extract_leaf_mesh(back).mesh;
            const amc::TriangleMesh expected_quantized = amc::extract_leaf_mesh(amc::in_decoder_order(m.hierarchy, options)).mesh;
            r.check = check_text(check_same_mesh_within(expected_quantized.positions, expected_quantized.triangles, got.positions,
                                                        got.triangles, stats.max_error, "the input's leaf mesh"));
        }
        out.push_back(r);
    }

    // Issue 30's mixing mode (opt-in, `--hierarchy-contexts mixed`): its hierarchy part of a
    // bit-exact file (its contexts read the decoded positions, so it has no connectivity-only
    // stream). Not timed: the file's times are mostly geometry.
    {
        Result r = make_result(m, "amc-mixed", "connectivity");
        amc::EncodeOptions options;
        options.hierarchy_contexts = amc::HierarchyContexts::mixed;
        amc::EncodeStats stats;
        const std::vector<uint8_t> file = amc::encode(m.hierarchy, options, &stats);
        r.bytes = stats.base_connectivity_bytes + stats.hierarchy_bytes;
        r.check = amc::identical(amc::decode(file.data(), file.size()), m.expected) ? "ok" : "decoded hierarchy not identical to the input";
        out.push_back(r);
    }

    // As users have it: only the leaf mesh, imported over the coarsest base found in it, then
    // coded; the import is timed with the encoder.
    {
        Result r = make_result(m, "amc-imported", "connectivity");
        amc::Hierarchy imported, back;
        std::vector<uint8_t> stream;
        amc::EncodeStats stats;
        r.encode_seconds = median_seconds(runs, [&] {
            imported = amc::in_decoder_order(amc::import_mesh(m.leaf, m.name, 1).hierarchy);  // one core, as Draco
            stream = amc::encode_hierarchy(imported, amc::EncodeOptions{}.hierarchy);
        });
        r.decode_seconds = median_seconds(runs, [&] { back = amc::decode_hierarchy(imported.base(), stream.data(), stream.size()); }, [&] { back = {}; });
        amc::encode(imported, {}, &stats);
        r.bytes = stats.base_connectivity_bytes + stream.size();
        r.base_triangles = imported.root_count();
        // The stream holds connectivity only (the decoded vertices sit at midpoints), so the
        // decoded leaf mesh's triangles are compared, as for the other connectivity rows.
        const amc::TriangleMesh input_again = amc::extract_leaf_mesh(imported).mesh;
        if (amc::extract_leaf_mesh(back).mesh.triangles != input_again.triangles)
            r.check = "decoded leaf mesh connectivity differs from the imported one";
        else if (input_again.triangles.size() != m.leaf.triangles.size())
            r.check = "imported leaf mesh differs from the input";
        else
            r.check = "ok";
        out.push_back(r);
    }

    // 1 bit per node: what the forest costs before any coding.
    Result one_bit = make_result(m, "one-bit-per-node", "connectivity");
    one_bit.bytes = base_connectivity_bytes + (m.hierarchy.node_count() + 7) / 8;
    one_bit.check = "computed";
    out.push_back(one_bit);

    // Connectivity alone: base connectivity (as the .amc file codes it) plus the hierarchy stream
    // of encode_hierarchy, which decodes on its own over the shared base mesh.
    for (const AmcMode& mode : amc_connectivity_modes()) {
        Result r = make_result(m, mode.coder, "connectivity");
        std::vector<uint8_t> stream;
        amc::Hierarchy back;
        r.encode_seconds = median_seconds(runs, [&] { stream = amc::encode_hierarchy(m.expected, mode.options); });
        r.decode_seconds = median_seconds(runs, [&] { back = amc::decode_hierarchy(m.expected.base(), stream.data(), stream.size()); }, [&] { back = {}; });
        r.bytes = base_connectivity_bytes + stream.size();
        const amc::TriangleMesh got = amc::extract_leaf_mesh(back).mesh;
        r.check = got.triangles == expected_leaf.triangles ? "ok" : "decoded leaf mesh connectivity differs";
        out.push_back(r);
    }
}

Model load_model(const std::string& path) {
    Model m;
    m.name = std::filesystem::path(path).stem().string();
    if (std::filesystem::path(path).extension() == ".amh") {
        m.hierarchy = amc::read_hierarchy(path);
    } else {
        m.hierarchy = amc::import_mesh(amc::read_mesh(path), path).hierarchy;
        m.name += " (mesh)";
    }
    m.expected = amc::in_decoder_order(m.hierarchy);
    m.leaf = amc::extract_leaf_mesh(m.hierarchy).mesh;
    m.indices.reserve(3 * m.leaf.triangles.size());
    for (const amc::Triangle& t : m.leaf.triangles) m.indices.insert(m.indices.end(), t.begin(), t.end());
    return m;
}

int run(int argc, char** argv) {
    int runs = 3;
    bool kept_encoders = false;
    std::string csv_path, markdown_path, fault_path;
    std::vector<std::string> inputs;
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        auto value = [&]() -> std::string {
            if (i + 1 >= argc) throw std::runtime_error(arg + " needs a value");
            return argv[++i];
        };
        if (arg == "--runs") runs = std::max(1, std::stoi(value()));
        else if (arg == "--kept-encoders") kept_encoders = true;
        else if (arg == "--faults") fault_path = value();
        else if (arg == "--csv") csv_path = value();
        else if (arg == "--markdown") markdown_path = value();
        else if (arg.rfind("--", 0) == 0) throw std::runtime_error("unknown option " + arg);
        else inputs.push_back(arg);
    }
    if (inputs.empty()) {
        std::fprintf(stderr, "usage: compare_bench [--runs N] [--kept-encoders] [--faults FILE] [--csv FILE] [--markdown FILE] model.amh...\n");
        return 2;
    }
    if (!fault_path.empty()) {
        fault_log = std::fopen(fault_path.c_str(), "w");
        if (fault_log == nullptr) throw std::runtime_error("can not write " + fault_path);
    }
    std::vector<Result> results;
    for (const std::string& path : inputs) {
        const Clock::time_point start = Clock::now();
        const Model m = load_model(path);
        const size_t first = results.size();
        measure_general_coders(m, runs, results);
        measure_draco(m, runs, kept_encoders, results);
        measure_amcodec(m, runs, kept_encoders, results);
        int failed = 0;
        for (size_t i = first; i < results.size(); ++i) failed += !passed(results[i]);
        std::fprintf(stderr, "%-18s %7zu faces  %5.1f s  %s\n", m.name.c_str(), m.leaf.triangles.size(), seconds_since(start),
                     failed ? "SOME CHECKS FAILED" : "all checks passed");
    }
    if (fault_log != nullptr) std::fclose(fault_log);
    if (!csv_path.empty()) write_csv(csv_path, results);
    if (!markdown_path.empty()) write_markdown(markdown_path, results, runs);
    return 0;
}

}  // namespace

}  // namespace amc_bench

int main(int argc, char** argv) {
    try {
        return amc_bench::run(argc, argv);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "compare_bench: %s\n", e.what());
        return 1;
    }
}
