// `amc import`, and the import step of `amc encode` for mesh inputs.
#include "mesh_import.h"
#include "progress.h"

#include <amc/import.h>

#include <chrono>
#include <cstdio>

namespace amc::cli {

ImportedMesh import_input(InputFile& input, const std::string& base_path, unsigned threads, const GlobalOptions& global,
                          bool with_numbering) {
    const TriangleMesh mesh = mesh_of(input);
    std::string().swap(input.bytes);
    ImportedHierarchy imported = base_path.empty() ? import_mesh(mesh, input.name, threads)
                                                   : import_leaf_mesh(mesh_of(read_input(base_path)), mesh, {}, input.name);
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
    const ImportedMesh imported = import_input(input, command.base, command.threads, global, !command.map.empty());
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
