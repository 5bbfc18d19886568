// Fold-overs, triangle quality, coincident vertices and the certified two-sided distance.
#include "geometry/surface_quality.h"

#include "geometry/closest_point.h"

#include <algorithm>
#include <cmath>
#include <queue>

namespace amc {
namespace {

double length(Vec3 v) { return std::sqrt(dot(v, v)); }

// A piece of a triangle of the measured surface whose distance bound is still open.
struct Piece {
    double upper;  // bound of the distance over the piece
    Vec3 a, b, c;
    bool operator<(const Piece& other) const { return upper < other.upper; }
};

// Evaluations the branch and bound may add after the first pass; the bound stays honest beyond
// it (max_upper is reported), only less tight.
constexpr uint64_t kRefinementBudget = 4000000;
// The bound is also good enough within this fraction of the largest distance found: where the
// distance is nearly constant (or nearly zero on most of a mesh lying on its reference) an
// absolute tolerance alone would split every triangle down to the tolerance's size.
constexpr double kRelativeSlack = 0.01;
// Boxes and triangles a closest-point query may test on average, beyond a floor (7 of the data's
// meshes and their remeshes of 10^5 faces: at most 31.4; a bipyramid of 2^10 sides: 205, of 2^11
// sides 394, the boxes of its long triangles all overlapping near the apexes): past it the measure
// stops and says so, instead of taking time quadratic in a vertex's valence (docs/FUZZING.md).
constexpr uint64_t kTestedPerEvaluation = 128;
constexpr uint64_t kTestedFloor = uint64_t(1) << 24;

}  // namespace

double triangle_quality(Vec3 a, Vec3 b, Vec3 c) {
    const Vec3 ab = b - a, bc = c - b, ca = a - c;
    const double squares = dot(ab, ab) + dot(bc, bc) + dot(ca, ca);
    if (!(squares > 0)) return 0;
    const double twice_area = length(cross(ab, ca));
    return 2 * std::sqrt(3.0) * twice_area / squares;
}

bool is_fold_over(Vec3 normal_a, Vec3 normal_b) {
    const double lengths = length(normal_a) * length(normal_b);
    if (!(lengths > 0)) return false;
    static const double cos_limit = std::cos(kFoldOverDegrees * 3.14159265358979323846 / 180.0);
    return dot(normal_a, normal_b) < cos_limit * lengths;
}

MeshShape measure_shape(const TriangleMesh& mesh) {
    MeshShape shape;
    const auto& p = mesh.positions;
    std::vector<Vec3> normals(mesh.triangles.size());
    std::vector<std::pair<uint64_t, uint32_t>> edges;
    edges.reserve(3 * mesh.triangles.size());
    double quality_sum = 0;
    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
        const Triangle& tri = mesh.triangles[t];
        const Vec3 a = p[tri[0]], b = p[tri[1]], c = p[tri[2]];
        normals[t] = cross(b - a, c - a);
        if (!(dot(normals[t], normals[t]) > 0)) ++shape.degenerate_triangles;
        const double q = triangle_quality(a, b, c);
        shape.min_quality = std::min(shape.min_quality, q);
        quality_sum += q;
        for (int k = 0; k < 3; ++k) {
            uint64_t u = tri[k], v = tri[(k + 1) % 3];
            if (u > v) std::swap(u, v);
            edges.push_back({u << 32 | v, uint32_t(t)});
        }
    }
    if (!mesh.triangles.empty()) shape.mean_quality = quality_sum / double(mesh.triangles.size());
    std::sort(edges.begin(), edges.end());
    for (size_t i = 0; i + 1 < edges.size(); ++i) {
        if (edges[i].first != edges[i + 1].first) continue;
        const bool manifold = (i + 2 >= edges.size() || edges[i + 2].first != edges[i].first) &&
                              (i == 0 || edges[i - 1].first != edges[i].first);
        if (manifold && is_fold_over(normals[edges[i].second], normals[edges[i + 1].second])) ++shape.fold_overs;
    }
    std::vector<Vec3> sorted = p;
    std::sort(sorted.begin(), sorted.end(), [](Vec3 u, Vec3 v) {
        return u.x != v.x ? u.x < v.x : u.y != v.y ? u.y < v.y : u.z < v.z;
    });
    for (size_t i = 0; i < sorted.size();) {
        size_t j = i + 1;
        while (j < sorted.size() && sorted[j] == sorted[i]) ++j;
        if (j - i > 1) shape.coincident_vertices += uint32_t(j - i);
        i = j;
    }
    return shape;
}

OneSidedDistance one_sided_distance(const TriangleMesh& from, const TriangleMesh& to, double tolerance) {
    OneSidedDistance result;
    const ClosestPointQuery query(to);
    auto distance = [&](Vec3 x) {
        ++result.evaluations;
        const double d = std::sqrt(query.closest(x, result.tested).distance_squared);
        if (result.tested > kTestedPerEvaluation * result.evaluations + kTestedFloor) result.complete = false;
        if (d > result.max) {
            result.max = d;
            result.max_point = x;
        }
        return d;
    };
    std::vector<double> at_vertex(from.positions.size());
    for (size_t v = 0; v < from.positions.size() && result.complete; ++v) {
        at_vertex[v] = distance(from.positions[v]);
        result.max = std::max(result.max, at_vertex[v]);
    }
    auto slack = [&](double max) { return max + std::max(tolerance, kRelativeSlack * max); };
    std::priority_queue<Piece> open;
    double closed_upper = 0;  // largest bound of a piece left unsplit
    auto keep = [&](Vec3 a, Vec3 b, Vec3 c, double at_centroid) {
        const Vec3 g = (1.0 / 3.0) * (a + b + c);
        const double reach = std::sqrt(std::max({dot(a - g, a - g), dot(b - g, b - g), dot(c - g, c - g)}));
        const double upper = at_centroid + reach;
        if (upper > slack(result.max)) {
            open.push({upper, a, b, c});
        } else {
            closed_upper = std::max(closed_upper, upper);
        }
    };
    double integral = 0;
    for (const Triangle& t : from.triangles) {
        if (!result.complete) return result;
        const Vec3 a = from.positions[t[0]], b = from.positions[t[1]], c = from.positions[t[2]];
        const double area = 0.5 * length(cross(b - a, c - a));
        const double dab = distance(0.5 * (a + b)), dbc = distance(0.5 * (b + c)), dca = distance(0.5 * (c + a));
        const double dg = distance((1.0 / 3.0) * (a + b + c));
        const double da = at_vertex[t[0]], db = at_vertex[t[1]], dc = at_vertex[t[2]];
        // The 7-point rule (Stroud T2:3-1): corners 3/60, edge midpoints 8/60, centroid 27/60.
        integral += area * ((3.0 / 60) * (da * da + db * db + dc * dc) + (8.0 / 60) * (dab * dab + dbc * dbc + dca * dca) +
                            (27.0 / 60) * dg * dg);
        result.area += area;
        result.max = std::max({result.max, dab, dbc, dca, dg});
        keep(a, b, c, dg);
    }
    const uint64_t budget = result.evaluations + kRefinementBudget;
    while (!open.empty() && open.top().upper > slack(result.max) && result.evaluations < budget && result.complete) {
        const Piece piece = open.top();
        open.pop();
        const Vec3 ab = 0.5 * (piece.a + piece.b), bc = 0.5 * (piece.b + piece.c), ca = 0.5 * (piece.c + piece.a);
        const Vec3 children[4][3] = {{piece.a, ab, ca}, {ab, piece.b, bc}, {ca, bc, piece.c}, {bc, ca, ab}};
        for (const auto& child : children) {
            const double dg = distance((1.0 / 3.0) * (child[0] + child[1] + child[2]));
            result.max = std::max(result.max, dg);
            keep(child[0], child[1], child[2], dg);
        }
    }
    result.max_upper = std::max({result.max, closed_upper, open.empty() ? 0.0 : open.top().upper});
    result.rms = result.area > 0 ? std::sqrt(integral / result.area) : 0;
    return result;
}

double bounding_box_diagonal(const TriangleMesh& mesh) {
    if (mesh.positions.empty()) return 0;
    Vec3 lo = mesh.positions[0], hi = lo;
    for (const Vec3& q : mesh.positions) {
        lo = {std::min(lo.x, q.x), std::min(lo.y, q.y), std::min(lo.z, q.z)};
        hi = {std::max(hi.x, q.x), std::max(hi.y, q.y), std::max(hi.z, q.z)};
    }
    return length(hi - lo);
}

SurfaceDistance surface_distance(const TriangleMesh& reference, const TriangleMesh& approximation, double tolerance) {
    SurfaceDistance d;
    d.diagonal = bounding_box_diagonal(reference);
    const double unit = d.diagonal > 0 ? d.diagonal : 1;
    d.to_reference = one_sided_distance(approximation, reference, tolerance * unit);
    if (!d.to_reference.complete) return d;  // not measured: nothing more to learn
    d.from_reference = one_sided_distance(reference, approximation, tolerance * unit);
    d.max = std::max(d.to_reference.max, d.from_reference.max) / unit;
    d.max_upper = std::max(d.to_reference.max_upper, d.from_reference.max_upper) / unit;
    const double area = d.to_reference.area + d.from_reference.area;
    if (area > 0) {
        const double squares = d.to_reference.rms * d.to_reference.rms * d.to_reference.area +
                               d.from_reference.rms * d.from_reference.rms * d.from_reference.area;
        d.rms = std::sqrt(squares / area) / unit;
    }
    return d;
}

}  // namespace amc
