// Bottom-up base detection against the true hierarchy (docs/IMPORT.md, "Bottom-up, measured
// against the truth"): for every corpus hierarchy, its leaf mesh as a user holds it (shuffled,
// non-base vertices moved: the detection reads no position, so the move changes nothing), the
// levels that undo_refinement_level finds one step at a time, each undone split compared with the
// true hierarchy's splits (same three midpoints = true), free and with the base vertices kept
// (the anchored way of import_leaf_mesh); beside it, what an ideal bottom-up search could undo
// per step, computed on the true hierarchy:
//   * whole: every node whose children are leaves, undone only together with every refined
//     same-level neighbour (no midpoint stays: the model of undo_refinement_level's patches);
//   * partial: the same, but a node may be undone while a neighbour stays refined (the node turns
//     green, the shared midpoint stays a vertex; fewer than three such neighbours).
// Prints a Markdown table, and with --steps every step. With --ready, every free step is also
// compared with what it could have undone: the true nodes "ready" before it (refined, every child
// a leaf or undone by an earlier step), split into those whose refined same-level neighbours are all
// ready too ("closed": the whole-patch model could undo them now) and the others ("waiting"), with
// how many of each the step undid and the sizes of the closed groups it left (docs/IMPORT.md,
// "A refined node across a closure").
//
// With --detect, also what detect_base (import_mesh's search, its rerun included) undid per level.
// With --wrong, the free steps' wrong splits counted by the coarsest vertex each reads as a
// midpoint (its level in the true hierarchy: 0 for a base vertex, l + 1 for a midpoint of a level-l
// node), beside the finest level the step undid (docs/IMPORT.md, "The demo's wrong undos").
//
// Usage: import_levels [--steps] [--ready] [--detect] [--wrong] [--seed N] corpus/*.amh   (--seed: the shuffle's, 23 by default)
#include "user_leaf_mesh.h"

#include "import/base_detection.h"
#include "import/inverse_refinement.h"

#include <amc/hierarchy.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <vector>

namespace {

using amc::NodeId;
using Key = std::array<uint32_t, 3>;

Key sorted_key(uint32_t a, uint32_t b, uint32_t c) {
    Key k{a, b, c};
    std::sort(k.begin(), k.end());
    return k;
}

// h rebuilt without the splits of the nodes marked in `drop` (whose children are leaves).
amc::Hierarchy without(const amc::Hierarchy& h, const std::vector<uint8_t>& drop) {
    amc::Hierarchy g(h.base());
    std::vector<NodeId> map(h.node_capacity(), amc::kNoNode);
    for (NodeId r = 0; r < h.root_count(); ++r) map[r] = r;
    for (NodeId n : h.breadth_first_order()) {
        if (h.is_leaf(n) || drop[n]) continue;
        g.split(map[n]);
        for (int k = 0; k < 4; ++k) map[h.child(n, k)] = g.child(map[n], k);
    }
    return g;
}

// Nodes undone per step by the ideal search (see the top of the file) until only the base is left.
std::vector<size_t> ideal_steps(amc::Hierarchy h, bool partial) {
    std::vector<size_t> steps;
    while (steps.size() < 64) {
        std::vector<uint8_t> undo(h.node_capacity(), 0);
        size_t count = 0;
        for (NodeId n = 0; n < h.node_capacity(); ++n) {
            if (!h.is_alive(n) || h.is_leaf(n)) continue;
            bool children_leaves = true;
            for (int k = 0; k < 4; ++k) children_leaves &= h.is_leaf(h.child(n, k));
            if (children_leaves) undo[n] = 1, ++count;
        }
        // Greatest valid subset: drop nodes whose undoing would break balance or closure.
        for (bool changed = true; changed;) {
            changed = false;
            for (NodeId n = 0; n < h.node_capacity(); ++n) {
                if (!undo[n]) continue;
                int staying = 0;
                bool valid = true;
                for (int e = 0; e < 3; ++e) {
                    const NodeId nb = h.neighbor(n, e);
                    if (nb == amc::kNoNode || h.is_leaf(nb) || undo[nb]) continue;
                    ++staying;
                    const int ne = h.neighbor_edge(n, e);  // its children on the shared edge: corners ne, ne + 1
                    for (int k : {ne, (ne + 1) % 3}) valid &= h.is_leaf(h.child(nb, k)) || undo[h.child(nb, k)];
                }
                if (partial ? staying == 3 || !valid : staying > 0) undo[n] = 0, --count, changed = true;
            }
        }
        if (count == 0) break;
        steps.push_back(count);
        h = without(h, undo);
    }
    return steps;
}

// Called after each step with the splits it undid.
using StepObserver = std::function<void(int step, const std::vector<std::array<uint32_t, 6>>& splits)>;

struct Detection {
    std::vector<std::array<size_t, 2>> steps;  // true, wrong blocks per step
    size_t true_blocks = 0, wrong_blocks = 0, triangles_left = 0;
    size_t first_step_finest = 0;  // true blocks of step 1 whose node is at the finest refined level
};

Detection detect(const amc::TriangleMesh& mesh, const std::map<Key, int>& level_of_split, int finest,
                 const std::vector<uint8_t>* kept, const StepObserver& observe = {}) {
    Detection out;
    const uint32_t vertex_count = uint32_t(mesh.positions.size());
    std::vector<std::vector<amc::Triangle>> levels;
    const std::vector<amc::Triangle>* triangles = &mesh.triangles;
    std::vector<uint8_t> refined(mesh.triangles.size(), 0), changed;
    for (int step = 0; step < amc::kMaxLevel; ++step) {
        amc::detail::CoarserLevel coarser =
            amc::detail::undo_refinement_level(*triangles, refined, vertex_count, step ? &changed : nullptr, kept);
        if (coarser.red_blocks == 0) break;
        std::array<size_t, 2> counts{0, 0};
        for (const auto& s : coarser.splits) {
            const auto it = level_of_split.find(sorted_key(s[3], s[4], s[5]));
            ++counts[it == level_of_split.end()];
            if (step == 0 && it != level_of_split.end() && it->second == finest) ++out.first_step_finest;
        }
        out.steps.push_back(counts);
        if (observe) observe(step, coarser.splits);
        out.true_blocks += counts[0];
        out.wrong_blocks += counts[1];
        refined = std::move(coarser.refined);
        changed = std::move(coarser.changed);
        levels.push_back(std::move(coarser.triangles));
        triangles = &levels.back();
    }
    out.triangles_left = triangles->size();
    return out;
}

// The --ready comparison: the true nodes undone so far, and per step what was ready.
class ReadyTrace {
public:
    ReadyTrace(const amc::Hierarchy& h, std::map<Key, NodeId> node_of_split)
        : h_(h), node_of_split_(std::move(node_of_split)), undone_(h.node_capacity(), 0) {}

    void step(int step, const std::vector<std::array<uint32_t, 6>>& splits) {
        std::vector<uint8_t> got(h_.node_capacity(), 0);
        size_t wrong = 0;
        for (const auto& s : splits) {
            const auto it = node_of_split_.find(sorted_key(s[3], s[4], s[5]));
            if (it == node_of_split_.end()) {
                ++wrong;
            } else {
                got[it->second] = 1;
            }
        }
        size_t closed = 0, closed_undone = 0, waiting = 0, waiting_undone = 0;
        std::map<size_t, size_t> missed_groups;  // closed groups left, by size class (1, 2, 3, 4+, 16+, 256+)
        for (const std::vector<NodeId>& group : same_level_groups()) {
            size_t ready = 0, undone = 0;
            for (NodeId n : group) ready += is_ready(n), undone += got[n];
            if (ready == group.size()) {
                closed += ready, closed_undone += undone;
                if (undone < group.size()) ++missed_groups[size_class(group.size())];
            } else {
                waiting += ready, waiting_undone += undone;
            }
        }
        std::printf("|   step %d: closed ready %zu, undone %zu; waiting %zu, undone %zu; wrong %zu; closed groups left by size:",
                    step + 1, closed, closed_undone, waiting, waiting_undone, wrong);
        for (const auto& [size, count] : missed_groups) std::printf(" %zu+: %zu", size, count);
        std::printf(" | | | | | | | |\n");
        for (NodeId n = 0; n < h_.node_capacity(); ++n) undone_[n] |= got[n];
    }

private:
    static size_t size_class(size_t size) { return size < 4 ? size : size < 16 ? 4 : size < 256 ? 16 : 256; }
    bool is_refined(NodeId n) const { return h_.is_alive(n) && !h_.is_leaf(n) && !undone_[n]; }
    bool is_ready(NodeId n) const {
        if (!is_refined(n)) return false;
        for (int k = 0; k < 4; ++k) {
            if (is_refined(h_.child(n, k))) return false;
        }
        return true;
    }
    // The refined nodes not undone yet, grouped by same-level adjacency (what a patch joins).
    std::vector<std::vector<NodeId>> same_level_groups() const {
        std::vector<uint8_t> seen(h_.node_capacity(), 0);
        std::vector<std::vector<NodeId>> groups;
        for (NodeId n = 0; n < h_.node_capacity(); ++n) {
            if (!is_refined(n) || seen[n]) continue;
            std::vector<NodeId> group{n};
            seen[n] = 1;
            for (size_t k = 0; k < group.size(); ++k) {
                for (int e = 0; e < 3; ++e) {
                    const NodeId m = h_.neighbor(group[k], e);
                    if (m == amc::kNoNode || seen[m] || !is_refined(m) || h_.level(m) != h_.level(n)) continue;
                    seen[m] = 1;
                    group.push_back(m);
                }
            }
            groups.push_back(std::move(group));
        }
        return groups;
    }

    const amc::Hierarchy& h_;
    std::map<Key, NodeId> node_of_split_;
    std::vector<uint8_t> undone_;
};

std::string list(const std::vector<size_t>& v) {
    std::string s;
    for (size_t x : v) s += (s.empty() ? "" : ", ") + std::to_string(x);
    return s;
}

}  // namespace

int main(int argc, char** argv) {
    bool print_steps = false, print_ready = false, print_detected = false, print_wrong = false;
    uint64_t seed = 23;
    std::vector<std::string> files;
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        if (arg == "--steps") {
            print_steps = true;
        } else if (arg == "--seed" && i + 1 < argc) {
            seed = std::strtoull(argv[++i], nullptr, 10);
        } else if (arg == "--ready") {
            print_ready = true;
        } else if (arg == "--detect") {
            print_detected = true;
        } else if (arg == "--wrong") {
            print_wrong = true;
        } else {
            files.push_back(arg);
        }
    }
    if (files.empty()) {
        std::fprintf(stderr, "usage: import_levels [--steps] [--ready] [--detect] [--wrong] [--seed N] hierarchy.amh...\n");
        return 2;
    }
    std::printf("| model | depth | refined nodes | ideal, whole patches: undone per step | ideal, partial | finest level's nodes found in step 1 | free: true / wrong blocks, triangles left | anchored: true / wrong, triangles left (base) |\n");
    std::printf("|---|---:|---:|---|---|---:|---|---|\n");
    for (const std::string& file : files) {
        const amc::Hierarchy h = amc::read_hierarchy(file);
        const amc::LeafMesh leaf = amc::extract_leaf_mesh(h);
        std::vector<uint32_t> user_of_leaf;
        const amc::TriangleMesh user =
            bench::user_leaf_mesh(leaf.mesh, uint32_t(h.base().positions.size()), 0.3, seed, &user_of_leaf);
        const std::vector<uint32_t> canonical = amc::canonical_vertex_order(h);
        auto user_vertex = [&](amc::VertexId v) { return user_of_leaf[canonical[v]]; };
        std::map<Key, int> level_of_split;
        std::map<Key, NodeId> node_of_split;
        int finest = -1;
        size_t at_finest = 0;
        for (NodeId n : h.breadth_first_order()) {
            if (h.is_leaf(n)) continue;
            const Key key = sorted_key(user_vertex(h.midpoint(n, 0)), user_vertex(h.midpoint(n, 1)),
                                       user_vertex(h.midpoint(n, 2)));
            level_of_split[key] = h.level(n);
            node_of_split[key] = n;
            finest = std::max(finest, h.level(n));
        }
        for (const auto& entry : level_of_split) at_finest += entry.second == finest;
        std::vector<uint8_t> kept(user.positions.size(), 0);
        for (amc::VertexId v = 0; v < h.base().positions.size(); ++v) kept[user_vertex(v)] = 1;
        ReadyTrace ready(h, std::move(node_of_split));
        // Per user vertex: the level at which it appears in the true hierarchy.
        std::vector<int> vertex_level(user.positions.size(), 0);
        for (NodeId n : h.breadth_first_order()) {
            if (h.is_leaf(n)) continue;
            for (int k = 0; k < 3; ++k) vertex_level[user_vertex(h.midpoint(n, k))] = h.level(n) + 1;
        }
        StepObserver observe = [&](int step, const std::vector<std::array<uint32_t, 6>>& splits) {
            if (print_ready) ready.step(step, splits);
            if (!print_wrong) return;
            std::map<int, size_t> wrong_by_level;  // coarsest vertex read as a midpoint -> wrong splits
            int finest_undone = -1;
            for (const auto& s : splits) {
                const auto it = level_of_split.find(sorted_key(s[3], s[4], s[5]));
                if (it != level_of_split.end()) {
                    finest_undone = std::max(finest_undone, it->second);
                    continue;
                }
                ++wrong_by_level[std::min({vertex_level[s[3]], vertex_level[s[4]], vertex_level[s[5]]})];
            }
            std::printf("|   step %d: finest node level undone %d; wrong splits by the coarsest vertex read as a midpoint:", step + 1,
                        finest_undone);
            for (const auto& [level, count] : wrong_by_level) std::printf(" level %d: %zu", level, count);
            std::printf(" | | | | | | | |\n");
        };
        const Detection free = detect(user, level_of_split, finest, nullptr, observe);
        const Detection anchored = detect(user, level_of_split, finest, &kept);
        const std::string name = std::filesystem::path(file).stem().string();
        std::printf("| %s | %d | %zu | %s | %s | %zu / %zu | %zu / %zu, %zu | %zu / %zu, %zu (%u) |\n", name.c_str(),
                    finest + 1, level_of_split.size(), list(ideal_steps(h, false)).c_str(),
                    list(ideal_steps(h, true)).c_str(), free.first_step_finest, at_finest, free.true_blocks,
                    free.wrong_blocks, free.triangles_left, anchored.true_blocks, anchored.wrong_blocks,
                    anchored.triangles_left, h.root_count());
        if (print_steps) {
            for (const Detection* d : {&free, &anchored}) {
                std::printf("|   %s steps (true/wrong): ", d == &free ? "free" : "anchored");
                for (const auto& s : d->steps) std::printf("%zu/%zu ", s[0], s[1]);
                std::printf("| | | | | | | |\n");
            }
        }
        if (print_detected) {
            // What import_mesh's base detection commits (with its rerun), per level.
            const amc::DetectedBase detected = amc::detect_base(user, name);
            std::printf("|   detect_base (true/wrong): ");
            for (const amc::DetectedLevel& level : detected.levels) {
                size_t wrong = 0;
                for (const auto& s : level.splits) wrong += level_of_split.count(sorted_key(s[3], s[4], s[5])) == 0;
                std::printf("%zu/%zu ", level.splits.size() - wrong, wrong);
            }
            std::printf("-> %zu triangles | | | | | | | |\n", detected.base.triangles.size());
        }
        std::fflush(stdout);
    }
    return 0;
}
