// Curvature-adaptive surface remeshing onto a reference mesh (remesh_adaptively): a coarse base
// from meshoptimizer with better-shaped triangles, greedy red-green refinement with every new
// vertex projected onto the reference, a correction of the vertices of fold-overs, poor triangles
// and coincident vertices, and the measures of the result (docs/REMESHER.md).
#include <amc/refinement.h>

#include "geometry/curvature.h"
#include "geometry/reference_surface.h"
#include "geometry/shape_improvement.h"
#include "geometry/surface_quality.h"
#include "hierarchy/vertex_placement.h"

#include <meshoptimizer.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <queue>

namespace amc {
namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Base vertices on creases of the reference sharper than this stay where the simplifier put them.
constexpr double kSharpDegrees = 90.0;

Vec3 round_to_float(Vec3 p) { return {double(float(p.x)), double(float(p.y)), double(float(p.z))}; }

Vec3 centroid(const Hierarchy& h, NodeId n) {
    return (1.0 / 3.0) * (h.position(h.vertex(n, 0)) + h.position(h.vertex(n, 1)) + h.position(h.vertex(n, 2)));
}

double diameter(const Hierarchy& h, NodeId n) {
    double longest = 0;
    for (int e = 0; e < 3; ++e) {
        Vec3 d = h.position(h.vertex(n, e)) - h.position(h.vertex(n, (e + 1) % 3));
        longest = std::max(longest, dot(d, d));
    }
    return std::sqrt(longest);
}

// ---- the base -------------------------------------------------------------------------------

// Simplifies to about `target` triangles with meshoptimizer and keeps the result only if it is a
// valid base mesh (the simplifier does not promise manifold output); retries with more triangles.
// A reference of at most `target` triangles is its own base. `source` receives the reference
// vertex of every base vertex.
TriangleMesh simplify_to_base(const TriangleMesh& reference, uint32_t target, std::vector<uint32_t>& source) {
    source.clear();
    if (target >= reference.triangles.size()) {
        for (uint32_t v = 0; v < reference.positions.size(); ++v) source.push_back(v);
        return reference;
    }
    std::vector<float> xyz;
    xyz.reserve(reference.positions.size() * 3);
    for (const Vec3& p : reference.positions) {
        xyz.push_back(float(p.x));
        xyz.push_back(float(p.y));
        xyz.push_back(float(p.z));
    }
    std::vector<unsigned> indices;
    for (const Triangle& t : reference.triangles) indices.insert(indices.end(), t.begin(), t.end());
    std::string last_problem;
    for (int attempt = 0; attempt < 8 && target < reference.triangles.size(); ++attempt) {
        std::vector<unsigned> simplified(indices.size());
        const size_t count = meshopt_simplify(simplified.data(), indices.data(), indices.size(), xyz.data(),
                                              reference.positions.size(), 3 * sizeof(float), size_t(target) * 3,
                                              1.0f, 0, nullptr);
        simplified.resize(count);
        // The simplifier can fold a thin part into a "pillow": two triangles on the same three
        // vertices. Both go; the validation below decides whether what is left is usable.
        std::map<std::array<unsigned, 3>, int> copies;
        for (size_t i = 0; i + 2 < simplified.size(); i += 3) {
            std::array<unsigned, 3> key{simplified[i], simplified[i + 1], simplified[i + 2]};
            std::sort(key.begin(), key.end());
            ++copies[key];
        }
        TriangleMesh base;
        base.single_precision = reference.single_precision;
        std::vector<uint32_t> remap(reference.positions.size(), 0xffffffffu);
        for (size_t i = 0; i + 2 < simplified.size(); i += 3) {
            std::array<unsigned, 3> key{simplified[i], simplified[i + 1], simplified[i + 2]};
            std::sort(key.begin(), key.end());
            if (copies[key] > 1) continue;
            Triangle t;
            for (int k = 0; k < 3; ++k) {
                uint32_t& id = remap[simplified[i + k]];
                if (id == 0xffffffffu) {
                    id = uint32_t(base.positions.size());
                    base.positions.push_back(reference.positions[simplified[i + k]]);
                    source.push_back(simplified[i + k]);
                }
                t[k] = id;
            }
            base.triangles.push_back(t);
        }
        try {
            validate_triangle_mesh(base, "simplified base mesh");
            return base;
        } catch (const Error& e) {
            last_problem = e.what();
            target = target + target / 3 + 8;
            source.clear();
        }
    }
    if (last_problem.empty()) return simplify_to_base(reference, target, source);
    throw Error("could not simplify the reference to a valid base mesh: " + last_problem);
}

// ---- counting the output -------------------------------------------------------------------

// Triangles of the conforming leaf mesh: every leaf gives one plus one per hanging node, so the
// count is the leaf count plus the number of (refined node, leaf) pairs of same-level neighbours.
class FaceCount {
public:
    uint64_t faces(const Hierarchy& h) const { return h.leaf_count() + pairs_; }

    // After refine() split `split`: a split node gains a pair with each leaf neighbour and loses
    // the pair it had as a leaf with each neighbour refined before this call.
    void add(const Hierarchy& h, const std::vector<NodeId>& split) {
        in_split_.resize(h.node_capacity(), 0);
        for (NodeId s : split) in_split_[s] = 1;
        for (NodeId s : split) {
            for (int e = 0; e < 3; ++e) {
                const NodeId q = h.neighbor(s, e);
                if (q == kNoNode) continue;
                if (h.is_leaf(q)) {
                    ++pairs_;
                } else if (!in_split_[q]) {
                    --pairs_;
                }
            }
        }
        for (NodeId s : split) in_split_[s] = 0;
    }

private:
    int64_t pairs_ = 0;
    std::vector<uint8_t> in_split_;
};

}  // namespace

Hierarchy remesh_adaptively(const TriangleMesh& reference, const SurfaceRemeshOptions& options,
                            SurfaceRemeshStats* stats) {
    if (options.max_level < 0 || options.max_level > kMaxLevel)
        throw Error("remesh: max_level " + std::to_string(options.max_level) + " is outside 0.." +
                    std::to_string(kMaxLevel));
    SurfaceRemeshStats local;
    SurfaceRemeshStats& s = stats != nullptr ? *stats : local;
    s = SurfaceRemeshStats{};
    auto start = std::chrono::steady_clock::now();
    const ReferenceSurface surface(reference);
    const bool single = options.precision == SurfacePrecision::float32 ||
                        (options.precision == SurfacePrecision::as_reference && reference.single_precision);
    const std::vector<uint8_t> sharp = sharp_vertices(reference, kSharpDegrees);
    s.reference_fold_overs = measure_shape(reference).fold_overs;
    // A base that folds over where the reference does not (a thin part the simplifier flattened
    // into a double sheet) passes its folds on to every level below it: retry with twice the
    // triangles until it folds no more than the reference, at worst the reference itself.
    TriangleMesh base;
    for (uint32_t target = std::max<uint32_t>(options.base_triangles, 4);; target = 2 * target) {
        std::vector<uint32_t> source;
        try {
            base = simplify_to_base(reference, target, source);
        } catch (const Error&) {
            // No valid base near this size (simplify_to_base tried a few): try twice as many.
            if (target >= reference.triangles.size()) throw;
            continue;
        }
        if (single) {
            for (Vec3& p : base.positions) p = round_to_float(p);
        }
        base.single_precision = single;
        std::vector<uint8_t> locked(base.positions.size());
        for (size_t v = 0; v < locked.size(); ++v) locked[v] = sharp[source[v]];
        const ShapeImprovementStats improved = improve_shapes(base, surface, reference, locked);
        s.base_min_quality = improved.min_quality_after;
        s.base_fold_overs = improved.fold_overs_after;
        ++s.base_attempts;
        if (s.base_fold_overs <= s.reference_fold_overs || target >= reference.triangles.size()) break;
    }
    Hierarchy h(std::move(base));
    s.base_triangles = h.root_count();
    s.simplify_seconds = seconds_since(start);

    start = std::chrono::steady_clock::now();
    VertexPlacement placement(h, surface);
    std::vector<double> curvature;
    if (options.criterion == RefinementCriterion::mean_curvature) {
        curvature = mean_curvature(reference);
    } else if (options.criterion == RefinementCriterion::gauss_curvature) {
        curvature = gauss_curvature(reference);
        for (double& k : curvature) k = std::sqrt(std::fabs(k));  // a length^-1 like |H|
    }
    // Priority of a leaf: how far the flat element is from the surface, either measured (distance
    // of its centroid from the reference) or predicted (curvature times size).
    auto priority = [&](NodeId n) {
        const auto hit = surface.faces().closest(centroid(h, n));
        if (options.criterion == RefinementCriterion::approximation_error) return std::sqrt(hit.distance_squared);
        return std::fabs(interpolate_at(reference, curvature, hit)) * diameter(h, n);
    };

    std::vector<NodeId> split;
    FaceCount faces;
    // Where the base folds over (a thin part whose rim is one base edge), refine first: the
    // projected vertices round the rim off level by level.
    for (int pass = 0; pass < options.max_level; ++pass) {
        const std::vector<NodeId> folded = leaves_with_fold_overs(h);
        if (folded.empty()) break;
        bool any = false;
        for (NodeId n : folded) {
            if (!h.is_leaf(n) || h.level(n) >= options.max_level) continue;
            split.clear();
            h.refine(n, &split);
            placement.place(split);
            faces.add(h, split);
            any = true;
        }
        if (!any) break;
    }
    using Entry = std::pair<double, NodeId>;
    std::priority_queue<Entry> queue;
    for (NodeId n : h.leaves()) queue.push({priority(n), n});
    while (!queue.empty() && faces.faces(h) < options.target_faces) {
        const NodeId n = queue.top().second;
        queue.pop();
        if (!h.is_leaf(n) || h.level(n) >= options.max_level) continue;
        split.clear();
        h.refine(n, &split);
        placement.place(split);
        faces.add(h, split);
        for (NodeId sn : split) {
            for (int k = 0; k < 4; ++k) queue.push({priority(h.child(sn, k)), h.child(sn, k)});
        }
    }
    s.refine_seconds = seconds_since(start);

    start = std::chrono::steady_clock::now();
    const CorrectionResult correction = correct_placements(h, placement.placements(), surface, options.min_quality);
    s.corrected_vertices = correction.moved;
    s.inherited_fold_overs = correction.inherited_fold_overs;
    s.correct_seconds = seconds_since(start);
    s.faces = uint32_t(faces.faces(h));

    if (options.measure) {
        start = std::chrono::steady_clock::now();
        const TriangleMesh leaf = extract_leaf_mesh(h).mesh;
        const MeshShape shape = measure_shape(leaf);
        s.fold_overs = shape.fold_overs;
        s.coincident_vertices = shape.coincident_vertices;
        s.min_quality = shape.min_quality;
        const SurfaceDistance d = surface_distance(reference, leaf);
        s.max_distance = d.max;
        s.max_distance_bound = d.max_upper;
        s.rms_distance = d.rms;
        s.measure_seconds = seconds_since(start);
    }
    return h;
}

}  // namespace amc
