// Exact lookup of vertices by position (bit patterns of the three coordinates): matching base
// vertices to leaf vertices, finding duplicate vertices, and the exact-midpoint fast path.
#pragma once

#include "common/keyed_hash.h"
#include "common/no_index.h"

#include <amc/mesh.h>

#include <cstdint>
#include <cstring>
#include <vector>

namespace amc {

class PositionIndex {
public:

    // Indexes every position, in the order of `insertion_order` (vertex ids; null: 0, 1, ...), so
    // that find() answers "first" in that order; `duplicate_of` receives, when not null, the first
    // pair (earlier, later) of vertices with the same position, or {kNoIndex, kNoIndex}.
    explicit PositionIndex(const std::vector<Vec3>& positions, uint32_t* first_duplicate = nullptr,
                           uint32_t* second_duplicate = nullptr,
                           const std::vector<uint32_t>* insertion_order = nullptr)
        : indexed_(&positions), insertion_order_(insertion_order), positions_(&positions) {
        build(first_duplicate, second_duplicate);
    }

    // The same index, built when first needed: the first find() scans the positions in insertion
    // order instead (the same answer), the next call builds it. A leaf mesh whose new vertices
    // are off their midpoints fails the import's exact way at its first lookup, and one scan is a
    // fraction of hashing every position into a table eight times the vertex count.
    struct Deferred {};
    PositionIndex(Deferred, const std::vector<Vec3>& positions, const std::vector<uint32_t>* insertion_order = nullptr)
        : indexed_(&positions), insertion_order_(insertion_order), positions_(&positions) {}

    // The index of the same positions renumbered: vertex v is new_id[v] in `renumbered`
    // (renumbered[new_id[v]] == positions[v]). Finds answer as an index built over `renumbered`
    // with the same insertion order would, without its random reads of the positions. Both
    // must outlive a deferred index.
    void rename(const std::vector<Vec3>& renumbered, const std::vector<uint32_t>& new_id) {
        positions_ = &renumbered;
        if (!built_) {
            new_id_ = &new_id;
            return;
        }
        for (uint32_t& slot : slots_) {
            if (slot != kNoIndex) slot = new_id[slot];
        }
    }

    // The first vertex at exactly p, or kNoIndex.
    uint32_t find(Vec3 p) const {
        if (!built_) {
            if (!scanned_) {
                scanned_ = true;
                return scan(p);
            }
            build(nullptr, nullptr);
        }
        for (size_t s = slot_of(p);; s = (s + 1) & (slots_.size() - 1)) {
            if (slots_[s] == kNoIndex) return kNoIndex;
            if (same((*positions_)[slots_[s]], p)) return slots_[s];
        }
    }

    // More than one vertex is at exactly p.
    bool shared(Vec3 p) const {
        if (!built_) build(nullptr, nullptr);
        if (shared_.empty()) return false;
        for (size_t s = slot_of(p);; s = (s + 1) & (slots_.size() - 1)) {
            if (slots_[s] == kNoIndex) return false;
            if (same((*positions_)[slots_[s]], p)) return shared_[s] != 0;
        }
    }

private:
    // Const: a deferred index is built by its first lookups (mutable state below).
    void build(uint32_t* first_duplicate, uint32_t* second_duplicate) const {
        const std::vector<Vec3>& positions = *indexed_;
        size_t capacity = 16;
        while (capacity < 2 * positions.size()) capacity *= 2;
        slots_.assign(capacity, kNoIndex);
        if (first_duplicate != nullptr) *first_duplicate = *second_duplicate = kNoIndex;
        for (uint32_t i = 0; i < positions.size(); ++i) {
            const uint32_t v = insertion_order_ ? (*insertion_order_)[i] : i;
            size_t s = slot_of(positions[v]);
            while (slots_[s] != kNoIndex && !same(positions[slots_[s]], positions[v])) s = (s + 1) & (slots_.size() - 1);
            if (slots_[s] == kNoIndex) {
                slots_[s] = v;
            } else {
                if (shared_.empty()) shared_.assign(slots_.size(), 0);
                shared_[s] = 1;
                if (first_duplicate != nullptr && *first_duplicate == kNoIndex) {
                    *first_duplicate = slots_[s];
                    *second_duplicate = v;
                }
            }
        }
        built_ = true;
        if (new_id_ != nullptr) {
            for (uint32_t& slot : slots_) {
                if (slot != kNoIndex) slot = (*new_id_)[slot];
            }
        }
    }
    // What find() answers, by reading every position in insertion order.
    uint32_t scan(Vec3 p) const {
        const std::vector<Vec3>& positions = *indexed_;
        for (uint32_t i = 0; i < positions.size(); ++i) {
            const uint32_t v = insertion_order_ ? (*insertion_order_)[i] : i;
            if (same(positions[v], p)) return new_id_ ? (*new_id_)[v] : v;
        }
        return kNoIndex;
    }
    static bool same(Vec3 a, Vec3 b) { return std::memcmp(&a, &b, sizeof(Vec3)) == 0; }
    // Keyed: a mesh's positions are the input's to choose, and an unkeyed hash's collisions are
    // found offline (positions sharing one slot made building the index quadratic).
    size_t slot_of(Vec3 p) const {
        uint64_t bits[3];
        std::memcpy(bits, &p, sizeof bits);
        return size_t(keyed_hash_words(key_, bits[0], bits[1], bits[2])) & (slots_.size() - 1);
    }
    const std::vector<Vec3>* indexed_;                  // the positions as inserted
    const std::vector<uint32_t>* insertion_order_;
    const std::vector<Vec3>* positions_;                // as found (renamed)
    const std::vector<uint32_t>* new_id_ = nullptr;     // a rename to apply when built
    const uint64_t key_ = process_hash_key();
    mutable bool built_ = false, scanned_ = false;
    mutable std::vector<uint32_t> slots_;
    mutable std::vector<uint8_t> shared_;  // per slot: another vertex has the same position (empty: none)
};

}  // namespace amc
