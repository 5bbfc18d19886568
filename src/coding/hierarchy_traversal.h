// The level-wise traversal shared by the hierarchy encoder and decoder (paper, II-B, II-C, II-E).
//
// Within a level every node is decided exactly once: either a rule implies its state (culled:
// 1-regularity, hanging nodes, uniform levels) or one symbol is coded in the node's context group.
// The encoder answers `code` from the hierarchy it holds; the decoder from the stream, splitting
// nodes as it goes. Both see the same decisions in the same order, so they agree on every context.
#pragma once

#include "coding/context_groups.h"

#include <amc/hierarchy.h>
#include <amc/hierarchy_coder.h>

#include <array>
#include <vector>

namespace amc {

enum class Fate : uint8_t { coded, uniform, one_regularity, hanging_nodes };

class LevelTraversal {
public:
    explicit LevelTraversal(const HierarchyCoderOptions& options) : options_(options) {}

    // Decides every node of `level_nodes` (one level, canonical order).
    //   code(NodeId n, int context_group) -> bool   the node's symbol (coded by the caller)
    //   force(NodeId n, Fate fate, bool refined)    a decision implied by a rule
    // After a call returns true / refined, h.is_leaf(n) must be false (the decoder splits).
    template <class Code, class Force>
    void run(const Hierarchy& h, const std::vector<NodeId>& level_nodes, bool uniform_level, Code&& code,
             Force&& force) {
        if (processed_.size() < h.node_capacity()) {
            processed_.resize(h.node_capacity());
            priority_.resize(h.node_capacity());
        }
        for (NodeId n : level_nodes) processed_[n] = 0;
        if (uniform_level) {
            for (NodeId n : level_nodes) force(n, Fate::uniform, true);
            return;
        }
        if (options_.traversal == Traversal::naive) {
            for (NodeId n : level_nodes) decide(h, n, code, force);
            return;
        }
        // Improved traversal: a bucket queue over priorities 0 (culled: nothing to code) to 4 (no
        // neighbour coded yet); each coded neighbour lowers a node's priority by one. Stale queue
        // entries are skipped, so every node enters the queue at most four times: linear time.
        for (auto& bucket : buckets_) bucket.clear();
        for (auto it = level_nodes.rbegin(); it != level_nodes.rend(); ++it) {
            const NodeId n = *it;
            priority_[n] = fate_of(h, n) != Fate::coded ? 0 : 4;
            buckets_[priority_[n]].push_back(n);
        }
        int current = 0;
        for (;;) {
            while (current < 5 && buckets_[current].empty()) ++current;
            if (current == 5) break;
            const NodeId n = buckets_[current].back();
            buckets_[current].pop_back();
            if (processed_[n] || priority_[n] != current) continue;
            decide(h, n, code, force);
            for (int e = 0; e < 3; ++e) {
                const NodeId q = h.neighbor(n, e);
                if (q == kNoNode || processed_[q] || priority_[q] == 0) continue;
                const uint8_t next = fate_of(h, q) != Fate::coded ? 0 : uint8_t(priority_[q] > 1 ? priority_[q] - 1 : 1);
                if (next != priority_[q]) {
                    priority_[q] = next;
                    buckets_[next].push_back(q);
                    if (next < current) current = next;
                }
            }
        }
    }

private:
    bool known_refined(const Hierarchy& h, NodeId q) const { return processed_[q] && !h.is_leaf(q); }

    // The rule that decides n given what is known now, or Fate::coded.
    Fate fate_of(const Hierarchy& h, NodeId n) const {
        if (options_.cull_one_regularity && !h.has_all_neighbors(n)) return Fate::one_regularity;
        if (options_.cull_hanging_nodes) {
            int refined = 0;
            for (int e = 0; e < 3; ++e) {
                const NodeId q = h.neighbor(n, e);
                refined += q != kNoNode && known_refined(h, q);
            }
            if (refined == 3) return Fate::hanging_nodes;
        }
        return Fate::coded;
    }

    template <class Code, class Force>
    void decide(const Hierarchy& h, NodeId n, Code& code, Force& force) {
        const Fate fate = fate_of(h, n);
        if (fate == Fate::coded) {
            int refined = 0, unrefined = 0;
            for (int e = 0; e < 3; ++e) {
                const NodeId q = h.neighbor(n, e);
                if (q == kNoNode) {
                    ++unrefined;  // boundary, or a coarser region: see context_groups.h
                } else if (processed_[q]) {
                    h.is_leaf(q) ? ++unrefined : ++refined;
                }
            }
            code(n, context_group_of(refined, unrefined));
        } else {
            force(n, fate, fate == Fate::hanging_nodes);
        }
        processed_[n] = 1;
    }

    HierarchyCoderOptions options_;
    std::vector<uint8_t> processed_;
    std::vector<uint8_t> priority_;
    std::array<std::vector<NodeId>, 5> buckets_;
};

// Children of the refined nodes of one level, in canonical order: the next level.
inline void next_level(const Hierarchy& h, const std::vector<NodeId>& level_nodes, std::vector<NodeId>& next) {
    next.clear();
    for (NodeId n : level_nodes) {
        if (!h.is_leaf(n)) {
            for (int k = 0; k < 4; ++k) next.push_back(h.child(n, k));
        }
    }
}

// The unrefined edge of a leaf with exactly two hanging nodes.
inline int unrefined_edge(const Hierarchy& h, NodeId n) {
    return !h.has_hanging_node(n, 0) ? 0 : !h.has_hanging_node(n, 1) ? 1 : 2;
}

}  // namespace amc
