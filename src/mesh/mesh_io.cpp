// read_mesh / write_mesh: format dispatch by extension, whole-file reads and atomic writes.
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include "amc/mesh.h"
#include "common/check.h"
#include "mesh/obj_io.h"
#include "mesh/off_io.h"
#include "mesh/ply_io.h"
#include "mesh/vtu_reader.h"
#include "mesh/vtu_writer.h"

namespace amc {
namespace {

std::string read_file(const std::string& path) {
    std::error_code ec;
    const std::filesystem::file_status status = std::filesystem::status(path, ec);
    if (ec || !std::filesystem::exists(status)) {
        throw Error(ErrorCode::io, path + ": cannot open file (" +
                    (ec ? ec.message() : std::string("No such file or directory")) + ")");
    }
    if (!std::filesystem::is_regular_file(status)) throw Error(ErrorCode::io, path + ": not a regular file");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(ErrorCode::io, path + ": cannot open file (" + std::strerror(errno) + ")");
    std::string bytes;
    char buffer[1 << 16];
    while (in.read(buffer, sizeof buffer) || in.gcount() > 0) bytes.append(buffer, in.gcount());
    if (in.bad()) throw Error(ErrorCode::io, path + ": read error");
    return bytes;
}

}  // namespace

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

TriangleMesh read_mesh(const std::string& path) {
    const MeshFormat format = mesh_format_from_path(path);
    if (format == MeshFormat::vtu) return read_vtu(path).mesh;
    const std::string bytes = read_file(path);
    return with_allocation_errors_as_limits(path.c_str(), [&] {
        TriangleMesh mesh;
        switch (format) {
            case MeshFormat::obj: mesh = parse_obj(bytes, path); break;
            case MeshFormat::off: mesh = parse_off(bytes, path); break;
            case MeshFormat::ply: mesh = parse_ply(bytes, path); break;
            case MeshFormat::vtu: break;
        }
        validate_triangle_mesh(mesh, path);
        return mesh;
    });
}

void write_mesh(const std::string& path, const TriangleMesh& mesh, const CellData* cells) {
    const MeshFormat format = mesh_format_from_path(path);
    std::string bytes;
    try {
        switch (format) {
            case MeshFormat::obj: bytes = format_obj(mesh); break;
            case MeshFormat::off: bytes = format_off(mesh); break;
            case MeshFormat::ply: bytes = format_ply(mesh, cells); break;
            case MeshFormat::vtu:
                bytes = format_vtu(mesh, {}, cells ? cell_data_arrays(*cells) : std::vector<DataArray>{},
                                   VtuEncoding::binary_zlib);
                break;
        }
    } catch (const Error& e) {
        throw e.prefixed(path);
    }
    write_file_atomically(path, bytes);
}

VtuMesh read_vtu(const std::string& path) {
    const std::string bytes = read_file(path);
    VtuMesh vtu = parse_vtu(bytes, path);
    validate_triangle_mesh(vtu.mesh, path);
    return vtu;
}

void write_vtu(const std::string& path, const VtuMesh& vtu, VtuEncoding encoding) {
    std::string bytes;
    try {
        bytes = format_vtu(vtu.mesh, vtu.point_data, vtu.cell_data, encoding);
    } catch (const Error& e) {
        throw e.prefixed(path);
    }
    write_file_atomically(path, bytes);
}

void write_file_atomically(const std::string& path, const std::string& bytes) {
    const std::string temp = path + ".tmp." + std::to_string(static_cast<long>(::getpid()));
    std::FILE* file = std::fopen(temp.c_str(), "wb");
    if (!file) {
        throw Error(ErrorCode::io, path + ": cannot create " + temp + " (" + std::strerror(errno) + ")");
    }
    const bool written = std::fwrite(bytes.data(), 1, bytes.size(), file) == bytes.size();
    int saved_errno = errno;
    const bool flushed = written && std::fflush(file) == 0;
    if (written && !flushed) saved_errno = errno;
    const bool closed = std::fclose(file) == 0;
    if (flushed && !closed) saved_errno = errno;
    if (!written || !flushed || !closed) {
        std::remove(temp.c_str());
        throw Error(ErrorCode::io, path + ": cannot write file (" + std::strerror(saved_errno) + ")");
    }
    if (std::rename(temp.c_str(), path.c_str()) != 0) {
        saved_errno = errno;
        std::remove(temp.c_str());
        throw Error(ErrorCode::io, path + ": cannot rename " + temp + " to it (" + std::strerror(saved_errno) + ")");
    }
}

}  // namespace amc
