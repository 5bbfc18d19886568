// Directed-edge index of a triangle mesh (the leaf mesh being imported): the face on the left of
// u->v, its third vertex, and the fan of faces around a vertex. Built in linear time.
#pragma once

#include "common/no_index.h"

#include <amc/mesh.h>

#include <algorithm>
#include <cstdint>
#include <memory>
#include <vector>

namespace amc {

class LeafHalfedges {
public:

    explicit LeafHalfedges(const TriangleMesh& mesh);

    // The face that holds the directed edge u->v, or kNoIndex.
    uint32_t face(uint32_t u, uint32_t v) const {
        const Entry* e = find(u, v);
        return e == nullptr ? kNoIndex : e->face & kFaceBits;
    }
    // The third vertex of that face, or kNoIndex.
    uint32_t apex(uint32_t u, uint32_t v) const {
        const Entry* e = find(u, v);
        return e == nullptr ? kNoIndex : e->apex;
    }
    // The face on the left of a directed edge and its third vertex (kNoIndex for both: no face).
    struct Edge {
        uint32_t face = kNoIndex, apex = kNoIndex;
    };
    // The edge u->v: face() and apex() in one lookup.
    Edge edge(uint32_t u, uint32_t v) const {
        const Entry* e = find(u, v);
        return e == nullptr ? Edge{} : Edge{e->face & kFaceBits, e->apex};
    }
    // Number of faces around u (the directed edges leaving u).
    uint32_t degree(uint32_t u) const { return slots_[u + 1].start - slots_[u].start; }
    // The i-th directed edge leaving u (in no particular order): its end and its face.
    uint32_t out_vertex(uint32_t u, uint32_t i) const { return entries_[slots_[u].start + i].to; }
    uint32_t out_face(uint32_t u, uint32_t i) const { return entries_[slots_[u].start + i].face & kFaceBits; }
    // The third vertex of that face (out ends and out apexes together are all of u's neighbours,
    // also on the boundary).
    uint32_t out_apex(uint32_t u, uint32_t i) const { return entries_[slots_[u].start + i].apex; }
    uint32_t vertex_count() const { return uint32_t(slots_.size() - 1); }
    // Calls f on every neighbour of u, each once (the out ends, and the apexes that are not also
    // an out end: in a closed fan none is), in no particular order. Half the lookups of visiting
    // ends and apexes, for the callers whose answer does not depend on the order.
    template <class F>
    void for_each_neighbor_once(uint32_t u, F f) const {
        for (uint32_t i = slots_[u].start, end = slots_[u + 1].start; i < end; ++i) {
            f(entries_[i].to);
            if (!(entries_[i].face & kApexIsEnd)) f(entries_[i].apex);
        }
    }

    // Whether p holds for every neighbour of u (as for_each_neighbor_once visits them), stopping
    // at the first for which it does not.
    template <class P>
    bool every_neighbor(uint32_t u, P p) const {
        for (uint32_t i = slots_[u].start, end = slots_[u + 1].start; i < end; ++i) {
            if (!p(entries_[i].to)) return false;
            if (!(entries_[i].face & kApexIsEnd) && !p(entries_[i].apex)) return false;
        }
        return true;
    }

private:
    struct Entry {
        uint32_t to, apex, face;  // face: its top bit kApexIsEnd (faces are fewer than 2^30)
    };
    static constexpr uint32_t kApexIsEnd = 0x80000000u;  // the apex is also the end of an out-edge of u
    static constexpr uint32_t kFaceBits = ~kApexIsEnd;
    // A vertex's first entry, and a filter of its out-edge ends (bit end_bit(v) of each end v): a
    // clear bit answers "no edge" without a search, as most of a node reading's lookups answer.
    struct Slot {
        uint32_t start, ends;
    };
    static uint32_t end_bit(uint32_t v) { return 1u << ((v * 0x9e3779b1u) >> 27); }
    const Entry* find(uint32_t u, uint32_t v) const {
        const Slot* const slot = slots_.data() + u;
        if (!(slot[0].ends & end_bit(v))) return nullptr;
        if (slot[1].start - slot[0].start > kScanned) {  // a large fan, sorted by end
            const Entry* const first = entries_.get() + slot[0].start;
            const Entry* const last = entries_.get() + slot[1].start;
            const Entry* e = std::lower_bound(first, last, v, [](const Entry& x, uint32_t to) { return x.to < to; });
            return e != last && e->to == v ? e : nullptr;
        }
        for (uint32_t i = slot[0].start, end = slot[1].start; i < end; ++i) {
            if (entries_[i].to == v) return &entries_[i];
        }
        return nullptr;
    }
    // A fan of more out-edges than this (a vertex of high valence) is sorted by their ends and
    // bisected: scanned, it made the lookups from its faces quadratic in the valence.
    static constexpr uint32_t kScanned = 64;
    std::vector<Slot> slots_;  // per vertex, and one past the last
    std::unique_ptr<Entry[]> entries_;  // 3 per face, grouped by start vertex; filled, never zeroed
};

}  // namespace amc
