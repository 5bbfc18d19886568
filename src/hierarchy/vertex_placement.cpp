// Placing the remesher's new vertices on the reference, and correcting them on the leaf mesh.
#include "hierarchy/vertex_placement.h"

#include "common/mixing.h"
#include "common/no_index.h"
#include "geometry/placement_normal.h"
#include "geometry/surface_quality.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <optional>
#include <set>
#include <unordered_map>

namespace amc {
namespace {

// A new vertex may tilt the halves of the elements it splits by at most this much, and leave
// them at least this fraction of their flat quality; else a nearer candidate (or the midpoint).
constexpr double kPlacementTiltDegrees = 80.0;
constexpr double kPlacementQualityFraction = 0.2;
// Rounds of sliding the corners of bad triangles along the surface.
constexpr int kSlideRounds = 8;

Vec3 round_to_float(Vec3 p) { return {double(float(p.x)), double(float(p.y)), double(float(p.z))}; }
double length(Vec3 v) { return std::sqrt(dot(v, v)); }
Vec3 unit(Vec3 v) {
    const double l = length(v);
    return l > 0 ? (1 / l) * v : Vec3{};
}

// The halves (corner 1 of each is the new vertex) with the new vertex at p: within the tilt and
// quality limits of their flat shape. Where the two elements meet at more than 90 degrees (a
// fold of the coarse mesh) tilting is the point, and only the quality counts.
bool admissible(const std::vector<std::array<Vec3, 3>>& halves, Vec3 p, bool folded) {
    static const double min_cos = std::cos(kPlacementTiltDegrees * 3.14159265358979323846 / 180.0);
    for (const auto& half : halves) {
        const Vec3 flat = cross(half[1] - half[0], half[2] - half[0]);
        const Vec3 moved = cross(p - half[0], half[2] - half[0]);
        if (!folded && !(dot(moved, flat) >= min_cos * length(moved) * length(flat))) return false;
        if (triangle_quality(half[0], p, half[2]) < kPlacementQualityFraction * triangle_quality(half[0], half[1], half[2]))
            return false;
    }
    return true;
}

// Interior edges of a triangle list as pairs of triangle indices, through neighbour links:
// neighbors[3t + k] is the triangle across edge k of t (corner k to k+1), or kNoIndex.
std::vector<uint32_t> triangle_neighbors(const std::vector<Triangle>& triangles) {
    std::vector<std::pair<uint64_t, uint32_t>> edges;
    edges.reserve(3 * triangles.size());
    for (size_t t = 0; t < triangles.size(); ++t) {
        for (int k = 0; k < 3; ++k) {
            uint64_t u = triangles[t][k], v = triangles[t][(k + 1) % 3];
            if (u > v) std::swap(u, v);
            edges.push_back({u << 32 | v, uint32_t(3 * t + k)});
        }
    }
    std::sort(edges.begin(), edges.end());
    std::vector<uint32_t> neighbors(3 * triangles.size(), kNoIndex);
    for (size_t i = 0; i + 1 < edges.size(); ++i) {
        if (edges[i].first != edges[i + 1].first) continue;
        neighbors[edges[i].second] = edges[i + 1].second / 3;
        neighbors[edges[i + 1].second] = edges[i].second / 3;
    }
    return neighbors;
}

// The correction of correct_placements on the leaf mesh, whose connectivity stays while the
// positions (read from and written to the hierarchy) change.
class LeafCorrection {
public:
    LeafCorrection(Hierarchy& h, Placements& placements, const ReferenceSurface& surface, double min_quality);
    CorrectionResult run();

private:
    Vec3 position(uint32_t v) const { return h_.position(id_of_[v]); }
    Vec3 normal(uint32_t t) const {
        const Triangle& c = leaf_.mesh.triangles[t];
        const Vec3 a = position(c[0]);
        return cross(position(c[1]) - a, position(c[2]) - a);
    }
    double quality(uint32_t t) const {
        const Triangle& c = leaf_.mesh.triangles[t];
        return triangle_quality(position(c[0]), position(c[1]), position(c[2]));
    }
    bool inherited_fold(uint32_t t, uint32_t g) const {
        auto flat_normal = [&](uint32_t u) {
            const Triangle& c = leaf_.mesh.triangles[u];
            return cross(flat_[c[1]] - flat_[c[0]], flat_[c[2]] - flat_[c[0]]);
        };
        return is_fold_over(flat_normal(t), flat_normal(g));
    }
    bool triangle_bad(uint32_t t) const {
        if (quality(t) < bound_[t]) return true;
        const Vec3 n = normal(t);
        for (int k = 0; k < 3; ++k) {
            const uint32_t g = neighbors_[3 * t + k];
            if (g != kNoIndex && is_fold_over(n, normal(g)) && !inherited_fold(t, g)) return true;
        }
        return false;
    }
    bool coincident(uint32_t v) const { return count_at_.at(position(v)) > 1; }
    bool needs_work(uint32_t t) const {
        if (triangle_bad(t)) return true;
        for (uint32_t v : leaf_.mesh.triangles[t])
            if (coincident(v)) return true;
        return false;
    }
    // Bad triangles around leaf vertex v, plus one if v coincides with another vertex.
    int badness_around(uint32_t v) const {
        int bad = coincident(v) ? 1 : 0;
        for (uint32_t i = start_[v]; i < start_[v + 1]; ++i) bad += triangle_bad(around_[i]);
        return bad;
    }
    double worst_around(uint32_t v) const {
        double worst = 1;
        for (uint32_t i = start_[v]; i < start_[v + 1]; ++i) worst = std::min(worst, quality(around_[i]));
        return worst;
    }
    bool movable(VertexId id) const { return placements_.is_placed(id) && placements_.step[id] < Placements::kSteps; }
    Vec3 midpoint_of(VertexId id) const {
        return 0.5 * (h_.position(placements_.end_a[id]) + h_.position(placements_.end_b[id]));
    }
    Vec3 stepped_position(VertexId id, int step) const {
        const Vec3 p = midpoint_of(id) + (1 - double(step) / Placements::kSteps) * placements_.offset[id];
        return h_.single_precision() ? round_to_float(p) : p;
    }
    void move(uint32_t v, Vec3 p) {
        auto it = count_at_.find(position(v));
        if (--it->second == 0) count_at_.erase(it);
        h_.set_position(id_of_[v], p);
        ++count_at_[p];
    }
    bool slide(uint32_t v);
    uint32_t step_one_corner(uint32_t t);
    bool flatten(NodeId node, std::vector<uint8_t>& moved);
    std::vector<uint32_t> follow_stepped();
    // The stepped vertices on edges that end at `id` may now be off their step.
    void unsettle_dependents(VertexId id) {
        for (uint32_t i = dependent_start_[id]; i < dependent_start_[id + 1]; ++i) unsettled_.insert(dependents_[i]);
    }

    Hierarchy& h_;
    Placements& placements_;
    const ReferenceSurface& surface_;
    const LeafMesh leaf_;
    std::vector<VertexId> id_of_;           // hierarchy vertex of every leaf-mesh vertex
    std::vector<uint32_t> leaf_index_;      // and back (kNoIndex for dead ids)
    std::vector<double> bound_;             // quality bound of every leaf triangle
    std::vector<uint32_t> neighbors_;       // 3 per triangle, kNoIndex on the boundary
    std::vector<uint32_t> start_, around_;  // triangles around every leaf vertex
    std::vector<Vec3> flat_;                // every leaf vertex in the flat subdivision of the base
    std::unordered_map<Vec3, uint32_t, PositionHash> count_at_;
    std::set<VertexId> stepped_;            // placed vertices with a step, coarse to fine
    std::vector<uint32_t> dependent_start_;  // the placed vertices on edges that end at each vertex
    std::vector<VertexId> dependents_;
    std::set<VertexId> unsettled_;  // vertices that may be off their step: flattened, or an edge end moved
};

LeafCorrection::LeafCorrection(Hierarchy& h, Placements& placements, const ReferenceSurface& surface, double min_quality)
    : h_(h), placements_(placements), surface_(surface), leaf_(extract_leaf_mesh(h)) {
    const std::vector<uint32_t> canonical = canonical_vertex_order(h);
    id_of_.assign(leaf_.mesh.positions.size(), kNoVertex);
    leaf_index_.assign(h.positions().size(), kNoIndex);
    for (VertexId v = 0; v < canonical.size(); ++v) {
        if (canonical[v] == kNoVertex || canonical[v] >= id_of_.size()) continue;
        id_of_[canonical[v]] = v;
        leaf_index_[v] = canonical[v];
    }
    placements_.grow(h.positions().size());
    const size_t n = leaf_.mesh.triangles.size();
    bound_.resize(n);
    const TriangleMesh& base = h.base();
    for (size_t t = 0; t < n; ++t) {
        NodeId root = leaf_.source[t];
        while (h.parent(root) != kNoNode) root = h.parent(root);
        const Triangle& c = base.triangles[root];
        const double flat = triangle_quality(base.positions[c[0]], base.positions[c[1]], base.positions[c[2]]) / 3;
        bound_[t] = std::min(min_quality, 0.999 * flat);  // 0.999: the flat subdivision's rounding
    }
    neighbors_ = triangle_neighbors(leaf_.mesh.triangles);
    start_.assign(id_of_.size() + 1, 0);
    for (const Triangle& t : leaf_.mesh.triangles)
        for (uint32_t v : t) ++start_[v + 1];
    for (size_t v = 0; v < id_of_.size(); ++v) start_[v + 1] += start_[v];
    around_.resize(3 * n);
    std::vector<uint32_t> fill(start_.begin(), start_.end() - 1);
    for (uint32_t t = 0; t < n; ++t)
        for (uint32_t v : leaf_.mesh.triangles[t]) around_[fill[v]++] = t;
    for (uint32_t v = 0; v < id_of_.size(); ++v) ++count_at_[position(v)];
    // Coarse to fine: a vertex id is larger than its edge's ends' (refinement only adds).
    std::vector<Vec3> flat_by_id(h.positions().size());
    for (VertexId id = 0; id < flat_by_id.size(); ++id) {
        flat_by_id[id] = placements_.is_placed(id)
                             ? 0.5 * (flat_by_id[placements_.end_a[id]] + flat_by_id[placements_.end_b[id]])
                             : h.position(id);
    }
    flat_.resize(id_of_.size());
    for (uint32_t v = 0; v < id_of_.size(); ++v) flat_[v] = flat_by_id[id_of_[v]];
    dependent_start_.assign(h.positions().size() + 1, 0);
    for (VertexId id = 0; id < h.positions().size(); ++id)
        if (placements_.is_placed(id)) {
            ++dependent_start_[placements_.end_a[id] + 1];
            ++dependent_start_[placements_.end_b[id] + 1];
        }
    for (size_t id = 0; id + 1 < dependent_start_.size(); ++id) dependent_start_[id + 1] += dependent_start_[id];
    dependents_.resize(dependent_start_.back());
    std::vector<uint32_t> next(dependent_start_.begin(), dependent_start_.end() - 1);
    for (VertexId id = 0; id < h.positions().size(); ++id)
        if (placements_.is_placed(id)) {
            dependents_[next[placements_.end_a[id]]++] = id;
            dependents_[next[placements_.end_b[id]]++] = id;
        }
}

CorrectionResult LeafCorrection::run() {
    CorrectionResult result;
    const uint32_t triangle_count = uint32_t(leaf_.mesh.triangles.size());
    std::vector<uint8_t> moved(h_.positions().size(), 0);
    std::vector<uint32_t> queue;
    std::vector<uint8_t> queued(triangle_count, 0);
    auto push = [&](uint32_t t) {
        if (queued[t]) return;
        queued[t] = 1;
        queue.push_back(t);
    };
    auto push_around = [&](uint32_t v) {
        for (uint32_t i = start_[v]; i < start_[v + 1]; ++i) {
            const uint32_t t = around_[i];
            push(t);
            for (int k = 0; k < 3; ++k)
                if (neighbors_[3 * t + k] != kNoIndex) push(neighbors_[3 * t + k]);
        }
    };
    // The bad triangles among those queued (the queue empties).
    auto take_bad = [&]() {
        std::vector<uint32_t> bad;
        for (uint32_t t : queue) {
            queued[t] = 0;
            if (needs_work(t)) bad.push_back(t);
        }
        queue.clear();
        return bad;
    };
    for (uint32_t t = 0; t < triangle_count; ++t) push(t);
    std::vector<uint32_t> bad = take_bad();
    for (int round = 0; round < kSlideRounds && !bad.empty(); ++round) {
        std::vector<uint32_t> corners;
        for (uint32_t t : bad)
            for (uint32_t v : leaf_.mesh.triangles[t])
                if (placements_.is_placed(id_of_[v])) corners.push_back(v);
        std::sort(corners.begin(), corners.end());
        corners.erase(std::unique(corners.begin(), corners.end()), corners.end());
        for (uint32_t t : bad) push(t);
        uint32_t slides = 0;
        for (uint32_t v : corners) {
            if (!slide(v)) continue;
            moved[id_of_[v]] = 1;
            push_around(v);
            ++slides;
        }
        result.slides += slides;
        bad = take_bad();
        if (slides == 0) break;
    }
    // Steps back, re-examining the triangles around every move.
    for (uint32_t t : bad) push(t);
    while (!queue.empty()) {
        while (!queue.empty()) {
            const uint32_t t = queue.back();
            queue.pop_back();
            queued[t] = 0;
            if (!needs_work(t)) continue;
            const uint32_t v = step_one_corner(t);
            if (v != kNoIndex) {
                ++result.steps;
                moved[id_of_[v]] = 1;
                push_around(v);
                push(t);
            } else if (flatten(leaf_.source[t], moved)) {
                ++result.flattened;
                for (uint32_t w : follow_stepped()) push_around(w);
                push(t);
            }
        }
        // Vertices stepped back follow their edges' ends, which may have moved since.
        for (uint32_t w : follow_stepped()) push_around(w);
    }
    for (uint32_t t = 0; t < triangle_count; ++t) {
        const Vec3 n = normal(t);
        for (int k = 0; k < 3; ++k) {
            const uint32_t g = neighbors_[3 * t + k];
            result.inherited_fold_overs += g != kNoIndex && g > t && is_fold_over(n, normal(g)) && inherited_fold(t, g);
        }
    }
    for (uint8_t m : moved) result.moved += m;
    return result;
}

// Slides leaf vertex v to the point of the surface, among a few, that leaves the least badness
// around it (ties: the best worst quality), if that is better than where it is: towards the
// centroid of its triangles by half, all and one and a half of the way, and its edge's midpoint
// projected again along the normal of its triangles as they are now.
bool LeafCorrection::slide(uint32_t v) {
    const VertexId id = id_of_[v];
    if (!placements_.is_placed(id) || placements_.step[id] != 0) return false;
    const Vec3 p = position(v);
    Vec3 centroid{}, normal_sum{};
    double weight = 0;
    for (uint32_t i = start_[v]; i < start_[v + 1]; ++i) {
        const Triangle& c = leaf_.mesh.triangles[around_[i]];
        const Vec3 n = normal(around_[i]);
        const double area = length(n);
        normal_sum = normal_sum + n;
        centroid = centroid + area * ((1.0 / 3.0) * (position(c[0]) + position(c[1]) + position(c[2])));
        weight += area;
    }
    if (!(weight > 0)) return false;
    const Vec3 n = unit(normal_sum);
    Vec3 shift = (1 / weight) * centroid - p;
    shift = shift - dot(shift, n) * n;
    const Vec3 mid = midpoint_of(id);
    const double shift_length = length(shift);
    const std::pair<Vec3, double> starts[] = {{p + shift, shift_length},
                                              {p + 0.5 * shift, shift_length},
                                              {p + 1.5 * shift, 1.5 * shift_length},
                                              {mid, length(h_.position(placements_.end_a[id]) - mid)}};
    int best_bad = badness_around(v);
    double best_worst = worst_around(v);
    Vec3 best = p;
    for (const auto& [from, size] : starts) {
        std::optional<Vec3> target = surface_.project_along(from, n, 2 * size);
        if (!target) target = surface_.project(from, n, 2 * size);
        if (!target) continue;
        const Vec3 q = h_.single_precision() ? round_to_float(*target) : *target;
        if (q == p || count_at_.count(q)) continue;
        move(v, q);
        const int bad = badness_around(v);
        const double worst = worst_around(v);
        if (bad < best_bad || (bad == best_bad && worst > best_worst)) {
            best = q;
            best_bad = bad;
            best_worst = worst;
        }
        move(v, p);
    }
    if (best == p) return false;
    move(v, best);
    placements_.offset[id] = best - mid;
    return true;
}

// Steps one corner of triangle t back; returns the leaf vertex moved, or kNoIndex if none can move.
uint32_t LeafCorrection::step_one_corner(uint32_t t) {
    uint32_t best_vertex = kNoIndex;
    int best_step = 0, best_change = 0;
    double best_distance = 0;
    for (uint32_t v : leaf_.mesh.triangles[t]) {
        const VertexId id = id_of_[v];
        if (!movable(id)) continue;
        const Vec3 old = position(v);
        const int before = badness_around(v);
        for (int step = placements_.step[id] + 1; step <= Placements::kSteps; ++step) {
            const Vec3 p = stepped_position(id, step);
            move(v, p);
            const int change = badness_around(v) - before;
            const double distance = length(p - old);
            const bool better = best_vertex == kNoIndex || (change < 0 && best_change >= 0) ||
                                ((change < 0) == (best_change < 0) && distance < best_distance);
            if (better) {
                best_vertex = v;
                best_step = step;
                best_change = change;
                best_distance = distance;
            }
        }
        move(v, old);
    }
    if (best_vertex == kNoIndex) return kNoIndex;
    const VertexId id = id_of_[best_vertex];
    placements_.step[id] = uint8_t(best_step);
    stepped_.insert(id);
    move(best_vertex, stepped_position(id, best_step));
    unsettle_dependents(id);
    return best_vertex;
}

// Sends the movable corners of `node`, or of its nearest ancestor that has some, to their last step.
bool LeafCorrection::flatten(NodeId node, std::vector<uint8_t>& moved) {
    for (NodeId n = node; n != kNoNode; n = h_.parent(n)) {
        bool any = false;
        for (int i = 0; i < 3; ++i) {
            const VertexId id = h_.vertex(n, i);
            if (!movable(id)) continue;
            placements_.step[id] = Placements::kSteps;
            stepped_.insert(id);
            unsettled_.insert(id);
            moved[id] = 1;
            any = true;
        }
        if (any) return true;
    }
    return false;
}

// Puts every stepped vertex at its step from its edge's midpoint as the edge is now, coarse to
// fine (an id is larger than its edge's ends'); returns the leaf vertices that moved. Only the
// unsettled ones can be off their step, so the pass costs what moved, not every stepped vertex.
std::vector<uint32_t> LeafCorrection::follow_stepped() {
    std::vector<uint32_t> changed;
    while (!unsettled_.empty()) {
        const VertexId id = *unsettled_.begin();
        unsettled_.erase(unsettled_.begin());
        if (!stepped_.count(id) || leaf_index_[id] == kNoIndex) continue;
        const Vec3 p = stepped_position(id, placements_.step[id]);
        if (p == h_.position(id)) continue;
        move(leaf_index_[id], p);
        changed.push_back(leaf_index_[id]);
        unsettle_dependents(id);
    }
    return changed;
}

}  // namespace

void Placements::grow(size_t vertex_count) {
    if (end_a.size() >= vertex_count) return;
    end_a.resize(vertex_count, kNoVertex);
    end_b.resize(vertex_count, kNoVertex);
    offset.resize(vertex_count);
    step.resize(vertex_count, 0);
}

size_t PositionHash::operator()(Vec3 p) const {
    auto bits = [](double x) {
        uint64_t u;
        std::memcpy(&u, &x, sizeof u);
        return u;
    };
    return size_t(hash_words(bits(p.x), bits(p.y), bits(p.z)));
}

VertexPlacement::VertexPlacement(Hierarchy& h, const ReferenceSurface& surface)
    : h_(h), surface_(surface), single_(h.single_precision()) {
    for (const Vec3& p : h.positions()) taken_.insert(p);
}

void VertexPlacement::place(const std::vector<NodeId>& split) {
    placements_.grow(h_.positions().size());
    for (NodeId s : split) {
        for (int e = 0; e < 3; ++e) {
            const VertexId m = h_.midpoint(s, e);
            if (!placements_.is_placed(m)) place_midpoint(s, e, m);
        }
    }
}

void VertexPlacement::place_midpoint(NodeId s, int e, VertexId m) {
    const VertexId ia = h_.vertex(s, e), ib = h_.vertex(s, (e + 1) % 3);
    const Vec3 a = h_.position(ia), b = h_.position(ib), c = h_.position(h_.vertex(s, (e + 2) % 3));
    const Vec3 mid = 0.5 * (a + b);
    const double reach = length(b - a);
    const NodeId q = h_.neighbor(s, e);
    // The elements on the edge cut in two at the new vertex (corner 1 of every half).
    std::vector<std::array<Vec3, 3>> halves = {{a, mid, c}, {c, mid, b}};
    Vec3 normal = cross(b - a, c - a);
    bool folded = false;
    if (q != kNoNode) {
        const Vec3 d = h_.position(h_.vertex(q, (h_.neighbor_edge(s, e) + 2) % 3));
        halves.push_back({b, mid, d});
        halves.push_back({d, mid, a});
        folded = dot(normal, cross(a - b, d - b)) < 0;
        normal = placement_normal(a, b, c, d);
    }
    Vec3 p = single_ ? round_to_float(mid) : mid;
    auto take = [&](std::optional<Vec3> candidate) {
        if (!candidate) return false;
        const Vec3 c = single_ ? round_to_float(*candidate) : *candidate;
        if (taken_.count(c) || !admissible(halves, c, folded)) return false;
        p = c;
        return true;
    };
    if (q == kNoNode) {
        const std::optional<Vec3> on_boundary = surface_.project_to_boundary(mid, reach);
        if (!take(on_boundary) && on_boundary) take(0.5 * (mid + *on_boundary));
    } else {
        const std::optional<Vec3> along = surface_.project_along(mid, normal, reach);
        if (!take(along)) {
            const std::optional<Vec3> facing = surface_.project(mid, normal, reach);
            if (!take(facing)) {
                // Nothing facing the element near it (an element spanning a hole or a gap): the
                // nearest point of the surface at all.
                const Vec3 nearest = surface_.faces().closest(mid).point;
                if (!take(nearest)) take(0.5 * (mid + (along ? *along : facing ? *facing : nearest)));
            }
        }
    }
    taken_.insert(p);
    h_.set_position(m, p);
    placements_.end_a[m] = ia;
    placements_.end_b[m] = ib;
    placements_.offset[m] = p - mid;
}

CorrectionResult correct_placements(Hierarchy& h, Placements& placements, const ReferenceSurface& surface,
                                    double min_quality) {
    return LeafCorrection(h, placements, surface, min_quality).run();
}

std::vector<NodeId> leaves_with_fold_overs(const Hierarchy& h) {
    const LeafMesh leaf = extract_leaf_mesh(h);
    const std::vector<uint32_t> neighbors = triangle_neighbors(leaf.mesh.triangles);
    auto normal = [&](uint32_t t) {
        const Triangle& c = leaf.mesh.triangles[t];
        const Vec3 a = leaf.mesh.positions[c[0]];
        return cross(leaf.mesh.positions[c[1]] - a, leaf.mesh.positions[c[2]] - a);
    };
    std::vector<NodeId> nodes;
    for (uint32_t t = 0; t < leaf.mesh.triangles.size(); ++t) {
        for (int k = 0; k < 3; ++k) {
            const uint32_t g = neighbors[3 * t + k];
            if (g != kNoIndex && is_fold_over(normal(t), normal(g))) nodes.push_back(leaf.source[t]);
        }
    }
    std::sort(nodes.begin(), nodes.end());
    nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
    return nodes;
}

}  // namespace amc
