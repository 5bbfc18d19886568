// Guided picks certified by their subtrees (docs/IMPORT.md, "Picks certified by their subtree"):
// after a coarse level is split, each position-guided pick of it is judged by reconstructing,
// from the state before the level, the two elements on its edge and every element around their
// corners down to kCertifyHorizon levels below. A subtree that closes (no misfit) certifies its
// vertex; a pick whose subtree misfits is replaced by the nearest other candidate whose subtree
// closes. A wrong coarse vertex's subtree reads well for a few levels and then cannot close,
// the true one's closes: on the corpus no right pick was replaced (measured).
#include "import/reconstruction.h"

#include <algorithm>
#include <vector>

namespace amc {

void Reconstruction::add_corner_fans(std::vector<NodeId>& region, size_t inner) const {
    VertexId corners[3 * 2];
    int corner_count = 0;
    for (size_t i = 0; i < inner && i < 2; ++i)
        for (int k = 0; k < 3; ++k) corners[corner_count++] = h_.vertex(region[i], k);
    for (size_t i = 0; i < region.size() && region.size() < kMaxJudgedRegion; ++i) {
        for (int e = 0; e < 3; ++e) {
            const NodeId y = h_.neighbor(region[i], e);
            if (y == kNoNode) continue;
            bool touches = false;
            for (int k = 0; k < 3; ++k)
                for (int c = 0; c < corner_count; ++c) touches |= h_.vertex(y, k) == corners[c];
            if (touches) add_once(region, y);
        }
    }
}

bool Reconstruction::certify_picks(int& depth, std::vector<NodeId>& level) {
    const int picked_level = depth - 1;
    // A coarser level is not judged again when the reconstruction comes back to it (to make a
    // level again with changed picks, or to start over after a failure): its picks stand.
    if (picked_level < certifying_level_ || picked_level >= kCertifiedLevels || guided_.empty() ||
        certify_over_budget(0))
        return false;
    if (certify_rounds_.size() <= size_t(picked_level)) certify_rounds_.resize(size_t(picked_level) + 1, 0);
    int& rounds = certify_rounds_[size_t(picked_level)];
    if (rounds >= kCertifyRounds) return false;
    ++rounds;
    if (picked_level != certifying_level_) {
        certifying_level_ = picked_level;
        judged_picks_.clear();
        changed_regions_.clear();
    }
    // Each pick's candidates, as plan_retries takes them: those that could split the edge in the
    // state before the level; one another pick of the level holds is tried as a swap of the two.
    struct Judged {
        NodeId node;
        int edge;
        uint32_t a, b, picked, count;
        uint32_t candidates[kRepairCandidates];
        uint64_t swap_edge[kRepairCandidates];
        int misfits;  // under the better of its two elements in the level's whole reconstruction
    };
    std::vector<Judged> judged;
    const size_t known_before = states_[size_t(picked_level)].h.positions().size();
    for (const GuidedSlot& g : guided_) {
        Judged s{g.node, g.edge, corner(g.node, g.edge), corner(g.node, (g.edge + 1) % 3),
                 leaf_of_vertex_[h_.midpoint(g.node, g.edge)], 0, {}, {}, 0};
        auto usable = [&](uint32_t v) {
            const uint32_t owner = vertex_of_leaf_[v];
            if (v == s.picked || (owner != kNoIndex && owner < known_before)) return false;
            bool fits_above = true;
            he_.for_each_neighbor_once(v, [&](uint32_t w) {
                const uint32_t o = vertex_of_leaf_[w];
                fits_above &= o == kNoIndex || o >= known_before || w == s.a || w == s.b;
            });
            return fits_above;
        };
        uint32_t found[kRepairCandidates];
        const uint32_t count = nearest_usable(guide_position(g.node, g.edge), usable, kRepairCandidates, found);
        for (uint32_t i = 0; i < count; ++i) {
            const uint32_t holder = vertex_of_leaf_[found[i]];
            s.swap_edge[s.count] = holder != kNoIndex && holder < pick_level_.size() && pick_level_[holder] == picked_level
                                       ? pick_edge_[holder]
                                       : 0;
            s.candidates[s.count++] = found[i];
        }
        if (s.count > 0) judged.push_back(s);
    }
    // Judged from the state before the level; the judgements take back what they change.
    const uint64_t work_before = work_;  // the return to a pick's level has a budget of its own
    restore(picked_level, local_level_);
    // Each round first reconstructs the level's whole subtree with every pick as made: a pick
    // whose two elements' subtrees close there stands without a judgement of its own. The others
    // are judged alone, those under the most misfits first; one next to a change made in the round
    // waits for the next round, whose whole reconstruction sees the change (a wrong vertex makes
    // its neighbours' subtrees misfit too, and most of them close once it is replaced). A later
    // round reconstructs again only the elements that misfit or changed, with those around them.
    std::vector<ForcedBefore> as_made;
    for (const Judged& s : judged) as_made.push_back(force(Retry{picked_level, s.a, s.b, s.picked, 0, 0}));
    std::vector<int>& misfits_below = level_misfits_;
    if (rounds == 1 || misfits_of_level_ != local_level_) {
        local_misfits(picked_level, picked_level + kCertifyHorizon, local_level_, local_level_.size(), kNoCap,
                      &misfits_below);
        misfits_of_level_ = local_level_;
    } else {
        std::vector<uint8_t> corner_mark(h_.positions().size(), 0);
        std::vector<NodeId> again;
        std::vector<uint32_t> again_index;
        for (size_t i = 0; i < local_level_.size(); ++i) {
            const NodeId n = local_level_[i];
            if (misfits_below[i] == 0 &&
                std::find(changed_regions_.begin(), changed_regions_.end(), n) == changed_regions_.end())
                continue;
            again.push_back(n);
            again_index.push_back(uint32_t(i));
            for (int k = 0; k < 3; ++k) corner_mark[h_.vertex(n, k)] = 1;
        }
        const size_t inner = again.size();
        for (size_t i = 0; i < local_level_.size(); ++i) {
            const NodeId n = local_level_[i];
            const bool around = corner_mark[h_.vertex(n, 0)] | corner_mark[h_.vertex(n, 1)] | corner_mark[h_.vertex(n, 2)];
            if (around && std::find(again.begin(), again.begin() + long(inner), n) == again.begin() + long(inner))
                again.push_back(n);
        }
        std::vector<int> again_misfits;
        local_misfits(picked_level, picked_level + kCertifyHorizon, again, inner, kNoCap, &again_misfits);
        for (size_t i = 0; i < inner; ++i) misfits_below[again_index[i]] = again_misfits[i];
    }
    for (size_t i = as_made.size(); i-- > 0;) put_back(as_made[i]);
    std::vector<uint32_t> index_in_level(h_.node_capacity(), kNoIndex);
    for (size_t i = 0; i < local_level_.size(); ++i) index_in_level[local_level_[i]] = uint32_t(i);
    auto misfits_under = [&](NodeId n) { return n == kNoNode ? 0 : misfits_below[index_in_level[n]]; };
    // A wrong vertex makes both elements on its edge misfit; a right one next to it, the element
    // the two share: the fewer of the two is the pick's (one element on the boundary).
    for (Judged& s : judged) {
        const NodeId across = h_.neighbor(s.node, s.edge);
        s.misfits = across == kNoNode ? misfits_under(s.node) : std::min(misfits_under(s.node), misfits_under(across));
    }
    std::stable_sort(judged.begin(), judged.end(), [](const Judged& x, const Judged& y) { return x.misfits > y.misfits; });
    std::vector<Retry> changes;
    std::vector<NodeId> changed_regions;  // the changed picks' two elements: one change per region and round
    std::vector<NodeId> region, near;
    auto meets = [&region](const std::vector<NodeId>& nodes) {
        for (NodeId x : region)
            if (std::find(nodes.begin(), nodes.end(), x) != nodes.end()) return true;
        return false;
    };
    for (const Judged& s : judged) {
        if (s.misfits == 0) break;  // the rest close
        if (certify_over_budget(work_ - work_before)) break;
        const uint64_t key = retry_key(s.a, s.b, s.picked);
        const NodeId across = h_.neighbor(s.node, s.edge);
        region.clear();
        add_once(region, s.node);
        add_once(region, across);
        const size_t inner = region.size();
        near = region;
        for (size_t i = 0; i < inner; ++i)
            for (int e = 0; e < 3; ++e) add_once(near, h_.neighbor(region[i], e));
        add_corner_fans(region, inner);
        if (std::binary_search(judged_picks_.begin(), judged_picks_.end(), key) && !meets(changed_regions_)) continue;
        if (meets(changed_regions)) continue;  // in the next round
        judged_picks_.push_back(key);
        // A candidate's subtree closes; one whose children misfit (read with the elements across
        // the two, no further) cannot, and is passed over at a fraction of the cost.
        const auto closes = [&](const Retry& retry, bool children_first) {
            const ForcedBefore before = force(retry);
            const bool closed_subtree =
                (!children_first || local_misfits(picked_level, picked_level + 1, near, inner, 1) == 0) &&
                local_misfits(picked_level, picked_level + kCertifyHorizon, region, inner, 1) == 0;
            put_back(before);
            return closed_subtree;
        };
        // The first candidate whose subtree closes replaces the pick if the pick's own does not
        // close here (a failing candidate stops at its first misfit, a closing pick runs to the
        // horizon: the pick is judged last, and only when it matters).
        const Retry as_made{picked_level, s.a, s.b, s.picked, 0, 0};
        Retry retries[kRepairCandidates];
        bool decided = false;  // a candidate replaced the pick, or the pick closed after all
        for (uint32_t i = 0; i < s.count; ++i) {
            retries[i] = Retry{picked_level, s.a, s.b, s.candidates[i], s.swap_edge[i], s.swap_edge[i] ? s.picked : 0};
            if (decided || !closes(retries[i], true)) continue;
            decided = true;
            if (closes(as_made, false)) continue;
            changes.push_back(retries[i]);
            changed_regions.insert(changed_regions.end(), region.begin(), region.begin() + long(inner));
        }
        if (decided || joint_over_budget()) continue;
        // No candidate closes alone: the best one may close with other picks moved too.
        const uint64_t joint_before = work_;
        if (joint_move(picked_level, region, inner, as_made, retries, s.count, changes))
            changed_regions.insert(changed_regions.end(), region.begin(), region.begin() + long(inner));
        joint_work_ += work_ - joint_before;
        work_ = joint_before;  // the certification's budget counts its own work
    }
    certify_work_ += work_ - work_before;
    work_ = work_before;
    std::sort(judged_picks_.begin(), judged_picks_.end());
    judged_picks_.erase(std::unique(judged_picks_.begin(), judged_picks_.end()), judged_picks_.end());
    changed_regions_.swap(changed_regions);
    if (changes.empty()) {
        restore(depth, level);
        return false;
    }
    for (const Retry& r : changes) force(r);
    depth = picked_level;
    restore(depth, level);
    return true;
}

}  // namespace amc
