// Closest point on a triangle mesh: an AABB tree (flat node array, binned SAH split) and
// Ericson's point-triangle test, searched branch and bound, nearer child first.
#include "geometry/closest_point.h"

#include "common/compiler.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <limits>
#include <string>

namespace amc {
namespace {

constexpr uint32_t kLeafSize = 2;
constexpr uint32_t kEmpty = std::numeric_limits<uint32_t>::max();
constexpr int kBins = 16;
// SAH splits may be unbalanced; from this depth on only median splits, which halve the count.
// So the depth is at most kSahDepth + 32, and the traversal stack grows by at most one entry per
// level.
constexpr uint32_t kSahDepth = 48;
constexpr int kStackSize = kSahDepth + 34;
// A node is pruned when its box distance exceeds the best distance by more than this relative
// slack: both squared distances carry a few ulps of rounding error, and a node must never be
// pruned when it holds a triangle whose computed distance equals or beats the best.
constexpr double kPruneSlack = 1e-13;
// A child of the box tree that is a fan (Node::index is then into fans_).
constexpr uint32_t kFanLeaf = kEmpty;
// A fan's cone is widened by this angle (radians) for the rounding of its directions, and its
// distance bound lowered by this share of the distance to the apex for the rounding of the bound.
constexpr double kConeWidening = 1e-9;
constexpr double kConeSlack = 1e-10;
constexpr double kUnderflowSlack = 8 * std::numeric_limits<double>::denorm_min();
// Vectors shorter than this have squares below DBL_MIN: their lengths are taken after scaling by
// kTinyScale, a power of two (exact).
constexpr double kTinyLength = 0x1p-500;
constexpr double kTinyScale = 0x1p+600;
constexpr double kRightAngle = 1.5707963267948966;
// A direction this close to a cone's axis (radians) is taken to meet the cone: the side plane
// facing it is found from its part across the axis, which below this is too much rounding.
constexpr double kNearAxis = 1e-4;
// A fan's tree halves its triangles at each level: at most 32 levels, one stack entry more each.
constexpr int kConeStackSize = 34;

double squared_length(Vec3 v) { return dot(v, v); }

// Float bounds rounded outward, so the float box contains the double one.
float float_below(double x) {
    if (!(x >= -FLT_MAX)) return -std::numeric_limits<float>::infinity();
    if (x > FLT_MAX) return FLT_MAX;
    float f = static_cast<float>(x);
    return static_cast<double>(f) > x ? std::nextafter(f, -std::numeric_limits<float>::infinity())
                                      : f;
}
float float_above(double x) {
    if (!(x <= FLT_MAX)) return std::numeric_limits<float>::infinity();
    if (x < -FLT_MAX) return -FLT_MAX;
    float f = static_cast<float>(x);
    return static_cast<double>(f) < x ? std::nextafter(f, std::numeric_limits<float>::infinity())
                                      : f;
}

Vec3 component_min(Vec3 a, Vec3 b) {
    return {std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)};
}
Vec3 component_max(Vec3 a, Vec3 b) {
    return {std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)};
}
double component(Vec3 v, int axis) { return axis == 0 ? v.x : axis == 1 ? v.y : v.z; }

// Inlined: the box tree's descent spends most of its time here.
AMC_ALWAYS_INLINE double box_distance_squared(const float* lo, const float* hi, Vec3 p) {
    double dx = std::max(std::max(lo[0] - p.x, p.x - hi[0]), 0.0);
    double dy = std::max(std::max(lo[1] - p.y, p.y - hi[1]), 0.0);
    double dz = std::max(std::max(lo[2] - p.z, p.z - hi[2]), 0.0);
    return dx * dx + dy * dy + dz * dz;
}

// |v|, accurate where its squares would fall below DBL_MIN.
double length_without_underflow(Vec3 v) {
    const double length = std::sqrt(squared_length(v));
    return length < kTinyLength ? std::sqrt(squared_length(kTinyScale * v)) / kTinyScale : length;
}

// What covers the rounding of the closest points computed on triangles whose coordinates are at
// most max_abs in magnitude (a few ulps of them), an axis.
double rounding_margin(double max_abs) { return 16 * DBL_EPSILON * max_abs; }

double max_abs_component(Vec3 lo, Vec3 hi) {
    return std::max({std::fabs(lo.x), std::fabs(lo.y), std::fabs(lo.z), std::fabs(hi.x), std::fabs(hi.y), std::fabs(hi.z)});
}

// The box [lo, hi] relative to `origin`, widened by the rounding margin of its own coordinates (not
// the whole mesh's: one far-away triangle would widen every box to the size of the mesh) and by the
// rounding of the subtraction of the origin (here and in a query), as floats rounded outward;
// returns the first margin.
double store_box(Vec3 lo, Vec3 hi, Vec3 origin, float* lo_out, float* hi_out) {
    const double margin = rounding_margin(max_abs_component(lo, hi));
    const Vec3 relative_lo = lo - origin, relative_hi = hi - origin;
    const double widening = margin + 4 * DBL_EPSILON * max_abs_component(relative_lo, relative_hi);
    for (int axis = 0; axis < 3; ++axis) {
        lo_out[axis] = float_below(component(relative_lo, axis) - widening);
        hi_out[axis] = float_above(component(relative_hi, axis) + widening);
    }
    return margin;
}

// Whether q lies in the box of triangle (a, b, c) widened by the rounding margin of its coordinates
// and by `widening` times its extent on each axis: where a line's hit must be for the tree's boxes,
// which hold that much around their triangles, to find it.
bool in_triangle_box(Vec3 q, Vec3 a, Vec3 b, Vec3 c, double widening) {
    const Vec3 lo = component_min(component_min(a, b), c), hi = component_max(component_max(a, b), c);
    const double margin = rounding_margin(max_abs_component(lo, hi));
    for (int axis = 0; axis < 3; ++axis) {
        const double extent = component(hi, axis) - component(lo, axis);
        const double w = margin + (widening > 0 ? widening * extent : 0.0);
        const double x = component(q, axis);
        if (!(x >= component(lo, axis) - w && x <= component(hi, axis) + w)) return false;
    }
    return true;
}

// Per axis, the median of the finite coordinates (0 where there are none): an origin near most of
// the mesh whatever a few far-away parts add.
Vec3 median_of_finite(const std::vector<Vec3>& points) {
    std::vector<double> values;
    values.reserve(points.size());
    double median[3] = {0, 0, 0};
    for (int axis = 0; axis < 3; ++axis) {
        values.clear();
        for (const Vec3& p : points) {
            const double x = component(p, axis);
            if (std::isfinite(x)) values.push_back(x);
        }
        if (values.empty()) continue;
        std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
        median[axis] = values[values.size() / 2];
    }
    return {median[0], median[1], median[2]};
}

// Closest point to p on segment [x, y]; t is the weight of y.
Vec3 closest_point_on_segment(Vec3 p, Vec3 x, Vec3 y, double& t) {
    Vec3 xy = y - x;
    double length_squared = dot(xy, xy);
    t = length_squared > 0 ? std::clamp(dot(p - x, xy) / length_squared, 0.0, 1.0) : 0.0;
    return x + t * xy;
}

// Zero-area (or numerically hopeless) triangles: the nearest of the closest points on the three
// edges. Such a triangle is a segment or a point, so this is exact.
Vec3 closest_point_on_edges(Vec3 p, Vec3 a, Vec3 b, Vec3 c, Vec3& barycentric) {
    double t_ab, t_bc, t_ca;
    Vec3 q_ab = closest_point_on_segment(p, a, b, t_ab);
    Vec3 q_bc = closest_point_on_segment(p, b, c, t_bc);
    Vec3 q_ca = closest_point_on_segment(p, c, a, t_ca);
    double d_ab = squared_length(p - q_ab);
    double d_bc = squared_length(p - q_bc);
    double d_ca = squared_length(p - q_ca);
    if (d_ab <= d_bc && d_ab <= d_ca) {
        barycentric = {1 - t_ab, t_ab, 0};
        return q_ab;
    }
    if (d_bc <= d_ca) {
        barycentric = {0, 1 - t_bc, t_bc};
        return q_bc;
    }
    barycentric = {t_ca, 0, 1 - t_ca};
    return q_ca;
}

}  // namespace

Vec3 closest_point_on_triangle(Vec3 p, Vec3 a, Vec3 b, Vec3 c, Vec3& barycentric) {
    // Ericson, Real-Time Collision Detection, 5.1.5: vertex regions, edge regions, then the face.
    Vec3 ab = b - a;
    Vec3 ac = c - a;
    Vec3 ap = p - a;
    double d1 = dot(ab, ap);
    double d2 = dot(ac, ap);
    if (d1 <= 0 && d2 <= 0) {
        barycentric = {1, 0, 0};
        return a;
    }
    Vec3 bp = p - b;
    double d3 = dot(ab, bp);
    double d4 = dot(ac, bp);
    if (d3 >= 0 && d4 <= d3) {
        barycentric = {0, 1, 0};
        return b;
    }
    double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) {
        double v = d1 / (d1 - d3);
        barycentric = {1 - v, v, 0};
        return a + v * ab;
    }
    Vec3 cp = p - c;
    double d5 = dot(ab, cp);
    double d6 = dot(ac, cp);
    if (d6 >= 0 && d5 <= d6) {
        barycentric = {0, 0, 1};
        return c;
    }
    double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) {
        double w = d2 / (d2 - d6);
        barycentric = {1 - w, 0, w};
        return a + w * ac;
    }
    double va = d3 * d6 - d5 * d4;
    if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
        double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        barycentric = {0, 1 - w, w};
        return b + w * (c - b);
    }
    // Face region. va + vb + vc = |ab x ac|^2; in exact arithmetic all three are positive here,
    // but a (nearly) zero-area triangle can reach this point with rounding noise instead.
    double sum = va + vb + vc;
    if (!(va > 0 && vb > 0 && vc > 0 && sum > 0 && std::isfinite(sum))) {
        return closest_point_on_edges(p, a, b, c, barycentric);
    }
    double v = vb / sum;
    double w = vc / sum;
    barycentric = {std::max(1 - v - w, 0.0), v, w};
    return a + v * ab + w * ac;
}

ClosestPointQuery::ClosestPointQuery(const TriangleMesh& reference) {
    const std::vector<Vec3>& positions = reference.positions;
    const std::vector<Triangle>& triangles = reference.triangles;
    if (triangles.empty()) throw Error("closest point query: the reference mesh has no triangles");
    if (triangles.size() >= kEmpty) {
        throw Error("closest point query: the reference mesh has too many triangles");
    }
    const uint32_t n = static_cast<uint32_t>(triangles.size());

    std::vector<uint32_t> valence(positions.size(), 0);
    for (uint32_t t = 0; t < n; ++t) {
        for (uint32_t v : triangles[t]) {
            if (v >= positions.size()) {
                throw Error("closest point query: triangle " + std::to_string(t) +
                            " refers to vertex " + std::to_string(v) + " of " +
                            std::to_string(positions.size()));
            }
            ++valence[v];
        }
    }

    // The fans: each triangle goes to its corner of highest valence (ties to the lower vertex)
    // when that reaches kFanValence. A fan whose directions cannot be measured (a corner not
    // finite, a squared length that overflows) stays in the box tree.
    std::vector<uint32_t> fan_of_vertex(positions.size(), kEmpty);
    std::vector<uint32_t> fan_apexes;
    std::vector<std::vector<uint32_t>> fan_triangles;
    for (uint32_t t = 0; t < n; ++t) {
        uint32_t apex = kEmpty;
        for (uint32_t v : triangles[t]) {
            if (valence[v] >= kFanValence && (apex == kEmpty || valence[v] > valence[apex] || (valence[v] == valence[apex] && v < apex))) apex = v;
        }
        if (apex == kEmpty) continue;
        if (fan_of_vertex[apex] == kEmpty) {
            fan_of_vertex[apex] = static_cast<uint32_t>(fan_apexes.size());
            fan_apexes.push_back(apex);
            fan_triangles.emplace_back();
        }
        fan_triangles[fan_of_vertex[apex]].push_back(t);
    }
    std::vector<bool> in_fan(n, false);
    {
        size_t kept = 0;
        for (size_t f = 0; f < fan_apexes.size(); ++f) {
            const Vec3 apex = positions[fan_apexes[f]];
            bool measurable = true;
            for (uint32_t t : fan_triangles[f]) {
                for (uint32_t v : triangles[t]) {
                    const Vec3 e = positions[v] - apex;
                    if (!std::isfinite(squared_length(e))) measurable = false;
                }
            }
            if (!measurable) continue;
            for (uint32_t t : fan_triangles[f]) in_fan[t] = true;
            if (kept != f) {
                fan_apexes[kept] = fan_apexes[f];
                fan_triangles[kept] = std::move(fan_triangles[f]);
            }
            ++kept;
        }
        fan_apexes.resize(kept);
        fan_triangles.resize(kept);
    }

    // The box tree's items: the triangles outside the fans, in index order, then the fans. Each
    // has a box and a centroid (a fan's: its box's centre).
    std::vector<uint32_t> item_triangle;
    for (uint32_t t = 0; t < n; ++t) {
        if (!in_fan[t]) item_triangle.push_back(t);
    }
    const uint32_t first_fan_item = static_cast<uint32_t>(item_triangle.size());
    const uint32_t items = first_fan_item + static_cast<uint32_t>(fan_apexes.size());
    std::vector<Vec3> item_lo(items, Vec3{DBL_MAX, DBL_MAX, DBL_MAX});
    std::vector<Vec3> item_hi(items, Vec3{-DBL_MAX, -DBL_MAX, -DBL_MAX});
    std::vector<Vec3> centroids(items);
    for (uint32_t i = 0; i < first_fan_item; ++i) {
        const Triangle& triangle = triangles[item_triangle[i]];
        for (uint32_t v : triangle) {
            item_lo[i] = component_min(item_lo[i], positions[v]);
            item_hi[i] = component_max(item_hi[i], positions[v]);
        }
        const Vec3& a = positions[triangle[0]];
        const Vec3& b = positions[triangle[1]];
        const Vec3& c = positions[triangle[2]];
        centroids[i] = (1.0 / 3.0) * a + (1.0 / 3.0) * b + (1.0 / 3.0) * c;  // no overflow
    }
    for (uint32_t i = first_fan_item; i < items; ++i) {
        for (uint32_t t : fan_triangles[i - first_fan_item]) {
            for (uint32_t v : triangles[t]) {
                item_lo[i] = component_min(item_lo[i], positions[v]);
                item_hi[i] = component_max(item_hi[i], positions[v]);
            }
        }
        centroids[i] = 0.5 * item_lo[i] + 0.5 * item_hi[i];
    }

    box_origin_ = median_of_finite(centroids);

    std::vector<uint32_t> order(items);
    for (uint32_t i = 0; i < items; ++i) order[i] = i;

    // Bounds of the items order[begin, end) and of their centroids.
    struct Bounds {
        Vec3 lo{DBL_MAX, DBL_MAX, DBL_MAX}, hi{-DBL_MAX, -DBL_MAX, -DBL_MAX};
        Vec3 centroid_lo{DBL_MAX, DBL_MAX, DBL_MAX}, centroid_hi{-DBL_MAX, -DBL_MAX, -DBL_MAX};
    };
    auto measure = [&](uint32_t begin, uint32_t end) {
        Bounds bounds;
        for (uint32_t i = begin; i < end; ++i) {
            uint32_t t = order[i];
            bounds.lo = component_min(bounds.lo, item_lo[t]);
            bounds.hi = component_max(bounds.hi, item_hi[t]);
            bounds.centroid_lo = component_min(bounds.centroid_lo, centroids[t]);
            bounds.centroid_hi = component_max(bounds.centroid_hi, centroids[t]);
        }
        return bounds;
    };
    // Binned surface area heuristic (SAH-lite) on the longest centroid axis: of the kBins - 1
    // planes between equal-width centroid bins, the one minimising area(left) * count(left) +
    // area(right) * count(right). From depth kSahDepth on, or when the centroids do not separate,
    // the object median instead (ties by item, so the tree does not depend on the standard
    // library's nth_element), which bounds the depth. Returns the split position.
    auto split = [&](uint32_t begin, uint32_t end, const Bounds& bounds, uint32_t depth) {
        const Vec3 extent = bounds.centroid_hi - bounds.centroid_lo;
        const int axis =
            extent.x >= extent.y && extent.x >= extent.z ? 0 : extent.y >= extent.z ? 1 : 2;
        const double axis_lo = component(bounds.centroid_lo, axis);
        const double axis_extent = component(extent, axis);
        if (depth < kSahDepth && axis_extent > 0) {
            const double scale = kBins / axis_extent;
            auto bin_of = [&](uint32_t t) {
                const double x = (component(centroids[t], axis) - axis_lo) * scale;
                if (!(x >= 0)) return 0;  // also NaN from non-finite input
                return x < kBins ? static_cast<int>(x) : kBins - 1;
            };
            Bounds bins[kBins];
            uint32_t counts[kBins] = {};
            for (uint32_t i = begin; i < end; ++i) {
                const uint32_t t = order[i];
                const int bin = bin_of(t);
                ++counts[bin];
                bins[bin].lo = component_min(bins[bin].lo, item_lo[t]);
                bins[bin].hi = component_max(bins[bin].hi, item_hi[t]);
            }
            auto half_area = [](Vec3 lo, Vec3 hi) {
                Vec3 e = hi - lo;
                return e.x * e.y + e.y * e.z + e.z * e.x;
            };
            double right_cost[kBins] = {};  // right_cost[i]: bins i.. on the right
            Vec3 lo = bins[kBins - 1].lo, hi = bins[kBins - 1].hi;
            uint32_t count = 0;
            for (int i = kBins - 1; i > 0; --i) {
                lo = component_min(lo, bins[i].lo);
                hi = component_max(hi, bins[i].hi);
                count += counts[i];
                right_cost[i] = count > 0 ? half_area(lo, hi) * count : 0;
            }
            lo = bins[0].lo;
            hi = bins[0].hi;
            count = 0;
            double best_cost = std::numeric_limits<double>::infinity();
            int best_plane = 0;
            for (int i = 1; i < kBins; ++i) {
                lo = component_min(lo, bins[i - 1].lo);
                hi = component_max(hi, bins[i - 1].hi);
                count += counts[i - 1];
                const uint32_t right_count = (end - begin) - count;
                if (count == 0 || right_count == 0) continue;
                const double cost = half_area(lo, hi) * count + right_cost[i];
                if (cost < best_cost) {
                    best_cost = cost;
                    best_plane = i;
                }
            }
            if (best_plane > 0) {
                auto middle = std::partition(order.begin() + begin, order.begin() + end,
                                             [&](uint32_t t) { return bin_of(t) < best_plane; });
                return static_cast<uint32_t>(middle - order.begin());
            }
        }
        const uint32_t mid = begin + (end - begin) / 2;
        std::nth_element(order.begin() + begin, order.begin() + mid, order.begin() + end,
                         [&](uint32_t s, uint32_t t) {
                             double cs = component(centroids[s], axis);
                             double ct = component(centroids[t], axis);
                             return cs < ct || (cs == ct && s < t);
                         });
        return mid;
    };
    // A leaf holds at most kLeafSize triangles, or one fan.
    auto is_leaf = [&](uint32_t begin, uint32_t end) {
        if (end - begin > kLeafSize) return false;
        if (end - begin == 1) return true;
        return std::all_of(order.begin() + begin, order.begin() + end, [&](uint32_t i) { return i < first_fan_item; });
    };

    // Top-down build with an explicit work list: each item is a range of triangles that becomes
    // child `slot` of node `parent`. Every level touches each triangle a constant number of times
    // and splits halve the count: O(n log n).
    struct Work {
        uint32_t parent, slot, begin, end, depth;
    };
    std::vector<Work> work;
    nodes_.reserve(items / 2 + 1);
    nodes_.push_back(Node{});
    {
        Bounds all = measure(0, items);
        if (is_leaf(0, items)) {
            work.push_back({0, 0, 0, items, 1});
            Node& root = nodes_[0];
            for (int axis = 0; axis < 3; ++axis) {
                root.lo[1][axis] = std::numeric_limits<float>::infinity();
                root.hi[1][axis] = -std::numeric_limits<float>::infinity();
            }
            root.index[1] = kEmpty;
            root.count[1] = 0;
        } else {
            uint32_t mid = split(0, items, all, 0);
            work.push_back({0, 1, mid, items, 1});
            work.push_back({0, 0, 0, mid, 1});
        }
    }
    while (!work.empty()) {
        Work item = work.back();
        work.pop_back();
        Bounds bounds = measure(item.begin, item.end);
        store_box(bounds.lo, bounds.hi, box_origin_, nodes_[item.parent].lo[item.slot], nodes_[item.parent].hi[item.slot]);
        if (is_leaf(item.begin, item.end)) {
            const bool fan = order[item.begin] >= first_fan_item;
            nodes_[item.parent].index[item.slot] = fan ? order[item.begin] - first_fan_item : item.begin;
            nodes_[item.parent].count[item.slot] = fan ? kFanLeaf : item.end - item.begin;
            continue;
        }
        const uint32_t child = static_cast<uint32_t>(nodes_.size());
        nodes_.push_back(Node{});
        nodes_[item.parent].index[item.slot] = child;
        nodes_[item.parent].count[item.slot] = 0;
        uint32_t mid = split(item.begin, item.end, bounds, item.depth);
        work.push_back({child, 1, mid, item.end, item.depth + 1});
        work.push_back({child, 0, item.begin, mid, item.depth + 1});
    }

    // The records: the box tree's triangles in leaf order (its leaves' positions in `order`
    // renumbered without the fans), then each fan's in its tree's leaf order.
    records_.reserve(n);
    triangles_.reserve(n);
    normals_.reserve(n);
    std::vector<uint32_t> record_of_position(items, kEmpty);
    for (uint32_t i = 0; i < items; ++i) {
        if (order[i] >= first_fan_item) continue;
        record_of_position[i] = static_cast<uint32_t>(records_.size());
        add_record(reference, item_triangle[order[i]]);
    }
    for (Node& node : nodes_) {
        for (int slot = 0; slot < 2; ++slot) {
            if (node.count[slot] > 0 && node.count[slot] != kFanLeaf) node.index[slot] = record_of_position[node.index[slot]];
        }
    }
    for (uint32_t f = 0; f < fan_apexes.size(); ++f) fans_.push_back(build_fan(reference, fan_apexes[f], fan_triangles[f]));
}

void ClosestPointQuery::add_record(const TriangleMesh& reference, uint32_t t) {
    const Triangle& triangle = reference.triangles[t];
    const Record record{reference.positions[triangle[0]], reference.positions[triangle[1]], reference.positions[triangle[2]]};
    records_.push_back(record);
    triangles_.push_back(t);
    const Vec3 normal = cross(record.b - record.a, record.c - record.a);
    const double length = std::sqrt(squared_length(normal));
    normals_.push_back(length > 0 && std::isfinite(length) ? (1 / length) * normal : Vec3{});
}

// The fan's tree: median splits of the triangles' middle directions from the apex along their
// widest axis, at most kLeafSize triangles a leaf. A node's cone is about the normalised sum of
// its triangles' unit directions to their other corners; it holds their triangles because a
// triangle's directions are the non-negative combinations of those two, and a cone of half-angle
// up to 90 degrees is convex.
ClosestPointQuery::Fan ClosestPointQuery::build_fan(const TriangleMesh& reference, uint32_t apex_vertex,
                                                   const std::vector<uint32_t>& fan) {
    const std::vector<Vec3>& positions = reference.positions;
    const Vec3 apex = positions[apex_vertex];
    const uint32_t m = static_cast<uint32_t>(fan.size());
    struct Directions {
        Vec3 to[2];      // unit directions to the corners other than the apex; zero for one at it
        Vec3 middle;     // the sort key: their normalised sum, or zero
    };
    auto unit = [](Vec3 v) {
        double length = std::sqrt(squared_length(v));
        if (length < kTinyLength) {  // squares below DBL_MIN, or 0: the direction would leave its cone
            v = kTinyScale * v;
            length = std::sqrt(squared_length(v));
        }
        return length > 0 ? (1 / length) * v : Vec3{};
    };
    std::vector<Directions> directions(m);
    std::vector<uint32_t> local(m);
    for (uint32_t i = 0; i < m; ++i) {
        local[i] = i;
        const Triangle& triangle = reference.triangles[fan[i]];
        int k = 0;
        bool skipped_apex = false;
        for (uint32_t v : triangle) {
            if (v == apex_vertex && !skipped_apex) {
                skipped_apex = true;
                continue;
            }
            directions[i].to[k++] = unit(positions[v] - apex);
        }
        directions[i].middle = unit(directions[i].to[0] + directions[i].to[1]);
    }

    const uint32_t root = static_cast<uint32_t>(cone_nodes_.size());
    double margin = 0;  // the root box's: the fan's own coordinates size its cones' margin
    const uint32_t first_record = static_cast<uint32_t>(records_.size());
    cone_nodes_.push_back(ConeNode{});
    struct Work {
        uint32_t node, begin, end;
    };
    std::vector<Work> work{{root, 0, m}};
    while (!work.empty()) {
        const Work item = work.back();
        work.pop_back();
        ConeNode node;
        Vec3 lo{DBL_MAX, DBL_MAX, DBL_MAX}, hi{-DBL_MAX, -DBL_MAX, -DBL_MAX};
        Vec3 sum{0, 0, 0};
        Vec3 middle_lo{DBL_MAX, DBL_MAX, DBL_MAX}, middle_hi{-DBL_MAX, -DBL_MAX, -DBL_MAX};
        for (uint32_t i = item.begin; i < item.end; ++i) {
            const uint32_t j = local[i];
            for (uint32_t v : reference.triangles[fan[j]]) {
                lo = component_min(lo, positions[v]);
                hi = component_max(hi, positions[v]);
            }
            sum = sum + directions[j].to[0] + directions[j].to[1];
            middle_lo = component_min(middle_lo, directions[j].middle);
            middle_hi = component_max(middle_hi, directions[j].middle);
        }
        const double box_margin = store_box(lo, hi, box_origin_, node.lo, node.hi);
        if (item.node == root) margin = box_margin;
        const Vec3 axis = unit(sum);
        if (squared_length(axis) > 0) {
            // The widest direction by its (sine, cosine) from the axis (a before b where sin(a - b) > 0,
            // both in [0, 180] degrees, or sin(a - b) = 0 and cos a < cos b: a direction opposite the
            // axis against 0 degrees), then its angle by atan2, which (unlike acos) stays accurate
            // near 0; a choice off by rounding is within the widening.
            double widest_sine = 0, widest_cosine = 1;
            for (uint32_t i = item.begin; i < item.end; ++i) {
                for (Vec3 to : directions[local[i]].to) {
                    if (!(squared_length(to) > 0)) continue;
                    const double sine = std::sqrt(squared_length(cross(to, axis))), cosine = dot(to, axis);
                    const double turn = sine * widest_cosine - cosine * widest_sine;
                    if (turn > 0 || (turn == 0 && cosine < widest_cosine)) widest_sine = sine, widest_cosine = cosine;
                }
            }
            const double half_angle = std::atan2(widest_sine, widest_cosine) + kConeWidening;
            if (half_angle <= kRightAngle) {
                node.axis = axis;
                node.cosine = std::cos(half_angle);
                node.sine = std::sin(half_angle);
                node.has_cone = true;
            }
        }
        if (item.end - item.begin <= kLeafSize) {
            node.index = first_record + item.begin;
            node.count = item.end - item.begin;
            cone_nodes_[item.node] = node;
            continue;
        }
        const Vec3 extent = middle_hi - middle_lo;
        const int split_axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : extent.y >= extent.z ? 1 : 2;
        const uint32_t mid = item.begin + (item.end - item.begin) / 2;
        std::nth_element(local.begin() + item.begin, local.begin() + mid, local.begin() + item.end, [&](uint32_t s, uint32_t t) {
            const double cs = component(directions[s].middle, split_axis);
            const double ct = component(directions[t].middle, split_axis);
            return cs < ct || (cs == ct && s < t);
        });
        node.index = static_cast<uint32_t>(cone_nodes_.size());
        node.count = 0;
        cone_nodes_[item.node] = node;
        cone_nodes_.push_back(ConeNode{});
        cone_nodes_.push_back(ConeNode{});
        work.push_back({node.index, item.begin, mid});
        work.push_back({node.index + 1, mid, item.end});
    }
    for (uint32_t i = 0; i < m; ++i) add_record(reference, fan[local[i]]);
    return Fan{apex, root, margin};
}

// A lower bound on the distance from p to the triangles of a fan's node, w = p - apex, box_p = p -
// box_origin_: its box's, and its cone's, which every triangle of the fan holds as it holds the apex
// (at angle theta from the axis, p is |w| sin(theta - half-angle) from the cone, |w| from 90 degrees
// beyond it on).
double ClosestPointQuery::cone_node_distance_squared(const ConeNode& node, Vec3 box_p, Vec3 w, double w_length,
                                                     double margin) const {
    const double box = box_distance_squared(node.lo, node.hi, box_p);
    if (!node.has_cone) return box;
    // Where |w|'s squares fall below DBL_MIN, |w x axis| would lose most of its digits: w is
    // scaled by a power of two first (exactly) and the gap scaled back.
    const double scale = w_length < kTinyLength ? kTinyScale : 1;
    const Vec3 ws = scale * w;
    const double along = dot(ws, node.axis);
    const double across = std::sqrt(squared_length(cross(ws, node.axis)));
    double gap = (along * node.cosine + across * node.sine <= 0 ? scale * w_length : across * node.cosine - along * node.sine) / scale;
    // The rounding of the bound, and of the computed closest points (margin an axis: < 2 margin in all).
    gap -= kConeSlack * w_length + 2 * margin;
    // Below DBL_MIN a triangle's squared distance (three squares, each rounded to a multiple of the
    // least subnormal) may round under this one square: lowered by a few of those units.
    return gap > 0 ? std::max(box, gap * gap - kUnderflowSlack) : box;
}

// False when a plane through the apex has the node's cone on one side and the segment from
// apex + w0 to apex + w1 more than `slack` beyond it on the other: the plane at 90 degrees plus
// the half-angle from the axis, towards the segment's direction nearest the axis (where the plane
// through the apex and the segment comes nearest it, else the nearer end's). Any such plane would
// do: its choice only decides how often the test prunes.
bool ClosestPointQuery::cone_may_meet_segment(const ConeNode& node, Vec3 w0, Vec3 w1, double slack) const {
    if (!node.has_cone) return true;
    const Vec3 u = node.axis;
    const double l0 = std::sqrt(squared_length(w0)), l1 = std::sqrt(squared_length(w1));
    if (!(l0 > 0 && l1 > 0)) return true;
    Vec3 nearest = dot(w0, u) * l1 >= dot(w1, u) * l0 ? w0 : w1;
    const Vec3 normal = cross(w0, w1);
    const double normal_squared = squared_length(normal);
    if (normal_squared > 0) {
        const Vec3 in_plane = u - (dot(u, normal) / normal_squared) * normal;
        if (dot(cross(w0, in_plane), normal) >= 0 && dot(cross(in_plane, w1), normal) >= 0) nearest = in_plane;
    }
    const Vec3 radial = nearest - dot(nearest, u) * u;
    const double radial_length = std::sqrt(squared_length(radial));
    // Near the axis the radial part is rounding noise, whose direction (maybe along u) says nothing.
    if (!(radial_length > kNearAxis * std::sqrt(squared_length(nearest)))) return true;
    const Vec3 side = (node.cosine / radial_length) * radial - node.sine * u;  // unit, at 90 degrees + a from u
    return !(dot(w0, side) > slack && dot(w1, side) > slack);
}

template <class Accept>
std::optional<ClosestPointQuery::Hit> ClosestPointQuery::search(Vec3 p, double bound_squared, const Accept& accept,
                                                                uint64_t* tested) const {
    const Vec3 box_p = p - box_origin_;
    double best = bound_squared;
    double prune = best * (1 + kPruneSlack);
    uint32_t best_record = kEmpty;
    uint32_t best_triangle = kEmpty;
    Vec3 best_point, best_barycentric;
    auto test_records = [&](uint32_t begin, uint32_t end) {
        for (uint32_t r = begin; r < end; ++r) {
            if (!accept(r)) continue;
            const Record& record = records_[r];
            Vec3 barycentric;
            Vec3 q = closest_point_on_triangle(p, record.a, record.b, record.c, barycentric);
            double d = squared_length(p - q);
            if (d < best || (d == best && triangles_[r] < best_triangle)) {
                best = d;
                prune = best * (1 + kPruneSlack);
                best_record = r;
                best_triangle = triangles_[r];
                best_point = q;
                best_barycentric = barycentric;
            }
        }
    };
    // A fan's tree, as the box tree below: nearer child first.
    auto search_fan = [&](const Fan& fan) {
        const Vec3 w = p - fan.apex;
        const double w_length = length_without_underflow(w);
        struct ConeEntry {
            uint32_t node;
            double distance_squared;
        };
        ConeEntry stack[kConeStackSize];
        int size = 0;
        stack[size++] = {fan.root, cone_node_distance_squared(cone_nodes_[fan.root], box_p, w, w_length, fan.margin)};
        while (size > 0) {
            const ConeEntry entry = stack[--size];
            if (entry.distance_squared > prune) continue;
            const ConeNode& node = cone_nodes_[entry.node];
            if (tested) *tested += node.count > 0 ? node.count : 1;
            if (node.count > 0) {
                test_records(node.index, node.index + node.count);
                continue;
            }
            const double d[2] = {cone_node_distance_squared(cone_nodes_[node.index], box_p, w, w_length, fan.margin),
                                 cone_node_distance_squared(cone_nodes_[node.index + 1], box_p, w, w_length, fan.margin)};
            const int near = d[1] < d[0] ? 1 : 0;
            for (int slot : {1 - near, near}) {
                if (d[slot] <= prune) stack[size++] = {node.index + slot, d[slot]};
            }
        }
    };

    // Pending subtrees (or leaves), each with the squared distance to its box.
    struct Entry {
        uint32_t index, count;
        double distance_squared;
    };
    Entry stack[kStackSize];
    int size = 0;
    stack[size++] = {0, 0, 0.0};
    while (size > 0) {
        const Entry entry = stack[--size];
        if (entry.distance_squared > prune) continue;
        if (entry.count == kFanLeaf) {
            if (tested) *tested += 1;
            search_fan(fans_[entry.index]);
            continue;
        }
        if (tested) *tested += entry.count > 0 ? entry.count : 1;
        if (entry.count > 0) {
            test_records(entry.index, entry.index + entry.count);
            continue;
        }
        const Node& node = nodes_[entry.index];
        double d[2];
        for (int slot = 0; slot < 2; ++slot) d[slot] = box_distance_squared(node.lo[slot], node.hi[slot], box_p);
        // Push the farther child first, so that the nearer one is searched first.
        const int near = d[1] < d[0] ? 1 : 0;
        for (int slot : {1 - near, near}) {
            if (node.index[slot] != kEmpty && d[slot] <= prune) {
                stack[size++] = {node.index[slot], node.count[slot], d[slot]};
            }
        }
    }
    if (best_record == kEmpty) return std::nullopt;
    return Hit{best_point, best_triangle, best, best_barycentric};
}

ClosestPointQuery::Hit ClosestPointQuery::closest(Vec3 p) const {
    uint64_t tested = 0;
    return closest(p, tested);
}

ClosestPointQuery::Hit ClosestPointQuery::closest(Vec3 p, uint64_t& tested) const {
    std::optional<Hit> hit = search(p, std::numeric_limits<double>::infinity(), [](uint32_t) { return true; }, &tested);
    if (!hit) {
        // Only non-finite input (a NaN coordinate) compares false against every distance.
        throw Error("closest point query: the query point is not finite");
    }
    return *hit;
}

std::optional<ClosestPointQuery::Hit> ClosestPointQuery::closest(Vec3 p,
                                                                 double max_distance) const {
    if (!(max_distance >= 0)) return std::nullopt;
    return search(p, max_distance * max_distance, [](uint32_t) { return true; });
}

std::optional<ClosestPointQuery::Hit> ClosestPointQuery::closest_facing(Vec3 p, Vec3 direction, double min_cosine,
                                                                        double max_distance) const {
    if (!(max_distance >= 0)) return std::nullopt;
    const double threshold = min_cosine * std::sqrt(squared_length(direction));
    return search(p, max_distance * max_distance,
                  [&](uint32_t r) { return dot(normals_[r], normals_[r]) > 0 && dot(normals_[r], direction) >= threshold; });
}

}  // namespace amc

namespace amc {

std::optional<ClosestPointQuery::Hit> ClosestPointQuery::intersect_line(Vec3 origin, Vec3 direction,
                                                                       double reach, double tolerance) const {
    const double direction_length = std::sqrt(squared_length(direction));
    if (!(direction_length > 0) || !(reach >= 0)) return std::nullopt;
    const Vec3 d = (1 / direction_length) * direction;
    double best = reach;  // |t| of the best hit so far, in units of length
    // A box is pruned beyond this: its slab bounds and a hit's t carry rounding relative to |t|
    // (from an origin far away, more than the box's own margin covers), as search's distances do.
    double prune = best * (1 + kPruneSlack);
    uint32_t best_record = kEmpty, best_triangle = kEmpty;
    Vec3 best_barycentric;
    // Slab test of the segment origin + t d, |t| <= prune, against a box; returns its |t| lower bound.
    // A triangle widened by `tolerance` reaches 2 tolerance times its extent beyond its box on each
    // axis (each widened corner moves by tolerance times its two edges), so a box is widened by that
    // much of its own extent, which holds its triangles'.
    const double widening = 2 * tolerance;
    const double inverse[3] = {1 / d.x, 1 / d.y, 1 / d.z};
    const Vec3 box_origin = origin - box_origin_;
    const double o[3] = {box_origin.x, box_origin.y, box_origin.z};
    auto enters = [&](const float* lo, const float* hi, double& near) {
        double t0 = -prune, t1 = prune;
        double box_lo[3] = {lo[0], lo[1], lo[2]}, box_hi[3] = {hi[0], hi[1], hi[2]};
        if (widening > 0) {
            for (int axis = 0; axis < 3; ++axis) {
                const double widen = widening * (box_hi[axis] - box_lo[axis]);
                box_lo[axis] -= widen;
                box_hi[axis] += widen;
            }
        }
        for (int axis = 0; axis < 3; ++axis) {
            double a = (box_lo[axis] - o[axis]) * inverse[axis], b = (box_hi[axis] - o[axis]) * inverse[axis];
            if (std::isnan(a) || std::isnan(b)) {  // parallel to the slab, on its plane: inside it
                a = -std::numeric_limits<double>::infinity();
                b = std::numeric_limits<double>::infinity();
            }
            if (a > b) std::swap(a, b);
            t0 = std::max(t0, a);
            t1 = std::min(t1, b);
        }
        if (t0 > t1) return false;
        near = t0 <= 0 && t1 >= 0 ? 0 : std::min(std::fabs(t0), std::fabs(t1));
        return near <= prune;
    };
    struct Entry {
        uint32_t index, count;
        double near;
    };
    Entry stack[kStackSize];
    int size = 0;
    stack[size++] = {0, 0, 0.0};
    auto test_records = [&](uint32_t begin, uint32_t end) {
        for (uint32_t r = begin; r < end; ++r) {
            if (!(dot(normals_[r], d) > 0)) continue;
            // Moller-Trumbore, two-sided in t.
            const Record& record = records_[r];
            const Vec3 e1 = record.b - record.a, e2 = record.c - record.a;
            const Vec3 pv = cross(d, e2);
            const double det = dot(e1, pv);
            if (!(std::fabs(det) > 0)) continue;
            const double inv = 1 / det;
            const Vec3 tv = origin - record.a;
            const double u = dot(tv, pv) * inv;
            if (u < -tolerance || u > 1 + tolerance) continue;
            const Vec3 qv = cross(tv, e1);
            const double v = dot(d, qv) * inv;
            if (v < -tolerance || u + v > 1 + tolerance) continue;
            const double t = dot(e2, qv) * inv;
            const double at = std::fabs(t);
            // A hit at exactly `reach` counts (the header's |t| <= reach), as a tie with a lower index
            // does; an infinite |t| (overflow) does not.
            // A line (nearly) in the triangle's plane can round to a hit anywhere in that plane: it
            // counts only inside the triangle's box (the header).
            if ((at < best || (at == best && at < std::numeric_limits<double>::infinity() &&
                               (best_record == kEmpty || triangles_[r] < best_triangle))) &&
                in_triangle_box(origin + t * d, record.a, record.b, record.c, widening)) {
                best = at;
                prune = best * (1 + kPruneSlack);
                best_record = r;
                best_triangle = triangles_[r];
                best_barycentric = {1 - u - v, u, v};
            }
        }
    };
    // A fan's tree, by its boxes and (unless triangles are widened) its cones.
    auto search_fan = [&](const Fan& fan) {
        const Vec3 from_apex = origin - fan.apex;
        auto may_meet = [&](const ConeNode& node) {
            if (tolerance > 0) return true;
            const Vec3 w0 = from_apex - best * d, w1 = from_apex + best * d;
            return cone_may_meet_segment(node, w0, w1, kConeSlack * (std::sqrt(squared_length(w0)) + std::sqrt(squared_length(w1))) + 2 * fan.margin);
        };
        struct ConeEntry {
            uint32_t node;
            double near;
        };
        ConeEntry stack[kConeStackSize];
        int size = 0;
        if (!may_meet(cone_nodes_[fan.root])) return;
        stack[size++] = {fan.root, 0.0};
        while (size > 0) {
            const ConeEntry entry = stack[--size];
            if (entry.near > prune) continue;
            const ConeNode& node = cone_nodes_[entry.node];
            if (node.count > 0) {
                test_records(node.index, node.index + node.count);
                continue;
            }
            double near[2];
            bool hit[2];
            for (uint32_t slot = 0; slot < 2; ++slot) {
                const ConeNode& child = cone_nodes_[node.index + slot];
                hit[slot] = enters(child.lo, child.hi, near[slot]) && may_meet(child);
            }
            const int first = hit[1] && (!hit[0] || near[1] < near[0]) ? 1 : 0;
            for (int slot : {1 - first, first}) {
                if (hit[slot]) stack[size++] = {node.index + slot, near[slot]};
            }
        }
    };
    while (size > 0) {
        const Entry entry = stack[--size];
        if (entry.near > prune) continue;
        if (entry.count == kFanLeaf) {
            search_fan(fans_[entry.index]);
            continue;
        }
        if (entry.count > 0) {
            test_records(entry.index, entry.index + entry.count);
            continue;
        }
        const Node& node = nodes_[entry.index];
        double near[2];
        bool hit[2];
        for (int slot = 0; slot < 2; ++slot)
            hit[slot] = node.index[slot] != kEmpty && enters(node.lo[slot], node.hi[slot], near[slot]);
        const int first = hit[1] && (!hit[0] || near[1] < near[0]) ? 1 : 0;
        for (int slot : {1 - first, first}) {
            if (hit[slot]) stack[size++] = {node.index[slot], node.count[slot], near[slot]};
        }
    }
    if (best_record == kEmpty) return std::nullopt;
    const Record& record = records_[best_record];
    const Vec3 point = best_barycentric.x * record.a + best_barycentric.y * record.b + best_barycentric.z * record.c;
    return Hit{point, best_triangle, squared_length(point - origin), best_barycentric};
}

}  // namespace amc
