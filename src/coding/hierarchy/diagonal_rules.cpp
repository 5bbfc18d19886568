// Diagonal rules of two-hanging-node closures (paper, section II-B: the orientation bit) and the
// context-group naming shared by the coder and its statistics.
#include "coding/hierarchy/context_groups.h"
#include "coding/hierarchy/hierarchy_level_coder.h"

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

template <class RotationOf>
DiagonalExceptions tally_exceptions(const Hierarchy& h, RotationOf rotation_of) {
    DiagonalExceptions tally;
    for (NodeId n = 0; n < h.node_capacity(); ++n) {
        if (!h.is_alive(n) || !h.is_leaf(n) || h.hanging_node_count(n) != 2) continue;
        const int unrefined = !h.has_hanging_node(n, 0) ? 0 : !h.has_hanging_node(n, 1) ? 1 : 2;
        tally.add((unrefined + 3 - rotation_of(n)) % 3, h.diagonal_flipped(n));
    }
    return tally;
}

}  // namespace

DiagonalExceptions diagonal_exceptions(const Hierarchy& h) {
    return tally_exceptions(h, [](NodeId) { return 0; });
}

DiagonalExceptions diagonal_exceptions(const Hierarchy& h, const std::vector<uint8_t>& root_rotation) {
    return tally_exceptions(h, [&](NodeId n) {
        while (n >= h.root_count()) n = h.parent(n);
        return int(root_rotation[n]);
    });
}

int context_group_index(int refined, int unrefined, int unknown) {
    if (refined < 0 || unrefined < 0 || unknown < 0 || refined + unrefined + unknown != 3) return -1;
    return context_group_of(refined, unrefined);
}

}  // namespace amc
