// Diagonal rules of two-hanging-node closures (paper, section II-B: the orientation bit) and the
// context-group naming shared by the coder and its statistics.
#include "coding/hierarchy/context_groups.h"
#include "coding/hierarchy/hierarchy_level_coder.h"
#include "common/parallel.h"

#include <algorithm>
#include <array>
#include <vector>

namespace amc {

bool diagonal_flag_by_rule(DiagonalRule rule, int unrefined_edge) {
    const int next = (unrefined_edge + 1) % 3, previous = (unrefined_edge + 2) % 3;
    int refined_edge = next;  // the default: Hierarchy's flag 0 means r = u+1
    switch (rule) {
        case DiagonalRule::next_after_unrefined: refined_edge = next; break;
        case DiagonalRule::previous_before_unrefined: refined_edge = previous; break;
        case DiagonalRule::lower_local_index: refined_edge = next < previous ? next : previous; break;
        case DiagonalRule::higher_local_index: refined_edge = next > previous ? next : previous; break;
    }
    return refined_edge != next;
}

void DiagonalExceptions::add(int unrefined_edge, bool flipped) {
    ++leaves;
    for (int r = 0; r < kDiagonalRuleCount; ++r) by_rule[r] += diagonal_flag_by_rule(DiagonalRule(r), unrefined_edge) != flipped;
}

DiagonalRule DiagonalExceptions::best() const {
    int best = 0;
    for (int r = 1; r < kDiagonalRuleCount; ++r) best = by_rule[r] < by_rule[best] ? r : best;
    return DiagonalRule(best);
}

namespace {

// Leaves closed by two hanging nodes, by unrefined edge (after the rotation) and diagonal flag,
// counted over node ranges on `threads` threads; the rules' exceptions follow from the six counts.
template <class RotationOf>
DiagonalExceptions tally_exceptions(const Hierarchy& h, RotationOf rotation_of, unsigned threads) {
    constexpr NodeId kRange = NodeId(1) << 16;  // nodes per task
    const size_t ranges = (size_t(h.node_capacity()) + kRange - 1) / kRange;
    std::vector<std::array<uint64_t, 6>> counts(ranges, std::array<uint64_t, 6>{});
    parallel_for(ranges, threads, [&](size_t i) {
        std::array<uint64_t, 6> count{};  // [2 * unrefined edge + flipped]
        const NodeId end = std::min<NodeId>(h.node_capacity(), NodeId(i + 1) * kRange);
        for (NodeId n = NodeId(i) * kRange; n < end; ++n) {
            if (!h.is_alive(n) || !h.is_leaf(n) || h.hanging_node_count(n) != 2) continue;
            const int unrefined = !h.has_hanging_node(n, 0) ? 0 : !h.has_hanging_node(n, 1) ? 1 : 2;
            ++count[size_t(2 * ((unrefined + 3 - rotation_of(n)) % 3) + int(h.diagonal_flipped(n)))];
        }
        counts[i] = count;
    });
    DiagonalExceptions tally;
    for (const auto& count : counts)
        for (int k = 0; k < 6; ++k) {
            tally.leaves += count[size_t(k)];
            for (int r = 0; r < kDiagonalRuleCount; ++r)
                tally.by_rule[r] += diagonal_flag_by_rule(DiagonalRule(r), k / 2) != bool(k % 2) ? count[size_t(k)] : 0;
        }
    return tally;
}

}  // namespace

DiagonalExceptions diagonal_exceptions(const Hierarchy& h, unsigned threads) {
    return tally_exceptions(h, [](NodeId) { return 0; }, threads);
}

DiagonalExceptions diagonal_exceptions(const Hierarchy& h, const std::vector<uint8_t>& root_rotation, unsigned threads) {
    return tally_exceptions(
        h,
        [&](NodeId n) {
            while (n >= h.root_count()) n = h.parent(n);
            return int(root_rotation[n]);
        },
        threads);
}

int context_group_index(int refined, int unrefined, int unknown) {
    if (refined < 0 || unrefined < 0 || unknown < 0 || refined + unrefined + unknown != 3) return -1;
    return context_group_of(refined, unrefined);
}

}  // namespace amc
