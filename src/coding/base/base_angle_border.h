// Mode 2 of the base connectivity stream, the state both sides share (FORMAT.md 4.10-4.16): the
// cut border of the conquest, the corner classes that predict its operations from the positions
// decoded so far, the gate rule and the context of every coded bit. Encoder and decoder run this
// same code, so they can not disagree on a context or a gate.
#pragma once

#include "coding/entropy/arithmetic_coder.h"
#include "coding/base/base_mesh_stream.h"
#include "common/exact_float.h"

#include <amc/mesh.h>

#include <algorithm>
#include <cstdint>
#include <vector>

namespace amc::angle_mode {

// No node of the cut border (amc::kNoNode is the hierarchy's: another id space).
constexpr uint32_t kNoBorderNode = 0xFFFFFFFFu;

// The corner a triangle closing the gap at a border vertex u would have at u: the angle between
// the border edges u -> v (next) and u -> t (previous), "reflex" when the closing triangle would
// face away from the decoded triangle (v, u, o) behind the edge u -> v. Classes (FORMAT.md 4.11):
enum CornerClass : uint8_t {
    kUnknown = 0,  // a vertex without position (a dummy) is involved
    kReflex = 1,   // also degenerate corners
    kBelow30 = 2,
    kBelow50 = 3,
    kBelow70 = 4,
    kBelow90 = 5,
    kBelow120 = 6,
    kWide = 7,
};
constexpr int kCornerClasses = 8;
constexpr uint32_t kMinCornerDegree = 2;  // FORMAT.md 4.11

// Squared cosines of the class bounds 30, 50, 70 and 120 degrees, as written in the spec.
constexpr double kCos2Of30 = 0.75, kCos2Of50 = 0.41, kCos2Of70 = 0.117, kCos2Of120 = 0.25;

// IEEE binary64 in exactly this order, every product rounded before it is added
// (common/exact_float.h): both sides of the coder get the same class on every platform and with
// any compiler flags. With x = v - u, y = t - u, z = o - u, the closing triangle faces like the
// one behind when the dot product of their normals, -(x × z)·(x × y) = (x·y)(x·z) - (x·x)(y·z), is
// positive.
inline CornerClass corner_class(const Vec3& u, const Vec3& v, const Vec3& t, const Vec3& o) {
    const Vec3 x = v - u, y = t - u, z = o - u;
    const double xx = exact_dot(x, x), xy = exact_dot(x, y), xz = exact_dot(x, z), yz = exact_dot(y, z);
    if (!(rounded(xy * xz) - rounded(xx * yz) > 0)) return kReflex;
    const double q = rounded(xx * exact_dot(y, y));
    const double c2 = rounded(xy * xy);
    if (xy > 0) {
        if (c2 > rounded(kCos2Of30 * q)) return kBelow30;
        if (c2 > rounded(kCos2Of50 * q)) return kBelow50;
        if (c2 > rounded(kCos2Of70 * q)) return kBelow70;
        return kBelow90;
    }
    return c2 < rounded(kCos2Of120 * q) ? kBelow120 : kWide;
}

// The adaptive models of mode 2. They start from prior probabilities (FORMAT.md 4.12), as if a
// few symbols had been seen already: base meshes are small, and learning from 1/2 costs bits.
constexpr int kDegreeClasses = 16;
constexpr int kContextSets = 3;
constexpr uint16_t kPriorWeight = 16;  // the symbols a prior counts for
// Priors in units of 2^-12 (measured on the corpus's full meshes, docs/BASE_CODER.md).
constexpr uint16_t kCloseUPrior[kCornerClasses] = {1417, 1647, 3981, 3953, 3711, 2560, 688, 53};
constexpr uint16_t kCloseVPrior[kCornerClasses] = {569, 4, 3629, 3813, 2187, 1470, 1122, 53};
constexpr uint16_t kNewVertexPrior = 4014, kDummyPrior = 41, kCopyPrior = 41, kSplitPrior = 3891, kNearestPrior = 3072;

inline BitModel primed(uint16_t prior) {
    BitModel m;
    m.p = uint32_t{prior} << 20;
    m.n = kPriorWeight;
    return m;
}

struct Models {
    BitModel close_u[kCornerClasses * kDegreeClasses];  // R/E: the tip is the vertex before u
    BitModel close_v[kCornerClasses * kDegreeClasses];  // L: the tip is the vertex after v
    BitModel new_vertex[4];                             // C, or else S/M
    BitModel dummy = primed(kDummyPrior);               // a new vertex closes a boundary loop
    BitModel copy = primed(kCopyPrior);                 // a new vertex repeats a decoded one
    BitModel split = primed(kSplitPrior);               // S (1) or M (0) when both are possible
    BitModel nearest = primed(kNearestPrior);           // S tip nearest to the predicted vertex
    SplitOffsetModels split_offset;                     // fresh

    // Set 0, for large meshes, starts fresh: there a wrong prior on a near-certain context (a
    // regular mesh's degrees) costs more than learning.
    explicit Models(int set) {
        if (set == 0) return;
        for (int c = 0; c < kCornerClasses; ++c) {
            for (int d = 0; d < kDegreeClasses; ++d) {
                close_u[c * kDegreeClasses + d] = primed(kCloseUPrior[c]);
                close_v[c * kDegreeClasses + d] = primed(kCloseVPrior[c]);
            }
        }
        for (BitModel& m : new_vertex) m = primed(kNewVertexPrior);
    }

    // The context of a closing bit: the corner class and the triangles already decoded around
    // the vertex, as finely as the stream's context set says.
    static int closing_context(int set, CornerClass corner, uint32_t degree) {
        static constexpr uint32_t kDegreeCap[kContextSets] = {15, 5, 0};
        return corner * kDegreeClasses + static_cast<int>(std::min(degree, kDegreeCap[set]));
    }
    // The context of the new-vertex bit in set 0: the gate's corner class, coarsely (the other
    // sets have one context).
    static int new_vertex_context(CornerClass corner) {
        static constexpr uint8_t kCoarse[kCornerClasses] = {0, 3, 1, 1, 2, 2, 3, 3};
        return kCoarse[corner];
    }
};

// The border of the conquest: a stack of loops of nodes, each loop a cyclic doubly linked list.
// A node stands for a vertex on the border and for the border edge from it to the next node;
// `opp` is the third vertex of the decoded triangle behind that edge. The top loop is the
// current one; its gate is the edge leaving its gate node.
class Border {
public:
    struct Loop {
        uint32_t gate;
        uint32_t length;
    };
    std::vector<Loop> stack;
    uint32_t gate_radius = 5;  // the stream's: how far from a closed vertex the next gate is looked for
    uint32_t tip_window = 0;   // mode 3's window of split tips around the gate (nearest_tip); 0 in mode 2

    void reserve(size_t vertices, size_t nodes) {
        vertices_.reserve(vertices);
        nodes_.reserve(nodes);
    }

    // Vertices, numbered in creation order.
    uint32_t add_vertex(const Vec3& p, bool has_position) {
        vertices_.push_back({p, 0, has_position ? 1u : 0u});
        return static_cast<uint32_t>(vertices_.size() - 1);
    }
    const Vec3& position(uint32_t v) const { return vertices_[v].position; }
    bool located(uint32_t v) const { return vertices_[v].located != 0; }  // false for dummies
    uint32_t degree(uint32_t v) const { return vertices_[v].degree; }      // decoded triangles around it
    void count_triangle(uint32_t a, uint32_t b, uint32_t c) {
        ++vertices_[a].degree;
        ++vertices_[b].degree;
        ++vertices_[c].degree;
    }

    // Nodes.
    uint32_t next(uint32_t n) const { return nodes_[n].next; }
    uint32_t prev(uint32_t n) const { return nodes_[n].prev; }
    uint32_t vert(uint32_t n) const { return nodes_[n].vert; }
    uint32_t opp(uint32_t n) const { return nodes_[n].opp; }
    Loop& top() { return stack.back(); }

    // A split's predicted tip (FORMAT.md 4.14): the node of the gate's loop of `length` nodes,
    // k = 2 .. length - 3 links after gate g's next node nv, nearest to the parallelogram over the
    // gate's triangle; node kNoBorderNode when no located node is a candidate. `predicted` is
    // false (and the loop not walked) when the gate's triangle lacks a position. With a
    // `tip_window` W (mode 3, FORMAT.md 4.17) only k = 2 .. W + 1 and length - 2 - W .. length - 3
    // are candidates. `charge`: the candidates' count, what the walk budget is charged.
    struct NearestTip {
        bool predicted = false;
        uint32_t node = kNoBorderNode, k = 0, charge = 0;
    };
    NearestTip nearest_tip(uint32_t g, uint32_t nv, uint32_t length) const {
        NearestTip tip;
        const uint32_t o = opp(g);
        if (!located(vert(g)) || !located(vert(nv)) || !located(o)) return tip;
        tip.predicted = true;
        const Vec3 predicted = (position(vert(g)) + position(vert(nv))) - position(o);
        double best_distance = 0;
        auto consider = [&](uint32_t x, uint32_t i) {
            if (!located(vert(x))) return;
            const Vec3 d = position(vert(x)) - predicted;
            const double distance = exact_dot(d, d);
            if (tip.node == kNoBorderNode || distance < best_distance) {
                tip.node = x;
                tip.k = i;
                best_distance = distance;
            }
        };
        const uint32_t last = length - 3;
        const bool whole = tip_window == 0 || uint64_t{length} <= 2 * uint64_t{tip_window} + 4;
        const uint32_t front_end = whole ? last : tip_window + 1;
        uint32_t x = next(next(nv));
        for (uint32_t i = 2; i <= front_end; ++i, x = next(x)) consider(x, i);
        if (whole) {
            tip.charge = length - 4;
            return tip;
        }
        const uint32_t back_start = length - 2 - tip_window;  // tip_window + 1 links before g
        x = walk(g, -int64_t{tip_window} - 1);
        for (uint32_t i = back_start; i <= last; ++i, x = next(x)) consider(x, i);
        tip.charge = 2 * tip_window;
        return tip;
    }

    // The corner class of node n as a gate: the gap at its vertex between the next and the
    // previous node. Cached; an op that relinks a node or changes its opp clears its cache.
    CornerClass corner(uint32_t n) {
        Node& node = nodes_[n];
        if (node.corner == kStale) node.corner = compute_corner(node);
        return CornerClass(node.corner);
    }

    // How much node n, as the gate, is expected to close its vertex's fan next (FORMAT.md
    // 4.11): small convex gaps first, then more decoded triangles; 0 for a dummy's node.
    uint32_t gate_score(uint32_t n) {
        static constexpr uint8_t kRank[kCornerClasses] = {4, 1, 8, 7, 6, 5, 3, 2};
        Node& node = nodes_[n];
        const Vertex& v = vertices_[node.vert];
        if (!v.located) return 0;
        // Fewer than two triangles leave a reflex gap on any reasonable surface: not computed.
        if (v.degree < kMinCornerDegree) return uint32_t{kRank[kReflex]} * 64 + v.degree;
        if (node.corner == kStale) node.corner = compute_corner(node);
        return uint32_t{kRank[node.corner]} * 64 + std::min<uint32_t>(v.degree, 63);
    }

    // Starts a component with triangle (a, b, c): loop a -> c -> b, gate at a.
    void start(uint32_t a, uint32_t b, uint32_t c) {
        const uint32_t na = new_node(a, b), nc = new_node(c, a), nb = new_node(b, c);
        link(na, nc);
        link(nc, nb);
        link(nb, na);
        stack.push_back({na, 3});
    }
    // C: new vertex w beyond the gate; returns its node.
    uint32_t op_new(uint32_t w) {
        Loop& l = top();
        const uint32_t g = l.gate, nv = next(g);
        const uint32_t nw = new_node(w, vert(g));
        set_opp(g, vert(nv));
        link(g, nw);
        link(nw, nv);
        ++l.length;
        return nw;
    }
    // R: the tip is the vertex before u: u leaves the border, then the gate moves (choose_gate).
    void op_right() {
        Loop& l = top();
        const uint32_t g = l.gate, p = prev(g), nv = next(g);
        set_opp(p, vert(g));
        link(p, nv);
        --l.length;
        choose_gate(p, nv);
    }
    // E: the three-node loop is closed.
    void op_end() { stack.pop_back(); }
    // L: the tip is the vertex after v: v leaves the border.
    void op_left() {
        Loop& l = top();
        const uint32_t g = l.gate, nv = next(g), nn = next(nv);
        set_opp(g, vert(nv));
        link(g, nn);
        --l.length;
    }
    // S: the tip is node n, k steps after the gate's next node (2 <= k <= length - 3). The part
    // from the gate's next node to n's predecessor becomes a loop of its own with a new node of
    // the tip's vertex, pushed just below the top; returns that node.
    uint32_t op_split(uint32_t n, uint32_t k) {
        const uint32_t nw = close_gate_at(n);
        top().length -= k;
        stack.insert(stack.end() - 1, Loop{nw, k + 1});
        return nw;
    }
    // M: the tip is node n of the loop at stack position `index`; that loop joins the top one.
    uint32_t op_merge(uint32_t n, size_t index) {
        const uint32_t other_length = stack[index].length;
        stack.erase(stack.begin() + static_cast<std::ptrdiff_t>(index));
        const uint32_t nw = close_gate_at(n);
        top().length += other_length + 1;
        return nw;
    }

    // The node `steps` links after n (backwards for negative steps).
    uint32_t walk(uint32_t n, int64_t steps) const {
        for (; steps > 0; --steps) n = nodes_[n].next;
        for (; steps < 0; ++steps) n = nodes_[n].prev;
        return n;
    }

private:
    static constexpr uint8_t kStale = 0xFF;
    struct Vertex {
        Vec3 position;
        uint32_t degree;
        uint32_t located;
    };
    struct Node {
        uint32_t next, prev, vert, opp;
        uint8_t corner;
    };
    std::vector<Vertex> vertices_;
    std::vector<Node> nodes_;

    uint32_t new_node(uint32_t v, uint32_t o) {
        nodes_.push_back({kNoBorderNode, kNoBorderNode, v, o, kStale});
        return static_cast<uint32_t>(nodes_.size() - 1);
    }
    void link(uint32_t a, uint32_t b) {
        nodes_[a].next = b;
        nodes_[a].corner = kStale;
        nodes_[b].prev = a;
        nodes_[b].corner = kStale;
    }
    void set_opp(uint32_t n, uint32_t o) {
        nodes_[n].opp = o;
        nodes_[n].corner = kStale;
    }
    // S and M: the gate's triangle has its tip at node n elsewhere on the border. The gate now
    // leads to n, and a new node of the tip's vertex joins n's predecessor to the gate's far end.
    uint32_t close_gate_at(uint32_t n) {
        const uint32_t g = top().gate, nv = next(g), pn = prev(n);
        const uint32_t nw = new_node(vert(n), vert(g));
        set_opp(g, vert(nv));
        link(g, n);
        link(pn, nw);
        link(nw, nv);
        return nw;
    }
#if defined(__GNUC__)
    __attribute__((noinline))
#endif
    uint8_t compute_corner(const Node& node) const {
        const Vertex &u = vertices_[node.vert], &v = vertices_[vert(node.next)], &t = vertices_[vert(node.prev)],
                     &o = vertices_[node.opp];
        if (!(u.located && v.located && t.located && o.located)) return kUnknown;
        return corner_class(u.position, v.position, t.position, o.position);
    }
    // After R: the gate goes to the best-scoring node among the nodes around the closed vertex,
    // taken in the order p, nv, prev(p), next(nv), ... (at most 2 * gate_radius + 2 of them and
    // never more than the loop has); the first of equal scores wins.
    void choose_gate(uint32_t p, uint32_t nv) {
        Loop& l = top();
        const uint32_t count = std::min<uint32_t>(2 * gate_radius + 2, l.length);
        uint32_t best = p, best_score = gate_score(p);
        uint32_t back = p, ahead = nv;
        for (uint32_t i = 1; i < count; ++i) {
            uint32_t candidate;
            if (i % 2 == 1) {
                candidate = ahead;
                ahead = nodes_[ahead].next;
            } else {
                back = nodes_[back].prev;
                candidate = back;
            }
            const uint32_t score = gate_score(candidate);
            if (score > best_score) {
                best = candidate;
                best_score = score;
            }
        }
        l.gate = best;
    }
};

// Upper bound on the border nodes S and M may visit in one stream (FORMAT.md 4.14): decoding
// stays linear in the triangle count whatever the stream says.
inline uint64_t walk_budget(uint64_t closed_triangles) { return 16 * closed_triangles + 65536; }

}  // namespace amc::angle_mode
