// Triangle meshes: the value type shared by every stage, its errors and its checks (the readers
// and writers of mesh files are in <amc/mesh_io.h>).
#pragma once

#include <array>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <variant>
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

// Checks that the mesh is a triangle mesh fit to be a base mesh: indices in range, coordinates
// finite, no degenerate (repeated-vertex) or repeated triangles, every edge shared by at most two
// triangles with opposite orientation (edge-manifold, consistently oriented).
// `what` names the source in messages. Throws Error.
void validate_triangle_mesh(const TriangleMesh& mesh, const std::string& what);

// ---------------------------------------------------------------------------------------------
// The contents of a VTK XML UnstructuredGrid (.vtu): point and cell data

// The value types of a VTK DataArray, in the order of DataArray::Values' alternatives.
enum class ValueType : uint8_t { int8, uint8, int16, uint16, int32, uint32, int64, uint64, float32, float64 };

// A named array of point or cell data: `components` values per point (or cell), tuple after
// tuple. Values keep their own type, so every value (64-bit integers, NaN payloads) survives a
// read and a write bit for bit.
struct DataArray {
    using Values = std::variant<std::vector<int8_t>, std::vector<uint8_t>, std::vector<int16_t>,
                                std::vector<uint16_t>, std::vector<int32_t>, std::vector<uint32_t>,
                                std::vector<int64_t>, std::vector<uint64_t>, std::vector<float>,
                                std::vector<double>>;
    std::string name;
    uint32_t components = 1;
    Values values;  // values[i * components + k]: component k of point (or cell) i

    ValueType type() const { return static_cast<ValueType>(values.index()); }
    std::size_t size() const;               // number of values (tuples x components)
    double value(std::size_t index) const;  // one value converted to double
};

// A triangle mesh with the point data (one tuple per vertex) and cell data (one tuple per
// triangle) of a VTU file.
struct VtuMesh {
    TriangleMesh mesh;
    std::vector<DataArray> point_data;
    std::vector<DataArray> cell_data;
};

// The cell arrays "level" and "green" (UInt8) of the non-empty arrays of `cells`, as write_mesh
// writes them: VtuMesh{leaf.mesh, {}, cell_data_arrays(leaf.cells)}.
std::vector<DataArray> cell_data_arrays(const CellData& cells);

// Writes `bytes` to `path` through a temporary file beside it (`path.tmp.PID.N`), flushed to the
// disk, and a rename: a reader, or a writer killed at any moment (or a crash of the machine),
// finds the old file or the whole new one, never a part. A killed writer may leave its temporary
// file behind. Threads may write the same path at once: each file is whole, the last rename
// wins. Throws Error.
void write_file_atomically(const std::string& path, const std::string& bytes);

}  // namespace amc
