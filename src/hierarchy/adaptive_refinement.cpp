// Adaptive refinement drivers: uniform, random, size-field (finite-element style); the surface
// remesher is in surface_remeshing.cpp.
#include <amc/refinement.h>

#include "common/check.h"
#include "common/mixing.h"
#include "hierarchy/node_shape.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace amc {

namespace {

void push_children(const Hierarchy& h, const std::vector<NodeId>& split, std::vector<NodeId>& out) {
    for (NodeId s : split) {
        for (int k = 0; k < 4; ++k) out.push_back(h.child(s, k));
    }
}

}  // namespace

void refine_uniformly(Hierarchy& h, int levels) {
    for (int l = 0; l < levels; ++l) {
        for (NodeId n : h.leaves()) h.refine(n);
    }
}

void refine_randomly(Hierarchy& h, uint32_t target_leaves, int max_level, uint64_t seed, double coarsen_ratio) {
    SplitMix64 random{seed};
    std::vector<NodeId> candidates = h.leaves();
    std::vector<NodeId> split;
    while (h.leaf_count() < target_leaves && !candidates.empty()) {
        const size_t pick = random.below(candidates.size());
        const NodeId n = candidates[pick];
        if (!h.is_alive(n) || !h.is_leaf(n) || h.level(n) >= max_level) {
            candidates[pick] = candidates.back();
            candidates.pop_back();
            continue;
        }
        split.clear();
        h.refine(n, &split);
        push_children(h, split, candidates);
        if (coarsen_ratio > 0 && double(random.next() % 1024) < coarsen_ratio * 1024) {
            const NodeId c = candidates[random.below(candidates.size())];
            if (h.is_alive(c) && h.parent(c) != kNoNode) {
                const NodeId p = h.parent(c);
                if (h.coarsen(p)) candidates.push_back(p);
            }
        }
    }
}

void refine_to_size(Hierarchy& h, const std::function<double(Vec3)>& size_at, int max_level, uint64_t max_nodes) {
    std::vector<NodeId> todo = h.leaves();
    std::vector<NodeId> split;
    while (!todo.empty()) {
        const NodeId n = todo.back();
        todo.pop_back();
        if (!h.is_alive(n) || !h.is_leaf(n) || h.level(n) >= max_level) continue;
        if (node_diameter(h, n) <= size_at(node_centroid(h, n))) continue;
        split.clear();
        h.refine(n, &split);
        AMC_REQUIRE(h.node_count() <= max_nodes, limit_exceeded, "more than " + std::to_string(max_nodes) + " nodes");
        push_children(h, split, todo);
    }
}

namespace {

// Coarsens, finest first, every node whose own size already satisfies the size field, until no
// more can go (balance may keep some).
void coarsen_to_size(Hierarchy& h, const std::function<double(Vec3)>& size_at) {
    for (bool changed = true; changed;) {
        changed = false;
        std::vector<NodeId> order = h.breadth_first_order();
        for (auto it = order.rbegin(); it != order.rend(); ++it) {
            const NodeId n = *it;
            if (h.is_alive(n) && !h.is_leaf(n) && node_diameter(h, n) <= size_at(node_centroid(h, n)) && h.coarsen(n))
                changed = true;
        }
    }
}

}  // namespace

Vec3 node_centroid(const Hierarchy& h, NodeId n) {
    return (1.0 / 3.0) * (h.position(h.vertex(n, 0)) + h.position(h.vertex(n, 1)) + h.position(h.vertex(n, 2)));
}

double node_diameter(const Hierarchy& h, NodeId n) {
    double longest = 0;
    for (int e = 0; e < 3; ++e) {
        Vec3 d = h.position(h.vertex(n, e)) - h.position(h.vertex(n, (e + 1) % 3));
        longest = std::max(longest, dot(d, d));
    }
    return std::sqrt(longest);
}

Hierarchy make_l_shape_model(int max_level, double size_scale) {
    Hierarchy h(make_l_shape(4));
    // A-priori grading for the corner singularity r^(2/3): element size ~ r^(1/3) far out,
    // shrinking to the finest level at the corner.
    refine_to_size(
        h,
        [size_scale](Vec3 x) {
            const double r = std::sqrt(x.x * x.x + x.y * x.y);
            return size_scale * std::pow(r, 0.6);
        },
        max_level);
    return h;
}

std::vector<Hierarchy> make_moving_front_sequence(int steps, int max_level, uint64_t max_nodes) {
    std::vector<Hierarchy> sequence;
    uint64_t kept = 0;  // nodes of the steps in `sequence`
    Hierarchy h(make_square(8));
    for (int step = 0; step < steps; ++step) {
        // A circular front around (-0.3, -0.2) sweeping outwards across the square.
        const double radius = 0.5 + 1.0 * step / std::max(1, steps - 1);
        auto size_at = [radius](Vec3 x) {
            const double dx = x.x + 0.3, dy = x.y + 0.2;
            return 1.2 * std::fabs(std::sqrt(dx * dx + dy * dy) - radius);
        };
        coarsen_to_size(h, size_at);
        bool fits = true;  // within the nodes the steps before left
        try {
            refine_to_size(h, size_at, max_level, max_nodes - kept);
        } catch (const Error& e) {
            if (e.code() != ErrorCode::limit_exceeded) throw;
            fits = false;
        }
        kept += h.node_count();
        AMC_REQUIRE(fits && kept <= max_nodes, limit_exceeded,
                    "more than " + std::to_string(max_nodes) + " nodes in its first " + std::to_string(step + 1) + " steps");
        sequence.push_back(h);
    }
    return sequence;
}

HierarchyStats compute_stats(const Hierarchy& h) {
    HierarchyStats s;
    s.base_triangles = h.root_count();
    s.base_vertices = uint32_t(h.base().positions.size());
    s.nodes = h.node_count();
    s.leaves = h.leaf_count();
    s.vertices = h.vertex_count();
    for (NodeId n : h.breadth_first_order()) {
        const uint32_t l = uint32_t(h.level(n));
        if (s.nodes_per_level.size() <= l) s.nodes_per_level.resize(l + 1);
        ++s.nodes_per_level[l];
        if (!h.is_leaf(n)) continue;
        switch (h.hanging_node_count(n)) {
            case 0: ++s.red_faces; break;
            case 1: ++s.one_hanging; s.green_faces += 2; break;
            default: ++s.two_hanging; s.green_faces += 3; break;
        }
    }
    s.levels = uint32_t(s.nodes_per_level.size());
    s.faces = s.red_faces + s.green_faces;
    return s;
}

}  // namespace amc
