// OBJ reader and writer: one pass over the text, std::from_chars for every number (correctly
// rounded, no locale), so a written file reads back bit-exact. The reader takes "v" and "f" lines
// and ignores every other command (vt, vn, g, o, s, usemtl, mtllib, l, p). Face corners may be
// "v", "v/vt", "v//vn" or "v/vt/vn" with 1-based or negative (relative) indices; texture and
// normal indices are checked for syntax only, since a triangle mesh has no use for them.
#include "mesh/obj_io.h"

#include <array>
#include <cstdint>
#include <string_view>
#include <vector>

#include "common/check.h"
#include "mesh/float_text.h"
#include "mesh/text_number.h"

namespace amc {
namespace {

[[noreturn]] void fail(const std::string& what, const std::string& message, ErrorCode code = ErrorCode::corrupt) {
    throw_error(code, what + ": " + message);
}

bool is_blank(char c) { return c == ' ' || c == '\t'; }

bool parse_nonzero_index(std::string_view token, int64_t& index) {
    return text::parse_int(token, index) && index != 0;
}

// A face corner's vertex index as written (1-based, or negative for relative), its texture and
// normal parts checked: "v", "v/vt", "v//vn" or "v/vt/vn", every written index nonzero.
bool parse_corner(std::string_view token, int64_t& vertex) {
    const std::size_t first_slash = token.find('/');
    if (!parse_nonzero_index(token.substr(0, first_slash), vertex)) return false;
    if (first_slash == std::string_view::npos) return true;
    std::string_view rest = token.substr(first_slash + 1);
    const std::size_t second_slash = rest.find('/');
    int64_t ignored = 0;
    if (second_slash == std::string_view::npos) return parse_nonzero_index(rest, ignored);
    const std::string_view texture = rest.substr(0, second_slash);
    const std::string_view normal = rest.substr(second_slash + 1);
    return (texture.empty() || parse_nonzero_index(texture, ignored)) && parse_nonzero_index(normal, ignored);
}

}  // namespace

// Messages count vertices and faces from 0, like validate_triangle_mesh, and give the line.
// Lines end at "\n", "\r\n" or "\r"; a command is the first character after leading blanks,
// followed by a blank.
TriangleMesh parse_obj(const std::string& input, const std::string& what) {
    const std::string_view text(input);
    TriangleMesh mesh;
    std::vector<std::array<int64_t, 3>> corners_of_face;  // 0-based, resolved, checked at the end
    std::size_t line_number = 0;
    std::size_t pos = 0;
    while (pos < text.size()) {
        std::size_t end = pos;  // string_view::find_first_of calls memchr once per character
        while (end < text.size() && text[end] != '\n' && text[end] != '\r') ++end;
        const std::string_view line = text.substr(pos, end - pos);
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
                const std::string_view token = tokens.next();
                if (!text::parse_real(token, c)) {
                    fail(what, "vertex " + std::to_string(mesh.positions.size()) + " (line " +
                                   std::to_string(line_number) + ") has " +
                                   (token.empty() ? std::string("fewer than 3 coordinates")
                                                  : "a malformed coordinate " + text::quote_token(token)));
                }
            }
            mesh.positions.push_back({xyz[0], xyz[1], xyz[2]});
            continue;
        }
        const std::size_t face = corners_of_face.size();
        std::array<int64_t, 3> corners{};
        std::size_t count = 0;
        for (std::string_view token = tokens.next(); !token.empty(); token = tokens.next(), ++count) {
            if (count >= 3) continue;  // counted for the message below
            int64_t written = 0;
            if (!parse_corner(token, written)) {
                fail(what, "OBJ parse error: face " + std::to_string(face) + " (line " + std::to_string(line_number) +
                               ") has a malformed vertex index " + text::quote_token(token));
            }
            // A negative index counts back from the last vertex read so far.
            corners[count] = written > 0 ? written - 1 : int64_t(mesh.positions.size()) + written;
            if (corners[count] < 0) {
                fail(what, "face " + std::to_string(face) + " has a relative vertex index before the first vertex");
            }
        }
        if (count != 3) {
            fail(what, "face " + std::to_string(face) + " (line " + std::to_string(line_number) + ") has " +
                           std::to_string(count) + " vertices; only triangle meshes are supported",
                 ErrorCode::invalid_input);
        }
        corners_of_face.push_back(corners);
    }
    if (mesh.positions.size() > UINT32_MAX) fail(what, "too many vertices", ErrorCode::limit_exceeded);

    // Faces may name vertices that come later in the file, so ranges are checked once all are read.
    const int64_t vertex_count = int64_t(mesh.positions.size());
    mesh.triangles.resize(corners_of_face.size());
    for (std::size_t face = 0; face < corners_of_face.size(); ++face) {
        for (int k = 0; k < 3; ++k) {
            const int64_t v = corners_of_face[face][size_t(k)];
            if (v >= vertex_count) {
                fail(what, "face " + std::to_string(face) + " has vertex index " + std::to_string(v + 1) +
                               " out of range (" + std::to_string(vertex_count) + " vertices, counted from 1)");
            }
            mesh.triangles[face][size_t(k)] = uint32_t(v);
        }
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
