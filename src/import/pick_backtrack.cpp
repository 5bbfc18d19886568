// Going back to an earlier level when a level further down contradicts a guided pick
// (docs/IMPORT.md, "Back to the level of the pick"): the first misfit's ancestors name the guided
// picks above it; each of their other candidates is judged on the nodes around it, reconstructed
// again from the state before the pick's level; the best are retried on the whole mesh and kept
// if the failing level then misfits less.
#include "import/reconstruction.h"

#include "hierarchy/hierarchy_builder.h"

#include <algorithm>
#include <string>
#include <utility>
#include <vector>

namespace amc {

void Reconstruction::remember(int depth, const std::vector<NodeId>& level) {
    // Only way 5's first attempt goes back to a level (run): the others keep no state.
    if (!judges_picks() || (depth > 0 && !keep_levels_ && depth > kCertifiedLevels)) return;
    if (states_.size() <= size_t(depth)) states_.resize(size_t(depth) + 1);
    // Levels more than kBacktrackLevels up are not gone back to: their memory is given back.
    if (keep_levels_ && depth > kBacktrackLevels) states_[size_t(depth - kBacktrackLevels - 1)] = LevelState();
    LevelState& s = states_[size_t(depth)];
    if (keep_levels_) work_ += state_size();
    s.h = h_;
    s.leaf_of_vertex = leaf_of_vertex_;
    s.vertex_of_leaf = vertex_of_leaf_;
    s.guided_of_vertex = guided_of_vertex_;
    s.guided = guided_;
    s.pick_level = pick_level_;
    s.pick_edge = pick_edge_;
    s.level = level;
}

void Reconstruction::restore(int depth, std::vector<NodeId>& level) {
    const LevelState& s = states_[size_t(depth)];
    h_ = s.h;
    work_ += state_size();
    leaf_of_vertex_ = s.leaf_of_vertex;
    vertex_of_leaf_ = s.vertex_of_leaf;
    guided_of_vertex_ = s.guided_of_vertex;
    guided_ = s.guided;
    pick_level_ = s.pick_level;
    pick_edge_ = s.pick_edge;
    level = s.level;
}

Reconstruction::ForcedBefore Reconstruction::force(const Retry& r) {
    ForcedBefore before;
    const uint64_t edges[2] = {edge_key(r.a, r.b), r.swap_edge};
    const uint32_t vertices[2] = {r.vertex, r.swap_vertex};
    for (int i = 0; i < (r.swap_edge ? 2 : 1); ++i) {
        const auto it = forced_.find(edges[i]);
        before.edge[i] = edges[i];
        before.vertex[i] = it != forced_.end() ? it->second : kNoIndex;
        forced_[edges[i]] = vertices[i];
        ++before.count;
    }
    return before;
}

void Reconstruction::put_back(const ForcedBefore& before) {
    for (int i = before.count - 1; i >= 0; --i) {
        if (before.vertex[i] != kNoIndex) {
            forced_[before.edge[i]] = before.vertex[i];
        } else {
            forced_.erase(before.edge[i]);
        }
    }
}

int Reconstruction::misfit_count(const std::vector<NodeId>& level) const {
    int count = 0;
    for (NodeId x : level) count += !fits(x, nullptr);
    return count;
}

int Reconstruction::local_misfits(int from, int depth, const std::vector<NodeId>& region, size_t inner, int cap,
                                  std::vector<int>* per_inner) {
    LocalUndo& undo = local_undo_;
    undo.splits.clear();
    undo.flags.clear();
    undo.matched.clear();
    undo.nodes = h_.node_capacity();
    undo.vertices = leaf_of_vertex_.size();
    undo.guided = guided_.size();
    undo.guided_of_vertex = guided_of_vertex_.size();
    undo.picks = pick_level_.size();
    // Each node with the index of its inner ancestor in `region` (kNoIndex: the context).
    std::vector<std::pair<NodeId, uint32_t>> nodes, next;
    for (size_t i = 0; i < region.size(); ++i) nodes.push_back({region[i], i < inner ? uint32_t(i) : kNoIndex});
    if (per_inner) per_inner->assign(inner, 0);
    int misfits = 0;
    auto miss = [&](uint32_t owner) {
        if (owner == kNoIndex) return;
        ++misfits;
        if (per_inner) ++(*per_inner)[owner];
    };
    try {
        for (int d = from; d < depth && !nodes.empty() && misfits < cap; ++d) {
            reveals_.clear();
            std::vector<std::pair<NodeId, uint32_t>> split;
            // The count only grows: once it reaches the cap, the rest is not read.
            for (const auto& node : nodes) {
                if (misfits >= cap) break;
                uint32_t p[3];
                if (!known_corners(node.first, p)) {  // under a midpoint not found: no reading
                    miss(node.second);
                    continue;
                }
                if (node.first < undo.nodes) undo.flags.push_back({node.first, h_.diagonal_flipped(node.first)});
                const Reading reading = read(p);
                if (reading.fault != Reading::none) {  // where classify throws
                    miss(node.second);
                    blame_node(node.second, node.first);
                    continue;
                }
                if (!take_reading(node.first, reading)) continue;
                if (h_.can_split(node.first)) {
                    h_.split(node.first);
                    undo.splits.push_back(node.first);
                    split.push_back(node);
                } else {
                    miss(node.second);
                    blame_node(node.second, node.first);
                }
            }
            if (misfits >= cap) break;
            leaf_of_vertex_.resize(h_.positions().size(), kNoIndex);
            auto match = [&](VertexId m, uint32_t l) {
                assign(m, l);
                undo.matched.push_back({m, l});
            };
            for (const Reveal& r : reveals_) {
                const NodeId q = h_.neighbor(r.node, r.edge);
                if (q == kNoNode || h_.is_leaf(q)) continue;
                const VertexId m = h_.midpoint(q, h_.neighbor_edge(r.node, r.edge));
                if (leaf_of_vertex_[m] == kNoIndex && vertex_of_leaf_[r.leaf_vertex] == kNoIndex) match(m, r.leaf_vertex);
            }
            next.clear();
            for (const auto& node : split) {
                if (misfits >= cap) break;
                for (int e = 0; e < 3; ++e) {
                    const VertexId m = h_.midpoint(node.first, e);
                    if (leaf_of_vertex_[m] != kNoIndex) continue;
                    try {
                        const uint32_t found = find_midpoint(node.first, e);
                        if (vertex_of_leaf_[found] == kNoIndex) {
                            match(m, found);
                            continue;
                        }
                    } catch (const SearchBudgetSpent&) {
                        throw;
                    } catch (const Error&) {  // a misfit
                    }
                    miss(node.second);
                    blame_node(node.second, node.first);
                }
                for (int k = 0; k < 4; ++k) next.push_back({h_.child(node.first, k), node.second});
            }
            if (misfits >= cap) break;
            nodes.swap(next);
            for (size_t i = 0; i < nodes.size() && misfits < cap; ++i) {
                if (nodes[i].second == kNoIndex) continue;
                if (!blames_) {
                    if (!fits(nodes[i].first, nullptr)) miss(nodes[i].second);
                    continue;
                }
                blamed_.clear();
                if (fits(nodes[i].first, &blamed_)) continue;
                miss(nodes[i].second);
                for (VertexId v : blamed_) blame_vertex(v);
                blame_node(nodes[i].second, nodes[i].first);
            }
        }
    } catch (...) {
        undo_local();
        throw;
    }
    undo_local();
    return misfits;
}

void Reconstruction::undo_local() {
    LocalUndo& undo = local_undo_;
    // Every vertex and leaf vertex it matched was free before.
    for (const auto& m : undo.matched) {
        leaf_of_vertex_[m.first] = kNoIndex;
        vertex_of_leaf_[m.second] = kNoIndex;
    }
    for (size_t i = undo.flags.size(); i-- > 0;) h_.set_diagonal_flipped(undo.flags[i].first, undo.flags[i].second);
    work_ += 4 * undo.splits.size() + undo.matched.size();
    HierarchyBuilder::undo_splits(h_, undo.splits, 0);
    leaf_of_vertex_.resize(undo.vertices);
    guided_.resize(undo.guided);
    guided_of_vertex_.resize(undo.guided_of_vertex);
    pick_level_.resize(undo.picks);
    pick_edge_.resize(undo.picks);
}

void Reconstruction::plan_retries(int depth, NodeId x) {
    retries_.clear();
    next_retry_ = 0;
    plan_floor_ = depth;
    // The guided picks above x (nearest level first) and their other candidates, nearest first:
    // those that could split the edge in the state before its level (no vertex matched above the
    // level next to them but the edge's ends).
    struct Suspect {
        int level;
        NodeId node;
        int edge;
        uint32_t a, b, picked, count;
        uint32_t candidates[kRepairCandidates];
        uint64_t swap_edge[kRepairCandidates];  // the edge of the pick of the level holding it, or 0
    };
    std::vector<Suspect> suspects;
    NodeId ancestor = x;
    for (int d = 1; d <= kBacktrackLevels && depth - d >= 0; ++d) {
        ancestor = h_.parent(ancestor);
        if (ancestor == kNoNode) break;
        const int level = depth - d;
        const size_t known_before = states_[size_t(level)].h.positions().size();
        for (int e = 0; e < 3; ++e) {
            const VertexId m = h_.midpoint(ancestor, e);
            if (m >= pick_level_.size() || pick_level_[m] != level) continue;
            const uint32_t picked = leaf_of_vertex_[m];
            Suspect s{level, ancestor, e, corner(ancestor, e), corner(ancestor, (e + 1) % 3), picked, 0, {}, {}};
            auto usable = [&](uint32_t v) {
                const uint32_t owner = vertex_of_leaf_[v];
                if (v == picked || (owner != kNoIndex && owner < known_before)) return false;
                bool fits_above = true;
                he_.for_each_neighbor_once(v, [&](uint32_t w) {
                    const uint32_t o = vertex_of_leaf_[w];
                    fits_above &= o == kNoIndex || o >= known_before || w == s.a || w == s.b;
                });
                return fits_above;
            };
            const uint32_t found = nearest_usable(guide_position(ancestor, e), usable, kRepairCandidates, s.candidates);
            for (uint32_t i = 0; i < found; ++i) {
                if (tried_.count(retry_key(s.a, s.b, s.candidates[i]))) continue;
                // A candidate another pick of the level holds: the two would swap.
                const uint32_t holder = vertex_of_leaf_[s.candidates[i]];
                s.swap_edge[s.count] = holder != kNoIndex && holder < pick_level_.size() && pick_level_[holder] == level
                                           ? pick_edge_[holder]
                                           : 0;
                s.candidates[s.count++] = s.candidates[i];
            }
            if (s.count > 0) suspects.push_back(s);
        }
    }
    // Each candidate judged by the misfits it leaves below the two elements on its edge,
    // reconstructed with the nodes around them from the state before its level; those that
    // leave fewer than the pick made, most removed first, are the retries.
    std::vector<std::pair<int, Retry>> better;
    for (const Suspect& s : suspects) {
        if (over_budget()) break;
        restore(s.level, local_level_);
        std::vector<NodeId> region;
        add_once(region, s.node);
        add_once(region, h_.neighbor(s.node, s.edge));
        const size_t inner = region.size();
        for (size_t i = 0; i < inner; ++i) {
            for (int e = 0; e < 3; ++e) add_once(region, h_.neighbor(region[i], e));
        }
        const int before = local_misfits(s.level, depth, region, inner);
        for (uint32_t i = 0; i < s.count; ++i) {
            const Retry retry{s.level, s.a, s.b, s.candidates[i], s.swap_edge[i], s.swap_edge[i] ? s.picked : 0};
            const ForcedBefore forced_before = force(retry);
            const int after = local_misfits(s.level, depth, region, inner);
            put_back(forced_before);
            if (after < before) better.push_back({before - after, retry});
        }
    }
    std::stable_sort(better.begin(), better.end(), [](const std::pair<int, Retry>& p, const std::pair<int, Retry>& q) {
        return p.first > q.first || (p.first == q.first && p.second.level > q.second.level);
    });
    for (const auto& b : better) {
        if (retries_.size() >= size_t(kRetriesPerFailure)) break;
        retries_.push_back(b.second);
    }
}

bool Reconstruction::start_next_retry(int& depth, std::vector<NodeId>& level) {
    if (over_budget()) return false;
    if (next_retry_ >= retries_.size()) {
        // Every retry for that misfit failed: back to the state they started from (the highest
        // level they restored is untouched), whose failure then plans for the next misfit.
        retry_open_ = false;
        retry_depth_ = -1;
        depth = plan_floor_;
        retries_.clear();
        restore(depth, level);
        return true;
    }
    const Retry r = retries_[next_retry_++];
    tried_.insert(retry_key(r.a, r.b, r.vertex));
    open_before_ = force(r);
    retry_open_ = true;
    // A retry overwrites the states below the level it restores, so the plan never restores a
    // level below one it restored before: it restores the highest of them instead (a forced
    // vertex is taken whenever its edge is split).
    depth = plan_floor_ = std::min(plan_floor_, r.level);
    restore(depth, level);
    return true;
}

bool Reconstruction::backtrack(int& depth, std::vector<NodeId>& level, bool read_failed, const std::string& error) {
    if (first_error_.empty()) first_error_ = error;
    if (!keep_levels_) {
        // The first failure: start again, this time keeping every level's state to go back to.
        if (depth == 0 || pick_level_.empty()) return false;
        keep_levels_ = true;
        depth = 0;
        restore(0, level);
        return true;
    }
    // A level that read well but whose vertices did not fit (one claimed twice, or none left for
    // an edge) counts as one misfit: its nodes are split by then, so they cannot be read again.
    const NodeId claimed_twice = read_failed ? kNoNode : failed_node_;
    const int misfits = read_failed ? misfit_count(level) : claimed_twice != kNoNode;
    if (retry_open_) {
        retry_open_ = false;
        if (depth == retry_depth_ && misfits > 0 && misfits < retry_misfits_) {
            // Kept: the level misfits less; what is left is a new failure.
            retry_depth_ = -1;
            kept_since_round_ = true;
        } else {
            put_back(open_before_);
            return start_next_retry(depth, level);
        }
    }
    // Many misfits at once are many wrong picks: more than the budget repairs (measured on the
    // corpus, docs/IMPORT.md).
    if (depth == 0 || misfits == 0 || misfits > kMaxMisfits) return false;
    // The first misfit not planned for yet (one whose retries all failed is passed over).
    NodeId first = kNoNode;
    for (NodeId x : level) {
        if (x != claimed_twice && (claimed_twice != kNoNode || fits(x, nullptr))) continue;
        if (!planned_.insert(retry_key(corner(x, 0), corner(x, 1), corner(x, 2))).second) continue;
        first = x;
        break;
    }
    if (first == kNoNode && kept_since_round_) {
        // Every misfit planned for once: another round, as retries kept since may help those
        // whose retries failed.
        kept_since_round_ = false;
        planned_.clear();
        return backtrack(depth, level, read_failed, error);
    }
    if (first == kNoNode) return false;
    retry_depth_ = depth;
    retry_misfits_ = misfits;
    plan_retries(depth, first);
    return start_next_retry(depth, level);
}

}  // namespace amc
