// Fuzz targets of the file readers: the hierarchy file (.amh) and the mesh formats. What a reader
// accepts its writer writes again, and that reads back the same, bit for bit.
#include "fuzz_targets.h"

#include "mesh/obj_io.h"
#include "mesh/off_io.h"
#include "mesh/ply_io.h"

#include <amc/hierarchy.h>

#include <cstring>
#include <string>

namespace amc::fuzz {
namespace {

bool same_bits(const TriangleMesh& a, const TriangleMesh& b) {
    return a.single_precision == b.single_precision && a.triangles == b.triangles &&
           a.positions.size() == b.positions.size() &&
           (a.positions.empty() || std::memcmp(a.positions.data(), b.positions.data(), a.positions.size() * sizeof(Vec3)) == 0);
}

template <class Parse, class Format>
void read_mesh_bytes(const uint8_t* data, size_t size, Parse parse, Format format) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    TriangleMesh mesh;
    try {
        mesh = parse(text, "input");
        validate_triangle_mesh(mesh, "input");
    } catch (const Error&) {
        return;
    }
    const std::string written = format(mesh);
    FUZZ_CHECK(same_bits(parse(written, "written"), mesh));
}

}  // namespace

void amh_read(const uint8_t* data, size_t size) {
    const std::string bytes(reinterpret_cast<const char*>(data), size);
    Hierarchy h;
    try {
        h = deserialize_hierarchy(bytes, "input");
    } catch (const Error&) {
        return;
    }
    FUZZ_CHECK(check_invariants(h).empty());
    // One file per hierarchy: the reader accepts exactly what the writer writes.
    FUZZ_CHECK(serialize_hierarchy(h) == bytes);
}

void obj_read(const uint8_t* data, size_t size) {
    read_mesh_bytes(data, size, [](const std::string& text, const std::string& what) { return parse_obj(text, what); },
                    [](const TriangleMesh& mesh) { return format_obj(mesh); });
}

void off_read(const uint8_t* data, size_t size) {
    read_mesh_bytes(data, size, [](const std::string& text, const std::string& what) { return parse_off(text, what); },
                    [](const TriangleMesh& mesh) { return format_off(mesh); });
}

void ply_read(const uint8_t* data, size_t size) {
    read_mesh_bytes(data, size, [](const std::string& text, const std::string& what) { return parse_ply(text, what); },
                    [](const TriangleMesh& mesh) { return format_ply(mesh); });
}

}  // namespace amc::fuzz
