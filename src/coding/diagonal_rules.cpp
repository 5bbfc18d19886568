// Diagonal rules of two-hanging-node closures (paper, section II-B: the orientation bit) and the
// context-group naming shared by the coder and its statistics.
#include "coding/context_groups.h"

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

uint64_t fewest_diagonal_exceptions(const Hierarchy& h, uint64_t& two_hanging) {
    uint64_t exceptions[kDiagonalRuleCount] = {};
    two_hanging = 0;
    for (NodeId n : h.leaves()) {
        if (h.hanging_node_count(n) != 2) continue;
        ++two_hanging;
        const int u = !h.has_hanging_node(n, 0) ? 0 : !h.has_hanging_node(n, 1) ? 1 : 2;
        for (int r = 0; r < kDiagonalRuleCount; ++r)
            exceptions[r] += diagonal_flag_by_rule(DiagonalRule(r), u) != h.diagonal_flipped(n);
    }
    uint64_t fewest = exceptions[0];
    for (uint64_t e : exceptions) fewest = e < fewest ? e : fewest;
    return fewest;
}

int context_group_index(int refined, int unrefined, int unknown) {
    if (refined < 0 || unrefined < 0 || unknown < 0 || refined + unrefined + unknown != 3) return -1;
    return context_group_of(refined, unrefined);
}

}  // namespace amc
