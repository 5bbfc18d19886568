#include "import/undo_steps.h"

#include "common/no_index.h"

#include <algorithm>

namespace amc {

namespace {

// How far the shortest paths are followed: a chain along a coarse edge of the remaining mesh is
// a few hops long, and the bound keeps a comparison's cost constant.
constexpr int kMaxHops = 24;

}  // namespace

UndoStepChoice::UndoStepChoice(const UndoSteps& steps) : steps_(steps) {
    const size_t vertex_count = steps.step.size();
    first_neighbor_.assign(vertex_count + 1, 0);
    for (const Triangle& t : steps.remaining) {
        for (int k = 0; k < 3; ++k) first_neighbor_[t[k] + 1] += 2;
    }
    for (size_t v = 0; v < vertex_count; ++v) first_neighbor_[v + 1] += first_neighbor_[v];
    neighbors_.resize(first_neighbor_.back());
    std::vector<uint32_t> next(first_neighbor_.begin(), first_neighbor_.end() - 1);
    for (const Triangle& t : steps.remaining) {
        for (int k = 0; k < 3; ++k) {
            neighbors_[next[t[k]]++] = t[(k + 1) % 3];
            neighbors_[next[t[k]]++] = t[(k + 2) % 3];
        }
    }
    // Each neighbour once (two faces list most of them): a search then looks each up once.
    uint32_t kept = 0;
    for (size_t v = 0; v < vertex_count; ++v) {
        const auto begin = neighbors_.begin() + first_neighbor_[v], end = neighbors_.begin() + first_neighbor_[v + 1];
        std::sort(begin, end);
        const uint32_t count = uint32_t(std::unique(begin, end) - begin);
        first_neighbor_[v] = kept;
        std::copy(begin, begin + count, neighbors_.begin() + kept);
        kept += count;
    }
    first_neighbor_[vertex_count] = kept;
    neighbors_.resize(kept);
    hops_from_a_.assign(vertex_count, -1);
    hops_from_b_.assign(vertex_count, -1);
}

// Breadth-first over the remaining mesh from `source`, through unmatched vertices only, until
// both `targets` have their hop counts (breadth-first order makes them final when set).
void UndoStepChoice::measure_from(uint32_t source, const uint32_t targets[2], std::vector<int>& hops,
                                  const std::vector<uint32_t>& vertex_of_leaf) {
    queue_.assign(1, source);
    hops[source] = 0;
    reached_.push_back(source);
    for (size_t i = 0; i < queue_.size(); ++i) {
        if (hops[targets[0]] >= 0 && hops[targets[1]] >= 0) return;
        const uint32_t u = queue_[i];
        ++walked_;
        if (hops[u] == kMaxHops || (u != source && vertex_of_leaf[u] != kNoIndex)) continue;
        walked_ += first_neighbor_[u + 1] - first_neighbor_[u];
        for (uint32_t j = first_neighbor_[u]; j < first_neighbor_[u + 1]; ++j) {
            const uint32_t x = neighbors_[j];
            if (hops[x] >= 0) continue;
            hops[x] = hops[u] + 1;
            reached_.push_back(x);
            queue_.push_back(x);
        }
    }
}

uint32_t UndoStepChoice::choose(const uint32_t* candidates, uint32_t count, uint32_t a, uint32_t b,
                                const std::vector<uint32_t>& vertex_of_leaf) {
    // A true split is undone only after every vertex inside the two elements on its edge, so the
    // midpoint outlasts the finer vertices around it, which are what a wrong pick takes.
    uint32_t found = kNoIndex;
    uint32_t never[2];
    uint32_t never_count = 0;
    for (uint32_t i = 0; i < count; ++i) {
        const uint32_t c = candidates[i];
        if (found == kNoIndex || steps_.step[c] > steps_.step[found]) found = c;
        if (steps_.step[c] == kNeverUndone && never_count < 2) never[never_count++] = c;
    }
    if (never_count < 2) return found;
    // Where the steps stopped, the midpoint lies on the chain of edges from a to b, which in the
    // remaining mesh is (nearly always) a shortest path between them: the candidate with the
    // smaller detour d(a, c) + d(c, b) - d(a, b) wins, the nearer on a tie. d(a, b) is common to
    // both, so only the two candidates' distances are needed.
    measure_from(a, never, hops_from_a_, vertex_of_leaf);
    auto path_length = [&](uint32_t c) {
        return hops_from_a_[c] < 0 || hops_from_b_[c] < 0 ? 1 << 21 : hops_from_a_[c] + hops_from_b_[c];
    };
    // The second wins only with a path, and then against a first without one whatever its length:
    // b's search is needed only for the candidates a reaches (a search that does not reach its
    // targets looks at its whole ball).
    if (hops_from_a_[never[1]] < 0) {
        found = never[0];
    } else {
        const uint32_t wanted[2] = {hops_from_a_[never[0]] < 0 ? never[1] : never[0], never[1]};
        measure_from(b, wanted, hops_from_b_, vertex_of_leaf);
        found = path_length(never[1]) < path_length(never[0]) ? never[1] : never[0];
    }
    for (uint32_t x : reached_) hops_from_a_[x] = hops_from_b_[x] = -1;
    reached_.clear();
    return found;
}

}  // namespace amc
