// read_mesh / write_mesh: format dispatch by extension and content (<amc/mesh_io.h>).
#include <cctype>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <string>

#include "amc/mesh_io.h"
#include "common/check.h"
#include "common/file_io.h"
#include "mesh/obj_io.h"
#include "mesh/off_io.h"
#include "mesh/ply_io.h"
#include "mesh/vtu_reader.h"
#include "mesh/vtu_writer.h"

namespace amc {

MeshFormat mesh_format_from_path(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    for (char& c : ext) {
        if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
    }
    if (ext == ".obj") return MeshFormat::obj;
    if (ext == ".off") return MeshFormat::off;
    if (ext == ".ply") return MeshFormat::ply;
    if (ext == ".vtu") return MeshFormat::vtu;
    throw Error(path + ": unknown mesh format " +
                (ext.empty() ? std::string("(no extension)") : "'" + ext + "'") +
                " (expected .obj, .off, .ply or .vtu)");
}

bool mesh_format_from_content(const std::string& bytes, MeshFormat& format) {
    size_t start = 0;  // skip a byte-order mark and leading white space
    if (bytes.compare(0, 3, "\xEF\xBB\xBF") == 0) start = 3;
    constexpr size_t kLongestWord = 8;  // "<VTKFile"
    while (start < bytes.size() && start < kMeshFormatContentBytes - kLongestWord &&
           std::isspace(static_cast<unsigned char>(bytes[start])))
        ++start;
    auto starts_with = [&](const char* word) { return bytes.compare(start, std::strlen(word), word) == 0; };
    if (bytes.compare(0, 4, "ply\n") == 0 || bytes.compare(0, 5, "ply\r\n") == 0) {
        format = MeshFormat::ply;
    } else if (starts_with("OFF") || starts_with("COFF") || starts_with("NOFF") || starts_with("CNOFF")) {
        format = MeshFormat::off;
    } else if (starts_with("<?xml") || starts_with("<VTKFile")) {
        format = MeshFormat::vtu;
    } else if (starts_with("#") || starts_with("v ") || starts_with("v\t") || starts_with("o ") || starts_with("g ") ||
               starts_with("mtllib") || starts_with("vn ") || starts_with("vt ") || starts_with("f ") || starts_with("s ")) {
        format = MeshFormat::obj;
    } else {
        return false;
    }
    return true;
}

TriangleMesh parse_mesh(const std::string& bytes, MeshFormat format, const std::string& what) {
    return with_allocation_errors_as_limits(what.c_str(), [&] {
        TriangleMesh mesh;
        switch (format) {
            case MeshFormat::obj: mesh = parse_obj(bytes, what); break;
            case MeshFormat::off: mesh = parse_off(bytes, what); break;
            case MeshFormat::ply: mesh = parse_ply(bytes, what); break;
            case MeshFormat::vtu: mesh = parse_vtu(bytes, what).mesh; break;
        }
        validate_triangle_mesh(mesh, what);
        return mesh;
    });
}

TriangleMesh read_mesh(const std::string& path) {
    const MeshFormat format = mesh_format_from_path(path);
    return parse_mesh(read_whole_file(path), format, path);
}

std::string format_mesh(const TriangleMesh& mesh, const CellData* cells, MeshFormat format,
                        MeshEncoding encoding, unsigned threads) {
    switch (format) {
        case MeshFormat::obj: return format_obj(mesh);
        case MeshFormat::off: return format_off(mesh);
        case MeshFormat::ply: return format_ply(mesh, cells, encoding);
        case MeshFormat::vtu:
            return format_vtu(mesh, {}, cells ? cell_data_arrays(*cells) : std::vector<DataArray>{},
                              encoding == MeshEncoding::ascii ? VtuEncoding::ascii : VtuEncoding::binary_zlib, threads);
    }
    return {};
}

void write_mesh(const std::string& path, const TriangleMesh& mesh, const CellData* cells,
                MeshEncoding encoding, unsigned threads) {
    const MeshFormat format = mesh_format_from_path(path);
    std::string bytes;
    try {
        bytes = format_mesh(mesh, cells, format, encoding, threads);
    } catch (const Error& e) {
        throw e.prefixed(path);
    }
    write_file_atomically(path, bytes);
}

VtuMesh read_vtu(const std::string& path, unsigned threads) {
    const std::string bytes = read_whole_file(path);
    VtuMesh vtu = parse_vtu(bytes, path, threads);
    validate_triangle_mesh(vtu.mesh, path);
    return vtu;
}

void write_vtu(const std::string& path, const VtuMesh& vtu, VtuEncoding encoding, unsigned threads) {
    std::string bytes;
    try {
        bytes = format_vtu(vtu.mesh, vtu.point_data, vtu.cell_data, encoding, threads);
    } catch (const Error& e) {
        throw e.prefixed(path);
    }
    write_file_atomically(path, bytes);
}

ImportedHierarchy import_leaf_mesh_files(const std::string& base_path, const std::string& leaf_path) {
    const TriangleMesh base = read_mesh(base_path);
    const TriangleMesh leaf = read_mesh(leaf_path);
    return import_leaf_mesh(base, leaf, {}, leaf_path);
}

}  // namespace amc
