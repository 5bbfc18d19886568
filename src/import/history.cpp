// Refinement histories: "refine these elements / coarsen these" steps replayed on a hierarchy
// (docs/IMPORT.md, section 3).
#include <amc/import.h>

#include "common/check.h"
#include "common/no_index.h"

#include <algorithm>
#include <functional>
#include <string>
#include <vector>

namespace amc {

namespace {

// The element lists of one step checked against the current leaf mesh: indices in range, none
// listed twice, none listed for both.
void check_elements(const std::vector<uint32_t>& refine, const std::vector<uint32_t>& coarsen, size_t elements) {
    std::vector<uint8_t> listed(elements, 0);  // 1 refine, 2 coarsen
    auto mark = [&](uint32_t e, uint8_t how, const char* list) {
        AMC_REQUIRE(e < elements, invalid_input,
                    std::string(list) + " element " + std::to_string(e) + " is out of range (the mesh has " +
                        std::to_string(elements) + " elements)");
        AMC_REQUIRE(listed[e] != how, invalid_input,
                    std::string(list) + " element " + std::to_string(e) + " is listed twice");
        AMC_REQUIRE(listed[e] == 0, invalid_input,
                    "element " + std::to_string(e) + " is listed for both refinement and coarsening");
        listed[e] = how;
    };
    for (uint32_t e : refine) mark(e, 1, "refine");
    for (uint32_t e : coarsen) mark(e, 2, "coarsen");
}

}  // namespace

void apply_adaptation_step(Hierarchy& h, const std::vector<uint32_t>& refine, const std::vector<uint32_t>& coarsen) {
    const LeafMesh leaf = extract_leaf_mesh(h);
    check_elements(refine, coarsen, leaf.source.size());

    // A leaf all of whose elements are listed for coarsening is "marked"; a parent whose four
    // children are marked leaves is a candidate. Elements listed for refinement name their nodes.
    std::vector<uint32_t> listed_count(h.node_capacity(), 0), element_count(h.node_capacity(), 0);
    for (size_t e = 0; e < leaf.source.size(); ++e) ++element_count[leaf.source[e]];
    for (uint32_t e : coarsen) ++listed_count[leaf.source[e]];
    std::vector<NodeId> candidates;
    for (NodeId n : h.breadth_first_order()) {
        if (h.is_leaf(n)) continue;
        bool all = true;
        for (int k = 0; k < 4 && all; ++k) {
            const NodeId c = h.child(n, k);
            all = h.is_leaf(c) && listed_count[c] == element_count[c];
        }
        if (all) candidates.push_back(n);
    }
    for (uint32_t e : refine) {
        AMC_REQUIRE(h.level(leaf.source[e]) < kMaxLevel, limit_exceeded,
                    "refine element " + std::to_string(e) + " is at the deepest level (" + std::to_string(kMaxLevel) +
                        ")");
    }

    for (uint32_t e : refine) h.refine(leaf.source[e]);
    // Deepest first: a parent's children may be candidates themselves, whose coarsening only
    // helps. Within a level, coarsening a parent can let a neighbour follow (it leaves the
    // neighbour fewer refined neighbours), so a level is passed over in order until nothing
    // changes; a pass looks again only at the neighbours of what was coarsened since it last
    // looked (nothing else changes their answer), so a chain of candidates each freed only by the
    // next costs a step each, not a pass over the level each.
    std::stable_sort(candidates.begin(), candidates.end(),
                     [&h](NodeId a, NodeId b) { return h.level(a) > h.level(b); });
    std::vector<uint32_t> index_of(h.node_capacity(), kNoIndex);  // a candidate's index in `candidates`
    for (size_t i = 0; i < candidates.size(); ++i) index_of[candidates[i]] = uint32_t(i);
    std::vector<uint32_t> due(candidates.size(), 0);  // the pass that is to look at a candidate
    uint32_t pass = 1;
    const auto first_look = std::greater<uint32_t>();  // the passes' heaps give the lowest index first
    for (size_t begin = 0; begin < candidates.size();) {
        size_t end = begin;
        while (end < candidates.size() && h.level(candidates[end]) == h.level(candidates[begin])) ++end;
        std::vector<uint32_t> look, next;  // this pass's indices (a heap), the next pass's
        for (size_t i = begin; i < end; ++i) look.push_back(uint32_t(i)), due[i] = pass;
        while (!look.empty()) {
            while (!look.empty()) {
                std::pop_heap(look.begin(), look.end(), first_look);
                const uint32_t i = look.back();
                look.pop_back();
                const NodeId n = candidates[i];
                if (!h.coarsen(n)) continue;
                candidates[i] = kNoNode;
                for (int e = 0; e < 3; ++e) {  // the same-level neighbours it may free
                    const NodeId q = h.neighbor(n, e);
                    const uint32_t j = q == kNoNode ? kNoIndex : index_of[q];
                    if (j == kNoIndex || j < begin || j >= end || candidates[j] == kNoNode) continue;
                    if (j > i && due[j] != pass) {  // still ahead in this pass
                        due[j] = pass;
                        look.push_back(j);
                        std::push_heap(look.begin(), look.end(), first_look);
                    } else if (j < i && due[j] != pass + 1) {
                        due[j] = pass + 1;
                        next.push_back(j);
                    }
                }
            }
            ++pass;
            std::sort(next.begin(), next.end());  // ascending: a heap for first_look
            look.swap(next);
        }
        begin = end;
    }
}

std::vector<Hierarchy> replay_history(const RefinementHistory& history) {
    std::vector<Hierarchy> states;
    states.reserve(history.steps.size());
    Hierarchy h(history.base);
    for (size_t i = 0; i < history.steps.size(); ++i) {
        try {
            apply_adaptation_step(h, history.steps[i].refine, history.steps[i].coarsen);
        } catch (const Error& e) {
            const AdaptationStep& step = history.steps[i];
            throw e.prefixed(history.source + (step.line ? ":" + std::to_string(step.line) : std::string()) +
                             ": step " + std::to_string(i + 1));
        }
        states.push_back(h);
    }
    return states;
}

}  // namespace amc
