// The inverse step's patch search: growing patches from seeds, committing them best first,
// improving them, and the coarser level they leave.
#include "import/level_finder.h"

#include "common/no_index.h"

#include <algorithm>
#include <utility>

namespace amc::detail::inverse {

namespace {

// More than one invalid block in this many: a wrong reading, not a true patch with a few wrong
// turns. Such a patch is not repaired, and a growth that shows that share is given up.
constexpr uint32_t kRepairableShare = 16;
// Settled blocks before a growth is judged by its share: a smaller sample misjudges.
constexpr uint32_t kJudgedAfter = 512;
// Settled blocks before an exploring growth is judged by its seed block.
constexpr uint32_t kSeedJudgedAfter = 128;
// Blocks: smaller patches are taken or dropped whole (not repaired, their seed not questioned).
constexpr uint32_t kRepairable = 16;
// Blocks of the patches the last sweep looks for (commit_small_patches).
constexpr uint32_t kSmallPatch = 16;
// Blocks: improve_patches solves again around patches of at most kImproved blocks; a growth
// there larger than kRivalGrowth is no local rival but the large reading of a level not ready
// yet, which fails again at every step (docs/IMPORT.md, "Rivals of small patches bounded").
constexpr uint32_t kImproved = 64;
constexpr uint32_t kRivalGrowth = 256;
// A growth of at least kBlockedGrowth blocks that fails on at most kFewInvalid: a true patch whose
// invalid sides may run across the parent of an earlier step's wrong block (LevelFinder::blockers).
constexpr uint32_t kBlockedGrowth = 256;
constexpr size_t kFewInvalid = 4;

}  // namespace

std::vector<uint32_t> LevelFinder::local_order(const std::vector<Triangle>& fine, uint32_t vertex_count) {
    // A counting sort by smallest vertex, stable.
    std::vector<uint32_t> start(size_t(vertex_count) + 1, 0);
    auto smallest = [&](uint32_t t) { return std::min({fine[t][0], fine[t][1], fine[t][2]}); };
    for (uint32_t t = 0; t < fine.size(); ++t) ++start[smallest(t) + 1];
    for (uint32_t v = 0; v < vertex_count; ++v) start[v + 1] += start[v];
    std::vector<uint32_t> order(fine.size());
    for (uint32_t t = 0; t < fine.size(); ++t) order[start[smallest(t)]++] = t;
    return order;
}

std::vector<uint32_t> LevelFinder::inverse(const std::vector<uint32_t>& order) {
    std::vector<uint32_t> out(order.size());
    for (uint32_t i = 0; i < order.size(); ++i) out[order[i]] = i;
    return out;
}

size_t LevelFinder::commit(const std::vector<uint8_t>* active) {
    const size_t first = patches_.size();
    std::vector<uint32_t> seeds;
    for (uint32_t c = 0; c < local_of_.size(); ++c) {
        if (!active || (*active)[c]) seeds.push_back(local_of_[c]);
    }
    if (active) seeds = free_near(std::move(seeds), 2);
    const std::vector<uint32_t> region = seeds;
    for (int round = 0; round < 4 && !seeds.empty(); ++round) {
        const size_t before = patches_.size();
        if (commit_best_first(seeds) == 0 || cancelled()) break;
        // The next round seeds only near what this one committed.
        seeds = free_triangles_near(before);
    }
    if (cancelled()) return patches_.size();
    commit_small_patches(region);
    improve_patches(first);
    return patches_.size();
}

void LevelFinder::commit_small_patches(const std::vector<uint32_t>& region) {
    // Most red-readable sides first, the caller's order among equals (a stable counting sort).
    std::array<std::vector<uint32_t>, 5> by_sides;
    for (uint32_t t : region) {
        if (!taken(t)) by_sides[4 - readable_sides(t)].push_back(t);
    }
    std::vector<uint32_t> seeds;
    for (const std::vector<uint32_t>& bucket : by_sides) seeds.insert(seeds.end(), bucket.begin(), bucket.end());
    growth_limit_ = kSmallPatch;
    commit_best_first(seeds);
    growth_limit_ = kNoIndex;
}

uint32_t LevelFinder::readable_sides(uint32_t t) const {
    const Block* b = possible_block(t);
    if (b == nullptr) return 0;
    const std::array<Fan, 3> fans = b->fan;  // a copy: possible_block below moves shapes_
    uint32_t count = 1;
    for (const Fan& fan : fans) {
        count += fan.kind == Fan::boundary ||
                 (fan.kind == Fan::triangles && fan.size == 3 && possible_block(fan.triangle(1)) != nullptr);
    }
    return count;
}

uint32_t LevelFinder::removed_by(size_t id) const {
    uint32_t removed = 0;
    const Patch& patch = patches_[id];
    for (uint32_t i = patch.first; i < patch.end; ++i) {
        if (!blocks_[i].alive) continue;
        for (uint32_t m : blocks_[i].m) removed += midpoint_block_[m][0] / 3 == i || midpoint_block_[m][0] / 3 < patch.first;
    }
    return removed;
}

bool LevelFinder::could_be_in_block(uint32_t caller_t) {
    const uint32_t t = local_of_[caller_t];
    uint32_t centers[4] = {t, kNoIndex, kNoIndex, kNoIndex};
    for (int e = 0; e < 3; ++e) {
        const uint32_t h = adjacency_.twin(3 * t + uint32_t(e));
        if (h != kNoHalfEdge) centers[e + 1] = h / 3;
    }
    for (uint32_t c : centers) {
        if (c == kNoIndex) continue;
        const uint32_t start = uint32_t(blocks_.size());
        if (!place_block(c)) continue;
        roll_back(start);
        return true;
    }
    return false;
}

void LevelFinder::release_patch(size_t id) {
    hold(uint32_t(id), false);
    for (uint32_t i = patches_[id].first; i < patches_[id].end; ++i) {
        if (blocks_[i].alive) deferred_[blocks_[i].center] = 1;
    }
    for (uint32_t i = patches_[id].first; i < patches_[id].end; ++i) {
        if (blocks_[i].alive) release(i);
    }
}

std::vector<uint32_t> LevelFinder::parents_of(size_t id, const std::vector<uint32_t>& parent_of_block) const {
    std::vector<uint32_t> parents;
    for (uint32_t i = patches_[id].first; i < patches_[id].end; ++i) {
        if (blocks_[i].alive) parents.push_back(parent_of_block[i]);
    }
    return parents;
}

CoarserLevel LevelFinder::coarser_level(std::vector<uint32_t>* parent_of_block) const {
    CoarserLevel out;
    if (parent_of_block) parent_of_block->assign(blocks_.size(), kNoIndex);
    std::vector<uint8_t> merged(tri_.size(), 0);
    // The coarser level has fewer triangles than this one: no reallocation on the way.
    out.triangles.reserve(tri_.size());
    out.refined.reserve(tri_.size());
    out.changed.reserve(tri_.size());
    for (uint32_t index = 0; index < blocks_.size(); ++index) {
        const Block& b = blocks_[index];
        if (!b.alive) continue;
        ++out.red_blocks;
        if (parent_of_block) (*parent_of_block)[index] = uint32_t(out.triangles.size());
        out.triangles.push_back({b.v[0], b.v[1], b.v[2]});
        out.splits.push_back({b.v[0], b.v[1], b.v[2], b.m[0], b.m[1], b.m[2]});
        out.refined.push_back(1);
        out.changed.push_back(1);
        merged[b.center] = 1;
        for (int k = 0; k < 3; ++k) merged[b.corner[size_t(k)]] = 1;
        for (int i = 0; i < 3; ++i) {
            const Side side = classify(index, i);
            if (side.kind == Side::green && side.emits) {
                ++out.green_groups;
                out.triangles.push_back(side.coarse);
                out.refined.push_back(0);
                out.changed.push_back(1);
                for (int k = 0; k < side.count; ++k) merged[side.group[k]] = 1;
            }
        }
    }
    if (out.red_blocks == 0) return CoarserLevel{};
    for (uint32_t t : local_of_) {
        if (merged[t]) continue;
        out.triangles.push_back(tri_[t]);
        out.refined.push_back(refined_[t]);
        out.changed.push_back(deferred_[t]);
    }
    for (uint32_t v = 0; v < midpoint_count_.size(); ++v) out.removed_vertices += midpoint_count_[v] != 0;
    return out;
}

std::vector<Triangle> LevelFinder::blockers() const {
    std::vector<uint32_t> sorted = blockers_;
    std::sort(sorted.begin(), sorted.end(), [&](uint32_t a, uint32_t b) { return caller_of_[a] < caller_of_[b]; });
    sorted.erase(std::unique(sorted.begin(), sorted.end()), sorted.end());
    std::vector<Triangle> out;
    for (uint32_t t : sorted) out.push_back(tri_[t]);
    return out;
}

uint32_t LevelFinder::grow_patch(uint32_t t, Preference preference, bool exploring) {
    constexpr int kRepairs = 4;
    std::vector<uint32_t> banned, suspects;
    uint32_t removed = 0;
    for (int attempt = 0;; ++attempt) {
        suspects.clear();
        removed = grow_patch_once(t, preference, exploring, attempt < kRepairs ? &suspects : nullptr);
        if (removed != 0 || suspects.empty()) break;
        const size_t before = banned.size();
        for (uint32_t c : suspects) {
            if (!repair_banned_[c]) repair_banned_[c] = 1, banned.push_back(c);
        }
        if (banned.size() == before) break;  // nothing new to take away: the same growth again
    }
    for (uint32_t c : banned) repair_banned_[c] = 0;
    return removed;
}

void LevelFinder::collect_suspects(const std::vector<uint32_t>& invalid, std::vector<uint32_t>& suspects) const {
    for_each_invalid_fan(invalid, [&](uint32_t i, const Fan& fan) {
        for (int k = 0; k < fan.size; ++k) {
            const uint32_t owner = block_of_[fan.triangle(k)];
            if (owner != kNoIndex && owner != i) suspects.push_back(blocks_[owner].center);
        }
        Block across;
        if (fan.size != 3 || !read_block(fan.triangle(1), across)) return;
        for (uint32_t v : across.v) {
            for (uint8_t k = 0; k < midpoint_count_[v]; ++k) suspects.push_back(blocks_[midpoint_block_[v][k] / 3].center);
        }
    });
    if (suspects.empty()) {
        for (uint32_t i : invalid) suspects.push_back(blocks_[i].center);
    }
}

uint32_t LevelFinder::grow_patch_once(uint32_t t, Preference preference, bool exploring, std::vector<uint32_t>* suspects) {
    const uint32_t start = uint32_t(blocks_.size());
    if (!place_block(t)) return 0;
    uint32_t settled = start, settled_invalid = 0;
    // A growth bounded below 2 * kJudgedAfter blocks is never judged by its share of invalid
    // settled blocks (there are never kJudgedAfter of them): they need not be counted.
    const bool judged = growth_limit_ >= 2 * kJudgedAfter;
    // A reading given up in this round is seeded again wherever its seeds were not among the
    // centers it placed (random in a user's face order): such a growth, once it has placed a block
    // on one of those centers and settled an invalid block, is given up too (docs/IMPORT.md,
    // "Retraced readings given up"). Only judged growths settle invalid blocks.
    const bool watch_retrace = give_up_retraced_ && exploring && judged;
    const uint8_t bit = uint8_t(1u << int(preference));
    uint32_t looked_at = start;
    bool on_given_up = false;
    for (uint32_t next = start; next < blocks_.size(); ++next) {
        for (; settled < start + (next - start) / 2; ++settled) settled_invalid += judged && !sides_valid(settled);
        for (; watch_retrace && !on_given_up && looked_at < blocks_.size(); ++looked_at)
            on_given_up = (given_up_[blocks_[looked_at].center] & bit) != 0;
        const bool retracing = on_given_up && settled_invalid > 0;
        if (retracing || hopeless(start, settled, settled_invalid, exploring)) {
            if (watch_retrace && (retracing || settled - start >= kJudgedAfter)) mark_given_up(start, preference);
            mark_explored(start, preference, exploring);
            roll_back(start);
            return 0;
        }
        for (int i = 0; i < 3; ++i) {
            const Fan& side = blocks_[next].fan[size_t(i)];
            if (side.kind != Fan::triangles || block_of_[side.triangle(1)] != kNoIndex) continue;
            const Fan fan = side;  // a copy: placing blocks moves blocks_
            if (preference == Preference::closure_first) {
                const uint32_t partner = closure_partner(blocks_[next], i, fan);
                if (partner != kNoIndex) {
                    // Block first places no partner across two triangles, and across three
                    // places the block across instead where it fits: then the growths differ.
                    bool across_fits = false;
                    if (!preference_mattered_ && fan.size == 3) {
                        const uint32_t size = uint32_t(blocks_.size());
                        if (place_block(fan.triangle(1))) across_fits = true, roll_back(size);
                    }
                    if (place_block(partner)) {
                        if (fan.size == 2 || across_fits) preference_mattered_ = true;
                        continue;
                    }
                }
                if (fan.size == 3) place_block(fan.triangle(1));
            } else if (fan.size == 3 && !place_block(fan.triangle(1))) {
                const uint32_t partner = closure_partner(blocks_[next], i, fan);
                if (partner != kNoIndex) place_block(partner);
            }
        }
    }
    mark_explored(start, preference, exploring);
    // A patch with invalid blocks is dropped; a large one with few is repaired (its suspects
    // collected), one with many is a wrong reading, not a true one with a few wrong turns.
    const uint32_t size = uint32_t(blocks_.size()) - start;
    const bool repairable = suspects && size >= kRepairable;
    // Only the whole set of invalid blocks counts, or that there are too many: the blocks placed
    // last, on the front where a wrong reading ends, are checked first.
    std::vector<uint32_t> invalid;
    for (uint32_t i = uint32_t(blocks_.size()); i-- > start;) {
        if (sides_valid(i)) continue;
        invalid.push_back(i);
        const bool counting = repairable ? invalid.size() * kRepairableShare <= size
                                         : size >= kBlockedGrowth && invalid.size() <= kFewInvalid;
        if (!counting) break;
    }
    std::reverse(invalid.begin(), invalid.end());
    if (!invalid.empty()) {
        // A large growth held by a few blocks: what refined triangles stood in their way.
        if (size >= kBlockedGrowth && invalid.size() <= kFewInvalid) {
            for_each_invalid_fan(invalid, [&](uint32_t i, const Fan& fan) {
                for (int k = 0; k < fan.size; ++k) {
                    const uint32_t g = fan.triangle(k);
                    if (refined_[g]) blockers_.push_back(g);
                    for (int f = 0; f < 3; ++f) {
                        const uint32_t h = adjacency_.twin(3 * g + uint32_t(f));
                        if (h != kNoHalfEdge && refined_[h / 3] && block_of_[h / 3] != i) blockers_.push_back(h / 3);
                    }
                }
            });
        }
        if (repairable && invalid.size() * kRepairableShare <= size) collect_suspects(invalid, *suspects);
        roll_back(start);
        return 0;
    }
    // A valid patch: no other reading needs to seed inside it.
    if (exploring) {
        for (uint32_t i = start; i < blocks_.size(); ++i) {
            covered_[blocks_[i].center] = 3;
            for (uint32_t c : blocks_[i].corner) covered_[c] = 3;
        }
    }
    uint32_t removed = 0;
    for (uint32_t i = start; i < blocks_.size(); ++i) {
        for (int e = 0; e < 3; ++e) {
            const auto& slots = midpoint_block_[blocks_[i].m[size_t(e)]];
            removed += slots[0] / 3 == i || (slots[0] / 3 < start && slots[1] / 3 == i);  // count each once
        }
    }
    return removed;
}

std::pair<uint32_t, uint32_t> LevelFinder::without_glued_seed(uint32_t start, Preference preference, uint32_t removed) {
    const uint32_t seed = blocks_[start].center;
    for (uint32_t m : blocks_[start].m) {
        if (midpoint_count_[m] > 1) return {seed, removed};  // joined by a midpoint: not glued
    }
    std::vector<uint32_t> rest;
    for (uint32_t i = start + 1; i < blocks_.size(); ++i) rest.push_back(blocks_[i].center);
    const std::vector<Block> grown(blocks_.begin() + start, blocks_.end());
    roll_back(start);
    repair_banned_[seed] = 1;
    const uint32_t without = grow_patch(rest.front(), preference);
    repair_banned_[seed] = 0;
    bool same = without > 0 && blocks_.size() - start == rest.size();
    for (size_t k = 0; same && k < rest.size(); ++k) {
        same = block_of_[rest[k]] != kNoIndex && blocks_[block_of_[rest[k]]].center == rest[k];
    }
    if (same) return {rest.front(), without};
    roll_back(start);
    // The patch as grown before (claimed in the same order, so the labels are the same as if it
    // were grown again from the seed, at a fraction of the cost).
    for (const Block& b : grown) {
        blocks_.push_back(b);
        claim(uint32_t(blocks_.size() - 1));
    }
    return {seed, removed};
}

bool LevelFinder::hopeless(uint32_t start, uint32_t settled, uint32_t settled_invalid, bool exploring) const {
    if (blocks_.size() - start > growth_limit_) return true;
    const uint32_t count = settled - start;
    if (count >= kJudgedAfter && settled_invalid * kRepairableShare > count) return true;
    // An invalid seed block: this seed misreads a patch that seeds inside it read right.
    return exploring && count == kSeedJudgedAfter && !sides_valid(start);
}

void LevelFinder::mark_explored(uint32_t start, Preference preference, bool exploring) {
    // Growth from any center of this patch would give the same patch under this preference:
    // those centers need not seed again (this keeps the seeds linear).
    if (!exploring) return;
    const uint8_t bit = uint8_t(1u << int(preference));
    for (uint32_t i = start; i < blocks_.size(); ++i) {
        covered_[blocks_[i].center] |= bit;
        explored_.push_back(blocks_[i].center);
    }
}

void LevelFinder::mark_given_up(uint32_t start, Preference preference) {
    const uint8_t bit = uint8_t(1u << int(preference));
    for (uint32_t i = start; i < blocks_.size(); ++i) {
        const uint32_t c = blocks_[i].center;
        if (given_up_[c] == 0) given_up_list_.push_back(c);
        given_up_[c] |= bit;
    }
}

Candidate LevelFinder::best_patch(uint32_t t, bool exploring, uint8_t failed) {
    Candidate best{0, t, Preference::closure_first};
    bool same_either_way = false;  // the closure-first growth met no side that block first reads otherwise
    for (Preference preference : {Preference::closure_first, Preference::block_first}) {
        if ((failed >> int(preference)) & 1) continue;
        if (exploring && (covered_[t] >> int(preference)) & 1) continue;
        if (same_either_way) {
            // Block first would grow the same blocks: the same answer, the same centers explored.
            const uint8_t bit = uint8_t(1u << int(preference));
            for (uint32_t c : explored_) covered_[c] |= bit;
            continue;
        }
        preference_mattered_ = false;
        explored_.clear();
        const uint32_t start = uint32_t(blocks_.size());
        const uint32_t removed = grow_patch(t, preference, exploring);
        roll_back(start);
        if (removed > best.removed) best = {removed, t, preference};
        same_either_way = preference == Preference::closure_first && !preference_mattered_;
        preference_mattered_ = true;  // other growths need not ask
    }
    return best;
}

uint32_t LevelFinder::commit_best_first(const std::vector<uint32_t>& seeds) {
    std::vector<Candidate> queue;
    for (uint32_t t : seeds) covered_[t] = 0;
    for (uint32_t t : given_up_list_) given_up_[t] = 0;  // a reading given up is judged again in each round
    given_up_list_.clear();
    for (uint32_t t : seeds) {
        if (covered_[t] == 3 || block_of_[t] != kNoIndex) continue;
        if (cancelled()) return 0;
        const Candidate c = best_patch(t, true);
        if (c.removed > 0) queue.push_back(c);
    }
    auto worse = [this](const Candidate& a, const Candidate& b) { return this->worse(a, b); };
    std::make_heap(queue.begin(), queue.end(), worse);
    uint32_t total = 0;
    while (!queue.empty() && !cancelled()) {
        std::pop_heap(queue.begin(), queue.end(), worse);
        Candidate c = queue.back();
        queue.pop_back();
        const uint32_t start = uint32_t(blocks_.size());
        c.removed = grow_patch(c.center, c.preference);
        if (c.removed > 0 && blocks_.size() - start >= kRepairable) {
            const auto [seed, removed] = without_glued_seed(start, c.preference, c.removed);
            c = {removed, seed, c.preference};
        }
        if (c.removed > 0 && (queue.empty() || !worse(c, queue.front()))) {
            patches_.push_back({start, uint32_t(blocks_.size())});
            hold(uint32_t(patches_.size() - 1), true);
            total += c.removed;
            continue;
        }
        roll_back(start);
        // The labels are as they were for the growth that just failed: it would fail again.
        if (c.removed == 0) c = best_patch(c.center, false, uint8_t(1u << int(c.preference)));
        if (c.removed == 0) {
            deferred_[c.center] = 1;  // valid once: worth a seed in the next step
            continue;
        }
        queue.push_back(c);
        std::push_heap(queue.begin(), queue.end(), worse);
    }
    return total;
}

std::vector<uint32_t> LevelFinder::free_triangles_near(size_t first) {
    std::vector<uint32_t> ring;
    for (size_t id = first; id < patches_.size(); ++id) {
        for (uint32_t i = patches_[id].first; i < patches_[id].end; ++i) {
            if (!blocks_[i].alive) continue;
            ring.push_back(blocks_[i].center);
            for (uint32_t c : blocks_[i].corner) ring.push_back(c);
        }
    }
    return free_near(std::move(ring), 2);
}

std::vector<uint32_t> LevelFinder::free_near(std::vector<uint32_t> ring, int rings) const {
    std::vector<uint8_t> reached(tri_.size(), 0);
    std::vector<uint32_t> unique;
    for (uint32_t t : ring) {
        if (!reached[t]) reached[t] = 1, unique.push_back(t);
    }
    ring = std::move(unique);
    for (size_t step = 0, begin = 0; step < size_t(rings); ++step) {
        const size_t end = ring.size();
        for (size_t k = std::exchange(begin, end); k < end; ++k) {
            for (int e = 0; e < 3; ++e) {
                const uint32_t h = adjacency_.twin(3 * ring[k] + uint32_t(e));
                if (h != kNoHalfEdge && !reached[h / 3]) reached[h / 3] = 1, ring.push_back(h / 3);
            }
        }
    }
    // In the caller's order: a scan of every triangle when the rings cover most of them, else a
    // sort of those reached (a scan in the caller's order reads the local arrays at random).
    std::vector<uint32_t> free;
    if (ring.size() * 8 > tri_.size()) {
        for (uint32_t t : local_of_) {
            if (reached[t] && !taken(t)) free.push_back(t);
        }
        return free;
    }
    for (uint32_t t : ring) {
        if (!taken(t)) free.push_back(t);
    }
    std::sort(free.begin(), free.end(), [&](uint32_t a, uint32_t b) { return caller_of_[a] < caller_of_[b]; });
    return free;
}

void LevelFinder::hold(uint32_t id, bool on) {
    const Patch& patch = patches_[id];
    std::vector<Side> closures;
    // Read with the patch's id on its blocks (the triangles it holds carry that id, so a
    // release reads its closures as such), then set.
    for (uint32_t i = patch.first; i < patch.end; ++i) {
        if (blocks_[i].alive) blocks_[i].patch = id;
    }
    for (uint32_t i = patch.first; i < patch.end; ++i) {
        if (!blocks_[i].alive) continue;
        for (int e = 0; e < 3; ++e) {
            const Side side = classify(i, e);
            if (side.kind == Side::green) closures.push_back(side);
        }
        if (!on) blocks_[i].patch = kNoIndex;
    }
    for (const Side& side : closures) {
        for (int k = 0; k < side.count; ++k) closure_of_[side.group[k]] = on ? id : kNoIndex;
        for (uint32_t v : side.coarse) on ? ++pinned_old_[v] : --pinned_old_[v];
    }
}

void LevelFinder::improve_patches(size_t first) {
    const size_t count = patches_.size();
    for (size_t r = first; r < count && !cancelled(); ++r) {
        const Patch patch = patches_[r];
        uint32_t before = 0;
        std::vector<uint32_t> seeds, taken;
        for (uint32_t i = patch.first; i < patch.end; ++i) {
            const Block& b = blocks_[i];
            if (!b.alive) continue;
            taken.push_back(i);
            for (uint32_t t : {b.center, b.corner[0], b.corner[1], b.corner[2]}) {
                seeds.push_back(t);
                for (int e = 0; e < 3; ++e) {
                    const uint32_t h = adjacency_.twin(3 * t + uint32_t(e));
                    if (h != kNoHalfEdge) seeds.push_back(h / 3);
                }
            }
            for (uint32_t m : b.m) before += midpoint_block_[m][0] / 3 == i || midpoint_block_[m][0] / 3 < patch.first;
        }
        if (taken.empty() || taken.size() > kImproved) continue;  // large patches have no rival nearby
        std::sort(seeds.begin(), seeds.end(), [&](uint32_t a, uint32_t b) { return caller_of_[a] < caller_of_[b]; });
        seeds.erase(std::unique(seeds.begin(), seeds.end()), seeds.end());
        hold(uint32_t(r), false);
        for (uint32_t i : taken) release(i), banned_[blocks_[i].center] = 1;
        const uint32_t start = uint32_t(blocks_.size());
        const size_t patches_before = patches_.size();
        growth_limit_ = kRivalGrowth;
        const uint32_t after = commit_best_first(seeds);
        growth_limit_ = kNoIndex;
        for (uint32_t i : taken) banned_[blocks_[i].center] = 0;
        if (after > before) continue;
        for (size_t k = patches_.size(); k-- > patches_before;) hold(uint32_t(k), false);
        roll_back(start);
        patches_.resize(patches_before);
        for (uint32_t i : taken) claim(i);
        hold(uint32_t(r), true);
    }
}

}  // namespace amc::detail::inverse
