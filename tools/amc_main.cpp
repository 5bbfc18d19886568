// amc: the command-line tool. Each subcommand is a thin layer over the public API.
#include <amc/codec.h>
#include <amc/hierarchy.h>
#include <amc/refinement.h>

#include "stats_report.h"

#include <CLI/CLI.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace {

using namespace amc;

double seconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

bool has_extension(const std::string& path, const std::string& extension) {
    std::string ext = std::filesystem::path(path).extension().string();
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    return ext == extension;
}

void print_stats_header() {
    std::printf("%-22s %7s %9s %9s %6s %9s %9s %9s %8s\n", "model", "base_f", "faces", "nodes", "levels", "red",
                "green", "vertices", "seconds");
}

void print_stats_row(const std::string& name, const Hierarchy& h, double seconds) {
    const HierarchyStats s = compute_stats(h);
    std::printf("%-22s %7u %9u %9u %6u %9u %9u %9u %8.2f\n", name.c_str(), s.base_triangles, s.faces, s.nodes,
                s.levels, s.red_faces, s.green_faces, s.vertices, seconds);
}

// Writes the leaf mesh (or the mesh of one level) in the format named by the extension.
void write_leaf_mesh(const std::string& path, const Hierarchy& h, int level) {
    const LeafMesh leaf = extract_leaf_mesh(h, level);
    write_mesh(path, leaf.mesh, &leaf.cells);
}

void save(const std::string& path, const Hierarchy& h) {
    if (has_extension(path, ".amh")) {
        write_hierarchy(path, h);
    } else {
        write_leaf_mesh(path, h, -1);
    }
}

std::vector<uint8_t> read_bytes(const std::string& path) {
    std::ifstream file(path, std::ios::binary);
    if (!file) throw Error(ErrorCode::io, path + ": cannot open file");
    std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
    if (file.bad()) throw Error(ErrorCode::io, path + ": read error");
    return bytes;
}

// A hierarchy from a hierarchy file, or from a compressed .amc file.
Hierarchy load_hierarchy(const std::string& path, int max_level = -1) {
    if (has_extension(path, ".amc")) {
        const std::vector<uint8_t> bytes = read_bytes(path);
        DecodeOptions options;
        options.max_level = max_level;
        try {
            return decode(bytes.data(), bytes.size(), options);
        } catch (const Error& e) {
            throw e.prefixed(path);
        }
    }
    return read_hierarchy(path);
}

const char* predictor_name(GeometryPredictor p) {
    return p == GeometryPredictor::butterfly ? "butterfly" : p == GeometryPredictor::midpoint ? "midpoint" : "automatic";
}

void print_encode_stats(const std::string& name, const EncodeStats& s, double encode_seconds, double decode_seconds) {
    std::printf("%s: %lu bytes = %.3f bits/face, %.2f bits/vertex (%lu faces, %lu vertices, %lu nodes, %d levels)\n",
                name.c_str(), (unsigned long)s.total_bytes, 8.0 * s.total_bytes / double(s.faces),
                8.0 * s.total_bytes / double(s.vertices), (unsigned long)s.faces, (unsigned long)s.vertices,
                (unsigned long)s.nodes, s.levels);
    std::printf("  connectivity %lu bytes (base %lu, hierarchy %lu) = %.3f bits/face; geometry %lu bytes (base %lu, "
                "refinement %lu); header %lu, framing %lu\n",
                (unsigned long)(s.base_connectivity_bytes + s.hierarchy_bytes), (unsigned long)s.base_connectivity_bytes,
                (unsigned long)s.hierarchy_bytes, 8.0 * (s.base_connectivity_bytes + s.hierarchy_bytes) / double(s.faces),
                (unsigned long)(s.base_geometry_bytes + s.geometry_bytes), (unsigned long)s.base_geometry_bytes,
                (unsigned long)s.geometry_bytes, (unsigned long)s.header_bytes, (unsigned long)s.framing_bytes);
    std::printf("  predictor per level:");
    for (const LevelStats& level : s.per_level) {
        if (level.new_vertices > 0) std::printf(" %s", predictor_name(level.predictor));
    }
    std::printf("\n");
    if (s.max_error > 0) std::printf("  quantized: max coordinate error %.3g\n", s.max_error);
    if (encode_seconds > 0)
        std::printf("  encode %.3f s (%.2f M faces/s)", encode_seconds, s.faces / encode_seconds / 1e6);
    if (decode_seconds > 0) std::printf(", decode %.3f s (%.2f M faces/s)", decode_seconds, s.faces / decode_seconds / 1e6);
    if (encode_seconds > 0) std::printf("\n");
}

RefinementCriterion parse_criterion(const std::string& name) {
    if (name == "mean") return RefinementCriterion::mean_curvature;
    if (name == "gauss") return RefinementCriterion::gauss_curvature;
    if (name == "error") return RefinementCriterion::approximation_error;
    throw Error("unknown criterion '" + name + "' (mean, gauss, error)");
}

// The main job on the embedded default: a procedural surface, remeshed adaptively by mean
// curvature, stored, compressed bit-exactly and quantized, decoded and checked.
int run_demo(const std::string& out_dir) {
    std::filesystem::create_directories(out_dir);
    auto start = std::chrono::steady_clock::now();
    const TriangleMesh reference = make_bumpy_sphere(6);
    SurfaceRemeshOptions options;
    options.base_triangles = 300;
    options.target_faces = 100000;
    options.max_level = 7;
    Hierarchy h = remesh_adaptively(reference, options);
    const double seconds = seconds_since(start);
    print_stats_header();
    print_stats_row("bumpy_sphere_mean", h, seconds);

    const std::string problem = check_invariants(h);
    if (!problem.empty()) throw Error("demo hierarchy is invalid: " + problem);
    const std::string amh = out_dir + "/demo.amh", vtu = out_dir + "/demo.vtu", amc = out_dir + "/demo.amc";
    write_hierarchy(amh, h);
    write_leaf_mesh(vtu, h, -1);
    if (!identical(h, read_hierarchy(amh))) throw Error("demo: hierarchy read back from " + amh + " differs");
    const uint64_t raw = std::filesystem::file_size(amh);

    std::printf("\n%-12s %10s %8s %10s %10s %12s %10s %10s %s\n", "coding", "bytes", "ratio", "bits/face", "conn b/f",
                "max error", "enc Mf/s", "dec Mf/s", "check");
    const Hierarchy expected = in_decoder_order(h);
    for (int bits : {0, 16, 12}) {
        EncodeOptions encode_options;
        encode_options.quantize_bits = bits;
        EncodeStats stats;
        auto t0 = std::chrono::steady_clock::now();
        const std::vector<uint8_t> bytes = encode(h, encode_options, &stats);
        const double encode_seconds = seconds_since(t0);
        t0 = std::chrono::steady_clock::now();
        const Hierarchy back = decode(bytes.data(), bytes.size());
        const double decode_seconds = seconds_since(t0);
        // Bit-exact: identical to the input in the decoder's base order; quantized: the same
        // connectivity and every coordinate within the reported error.
        bool ok = back.node_count() == expected.node_count() && back.vertex_count() == expected.vertex_count();
        if (bits == 0) {
            ok = ok && identical(back, expected);
        } else {
            const std::vector<uint32_t> ca = canonical_vertex_order(back), cb = canonical_vertex_order(expected);
            std::vector<Vec3> pa(back.vertex_count()), pb(expected.vertex_count());
            for (size_t v = 0; v < ca.size(); ++v) if (ca[v] != 0xffffffffu) pa[ca[v]] = back.position(VertexId(v));
            for (size_t v = 0; v < cb.size(); ++v) if (cb[v] != 0xffffffffu) pb[cb[v]] = expected.position(VertexId(v));
            for (size_t i = 0; ok && i < pa.size(); ++i) {
                const Vec3 d = pa[i] - pb[i];
                ok = std::fabs(d.x) <= stats.max_error && std::fabs(d.y) <= stats.max_error && std::fabs(d.z) <= stats.max_error;
            }
            ok = ok && extract_leaf_mesh(back).mesh.triangles == extract_leaf_mesh(expected).mesh.triangles;
        }
        if (!ok) throw Error("demo: decoded hierarchy differs from the input (" + std::to_string(bits) + " bits)");
        if (bits == 0) write_file_atomically(amc, std::string(bytes.begin(), bytes.end()));
        const std::string name = bits == 0 ? "lossless" : std::to_string(bits) + " bits";
        std::printf("%-12s %10zu %7.1fx %10.3f %10.3f %12.3g %10.2f %10.2f %s\n", name.c_str(), bytes.size(),
                    double(raw) / double(bytes.size()), 8.0 * bytes.size() / double(stats.faces),
                    8.0 * double(stats.base_connectivity_bytes + stats.hierarchy_bytes) / double(stats.faces), stats.max_error,
                    stats.faces / encode_seconds / 1e6, stats.faces / decode_seconds / 1e6, bits == 0 ? "bit-exact" : "within error");
    }
    std::printf("\nwrote %s (%ju bytes, uncompressed), %s and %s\n", amh.c_str(), uintmax_t(raw), amc.c_str(), vtu.c_str());
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"amc: lossless compression of adaptive multiresolution meshes"};
    app.require_subcommand(1);

    std::string out_dir = "amc_demo";
    auto* demo = app.add_subcommand("demo", "Build, store and check a hierarchy from the embedded procedural model");
    demo->add_option("--out-dir", out_dir, "Folder for demo.amh and demo.vtu")->capture_default_str();

    std::string input, model = "surface", criterion = "mean", output, leaf_output;
    uint32_t faces = 150000, base_faces = 500;
    int max_level = 7, levels = 3, steps = 5;
    uint64_t seed = 1;
    auto* refine = app.add_subcommand("refine", "Make an adaptive red-green hierarchy");
    refine->add_option("--input", input, "Reference surface (OBJ/OFF/PLY) for --model surface");
    refine->add_option("--model", model, "surface | bumpy | lshape | front | uniform | random")->capture_default_str();
    refine->add_option("--criterion", criterion, "mean | gauss | error (surface models)")->capture_default_str();
    refine->add_option("--faces", faces, "Target number of leaves (surface, random)")->capture_default_str();
    refine->add_option("--base-faces", base_faces, "Size of the simplified base mesh")->capture_default_str();
    refine->add_option("--max-level", max_level, "Level cap")->capture_default_str();
    refine->add_option("--levels", levels, "Levels of uniform refinement")->capture_default_str();
    refine->add_option("--steps", steps, "Time steps of the moving front")->capture_default_str();
    refine->add_option("--seed", seed, "Seed of random refinement")->capture_default_str();
    refine->add_option("-o,--output", output, "Hierarchy file (.amh) or leaf mesh (.obj/.off/.ply/.vtu); "
                                              "for --model front, a prefix: <prefix>_<step>.amh");
    refine->add_option("--leaf-mesh", leaf_output, "Also write the leaf mesh (.obj/.off/.ply/.vtu)");

    std::string extract_input, extract_output;
    int extract_level = -1;
    auto* extract = app.add_subcommand("extract", "Write the leaf mesh, or the mesh of one level, of a hierarchy");
    extract->add_option("input", extract_input, "Hierarchy file (.amh)")->required();
    extract->add_option("-o,--output", extract_output, "Mesh file (.obj/.off/.ply/.vtu)")->required();
    extract->add_option("--level", extract_level, "Cut the hierarchy at this level");

    std::string info_input;
    auto* info = app.add_subcommand("info", "Describe a mesh (.obj/.off/.ply) or hierarchy (.amh) file");
    info->add_option("file", info_input, "Input file")->required();

    std::string encode_input, encode_output;
    int quantize_bits = 0;
    std::string predictor_option = "auto";
    auto* encode_cmd = app.add_subcommand("encode", "Compress a hierarchy (.amh) to an .amc file");
    encode_cmd->add_option("input", encode_input, "Hierarchy file (.amh)")->required();
    encode_cmd->add_option("-o,--output", encode_output, "Compressed file (.amc)")->required();
    encode_cmd->add_option("--quantize", quantize_bits, "Quantize coordinates to BITS per axis (lossy; 0 = bit-exact)")
        ->check(CLI::Range(0, 30));
    encode_cmd->add_option("--predictor", predictor_option, "auto | midpoint | butterfly")->capture_default_str();

    std::string decode_input, decode_output;
    int decode_level = -1;
    auto* decode_cmd = app.add_subcommand("decode", "Decompress an .amc file to a leaf mesh or hierarchy file");
    decode_cmd->add_option("input", decode_input, "Compressed file (.amc)")->required();
    decode_cmd->add_option("-o,--output", decode_output, "Leaf mesh (.obj/.off/.ply/.vtu) or hierarchy (.amh)")->required();
    decode_cmd->add_option("--level", decode_level, "Decode only up to this level (progressive)");

    std::vector<std::string> report_inputs;
    int report_runs = 3;
    auto* report = app.add_subcommand("report", "The .amc file per model: sizes by part, lossless and quantized, speeds");
    report->add_option("files", report_inputs, "Hierarchy files (.amh)")->required();
    report->add_option("--runs", report_runs, "Runs per measurement (the median is reported)")->capture_default_str();

    std::vector<std::string> stats_inputs;
    bool stats_groups = false;
    auto* stats = app.add_subcommand("stats", "Hierarchy coder statistics: the paper's Tables 1 and 2");
    stats->add_option("files", stats_inputs, "Hierarchy files (.amh)")->required();
    stats->add_flag("--groups", stats_groups, "Also print the context groups (Table 2) of each file");
    bool stats_verify = false;
    stats->add_flag("--verify", stats_verify, "Round-trip every file under all 64 switch combinations");

    CLI11_PARSE(app, argc, argv);

    try {
        if (*demo) return run_demo(out_dir);
        if (*refine) {
            auto start = std::chrono::steady_clock::now();
            std::vector<std::pair<std::string, Hierarchy>> results;
            if (model == "surface" || model == "bumpy") {
                TriangleMesh reference;
                std::string name = model;
                if (model == "surface") {
                    if (input.empty()) throw Error("--model surface needs --input MESH");
                    reference = read_mesh(input);
                    name = std::filesystem::path(input).stem().string();
                } else {
                    reference = make_bumpy_sphere(6);
                }
                SurfaceRemeshOptions options;
                options.criterion = parse_criterion(criterion);
                options.base_triangles = base_faces;
                options.target_faces = faces;
                options.max_level = max_level;
                results.emplace_back(name + "_" + criterion, remesh_adaptively(reference, options));
            } else if (model == "lshape") {
                results.emplace_back("lshape", make_l_shape_model(max_level));
            } else if (model == "front") {
                std::vector<Hierarchy> sequence = make_moving_front_sequence(steps, max_level);
                for (size_t i = 0; i < sequence.size(); ++i)
                    results.emplace_back("front_" + std::to_string(i), std::move(sequence[i]));
            } else if (model == "uniform" || model == "random") {
                Hierarchy h(input.empty() ? make_icosahedron() : read_mesh(input));
                if (model == "uniform") {
                    refine_uniformly(h, levels);
                } else {
                    refine_randomly(h, faces, max_level, seed);
                }
                results.emplace_back(model, std::move(h));
            } else {
                throw Error("unknown model '" + model + "'");
            }
            const double seconds = seconds_since(start);
            print_stats_header();
            for (auto& [name, h] : results) {
                print_stats_row(name, h, seconds / double(results.size()));
                std::string target = output;
                if (!target.empty() && results.size() > 1) target = output + "_" + name.substr(name.rfind('_') + 1) + ".amh";
                if (!target.empty()) save(target, h);
                if (!leaf_output.empty() && results.size() == 1) write_leaf_mesh(leaf_output, h, -1);
            }
            return 0;
        }
        if (*extract) {
            const Hierarchy h = load_hierarchy(extract_input);
            if (extract_level > h.depth()) {
                throw Error(extract_input + ": level " + std::to_string(extract_level) + " requested but the hierarchy has levels 0.." +
                            std::to_string(h.depth()));
            }
            write_leaf_mesh(extract_output, h, extract_level);
            return 0;
        }
        if (*encode_cmd) {
            const Hierarchy h = load_hierarchy(encode_input);
            EncodeOptions options;
            options.quantize_bits = quantize_bits;
            if (predictor_option == "midpoint") options.predictor = GeometryPredictor::midpoint;
            else if (predictor_option == "butterfly") options.predictor = GeometryPredictor::butterfly;
            else if (predictor_option != "auto") throw Error("unknown predictor '" + predictor_option + "'");
            EncodeStats stats;
            auto start = std::chrono::steady_clock::now();
            const std::vector<uint8_t> bytes = encode(h, options, &stats);
            const double seconds = seconds_since(start);
            write_file_atomically(encode_output, std::string(bytes.begin(), bytes.end()));
            print_encode_stats(encode_output, stats, seconds, 0);
            return 0;
        }
        if (*decode_cmd) {
            const Hierarchy h = load_hierarchy(decode_input, decode_level);
            save(decode_output, h);
            std::printf("%s: %u nodes, %u vertices, depth %d -> %s\n", decode_input.c_str(), h.node_count(),
                        h.vertex_count(), h.depth(), decode_output.c_str());
            return 0;
        }
        if (*report) {
            print_codec_report_header();
            for (const std::string& file : report_inputs)
                print_codec_report(std::filesystem::path(file).stem().string(), load_hierarchy(file), std::max(1, report_runs));
            return 0;
        }
        if (*stats) {
            print_table1_header();
            for (const std::string& file : stats_inputs) {
                print_table1_row(std::filesystem::path(file).stem().string(), read_hierarchy(file));
            }
            if (stats_verify) {
                for (const std::string& file : stats_inputs) {
                    const int n = verify_all_switch_combinations(load_hierarchy(file));
                    std::printf("%s: round trip identical under all %d switch combinations\n", file.c_str(), n);
                }
            }
            if (stats_groups) {
                for (const std::string& file : stats_inputs) {
                    std::printf("\n");
                    print_table2(std::filesystem::path(file).stem().string(), read_hierarchy(file));
                }
            }
            return 0;
        }
        if (*info) {
            if (has_extension(info_input, ".amc")) {
                const std::vector<uint8_t> bytes = read_bytes(info_input);
                FileInfo file;
                try {
                    file = inspect(bytes.data(), bytes.size());
                } catch (const Error& e) {
                    throw e.prefixed(info_input);
                }
                std::printf("%s: amc version %d, %s coordinates", info_input.c_str(), file.version,
                            file.quantize_bits ? "quantized" : file.single_precision ? "float32" : "float64");
                if (file.quantize_bits) std::printf(" (%d bits)", file.quantize_bits);
                std::printf("\n  base mesh %lu vertices, %lu triangles; %lu nodes, %d levels, %lu vertices, %lu faces\n",
                            (unsigned long)file.base_vertices, (unsigned long)file.base_triangles, (unsigned long)file.nodes,
                            file.levels, (unsigned long)file.vertices, (unsigned long)file.faces);
                // Decoding validates what the block checksums can not: the structure of the payloads.
                try {
                    decode(bytes.data(), bytes.size());
                } catch (const Error& e) {
                    throw e.prefixed(info_input);
                }
                std::printf("  %lu bytes: %.3f bits/face, %.2f bits/vertex; decodes: yes\n", (unsigned long)bytes.size(),
                            8.0 * bytes.size() / double(file.faces), 8.0 * bytes.size() / double(file.vertices));
                std::printf("  %-20s %10s %10s\n", "block", "offset", "bytes");
                for (const FileBlock& b : file.blocks) {
                    std::string name = b.name;
                    if (b.level >= 0) name += " " + std::to_string(b.level);
                    std::printf("  %-20s %10lu %10lu\n", name.c_str(), (unsigned long)b.offset, (unsigned long)b.size);
                }
                return 0;
            }
            if (has_extension(info_input, ".amh")) {
                const Hierarchy h = read_hierarchy(info_input);
                print_stats_header();
                print_stats_row(std::filesystem::path(info_input).filename().string(), h, 0.0);
                const HierarchyStats s = compute_stats(h);
                std::printf("nodes per level:");
                for (uint32_t n : s.nodes_per_level) std::printf(" %u", n);
                std::printf("\nleaves closed by one / two hanging nodes: %u / %u\n", s.one_hanging, s.two_hanging);
            } else {
                const TriangleMesh mesh = read_mesh(info_input);
                std::printf("%s: %zu vertices, %zu triangles, %s precision\n", info_input.c_str(), mesh.positions.size(),
                            mesh.triangles.size(), mesh.single_precision ? "single" : "double");
            }
            return 0;
        }
    } catch (const std::exception& e) {
        std::fprintf(stderr, "amc: error: %s\n", e.what());
        return 1;
    }
    return 0;
}
