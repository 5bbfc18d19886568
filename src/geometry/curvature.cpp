// Discrete mean and Gauss curvature (Meyer et al. 2003) from one pass over the triangles.
#include "geometry/curvature.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>

namespace amc {
namespace {

constexpr double kPi = 3.14159265358979323846;
// A triangle whose doubled area is at most this times its squared longest edge (smallest angle
// below about 1e-12 radians) is degenerate and skipped.
constexpr double kDegenerateRatio = 1e-12;
// Cotangents are clamped to this magnitude (angles within about 1e-6 radians of 0 or pi).
constexpr double kMaxCotangent = 1e6;

double length(Vec3 v) { return std::sqrt(dot(v, v)); }

// Everything both curvatures need, summed over the incident triangles of each vertex.
struct VertexSums {
    std::vector<Vec3> laplacian;    // Meyer eq. 8 numerator: sum of cot weights times (x_i - x_j)
    std::vector<double> angle;      // sum of corner angles
    std::vector<double> area;       // mixed Voronoi area
    std::vector<uint8_t> boundary;  // on an edge of exactly one triangle
};

void check_indices(const TriangleMesh& mesh, const char* what) {
    const std::size_t n = mesh.positions.size();
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
        for (uint32_t v : mesh.triangles[t]) {
            if (v >= n) {
                throw Error(std::string(what) + ": triangle " + std::to_string(t) +
                            " refers to vertex " + std::to_string(v) + " of " + std::to_string(n));
            }
        }
    }
}

// The halfedges (3 * triangle + k, the edge from corner k to corner k + 1) whose undirected
// edge is used by exactly one triangle.
std::vector<uint32_t> boundary_halfedges(const TriangleMesh& mesh) {
    std::vector<std::pair<uint64_t, uint32_t>> edges;
    edges.reserve(3 * mesh.triangles.size());
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
        const Triangle& tri = mesh.triangles[t];
        for (int k = 0; k < 3; ++k) {
            uint64_t u = tri[k], v = tri[(k + 1) % 3];
            if (u > v) std::swap(u, v);
            edges.push_back({u << 32 | v, static_cast<uint32_t>(3 * t + k)});
        }
    }
    std::sort(edges.begin(), edges.end());
    std::vector<uint32_t> boundary;
    for (std::size_t i = 0; i < edges.size();) {
        std::size_t j = i + 1;
        while (j < edges.size() && edges[j].first == edges[i].first) ++j;
        if (j - i == 1) boundary.push_back(edges[i].second);
        i = j;
    }
    return boundary;
}

VertexSums accumulate(const TriangleMesh& mesh, const char* what) {
    check_indices(mesh, what);
    const std::size_t n = mesh.positions.size();
    VertexSums sums;
    sums.laplacian.assign(n, Vec3{});
    sums.angle.assign(n, 0.0);
    sums.area.assign(n, 0.0);
    sums.boundary.assign(n, 0);
    const std::vector<uint32_t> boundary = boundary_halfedges(mesh);
    for (uint32_t halfedge : boundary) {
        const Triangle& t = mesh.triangles[halfedge / 3];
        sums.boundary[t[halfedge % 3]] = 1;
        sums.boundary[t[(halfedge % 3 + 1) % 3]] = 1;
    }

    for (const Triangle& t : mesh.triangles) {
        const Vec3 x[3] = {mesh.positions[t[0]], mesh.positions[t[1]], mesh.positions[t[2]]};
        // edge[k] is the edge opposite corner k, from corner k+1 to corner k+2.
        const Vec3 edge[3] = {x[2] - x[1], x[0] - x[2], x[1] - x[0]};
        const double edge_squared[3] = {dot(edge[0], edge[0]), dot(edge[1], edge[1]),
                                        dot(edge[2], edge[2])};
        const Vec3 face_normal = cross(edge[2], x[2] - x[0]);  // length = twice the area
        const double double_area = length(face_normal);
        const double longest = std::max({edge_squared[0], edge_squared[1], edge_squared[2]});
        if (!std::isfinite(double_area) || !(double_area > kDegenerateRatio * longest)) continue;
        const double area = 0.5 * double_area;

        double cot[3];
        double corner_dot[3];
        bool obtuse = false;
        for (int k = 0; k < 3; ++k) {
            // The two edges leaving corner k: to k+1 is edge[k+2], to k+2 is -edge[k+1].
            corner_dot[k] = -dot(edge[(k + 2) % 3], edge[(k + 1) % 3]);
            cot[k] = std::clamp(corner_dot[k] / double_area, -kMaxCotangent, kMaxCotangent);
            obtuse = obtuse || corner_dot[k] < 0;
            sums.angle[t[k]] += std::atan2(double_area, corner_dot[k]);
        }
        for (int k = 0; k < 3; ++k) {
            const uint32_t i = t[(k + 1) % 3];
            const uint32_t j = t[(k + 2) % 3];
            // Edge (i, j) is opposite corner k: its weight is cot k (eq. 8).
            const Vec3 w = cot[k] * edge[k];  // cot k * (x_j - x_i)
            sums.laplacian[i] = sums.laplacian[i] - w;
            sums.laplacian[j] = sums.laplacian[j] + w;
        }
        for (int k = 0; k < 3; ++k) {
            double mixed;
            if (!obtuse) {
                // Voronoi area (section 3.3): 1/8 sum over the two edges at k of |edge|^2 times
                // the cotangent of the angle opposite that edge.
                const int k1 = (k + 1) % 3, k2 = (k + 2) % 3;
                mixed = (edge_squared[k2] * cot[k2] + edge_squared[k1] * cot[k1]) / 8;
            } else {
                mixed = corner_dot[k] < 0 ? area / 2 : area / 4;
            }
            sums.area[t[k]] += mixed;
        }
    }
    return sums;
}

double finite_or_zero(double value) { return std::isfinite(value) ? value : 0.0; }

}  // namespace

double triangle_area(Vec3 a, Vec3 b, Vec3 c) { return 0.5 * length(cross(b - a, c - a)); }

std::vector<uint8_t> boundary_vertices(const TriangleMesh& mesh) {
    return accumulate(mesh, "boundary vertices").boundary;
}

std::vector<double> mixed_areas(const TriangleMesh& mesh) {
    return accumulate(mesh, "mixed areas").area;
}

std::vector<double> mean_curvature(const TriangleMesh& mesh) {
    VertexSums sums = accumulate(mesh, "mean curvature");
    std::vector<double> result(mesh.positions.size(), 0.0);
    for (std::size_t v = 0; v < result.size(); ++v) {
        const double area = sums.area[v];
        if (!(area > 0) || sums.boundary[v]) continue;
        // |H| = |K| / 2 with K = L / (2 A_mixed).
        result[v] = finite_or_zero(length(sums.laplacian[v]) / (4 * area));
    }
    // Boundary vertices: the mean over their interior neighbours (each counted once per incident
    // triangle, i.e. twice for a manifold edge: the same weight for all).
    std::vector<double> neighbour_sum(result.size(), 0.0);
    std::vector<uint32_t> neighbour_count(result.size(), 0);
    for (const Triangle& t : mesh.triangles) {
        for (int k = 0; k < 3; ++k) {
            const uint32_t u = t[k], w = t[(k + 1) % 3];
            if (sums.boundary[u] && !sums.boundary[w]) {
                neighbour_sum[u] += result[w];
                ++neighbour_count[u];
            } else if (sums.boundary[w] && !sums.boundary[u]) {
                neighbour_sum[w] += result[u];
                ++neighbour_count[w];
            }
        }
    }
    for (std::size_t v = 0; v < result.size(); ++v) {
        if (sums.boundary[v] && neighbour_count[v] > 0) {
            result[v] = neighbour_sum[v] / neighbour_count[v];
        }
    }
    return result;
}

std::vector<double> gauss_curvature(const TriangleMesh& mesh) {
    VertexSums sums = accumulate(mesh, "Gauss curvature");
    std::vector<double> result(mesh.positions.size(), 0.0);
    for (std::size_t v = 0; v < result.size(); ++v) {
        const double area = sums.area[v];
        if (!(area > 0)) continue;
        const double flat = sums.boundary[v] ? kPi : 2 * kPi;
        result[v] = finite_or_zero((flat - sums.angle[v]) / area);
    }
    return result;
}

double interpolate_at(const TriangleMesh& mesh, const std::vector<double>& per_vertex,
                      const ClosestPointQuery::Hit& hit) {
    if (per_vertex.size() != mesh.positions.size()) {
        throw Error("interpolate_at: the field has " + std::to_string(per_vertex.size()) +
                    " values for " + std::to_string(mesh.positions.size()) + " vertices");
    }
    if (hit.triangle >= mesh.triangles.size()) {
        throw Error("interpolate_at: hit triangle " + std::to_string(hit.triangle) + " of " +
                    std::to_string(mesh.triangles.size()));
    }
    const Triangle& t = mesh.triangles[hit.triangle];
    for (uint32_t v : t) {
        if (v >= per_vertex.size()) {
            throw Error("interpolate_at: triangle " + std::to_string(hit.triangle) +
                        " refers to vertex " + std::to_string(v) + " of " +
                        std::to_string(per_vertex.size()));
        }
    }
    return hit.barycentric.x * per_vertex[t[0]] + hit.barycentric.y * per_vertex[t[1]] +
           hit.barycentric.z * per_vertex[t[2]];
}

}  // namespace amc
