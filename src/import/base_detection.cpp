#include "import/base_detection.h"

#include "common/no_index.h"
#include "import/inverse_refinement.h"

#include <utility>
#include <vector>

namespace amc {
namespace {

// The base mesh over the used vertices of `triangles`, numbered in the order of their input ids.
void set_base(const TriangleMesh& mesh, const std::vector<Triangle>& triangles, DetectedBase& out) {
    const uint32_t vertex_count = uint32_t(mesh.positions.size());
    std::vector<uint32_t> base_index(vertex_count, kNoIndex);
    for (const Triangle& t : triangles) {
        for (uint32_t v : t) base_index[v] = 0;
    }
    out.base = TriangleMesh{};
    out.leaf_vertex_of_base.clear();
    for (uint32_t v = 0; v < vertex_count; ++v) {
        if (base_index[v] == 0) {
            base_index[v] = uint32_t(out.leaf_vertex_of_base.size());
            out.leaf_vertex_of_base.push_back(v);
            out.base.positions.push_back(mesh.positions[v]);
        }
    }
    out.base.single_precision = mesh.single_precision;
    out.base.triangles.reserve(triangles.size());
    for (const Triangle& t : triangles) out.base.triangles.push_back({base_index[t[0]], base_index[t[1]], base_index[t[2]]});
}

// The vertices in breadth-first order over the triangles (input ids; unused vertices last). The
// search reads the labels of a vertex's neighbours at every step: numbered this way they share
// cache lines, where a shuffled input's numbering makes each read a miss. The search never
// compares vertex ids, so the numbering changes no result.
std::vector<uint32_t> breadth_first_vertices(const std::vector<Triangle>& triangles, uint32_t vertex_count) {
    std::vector<uint32_t> first(size_t(vertex_count) + 1, 0), around(triangles.size() * 3);
    for (const Triangle& t : triangles) {
        for (uint32_t v : t) ++first[v + 1];
    }
    for (uint32_t v = 0; v < vertex_count; ++v) first[v + 1] += first[v];
    std::vector<uint32_t> fill(first.begin(), first.end() - 1);
    for (uint32_t t = 0; t < triangles.size(); ++t) {
        for (uint32_t v : triangles[t]) around[fill[v]++] = t;
    }
    std::vector<uint32_t> order;
    order.reserve(vertex_count);
    std::vector<uint8_t> seen(vertex_count, 0);
    for (uint32_t root = 0; root < vertex_count; ++root) {
        if (seen[root]) continue;
        seen[root] = 1;
        order.push_back(root);
        for (size_t next = order.size() - 1; next < order.size(); ++next) {
            const uint32_t v = order[next];
            for (uint32_t k = first[v]; k < first[v + 1]; ++k) {
                for (uint32_t w : triangles[around[k]]) {
                    if (!seen[w]) seen[w] = 1, order.push_back(w);
                }
            }
        }
    }
    return order;
}

void renumber(std::vector<Triangle>& triangles, const std::vector<uint32_t>& id) {
    for (Triangle& t : triangles) {
        for (uint32_t& v : t) v = id[v];
    }
}

}  // namespace

DetectedBase detect_base(const TriangleMesh& mesh, const std::string& what) {
    validate_triangle_mesh(mesh, what);
    const uint32_t vertex_count = uint32_t(mesh.positions.size());
    DetectedBase out;
    // The search runs on its own vertex numbering (breadth_first_vertices); the levels it found
    // are given back in input ids.
    const std::vector<uint32_t> input_of = breadth_first_vertices(mesh.triangles, vertex_count);
    std::vector<uint32_t> search_of(vertex_count);
    for (uint32_t v = 0; v < vertex_count; ++v) search_of[input_of[v]] = v;
    std::vector<Triangle> renumbered = mesh.triangles;
    renumber(renumbered, search_of);
    const std::vector<Triangle>* triangles = &renumbered;
    std::vector<uint8_t> refined(mesh.triangles.size(), 0);
    std::vector<uint8_t> changed;
    // Each level undone adds one to the depth of the hierarchy, which kMaxLevel caps.
    while (out.levels.size() < size_t(kMaxLevel)) {
        detail::CoarserLevel coarser =
            detail::undo_refinement_level(*triangles, refined, vertex_count, out.levels.empty() ? nullptr : &changed);
        if (coarser.red_blocks == 0) break;
        DetectedLevel level;
        level.splits = std::move(coarser.splits);
        level.closures = coarser.green_groups;
        level.triangles = std::move(coarser.triangles);
        refined = std::move(coarser.refined);
        changed = std::move(coarser.changed);
        out.levels.push_back(std::move(level));
        triangles = &out.levels.back().triangles;
    }
    for (DetectedLevel& level : out.levels) {
        renumber(level.triangles, input_of);
        for (auto& split : level.splits) {
            for (uint32_t& v : split) v = input_of[v];
        }
    }
    set_base(mesh, out.levels.empty() ? mesh.triangles : out.levels.back().triangles, out);
    return out;
}

DetectedBase truncated(const TriangleMesh& mesh, DetectedBase detected, size_t levels) {
    detected.levels.resize(std::min(levels, detected.levels.size()));
    set_base(mesh, detected.levels.empty() ? mesh.triangles : detected.levels.back().triangles, detected);
    return detected;
}

}  // namespace amc
