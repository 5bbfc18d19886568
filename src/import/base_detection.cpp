#include "import/base_detection.h"

#include "common/no_index.h"
#include "common/parallel.h"
#include "import/inverse_refinement.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <condition_variable>
#include <functional>
#include <map>
#include <mutex>
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

// One run of the search: the levels it undid, per level what a search from it needs besides the
// level (which made triangles are refined: the splits' parents; the positions in its mesh of the
// triangles its step left for later) and the blockers its step reported; and the mesh the last
// level left, with its flags, where the next step starts (only the last: a large mesh has tens of
// levels).
struct SearchRun {
    std::vector<DetectedLevel> levels;
    std::vector<std::vector<uint8_t>> made_refined;
    std::vector<std::vector<uint32_t>> deferred;
    std::vector<std::vector<Triangle>> blockers;
    std::vector<Triangle> mesh;           // empty while no level is undone
    std::vector<uint8_t> refined, changed;  // per triangle of `mesh`
};

// Set when a search's answer is no longer wanted: it stops within its step.
using Cancel = std::atomic<bool>;

// One more level undone at the end of `run`, seeded only where the last step changed the mesh
// or, `everywhere`, on the whole mesh; in step s the vertices marked in kept[s] (if any) stay.
// Returns whether the step undid anything (false also when `cancel`, if given, was set).
bool undo_one_level(const std::vector<Triangle>& triangles, uint32_t vertex_count,
                    const std::vector<std::vector<uint8_t>>& kept, bool everywhere, SearchRun& run,
                    const Cancel* cancel = nullptr) {
    const size_t s = run.levels.size();
    const bool has_kept = s < kept.size() && !kept[s].empty();
    const std::vector<uint8_t> unrefined(s == 0 ? triangles.size() : 0, 0);
    detail::CoarserLevel coarser = detail::undo_refinement_level(
        s == 0 ? triangles : run.mesh, s == 0 ? unrefined : run.refined, vertex_count,
        s == 0 || everywhere ? nullptr : &run.changed, has_kept ? &kept[s] : nullptr, false, cancel);
    if (coarser.red_blocks == 0) return false;
    DetectedLevel level = detail::detected_level(coarser);
    const size_t made = level.made.size();
    std::vector<uint32_t> deferred;
    for (size_t i = made; i < coarser.changed.size(); ++i) {
        if (coarser.changed[i]) deferred.push_back(uint32_t(i));
    }
    run.levels.push_back(std::move(level));
    run.made_refined.emplace_back(coarser.refined.begin(), coarser.refined.begin() + std::ptrdiff_t(made));
    run.deferred.push_back(std::move(deferred));
    run.blockers.push_back(std::move(coarser.blockers));
    run.mesh = std::move(coarser.triangles);
    run.refined = std::move(coarser.refined);
    run.changed = std::move(coarser.changed);
    return true;
}

size_t base_size(const SearchRun& run, size_t leaf_triangles) {
    return run.levels.empty() ? leaf_triangles : run.levels.back().triangles_left;
}

// The first `count` levels of `run` (leaf triangles `triangles`), the later ones dropped, with
// the mesh and flags they leave made again from the leaf.
SearchRun first_levels(const SearchRun& run, const std::vector<Triangle>& triangles, uint32_t vertex_count,
                       size_t count) {
    SearchRun out;
    out.levels.assign(run.levels.begin(), run.levels.begin() + std::ptrdiff_t(count));
    out.made_refined.assign(run.made_refined.begin(), run.made_refined.begin() + std::ptrdiff_t(count));
    out.deferred.assign(run.deferred.begin(), run.deferred.begin() + std::ptrdiff_t(count));
    out.blockers.assign(run.blockers.begin(), run.blockers.begin() + std::ptrdiff_t(count));
    if (count == 0) return out;
    std::vector<uint8_t> removed(vertex_count, 0);
    std::vector<uint32_t> kept_from;
    std::vector<Triangle> mesh = triangles;
    std::vector<uint8_t> refined(triangles.size(), 0);
    for (size_t s = 0; s < count; ++s) {
        mesh = detail::mesh_after_level(mesh, out.levels[s], removed, &kept_from);
        std::vector<uint8_t> next = out.made_refined[s];
        next.reserve(mesh.size());
        for (uint32_t from : kept_from) next.push_back(refined[from]);
        refined = std::move(next);
    }
    out.changed.assign(mesh.size(), 0);
    std::fill(out.changed.begin(), out.changed.begin() + std::ptrdiff_t(out.levels[count - 1].made.size()), 1);
    for (uint32_t i : out.deferred[count - 1]) out.changed[i] = 1;
    out.mesh = std::move(mesh);
    out.refined = std::move(refined);
    return out;
}

// Whether a search that left `base` of the `leaf` triangles undid at least 1/10 of them: an
// adaptive mesh, where an irregular one reads a few small patches only.
bool undid_much(size_t base, size_t leaf) {
    constexpr size_t kReadMuch = 10;  // base <= leaf * 9 / 10
    return base * kReadMuch <= leaf * (kReadMuch - 1);
}

// Called after each step a search undid.
using StepObserver = std::function<void(const SearchRun&)>;

// More levels undone at the end of `run`; in step s the vertices marked in kept[s] (if any) stay.
void undo_more_levels(const std::vector<Triangle>& triangles, uint32_t vertex_count,
                      const std::vector<std::vector<uint8_t>>& kept, const Cancel& cancel, const StepObserver& observe,
                      SearchRun& run) {
    // Each level undone adds one to the depth of the hierarchy, which kMaxLevel caps.
    while (run.levels.size() < size_t(kMaxLevel) && !cancel && undo_one_level(triangles, vertex_count, kept, false, run, &cancel)) {
        if (observe) observe(run);
    }
}

// Where the search stopped after undoing much of an adaptive mesh: a step seeded on the whole
// mesh and, if it undoes something, the steps after it, a few rounds. A step seeds only where
// the last one changed the mesh, and its failing growths mark the true blocks they pass as
// explored; a fresh step seeded everywhere reads the valid patches left so (docs/IMPORT.md,
// "Seeded everywhere once stopped"). It only adds levels: the base found is never finer.
void seed_everywhere_once_stopped(const std::vector<Triangle>& triangles, uint32_t vertex_count, SearchRun& run) {
    if (!undid_much(base_size(run, triangles.size()), triangles.size())) return;
    constexpr int kRounds = 8;
    for (int round = 0; round < kRounds && run.levels.size() + 1 < size_t(kMaxLevel); ++round) {
        if (!undo_one_level(triangles, vertex_count, {}, true, run)) break;
        while (run.levels.size() < size_t(kMaxLevel) && undo_one_level(triangles, vertex_count, {}, false, run)) {
        }
    }
}

std::array<uint32_t, 3> vertex_set(uint32_t a, uint32_t b, uint32_t c) {
    std::array<uint32_t, 3> key{a, b, c};
    std::sort(key.begin(), key.end());
    return key;
}

// The earliest step of `run` with a one-block patch (a split sharing no midpoint with the
// step's other splits) whose parent a later step reported as a blocker, and in `kept` (per step,
// empty or per vertex) the vertices that leave that step's such patches out: their midpoints,
// kept from that step until the one that reported them (which needed the parent unrefined there,
// most likely because they are hanging nodes of its patch). Returns false when there is none.
bool wrong_single_blocks(const SearchRun& run, uint32_t vertex_count, size_t& step,
                         std::vector<std::vector<uint8_t>>& kept) {
    size_t reports = 0;
    for (const auto& blockers : run.blockers) reports += blockers.size();
    if (reports == 0) return false;
    // Per parent (vertex set): the step and index of its split when that split is a one-block patch.
    std::map<std::array<uint32_t, 3>, std::pair<size_t, size_t>> single;
    std::vector<uint8_t> midpoint_uses(vertex_count, 0);
    for (size_t s = 0; s < run.levels.size(); ++s) {
        const auto& splits = run.levels[s].splits;
        for (const auto& split : splits) {
            for (int k = 3; k < 6; ++k) midpoint_uses[split[size_t(k)]] = uint8_t(std::min(2, midpoint_uses[split[size_t(k)]] + 1));
        }
        for (size_t i = 0; i < splits.size(); ++i) {
            const auto& split = splits[i];
            if (midpoint_uses[split[3]] == 1 && midpoint_uses[split[4]] == 1 && midpoint_uses[split[5]] == 1)
                single[vertex_set(split[0], split[1], split[2])] = {s, i};
        }
        for (const auto& split : splits) {
            for (int k = 3; k < 6; ++k) midpoint_uses[split[size_t(k)]] = 0;
        }
    }
    // (step of the split, its index, step of the report)
    std::vector<std::array<size_t, 3>> found;
    for (size_t k = 0; k < run.blockers.size(); ++k) {
        for (const Triangle& t : run.blockers[k]) {
            const auto it = single.find(vertex_set(t[0], t[1], t[2]));
            if (it != single.end() && it->second.first < k) found.push_back({it->second.first, it->second.second, k});
        }
    }
    if (found.empty()) return false;
    step = (*std::min_element(found.begin(), found.end()))[0];
    for (const auto& [s, i, k] : found) {
        if (s != step) continue;
        for (size_t j = s; j < k; ++j) {
            if (kept.size() <= j) kept.resize(j + 1);
            if (kept[j].empty()) kept[j].assign(vertex_count, 0);
            for (int m = 3; m < 6; ++m) kept[j][run.levels[s].splits[i][size_t(m)]] = 1;
        }
    }
    return true;
}

// The levels undone from the leaf mesh `triangles` (search ids), with the rerun of "One-block
// patches taken back".
SearchRun search_levels(const std::vector<Triangle>& triangles, uint32_t vertex_count, const Cancel& cancel,
                        const StepObserver& observe = {}) {
    SearchRun run;
    undo_more_levels(triangles, vertex_count, {}, cancel, observe, run);
    // A one-block patch can be a wrong reading that its step cannot tell from a true one; a later
    // step then finds its parent in the way of a large patch. Such patches are left out and the
    // search run again from their step, once; the run that ends at the coarser base stands
    // (docs/IMPORT.md, "One-block patches taken back").
    size_t step = 0;
    std::vector<std::vector<uint8_t>> kept;
    if (!cancel && wrong_single_blocks(run, vertex_count, step, kept)) {
        SearchRun trial = first_levels(run, triangles, vertex_count, step);
        undo_more_levels(triangles, vertex_count, kept, cancel, {}, trial);
        if (base_size(trial, triangles.size()) < base_size(run, triangles.size())) run = std::move(trial);
    }
    return run;
}

// When the reverse search may run beside the first: once the first has undone much of the mesh in
// steps that each leave more than half of it, so that it will most likely be searched again (an
// irregular mesh, where the first undoes little, and a uniform refinement, whose steps leave a
// quarter, get their second search only once the first has ended needing it); cancelled, within
// its step, once the first has ended not needing it.
class SecondSearchGate {
public:
    void open_if(bool likely_needed) {
        if (!likely_needed) return;
        std::lock_guard<std::mutex> lock(mutex_);
        open_ = true;
        opened_.notify_all();
    }
    void first_ended(bool needed) {
        std::lock_guard<std::mutex> lock(mutex_);
        cancelled_ = !needed;
        open_ = true;
        opened_.notify_all();
    }
    // Blocks until the search may start; false when it is not needed.
    bool wait() {
        std::unique_lock<std::mutex> lock(mutex_);
        opened_.wait(lock, [this] { return open_; });
        return !cancelled_;
    }
    const Cancel& cancelled() const { return cancelled_; }

private:
    std::mutex mutex_;
    std::condition_variable opened_;
    bool open_ = false;
    Cancel cancelled_{false};
};

}  // namespace

namespace detail {

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

DetectedLevel detected_level(CoarserLevel& coarser) {
    const size_t made = size_t(coarser.red_blocks) + coarser.green_groups;
    DetectedLevel level;
    level.splits = std::move(coarser.splits);
    level.closures = coarser.green_groups;
    level.made.assign(coarser.triangles.begin(), coarser.triangles.begin() + std::ptrdiff_t(made));
    level.triangles_left = coarser.triangles.size();
    return level;
}

std::vector<Triangle> mesh_after_level(const std::vector<Triangle>& mesh, const DetectedLevel& level,
                                       std::vector<uint8_t>& removed, std::vector<uint32_t>* kept_from) {
    for (const auto& split : level.splits) {
        for (size_t k = 3; k < 6; ++k) removed[split[k]] = 1;
    }
    std::vector<Triangle> out;
    out.reserve(level.made.size() + mesh.size());
    out.insert(out.end(), level.made.begin(), level.made.end());
    if (kept_from) kept_from->clear();
    for (uint32_t t = 0; t < mesh.size(); ++t) {
        const Triangle& triangle = mesh[t];
        if (removed[triangle[0]] | removed[triangle[1]] | removed[triangle[2]]) continue;
        out.push_back(triangle);
        if (kept_from) kept_from->push_back(t);
    }
    for (const auto& split : level.splits) {
        for (size_t k = 3; k < 6; ++k) removed[split[k]] = 0;
    }
    return out;
}

}  // namespace detail

bool searched_again(size_t base, size_t leaf, size_t levels) {
    constexpr size_t kFarFromBase = 16;  // base > leaf / 16
    return base * kFarFromBase > leaf && (undid_much(base, leaf) || levels == 0);
}

DetectedBase detect_base(const TriangleMesh& mesh, const std::string& what, unsigned threads) {
    validate_triangle_mesh(mesh, what);
    const uint32_t vertex_count = uint32_t(mesh.positions.size());
    DetectedBase out;
    // The search runs on its own vertex numbering (breadth_first_vertices); the levels it found
    // are given back in input ids.
    const std::vector<uint32_t> input_of = detail::breadth_first_vertices(mesh.triangles, vertex_count);
    std::vector<uint32_t> search_of(vertex_count);
    for (uint32_t v = 0; v < vertex_count; ++v) search_of[input_of[v]] = v;
    std::vector<Triangle> renumbered = mesh.triangles;
    detail::renumber(renumbered, search_of);
    // The search takes the triangles' order wherever two readings tie, and in some orders a few
    // wrong early readings keep it far from the base: such a search is run again over the
    // triangles in reverse order, and the coarser base stands (docs/IMPORT.md, "Searched twice").
    // With a second thread the reverse search runs beside the first (SecondSearchGate); on one
    // thread it runs after it, when needed. Either way the answer is the same.
    SearchRun run, other;
    bool again = false;
    SecondSearchGate gate;
    const Cancel never{false};
    parallel_for(2, resolve_thread_count(threads), [&](size_t task) {
        if (task == 0) {
            try {
                run = search_levels(renumbered, vertex_count, never, [&](const SearchRun& so_far) {
                    const size_t steps = so_far.levels.size();
                    const size_t before = steps < 2 ? renumbered.size() : so_far.levels[steps - 2].triangles_left;
                    const size_t after = so_far.levels.back().triangles_left;
                    gate.open_if(undid_much(after, renumbered.size()) && 2 * after > before);
                });
            } catch (...) {
                gate.first_ended(false);  // the other task must not wait for ever
                throw;
            }
            again = searched_again(base_size(run, renumbered.size()), renumbered.size(), run.levels.size());
            gate.first_ended(again);
        } else {
            if (!gate.wait()) return;
            const std::vector<Triangle> reversed(renumbered.rbegin(), renumbered.rend());
            other = search_levels(reversed, vertex_count, gate.cancelled());
        }
    });
    if (again && base_size(other, renumbered.size()) < base_size(run, renumbered.size())) {
        run = std::move(other);
        out.found_in_reverse = true;
    }
    seed_everywhere_once_stopped(renumbered, vertex_count, run);
    out.levels = std::move(run.levels);
    for (DetectedLevel& level : out.levels) {
        detail::renumber(level.made, input_of);
        for (auto& split : level.splits) {
            for (uint32_t& v : split) v = input_of[v];
        }
    }
    detail::renumber(run.mesh, input_of);
    set_base(mesh, out.levels.empty() ? mesh.triangles : run.mesh, out);
    return out;
}

std::vector<Triangle> mesh_after(const std::vector<Triangle>& leaf, const std::vector<DetectedLevel>& levels,
                                 size_t count, uint32_t vertex_count) {
    std::vector<uint8_t> removed(vertex_count, 0);
    std::vector<Triangle> mesh = leaf;
    for (size_t s = 0; s < std::min(count, levels.size()); ++s) mesh = detail::mesh_after_level(mesh, levels[s], removed);
    return mesh;
}

DetectedBase truncated(const TriangleMesh& mesh, DetectedBase detected, size_t levels) {
    if (levels >= detected.levels.size()) return detected;
    detected.levels.resize(levels);
    if (levels == 0) {
        set_base(mesh, mesh.triangles, detected);
    } else {
        const std::vector<Triangle> leaf = detected.found_in_reverse
                                               ? std::vector<Triangle>(mesh.triangles.rbegin(), mesh.triangles.rend())
                                               : mesh.triangles;
        set_base(mesh, mesh_after(leaf, detected.levels, levels, uint32_t(mesh.positions.size())), detected);
    }
    return detected;
}

}  // namespace amc
