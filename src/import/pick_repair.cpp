// Guided picks taken back when the next level contradicts them (docs/IMPORT.md, "The children
// repair the picks"): a child whose reading misfits blames the guided picks among the corners
// involved, and the candidate (or the swap with another pick) that leaves fewest misfits wins.
#include "import/reconstruction.h"

#include <algorithm>
#include <utility>
#include <vector>

namespace amc {

void Reconstruction::note_guided(VertexId m, NodeId n, int e) {
    if (guided_of_vertex_.size() <= m) {
        guided_of_vertex_.reserve(leaf_.positions.size());  // as leaf_of_vertex_
        guided_of_vertex_.resize(h_.positions().size(), kNoIndex);
    }
    guided_of_vertex_[m] = uint32_t(guided_.size());
    guided_.push_back({n, e});
}

bool Reconstruction::fits(NodeId x, std::vector<VertexId>* suspects) const {
    auto blame = [&](NodeId y) {
        for (int i = 0; suspects && y != kNoNode && i < 3; ++i) {
            if (guided(h_.vertex(y, i))) suspects->push_back(h_.vertex(y, i));
        }
    };
    auto refined = [&](NodeId y) {
        uint32_t p[3];
        return y != kNoNode && known_corners(y, p) && read(p).refined();
    };
    uint32_t p[3];
    if (!known_corners(x, p)) return true;
    const Reading r = read(p);
    // A refined node needs a same-level neighbour across every inner edge (2:1 balance).
    bool ok = r.fault == Reading::none && !(r.refined() && !h_.has_all_neighbors(x));
    for (int e = 0; ok && e < 3; ++e) {
        if (r.unsplit[e] && refined(h_.neighbor(x, e))) {  // a T-junction
            blame(h_.neighbor(x, e));
            ok = false;
        }
    }
    for (int i = 0; ok && i < r.reveal_count; ++i) {
        const NodeId y = h_.neighbor(x, r.reveal_edge[i]);
        const uint32_t owner = vertex_of_leaf_[r.reveal_vertex[i]];
        if (!refined(y)) {
            blame(y);
            ok = false;
        } else if (owner != kNoIndex) {  // the hanging node is taken already
            if (suspects && guided(owner)) suspects->push_back(owner);
            ok = false;
        }
    }
    if (!ok) blame(x);
    return ok;
}

void Reconstruction::repair_picks() {
    if (guided_.empty()) return;
    // The children a guided pick can make misfit: around it (a taken hanging node is
    // revealed by a neighbour of the element that took it). Marked in a bitmap and listed in id
    // order, each once: what sorting the list did (the passes depend on the order) without its
    // n log n, which was a twentieth of a 10^6-face import.
    std::vector<uint64_t> marked((size_t(h_.node_capacity()) + 63) / 64, 0);
    auto mark = [&](NodeId x) { marked[x >> 6] |= uint64_t(1) << (x & 63); };
    for (const GuidedSlot& s : guided_) {
        for (NodeId parent : {s.node, h_.neighbor(s.node, s.edge)}) {
            for (int k = 0; parent != kNoNode && !h_.is_leaf(parent) && k < 4; ++k) {
                mark(h_.child(parent, k));
                for (int e = 0; e < 3; ++e) {
                    if (h_.neighbor(h_.child(parent, k), e) != kNoNode) mark(h_.neighbor(h_.child(parent, k), e));
                }
            }
        }
    }
    std::vector<NodeId> children;
    for (size_t w = 0; w < marked.size(); ++w) {
        for (uint64_t bits = marked[w]; bits != 0; bits &= bits - 1)
            children.push_back(NodeId(w * 64 + size_t(__builtin_ctzll(bits))));
    }
    for (int pass = 0; pass < kRepairPasses; ++pass) {
        bool changed = false;
        for (NodeId x : children) {
            suspects_.clear();
            if (fits(x, &suspects_)) continue;
            // Of the suspects' best moves, the one that removes the most misfits.
            Move best;
            for (size_t i = 0; i < suspects_.size(); ++i) {
                const VertexId v = suspects_[i];
                if (std::find(suspects_.begin(), suspects_.begin() + long(i), v) != suspects_.begin() + long(i))
                    continue;  // tried already
                const Move move = best_move(v, x);
                if (move.gain > best.gain) best = move;
            }
            if (best.gain > 0) {
                make(best);
                changed = true;
            }
        }
        if (!changed) break;
    }
}

void Reconstruction::guided_clear() {
    for (const GuidedSlot& s : guided_) guided_of_vertex_[h_.midpoint(s.node, s.edge)] = kNoIndex;
    guided_.clear();
}

// The referee's answers for the repaired picks, applied together (one may free another's).
bool Reconstruction::referee_after_repair() {
    std::vector<std::pair<VertexId, uint32_t>> changes;
    for (const GuidedSlot& s : guided_) {
        const VertexId m = h_.midpoint(s.node, s.edge);
        const uint32_t picked = leaf_of_vertex_[m];
        const uint32_t a = corner(s.node, s.edge), b = corner(s.node, (s.edge + 1) % 3);
        const uint32_t answer = (*referee_)(GuidedPick{h_.level(s.node), a, b, picked, nullptr, 0, true});
        if (answer != picked) changes.emplace_back(m, answer);
    }
    for (const auto& change : changes) unassign(change.first);
    for (const auto& change : changes) {
        if (vertex_of_leaf_[change.second] == kNoIndex) assign(change.first, change.second);
    }
    for (const auto& change : changes) {
        if (leaf_of_vertex_[change.first] == kNoIndex) fail("the referee's vertex is taken");
    }
    return !changes.empty();
}

void Reconstruction::add_around(VertexId v) {
    const GuidedSlot s = guided_[guided_of_vertex_[v]];
    for (NodeId parent : {s.node, h_.neighbor(s.node, s.edge)}) {
        if (parent == kNoNode || h_.is_leaf(parent)) continue;
        for (int k = 0; k < 4; ++k) {
            add_once(around_, h_.child(parent, k));
            for (int e = 0; e < 3; ++e) add_once(around_, h_.neighbor(h_.child(parent, k), e));
        }
    }
}

void Reconstruction::make(const Move& m) {
    const VertexId other = vertex_of_leaf_[m.to];
    unassign(m.v);
    if (other != kNoIndex) unassign(other);
    assign(m.v, m.to);
    if (other != kNoIndex) assign(other, m.from);
}

Reconstruction::Move Reconstruction::best_move(VertexId v, NodeId misfit) {
    const GuidedSlot s = guided_[guided_of_vertex_[v]];
    const uint32_t original = leaf_of_vertex_[v];
    uint32_t candidates[kRepairCandidates];
    unassign(v);
    const uint32_t found = nearest_usable(
        guide_position(s.node, s.edge), MidpointTest(*this, s.node, s.edge, true), kRepairCandidates, candidates,
        pick_search_limit(corner(s.node, s.edge), corner(s.node, (s.edge + 1) % 3)));
    assign(v, original);
    auto misfits = [&] {
        int m = 0;
        for (NodeId y : around_) m += !fits(y, nullptr);
        return m;
    };
    Move best;
    for (uint32_t i = 0; i < found; ++i) {
        const uint32_t c = candidates[i];
        if (c == original) continue;
        const VertexId other = vertex_of_leaf_[c];
        around_.clear();
        add_around(v);
        if (other != kNoIndex) add_around(other);
        add_once(around_, misfit);
        const int before = misfits();
        const Move move{v, original, c, 0};
        make(move);
        const int gain = before - misfits();
        take_back(move);
        if (gain > best.gain) best = Move{v, original, c, gain};
    }
    return best;
}

}  // namespace amc
