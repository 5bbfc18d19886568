// validate_triangle_mesh: the checks a base mesh must pass before it is coded. Everything is
// O(n): half-edges are grouped by vertex with a counting sort and checked with a stamp per vertex;
// only a mesh that fails is grouped and sorted again, to name its first fault.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "amc/mesh.h"
#include "mesh/vertex_buckets.h"

namespace amc {
namespace {

[[noreturn]] void fail(const std::string& what, const std::string& message) {
    throw Error(what + ": " + message);
}

std::string edge_name(uint32_t a, uint32_t b) {
    return "edge (" + std::to_string(a) + "," + std::to_string(b) + ")";
}

void check_indices(const TriangleMesh& mesh, const std::string& what) {
    const std::size_t n = mesh.positions.size();
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
        const Triangle& tri = mesh.triangles[t];
        for (uint32_t v : tri) {
            if (v >= n) {
                fail(what, "triangle " + std::to_string(t) + " has index " + std::to_string(v) +
                               " out of range (" + std::to_string(n) + " vertices)");
            }
        }
        for (int i = 0; i < 3; ++i) {
            if (tri[i] == tri[(i + 1) % 3]) {
                fail(what, "triangle " + std::to_string(t) + " is degenerate (repeats vertex " +
                               std::to_string(tri[i]) + ")");
            }
        }
    }
}

void check_positions(const TriangleMesh& mesh, const std::string& what) {
    for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
        const Vec3& p = mesh.positions[v];
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
            fail(what, "vertex " + std::to_string(v) + " has a non-finite coordinate");
        }
    }
    std::vector<bool> used(mesh.positions.size(), false);
    for (const Triangle& tri : mesh.triangles) {
        for (uint32_t v : tri) used[v] = true;
    }
    for (std::size_t v = 0; v < used.size(); ++v) {
        if (!used[v]) {
            fail(what, "vertex " + std::to_string(v) +
                           " is not used by any triangle (isolated vertices cannot be coded)");
        }
    }
}

// Two triangles over the same three vertices (in either orientation).
void check_repeated_triangles(const TriangleMesh& mesh, const std::string& what) {
    struct Key {
        uint32_t mid, high, index;  // the sorted vertices after the lowest, and the triangle
        bool operator<(const Key& o) const {
            return mid != o.mid ? mid < o.mid : high != o.high ? high < o.high : index < o.index;
        }
    };
    // Each triangle's vertices sorted once (bucket_by_vertex reads an item twice, then makes it).
    std::vector<Triangle> sorted(mesh.triangles.size());
    for (std::size_t t = 0; t < sorted.size(); ++t) {
        const Triangle& tri = mesh.triangles[t];
        const uint32_t lo = std::min(tri[0], tri[1]), hi = std::max(tri[0], tri[1]);
        sorted[t] = {std::min(lo, tri[2]), std::max(lo, std::min(hi, tri[2])), std::max(hi, tri[2])};
    }
    std::vector<Key> keys;
    const std::vector<std::size_t> start = bucket_by_vertex(
        mesh.positions.size(), mesh.triangles.size(), [&](std::size_t t) { return sorted[t][0]; },
        [&](std::size_t t) { return Key{sorted[t][1], sorted[t][2], static_cast<uint32_t>(t)}; }, keys);
    // Report the repeat with the smallest index, so the message does not depend on the order.
    std::size_t best_first = 0, best_repeat = SIZE_MAX;
    for (std::size_t v = 0; v + 1 < start.size(); ++v) {
        const auto first = keys.begin() + start[v], last = keys.begin() + start[v + 1];
        std::sort(first, last);
        for (auto k = first; k != last && k + 1 != last; ++k) {
            if (k[1].mid == k[0].mid && k[1].high == k[0].high &&
                (k == first || k[-1].mid != k[0].mid || k[-1].high != k[0].high) &&
                k[1].index < best_repeat) {
                best_repeat = k[1].index;
                best_first = k[0].index;
            }
        }
    }
    if (best_repeat != SIZE_MAX) {
        fail(what, "triangle " + std::to_string(best_repeat) + " repeats triangle " +
                       std::to_string(best_first));
    }
}

// Every undirected edge is used by at most two triangles, and by two only in opposite
// directions (edge-manifold and consistently oriented). Boundaries and any genus are fine.
// Edges are grouped by their lower vertex, so the first offending edge in (low, high) order is
// reported.
void check_edges(const TriangleMesh& mesh, const std::string& what) {
    struct HalfEdge {
        uint32_t high, face;
        bool forward;  // runs from the lower vertex to the higher one
        bool operator<(const HalfEdge& o) const {
            return high != o.high ? high < o.high : face < o.face;
        }
    };
    // Each half-edge's lower vertex and entry made once (bucket_by_vertex reads an item twice).
    std::vector<uint32_t> low(mesh.triangles.size() * 3);
    std::vector<HalfEdge> made(low.size());
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
        const Triangle& tri = mesh.triangles[t];
        for (int i = 0; i < 3; ++i) {
            const uint32_t a = tri[i], b = tri[i == 2 ? 0 : i + 1];
            low[3 * t + i] = std::min(a, b);
            made[3 * t + i] = HalfEdge{std::max(a, b), static_cast<uint32_t>(t), a < b};
        }
    }
    std::vector<HalfEdge> edges;
    const std::vector<std::size_t> start = bucket_by_vertex(
        mesh.positions.size(), low.size(), [&](std::size_t h) { return low[h]; }, [&](std::size_t h) { return made[h]; },
        edges);
    for (std::size_t lo = 0; lo + 1 < start.size(); ++lo) {
        const auto first = edges.begin() + start[lo], last = edges.begin() + start[lo + 1];
        std::sort(first, last);
        for (auto i = first; i != last;) {
            auto j = i + 1;
            while (j != last && j->high == i->high) ++j;
            const uint32_t low = static_cast<uint32_t>(lo), high = i->high;
            const std::size_t count = static_cast<std::size_t>(j - i);
            if (count > 2) {
                std::string faces;
                for (auto k = i; k != j && k != i + 8; ++k) {
                    faces += (k == i ? "" : ", ") + std::to_string(k->face);
                }
                if (count > 8) faces += ", ...";
                fail(what, edge_name(low, high) + " is shared by " + std::to_string(count) +
                               " triangles (non-manifold): triangles " + faces);
            }
            if (count == 2 && i[0].forward == i[1].forward) {
                const uint32_t a = i->forward ? low : high, b = i->forward ? high : low;
                fail(what, edge_name(a, b) + " is used twice in the same direction by triangles " +
                               std::to_string(i[0].face) + " and " + std::to_string(i[1].face) +
                               " (inconsistent orientation)");
            }
            i = j;
        }
    }
}

// Whether check_repeated_triangles or check_edges would fail, in one linear pass without sorting:
// the half-edges grouped by their first vertex a, each with the triangle's third vertex. Both
// checks pass exactly when no half-edge is repeated (an edge used by two triangles in one
// direction, or by three) and no two triangles (a, b, c) and (a, c, b) form a pillow (a repeated
// triangle in the other orientation; one in the same orientation repeats its half-edges).
bool has_edge_fault(const TriangleMesh& mesh) {
    const std::size_t n = mesh.positions.size();
    std::vector<std::size_t> first(n + 1, 0);
    for (const Triangle& tri : mesh.triangles)
        for (uint32_t v : tri) ++first[v + 1];
    for (std::size_t v = 0; v < n; ++v) first[v + 1] += first[v];
    struct Leaving {
        uint32_t to, third;
    };
    std::vector<Leaving> leaving(3 * mesh.triangles.size());
    std::vector<std::size_t> next(first.begin(), first.end() - 1);
    for (const Triangle& tri : mesh.triangles) {
        leaving[next[tri[0]]++] = {tri[1], tri[2]};
        leaving[next[tri[1]]++] = {tri[2], tri[0]};
        leaving[next[tri[2]]++] = {tri[0], tri[1]};
    }
    // Per vertex a, stamp[b] == a + 1 marks the half-edge (a, b) and third_of[b] is its third vertex.
    std::vector<uint32_t> stamp(n, 0), third_of(n);
    for (std::size_t a = 0; a < n; ++a) {
        const uint32_t mark = static_cast<uint32_t>(a) + 1;
        for (std::size_t i = first[a]; i < first[a + 1]; ++i) {
            const Leaving& e = leaving[i];
            if (stamp[e.to] == mark) return true;  // a repeated half-edge
            stamp[e.to] = mark;
            third_of[e.to] = e.third;
        }
        for (std::size_t i = first[a]; i < first[a + 1]; ++i) {
            const Leaving& e = leaving[i];
            if (stamp[e.third] == mark && third_of[e.third] == e.to) return true;  // (a,to,third) and (a,third,to)
        }
    }
    return false;
}

}  // namespace

void validate_triangle_mesh(const TriangleMesh& mesh, const std::string& what) {
    if (mesh.triangles.empty()) fail(what, "the mesh has no triangles");
    if (mesh.triangles.size() > UINT32_MAX) fail(what, "too many triangles");
    check_indices(mesh, what);
    check_positions(mesh, what);
    if (!has_edge_fault(mesh)) return;
    // The checks that sort find the fault again, to report the first one in their order.
    check_repeated_triangles(mesh, what);
    check_edges(mesh, what);
    fail(what, "the mesh is not edge-manifold and consistently oriented");
}

}  // namespace amc
