// `amc info` and `amc extract`: what a file holds, and the mesh of one level.
#include "cli_files.h"
#include "commands.h"

#include <amc/codec.h>
#include <amc/mesh_io.h>

#include <cstdio>
#include <filesystem>

namespace amc::cli {

namespace {

void print_hierarchy_summary(const std::string& name, const Hierarchy& h) {
    const HierarchyStats s = compute_stats(h);
    std::printf("%-22s %7s %9s %9s %6s %9s %9s %9s\n", "model", "base_f", "faces", "nodes", "levels", "red", "green",
                "vertices");
    std::printf("%-22s %7u %9u %9u %6u %9u %9u %9u\n", name.c_str(), s.base_triangles, s.faces, s.nodes, s.levels,
                s.red_faces, s.green_faces, s.vertices);
    std::printf("nodes per level:");
    for (uint32_t n : s.nodes_per_level) std::printf(" %u", n);
    std::printf("\nleaves closed by one / two hanging nodes: %u / %u\n", s.one_hanging, s.two_hanging);
}

void print_compressed_info(const InputFile& input, uint64_t max_nodes) {
    const auto* data = reinterpret_cast<const uint8_t*>(input.bytes.data());
    FileInfo file;
    try {
        file = inspect(data, input.bytes.size());
    } catch (const Error& e) {
        throw e.prefixed(input.name);
    }
    std::printf("%s: amc version %d, %s coordinates", input.name.c_str(), file.version,
                file.quantize_bits ? "quantized" : file.single_precision ? "float32" : "float64");
    if (file.quantize_bits) std::printf(" (%d bits)", file.quantize_bits);
    std::printf("\n  base mesh %lu vertices, %lu triangles; %lu nodes, %d levels, %lu vertices, %lu faces\n",
                (unsigned long)file.base_vertices, (unsigned long)file.base_triangles, (unsigned long)file.nodes, file.levels,
                (unsigned long)file.vertices, (unsigned long)file.faces);
    // Decoding validates what the block checksums can not: the structure of the payloads.
    DecodeOptions options;
    if (max_nodes > 0) options.max_nodes = max_nodes;
    LeafNumbering numbering;
    decode_input(input, options, &numbering);
    std::printf("  %lu bytes: %.3f bits/face, %.2f bits/vertex; decodes: yes%s\n", (unsigned long)input.bytes.size(),
                8.0 * input.bytes.size() / double(file.faces), 8.0 * input.bytes.size() / double(file.vertices),
                numbering.empty() ? "" : "; stores the input's numbering");
    std::printf("  %-20s %10s %10s\n", "block", "offset", "bytes");
    for (const FileBlock& b : file.blocks) {
        std::string name = b.name;
        if (b.level >= 0) name += " " + std::to_string(b.level);
        std::printf("  %-20s %10lu %10lu\n", name.c_str(), (unsigned long)b.offset, (unsigned long)b.size);
    }
    if (!file.chunks.empty()) {
        std::printf("  %-8s %12s %10s %10s %10s\n", "chunk", "roots", "nodes", "offset", "bytes");
        for (size_t c = 0; c < file.chunks.size(); ++c) {
            const ChunkInfo& k = file.chunks[c];
            std::printf("  %-8zu %5u-%-6u %10lu %10lu %10lu\n", c, k.first_root, k.first_root + k.roots - 1,
                        (unsigned long)k.nodes, (unsigned long)k.offset, (unsigned long)k.size);
        }
    }
}

}  // namespace

void run_info(const InfoCommand& command, const GlobalOptions& global) {
    const InputFile input = read_input(command.input);
    switch (input.kind) {
        case FileKind::compressed: print_compressed_info(input, command.max_nodes); break;
        case FileKind::hierarchy:
            print_hierarchy_summary(std::filesystem::path(input.name).filename().string(), hierarchy_of(input));
            break;
        case FileKind::series: run_series_info(input, {command.input, -1, false, command.max_nodes, -1}, global); break;
        case FileKind::mesh: {
            const TriangleMesh mesh = mesh_of(input);
            std::printf("%s: %zu vertices, %zu triangles, %s precision\n", input.name.c_str(), mesh.positions.size(),
                        mesh.triangles.size(), mesh.single_precision ? "single" : "double");
            break;
        }
    }
}

void run_extract(const ExtractCommand& command, const GlobalOptions& global) {
    const InputFile input = read_input(command.input);
    MeshFormat format = MeshFormat::ply;
    if (command.output != "-" && output_kind(command.output, &format) != OutputKind::mesh)
        throw UsageError("extract writes a mesh (.obj .off .ply .vtu), not " + command.output);
    Hierarchy h;
    if (input.kind == FileKind::compressed) {
        DecodeOptions options;
        options.max_level = command.level;
        if (command.max_nodes > 0) options.max_nodes = command.max_nodes;
        h = decode_input(input, options);
    } else {
        h = hierarchy_of(input);
    }
    check_level(input.name, command.level, h.depth());
    const LeafMesh leaf = extract_leaf_mesh(h, command.level);
    write_output(command.output, format_mesh(leaf.mesh, &leaf.cells, format, global.mesh_encoding), global.force);
}

}  // namespace amc::cli
