#include "import/leaf_detour.h"

#include <algorithm>

namespace amc {

LeafDetour::LeafDetour(const LeafHalfedges& halfedges)
    : he_(halfedges),
      hops_a_(halfedges.vertex_count(), -1),
      hops_b_(halfedges.vertex_count(), -1) {}

// Breadth-first over the leaf mesh from `source`, up to max_hops; clears the previous search.
void LeafDetour::search(uint32_t source, std::vector<int>& hops, std::vector<uint32_t>& reached, int max_hops,
                        uint32_t* pending, uint32_t pending_count) {
    for (uint32_t x : reached) hops[x] = -1;
    reached.assign(1, source);
    hops[source] = 0;
    extend(hops, reached, 0, max_hops, pending, pending_count);
}

// Continues a search that has reached, in `reached`, every vertex within `radius` hops (those at
// `radius` not yet looked around), out to max_hops: the hop counts are a new search's, without
// walking the ball again.
void LeafDetour::extend(std::vector<int>& hops, std::vector<uint32_t>& reached, int radius, int max_hops,
                        uint32_t* pending, uint32_t pending_count) {
    // A vertex is final when first reached: once every pending one is, nothing asked changes.
    auto settle = [&](uint32_t x) {
        for (uint32_t i = 0; i < pending_count;) {
            if (pending[i] == x) {
                pending[i] = pending[--pending_count];
            } else {
                ++i;
            }
        }
    };
    const bool stops = pending_count > 0;
    for (uint32_t i = 0; i < pending_count;) {  // those the ball has reached already
        if (hops[pending[i]] >= 0) {
            pending[i] = pending[--pending_count];
        } else {
            ++i;
        }
    }
    size_t first = 0;  // the first vertex not looked around yet
    while (first < reached.size() && hops[reached[first]] < radius) ++first;
    for (size_t i = first; i < reached.size(); ++i) {
        if (stops && pending_count == 0) return;
        const uint32_t u = reached[i];
        if (hops[u] == max_hops) continue;
        walked_ += he_.degree(u);
        he_.for_each_neighbor_once(u, [&](uint32_t x) {
            if (hops[x] >= 0) return;
            hops[x] = hops[u] + 1;
            reached.push_back(x);
            settle(x);
        });
    }
}

bool LeafDetour::measure(uint32_t a, uint32_t b, int max_hops) {
    search(a, hops_a_, reached_a_, max_hops);
    if (hops_a_[b] < 0) return false;
    shortest_ = hops_a_[b];
    search(b, hops_b_, reached_b_, max_hops);
    return true;
}

bool LeafDetour::measure(uint32_t a, uint32_t b, int max_hops, const uint32_t* targets, uint32_t count) {
    // Whether b is within max_hops at all, from two balls of half the radius that meet: most
    // edges of the coarse levels are longer, and the whole ball around a is several times larger.
    search(a, hops_a_, reached_a_, (max_hops + 1) / 2);
    search(b, hops_b_, reached_b_, max_hops / 2);
    bool meet = false;
    for (uint32_t x : reached_b_) meet |= hops_a_[x] >= 0;
    if (!meet) return false;
    uint32_t pending[kMaxTargets + 1];
    count = count < kMaxTargets ? count : kMaxTargets;
    for (uint32_t i = 0; i < count; ++i) pending[i] = targets[i];
    pending[count] = b;
    extend(hops_a_, reached_a_, (max_hops + 1) / 2, max_hops, pending, count + 1);
    if (hops_a_[b] < 0) return false;
    shortest_ = hops_a_[b];
    for (uint32_t i = 0; i < count; ++i) pending[i] = targets[i];
    extend(hops_b_, reached_b_, max_hops / 2, max_hops, pending, count);
    return true;
}

int LeafDetour::detour(uint32_t c) const {
    return hops_a_[c] < 0 || hops_b_[c] < 0 ? kFar : hops_a_[c] + hops_b_[c] - shortest_;
}

uint32_t LeafDetour::keep_least_detour(uint32_t a, uint32_t b, int max_hops, uint32_t* candidates, uint32_t count) {
    Answer* answer = nullptr;
    if (count <= kRemembered && max_hops < 256) {
        if (answers_.empty()) answers_.resize(kAnswerSlots);
        uint64_t key = (uint64_t(a) << 32 | b) * 0x9e3779b97f4a7c15ull;
        for (uint32_t i = 0; i < count; ++i) key = (key ^ candidates[i]) * 0xbf58476d1ce4e5b9ull;
        answer = &answers_[(key >> 40) & (kAnswerSlots - 1)];
        bool same = answer->count == count && answer->a == a && answer->b == b && answer->max_hops == max_hops;
        for (uint32_t i = 0; same && i < count; ++i) same = answer->candidate[i] == candidates[i];
        if (same) {
            uint32_t kept = 0;
            for (uint32_t i = 0; i < count; ++i) {
                if ((answer->kept >> i) & 1) candidates[kept++] = candidates[i];
            }
            return kept;
        }
    }
    uint32_t kept_mask = (1u << count) - 1;  // b farther than max_hops: all kept
    if (measure(a, b, max_hops, candidates, count)) {
        int least = kFar;
        for (uint32_t i = 0; i < count; ++i) least = std::min(least, detour(candidates[i]));
        kept_mask = 0;
        for (uint32_t i = 0; i < count; ++i) kept_mask |= uint32_t(detour(candidates[i]) == least) << i;
    }
    if (answer) {
        answer->a = a;
        answer->b = b;
        for (uint32_t i = 0; i < count; ++i) answer->candidate[i] = candidates[i];
        answer->count = uint8_t(count);
        answer->max_hops = uint8_t(max_hops);
        answer->kept = uint8_t(kept_mask);
    }
    uint32_t kept = 0;
    for (uint32_t i = 0; i < count; ++i) {
        if ((kept_mask >> i) & 1) candidates[kept++] = candidates[i];
    }
    return kept;
}

}  // namespace amc
