// How far a candidate for the vertex that splits a short edge (a, b) lies off the shortest paths
// from a to b in the leaf mesh (docs/IMPORT.md, "The chain decides the fine levels"): the true
// vertex lies on the chain of leaf edges along (a, b), which at the fine levels is a shortest
// path or one hop longer.
#pragma once

#include "import/leaf_halfedges.h"

#include <cstdint>
#include <vector>

namespace amc {

class LeafDetour {
public:
    explicit LeafDetour(const LeafHalfedges& halfedges);

    // Measures from a and b, up to max_hops; false when b is farther than that from a.
    bool measure(uint32_t a, uint32_t b, int max_hops);
    // The same for the detours of `targets` (at most kMaxTargets) only: each search stops once
    // it has reached them (and b), which at the fine levels is long before max_hops.
    bool measure(uint32_t a, uint32_t b, int max_hops, const uint32_t* targets, uint32_t count);
    static constexpr uint32_t kMaxTargets = 8;
    // hops(a, c) + hops(c, b) - hops(a, b) after measure(a, b, ...), or kFar when c is farther.
    int detour(uint32_t c) const;
    static constexpr int kFar = 1 << 20;

    // Keeps, in order at the front, those of `candidates` (at least two) with the least detour
    // when b is within max_hops of a; returns how many (`count` when b is farther). The answer
    // depends on the leaf mesh alone, and the certification of picks asks the same edge with the
    // same candidates again and again (93% of the calls of a 10^5-face refusal): answers for up to
    // kRemembered candidates are remembered.
    uint32_t keep_least_detour(uint32_t a, uint32_t b, int max_hops, uint32_t* candidates, uint32_t count);
    static constexpr uint32_t kRemembered = 4;
    // The faces around the vertices the searches so far looked around (a caller's budget).
    uint64_t walked() const { return walked_; }

private:
    // One remembered answer: the question, and which candidates it kept (bit i: candidate i).
    struct Answer {
        uint32_t a = 0, b = 0;
        uint32_t candidate[kRemembered] = {};
        uint8_t count = 0;  // 0: empty
        uint8_t max_hops = 0;
        uint8_t kept = 0;
    };
    static constexpr uint32_t kAnswerSlots = 1u << 16;  // direct-mapped; a clash forgets the older answer

    // Breadth-first from source up to max_hops, or until every one of `pending` is reached.
    void search(uint32_t source, std::vector<int>& hops, std::vector<uint32_t>& reached, int max_hops,
                uint32_t* pending = nullptr, uint32_t pending_count = 0);
    // Goes on with the last search, which reached every vertex within `radius` hops, out to max_hops.
    void extend(std::vector<int>& hops, std::vector<uint32_t>& reached, int radius, int max_hops,
                uint32_t* pending, uint32_t pending_count);

    const LeafHalfedges& he_;
    std::vector<int> hops_a_, hops_b_;  // -1: not reached
    std::vector<uint32_t> reached_a_, reached_b_;
    int shortest_ = 0;
    std::vector<Answer> answers_;  // allocated on the first question
    uint64_t walked_ = 0;
};

}  // namespace amc
