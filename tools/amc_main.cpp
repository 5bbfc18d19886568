// amc: the command-line tool. Parses the command line and runs one subcommand (commands.h).
// Exit codes: 0 success, 1 an error in the data or the files, 2 a usage error.
#include "cli_files.h"
#include "commands.h"
#include "stats_report.h"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <new>

namespace {

using namespace amc;
using namespace amc::cli;

constexpr int kExitError = 1;
constexpr int kExitUsage = 2;

const char* const kExamples = R"(
Examples:
  amc demo                                   the main job on the embedded model
  amc encode mesh.ply                        -> mesh.amc (base mesh detected)
  amc encode --base coarse.obj leaf.vtu -o leaf.amc --keep-numbering
  amc decode mesh.amc                        -> mesh.ply (in the input's numbering if stored)
  amc decode mesh.amc -o coarse.vtu --level 3
  amc import leaf.off --base coarse.off -o leaf.amh
  amc refine --model lshape --max-level 10 -o lshape.amh
  amc info mesh.amc
  amc series encode run.pvd --base coarse.vtu    -> run.amcs (frames with their point and cell data)
  amc series decode run.amcs -o out.pvd          -> out.pvd + out_<k>.vtu
  amc decode run.amcs --frame 40 -o f40.vtu      one frame, from the keyframe before it
  cat mesh.ply | amc encode - > mesh.amc
  amc octree make --dim 3 --model sphere --level 7 -o sphere.amq
  amc octree decode sphere.amq -o sphere.vtu     leaves as hexahedra (or -o x.p4est with p4est)
  amc octree decode sphere.amq --conforming -o tets.vtu   tetrahedra, no hanging nodes

Exit status: 0 success, 1 error (bad input, existing output without -f), 2 usage error.
)";

void add_max_nodes(CLI::App* command, uint64_t& max_nodes) {
    command->add_option("--max-nodes", max_nodes, "Refuse files that would build more nodes (default 2^26)")
        ->check(CLI::Range(uint64_t{1}, uint64_t{1} << 32));
}

// The readers' bound on what a file may announce per byte it holds (0 lifts it, for files written
// before 2026-12-02, whose writers did not pad).
void add_per_byte_bound(CLI::App* command, const std::string& flag, const std::string& what, int64_t& bound) {
    command->add_option(flag, bound,
                        "Refuse files announcing more " + what + " per byte (default 4096; 0: no bound, for files "
                        "whose writer did not pad, before 2026-12-02)")
        ->check(CLI::Range(int64_t{0}, int64_t{1} << 40));
}

// CLI11's ranges compare, and NaN passes every comparison: a number option that must be one.
const CLI::Validator kNotNan(
    [](std::string& text) -> std::string {
        double value = 0;
        return CLI::detail::lexical_cast(text, value) && std::isnan(value) ? "NaN is not a number here" : "";
    },
    "NUMBER");

// CLI11 reads integers with strtoll / strtoull in base 0: "010" would be 8 and "0x10" 16, and an
// unsigned option takes "-1" as 2^64 - 1. Decimal only, as zstd and xz read them; zeros before
// the first digit that counts are dropped.
CLI::Validator decimal_integer(bool is_signed) {
    return CLI::Validator(
        [is_signed](std::string& text) -> std::string {
            const size_t sign = !text.empty() && (text[0] == '+' || (is_signed && text[0] == '-')) ? 1 : 0;
            if (text.size() == sign || text.find_first_not_of("0123456789", sign) != std::string::npos)
                return "'" + text + "' is not a decimal " + (is_signed ? "integer" : "number (0, 1, 2, ...)");
            text.erase(sign, std::min(text.find_first_not_of('0', sign), text.size() - 1) - sign);
            return std::string();
        },
        "");
}

// Every integer option of `app` and its subcommands, flags aside, reads decimal (decimal_integer).
void read_integers_in_decimal(CLI::App& app) {
    for (CLI::Option* option : app.get_options()) {
        const std::string type = option->get_type_name();
        const bool is_signed = type.rfind("INT", 0) == 0, is_unsigned = type.rfind("UINT", 0) == 0;
        if ((is_signed || is_unsigned) && option->get_type_size_min() > 0) option->transform(decimal_integer(is_signed));
    }
    for (CLI::App* command : app.get_subcommands([](CLI::App*) { return true; })) read_integers_in_decimal(*command);
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"amc: lossless compression of adaptive multiresolution meshes"};
    app.footer(kExamples);
    app.require_subcommand(1);
    app.fallthrough();
    app.set_version_flag("--version", std::string("amc ") + AMC_VERSION);
    GlobalOptions global;
    bool quiet = false, verbose = false;
    app.add_flag("-f,--force", global.force, "Overwrite existing output files");
    app.add_flag("-q,--quiet", quiet, "Print errors only");
    app.add_flag("-v,--verbose", verbose, "Print more");
    bool ascii = false;
    app.add_flag("--ascii", ascii, "Write PLY and VTU outputs as text (ASCII PLY carries the level and green face properties)");

    std::string out_dir = "amc_demo";
    auto* demo = app.add_subcommand("demo", "Build, compress and check a hierarchy from the embedded procedural model");
    demo->add_option("--out-dir", out_dir, "Folder for demo.amh, demo.amc and demo.vtu")->capture_default_str();

    EncodeCommand encode;
    auto* encode_cmd = app.add_subcommand("encode", "Compress a mesh or a hierarchy (.amh) to an .amc file");
    encode_cmd->add_option("input", encode.input, "Mesh (OBJ, OFF, PLY, VTU), hierarchy (.amh), or - for stdin")->required();
    encode_cmd->add_option("-o,--output", encode.output, "Compressed file (default: the input with .amc; - for stdout)");
    encode_cmd->add_option("--base", encode.base, "Base mesh of a leaf-mesh input (default: the coarsest base found)");
    encode_cmd->add_option("--base-map", encode.base_map,
                           "With --base: the input's vertex of each base vertex (text, one index a base vertex; default: by position)");
    encode_cmd->add_flag("--keep-numbering", encode.keep_numbering,
                         "Store the input mesh's vertex and face numbering, so that decode restores it");
    encode_cmd->add_option("--map", encode.map, "Write the map from the input's numbering to the decoded mesh (text)");
    encode_cmd->add_option("--quantize", encode.quantize_bits, "Quantize coordinates to BITS per axis (lossy; 0 = bit-exact)")
        ->check(CLI::Range(0, 30));
    encode_cmd->add_option("--predictor", encode.predictor, "auto | midpoint | butterfly | normal | grid (normal, --quantize only) | unit (normal frame of unit normals) | midpoint-static | butterfly-static (static tables, bit-exact only)")
        ->capture_default_str();
    encode_cmd->add_option("--chunks", encode.chunks,
                           "Cut the forest into this many chunks, each decodable alone (0: one per --chunk-faces faces, coded again in one per " +
                               std::to_string(EncodeOptions{}.min_chunk_bytes / 1024) + " KiB of code when that removes a quarter of them or more)")
        ->check(CLI::Range(0u, 1u << 30));
    encode_cmd->add_option("--chunk-faces", encode.chunk_faces, "Faces per chunk when --chunks is 0")
        ->check(CLI::Range(uint64_t{1}, uint64_t{1} << 40))
        ->capture_default_str();
    encode_cmd->add_option("--threads", encode.threads, "Threads that code chunks, or at --effort 3 and 4 the base orders' files, at once, and of the base search of a mesh input (0: every core)")
        ->check(CLI::Range(0u, 4096u));
    encode_cmd->add_option("--hierarchy-contexts", encode.hierarchy_contexts,
                           "paper (fastest decode) | mixed (smaller connectivity, slower decode, one chunk; written as the version of the mixing model that codes smallest, docs/FORMAT.md)")
        ->check(CLI::IsMember({"paper", "mixed"}))
        ->capture_default_str();
    encode_cmd->add_option("--geometry-contexts", encode.geometry_contexts,
                           "grid | roles (with --quantize: grid also tries tables split by where the prediction falls "
                           "between grid points on every level, smaller geometry, .amc version 9; bit-exact: grid also tries the frame of "
                           "unit normals, .amc version 12; roles keeps mode 3)")
        ->check(CLI::IsMember({"grid", "roles"}))
        ->capture_default_str();
    encode_cmd->add_option("--traversal", encode.traversal,
                           "auto (improved; with --hierarchy-contexts mixed the smaller of the two per file) | improved "
                           "(the paper's priority order, smallest) | naive (canonical order: about 15 % less "
                           "decode time; surface files up to 4 % larger, graded FE ones far larger; docs/CODEC.md)")
        ->check(CLI::IsMember({"auto", "improved", "naive"}))
        ->capture_default_str();
    encode_cmd->add_option("--effort", encode.effort,
                           "How hard the encoder looks: " + std::to_string(kMaxGeometryEffort) +
                               " codes every geometry mode of each level until it can not be the smallest; lower judges the "
                               "adaptive predictors from a sample of the level (faster, slightly larger); 3 and 4 also code 4 and 16 "
                               "other base orders and keep the smallest file (about 5 and 17 times effort 2's time)")
        ->check(CLI::Range(0, kMaxEffort))
        ->capture_default_str();
    encode_cmd->add_flag("--series", encode.series, "The input is a series (as 'amc series encode'; implied by a .pvd input)");

    DecodeCommand decode;
    auto* decode_cmd = app.add_subcommand("decode", "Decompress an .amc file to a leaf mesh or a hierarchy");
    decode_cmd->add_option("input", decode.input, "Compressed file (.amc), or - for stdin")->required();
    decode_cmd->add_option("-o,--output", decode.output,
                           "Leaf mesh (.obj .off .ply .vtu) or hierarchy (.amh) (default: the input with .ply; - for stdout)");
    decode_cmd->add_option("--format", decode.format, "Format for stdout: ply | obj | off | vtu | amh");
    decode_cmd->add_option("--level", decode.level, "Decode only up to this level (progressive)")->check(CLI::Range(0, kMaxLevel));
    decode_cmd->add_option("--frame", decode.frame, "A series (.amcs): only this frame")
        ->check(CLI::Range(int64_t{0}, int64_t{1} << 40));
    decode_cmd->add_flag("--canonical", decode.canonical, "Write the canonical numbering even if the file stores another");
    decode_cmd->add_flag("--partial", decode.partial,
                         "Accept a file still arriving (cut anywhere after the base mesh): decode its complete levels");
    decode_cmd->add_option("--map", decode.map, "Write the stored numbering map (input's numbering -> canonical)");
    add_max_nodes(decode_cmd, decode.max_nodes);
    decode_cmd->add_option("--threads", decode.threads, "Threads that decode chunks at once and compress a VTU output (0: every core)")
        ->check(CLI::Range(0u, 4096u));
    decode_cmd->add_option("--chunks", decode.chunks,
                           "Decode only these chunks (amc info lists them), e.g. 0,3-5: their roots' trees alone")
        ->check(CLI::Validator([](std::string& text) { return text.empty() ? "no chunk listed (e.g. 0,3-5)" : ""; }, ""));
    decode_cmd->add_option("--triangles", decode.triangles,
                           "Decode only the chunks that hold these base triangles (file order), e.g. 7,120")
        ->delimiter(',');

    ImportCommand import;
    auto* import_cmd = app.add_subcommand("import", "Turn a leaf mesh into a hierarchy file (.amh)");
    import_cmd->add_option("input", import.input, "Leaf mesh (OBJ, OFF, PLY, VTU), or - for stdin")->required();
    import_cmd->add_option("-o,--output", import.output, "Hierarchy file (default: the input with .amh)");
    import_cmd->add_option("--base", import.base, "Base mesh (default: the coarsest base found)");
    import_cmd->add_option("--base-map", import.base_map,
                           "With --base: the input's vertex of each base vertex (text, one index a base vertex; default: by position)");
    import_cmd->add_option("--map", import.map, "Write the map from the input's numbering to the hierarchy's leaf mesh");
    import_cmd->add_option("--threads", import.threads, "Threads of the base search without --base (it uses up to two; 0: every core)")
        ->check(CLI::Range(0u, 4096u));

    ExtractCommand extract;
    auto* extract_cmd = app.add_subcommand("extract", "Write the leaf mesh, or the mesh of one level, of a hierarchy");
    extract_cmd->add_option("input", extract.input, "Hierarchy (.amh) or compressed file (.amc)")->required();
    extract_cmd->add_option("-o,--output", extract.output, "Mesh file (.obj .off .ply .vtu)")->required();
    extract_cmd->add_option("--level", extract.level, "Cut the hierarchy at this level")->check(CLI::Range(0, kMaxLevel));
    add_max_nodes(extract_cmd, extract.max_nodes);

    InfoCommand info;
    auto* info_cmd = app.add_subcommand("info", "Describe a mesh, hierarchy (.amh), compressed (.amc) or series (.amcs) file");
    info_cmd->add_option("file", info.input, "Input file, or - for stdin")->required();
    add_max_nodes(info_cmd, info.max_nodes);

    RefineCommand refine;
    auto* refine_cmd = app.add_subcommand("refine", "Make an adaptive red-green hierarchy");
    refine_cmd->add_option("--input", refine.input, "Reference surface (--model surface) or base mesh (uniform, random)");
    refine_cmd->add_option("--model", refine.model, "surface | bumpy | lshape | front | uniform | random")->capture_default_str();
    refine_cmd->add_option("--criterion", refine.criterion, "mean | gauss | error (surface models)")->capture_default_str();
    refine_cmd->add_option("--faces", refine.faces, "Target number of leaf-mesh triangles (surface), of leaves (random)")
        ->capture_default_str()->check(CLI::Range(1u, 1u << 30));
    refine_cmd->add_option("--base-faces", refine.base_faces, "Size of the simplified base mesh")
        ->capture_default_str()->check(CLI::Range(4u, 1u << 24));
    refine_cmd->add_option("--max-level", refine.max_level, "Level cap")->capture_default_str()->check(CLI::Range(0, kMaxLevel));
    refine_cmd->add_option("--levels", refine.levels, "Levels of uniform refinement")->capture_default_str()->check(CLI::Range(0, kMaxLevel));
    refine_cmd->add_option("--steps", refine.steps, "Time steps of the moving front")->capture_default_str()->check(CLI::Range(1, 100000));
    refine_cmd->add_option("--seed", refine.seed, "Seed of random refinement")->capture_default_str();
    refine_cmd->add_option("--max-nodes", refine.max_nodes,
                           "Refuse to make more nodes (uniform and random: counted before they are made; front: all its "
                           "steps together; lshape is bounded by its grading) (default 2^26, what decoders read by default)")
        ->check(CLI::Range(uint64_t{1}, uint64_t{1} << 32));
    refine_cmd->add_option("-o,--output", refine.output,
                           "Hierarchy (.amh) or leaf mesh (.obj .off .ply .vtu); --model front: one file per step, "
                           "NAME_<step>.amh")->required();
    refine_cmd->add_option("--leaf-mesh", refine.leaf_output, "Also write the leaf mesh (.obj .off .ply .vtu)");
    refine_cmd->add_option("--precision", refine.precision, "Coordinates of a remesh: input (float32 if the input is) | float32 | float64")
        ->capture_default_str()->check(CLI::IsMember({"input", "float32", "float64"}));
    refine_cmd->add_flag("--no-measure", refine.no_measure,
                         "Surface models: skip measuring the remesh against its input (fold-overs, quality, distance)");

    std::vector<std::string> report_inputs;
    int report_runs = 3;
    auto* report = app.add_subcommand("report", "The .amc file per model: sizes by part, lossless and quantized, speeds");
    report->add_option("files", report_inputs, "Hierarchy files (.amh)")->required();
    report->add_option("--runs", report_runs, "Runs per measurement (the median is reported)")->capture_default_str()->check(CLI::Range(1, 1000));

    auto* series = app.add_subcommand("series", "Time series of adaptive meshes with their fields (.amcs)");
    series->require_subcommand(1);
    SeriesEncodeCommand series_encode;
    auto* series_encode_cmd = series->add_subcommand("encode", "Compress a ParaView collection (.pvd) or frame files to .amcs");
    series_encode_cmd->add_option("inputs", series_encode.inputs,
                                  "A .pvd, or frame files in order: VTU (with point and cell data), OBJ, OFF, PLY, .amh, .amc; or "
                                  ".amq forests (a forest series)")
        ->required();
    series_encode_cmd->add_option("-o,--output", series_encode.output, "Series file (default: the first input with .amcs; - for stdout)");
    series_encode_cmd->add_option("--base", series_encode.base, "Base mesh of mesh frames (default: the coarsest base found in the first frame)");
    series_encode_cmd->add_option("--keyframe", series_encode.keyframe_interval,
                                  "A keyframe every K frames, for random access (default 0: frame 0 only), besides any frame that is smaller coded alone")
        ->check(CLI::Range(0u, 1u << 30));
    series_encode_cmd->add_flag("--fixed-keyframes", series_encode.fixed_keyframes,
                                "Keyframes only where --keyframe puts them (no frame made a keyframe because it is smaller alone)");
    series_encode_cmd->add_option("--error-bound", series_encode.error_bound,
                                  "Absolute error bound of every float field (default 0: bit-exact)")
        ->check(CLI::Range(0.0, 1e300))
        ->check(kNotNan);
    series_encode_cmd->add_option("--field-bound", series_encode.field_bounds, "NAME=BOUND: a bound for one field (repeatable)");
    SeriesDecodeCommand series_decode;
    auto* series_decode_cmd = series->add_subcommand("decode", "Decompress an .amcs file to a .pvd and one VTU per frame");
    series_decode_cmd->add_option("input", series_decode.input, "Series file (.amcs), or - for stdin")->required();
    series_decode_cmd->add_option("-o,--output", series_decode.output,
                                  "Collection (.pvd; frames go to NAME_<k>.vtu beside it), or with --frame the frame's "
                                  ".vtu .obj .off .ply .amh (default: the input with .pvd, or NAME_<k>.vtu)");
    series_decode_cmd->add_option("--frame", series_decode.frame, "Only this frame (decodes from the keyframe before it)")
        ->check(CLI::Range(int64_t{0}, int64_t{1} << 40));
    series_decode_cmd->add_option("--level", series_decode.level, "The mesh of this level (point fields only)")
        ->check(CLI::Range(0, kMaxLevel));
    series_decode_cmd->add_flag("--partial", series_decode.allow_unfinished,
                                "Read the complete frames of a file whose writer has not finished");
    add_max_nodes(series_decode_cmd, series_decode.max_nodes);
    add_per_byte_bound(series_decode_cmd, "--max-nodes-per-byte", "nodes (trees of a forest series)",
                       series_decode.max_nodes_per_byte);
    SeriesInfoCommand series_info;
    auto* series_info_cmd = series->add_subcommand("info", "Frames of an .amcs file: times, sizes, meshes, fields");
    series_info_cmd->add_option("input", series_info.input, "Series file (.amcs), or - for stdin")->required();
    series_info_cmd->add_option("--frame", series_info.frame, "Describe this frame's fields (default: frame 0's)")
        ->check(CLI::Range(int64_t{0}, int64_t{1} << 40));
    series_info_cmd->add_flag("--partial", series_info.allow_unfinished,
                              "Read the complete frames of a file whose writer has not finished");
    add_max_nodes(series_info_cmd, series_info.max_nodes);
    add_per_byte_bound(series_info_cmd, "--max-nodes-per-byte", "nodes (trees of a forest series)",
                       series_info.max_nodes_per_byte);

    std::vector<std::string> stats_inputs;
    bool stats_groups = false, stats_verify = false;
    auto* stats = app.add_subcommand("stats", "Hierarchy coder statistics: the paper's Tables 1 and 2");
    stats->add_option("files", stats_inputs, "Hierarchy files (.amh)")->required();
    stats->add_flag("--groups", stats_groups, "Also print the context groups (Table 2) of each file");
    stats->add_flag("--verify", stats_verify, "Round-trip every file under all 64 switch combinations");

    auto* octree = app.add_subcommand("octree", "Quadtree and octree forests as p4est keeps them (.amq)");
    octree->require_subcommand(1);
    OctreeMakeCommand octree_make;
    auto* octree_make_cmd = octree->add_subcommand("make", "Make a forest (2:1 balanced) and write it as .amq, .vtu or .p4est");
    octree_make_cmd->add_option("--dim", octree_make.dim, "2 (quadtrees) or 3 (octrees)")->check(CLI::Range(2, 3))->capture_default_str();
    octree_make_cmd->add_option("--model", octree_make.model, "sphere, front, random or uniform")->capture_default_str();
    octree_make_cmd->add_option("--level", octree_make.level, "Finest level")->check(CLI::Range(0, 18))->capture_default_str();
    octree_make_cmd->add_option("--trees", octree_make.trees, "Brick of trees, NXxNY or NXxNYxNZ")->capture_default_str();
    octree_make_cmd->add_option("--balance", octree_make.balance, "face, edge, corner or none")->capture_default_str();
    octree_make_cmd->add_option("--seed", octree_make.seed, "Random model's seed")->capture_default_str();
    octree_make_cmd->add_option("--max-leaves", octree_make.max_leaves,
                                "Refuse to make a forest of more leaves (default 2^26, the octants readers accept by default)")
        ->check(CLI::Range(uint64_t{1}, uint64_t{1} << 32));
    octree_make_cmd->add_option("-o,--output", octree_make.output, "Output (.amq, .vtu, .p4est; - for .amq to stdout)")->required();
    octree_make_cmd->add_flag("--conforming", octree_make.conforming,
                              "VTU output as triangles / tetrahedra without hanging nodes (else quads / hexahedra)");
    OctreeEncodeCommand octree_encode;
    auto* octree_encode_cmd = octree->add_subcommand("encode", "Compress a p4est file (needs AMC_WITH_P4EST) to .amq");
    octree_encode_cmd->add_option("input", octree_encode.input, "p4est_save file (.p4est) or .amq")->required();
    octree_encode_cmd->add_option("-o,--output", octree_encode.output, "Output (default: the input with .amq)");
    octree_encode_cmd->add_option("--data", octree_encode.data,
                                  "p4est user data as leaf fields NAME:TYPE[:COMPONENTS],... in order (TYPE Int8 .. UInt64, "
                                  "Float32, Float64; default one UInt8 field p4est_data)");
    octree_encode_cmd->add_option("--vertex-step", octree_encode.vertex_step,
                                  "Coarse-mesh vertices on a grid of this step (default 0: bit-exact)")
        ->check(CLI::NonNegativeNumber)
        ->check(kNotNan);
    OctreeDecodeCommand octree_decode;
    auto* octree_decode_cmd = octree->add_subcommand("decode", "Decompress an .amq file to VTU (or p4est)");
    octree_decode_cmd->add_option("input", octree_decode.input, ".amq file, or - for stdin")->required();
    octree_decode_cmd->add_option("-o,--output", octree_decode.output, "Output .vtu or .p4est (default: the input with .vtu)");
    octree_decode_cmd->add_flag("--conforming", octree_decode.conforming,
                                "VTU output as triangles / tetrahedra without hanging nodes (else quads / hexahedra)");
    octree_decode_cmd->add_option("--level", octree_decode.level, "Progressive: only the levels up to this one")
        ->check(CLI::Range(0, 29));
    add_max_nodes(octree_decode_cmd, octree_decode.max_nodes);
    add_per_byte_bound(octree_decode_cmd, "--max-octants-per-byte", "octants", octree_decode.max_octants_per_byte);
    OctreeInfoCommand octree_info;
    auto* octree_info_cmd = octree->add_subcommand("info", "Describe an .amq file (decodes it)");
    octree_info_cmd->add_option("input", octree_info.input, ".amq file, or - for stdin")->required();
    add_max_nodes(octree_info_cmd, octree_info.max_nodes);
    add_per_byte_bound(octree_info_cmd, "--max-octants-per-byte", "octants", octree_info.max_octants_per_byte);

    try {
        read_integers_in_decimal(app);
        app.parse(argc, argv);
        if (quiet && verbose) throw CLI::ValidationError("-q and -v exclude each other");
    } catch (const CLI::ParseError& e) {
        const int code = app.exit(e);  // prints help, the version, or the error
        return code == 0 ? 0 : kExitUsage;
    }
    global.verbosity = quiet ? 0 : verbose ? 2 : 1;
    global.mesh_encoding = ascii ? MeshEncoding::ascii : MeshEncoding::binary;

    try {
        if (*demo) run_demo(out_dir, global);
        if (*encode_cmd) run_encode(encode, global);
        if (*decode_cmd) run_decode(decode, global);
        if (*import_cmd) run_import(import, global);
        if (*extract_cmd) run_extract(extract, global);
        if (*info_cmd) run_info(info, global);
        if (*series_encode_cmd) run_series_encode(series_encode, global);
        if (*series_decode_cmd) run_series_decode(read_input(series_decode.input), series_decode, global);
        if (*series_info_cmd) run_series_info(read_input(series_info.input), series_info, global);
        if (*refine_cmd) run_refine(refine, global);
        if (*octree_make_cmd) run_octree_make(octree_make, global);
        if (*octree_encode_cmd) run_octree_encode(octree_encode, global);
        if (*octree_decode_cmd) run_octree_decode(octree_decode, global);
        if (*octree_info_cmd) run_octree_info(octree_info, global);
        if (*report) {
            print_codec_report_header();
            for (const std::string& file : report_inputs)
                print_codec_report(std::filesystem::path(file).stem().string(), read_hierarchy(file), report_runs);
        }
        if (*stats) {
            print_table1_header();
            for (const std::string& file : stats_inputs) print_table1_row(std::filesystem::path(file).stem().string(), read_hierarchy(file));
            if (stats_verify) {
                for (const std::string& file : stats_inputs) {
                    const int n = verify_all_switch_combinations(read_hierarchy(file));
                    std::printf("%s: round trip identical under all %d switch combinations\n", file.c_str(), n);
                }
            }
            if (stats_groups) {
                for (const std::string& file : stats_inputs) {
                    std::printf("\n");
                    print_table2(std::filesystem::path(file).stem().string(), read_hierarchy(file));
                }
            }
        }
    } catch (const UsageError& e) {
        std::fprintf(stderr, "amc: %s\nRun 'amc --help' for usage.\n", e.what());
        return kExitUsage;
    } catch (const std::bad_alloc&) {
        // The decoders bound their allocations by the input; what remains is a machine short of memory.
        std::fprintf(stderr, "amc: error: out of memory\n");
        return kExitError;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "amc: error: %s\n", e.what());
        return kExitError;
    }
    return 0;
}
