// Nearest vertex to a point among those a predicate accepts, over the leaf vertices of an
// adaptive mesh (a uniform grid scans hundreds of vertices per cell where the mesh is fine and
// many empty cells where it is coarse).
//
// Two trees answer alike. A tree over the vertices in Morton order, built in one pass from their
// codes, answers every query whose nearest usable vertices lie at distinct distances. Where two
// lie at the same distance, which one is found first decides, and the import has always taken
// the first in a k-d tree built from the vertices in a given order: that tree is built on the
// first such query only, and answers it (docs/IMPORT.md, "Complexity and speed").
#pragma once

#include "common/exact_float.h"
#include "common/no_index.h"
#include "import/spatial_order.h"

#include <amc/mesh.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <vector>

namespace amc {

class NearestVertex {
    static constexpr uint32_t kBucket = 16;  // points in a leaf of the k-d tree (its ties depend on it)
    // Points in a leaf of the Morton tree, whose answers do not depend on it (docs/IMPORT.md).
    static constexpr uint32_t kMortonBucket = 8;
    struct Point {
        double x[3];
        uint32_t vertex;
    };
    static double squared_distance(const Point& q, Vec3 p) {
        const double dx = q.x[0] - p.x, dy = q.x[1] - p.y, dz = q.x[2] - p.z;
        return exact_dot({dx, dy, dz}, {dx, dy, dz});  // the same pick in every build
    }

public:
    static constexpr uint32_t kMaxCount = 8;

private:
    // The nearest usable vertices found so far, nearest first (squared distances). The k-d tree
    // keeps the first found of equally near ones; the Morton tree notes the least distance at
    // which it met two usable vertices (`tie`) instead.
    struct Nearest {
        explicit Nearest(uint32_t n, double max_squared_distance)
            : wanted(n < kMaxCount ? n : kMaxCount),
              limit(max_squared_distance),
              bound(below(max_squared_distance)) {}
        uint32_t wanted, count = 0;
        double limit;
        // matters(d) is d <= bound: the largest double below limit while fewer than wanted are
        // listed (d < limit, exactly), then the last listed distance; once a tie is noted, below
        // it too. One compare per tree node.
        double bound;
        double tie = std::numeric_limits<double>::infinity();
        uint64_t examined = 0;  // points whose distance the search computed
        uint32_t vertex[kMaxCount];
        double distance[kMaxCount];
        // The largest double below x (std::nextafter towards -infinity, without its call for the
        // limits queries pass: infinity, and positive finite values).
        static double below(double x) {
            if (x == std::numeric_limits<double>::infinity()) return std::numeric_limits<double>::max();
            if (!(x > 0 && x < std::numeric_limits<double>::infinity()))
                return std::nextafter(x, -std::numeric_limits<double>::infinity());
            uint64_t bits;
            std::memcpy(&bits, &x, sizeof bits);
            --bits;  // a positive finite double's predecessor (to 0 from the least subnormal)
            std::memcpy(&x, &bits, sizeof bits);
            return x;
        }
        bool improves(double d) const { return count < wanted ? d < limit : d < distance[count - 1]; }
        // Whether a vertex at squared distance d may change the answer or tie with it.
        bool matters(double d) const { return d <= bound; }
        void insert(uint32_t v, double d) {
            uint32_t i = count < wanted ? count++ : count - 1;
            for (; i > 0 && distance[i - 1] > d; --i) {
                vertex[i] = vertex[i - 1];
                distance[i] = distance[i - 1];
            }
            vertex[i] = v;
            distance[i] = d;
            if (count == wanted && distance[count - 1] < bound) bound = distance[count - 1];
        }
        // A usable vertex at d, where matters(d): a tie when a listed one is as near. Vertices as
        // far as a tie or farther can no longer change whether the answer ties, nor the answer
        // when it does not (it lies nearer then): they no longer matter, so a search among many
        // vertices at one distance does not test each one's use.
        void offer(uint32_t v, double d) {
            for (uint32_t i = 0; i < count; ++i) {
                if (distance[i] == d) {
                    if (d < tie) tie = d;
                    bound = below(d);  // d <= bound, so this only lowers it
                    return;
                }
            }
            insert(v, d);
        }
        // Whether the answer has two vertices at one distance, or one as near as the last listed:
        // then the order of the search decides it.
        bool tied() const { return count < wanted ? tie < limit : count > 0 && tie <= distance[count - 1]; }
        uint32_t copy_to(uint32_t* out) const {
            for (uint32_t i = 0; i < count; ++i) out[i] = vertex[i];
            return count;
        }
    };

public:
    // The k-d tree alone: the points split at their median along the axis of the largest extent,
    // taken in `insertion_order` (vertex ids; null: 0, 1, ...), so which of two equally near
    // vertices it finds first follows that order.
    class KdTree {
    public:
        KdTree(const std::vector<Vec3>& positions, const std::vector<uint32_t>* insertion_order);
        // `other` with every vertex v named new_id[v].
        KdTree(const KdTree& other, const std::vector<uint32_t>& new_id);
        // As NearestVertex::find_nearest; adds the points it examined to *examined, when given.
        template <class Usable>
        uint32_t find_nearest(Vec3 p, Usable usable, uint32_t count, uint32_t* out,
                              double max_squared_distance = std::numeric_limits<double>::infinity(),
                              uint64_t* examined = nullptr) const {
            Nearest best(count, max_squared_distance);
            if (!points_.empty() && best.wanted > 0) search(p, usable, 0, 0, uint32_t(points_.size()), best);
            if (examined) *examined += best.examined;
            return best.copy_to(out);
        }

    private:
        template <class Usable>
        void search(Vec3 p, Usable& usable, uint32_t node, uint32_t lo, uint32_t hi, Nearest& best) const {
            if (hi - lo <= kBucket) {
                best.examined += hi - lo;
                for (uint32_t i = lo; i < hi; ++i) {
                    const Point& q = points_[i];
                    const double distance = squared_distance(q, p);
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
        void build(uint32_t node, uint32_t lo, uint32_t hi);
        std::vector<Point> points_;  // in tree order
        // Split axis and coordinate of each inner node, heap-numbered (children 2i+1, 2i+2); the
        // children's builds reorder the points, so the split point's coordinate is kept here.
        std::vector<uint8_t> axis_;
        std::vector<double> split_;
    };

    // The k-d tree takes the points in `insertion_order` (KdTree). `positions` and
    // `insertion_order` must outlive this object (the k-d tree is built from them when a tie
    // first calls for it). `sorted_codes`: positions' Morton codes when they are already in Morton
    // order (spatial_vertex_order's), which are then neither computed nor sorted again.
    explicit NearestVertex(const std::vector<Vec3>& positions, const std::vector<uint32_t>* insertion_order = nullptr,
                           const std::vector<uint32_t>* sorted_codes = nullptr);
    // `other`'s searches with every vertex v named new_id[v]: what a build over the same positions
    // renumbered, inserted in other's order, makes, without the build. `other` and new_id must
    // outlive this object (other's k-d tree, if a tie calls for it, is built once and renamed).
    NearestVertex(const NearestVertex& other, const std::vector<uint32_t>& new_id);
    ~NearestVertex();

    // The vertex nearest to p among those for which usable(v) holds (tested only on vertices as
    // near as the best so far or nearer: it may cost more than a distance; it must change
    // nothing); kNoIndex when none is.
    template <class Usable>
    uint32_t find(Vec3 p, Usable usable) const {
        uint32_t found = kNoIndex;
        find_nearest(p, usable, 1, &found);
        return found;
    }

    // The up to `count` (at most kMaxCount) usable vertices nearest to p, nearest first, into
    // `out`; returns how many there are.
    // Only vertices nearer than sqrt(max_squared_distance) count: where none is usable, the
    // search stops there instead of visiting the whole tree.
    template <class Usable>
    uint32_t find_nearest(Vec3 p, Usable usable, uint32_t count, uint32_t* out,
                          double max_squared_distance = std::numeric_limits<double>::infinity()) const {
        Nearest best(count, max_squared_distance);
        if (!points_.empty() && best.wanted > 0) {
            // The answer and whether it ties do not depend on the order in which points are met.
            const uint32_t searched = best.wanted == 1 ? search_cell(p, usable, best) : kNoIndex;
            if (searched != 0) search(p, usable, best, 0, searched);
        }
        examined_ += best.examined;
        if (best.tied()) return kd_tree().find_nearest(p, usable, count, out, max_squared_distance, &examined_);
        return best.copy_to(out);
    }

    // The points whose distance the searches so far computed: what a caller bounds when many
    // vertices lie at one distance (every one of them is examined) or most near ones are unusable.
    uint64_t examined() const { return examined_; }

private:
    // The Morton tree over points_ in Morton order: a node is a range of points whose codes share
    // a prefix, split where the next bit of the codes changes, so into the two halves of its cell
    // along that bit's axis: every point of the first child lies at or below every point of the
    // second on it. A cell holding more than a bucket is split at its median, as a k-d tree
    // splits. A leaf holds at most kMortonBucket points. Nodes in depth-first order: a node's first
    // child follows it.
    struct Node {
        double below, above;  // the first child's greatest and the second's least coordinate on the axis
        uint32_t begin, end;  // its points
        uint32_t second;      // its second child; kNoIndex for a leaf
        uint32_t axis;
    };
    static constexpr int kMaxDepth = 62;  // 30 code bits, then halvings

    // The subtree of node `start` less that of node `skip` (searched already), depth first, the
    // nearer child first, as the k-d tree searches, with a stack instead of calls.
    template <class Usable>
    void search(Vec3 p, Usable& usable, Nearest& best, uint32_t start, uint32_t skip = kNoIndex) const {
        const double q[3] = {p.x, p.y, p.z};
        struct Pending {
            uint32_t node;
            double gap;  // a lower bound of its points' squared distances
        };
        Pending stack[kMaxDepth + 1];
        int top = 0;
        uint32_t index = start;
        for (;;) {
            const Node& node = nodes_[index];
            if (node.second == kNoIndex) {
                best.examined += node.end - node.begin;
                for (uint32_t i = node.begin; i < node.end; ++i) {
                    const double d = squared_distance(points_[i], p);
                    if (best.matters(d) && usable(points_[i].vertex)) best.offer(points_[i].vertex, d);
                }
            } else {
                // The gap to each child on the axis, rounded as a coordinate difference is, then
                // squared: both monotone, so no point of the child is nearer.
                const double c = q[node.axis];
                const double to_first = c > node.below ? c - node.below : 0.0;
                const double to_second = c < node.above ? node.above - c : 0.0;
                const bool first_nearer = to_first <= to_second;
                const double far_gap = first_nearer ? to_second * to_second : to_first * to_first;
                const uint32_t far = first_nearer ? node.second : index + 1;
                if (best.matters(far_gap) && far != skip) stack[top++] = {far, far_gap};
                const double near_gap = first_nearer ? to_first * to_first : to_second * to_second;
                const uint32_t near = first_nearer ? index + 1 : node.second;
                if (best.matters(near_gap) && near != skip) {
                    index = near;
                    continue;
                }
            }
            do {
                if (top == 0) return;
                --top;
            } while (!best.matters(stack[top].gap));
            index = stack[top].node;
        }
    }
    // A single nearest vertex, searched first in the subtree that holds every point of p's cell of
    // kJumpBits code bits (jump_: no descent from the root, most of a query's inner nodes). Returns
    // 0 when that found one nearer than any point outside the cell can be: the whole tree's answer,
    // ties included (every point as near lies in the cell). Else the subtree searched (kNoIndex:
    // none), which the search of the rest skips.
    template <class Usable>
    uint32_t search_cell(Vec3 p, Usable& usable, Nearest& best) const {
        if (jump_.empty()) return kNoIndex;
        const double c[3] = {p.x, p.y, p.z};
        double t[3];
        uint32_t cell[3], prefix = 0;
        for (int a = 0; a < 3; ++a) {
            t[a] = frame_.t(c[a], a);
            if (!(std::fabs(t[a]) < kMaxCellUnits)) return kNoIndex;  // far outside (or NaN): the margin below would not hold
            cell[a] = detail::MortonFrame::cell_of(t[a]);
            for (uint32_t k = 0; k < kJumpBits / 3; ++k) prefix |= (cell[a] >> (10 - kJumpBits / 3 + k) & 1) << (3 * k + a);
        }
        const Jump jump = jump_[prefix];
        if (jump.node == kNoIndex || jump.node == 0) return kNoIndex;
        search(p, usable, best, jump.node);
        if (best.count == 0) return jump.node;
        // The cell of the node's common prefix (jump.bits of the code's top bits; all of the node's
        // points share it, and every point with that prefix is the node's): its range on axis a
        // is [low, low + 2^free) in cells, and a point outside it lies at t <= low or t >= high.
        // The least gap from t to a side that points lie beyond (none lie below cell 0 or above
        // the last), less a margin for the rounding of t (about 1e-13 cells here), bounds the
        // distance to every point outside.
        double gap = std::numeric_limits<double>::infinity();
        const uint32_t free_bits = 30 - jump.bits;
        for (int a = 0; a < 3; ++a) {
            const uint32_t free = free_bits > uint32_t(a) ? (free_bits - a + 2) / 3 : 0;  // axis a's bits 3k + a below the prefix
            const uint32_t low = cell[a] >> free << free, high = low + (1u << free);
            if (low > 0) gap = std::min(gap, t[a] - low);
            if (high < detail::MortonFrame::kCellsPerAxis) gap = std::min(gap, high - t[a]);
        }
        if (gap == std::numeric_limits<double>::infinity()) return 0;
        const double distance = (gap - kCellMargin) / frame_.scale;
        return distance > 0 && best.distance[0] < distance * distance * (1 - 1e-9) ? 0 : jump.node;
    }
    static constexpr uint32_t kJumpBits = 15;  // 32768 cells of 32^3 of the 1024^3 (128 KiB of jumps)
    static constexpr double kMaxCellUnits = 1e6;
    static constexpr double kCellMargin = 1e-6;
    // The node to start from for each kJumpBits-bit code prefix, and how many of the code's top
    // bits its points share (kNoIndex: no node holds that cell's points; search the whole tree).
    struct Jump {
        uint32_t node = kNoIndex;
        uint32_t bits = 0;
    };
    struct Box {
        double low[3], high[3];
    };
    Box build_node(const std::vector<uint32_t>& codes, uint32_t begin, uint32_t end, int depth);
    // jump_ and frame_, after build_node: `all` is the root's box.
    void build_jumps(const std::vector<uint32_t>& codes, const Box& all);
    const KdTree& kd_tree() const;

    std::vector<Point> points_;  // in Morton order
    std::vector<Node> nodes_;
    detail::MortonFrame frame_;  // the cells of the codes the tree was built from
    std::vector<Jump> jump_;     // empty: the frame is not the codes' (no jumps)
    // What the k-d tree is built from: the positions and their order, or another's tree renamed.
    const std::vector<Vec3>* positions_ = nullptr;
    const std::vector<uint32_t>* insertion_order_ = nullptr;
    const NearestVertex* renamed_from_ = nullptr;
    const std::vector<uint32_t>* new_id_ = nullptr;
    mutable std::unique_ptr<KdTree> kd_tree_;
    mutable uint64_t examined_ = 0;
};

}  // namespace amc
