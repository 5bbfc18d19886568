// `amc encode` and `amc decode`: files in, .amc out, and back.
#include "cli_files.h"
#include "commands.h"
#include "mesh_import.h"
#include "progress.h"

#include <amc/codec.h>
#include <amc/mesh_io.h>
#include <amc/numbering.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <stdexcept>

namespace amc::cli {

namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

const char* predictor_name(GeometryPredictor p) {
    return p == GeometryPredictor::butterfly      ? "butterfly"
           : p == GeometryPredictor::midpoint     ? "midpoint"
           : p == GeometryPredictor::normal_frame ? "normal"
           : p == GeometryPredictor::normal_frame_grid ? "grid"
           : p == GeometryPredictor::unit_normal_frame ? "unit"
           : p == GeometryPredictor::midpoint_static ? "midpoint-static"
           : p == GeometryPredictor::butterfly_static ? "butterfly-static"
                                                  : "automatic";
}

GeometryPredictor parse_predictor(const std::string& name) {
    if (name == "auto") return GeometryPredictor::automatic;
    if (name == "midpoint") return GeometryPredictor::midpoint;
    if (name == "butterfly") return GeometryPredictor::butterfly;
    if (name == "normal") return GeometryPredictor::normal_frame;
    if (name == "grid") return GeometryPredictor::normal_frame_grid;
    if (name == "unit") return GeometryPredictor::unit_normal_frame;
    if (name == "midpoint-static") return GeometryPredictor::midpoint_static;
    if (name == "butterfly-static") return GeometryPredictor::butterfly_static;
    throw UsageError("--predictor: unknown predictor '" + name +
                     "' (auto, midpoint, butterfly, normal, grid, unit, midpoint-static, butterfly-static)");
}

// "0,3-5" -> 0, 3, 4, 5 (increasing, each once), of a file of `chunk_count` chunks (a range is
// checked against it before it is expanded: "0-1073741823" would list a billion chunks).
std::vector<uint32_t> parse_chunk_list(const std::string& text, uint32_t chunk_count) {
    std::vector<uint32_t> out;
    size_t pos = 0;
    while (pos <= text.size()) {
        const size_t comma = std::min(text.find(',', pos), text.size());
        const std::string item = text.substr(pos, comma - pos);
        const size_t dash = item.find('-');
        try {
            size_t used = 0;
            const unsigned long first = std::stoul(item.substr(0, dash), &used);
            if (used != item.substr(0, dash).size()) throw std::invalid_argument(item);
            unsigned long last = first;
            if (dash != std::string::npos) {
                last = std::stoul(item.substr(dash + 1), &used);
                if (used != item.size() - dash - 1) throw std::invalid_argument(item);
            }
            if (last < first || last >= (1ul << 30)) throw std::invalid_argument(item);
            if (last >= chunk_count)
                throw Error("chunk " + std::to_string(last) + " is not in the file (it has " + std::to_string(chunk_count) +
                            (chunk_count == 1 ? " chunk)" : " chunks)"));
            for (unsigned long c = first; c <= last; ++c) out.push_back(uint32_t(c));
        } catch (const std::logic_error&) {
            throw UsageError("--chunks: '" + item + "' is not a chunk number or range (e.g. 0,3-5)");
        }
        pos = comma + 1;
    }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
}

// Summaries go to stderr when the data goes to stdout.
std::FILE* report_stream(const std::string& output) { return output == "-" ? stderr : stdout; }

void print_encode_stats(std::FILE* out, const std::string& name, const EncodeStats& s, double seconds) {
    std::fprintf(out, "%s: %lu bytes = %.3f bits/face, %.2f bits/vertex (%lu faces, %lu vertices, %lu nodes, %d levels)\n",
                 name.c_str(), (unsigned long)s.total_bytes, 8.0 * s.total_bytes / double(s.faces),
                 8.0 * s.total_bytes / double(s.vertices), (unsigned long)s.faces, (unsigned long)s.vertices,
                 (unsigned long)s.nodes, s.levels);
    std::fprintf(out,
                 "  connectivity %lu bytes (base %lu, hierarchy %lu) = %.3f bits/face; geometry %lu bytes (base %lu, "
                 "refinement %lu); header %lu, framing %lu",
                 (unsigned long)(s.base_connectivity_bytes + s.hierarchy_bytes), (unsigned long)s.base_connectivity_bytes,
                 (unsigned long)s.hierarchy_bytes, 8.0 * (s.base_connectivity_bytes + s.hierarchy_bytes) / double(s.faces),
                 (unsigned long)(s.base_geometry_bytes + s.geometry_bytes), (unsigned long)s.base_geometry_bytes,
                 (unsigned long)s.geometry_bytes, (unsigned long)s.header_bytes, (unsigned long)s.framing_bytes);
    if (s.numbering_bytes > 0) std::fprintf(out, "; numbering %lu", (unsigned long)s.numbering_bytes);
    std::fprintf(out, "\n  predictor per level:");
    for (const LevelStats& level : s.per_level) {
        if (level.new_vertices > 0) std::fprintf(out, " %s", predictor_name(level.predictor));
    }
    std::fprintf(out, "\n");
    if (s.max_error > 0) std::fprintf(out, "  quantized: max coordinate error %.3g\n", s.max_error);
    std::fprintf(out, "  encode %.3f s (%.2f M faces/s)\n", seconds, s.faces / seconds / 1e6);
}

}  // namespace

void run_encode(const EncodeCommand& command, const GlobalOptions& global) {
    if (command.series || is_pvd(command.input)) {
        if (command.keep_numbering || !command.map.empty() || command.quantize_bits != 0 || command.predictor != "auto" ||
            command.hierarchy_contexts != "paper" || command.geometry_contexts != "grid" ||
            (command.traversal != "auto" && command.traversal != "improved"))
            throw UsageError("--keep-numbering, --map, --quantize, --predictor, --hierarchy-contexts, --geometry-contexts and "
                             "--traversal do not apply to a series");
        SeriesEncodeCommand series;
        series.inputs = {command.input};
        series.output = command.output;
        series.base = command.base;
        run_series_encode(series, global);
        return;
    }
    Progress progress(global.verbosity > 0);
    progress.phase("reading " + command.input);
    InputFile input = read_input(command.input);
    const std::string output = command.output.empty() ? default_output(command.input, ".amc") : command.output;
    const OutputKind kind = output_kind(output);
    if (output != "-" && (kind == OutputKind::mesh || kind == OutputKind::hierarchy))
        throw UsageError("encode writes compressed .amc data, but " + output + " names a " +
                         (kind == OutputKind::mesh ? "mesh" : "hierarchy") + " file (use .amc)");
    if (input.kind == FileKind::compressed) throw Error(input.name + ": already compressed .amc data");
    if (!command.base.empty() && input.kind != FileKind::mesh)
        throw UsageError("--base applies to a mesh input; " + input.name + " is " + file_kind_name(input.kind));
    if (!command.base_map.empty() && command.base.empty()) throw UsageError("--base-map needs --base");
    if ((command.keep_numbering || !command.map.empty()) && input.kind != FileKind::mesh)
        throw UsageError("--keep-numbering and --map apply to a mesh input; " + input.name + " is " +
                         file_kind_name(input.kind) + ", which is numbered canonically already");
    if (!global.force && !command.map.empty()) refuse_existing(command.map);

    EncodeOptions options;
    options.quantize_bits = command.quantize_bits;
    options.predictor = parse_predictor(command.predictor);
    options.grid_contexts = command.geometry_contexts == "grid";  // bit-exact files have no grid: ignored there
    options.unit_normals = command.geometry_contexts == "grid";   // quantized files ignore it
    if (options.predictor == GeometryPredictor::normal_frame_grid && options.quantize_bits == 0)
        throw UsageError("--predictor grid needs --quantize (grid points exist only on a grid)");
    if ((options.predictor == GeometryPredictor::midpoint_static || options.predictor == GeometryPredictor::butterfly_static) &&
        options.quantize_bits != 0)
        throw UsageError("--predictor midpoint-static and butterfly-static are for bit-exact files (without --quantize)");
    options.effort = command.effort;
    options.chunks = command.chunks;
    options.chunk_faces = command.chunk_faces;
    options.threads = command.threads;
    options.hierarchy_contexts = command.hierarchy_contexts == "mixed" ? HierarchyContexts::mixed : HierarchyContexts::paper;
    options.hierarchy.traversal = command.traversal == "naive" ? Traversal::naive : Traversal::improved;
    options.choose_traversal = command.traversal == "auto";
    Hierarchy h;
    LeafNumbering numbering;
    auto start = std::chrono::steady_clock::now();
    if (input.kind == FileKind::hierarchy) {
        h = hierarchy_of(input);
    } else {
        progress.phase("importing " + input.name);
        const bool with_numbering = command.keep_numbering || !command.map.empty();
        ImportedMesh imported = import_input(input, command.base, command.base_map, command.threads, global, with_numbering);
        h = std::move(imported.hierarchy);
        if (with_numbering) {
            numbering = std::move(imported.numbering);
            options.numbering = &numbering;
            options.store_numbering = command.keep_numbering;
        }
    }
    const double import_seconds = seconds_since(start);
    EncodeStats stats;
    progress.phase("encoding " + input.name);
    start = std::chrono::steady_clock::now();
    const std::vector<uint8_t> bytes = encode(h, options, &stats);
    const double seconds = seconds_since(start);
    write_output(output, std::string(bytes.begin(), bytes.end()), global.force);
    if (!command.map.empty()) write_output(command.map, format_numbering_map(stats.numbering), global.force);
    progress.finish();
    if (global.verbosity > 0) {
        std::FILE* out = report_stream(output);
        print_encode_stats(out, output == "-" ? "stdout" : output, stats, seconds);
        if (input.kind == FileKind::mesh)
            std::fprintf(out, "  import %.3f s: base %lu triangles (%s)\n", import_seconds, (unsigned long)h.root_count(),
                         command.base.empty() ? "detected" : command.base.c_str());
    }
    // Not an error (a caller may raise the limit), but the default decode refuses such a file.
    if (stats.nodes > DecodeOptions().max_nodes)
        std::fprintf(stderr, "amc: warning: %s holds %lu nodes, more than decoders read by default (%lu): decode it with --max-nodes %lu\n",
                     output == "-" ? "stdout" : output.c_str(), (unsigned long)stats.nodes,
                     (unsigned long)DecodeOptions().max_nodes, (unsigned long)stats.nodes);
}

void run_decode(const DecodeCommand& command, const GlobalOptions& global) {
    Progress progress(global.verbosity > 0);
    progress.phase("reading " + command.input);
    const InputFile input = read_input(command.input);
    if (input.kind == FileKind::series) {
        if (!command.format.empty() || command.canonical || !command.map.empty())
            throw UsageError("--format, --canonical and --map do not apply to a series (.amcs)");
        progress.finish();
        run_series_decode(input, {command.input, command.output, command.frame, command.level, false, command.max_nodes, -1},
                          global);
        return;
    }
    if (command.frame >= 0) throw UsageError("--frame applies to a series (.amcs); " + input.name + " is " + file_kind_name(input.kind));
    const std::string output = command.output.empty() ? default_output(command.input, ".ply") : command.output;
    MeshFormat mesh_format = MeshFormat::ply;
    OutputKind kind = output_kind(output, &mesh_format);
    if (output == "-") {
        kind = OutputKind::mesh;
        if (command.format == "amh") kind = OutputKind::hierarchy;
        else if (command.format == "obj") mesh_format = MeshFormat::obj;
        else if (command.format == "off") mesh_format = MeshFormat::off;
        else if (command.format == "vtu") mesh_format = MeshFormat::vtu;
        else if (!command.format.empty() && command.format != "ply")
            throw UsageError("--format: unknown format '" + command.format + "' (ply, obj, off, vtu, amh)");
    } else if (!command.format.empty()) {
        throw UsageError("--format applies to stdout (-o -); the extension of " + output + " names the format");
    }
    if (kind == OutputKind::compressed || kind == OutputKind::other)
        throw UsageError("decode writes a mesh (.obj .off .ply .vtu) or a hierarchy (.amh), not " + output);
    if (!command.map.empty() && command.level >= 0)
        throw UsageError("--map describes the whole leaf mesh: it does not combine with --level");
    if (!global.force && !command.map.empty()) refuse_existing(command.map);

    DecodeOptions options;
    options.max_level = command.level;
    options.threads = command.threads;
    options.lean_memory = true;  // one decode in this process: nothing to keep for a next one
    if (command.max_nodes > 0) options.max_nodes = command.max_nodes;
    const bool some_chunks = !command.chunks.empty() || !command.triangles.empty();
    if (some_chunks && (command.partial || !command.map.empty() || !command.chunks.empty() == !command.triangles.empty()))
        throw UsageError("--chunks and --triangles (one of them) do not combine with --partial or --map");
    LeafNumbering numbering;
    progress.phase("decoding " + input.name);
    auto start = std::chrono::steady_clock::now();
    Hierarchy h;
    std::string partial_note;  // how far a partial file got
    if (some_chunks) {
        const auto* data = reinterpret_cast<const uint8_t*>(input.bytes.data());
        try {
            const FileInfo info = inspect(data, input.bytes.size());
            const std::vector<uint32_t> chunks =
                !command.chunks.empty()
                    ? parse_chunk_list(command.chunks, info.chunks.empty() ? 1 : uint32_t(info.chunks.size()))
                    : chunks_covering(info, command.triangles);
            h = decode_chunks(data, input.bytes.size(), chunks, options).hierarchy;
        } catch (const Error& e) {
            throw e.prefixed(input.name);
        }
        partial_note = ", chunks only";
    } else if (command.partial) {
        PartialDecode partial = decode_partial_input(input, options);
        h = std::move(partial.hierarchy);
        numbering = std::move(partial.numbering);
        if (!partial.complete)
            partial_note = ", partial: levels 0.." + std::to_string(partial.level) + " of 0.." +
                           std::to_string(partial.levels - 1);
        if (!partial.complete && !command.map.empty())
            throw Error(input.name + ": the file is partial (levels 0.." + std::to_string(partial.level) + " of 0.." +
                        std::to_string(partial.levels - 1) + "): --map needs the whole file");
    } else {
        h = decode_input(input, options, &numbering);
    }
    const double seconds = seconds_since(start);
    const int depth = h.depth();  // a pass over every node: once
    if (partial_note.empty())  // a partial file gives what has arrived
        check_level(input.name, command.level, depth);
    if (!command.map.empty() && numbering.empty())
        throw Error(input.name + ": the file stores no numbering (encode a mesh with --keep-numbering, or keep the map "
                    "that encode --map writes)");

    bool renumbered = false;
    progress.phase("writing " + output);
    if (kind == OutputKind::hierarchy) {
        write_output(output, serialize_hierarchy(h), global.force);
    } else {
        const LeafMesh leaf = extract_leaf_mesh(h, command.level);
        if (!numbering.empty() && !command.canonical) {
            CellData cells;
            const TriangleMesh mesh = renumber_leaf_mesh(leaf, numbering, &cells);
            write_output(output, format_mesh(mesh, &cells, mesh_format, global.mesh_encoding, command.threads), global.force);
            renumbered = true;
        } else {
            write_output(output, format_mesh(leaf.mesh, &leaf.cells, mesh_format, global.mesh_encoding, command.threads), global.force);
        }
    }
    if (!command.map.empty()) write_output(command.map, format_numbering_map(numbering), global.force);
    progress.finish();
    if (global.verbosity > 0)
        std::fprintf(report_stream(output), "%s: %u nodes, %u vertices, depth %d%s -> %s%s (%.3f s)\n", input.name.c_str(),
                     h.node_count(), h.vertex_count(), depth, partial_note.c_str(),
                     output == "-" ? "stdout" : output.c_str(), renumbered ? " in the input's numbering" : "", seconds);
}

}  // namespace amc::cli
