// Projection onto a reference surface: facing faces inside, boundary curves on the rim.
#include "geometry/reference_surface.h"

#include <algorithm>

namespace amc {
namespace {

// The edges used by one triangle, as zero-area triangles (a, b, b).
TriangleMesh boundary_segments(const TriangleMesh& mesh) {
    std::vector<uint64_t> edges;
    edges.reserve(3 * mesh.triangles.size());
    for (const Triangle& t : mesh.triangles) {
        for (int k = 0; k < 3; ++k) {
            uint64_t u = t[k], v = t[(k + 1) % 3];
            if (u > v) std::swap(u, v);
            edges.push_back(u << 32 | v);
        }
    }
    std::sort(edges.begin(), edges.end());
    TriangleMesh segments;
    segments.positions = mesh.positions;
    for (size_t i = 0; i < edges.size();) {
        size_t j = i + 1;
        while (j < edges.size() && edges[j] == edges[i]) ++j;
        if (j - i == 1) segments.triangles.push_back({uint32_t(edges[i] >> 32), uint32_t(edges[i]), uint32_t(edges[i])});
        i = j;
    }
    return segments;
}

}  // namespace

ReferenceSurface::ReferenceSurface(const TriangleMesh& reference) : faces_(reference) {
    const TriangleMesh segments = boundary_segments(reference);
    if (!segments.triangles.empty()) boundary_.emplace(segments);
}

std::optional<Vec3> ReferenceSurface::project(Vec3 p, Vec3 normal, double reach) const {
    const auto hit = faces_.closest_facing(p, normal, 0.0, reach);
    if (!hit) return std::nullopt;
    return hit->point;
}

std::optional<Vec3> ReferenceSurface::project_along(Vec3 p, Vec3 normal, double reach) const {
    const auto hit = faces_.intersect_line(p, normal, reach);
    if (!hit) return std::nullopt;
    return hit->point;
}

std::optional<Vec3> ReferenceSurface::project_to_boundary(Vec3 p, double reach) const {
    if (!boundary_) return std::nullopt;
    const auto hit = boundary_->closest(p, reach);
    if (!hit) return std::nullopt;
    return hit->point;
}

}  // namespace amc
