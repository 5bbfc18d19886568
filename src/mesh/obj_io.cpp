// OBJ reader (tinyobjloader for the structure, std::from_chars for the coordinates) and writer.
//
// Why the coordinates are parsed again: tinyobjloader's number parser (tryParseDouble) is not
// correctly rounded (it sums digits in a double and scales by pow(5, e) and ldexp), and it maps a
// token it cannot parse ("nan", "abc") silently to 0. That holds for the Debian float build
// (libtinyobjloader.so, real_t = float, which also rounds every coordinate to float) and for the
// double build (libtinyobjloader_double.so) alike. So tinyobjloader parses the faces (with
// v/vt/vn triples and relative indices) and reports syntax errors, and the "v" lines are scanned
// once more here with std::from_chars, which is correctly rounded, so a written file reads back
// bit-exact. tinyobjloader's own coordinates only serve as a cross-check of the vertex count, so
// the float build that CMakeLists links (tinyobjloader::tinyobjloader) is fine.
// Never compile this file with TINYOBJLOADER_USE_DOUBLE while linking the float library: both
// builds export the same mangled names, and attrib_t's layout would silently disagree.
#include "mesh/obj_io.h"

#include <cstdint>
#include <sstream>
#include <string_view>
#include <vector>

#include <tiny_obj_loader.h>

#include "common/check.h"
#include "mesh/float_text.h"
#include "mesh/text_number.h"

namespace amc {
namespace {

[[noreturn]] void fail(const std::string& what, const std::string& message, ErrorCode code = ErrorCode::corrupt) {
    throw_error(code, what + ": " + message);
}

std::string first_line(const std::string& s) {
    std::string line = s.substr(0, s.find('\n'));
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
    return line.empty() ? std::string("not a valid OBJ file") : line;
}

bool is_blank(char c) { return c == ' ' || c == '\t'; }

// Messages count vertices and faces from 0, like validate_triangle_mesh, and give the line.
// The "v" lines and the number of vertices of every "f" line, with the line rules tinyobjloader
// uses (lines end at "\n", "\r\n" or "\r"; a command is its first character after leading
// blanks followed by a blank).
struct ObjScan {
    std::vector<Vec3> positions;
    std::size_t face_count = 0;
};

ObjScan scan_obj(std::string_view text, const std::string& what) {
    ObjScan scan;
    std::size_t line_number = 0;
    std::size_t pos = 0;
    while (pos < text.size()) {
        std::size_t end = text.find_first_of("\r\n", pos);
        if (end == std::string_view::npos) end = text.size();
        std::string_view line = text.substr(pos, end - pos);
        pos = end;
        if (pos < text.size()) {
            const bool crlf = text[pos] == '\r' && pos + 1 < text.size() && text[pos + 1] == '\n';
            pos += crlf ? 2 : 1;
        }
        ++line_number;

        std::size_t i = 0;
        while (i < line.size() && is_blank(line[i])) ++i;
        if (i + 1 >= line.size() || !is_blank(line[i + 1])) continue;
        const char command = line[i];
        if (command != 'v' && command != 'f') continue;
        text::TokenCursor tokens(line.substr(i + 2), /*hash_comments=*/false);
        if (command == 'v') {
            double xyz[3];
            for (double& c : xyz) {
                std::string_view token = tokens.next();
                if (!text::parse_real(token, c)) {
                    fail(what, "vertex " + std::to_string(scan.positions.size()) + " (line " +
                                   std::to_string(line_number) + ") has " +
                                   (token.empty() ? std::string("fewer than 3 coordinates")
                                                  : "a malformed coordinate " + text::quote_token(token)));
                }
            }
            scan.positions.push_back({xyz[0], xyz[1], xyz[2]});
        } else {
            std::size_t corners = 0;
            while (!tokens.next().empty()) ++corners;
            if (corners != 3) {
                fail(what, "face " + std::to_string(scan.face_count) + " (line " +
                               std::to_string(line_number) + ") has " + std::to_string(corners) +
                               " vertices; only triangle meshes are supported", ErrorCode::invalid_input);
            }
            ++scan.face_count;
        }
    }
    return scan;
}

}  // namespace

TriangleMesh parse_obj(const std::string& text, const std::string& what) {
    tinyobj::attrib_t attrib;
    std::vector<tinyobj::shape_t> shapes;
    std::vector<tinyobj::material_t> materials;
    std::string warn, err;
    std::istringstream in(text);
    // No MaterialReader: "mtllib" lines are ignored. triangulate=false keeps polygons visible.
    const bool ok = tinyobj::LoadObj(&attrib, &shapes, &materials, &warn, &err, &in, nullptr,
                                     /*triangulate=*/false, /*default_vcols_fallback=*/false);
    if (!ok || !err.empty()) fail(what, "OBJ parse error: " + first_line(err));

    ObjScan scan = scan_obj(text, what);
    if (scan.positions.size() * 3 != attrib.vertices.size()) {
        fail(what, "OBJ parse error: inconsistent vertex count");
    }
    if (scan.positions.size() > UINT32_MAX) fail(what, "too many vertices", ErrorCode::limit_exceeded);

    TriangleMesh mesh;
    mesh.positions = std::move(scan.positions);
    mesh.triangles.reserve(scan.face_count);
    const int64_t vertex_count = static_cast<int64_t>(mesh.positions.size());
    for (const tinyobj::shape_t& shape : shapes) {
        const std::vector<tinyobj::index_t>& indices = shape.mesh.indices;
        std::size_t offset = 0;
        for (unsigned corners : shape.mesh.num_face_vertices) {
            const std::size_t face = mesh.triangles.size();  // 0-based, like "triangle N"
            if (corners != 3) {
                fail(what, "face " + std::to_string(face) + " has " + std::to_string(corners) +
                               " vertices; only triangle meshes are supported", ErrorCode::invalid_input);
            }
            if (offset + 3 > indices.size()) fail(what, "OBJ parse error: truncated face list", ErrorCode::truncated);
            Triangle tri;
            for (int k = 0; k < 3; ++k) {
                // tinyobjloader resolves relative (negative) indices but checks no range.
                const int64_t v = indices[offset + k].vertex_index;
                if (v < 0) {
                    fail(what, "face " + std::to_string(face) +
                                   " has a relative vertex index before the first vertex");
                }
                if (v >= vertex_count) {
                    fail(what, "face " + std::to_string(face) + " has vertex index " +
                                   std::to_string(v + 1) + " out of range (" +
                                   std::to_string(vertex_count) + " vertices, counted from 1)");
                }
                tri[k] = static_cast<uint32_t>(v);
            }
            offset += 3;
            mesh.triangles.push_back(tri);
        }
    }
    // Faces with fewer than 3 vertices are dropped by tinyobjloader; scan_obj rejects them
    // first, so the counts agree unless the two parsers disagree about the syntax.
    if (mesh.triangles.size() != scan.face_count) {
        fail(what, "OBJ parse error: inconsistent face count");
    }

    text::adopt_float_text(mesh);
    return mesh;
}

std::string format_obj(const TriangleMesh& mesh) {
    std::string out;
    out.reserve(mesh.positions.size() * 40 + mesh.triangles.size() * 24);
    const bool float_text = text::prints_as_float_text(mesh);
    for (const Vec3& p : mesh.positions) {
        out += "v ";
        text::append_position(out, p, float_text);
    }
    for (const Triangle& t : mesh.triangles) {
        out += "f ";
        text::append_line(out, uint64_t(t[0]) + 1, uint64_t(t[1]) + 1, uint64_t(t[2]) + 1);
    }
    return out;
}

}  // namespace amc
