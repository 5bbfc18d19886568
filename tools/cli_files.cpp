// Input and output files of the `amc` command (see cli_files.h).
#include "cli_files.h"

#include <amc/hierarchy.h>
#include <amc/mesh_io.h>
#include <amc/octree.h>

#include "common/file_io.h"

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>

namespace amc::cli {

namespace {

std::string lower_extension(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    return ext;
}

bool starts_with(const std::string& bytes, const char* magic) { return bytes.compare(0, std::strlen(magic), magic) == 0; }

}  // namespace

const char* file_kind_name(FileKind kind) {
    switch (kind) {
        case FileKind::compressed: return "compressed .amc data";
        case FileKind::hierarchy: return "a hierarchy (.amh)";
        case FileKind::mesh: return "a mesh";
        case FileKind::series: return "a series (.amcs)";
    }
    return "?";
}

namespace {

// The kind of an input from its first bytes (and, for OBJ, which has no magic word, its name);
// throws when no kind fits. mesh_format_from_content reads no further than kFirstBytes.
void judge_kind(InputFile& in, const std::string& path, const std::string& bytes) {
    if (starts_with(bytes, "AMCF")) {
        in.kind = FileKind::compressed;
    } else if (starts_with(bytes, "AMCH")) {
        in.kind = FileKind::hierarchy;
    } else if (starts_with(bytes, "AMCS")) {
        in.kind = FileKind::series;
    } else if (mesh_format_from_content(bytes, in.mesh_format)) {
        in.kind = FileKind::mesh;
    } else if (lower_extension(path) == ".obj") {
        in.kind = FileKind::mesh;  // OBJ has no magic word: trust the name
        in.mesh_format = MeshFormat::obj;
    } else {
        throw Error(ErrorCode::bad_magic, in.name + ": " + (bytes.empty() ? "empty file" : "not a file amc reads") +
                    " (expected .amc, .amh, .amcs, or a mesh: OBJ, OFF, PLY, VTU)");
    }
}

}  // namespace

InputFile read_input(const std::string& path) {
    static_assert(kFirstBytes >= kMeshFormatContentBytes, "the kind is judged on the first bytes alone");
    InputFile in;
    in.name = path == "-" ? "stdin" : path;
    // Judged before the rest is read: `yes | amc info -` is refused at once, not when memory runs out.
    const FirstBytesCheck judge = [&](const std::string& first) { judge_kind(in, path, first); };
    in.bytes = path == "-" ? read_whole_stream(std::cin, in.name, judge) : read_whole_file(path, judge);
    return in;
}

std::string read_octree_input(const std::string& path) {
    const FirstBytesCheck header = [](const std::string& first) {
        check_octree_file_start(reinterpret_cast<const uint8_t*>(first.data()), first.size());
    };
    if (path == "-") return read_whole_stream(std::cin, "stdin", header);
    std::ifstream in(path, std::ios::binary);  // not read_whole_file: a pipe or a device is read too
    if (!in) throw Error(ErrorCode::io, "can not open");
    return read_whole_stream(in, path, header);
}

std::string default_output(const std::string& input, const std::string& extension) {
    if (input == "-") return "-";
    return std::filesystem::path(input).replace_extension(extension).string();
}

OutputKind output_kind(const std::string& path, MeshFormat* mesh_format) {
    const std::string ext = lower_extension(path);
    if (ext == ".amc") return OutputKind::compressed;
    if (ext == ".amh") return OutputKind::hierarchy;
    for (auto [name, format] : {std::pair{".obj", MeshFormat::obj}, std::pair{".off", MeshFormat::off},
                                std::pair{".ply", MeshFormat::ply}, std::pair{".vtu", MeshFormat::vtu}}) {
        if (ext == name) {
            if (mesh_format != nullptr) *mesh_format = format;
            return OutputKind::mesh;
        }
    }
    return OutputKind::other;
}

void write_output(const std::string& path, const std::string& bytes, bool force) {
    if (path == "-") {
        std::fwrite(bytes.data(), 1, bytes.size(), stdout);
        if (std::fflush(stdout) != 0 || std::ferror(stdout)) throw Error(ErrorCode::io, "stdout: write error");
        return;
    }
    if (!force) refuse_existing(path);
    write_file_atomically(path, bytes);
}

void refuse_existing(const std::string& path) {
    std::error_code ec;
    if (path != "-" && std::filesystem::exists(path, ec)) throw Error(ErrorCode::io, path + ": already exists (use -f to overwrite)");
}

Hierarchy decode_input(const InputFile& input, const DecodeOptions& options, LeafNumbering* numbering) {
    if (input.kind != FileKind::compressed)
        throw Error(input.name + ": expected compressed .amc data, found " + file_kind_name(input.kind));
    try {
        return decode(reinterpret_cast<const uint8_t*>(input.bytes.data()), input.bytes.size(), options, numbering);
    } catch (const Error& e) {
        throw e.prefixed(input.name);
    }
}

void check_level(const std::string& name, int level, int depth) {
    if (level > depth)
        throw Error(ErrorCode::invalid_input, name + ": level " + std::to_string(level) +
                                                  " requested but the hierarchy has levels 0.." + std::to_string(depth));
}

PartialDecode decode_partial_input(const InputFile& input, const DecodeOptions& options) {
    if (input.kind != FileKind::compressed)
        throw Error(input.name + ": expected compressed .amc data, found " + file_kind_name(input.kind));
    try {
        return decode_partial(reinterpret_cast<const uint8_t*>(input.bytes.data()), input.bytes.size(), options);
    } catch (const Error& e) {
        throw e.prefixed(input.name);
    }
}

Hierarchy hierarchy_of(const InputFile& input) {
    if (input.kind != FileKind::hierarchy)
        throw Error(input.name + ": expected a hierarchy (.amh), found " + file_kind_name(input.kind));
    return deserialize_hierarchy(input.bytes, input.name);
}

TriangleMesh mesh_of(const InputFile& input) {
    if (input.kind != FileKind::mesh) throw Error(input.name + ": expected a mesh, found " + file_kind_name(input.kind));
    return parse_mesh(input.bytes, input.mesh_format, input.name);
}

}  // namespace amc::cli
