// Inter-frame connectivity coder; see frame_connectivity.h and docs/FORMAT.md, section 7.5.
// Encoder and decoder run the same walk (code_forest), so they agree on every context.
#include "series/frame_connectivity.h"

#include "common/check.h"
#include "common/exact_float.h"

#include <algorithm>
#include <cmath>
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

// What the decoder knows of a node when it decides it (FORMAT.md 7.6).
struct NodeContext {
    int cls = 0;                 // class in the reference
    int decided_changed = 0;     // decided same-level neighbours that changed
    int decided_refined = 0;     // decided same-level neighbours that are refined
    bool parent_area = false;    // the parent or one of its neighbours changed
    int reference_refined = 0;   // same-level neighbours of cp(n) refined in the reference
    int indicator = 0;           // indicator context of cp(n) (classes 1 and 2), 0 none
};

int refine_context_v1(const NodeContext& c) {
    return (c.cls * 3 + std::min(c.cls == 0 ? c.decided_refined : c.decided_changed, 2)) * 2 + int(c.parent_area);
}

// Version 2: the node's class, its refinement indicator in the reference, where it sits there
// (inside or at the border of the refined region), how much changed around it now.
int refine_context_v2(const NodeContext& c) {
    int border;
    if (c.cls == 0) border = std::min(c.decided_refined, 2);
    else if (c.cls == 1) border = std::min(c.reference_refined, 2);
    else border = c.reference_refined == 3 ? 0 : c.reference_refined == 2 ? 1 : 2;
    return (((c.cls * FrameConnectivityModels::kIndicatorContexts + c.indicator) * 3 + border) * 3 +
            std::min(c.decided_changed, 2)) * 2 + int(c.parent_area);
}

// Version 3: fresh refine models (the first type-3 frame after a keyframe) start from what the
// class and the indicator predict, so that a small frame does not pay for learning it: a node
// below its threshold (or a leaf without indicator) most likely not refined, one above it (or a
// refined node without indicator) most likely refined, near the threshold less sure; class 0
// even. The prior weighs as much as kPriorWeight symbols seen.
constexpr uint16_t kPriorWeight = 1;

uint32_t refine_prior(int cls, int x) {
    constexpr uint32_t sure = uint32_t{1} << 26, unsure = uint32_t{1} << 30;  // 1/64, 1/4
    if (cls == 0) return uint32_t{1} << 31;
    if (x == 0) return cls == 1 ? sure : ~sure;
    if (x >= 8) return x <= 9 ? ~unsure : ~sure;  // level at or above the threshold (13: infinite)
    return x >= 6 ? unsure : sure;                // below it (1: zero)
}

void prime_refine_models(FrameConnectivityModels& models) {
    constexpr int per_indicator = 3 * 3 * 2;
    for (size_t ctx = 0; ctx < models.refine.size(); ++ctx) {
        const int x = int(ctx / per_indicator) % FrameConnectivityModels::kIndicatorContexts;
        const int cls = int(ctx / (per_indicator * FrameConnectivityModels::kIndicatorContexts));
        models.refine[ctx].p = refine_prior(cls, x);
        models.refine[ctx].n = cls == 0 ? 0 : kPriorWeight;
    }
}

// The distance of a node's indicator level to its class's threshold, in 12 steps (FORMAT.md 7.6).
int indicator_context(const Indicator& indicator, NodeId p, int cls) {
    const int32_t level = indicator.levels[p];
    if (level == kNoIndicator) return 0;
    if (level == kZeroIndicator) return 1;
    if (level == kInfiniteIndicator) return 13;
    const int64_t d = int64_t(level) - indicator.threshold[cls - 1];
    const int step = d < -16 ? 0 : d < -8 ? 1 : d < -4 ? 2 : d < -2 ? 3 : d < 2 ? int(6 + d) : d < 4 ? 8 : d < 8 ? 9 : d < 16 ? 10 : 11;
    return 2 + step;
}

// The walk of FORMAT.md 7.6. `io` answers "refined?" and "flipped?"; out is built as it goes.
template <class Io>
void code_forest(const Hierarchy& prev, int version, ConnectivityMemory& memory, const Indicator* indicator,
                 Io& io, uint64_t max_nodes, Hierarchy& out, Counterparts& cp, FrameConnectivityStats* stats) {
    FrameConnectivityModels fresh;
    FrameConnectivityModels& models = version >= 2 ? memory.models : fresh;
    if (version >= 3 && !memory.primed) {
        prime_refine_models(models);
        memory.primed = true;
    }
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
                NodeContext c;
                c.cls = cls;
                for (int e = 0; e < 3; ++e) {
                    const NodeId q = out.neighbor(n, e);
                    if (q == kNoNode || !(state[q] & kDecided)) continue;
                    c.decided_changed += bool(state[q] & kChanged);
                    c.decided_refined += bool(state[q] & kRefined);
                }
                const NodeId parent = out.parent(n);
                if (parent != kNoNode) {
                    c.parent_area = changed(parent);
                    for (int e = 0; e < 3; ++e) c.parent_area |= changed(out.neighbor(parent, e));
                }
                int ctx;
                if (version >= 2) {
                    if (p != kNoNode)
                        for (int e = 0; e < 3; ++e) {
                            const NodeId q = prev.neighbor(p, e);
                            c.reference_refined += q != kNoNode && !prev.is_leaf(q);
                        }
                    if ((cls == 1 || cls == 2) && indicator) c.indicator = indicator_context(*indicator, p, cls);
                    ctx = refine_context_v2(c);
                    refined = io.refined(n, models.refine[size_t(ctx)]);
                } else {
                    ctx = refine_context_v1(c);
                    refined = io.refined(n, models.refine_v1[size_t(ctx)]);
                }
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

void encode_frame_connectivity(const Hierarchy& prev, const Hierarchy& target, int version, ConnectivityMemory& memory,
                               const Indicator* indicator, ArithmeticEncoder& encoder, Hierarchy& out,
                               Counterparts& counterparts, FrameConnectivityStats* stats) {
    require_same_base(prev, target);
    out.reset(target.base());
    std::vector<NodeId> target_of(out.root_count());
    for (NodeId r = 0; r < out.root_count(); ++r) target_of[r] = r;
    EncodingIo io{encoder, target, target_of};
    FrameConnectivityStats local;
    code_forest(prev, version, memory, indicator, io, UINT64_MAX, out, counterparts, &local);
    local.removed_nodes = removed_nodes(prev, out, counterparts);
    if (stats) *stats = local;
}

void decode_frame_connectivity(const Hierarchy& prev, int version, ConnectivityMemory& memory,
                               const Indicator* indicator, ArithmeticDecoder& decoder, uint64_t max_nodes,
                               Hierarchy& out, Counterparts& counterparts) {
    out.reset(prev.base());
    DecodingIo io{decoder};
    code_forest(prev, version, memory, indicator, io, max_nodes, out, counterparts, nullptr);
}

namespace {

// floor(8 log2 q) for a finite q > 0, exactly (no libm): q = m 2^e with m in [0.5, 1), and
// 8 log2 m in [-8, 0) counted against the doubles nearest to 2^(j/8 - 1), j = 1..7.
int32_t indicator_level(double q) {
    static constexpr double kSteps[7] = {0.5452538663326288, 0.5946035575013605, 0.6484197773255048, 0.7071067811865476,
                                         0.7711054127039704, 0.8408964152537145, 0.9170040432046712};
    int e;
    const double m = std::frexp(q, &e);
    int32_t level = 8 * (e - 1);
    for (double step : kSteps) level += m >= step;
    return level;
}

}  // namespace

Indicator indicator_levels(const Hierarchy& prev, const std::vector<uint32_t>& first_cell,
                           const std::vector<double>& values) {
    double mean = 0;
    for (double x : values) mean += rounded(x * x);  // both sides take the indicator's levels from it
    mean /= double(std::max<size_t>(values.size(), 1));
    std::vector<double> largest(prev.node_capacity(), -1.0);
    for (NodeId n : prev.breadth_first_order()) {
        if (!prev.is_leaf(n)) continue;
        double m = 0;
        const size_t cells = size_t(1 + prev.hanging_node_count(n));
        for (size_t k = 0; k < cells && first_cell[n] + k < values.size(); ++k) {
            const double x = values[first_cell[n] + k];
            m = std::max(m, x * x);  // a NaN never wins
        }
        largest[n] = m;
        const NodeId parent = prev.parent(n);
        if (parent != kNoNode) largest[parent] = std::max(largest[parent], m);
    }
    Indicator out;
    out.levels.assign(prev.node_capacity(), kNoIndicator);
    for (NodeId n = 0; n < prev.node_capacity(); ++n) {
        if (largest[n] < 0) continue;
        const double q = largest[n] / mean;
        out.levels[n] = !(q > 0) ? kZeroIndicator : !std::isfinite(q) ? kInfiniteIndicator : indicator_level(q);
    }
    return out;
}

void fit_indicator_thresholds(const Hierarchy& prev, const Hierarchy& next, const Counterparts& cp, Indicator& indicator) {
    std::vector<std::pair<int32_t, bool>> samples[2];
    for (NodeId n : next.breadth_first_order()) {
        const NodeId p = cp[n];
        const int cls = previous_class(prev, p);
        if (cls != 1 && cls != 2) continue;
        const int32_t level = indicator.levels[p];
        if (level == kNoIndicator || level == kZeroIndicator || level == kInfiniteIndicator) continue;
        samples[cls - 1].push_back({level, !next.is_leaf(n)});
    }
    for (int c = 0; c < 2; ++c) {
        std::vector<std::pair<int32_t, bool>>& v = samples[c];
        indicator.threshold[c] = 0;
        if (v.empty()) continue;
        std::sort(v.begin(), v.end());
        // Errors of threshold t: refined nodes below t, leaves at or above it.
        size_t refined_below = 0, leaves_above = 0;
        for (const auto& x : v) leaves_above += !x.second;
        size_t best = leaves_above;
        int32_t best_t = v.front().first;
        for (size_t i = 0; i < v.size(); ++i) {
            refined_below += v[i].second;
            leaves_above -= !v[i].second;
            if (i + 1 < v.size() && v[i + 1].first == v[i].first) continue;
            if (refined_below + leaves_above < best) {
                best = refined_below + leaves_above;
                best_t = v[i].first + 1;
            }
        }
        indicator.threshold[c] = std::max(-kMaxIndicatorThreshold, std::min(best_t, kMaxIndicatorThreshold));
    }
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
