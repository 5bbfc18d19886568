// Fuzz targets of the file readers: the hierarchy file (.amh) and the mesh formats. What a reader
// accepts its writer writes again, and that reads back the same, bit for bit.
#include "fuzz_targets.h"

#include "mesh/obj_io.h"
#include "mesh/off_io.h"
#include "mesh/ply_io.h"
#include "mesh/vtu_reader.h"
#include "mesh/vtu_writer.h"

#include <amc/hierarchy.h>
#include <amc/mesh_io.h>

#include <cmath>
#include <cstring>
#include <type_traits>
#include <string>
#include <variant>

namespace amc::fuzz {
namespace {

bool same_bits(const TriangleMesh& a, const TriangleMesh& b) {
    return a.single_precision == b.single_precision && a.triangles == b.triangles &&
           a.positions.size() == b.positions.size() &&
           (a.positions.empty() || std::memcmp(a.positions.data(), b.positions.data(), a.positions.size() * sizeof(Vec3)) == 0);
}

// Two values the same bits, or (as_text) two NaNs of the same sign: a text file writes "nan" and
// keeps no payload.
template <class T>
bool same_value(const T& x, const T& y, bool as_text) {
    if constexpr (std::is_floating_point_v<T>) {
        if (as_text && std::isnan(x) && std::isnan(y)) return std::signbit(x) == std::signbit(y);
    }
    return std::memcmp(&x, &y, sizeof x) == 0;
}

bool same_bits(const std::vector<DataArray>& a, const std::vector<DataArray>& b, bool as_text = false) {
    if (a.size() != b.size()) return false;
    for (size_t i = 0; i < a.size(); ++i) {
        if (a[i].name != b[i].name || a[i].components != b[i].components || a[i].values.index() != b[i].values.index())
            return false;
        const bool same = std::visit(
            [&](const auto& x) {
                const auto& y = std::get<std::decay_t<decltype(x)>>(b[i].values);
                if (x.size() != y.size()) return false;
                for (size_t k = 0; k < x.size(); ++k)
                    if (!same_value(x[k], y[k], as_text)) return false;
                return true;
            },
            a[i].values);
        if (!same) return false;
    }
    return true;
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

void vtu_read(const uint8_t* data, size_t size) {
    const std::string_view bytes(reinterpret_cast<const char*>(data), size);
    VtuMesh vtu;
    try {
        vtu = parse_vtu(bytes, "input");
        validate_triangle_mesh(vtu.mesh, "input");
    } catch (const Error&) {
        return;
    }
    // Written again (binary or ascii, by the input's size), it reads back bit for bit.
    const bool as_text = size % 2;
    const std::string written = format_vtu(vtu.mesh, vtu.point_data, vtu.cell_data,
                                           as_text ? VtuEncoding::ascii : VtuEncoding::binary_zlib);
    const VtuMesh back = parse_vtu(written, "written");
    FUZZ_CHECK(same_bits(back.mesh, vtu.mesh));
    FUZZ_CHECK(same_bits(back.point_data, vtu.point_data, as_text) && same_bits(back.cell_data, vtu.cell_data, as_text));
}

}  // namespace amc::fuzz
