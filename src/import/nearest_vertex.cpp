#include "import/nearest_vertex.h"

#include "common/huge_pages.h"
#include "import/spatial_order.h"

#include <algorithm>

namespace amc {

NearestVertex::NearestVertex(const std::vector<Vec3>& positions, const std::vector<uint32_t>* insertion_order,
                             const std::vector<uint32_t>* sorted_codes)
    : positions_(&positions), insertion_order_(insertion_order) {
    const uint32_t n = uint32_t(positions.size());
    if (n == 0) return;
    points_.reserve(n);
    advise_huge_pages(points_.data(), points_.capacity() * sizeof(Point));  // each query reads a few buckets
    nodes_.reserve(size_t(4) * (n / kMortonBucket + 1));
    if (sorted_codes != nullptr && sorted_codes->size() == n) {
        for (uint32_t v = 0; v < n; ++v) points_.push_back({{positions[v].x, positions[v].y, positions[v].z}, v});
        build_jumps(*sorted_codes, build_node(*sorted_codes, 0, n, 0));
        return;
    }
    const std::vector<uint32_t> code = detail::morton_codes(positions);
    const std::vector<uint32_t> order = detail::order_by_codes(code);
    std::vector<uint32_t> codes_in_order(n);
    for (uint32_t i = 0; i < n; ++i) {
        const uint32_t v = order[i];
        points_.push_back({{positions[v].x, positions[v].y, positions[v].z}, v});
        codes_in_order[i] = code[v];
    }
    build_jumps(codes_in_order, build_node(codes_in_order, 0, n, 0));
}

void NearestVertex::build_jumps(const std::vector<uint32_t>& codes, const Box& all) {
    frame_ = detail::MortonFrame(all.low, all.high);  // the codes' (morton_codes): the same least and greatest coordinates
    if (!(frame_.scale > 0 && frame_.scale < std::numeric_limits<double>::infinity())) return;
    constexpr uint32_t kShift = 30 - kJumpBits;  // a prefix's bits in the code
    jump_.assign(size_t(1) << kJumpBits, Jump{});
    for (uint32_t prefix = 0; prefix < jump_.size(); ++prefix) {
        // Down from the root along the prefix, through nodes split by a code bit (a node's points
        // are then all those with its common prefix), to the first whose points share the whole
        // prefix, or a leaf, or a cell split at its median.
        uint32_t x = 0;
        for (;;) {
            const Node& node = nodes_[x];
            const uint32_t differ = codes[node.begin] ^ codes[node.end - 1];
            const uint32_t shared = differ == 0 ? 30 : 30 - (32 - __builtin_clz(differ));  // top bits in common
            const uint32_t bits = std::min(shared, kJumpBits);
            if ((codes[node.begin] >> (30 - bits)) != (prefix >> (kJumpBits - bits))) break;  // no point has the prefix
            if (bits == kJumpBits || node.second == kNoIndex || differ == 0) {
                jump_[prefix] = {x, bits};
                break;
            }
            const uint32_t bit = 31 - __builtin_clz(differ);  // >= kShift: the prefix's bit decides
            x = (prefix >> (bit - kShift) & 1) ? node.second : x + 1;
        }
    }
}

NearestVertex::Box NearestVertex::build_node(const std::vector<uint32_t>& codes, uint32_t begin, uint32_t end,
                                             int depth) {
    const uint32_t index = uint32_t(nodes_.size());
    nodes_.push_back({0, 0, begin, end, kNoIndex, 0});
    if (end - begin <= kMortonBucket || depth >= kMaxDepth) {
        Box box;
        for (int a = 0; a < 3; ++a) box.low[a] = box.high[a] = points_[begin].x[a];
        for (uint32_t i = begin + 1; i < end; ++i) {
            for (int a = 0; a < 3; ++a) {
                box.low[a] = std::min(box.low[a], points_[i].x[a]);
                box.high[a] = std::max(box.high[a], points_[i].x[a]);
            }
        }
        return box;
    }
    const uint32_t differ = codes[begin] ^ codes[end - 1];
    uint32_t split, axis;
    if (differ != 0) {
        const int bit = 31 - __builtin_clz(differ);  // the codes agree above it
        axis = uint32_t(bit % 3);                    // spatial_order.cpp: bit 3k + a is axis a's
        split = uint32_t(std::partition_point(codes.begin() + begin, codes.begin() + end,
                                              [bit](uint32_t c) { return !(c >> bit & 1); }) -
                         codes.begin());
    } else {
        // One grid cell (a strongly graded mesh crowds thousands of vertices into one): split at
        // the median of its largest extent, as a k-d tree does (the order inside a cell does not
        // matter, ties being the k-d tree's to answer).
        double low[3], high[3];
        for (int a = 0; a < 3; ++a) low[a] = high[a] = points_[begin].x[a];
        for (uint32_t i = begin + 1; i < end; ++i) {
            for (int a = 0; a < 3; ++a) {
                low[a] = std::min(low[a], points_[i].x[a]);
                high[a] = std::max(high[a], points_[i].x[a]);
            }
        }
        axis = 0;
        for (uint32_t a = 1; a < 3; ++a) {
            if (high[a] - low[a] > high[axis] - low[axis]) axis = a;
        }
        split = begin + (end - begin) / 2;
        std::nth_element(points_.begin() + begin, points_.begin() + split, points_.begin() + end,
                         [axis](const Point& a, const Point& b) { return a.x[axis] < b.x[axis]; });
    }
    const Box first = build_node(codes, begin, split, depth + 1);
    const uint32_t second_index = uint32_t(nodes_.size());
    const Box second = build_node(codes, split, end, depth + 1);
    Node& node = nodes_[index];
    node.second = second_index;
    node.axis = axis;
    node.below = first.high[axis];
    node.above = second.low[axis];
    Box box;
    for (int a = 0; a < 3; ++a) {
        box.low[a] = std::min(first.low[a], second.low[a]);
        box.high[a] = std::max(first.high[a], second.high[a]);
    }
    return box;
}

NearestVertex::NearestVertex(const NearestVertex& other, const std::vector<uint32_t>& new_id)
    : nodes_(other.nodes_), frame_(other.frame_), jump_(other.jump_), renamed_from_(&other), new_id_(&new_id) {
    points_.reserve(other.points_.size());
    advise_huge_pages(points_.data(), points_.capacity() * sizeof(Point));
    for (const Point& p : other.points_) points_.push_back({{p.x[0], p.x[1], p.x[2]}, new_id[p.vertex]});
}

NearestVertex::~NearestVertex() = default;

const NearestVertex::KdTree& NearestVertex::kd_tree() const {
    if (!kd_tree_) {
        kd_tree_ = renamed_from_ ? std::make_unique<KdTree>(renamed_from_->kd_tree(), *new_id_)
                                 : std::make_unique<KdTree>(*positions_, insertion_order_);
    }
    return *kd_tree_;
}

NearestVertex::KdTree::KdTree(const std::vector<Vec3>& positions, const std::vector<uint32_t>* insertion_order) {
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

NearestVertex::KdTree::KdTree(const KdTree& other, const std::vector<uint32_t>& new_id)
    : axis_(other.axis_), split_(other.split_) {
    points_.reserve(other.points_.size());
    advise_huge_pages(points_.data(), points_.capacity() * sizeof(Point));
    for (const Point& p : other.points_) points_.push_back({{p.x[0], p.x[1], p.x[2]}, new_id[p.vertex]});
}

// Splits [lo, hi) at its median along the axis of its largest extent.
void NearestVertex::KdTree::build(uint32_t node, uint32_t lo, uint32_t hi) {
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
