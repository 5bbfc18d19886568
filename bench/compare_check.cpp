#include "compare_check.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <array>
#include <tuple>
#include <unordered_set>

namespace amc_bench {

namespace {

// The smallest of a face's three rotations (orientation kept): equal for two faces exactly when
// they are the same cycle, even if two corners are equal (a face whose corners coincide in space).
template <class Face>
Face smallest_rotation(const Face& f) {
    const Face r1{f[1], f[2], f[0]}, r2{f[2], f[0], f[1]};
    return std::min({f, r1, r2});
}

std::vector<amc::Triangle> canonical_faces(const std::vector<amc::Triangle>& faces) {
    std::vector<amc::Triangle> out;
    out.reserve(faces.size());
    for (const amc::Triangle& t : faces) out.push_back(smallest_rotation(t));
    std::sort(out.begin(), out.end());
    return out;
}

std::string face_text(const amc::Triangle& t) {
    return "(" + std::to_string(t[0]) + " " + std::to_string(t[1]) + " " + std::to_string(t[2]) + ")";
}

// A position by its coordinates' bit patterns, so that -0.0 and 0.0 differ as they would in a file.
struct PositionKey {
    uint64_t x, y, z;
    bool operator==(const PositionKey& o) const { return x == o.x && y == o.y && z == o.z; }
};
struct PositionKeyHash {
    size_t operator()(const PositionKey& k) const {
        uint64_t h = k.x * 0x9E3779B97F4A7C15ull;
        h ^= k.y * 0xC2B2AE3D27D4EB4Full + (h << 6) + (h >> 2);
        h ^= k.z * 0x165667B19E3779F9ull + (h << 6) + (h >> 2);
        return size_t(h);
    }
};

PositionKey key_of(amc::Vec3 p) {
    PositionKey k;
    std::memcpy(&k.x, &p.x, 8);
    std::memcpy(&k.y, &p.y, 8);
    std::memcpy(&k.z, &p.z, 8);
    return k;
}

bool operator<(const PositionKey& a, const PositionKey& b) { return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z); }

using PositionFace = std::array<PositionKey, 3>;

// Faces as position triples in their smallest rotation, sorted.
std::vector<PositionFace> canonical_position_faces(const std::vector<amc::Vec3>& positions, const std::vector<amc::Triangle>& faces) {
    std::vector<PositionFace> out;
    out.reserve(faces.size());
    for (const amc::Triangle& t : faces) {
        out.push_back(smallest_rotation(PositionFace{key_of(positions[t[0]]), key_of(positions[t[1]]), key_of(positions[t[2]])}));
    }
    std::sort(out.begin(), out.end());
    return out;
}

double chebyshev_distance(amc::Vec3 a, amc::Vec3 b) {
    return std::max({std::fabs(a.x - b.x), std::fabs(a.y - b.y), std::fabs(a.z - b.z)});
}

}  // namespace

MeshCheck check_same_faces(const std::vector<amc::Triangle>& original, const std::vector<amc::Triangle>& decoded) {
    MeshCheck check;
    if (original.size() != decoded.size()) {
        check.problem = std::to_string(decoded.size()) + " faces decoded, " + std::to_string(original.size()) + " expected";
        return check;
    }
    const std::vector<amc::Triangle> a = canonical_faces(original), b = canonical_faces(decoded);
    const auto mismatch = std::mismatch(a.begin(), a.end(), b.begin());
    if (mismatch.first != a.end()) {
        check.problem = "face " + face_text(*mismatch.first) + " missing, " + face_text(*mismatch.second) + " decoded instead";
        return check;
    }
    check.ok = true;
    return check;
}

MeshCheck check_decoded_mesh(const amc::TriangleMesh& original, const std::vector<amc::Vec3>& positions,
                             const std::vector<amc::Triangle>& triangles) {
    MeshCheck check;
    if (positions.size() < original.positions.size()) {
        check.problem = std::to_string(positions.size()) + " vertices decoded, " + std::to_string(original.positions.size()) + " expected";
        return check;
    }
    check.split_vertices = positions.size() - original.positions.size();
    std::unordered_set<PositionKey, PositionKeyHash> input_positions;
    input_positions.reserve(original.positions.size());
    for (const amc::Vec3& p : original.positions) input_positions.insert(key_of(p));
    for (size_t d = 0; d < positions.size(); ++d) {
        if (input_positions.count(key_of(positions[d])) == 0) {
            check.problem = "decoded vertex " + std::to_string(d) + " is at no input position";
            return check;
        }
    }
    if (triangles.size() != original.triangles.size()) {
        check.problem = std::to_string(triangles.size()) + " faces decoded, " + std::to_string(original.triangles.size()) + " expected";
        return check;
    }
    for (const amc::Triangle& t : triangles) {
        if (t[0] >= positions.size() || t[1] >= positions.size() || t[2] >= positions.size()) {
            check.problem = "decoded face " + face_text(t) + " has a vertex index out of range";
            return check;
        }
    }
    const std::vector<PositionFace> a = canonical_position_faces(original.positions, original.triangles);
    const std::vector<PositionFace> b = canonical_position_faces(positions, triangles);
    const auto mismatch = std::mismatch(a.begin(), a.end(), b.begin());
    if (mismatch.first != a.end()) {
        check.problem = "decoded faces differ from the input's (face " + std::to_string(mismatch.first - a.begin()) +
                        " of the sorted position triples)";
        return check;
    }
    check.ok = true;
    return check;
}

MeshCheck check_same_mesh_within(const std::vector<amc::Vec3>& reference_positions,
                                 const std::vector<amc::Triangle>& reference_triangles,
                                 const std::vector<amc::Vec3>& positions, const std::vector<amc::Triangle>& triangles,
                                 double tolerance, const std::string& reference) {
    MeshCheck check;
    if (triangles != reference_triangles) {
        check.problem = "faces differ from " + reference;
        return check;
    }
    if (positions.size() != reference_positions.size()) {
        check.problem = std::to_string(positions.size()) + " vertices decoded, " + std::to_string(reference_positions.size()) +
                        " in " + reference;
        return check;
    }
    for (size_t d = 0; d < positions.size(); ++d)
        check.max_error = std::max(check.max_error, chebyshev_distance(positions[d], reference_positions[d]));
    if (check.max_error > tolerance) {
        check.problem = "coordinate error " + std::to_string(check.max_error) + " from " + reference + " above " +
                        std::to_string(tolerance);
        return check;
    }
    check.ok = true;
    return check;
}

}  // namespace amc_bench
