// Curvature-adaptive surface remeshing onto a reference mesh (remesh_adaptively): a coarse base
// from meshoptimizer with better-shaped triangles, greedy red-green refinement with every new
// vertex projected onto the reference, a correction of the vertices of fold-overs, poor triangles
// and coincident vertices, and the measures of the result (docs/REMESHER.md).
#include <amc/refinement.h>

#include "common/check.h"
#include "geometry/curvature.h"
#include "geometry/reference_surface.h"
#include "geometry/shape_improvement.h"
#include "geometry/surface_quality.h"
#include "hierarchy/node_shape.h"
#include "hierarchy/refinement_counts.h"
#include "hierarchy/vertex_placement.h"

#include <meshoptimizer.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <queue>
#include <string>
#include <tuple>
#include <vector>

namespace amc {
namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// A base is taken at once if it strays from the reference by at most this fraction of the
// diagonal, both ways (else a larger or smaller one is tried): a thin part the base misses or
// bridges by more is lost.
constexpr double kBaseDistance = 0.01;
// A base is taken at once only if its worst triangle has this quality, or half the reference's
// worst if that is lower: the leaf mesh's quality bound is a third of its base triangle's.
constexpr double kBaseQuality = 0.05;
// The base search goes down to bases of this many triangles.
constexpr uint64_t kSmallestBase = 50;

// Base vertices on creases of the reference sharper than this stay where the simplifier put them.
constexpr double kSharpDegrees = 90.0;

Vec3 round_to_float(Vec3 p) { return {double(float(p.x)), double(float(p.y)), double(float(p.z))}; }

// ---- the base -------------------------------------------------------------------------------

// Where `base` strays from `reference` by more than `max_distance`, both ways: the reference
// vertices farther than that from the base (a part the base lost), and the corners of the
// reference triangles nearest to the base's edge midpoints and centroids that are farther than
// that from the reference (a base triangle that bridges across a thin part). Returns the largest
// of those distances; `strayed` (if given) receives those reference vertices.
double base_distance(const TriangleMesh& reference, const ClosestPointQuery& on_reference, const TriangleMesh& base,
                     double max_distance, std::vector<uint32_t>* strayed) {
    const ClosestPointQuery on_base(base);
    double farthest = 0;
    const double limit = max_distance * max_distance;
    for (uint32_t v = 0; v < reference.positions.size(); ++v) {
        const double d = on_base.closest(reference.positions[v]).distance_squared;
        farthest = std::max(farthest, d);
        if (d > limit && strayed != nullptr) strayed->push_back(v);
    }
    for (const Triangle& t : base.triangles) {
        const Vec3 a = base.positions[t[0]], b = base.positions[t[1]], c = base.positions[t[2]];
        for (Vec3 p : {0.5 * (a + b), 0.5 * (b + c), 0.5 * (c + a), (1.0 / 3.0) * (a + b + c)}) {
            const ClosestPointQuery::Hit hit = on_reference.closest(p);
            farthest = std::max(farthest, hit.distance_squared);
            if (hit.distance_squared > limit && strayed != nullptr)
                strayed->insert(strayed->end(), reference.triangles[hit.triangle].begin(),
                                reference.triangles[hit.triangle].end());
        }
    }
    if (strayed != nullptr) {
        std::sort(strayed->begin(), strayed->end());
        strayed->erase(std::unique(strayed->begin(), strayed->end()), strayed->end());
    }
    return std::sqrt(farthest);
}

// Simplifies to about `target` triangles with meshoptimizer and keeps the result only if it is a
// valid base mesh (the simplifier does not promise manifold output); retries with more triangles.
// The simplifier can flatten a thin part into "pillows" (two triangles on the same three
// vertices), fold it away or bridge across it: the reference triangles where the result strays
// from the reference by more than `max_distance` (base_distance), and two rings around them, are
// then kept as they are (the simplifier's borders locked around them) and it runs again, while
// that strays at fewer reference vertices, so that the base keeps the part. A reference of at
// most `target` triangles is its own base. `source` receives the reference vertex of every base vertex.
TriangleMesh simplify_to_base(const TriangleMesh& reference, const ClosestPointQuery& on_reference, uint32_t target,
                              double max_distance, std::vector<uint32_t>& source) {
    source.clear();
    const size_t size = reference.triangles.size();
    if (target >= size) {
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
    // Triangles around every reference vertex, for growing the kept region.
    std::vector<uint32_t> start(reference.positions.size() + 1, 0), around(3 * size);
    for (const Triangle& t : reference.triangles)
        for (uint32_t v : t) ++start[v + 1];
    for (size_t v = 0; v < reference.positions.size(); ++v) start[v + 1] += start[v];
    {
        std::vector<uint32_t> fill(start.begin(), start.end() - 1);
        for (uint32_t t = 0; t < size; ++t)
            for (uint32_t v : reference.triangles[t]) around[fill[v]++] = t;
    }
    std::vector<uint8_t> kept(size, 0), kept_before;
    size_t kept_count = 0, kept_count_before = 0, fewest_lost = size_t(-1);
    bool growing = true;
    std::string last_problem;
    for (int attempt = 0; attempt < 24 && target < size; ++attempt) {
        std::vector<unsigned> indices, simplified;
        for (uint32_t t = 0; t < size; ++t)
            if (!kept[t]) indices.insert(indices.end(), reference.triangles[t].begin(), reference.triangles[t].end());
        simplified.resize(indices.size());
        const size_t goal = std::min<size_t>(target, indices.size() / 3);
        const size_t count = meshopt_simplify(simplified.data(), indices.data(), indices.size(), xyz.data(),
                                              reference.positions.size(), 3 * sizeof(float), goal * 3, 1.0f,
                                              kept_count > 0 ? meshopt_SimplifyLockBorder : 0, nullptr);
        simplified.resize(count);
        for (uint32_t t = 0; t < size; ++t)
            if (kept[t]) simplified.insert(simplified.end(), reference.triangles[t].begin(), reference.triangles[t].end());
        // Pillows go; the validation below decides whether what is left is usable.
        std::map<std::array<unsigned, 3>, int> copies;
        for (size_t i = 0; i + 2 < simplified.size(); i += 3) {
            std::array<unsigned, 3> key{simplified[i], simplified[i + 1], simplified[i + 2]};
            std::sort(key.begin(), key.end());
            ++copies[key];
        }
        TriangleMesh base;
        base.single_precision = reference.single_precision;
        std::vector<uint32_t> remap(reference.positions.size(), kNoVertex);
        for (size_t i = 0; i + 2 < simplified.size(); i += 3) {
            std::array<unsigned, 3> key{simplified[i], simplified[i + 1], simplified[i + 2]};
            std::sort(key.begin(), key.end());
            if (copies[key] > 1) continue;
            Triangle t;
            for (int k = 0; k < 3; ++k) {
                uint32_t& id = remap[simplified[i + k]];
                if (id == kNoVertex) {
                    id = uint32_t(base.positions.size());
                    base.positions.push_back(reference.positions[simplified[i + k]]);
                    source.push_back(simplified[i + k]);
                }
                t[k] = id;
            }
            base.triangles.push_back(t);
        }
        // A part lost: keep the reference's triangles around it (two rings) and simplify again,
        // while that loses fewer reference vertices (else back to the last region that helped).
        if (growing && !base.triangles.empty()) {
            std::vector<uint32_t> lost;
            base_distance(reference, on_reference, base, max_distance, &lost);
            if (!lost.empty() && lost.size() >= fewest_lost) {
                kept = kept_before;
                kept_count = kept_count_before;
                growing = false;
                source.clear();
                continue;
            }
            fewest_lost = lost.size();
            kept_before = kept;
            kept_count_before = kept_count;
            for (int ring = 0; ring < 2 && !lost.empty() && kept_count < size / 2; ++ring) {
                std::vector<uint32_t> next;
                for (uint32_t v : lost) {
                    for (uint32_t i = start[v]; i < start[v + 1]; ++i) {
                        const uint32_t t = around[i];
                        if (kept[t]) continue;
                        kept[t] = 1;
                        ++kept_count;
                        next.insert(next.end(), reference.triangles[t].begin(), reference.triangles[t].end());
                    }
                }
                lost = std::move(next);
            }
            if (kept_count > kept_count_before) {
                source.clear();
                continue;
            }
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
    if (last_problem.empty() || target >= size) return simplify_to_base(reference, on_reference, uint32_t(size), max_distance, source);
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
    const MeshShape reference_shape = measure_shape(reference);
    s.reference_fold_overs = reference_shape.fold_overs;
    // A base that folds over passes its folds on to every level below it (the correction falls
    // back on the flat subdivision of the base, which folds wherever the base does), and a thin
    // part the base flattened stays lost (new vertices are projected from the base). Sizes B, 2B,
    // 4B, 8B (below the reference's and half the faces asked), then B/2 and B/4 are tried; the
    // first base without fold-overs, within kBaseDistance of the reference and without slivers
    // (kBaseQuality) is taken, else the best by that order.
    const double diagonal = bounding_box_diagonal(reference);
    const uint64_t reference_size = reference.triangles.size();
    const uint64_t asked = std::max<uint32_t>(options.base_triangles, 4);
    std::vector<uint64_t> targets;
    const uint64_t largest = std::max<uint64_t>(asked, options.target_faces / 2);  // leave refinement room
    for (uint64_t t = asked; t < reference_size && t <= largest && targets.size() < 4; t *= 2) targets.push_back(t);
    if (targets.empty()) targets.push_back(asked);  // the reference is its own base
    for (uint64_t t = std::min(asked, reference_size) / 2; t >= kSmallestBase && targets.size() < 6; t /= 2)
        targets.push_back(t);
    const double good_quality = std::min(kBaseQuality, 0.5 * reference_shape.min_quality);
    TriangleMesh base;
    bool have_base = false;
    std::tuple<uint32_t, bool, bool, double> best_rank;
    std::string problem;
    for (const uint64_t target : targets) {
        std::vector<uint32_t> source;
        TriangleMesh candidate;
        try {
            candidate = simplify_to_base(reference, surface.faces(), uint32_t(target), kBaseDistance * diagonal, source);
        } catch (const Error& e) {
            problem = e.what();  // no valid base near this size (simplify_to_base tried a few)
            continue;
        }
        ++s.base_attempts;
        if (single) {
            for (Vec3& p : candidate.positions) p = round_to_float(p);
        }
        candidate.single_precision = single;
        std::vector<uint8_t> locked(candidate.positions.size());
        for (size_t v = 0; v < locked.size(); ++v) locked[v] = sharp[source[v]];
        ShapeImprovementStats improved = improve_shapes(candidate, surface, reference, locked);
        if (improved.fold_overs_after > 0) {
            improved.fold_overs_after = unfold(candidate, options.min_quality);
            improved.min_quality_after = measure_shape(candidate).min_quality;
        }
        const double distance = base_distance(reference, surface.faces(), candidate, 0, nullptr) / diagonal;
        // Fold-overs first, then straying, then slivers (which the leaf mesh's quality bound, a
        // third of the base triangle's, would pass on), then the distance.
        const auto rank = std::make_tuple(improved.fold_overs_after, distance > kBaseDistance,
                                          improved.min_quality_after < good_quality, distance);
        if (!have_base || rank < best_rank) {
            best_rank = rank;
            base = std::move(candidate);
            have_base = true;
            s.base_min_quality = improved.min_quality_after;
            s.base_fold_overs = improved.fold_overs_after;
            s.base_distance = distance;
        }
        if (std::get<0>(best_rank) == 0 && !std::get<1>(best_rank) && !std::get<2>(best_rank)) break;
    }
    if (!have_base) throw Error(problem);
    Hierarchy h(std::move(base));
    s.base_triangles = h.root_count();
    // Refused before refining where the target can only be met past max_nodes: a leaf shows at
    // most 3 triangles, and short of the target every leaf reaches max_level (counted up to 2^32).
    const uint64_t leaves_at_max_level = uniform_leaf_count(h.root_count(), options.max_level, uint64_t{1} << 32);
    const uint64_t fewest_leaves = std::min<uint64_t>(options.target_faces / 3, leaves_at_max_level);
    AMC_REQUIRE(fewest_leaves <= options.max_nodes, limit_exceeded,
                "remesh: at least " + std::to_string(fewest_leaves) + " leaves, more than " +
                    std::to_string(options.max_nodes) + " nodes");
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
        const auto hit = surface.faces().closest(node_centroid(h, n));
        if (options.criterion == RefinementCriterion::approximation_error) return std::sqrt(hit.distance_squared);
        return std::fabs(interpolate_at(reference, curvature, hit)) * node_diameter(h, n);
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
            AMC_REQUIRE(h.node_count() <= options.max_nodes, limit_exceeded,
                        "remesh: more than " + std::to_string(options.max_nodes) + " nodes");
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
        AMC_REQUIRE(h.node_count() <= options.max_nodes, limit_exceeded,
                    "remesh: more than " + std::to_string(options.max_nodes) + " nodes");
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
        s.distance_measured = d.complete();
        if (s.distance_measured) {
            s.max_distance = d.max;
            s.max_distance_bound = d.max_upper;
            s.rms_distance = d.rms;
        }
        s.measure_seconds = seconds_since(start);
    }
    return h;
}

}  // namespace amc
