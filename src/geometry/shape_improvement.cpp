// Edge flips and tangential relaxation of a coarse mesh on its reference surface, each step kept
// only when it improves the triangles it touches without moving them away from the surface.
#include "geometry/shape_improvement.h"

#include "common/no_index.h"
#include "geometry/surface_quality.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <set>
#include <unordered_map>

namespace amc {
namespace {

// Flips outside fold-overs only where the pair is nearly planar before and after (normals within
// this angle): there the diagonal is a choice of shape, not of geometry.
constexpr double kFlipBendDegrees = 30.0;
// Relaxation moves a vertex this fraction of the way to the centroid of the triangles around it.
constexpr double kRelaxationStep = 0.5;
// A step must raise the worst quality it touches by this factor (or remove a fold-over).
constexpr double kGain = 1.01;

double length(Vec3 v) { return std::sqrt(dot(v, v)); }
Vec3 unit(Vec3 v) {
    const double l = length(v);
    return l > 0 ? (1 / l) * v : Vec3{};
}
double cos_degrees(double degrees) { return std::cos(degrees * 3.14159265358979323846 / 180.0); }

// Half-edge 3t+k runs from corner k to corner k+1 of triangle t; opposite[h] is the half-edge of
// the other triangle on that edge, or kNoIndex on the boundary.
std::vector<uint32_t> opposite_halfedges(const TriangleMesh& mesh) {
    std::vector<std::pair<uint64_t, uint32_t>> edges;
    edges.reserve(3 * mesh.triangles.size());
    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
        for (int k = 0; k < 3; ++k) {
            uint64_t u = mesh.triangles[t][k], v = mesh.triangles[t][(k + 1) % 3];
            if (u > v) std::swap(u, v);
            edges.push_back({u << 32 | v, uint32_t(3 * t + k)});
        }
    }
    std::sort(edges.begin(), edges.end());
    std::vector<uint32_t> opposite(edges.size(), kNoIndex);
    for (size_t i = 0; i + 1 < edges.size(); ++i) {
        if (edges[i].first != edges[i + 1].first) continue;
        opposite[edges[i].second] = edges[i + 1].second;
        opposite[edges[i + 1].second] = edges[i].second;
    }
    return opposite;
}

uint64_t edge_key(uint64_t u, uint64_t v) { return u < v ? u << 32 | v : v << 32 | u; }

// The state of the mesh and what keeps it faithful: every reference vertex belongs to the mesh
// triangle nearest to it, and a step may not move the triangles it changes farther from the
// reference vertices they own (which would lose a thin part or round a corner off), or their
// chords farther from the surface, than they were or than the worst of the mesh as it came.
class Improver {
public:
    Improver(TriangleMesh& mesh, const ReferenceSurface& surface, const TriangleMesh& reference)
        : mesh_(mesh), surface_(surface), reference_(reference), owned_(mesh.triangles.size()) {
        // The nearest triangle's distance is owned_error over the whole mesh (the query's is the
        // same closest_point_on_triangle), without a loop over all triangles for every vertex.
        const ClosestPointQuery nearest(mesh);
        double farthest_squared = 0;
        for (uint32_t v = 0; v < reference.positions.size(); ++v) {
            const ClosestPointQuery::Hit hit = nearest.closest(reference.positions[v]);
            owned_[hit.triangle].push_back(v);
            farthest_squared = std::max(farthest_squared, hit.distance_squared);
        }
        allowed_owned_ = std::sqrt(farthest_squared);
        allowed_chord_ = chord_error(mesh.triangles);
    }

    uint32_t flip_pass();
    uint32_t relaxation_pass(const std::vector<uint8_t>& fixed);

private:
    Vec3 normal(const Triangle& t) const {
        const Vec3 a = mesh_.positions[t[0]];
        return cross(mesh_.positions[t[1]] - a, mesh_.positions[t[2]] - a);
    }
    double quality(const Triangle& t) const {
        return triangle_quality(mesh_.positions[t[0]], mesh_.positions[t[1]], mesh_.positions[t[2]]);
    }
    double distance_to(Vec3 p, const Triangle& t) const {
        Vec3 weights;
        const Vec3 c = closest_point_on_triangle(p, mesh_.positions[t[0]], mesh_.positions[t[1]], mesh_.positions[t[2]], weights);
        return length(c - p);
    }
    // The largest distance of the reference vertices owned by `owners` to the triangles `shape`.
    // A shape around a vertex of high valence is searched (the ring of a moved vertex, each of its
    // owned vertices against every triangle, was quadratic in the valence): the query's nearest
    // triangle is the loop's, by the same closest_point_on_triangle, so the same double.
    double owned_error(const std::vector<uint32_t>& owners, const std::vector<Triangle>& shape) const {
        if (shape.size() >= ClosestPointQuery::kFanValence) {
            if (std::optional<double> worst = searched_owned_error(owners, shape)) return *worst;
        }
        double worst = 0;
        for (uint32_t t : owners) {
            for (uint32_t r : owned_[t]) {
                double nearest = std::numeric_limits<double>::infinity();
                for (const Triangle& s : shape) nearest = std::min(nearest, distance_to(reference_.positions[r], s));
                worst = std::max(worst, nearest);
            }
        }
        return worst;
    }
    // owned_error by a ClosestPointQuery over `shape` (its vertices shared, so that the ring's
    // centre forms a fan); nullopt where a corner is not finite (the loop then decides).
    std::optional<double> searched_owned_error(const std::vector<uint32_t>& owners, const std::vector<Triangle>& shape) const {
        TriangleMesh local;
        std::unordered_map<uint32_t, uint32_t> local_of;
        for (const Triangle& t : shape) {
            Triangle corners;
            for (int k = 0; k < 3; ++k) {
                const auto [it, added] = local_of.try_emplace(t[k], uint32_t(local.positions.size()));
                if (added) {
                    const Vec3 p = mesh_.positions[t[k]];
                    if (!(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z))) return std::nullopt;
                    local.positions.push_back(p);
                }
                corners[k] = it->second;
            }
            local.triangles.push_back(corners);
        }
        const ClosestPointQuery nearest(local);
        double worst = 0;
        for (uint32_t t : owners) {
            for (uint32_t r : owned_[t]) worst = std::max(worst, std::sqrt(nearest.closest(reference_.positions[r]).distance_squared));
        }
        return worst;
    }
    // The largest distance of the edge midpoints and centroids of `shape` to the surface.
    double chord_error(const std::vector<Triangle>& shape) const {
        double worst = 0;
        for (const Triangle& t : shape) {
            const Vec3 a = mesh_.positions[t[0]], b = mesh_.positions[t[1]], c = mesh_.positions[t[2]];
            for (Vec3 p : {0.5 * (a + b), 0.5 * (b + c), 0.5 * (c + a), (1.0 / 3.0) * (a + b + c)})
                worst = std::max(worst, std::sqrt(surface_.faces().closest(p).distance_squared));
        }
        return worst;
    }

    TriangleMesh& mesh_;
    const ReferenceSurface& surface_;
    const TriangleMesh& reference_;
    std::vector<std::vector<uint32_t>> owned_;  // reference vertices nearest to each triangle
    // The mesh's largest errors as it came: a step may raise a local error up to them, never above.
    double allowed_owned_ = 0, allowed_chord_ = 0;
};

uint32_t Improver::flip_pass() {
    const std::vector<uint32_t> opposite = opposite_halfedges(mesh_);
    std::set<uint64_t> edges;
    for (const Triangle& t : mesh_.triangles)
        for (int k = 0; k < 3; ++k) edges.insert(edge_key(t[k], t[(k + 1) % 3]));
    std::vector<uint8_t> touched(mesh_.triangles.size(), 0);
    const double flat = cos_degrees(kFlipBendDegrees);
    uint32_t flips = 0;
    for (uint32_t h = 0; h < opposite.size(); ++h) {
        const uint32_t g = opposite[h];
        if (g == kNoIndex || g < h) continue;
        const uint32_t t1 = h / 3, t2 = g / 3;
        if (touched[t1] || touched[t2]) continue;
        const Triangle old1 = mesh_.triangles[t1], old2 = mesh_.triangles[t2];
        const uint32_t u = old1[h % 3], v = old1[(h % 3 + 1) % 3], w1 = old1[(h % 3 + 2) % 3];
        const uint32_t w2 = old2[(g % 3 + 2) % 3];
        if (w1 == w2 || edges.count(edge_key(w1, w2))) continue;
        const Triangle new1{w1, u, w2}, new2{w2, v, w1};
        const Vec3 n_old1 = normal(old1), n_old2 = normal(old2), n_new1 = normal(new1), n_new2 = normal(new2);
        const bool was_fold = is_fold_over(n_old1, n_old2);
        if (is_fold_over(n_new1, n_new2)) continue;
        if (!was_fold) {
            if (dot(unit(n_old1), unit(n_old2)) < flat || dot(unit(n_new1), unit(n_new2)) < flat) continue;
            if (!(std::min(quality(new1), quality(new2)) > kGain * std::min(quality(old1), quality(old2)))) continue;
        }
        // No fold-over with the four triangles around the pair (left alone if one of them was
        // flipped in this pass: the links here are stale for it).
        const uint32_t outer[4] = {opposite[3 * t1 + (h % 3 + 2) % 3], opposite[3 * t2 + (g % 3 + 1) % 3],
                                   opposite[3 * t2 + (g % 3 + 2) % 3], opposite[3 * t1 + (h % 3 + 1) % 3]};
        bool blocked = false;
        for (int i = 0; i < 4 && !blocked; ++i) {
            if (outer[i] == kNoIndex) continue;
            const uint32_t t = outer[i] / 3;
            blocked = touched[t] || is_fold_over(i < 2 ? n_new1 : n_new2, normal(mesh_.triangles[t]));
        }
        if (blocked) continue;
        const std::vector<uint32_t> owners{t1, t2};
        if (owned_error(owners, {new1, new2}) > std::max(owned_error(owners, {old1, old2}), allowed_owned_)) continue;
        if (chord_error({new1, new2}) > std::max(chord_error({old1, old2}), allowed_chord_)) continue;
        mesh_.triangles[t1] = new1;
        mesh_.triangles[t2] = new2;
        // The owned vertices go to the nearer of the two new triangles.
        std::vector<uint32_t> pool = owned_[t1];
        pool.insert(pool.end(), owned_[t2].begin(), owned_[t2].end());
        owned_[t1].clear();
        owned_[t2].clear();
        for (uint32_t r : pool) {
            const Vec3 p = reference_.positions[r];
            owned_[distance_to(p, new1) <= distance_to(p, new2) ? t1 : t2].push_back(r);
        }
        edges.erase(edge_key(u, v));
        edges.insert(edge_key(w1, w2));
        touched[t1] = touched[t2] = 1;
        ++flips;
    }
    return flips;
}

uint32_t Improver::relaxation_pass(const std::vector<uint8_t>& fixed) {
    const std::vector<uint32_t> opposite = opposite_halfedges(mesh_);
    std::vector<uint32_t> start(mesh_.positions.size() + 1, 0), around(3 * mesh_.triangles.size());
    for (const Triangle& t : mesh_.triangles)
        for (uint32_t v : t) ++start[v + 1];
    for (size_t v = 0; v < mesh_.positions.size(); ++v) start[v + 1] += start[v];
    {
        std::vector<uint32_t> fill(start.begin(), start.end() - 1);
        for (uint32_t t = 0; t < mesh_.triangles.size(); ++t)
            for (uint32_t v : mesh_.triangles[t]) around[fill[v]++] = t;
    }
    // Fold-overs of the triangles around v with their neighbours, and their worst quality.
    auto state_around = [&](uint32_t v, int& folds, double& worst) {
        folds = 0;
        worst = 1;
        for (uint32_t i = start[v]; i < start[v + 1]; ++i) {
            const uint32_t t = around[i];
            const Vec3 n = normal(mesh_.triangles[t]);
            for (int k = 0; k < 3; ++k) {
                const uint32_t g = opposite[3 * t + k];
                folds += g != kNoIndex && is_fold_over(n, normal(mesh_.triangles[g / 3]));
            }
            worst = std::min(worst, quality(mesh_.triangles[t]));
        }
    };
    uint32_t moves = 0;
    for (uint32_t v = 0; v < mesh_.positions.size(); ++v) {
        if (fixed[v] || start[v] == start[v + 1]) continue;
        const Vec3 p = mesh_.positions[v];
        Vec3 centroid{}, normal_sum{};
        double weight = 0;
        std::vector<uint32_t> ring;
        std::vector<Triangle> shape;
        for (uint32_t i = start[v]; i < start[v + 1]; ++i) {
            const Triangle& t = mesh_.triangles[around[i]];
            const Vec3 n = normal(t);
            const double area = 0.5 * length(n);
            normal_sum = normal_sum + n;
            centroid = centroid + area * ((1.0 / 3.0) * (mesh_.positions[t[0]] + mesh_.positions[t[1]] + mesh_.positions[t[2]]));
            weight += area;
            ring.push_back(around[i]);
            shape.push_back(t);
        }
        if (!(weight > 0)) continue;
        const Vec3 n = unit(normal_sum);
        Vec3 step = kRelaxationStep * ((1 / weight) * centroid - p);
        step = step - dot(step, n) * n;
        const auto projected = surface_.project(p + step, n, 2 * length(step));
        if (!projected) continue;
        Vec3 q = *projected;
        if (mesh_.single_precision) q = {double(float(q.x)), double(float(q.y)), double(float(q.z))};
        int folds = 0, new_folds = 0;
        double worst = 1, new_worst = 1;
        state_around(v, folds, worst);
        mesh_.positions[v] = q;
        state_around(v, new_folds, new_worst);
        if (!(new_folds < folds || (new_folds == folds && new_worst > kGain * worst))) {
            mesh_.positions[v] = p;
            continue;
        }
        // The costlier guards only for a move that would be taken.
        const double owned_after = owned_error(ring, shape), chord_after = chord_error(shape);
        mesh_.positions[v] = p;
        if (owned_after > std::max(owned_error(ring, shape), allowed_owned_) ||
            chord_after > std::max(chord_error(shape), allowed_chord_))
            continue;
        mesh_.positions[v] = q;
        ++moves;
    }
    return moves;
}

}  // namespace

uint32_t unfold(TriangleMesh& mesh, double min_quality, int rounds) {
    const std::vector<uint32_t> opposite = opposite_halfedges(mesh);
    const size_t n = mesh.positions.size();
    std::vector<uint32_t> start(n + 1, 0), around(3 * mesh.triangles.size());
    for (const Triangle& t : mesh.triangles)
        for (uint32_t v : t) ++start[v + 1];
    for (size_t v = 0; v < n; ++v) start[v + 1] += start[v];
    {
        std::vector<uint32_t> fill(start.begin(), start.end() - 1);
        for (uint32_t t = 0; t < mesh.triangles.size(); ++t)
            for (uint32_t v : mesh.triangles[t]) around[fill[v]++] = t;
    }
    std::vector<uint8_t> on_boundary(n, 0);  // boundary vertices stay: they keep the boundary's shape
    for (uint32_t h = 0; h < opposite.size(); ++h) {
        if (opposite[h] != kNoIndex) continue;
        on_boundary[mesh.triangles[h / 3][h % 3]] = 1;
        on_boundary[mesh.triangles[h / 3][(h % 3 + 1) % 3]] = 1;
    }
    auto normal = [&](uint32_t t) {
        const Triangle& c = mesh.triangles[t];
        return cross(mesh.positions[c[1]] - mesh.positions[c[0]], mesh.positions[c[2]] - mesh.positions[c[0]]);
    };
    auto folds_at = [&](uint32_t h) {
        return opposite[h] != kNoIndex && is_fold_over(normal(h / 3), normal(opposite[h] / 3));
    };
    // Fold-overs on the edges of the triangles around v, and their worst quality.
    auto state_around = [&](uint32_t v, int& folds, double& worst) {
        folds = 0;
        worst = 1;
        for (uint32_t i = start[v]; i < start[v + 1]; ++i) {
            const uint32_t t = around[i];
            for (int k = 0; k < 3; ++k) folds += folds_at(3 * t + k);
            const Triangle& c = mesh.triangles[t];
            worst = std::min(worst, triangle_quality(mesh.positions[c[0]], mesh.positions[c[1]], mesh.positions[c[2]]));
        }
    };
    uint32_t left = 0;
    for (int round = 0; round < rounds; ++round) {
        std::vector<uint32_t> candidates;
        for (uint32_t h = 0; h < opposite.size(); ++h) {
            if (opposite[h] == kNoIndex || opposite[h] < h || !folds_at(h)) continue;
            for (uint32_t e : {h, opposite[h]})
                for (int k = 0; k < 3; ++k) candidates.push_back(mesh.triangles[e / 3][k]);
        }
        left = 0;
        for (uint32_t h = 0; h < opposite.size(); ++h) left += opposite[h] != kNoIndex && opposite[h] > h && folds_at(h);
        if (left == 0) return 0;
        std::sort(candidates.begin(), candidates.end());
        candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
        uint32_t moves = 0;
        for (uint32_t v : candidates) {
            if (on_boundary[v]) continue;
            Vec3 centroid{};
            double count = 0;
            for (uint32_t i = start[v]; i < start[v + 1]; ++i) {
                for (uint32_t w : mesh.triangles[around[i]]) {
                    if (w == v) continue;
                    centroid = centroid + mesh.positions[w];
                    count += 1;
                }
            }
            if (count == 0) continue;
            centroid = (1 / count) * centroid;
            const Vec3 p = mesh.positions[v];
            int folds = 0;
            double worst = 1;
            state_around(v, folds, worst);
            if (folds == 0) continue;
            for (double f : {0.0625, 0.125, 0.25, 0.5, 0.75, 1.0}) {
                Vec3 q = p + f * (centroid - p);
                if (mesh.single_precision) q = {double(float(q.x)), double(float(q.y)), double(float(q.z))};
                mesh.positions[v] = q;
                int new_folds = 0;
                double new_worst = 1;
                state_around(v, new_folds, new_worst);
                if (new_folds < folds && new_worst >= std::min(worst, min_quality)) break;
                mesh.positions[v] = p;
            }
            moves += !(mesh.positions[v] == p);
        }
        if (moves == 0) break;
    }
    left = 0;
    for (uint32_t h = 0; h < opposite.size(); ++h) left += opposite[h] != kNoIndex && opposite[h] > h && folds_at(h);
    return left;
}

std::vector<uint8_t> sharp_vertices(const TriangleMesh& mesh, double degrees) {
    const std::vector<uint32_t> opposite = opposite_halfedges(mesh);
    const double limit = cos_degrees(degrees);
    std::vector<uint8_t> sharp(mesh.positions.size(), 0);
    auto normal_of = [&](uint32_t t) {
        const Triangle& c = mesh.triangles[t];
        return unit(cross(mesh.positions[c[1]] - mesh.positions[c[0]], mesh.positions[c[2]] - mesh.positions[c[0]]));
    };
    for (uint32_t h = 0; h < opposite.size(); ++h) {
        const uint32_t g = opposite[h];
        if (g == kNoIndex || dot(normal_of(h / 3), normal_of(g / 3)) >= limit) continue;
        sharp[mesh.triangles[h / 3][h % 3]] = 1;
        sharp[mesh.triangles[h / 3][(h % 3 + 1) % 3]] = 1;
    }
    return sharp;
}

ShapeImprovementStats improve_shapes(TriangleMesh& mesh, const ReferenceSurface& surface, const TriangleMesh& reference,
                                     const std::vector<uint8_t>& locked, int rounds) {
    ShapeImprovementStats stats;
    const MeshShape before = measure_shape(mesh);
    stats.min_quality_before = before.min_quality;
    stats.fold_overs_before = before.fold_overs;
    std::vector<uint8_t> fixed(mesh.positions.size(), 0);
    for (size_t v = 0; v < fixed.size() && v < locked.size(); ++v) fixed[v] = locked[v];
    {
        const std::vector<uint32_t> opposite = opposite_halfedges(mesh);
        for (uint32_t h = 0; h < opposite.size(); ++h) {
            if (opposite[h] != kNoIndex) continue;
            fixed[mesh.triangles[h / 3][h % 3]] = 1;
            fixed[mesh.triangles[h / 3][(h % 3 + 1) % 3]] = 1;
        }
    }
    Improver improver(mesh, surface, reference);
    for (int round = 0; round < rounds; ++round) {
        uint32_t flips = 0;
        for (int pass = 0; pass < 8; ++pass) {
            const uint32_t f = improver.flip_pass();
            flips += f;
            if (f == 0) break;
        }
        const uint32_t moves = improver.relaxation_pass(fixed);
        stats.flips += flips;
        stats.moves += moves;
        if (flips == 0 && moves == 0) break;
    }
    const MeshShape after = measure_shape(mesh);
    stats.min_quality_after = after.min_quality;
    stats.fold_overs_after = after.fold_overs;
    return stats;
}

}  // namespace amc
