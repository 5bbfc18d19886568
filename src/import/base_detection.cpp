#include "import/base_detection.h"

#include "common/no_index.h"
#include "import/inverse_refinement.h"

#include <utility>

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

}  // namespace

DetectedBase detect_base(const TriangleMesh& mesh, const std::string& what) {
    validate_triangle_mesh(mesh, what);
    const uint32_t vertex_count = uint32_t(mesh.positions.size());
    DetectedBase out;
    const std::vector<Triangle>* triangles = &mesh.triangles;
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
    set_base(mesh, *triangles, out);
    return out;
}

DetectedBase truncated(const TriangleMesh& mesh, DetectedBase detected, size_t levels) {
    detected.levels.resize(std::min(levels, detected.levels.size()));
    set_base(mesh, detected.levels.empty() ? mesh.triangles : detected.levels.back().triangles, detected);
    return detected;
}

}  // namespace amc
