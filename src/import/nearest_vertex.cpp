#include "import/nearest_vertex.h"

#include "common/huge_pages.h"

#include <algorithm>

namespace amc {

NearestVertex::NearestVertex(const std::vector<Vec3>& positions, const std::vector<uint32_t>* insertion_order) {
    points_.reserve(positions.size());
    advise_huge_pages(points_.data(), points_.capacity() * sizeof(Point));  // each query reads a few buckets at random
    for (uint32_t i = 0; i < positions.size(); ++i) {
        const uint32_t v = insertion_order ? (*insertion_order)[i] : i;
        points_.push_back({{positions[v].x, positions[v].y, positions[v].z}, v});
    }
    size_t inner = 1;
    while (inner * kBucket < points_.size()) inner *= 2;
    axis_.assign(2 * inner, 0);
    split_.assign(2 * inner, 0);
    build(0, 0, uint32_t(points_.size()));
}

NearestVertex::NearestVertex(const NearestVertex& other, const std::vector<uint32_t>& new_id)
    : axis_(other.axis_), split_(other.split_) {
    points_.reserve(other.points_.size());
    advise_huge_pages(points_.data(), points_.capacity() * sizeof(Point));
    for (const Point& p : other.points_) points_.push_back({{p.x[0], p.x[1], p.x[2]}, new_id[p.vertex]});
}

// Splits [lo, hi) at its median along the axis of its largest extent.
void NearestVertex::build(uint32_t node, uint32_t lo, uint32_t hi) {
    if (hi - lo <= kBucket) return;
    double low[3] = {points_[lo].x[0], points_[lo].x[1], points_[lo].x[2]};
    double high[3] = {low[0], low[1], low[2]};
    for (uint32_t i = lo + 1; i < hi; ++i) {
        for (int a = 0; a < 3; ++a) {
            low[a] = std::min(low[a], points_[i].x[a]);
            high[a] = std::max(high[a], points_[i].x[a]);
        }
    }
    int axis = 0;
    for (int a = 1; a < 3; ++a) {
        if (high[a] - low[a] > high[axis] - low[axis]) axis = a;
    }
    axis_[node] = uint8_t(axis);
    const uint32_t mid = lo + (hi - lo) / 2;
    std::nth_element(points_.begin() + lo, points_.begin() + mid, points_.begin() + hi,
                     [axis](const Point& a, const Point& b) { return a.x[axis] < b.x[axis]; });
    split_[node] = points_[mid].x[axis];
    build(2 * node + 1, lo, mid);
    build(2 * node + 2, mid, hi);
}

}  // namespace amc
