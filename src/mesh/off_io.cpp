// OFF reader and writer.
#include "mesh/off_io.h"

#include <cstdint>

#include "common/check.h"
#include "mesh/float_text.h"
#include "mesh/text_number.h"

namespace amc {
namespace {

[[noreturn]] void fail(const std::string& what, const std::string& message, ErrorCode code = ErrorCode::corrupt) {
    throw_error(code, what + ": " + message);
}

// Fewest bytes a vertex ("\n0 0 0") and a face ("\n3 0 1 2") can take, separator included.
constexpr uint64_t min_vertex_bytes = 6;
constexpr uint64_t min_face_bytes = 8;

uint64_t read_count(text::TokenCursor& in, const std::string& what, const char* name) {
    std::string_view token = in.next();
    int64_t value = 0;
    if (token.empty()) fail(what, std::string("truncated header: missing ") + name + " count", ErrorCode::truncated);
    if (!text::parse_int(token, value) || value < 0) {
        fail(what, std::string("bad ") + name + " count " + text::quote_token(token) + " (line " +
                       std::to_string(in.line()) + ")");
    }
    return static_cast<uint64_t>(value);
}

}  // namespace

TriangleMesh parse_off(std::string_view text, const std::string& what) {
    text::TokenCursor in(text, /*hash_comments=*/true);
    std::string_view magic = in.next();
    if (magic != "OFF") {
        fail(what, "not an OFF file (expected \"OFF\", found " +
                       (magic.empty() ? std::string("nothing") : text::quote_token(magic)) + ")", ErrorCode::bad_magic);
    }
    const uint64_t vertex_count = read_count(in, what, "vertex");
    const uint64_t face_count = read_count(in, what, "face");
    read_count(in, what, "edge");  // unused, but must be present
    // Check the counts against the bytes left before allocating anything.
    if (vertex_count > UINT32_MAX || face_count > UINT32_MAX ||
        vertex_count * min_vertex_bytes + face_count * min_face_bytes > in.remaining()) {
        fail(what, "header declares " + std::to_string(vertex_count) + " vertices and " +
                       std::to_string(face_count) + " faces, more than the " +
                       std::to_string(in.remaining()) + " bytes after it can hold");
    }

    TriangleMesh mesh;
    mesh.positions.resize(vertex_count);
    for (uint64_t v = 0; v < vertex_count; ++v) {
        double xyz[3];
        for (double& c : xyz) {
            std::string_view token = in.next();
            if (token.empty()) {
                fail(what, "truncated: file ends in vertex " + std::to_string(v) + " of " +
                               std::to_string(vertex_count), ErrorCode::truncated);
            }
            if (!text::parse_real(token, c)) {
                fail(what, "vertex " + std::to_string(v) + " (line " + std::to_string(in.line()) +
                               ") has a malformed coordinate " + text::quote_token(token));
            }
        }
        mesh.positions[v] = {xyz[0], xyz[1], xyz[2]};
    }

    mesh.triangles.resize(face_count);
    for (uint64_t f = 0; f < face_count; ++f) {
        std::string_view token = in.next();
        if (token.empty()) {
            fail(what, "truncated: file ends before face " + std::to_string(f) + " of " +
                           std::to_string(face_count), ErrorCode::truncated);
        }
        int64_t corners = 0;
        if (!text::parse_int(token, corners)) {
            fail(what, "face " + std::to_string(f) + " (line " + std::to_string(in.line()) +
                           ") has a malformed vertex count " + text::quote_token(token));
        }
        if (corners != 3) {
            fail(what, "face " + std::to_string(f) + " has " + std::to_string(corners) +
                           " vertices; only triangle meshes are supported", ErrorCode::invalid_input);
        }
        for (uint32_t& index : mesh.triangles[f]) {
            token = in.next();
            int64_t value = 0;
            if (token.empty()) {
                fail(what, "truncated: file ends in face " + std::to_string(f) + " of " +
                               std::to_string(face_count), ErrorCode::truncated);
            }
            if (!text::parse_int(token, value)) {
                fail(what, "face " + std::to_string(f) + " (line " + std::to_string(in.line()) +
                               ") has a malformed index " + text::quote_token(token));
            }
            if (value < 0 || static_cast<uint64_t>(value) >= vertex_count) {
                fail(what, "face " + std::to_string(f) + " has index " + std::to_string(value) +
                               " out of range (" + std::to_string(vertex_count) + " vertices)");
            }
            index = static_cast<uint32_t>(value);
        }
        in.skip_line();  // optional face colour
    }
    text::adopt_float_text(mesh);
    return mesh;
}

std::string format_off(const TriangleMesh& mesh) {
    std::string out = "OFF\n";
    text::append_uint(out, mesh.positions.size());
    out += ' ';
    text::append_uint(out, mesh.triangles.size());
    out += " 0\n";
    const bool float_text = text::prints_as_float_text(mesh);
    for (const Vec3& p : mesh.positions) {
        text::append_position(out, p, float_text);
    }
    for (const Triangle& t : mesh.triangles) {
        out += "3 ";
        text::append_line(out, t[0], t[1], t[2]);
    }
    return out;
}

}  // namespace amc
