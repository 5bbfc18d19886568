// Inter-frame connectivity coder; see frame_connectivity.h and docs/FORMAT.md, section 7.5.
// Encoder and decoder run the same walk (code_forest), so they agree on every context.
#include "series/frame_connectivity.h"

#include "common/check.h"

#include <string>

namespace amc {

namespace {

constexpr uint8_t kDecided = 1, kRefined = 2, kChanged = 4;

// The previous frame's class of a node: 0 absent, 1 leaf, 2 refined with four leaf children,
// 3 refined with a refined child.
int previous_class(const Hierarchy& prev, NodeId p) {
    if (p == kNoNode) return 0;
    if (prev.is_leaf(p)) return 1;
    for (int k = 0; k < 4; ++k)
        if (!prev.is_leaf(prev.child(p, k))) return 3;
    return 2;
}

// The unrefined edge of a leaf with exactly two hanging nodes, or -1.
int two_hanging_unrefined_edge(const Hierarchy& h, NodeId n) {
    if (h.hanging_node_count(n) != 2) return -1;
    return !h.has_hanging_node(n, 0) ? 0 : !h.has_hanging_node(n, 1) ? 1 : 2;
}

struct DecodingIo {
    ArithmeticDecoder& coder;
    bool refined(NodeId, BitModel& model) { return coder.decode(model); }
    bool forced_refined(NodeId, bool implied) { return implied; }
    bool flipped(NodeId, BitModel& model) { return coder.decode(model); }
    void link_children(NodeId, NodeId) {}
};

// The walk of FORMAT.md 7.5. `io` answers "refined?" and "flipped?"; out is built as it goes.
template <class Io>
void code_forest(const Hierarchy& prev, Io& io, uint64_t max_nodes, Hierarchy& out, Counterparts& cp,
                 FrameConnectivityStats* stats) {
    FrameConnectivityModels models;
    std::vector<uint8_t> state;
    const uint32_t roots = out.root_count();
    cp.assign(roots, kNoNode);
    state.assign(roots, 0);
    for (NodeId r = 0; r < roots; ++r) cp[r] = r;
    std::vector<NodeId> level, next;
    for (NodeId r = 0; r < roots; ++r) level.push_back(r);
    uint64_t nodes = roots;
    auto changed = [&](NodeId q) { return q != kNoNode && (state[q] & kChanged); };

    while (!level.empty()) {
        next.clear();
        for (NodeId n : level) {
            const NodeId p = cp[n];
            const int cls = previous_class(prev, p);
            const bool was_refined = cls >= 2;
            bool refined;
            int refined_neighbors = 0;
            bool complete = true;
            for (int e = 0; e < 3; ++e) {
                const NodeId q = out.neighbor(n, e);
                if (q == kNoNode) complete &= out.is_boundary_edge(n, e);
                else if ((state[q] & (kDecided | kRefined)) == (kDecided | kRefined)) ++refined_neighbors;
            }
            if (!complete || out.level(n) >= kMaxLevel) {
                refined = io.forced_refined(n, false);
            } else if (refined_neighbors == 3) {
                refined = io.forced_refined(n, true);
            } else {
                int count = 0;
                for (int e = 0; e < 3; ++e) {
                    const NodeId q = out.neighbor(n, e);
                    if (q == kNoNode || !(state[q] & kDecided)) continue;
                    count += cls == 0 ? bool(state[q] & kRefined) : bool(state[q] & kChanged);
                }
                bool parent_area = false;
                const NodeId parent = out.parent(n);
                if (parent != kNoNode) {
                    parent_area = changed(parent);
                    for (int e = 0; e < 3; ++e) parent_area |= changed(out.neighbor(parent, e));
                }
                const int ctx = (cls * 3 + std::min(count, 2)) * 2 + int(parent_area);
                refined = io.refined(n, models.refine[size_t(ctx)]);
                if (stats) ++stats->coded_symbols;
            }
            state[n] = uint8_t(kDecided | (refined ? kRefined : 0) | (refined != was_refined ? kChanged : 0));
            if (stats) stats->changed_nodes += refined != was_refined;
            if (!refined) continue;
            AMC_REQUIRE(nodes + 4 <= max_nodes, limit_exceeded,
                        "series frame: more than " + std::to_string(max_nodes) + " nodes");
            out.split(n);
            nodes += 4;
            const NodeId first = out.child(n, 0);
            if (cp.size() < size_t(first) + 4) {
                cp.resize(size_t(first) + 4, kNoNode);
                state.resize(size_t(first) + 4, 0);
            }
            io.link_children(n, first);
            for (int k = 0; k < 4; ++k) {
                const NodeId c = first + NodeId(k);
                cp[c] = was_refined ? prev.child(p, k) : kNoNode;
                state[c] = 0;
                next.push_back(c);
            }
        }
        // Diagonals of the level's leaves with two hanging nodes, in canonical order.
        for (NodeId n : level) {
            if (!out.is_leaf(n)) continue;
            const int hanging = out.hanging_node_count(n);
            AMC_REQUIRE(hanging < 3, corrupt, "series frame: a leaf with three hanging nodes (closure violated)");
            if (hanging != 2) continue;
            const int u = two_hanging_unrefined_edge(out, n);
            const NodeId p = cp[n];
            int ctx = 0;
            if (p != kNoNode && prev.is_leaf(p) && two_hanging_unrefined_edge(prev, p) == u)
                ctx = 1 + int(prev.diagonal_flipped(p));
            out.set_diagonal_flipped(n, io.flipped(n, models.diagonal[size_t(ctx)]));
        }
        level.swap(next);
    }
    if (stats) stats->nodes = nodes;
}

// Encoding needs the target's node for each node of out: kept beside the walk.
struct EncodingIo {
    ArithmeticEncoder& coder;
    const Hierarchy& target;
    std::vector<NodeId>& target_of;
    bool refined(NodeId n, BitModel& model) {
        const bool bit = !target.is_leaf(target_of[n]);
        coder.encode(bit, model);
        return bit;
    }
    bool forced_refined(NodeId n, bool implied) {
        AMC_REQUIRE(!target.is_leaf(target_of[n]) == implied, invalid_input,
                    "series frame: the hierarchy breaks balance or closure at a node of level " +
                        std::to_string(target.level(target_of[n])));
        return implied;
    }
    bool flipped(NodeId n, BitModel& model) {
        const bool bit = target.diagonal_flipped(target_of[n]);
        coder.encode(bit, model);
        return bit;
    }
    void link_children(NodeId n, NodeId first) {
        if (target_of.size() < size_t(first) + 4) target_of.resize(size_t(first) + 4, kNoNode);
        for (int k = 0; k < 4; ++k) target_of[first + NodeId(k)] = target.child(target_of[n], k);
    }
};

void require_same_base(const Hierarchy& prev, const Hierarchy& target) {
    AMC_REQUIRE(prev.base().triangles == target.base().triangles, invalid_input,
                "series frame: the hierarchy is not over the series' base mesh (different base triangles)");
}

// Number of nodes of prev with no node at their place in out.
uint64_t removed_nodes(const Hierarchy& prev, const Hierarchy& out, const Counterparts& cp) {
    uint64_t kept = 0;
    for (NodeId n = 0; n < cp.size(); ++n) kept += out.is_alive(n) && cp[n] != kNoNode;
    return prev.node_count() - kept;
}

}  // namespace

void encode_frame_connectivity(const Hierarchy& prev, const Hierarchy& target, ArithmeticEncoder& encoder,
                               Hierarchy& out, Counterparts& counterparts, FrameConnectivityStats* stats) {
    require_same_base(prev, target);
    out.reset(target.base());
    std::vector<NodeId> target_of(out.root_count());
    for (NodeId r = 0; r < out.root_count(); ++r) target_of[r] = r;
    EncodingIo io{encoder, target, target_of};
    FrameConnectivityStats local;
    code_forest(prev, io, UINT64_MAX, out, counterparts, &local);
    local.removed_nodes = removed_nodes(prev, out, counterparts);
    if (stats) *stats = local;
}

void decode_frame_connectivity(const Hierarchy& prev, ArithmeticDecoder& decoder, uint64_t max_nodes, Hierarchy& out,
                               Counterparts& counterparts) {
    out.reset(prev.base());
    DecodingIo io{decoder};
    code_forest(prev, io, max_nodes, out, counterparts, nullptr);
}

Counterparts match_nodes(const Hierarchy& prev, const Hierarchy& next) {
    require_same_base(prev, next);
    Counterparts cp(next.node_capacity(), kNoNode);
    for (NodeId n : next.breadth_first_order()) {
        if (n < next.root_count()) cp[n] = n;
        if (next.is_leaf(n)) continue;
        const NodeId p = cp[n];
        for (int k = 0; k < 4; ++k)
            cp[next.child(n, k)] = (p != kNoNode && !prev.is_leaf(p)) ? prev.child(p, k) : kNoNode;
    }
    return cp;
}

}  // namespace amc
