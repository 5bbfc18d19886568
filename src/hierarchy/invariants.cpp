// Every structural invariant of a red-green hierarchy, checked from scratch. Used by tests after
// every operation, and by every writer before it writes (writer_checks.h).
#include "hierarchy/writer_checks.h"

#include "common/check.h"
#include "common/exact_float.h"
#include "common/parallel.h"
#include "hierarchy/hierarchy_builder.h"

#include <amc/hierarchy.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <sstream>

namespace amc {

namespace {

std::string number_text(double x) {
    std::ostringstream s;
    s.precision(17);
    s << x;
    return s.str();
}

std::string node_text(const Hierarchy& h, NodeId n) {
    std::ostringstream s;
    s << "node " << n << " (level " << h.level(n) << ")";
    return s.str();
}

// What check_invariants finds in the nodes [begin, end): the first problem, the live nodes and
// the split edges counted at their lower-numbered refined node.
struct RangeCheck {
    std::string problem;
    uint32_t nodes = 0;
    uint64_t split_edges = 0;
};

std::string check_node_range(const Hierarchy& h, NodeId begin, NodeId end, uint32_t& nodes, uint64_t& split_edges) {
    for (NodeId n = begin; n < end; ++n) {
        if (!h.is_alive(n)) continue;
        ++nodes;
        for (int e = 0; e < 3; ++e) {
            const NodeId q = h.neighbor(n, e);
            if (q == kNoNode) {
                if (h.is_boundary_edge(n, e)) continue;
                // No same-level neighbour: the region across is a coarser leaf, so n can not
                // have children (balance), and n's parent must see that coarser leaf.
                if (!h.is_leaf(n)) return node_text(h, n) + " is refined next to a coarser leaf (balance)";
                const NodeId p = h.parent(n);
                if (p == kNoNode) return node_text(h, n) + ": root without neighbour on inner edge";
                const NodeId pq = h.neighbor(p, e);
                if (pq == kNoNode || !h.is_leaf(pq))
                    return node_text(h, n) + ": missing neighbour link on edge " + std::to_string(e);
                continue;
            }
            if (!h.is_alive(q)) return node_text(h, n) + " links to a removed node";
            const int eq = h.neighbor_edge(n, e);
            if (h.neighbor(q, eq) != n || h.neighbor_edge(q, eq) != e)
                return node_text(h, n) + ": neighbour link on edge " + std::to_string(e) + " is not mutual";
            if (h.level(q) != h.level(n)) return node_text(h, n) + ": neighbour on another level";
            if (h.vertex(q, eq) != h.vertex(n, (e + 1) % 3) || h.vertex(q, (eq + 1) % 3) != h.vertex(n, e))
                return node_text(h, n) + ": neighbour does not share edge " + std::to_string(e);
            if (h.is_boundary_edge(n, e)) return node_text(h, n) + ": boundary edge with a neighbour";
        }
        if (h.is_leaf(n)) {
            if (h.hanging_node_count(n) == 3) return node_text(h, n) + " has three hanging nodes (closure)";
            continue;
        }
        if (!h.has_all_neighbors(n))
            return node_text(h, n) + " is refined but not all neighbours have its level (balance)";
        if (h.level(n) >= kMaxLevel) return node_text(h, n) + " is refined beyond the level cap " + std::to_string(kMaxLevel);
        for (int k = 0; k < 4; ++k) {
            const NodeId c = h.child(n, k);
            if (!h.is_alive(c) || h.parent(c) != n || h.child_index(c) != k || h.level(c) != h.level(n) + 1)
                return node_text(h, n) + ": child " + std::to_string(k) + " is inconsistent";
        }
        // The six points of the split (red_split.h): corners, then midpoints.
        const VertexId points[6] = {h.vertex(n, 0),   h.vertex(n, 1),   h.vertex(n, 2),
                                    h.midpoint(n, 0), h.midpoint(n, 1), h.midpoint(n, 2)};
        for (int k = 0; k < 4; ++k) {
            for (int i = 0; i < 3; ++i) {
                if (h.vertex(h.child(n, k), i) != points[red_split::kChildPoints[k][i]])
                    return node_text(h, n) + ": child " + std::to_string(k) + " has wrong vertices";
            }
        }
        for (int e = 0; e < 3; ++e) {
            const NodeId q = h.neighbor(n, e);
            if (q == kNoNode || h.is_leaf(q) || q > n) {
                ++split_edges;  // count each split edge once
            } else if (h.midpoint(q, h.neighbor_edge(n, e)) != h.midpoint(n, e)) {
                return node_text(h, n) + ": midpoint of edge " + std::to_string(e) + " not shared";
            }
        }
    }
    return "";
}

}  // namespace

std::string check_invariants(const Hierarchy& h) { return check_invariants(h, 1); }

std::string check_invariants(const Hierarchy& h, unsigned threads) {
    // Ranges of nodes checked independently; the first problem in node order is reported, so the
    // message does not depend on the threads.
    constexpr NodeId kRange = NodeId(1) << 16;
    std::vector<RangeCheck> ranges((size_t(h.node_capacity()) + kRange - 1) / kRange);
    parallel_for(ranges.size(), threads, [&](size_t i) {
        RangeCheck& r = ranges[i];
        const NodeId begin = NodeId(i) * kRange, end = std::min<NodeId>(h.node_capacity(), begin + kRange);
        r.problem = check_node_range(h, begin, end, r.nodes, r.split_edges);
    });
    uint32_t nodes = 0;
    uint64_t split_edges = 0;
    for (const RangeCheck& r : ranges) {
        if (!r.problem.empty()) return r.problem;
        nodes += r.nodes;
        split_edges += r.split_edges;
    }
    if (nodes != h.node_count()) return "node count " + std::to_string(h.node_count()) + " but " + std::to_string(nodes) + " live nodes";
    if (h.vertex_count() != h.base().positions.size() + split_edges)
        return "vertex count " + std::to_string(h.vertex_count()) + " != base vertices + split edges (" +
               std::to_string(h.base().positions.size() + split_edges) + ")";
    return "";
}

namespace {

// The first problem of the positions of vertices [begin, end), or "".
std::string check_position_range(const Hierarchy& h, const std::vector<uint32_t>& canonical, VertexId begin, VertexId end) {
    for (VertexId v = begin; v < end; ++v) {
        if (!canonical.empty() && canonical[v] == kNoVertex) continue;
        const Vec3 p = h.position(v);
        for (const double x : {p.x, p.y, p.z}) {
            if (!std::isfinite(x)) return "vertex " + std::to_string(v) + " has a non-finite coordinate";
            if (h.single_precision() && !(std::fabs(x) <= FLT_MAX && rounded_to_float(x) == x))
                return "vertex " + std::to_string(v) + " has a coordinate that is not a float32 value (" +
                       number_text(x) + ") in a single-precision hierarchy";
        }
    }
    return "";
}

// Whether every coordinate (the bits of `coordinates` doubles at `bytes`) is zero or a normal
// float32 value: at most 23 fraction bits and an exponent of -126 to 127. Integer operations
// only (the differences' sign bits), over the coordinates as one array, which GCC vectorises.
bool zero_or_normal_floats(const unsigned char* bytes, size_t coordinates) {
    uint64_t failed = 0;
    for (size_t k = 0; k < coordinates; ++k) {
        uint64_t x;
        std::memcpy(&x, bytes + 8 * k, 8);
        const uint64_t exponent = (x >> 52) & 0x7FF;
        const uint64_t out_of_range = ((exponent - 897) | (1150 - exponent)) >> 63;  // float32's -126..127
        const uint64_t magnitude = x << 1;
        const uint64_t nonzero = (magnitude | (0 - magnitude)) >> 63;
        const uint64_t fraction_below_float = ((x & 0x1FFFFFFF) + 0x1FFFFFFF) >> 29;  // any of the 29 low bits
        failed |= (out_of_range & nonzero) | fraction_below_float;
    }
    return failed == 0;
}

// Whether every coordinate of vertices [begin, end) passes check_position_range's tests: one pass
// without branches or messages (every encode checks its whole input), the messages only for a
// range that fails. Out-of-range values are not converted to float (a select, not a branch).
bool positions_pass(const Hierarchy& h, VertexId begin, VertexId end) {
    static_assert(sizeof(Vec3) == 3 * sizeof(double), "a position is three coordinates");
    const Vec3* positions = h.positions().data();
    const unsigned char* bytes = reinterpret_cast<const unsigned char*>(positions + begin);
    const size_t coordinates = 3 * size_t(end - begin);
    if (h.single_precision()) {
        if (zero_or_normal_floats(bytes, coordinates)) return true;
        bool bad = false;  // subnormal float32 values, or a failure: the exact tests
        for (VertexId v = begin; v < end; ++v) {
            for (const double x : {positions[v].x, positions[v].y, positions[v].z}) {
                const bool in_range = std::fabs(x) <= FLT_MAX;  // false for NaN too
                const double y = in_range ? x : 0.0;
                bad |= !in_range | (rounded_to_float(y) != y);
            }
        }
        return !bad;
    }
    // A coordinate is not finite when its exponent bits are all set: adding one to the exponent
    // then carries into the sign bit. Integer ORs over the coordinates as one array, which GCC
    // vectorises (the compares were not).
    constexpr uint64_t kExponent = 0x7FF0000000000000ull, kExponentOne = 0x0010000000000000ull;
    uint64_t carries = 0;
    for (size_t k = 0; k < coordinates; ++k) {
        uint64_t x;
        std::memcpy(&x, bytes + 8 * k, 8);
        carries |= (x & kExponent) + kExponentOne;
    }
    return (carries >> 63) == 0;
}

// Ranges of vertices checked on `threads` threads; the first problem in vertex order is reported.
std::string check_positions(const Hierarchy& h, unsigned threads) {
    // Without removed ids every id is a live vertex: no need to find them.
    const bool all_live = h.vertex_count() == h.positions().size();
    const std::vector<uint32_t> canonical = all_live ? std::vector<uint32_t>() : canonical_vertex_order(h);
    constexpr VertexId kRange = VertexId(1) << 16;
    const VertexId vertices = VertexId(h.positions().size());
    std::vector<std::string> problems((size_t(vertices) + kRange - 1) / kRange);
    parallel_for(problems.size(), threads, [&](size_t i) {
        const VertexId begin = VertexId(i) * kRange, end = std::min<VertexId>(vertices, begin + kRange);
        if (!all_live || !positions_pass(h, begin, end)) problems[i] = check_position_range(h, canonical, begin, end);
    });
    for (const std::string& problem : problems)
        if (!problem.empty()) return problem;
    return "";
}

}  // namespace

std::string check_positions(const Hierarchy& h) { return check_positions(h, 1); }

void check_before_writing(const Hierarchy& h, const std::string& what, bool positions, unsigned threads) {
    validate_triangle_mesh(h.base(), what + ": base mesh");
    if (!HierarchyBuilder::structure_checked(h)) {
        const std::string problem = check_invariants(h, threads);
        AMC_REQUIRE(problem.empty(), invalid_input, what + ": invalid hierarchy: " + problem);
    }
    if (!positions) return;
    const std::string position_problem = check_positions(h, threads);
    AMC_REQUIRE(position_problem.empty(), invalid_input, what + ": " + position_problem);
}

}  // namespace amc
