// Nearest vertex to a point among those a predicate accepts: a k-d tree over the leaf vertices,
// which adapts to the density of an adaptive mesh (a uniform grid scans hundreds of vertices per
// cell where the mesh is fine and many empty cells where it is coarse).
#pragma once

#include "common/exact_float.h"
#include "common/no_index.h"

#include <amc/mesh.h>

#include <cstdint>
#include <limits>
#include <vector>

namespace amc {

class NearestVertex {
public:
    // The tree is built from the points in `insertion_order` (vertex ids; null: 0, 1, ...): its
    // shape, and so which of two equally near vertices is found first, follows that order.
    explicit NearestVertex(const std::vector<Vec3>& positions, const std::vector<uint32_t>* insertion_order = nullptr);
    // `other`'s tree with every vertex v named new_id[v]: what a build over the same positions
    // renumbered, inserted in other's order, makes, without the build.
    NearestVertex(const NearestVertex& other, const std::vector<uint32_t>& new_id);

    // The vertex nearest to p among those for which usable(v) holds (tested only on vertices
    // nearer than the best so far: it may cost more than a distance); kNoIndex when none is.
    template <class Usable>
    uint32_t find(Vec3 p, Usable usable) const {
        Nearest best(1);
        if (!points_.empty()) search(p, usable, 0, 0, uint32_t(points_.size()), best);
        return best.count == 0 ? kNoIndex : best.vertex[0];
    }

    static constexpr uint32_t kMaxCount = 8;

    // The up to `count` (at most kMaxCount) usable vertices nearest to p, nearest first, into
    // `out`; returns how many there are.
    // Only vertices nearer than sqrt(max_squared_distance) count: where none is usable, the
    // search stops there instead of visiting the whole tree.
    template <class Usable>
    uint32_t find_nearest(Vec3 p, Usable usable, uint32_t count, uint32_t* out,
                          double max_squared_distance = std::numeric_limits<double>::infinity()) const {
        Nearest best(count < kMaxCount ? count : kMaxCount);
        best.limit = max_squared_distance;
        if (!points_.empty() && best.wanted > 0) search(p, usable, 0, 0, uint32_t(points_.size()), best);
        for (uint32_t i = 0; i < best.count; ++i) out[i] = best.vertex[i];
        return best.count;
    }

private:
    static constexpr uint32_t kBucket = 16;  // points in a leaf of the tree
    struct Point {
        double x[3];
        uint32_t vertex;
    };
    // The nearest usable vertices found so far, nearest first (squared distances).
    struct Nearest {
        explicit Nearest(uint32_t n) : wanted(n) {}
        uint32_t wanted, count = 0;
        double limit = std::numeric_limits<double>::infinity();
        uint32_t vertex[kMaxCount];
        double distance[kMaxCount];
        bool improves(double d) const { return count < wanted ? d < limit : d < distance[count - 1]; }
        void insert(uint32_t v, double d) {
            uint32_t i = count < wanted ? count++ : count - 1;
            for (; i > 0 && distance[i - 1] > d; --i) {
                vertex[i] = vertex[i - 1];
                distance[i] = distance[i - 1];
            }
            vertex[i] = v;
            distance[i] = d;
        }
    };

    void build(uint32_t node, uint32_t lo, uint32_t hi);

    template <class Usable>
    void search(Vec3 p, Usable& usable, uint32_t node, uint32_t lo, uint32_t hi, Nearest& best) const {
        if (hi - lo <= kBucket) {
            for (uint32_t i = lo; i < hi; ++i) {
                const Point& q = points_[i];
                const double dx = q.x[0] - p.x, dy = q.x[1] - p.y, dz = q.x[2] - p.z;
                const double distance = exact_dot({dx, dy, dz}, {dx, dy, dz});  // the same pick in every build
                if (best.improves(distance) && usable(q.vertex)) best.insert(q.vertex, distance);
            }
            return;
        }
        const uint32_t mid = lo + (hi - lo) / 2;
        const int axis = axis_[node];
        const double coordinate = axis == 0 ? p.x : axis == 1 ? p.y : p.z;
        const double offset = coordinate - split_[node];
        // Points left of mid lie at or below its coordinate on the axis, points from mid on at or above.
        const bool left_first = offset < 0;
        search(p, usable, 2 * node + (left_first ? 1 : 2), left_first ? lo : mid, left_first ? mid : hi, best);
        if (best.improves(offset * offset))
            search(p, usable, 2 * node + (left_first ? 2 : 1), left_first ? mid : lo, left_first ? hi : mid, best);
    }

    std::vector<Point> points_;  // in tree order
    // Split axis and coordinate of each inner node, heap-numbered (children 2i+1, 2i+2); the
    // children's builds reorder the points, so the split point's coordinate is kept here.
    std::vector<uint8_t> axis_;
    std::vector<double> split_;
};

}  // namespace amc
