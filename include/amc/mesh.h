// Triangle meshes: the value type shared by every stage, and the readers/writers of mesh files.
#pragma once

#include <array>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace amc {

// What went wrong, as a value a caller can branch on (Error::code(), DecodeResult::code).
// Frozen: names and values are part of the API; messages may change, codes do not.
enum class ErrorCode : uint8_t {
    invalid_input = 1,        // an argument, mesh or hierarchy that breaks the rules
    io = 2,                   // a file that can not be opened, read or written
    truncated = 3,            // data that ends before what it announces
    bad_magic = 4,            // not a file or stream of the expected kind
    unsupported_version = 5,  // a format version this build does not read
    checksum = 6,             // a checksum that does not match
    corrupt = 7,              // structure no encoder writes: a count, index or symbol out of place
    limit_exceeded = 8,       // beyond the caller's limits (DecodeOptions::max_nodes) or this build's
};
// "invalid input", "I/O", "truncated", "bad magic", "unsupported version", "checksum", "corrupt",
// "limit exceeded".
const char* error_code_name(ErrorCode code);

// Every error that reaches a user: a file or stage name and the first offending element, and
// the kind of problem as a code.
class Error : public std::runtime_error {
public:
    Error(ErrorCode code, const std::string& message) : std::runtime_error(message), code_(code) {}
    explicit Error(const std::string& message) : Error(ErrorCode::invalid_input, message) {}
    ErrorCode code() const noexcept { return code_; }
    // The same error with `context` (a file name, say) in front of the message.
    Error prefixed(const std::string& context) const { return Error(code_, context + ": " + what()); }

private:
    ErrorCode code_;
};

struct Vec3 {
    double x = 0, y = 0, z = 0;
};

inline Vec3 operator+(Vec3 a, Vec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline Vec3 operator*(double s, Vec3 a) { return {s * a.x, s * a.y, s * a.z}; }
inline double dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Vec3 cross(Vec3 a, Vec3 b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline bool operator==(Vec3 a, Vec3 b) { return a.x == b.x && a.y == b.y && a.z == b.z; }

using Triangle = std::array<uint32_t, 3>;

// Coordinates are held as double; `single_precision` records that every coordinate came from
// (and is exactly representable as) float32, so writers and coders can keep them bit-exact.
struct TriangleMesh {
    std::vector<Vec3> positions;
    std::vector<Triangle> triangles;
    bool single_precision = false;
};

// Per-triangle data written beside a leaf mesh (VTU cell data, PLY face properties).
struct CellData {
    std::vector<uint8_t> level;     // refinement level of the element
    std::vector<uint8_t> is_green;  // 1 for closure (green) triangles, 0 for red ones
};

enum class MeshFormat { obj, off, ply, vtu };

// Format from the file name's extension (.obj, .off, .ply, .vtu); throws Error otherwise.
MeshFormat mesh_format_from_path(const std::string& path);

// Reads an OBJ, OFF or PLY file (by extension) and validates it with validate_triangle_mesh.
// Throws Error naming the file and the first offending element.
TriangleMesh read_mesh(const std::string& path);

// Checks that the mesh is a triangle mesh fit to be a base mesh: indices in range, coordinates
// finite, no degenerate (repeated-vertex) or repeated triangles, every edge shared by at most two
// triangles with opposite orientation (edge-manifold, consistently oriented).
// `what` names the source in messages. Throws Error.
void validate_triangle_mesh(const TriangleMesh& mesh, const std::string& what);

// Writes a mesh; format from the extension. Cell data is written where the format can hold it
// (VTU cell arrays, PLY face properties) and ignored otherwise. The file is written to a
// temporary name and renamed, so it is never half-written. Throws Error.
void write_mesh(const std::string& path, const TriangleMesh& mesh, const CellData* cells = nullptr);

// Writes `bytes` to `path` through a temporary file and a rename. Throws Error.
void write_file_atomically(const std::string& path, const std::string& bytes);

}  // namespace amc
