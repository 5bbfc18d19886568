// `amc import`, and the import step of `amc encode` for mesh inputs.
#include "mesh_import.h"
#include "progress.h"

#include <amc/import.h>

#include "common/file_io.h"

#include <cctype>
#include <charconv>
#include <chrono>
#include <cstdio>
#include <fstream>

namespace amc::cli {

std::vector<uint32_t> parse_base_map(const std::string& text, const std::string& name) {
    std::vector<uint32_t> map;
    size_t line = 1;
    for (size_t i = 0; i < text.size();) {
        const char c = text[i];
        if (c == '\n') {
            ++line, ++i;
        } else if (c == ' ' || c == '\t' || c == '\r') {
            ++i;
        } else if (c == '#' && (i == 0 || text[i - 1] == '\n')) {
            while (i < text.size() && text[i] != '\n') ++i;
        } else {
            size_t end = i;
            while (end < text.size() && !std::isspace(static_cast<unsigned char>(text[end]))) ++end;
            uint32_t v = 0;
            const auto [ptr, ec] = std::from_chars(text.data() + i, text.data() + end, v);
            if (ec != std::errc() || ptr != text.data() + end)
                throw Error(name + ": line " + std::to_string(line) + ": \"" + text.substr(i, std::min<size_t>(end - i, 40)) +
                            "\" is not a vertex index");
            map.push_back(v);
            i = end;
        }
    }
    return map;
}

ImportedMesh import_input(InputFile& input, const std::string& base_path, const std::string& base_map_path, unsigned threads,
                          const GlobalOptions& global, bool with_numbering) {
    const TriangleMesh mesh = mesh_of(input);
    std::string().swap(input.bytes);
    std::vector<uint32_t> base_map;
    if (!base_map_path.empty()) {
        // Refused on its first bytes unless they can begin a map: an index or a comment.
        const FirstBytesCheck starts_like_a_map = [&](const std::string& first) {
            const size_t start = first.find_first_not_of(" \t\r\n");
            if (start != std::string::npos && first[start] != '#' && !std::isdigit(static_cast<unsigned char>(first[start])))
                throw Error(base_map_path + ": not a base vertex map (decimal vertex indices)");
        };
        std::ifstream in(base_map_path, std::ios::binary);
        if (!in) throw Error(ErrorCode::io, base_map_path + ": can not be opened for reading");
        base_map = parse_base_map(read_whole_stream(in, base_map_path, starts_like_a_map), base_map_path);
        if (base_map.empty()) throw Error(base_map_path + ": no vertex index (a base vertex map lists one per base vertex)");
    }
    ImportedHierarchy imported;
    if (base_path.empty()) {
        imported = import_mesh(mesh, input.name, threads);
    } else {
        const InputFile base_file = read_input(base_path);
        const TriangleMesh base = mesh_of(base_file);
        if (!base_map.empty() && base_map.size() != base.positions.size())
            throw Error(base_map_path + ": " + std::to_string(base_map.size()) + " vertex indices for the " +
                        std::to_string(base.positions.size()) + " vertices of " + base_file.name);
        imported = import_leaf_mesh(base, mesh, base_map, input.name);
    }
    if (global.verbosity > 1) {
        const HierarchyStats stats = compute_stats(imported.hierarchy);
        std::fprintf(stderr, "%s: base %u triangles, %u levels, %u nodes\n", input.name.c_str(), stats.base_triangles,
                     stats.levels, stats.nodes);
    }
    ImportedMesh out;
    if (with_numbering) out.numbering = leaf_numbering(imported.hierarchy, mesh, imported.vertex_of_input);
    out.hierarchy = std::move(imported.hierarchy);
    return out;
}

std::string format_numbering_map(const LeafNumbering& numbering) {
    std::string text = "amc-numbering-map 1\nvertices " + std::to_string(numbering.vertex.size()) + "\n";
    for (uint32_t v : numbering.vertex) text += std::to_string(v) + "\n";
    text += "faces " + std::to_string(numbering.face.size()) + "\n";
    for (size_t j = 0; j < numbering.face.size(); ++j)
        text += std::to_string(numbering.face[j]) + " " + std::to_string(int(numbering.rotation[j])) + "\n";
    return text;
}

void run_import(const ImportCommand& command, const GlobalOptions& global) {
    Progress progress(global.verbosity > 0);
    progress.phase("reading " + command.input);
    InputFile input = read_input(command.input);
    const std::string output = command.output.empty() ? default_output(command.input, ".amh") : command.output;
    if (output != "-" && output_kind(output) != OutputKind::hierarchy)
        throw UsageError("import writes a hierarchy file (.amh), not " + output);
    if (!global.force) {
        refuse_existing(output);
        if (!command.map.empty()) refuse_existing(command.map);
    }
    progress.phase("importing " + input.name);
    const auto start = std::chrono::steady_clock::now();
    if (!command.base_map.empty() && command.base.empty()) throw UsageError("--base-map needs --base");
    const ImportedMesh imported = import_input(input, command.base, command.base_map, command.threads, global, !command.map.empty());
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    write_output(output, serialize_hierarchy(imported.hierarchy), global.force);
    if (!command.map.empty()) write_output(command.map, format_numbering_map(imported.numbering), global.force);
    progress.finish();
    if (global.verbosity > 0) {
        const HierarchyStats s = compute_stats(imported.hierarchy);
        std::fprintf(output == "-" ? stderr : stdout,
                     "%s: base %u triangles (%s), %u levels, %u nodes, %u faces -> %s (%.3f s)\n", input.name.c_str(),
                     s.base_triangles, command.base.empty() ? "detected" : command.base.c_str(), s.levels, s.nodes,
                     s.faces, output == "-" ? "stdout" : output.c_str(), seconds);
    }
}

}  // namespace amc::cli
