// Joint moves of guided picks (docs/IMPORT.md, "Joint moves"): where no single candidate of a
// judged pick closes its subtree, the candidate that leaves the fewest misfits is forced together
// with other vertices for the picks its misfits blame (of the same level, or finer ones made inside
// the judgement), one move at a time, each the one that removes the most misfits. The group is
// certified by the same test as a single change: its subtree closes, while the pick as made,
// given the same search, does not. Wrong picks that hold each other in place (a lattice line
// shifted by a quarter, the edges around a wrong vertex) and a coarse truth whose subtree misfits
// only through the finer picks the judgement makes are moved this way.
#include "import/reconstruction.h"

#include <algorithm>
#include <vector>

namespace amc {

void Reconstruction::blame_vertex(VertexId v) {
    if (!guided(v) || v >= pick_level_.size() || pick_level_[v] < blame_from_) return;
    const uint64_t key = pick_edge_[v];
    for (Blame& b : *blames_) {
        if (edge_key(b.a, b.b) == key) {
            ++b.count;
            return;
        }
    }
    blames_->push_back({pick_level_[v], uint32_t(key >> 32), uint32_t(key), leaf_of_vertex_[v], 1});
}

uint32_t Reconstruction::joint_candidates(uint32_t a, uint32_t b, uint32_t vertex, uint32_t* out) {
    const Vec3 pa = leaf_.positions[a], pb = leaf_.positions[b];
    const Vec3 ab = pb - pa;
    auto usable = [&](uint32_t v) { return v != vertex && vertex_of_leaf_[v] == kNoIndex; };
    uint32_t count = nearest_usable(0.5 * (pa + pb), usable, NearestVertex::kMaxCount, out, exact_dot(ab, ab));
    // The truth of a wrong pick that is not among the nearest is most often next to it (measured).
    for_each_neighbor(vertex, [&](uint32_t w) {
        if (count < kMaxJointCandidates && usable(w) && std::find(out, out + count, w) == out + count) out[count++] = w;
    });
    return count;
}

bool Reconstruction::closes_jointly(int level, const std::vector<NodeId>& region, size_t inner, const Retry& first,
                                    int misfits, std::vector<Retry>& moves) {
    const int depth = level + kCertifyHorizon;
    moves.assign(1, first);
    std::vector<ForcedBefore> forced{force(first)};
    std::vector<Blame> blames;
    int best = misfits;
    try {
        while (best > 0 && int(moves.size()) < kJointMoves) {
            blames.clear();
            blames_ = &blames;
            blame_from_ = level;
            local_misfits(level, depth, region, inner);
            blames_ = nullptr;
            blames.erase(std::remove_if(blames.begin(), blames.end(),
                                        [&](const Blame& b) {
                                            for (const Retry& m : moves)
                                                if (edge_key(m.a, m.b) == edge_key(b.a, b.b)) return true;
                                            return false;
                                        }),
                         blames.end());
            std::stable_sort(blames.begin(), blames.end(), [](const Blame& x, const Blame& y) { return x.count > y.count; });
            Retry best_move{};
            int best_after = best;
            for (size_t i = 0; i < blames.size() && i < size_t(kJointSuspects); ++i) {
                const Blame& suspect = blames[i];
                uint32_t candidates[kMaxJointCandidates];
                const uint32_t count = joint_candidates(suspect.a, suspect.b, suspect.vertex, candidates);
                for (uint32_t c = 0; c < count; ++c) {
                    const Retry move{suspect.level, suspect.a, suspect.b, candidates[c], 0, 0};
                    const ForcedBefore before = force(move);
                    const int after = local_misfits(level, depth, region, inner, best_after);
                    put_back(before);
                    if (after < best_after) {
                        best_after = after;
                        best_move = move;
                    }
                }
            }
            if (best_after >= best) break;
            forced.push_back(force(best_move));
            moves.push_back(best_move);
            best = best_after;
        }
    } catch (...) {
        blames_ = nullptr;
        for (size_t i = forced.size(); i-- > 0;) put_back(forced[i]);
        throw;
    }
    for (size_t i = forced.size(); i-- > 0;) put_back(forced[i]);
    return best == 0;
}

bool Reconstruction::joint_move(int level, const std::vector<NodeId>& region, size_t inner, const Retry& as_made,
                                const Retry* retries, uint32_t count, std::vector<Retry>& changes) {
    const auto misfits_with = [&](const Retry& retry, int cap) {
        const ForcedBefore before = force(retry);
        const int misfits = local_misfits(level, level + kCertifyHorizon, region, inner, cap);
        put_back(before);
        return misfits;
    };
    // Counted no further than needed: a group of kJointMoves rarely closes more misfits than that.
    const int pick_misfits = misfits_with(as_made, kJointMisfits + 1);
    int fewest = std::min(pick_misfits, kJointMisfits + 1);
    const Retry* best = nullptr;
    for (uint32_t i = 0; i < count; ++i) {
        const int misfits = misfits_with(retries[i], fewest);
        if (misfits < fewest) {
            fewest = misfits;
            best = &retries[i];
        }
    }
    std::vector<Retry> moves, pick_moves;
    if (!best || !closes_jointly(level, region, inner, *best, fewest, moves)) return false;
    // The same search for the pick as made: if it closes too, the subtree does not tell them apart.
    if (closes_jointly(level, region, inner, as_made, pick_misfits, pick_moves)) return false;
    // The finer picks of the group only certified it: their own levels judge them.
    for (const Retry& m : moves)
        if (m.level == level) changes.push_back(m);
    return true;
}

}  // namespace amc
