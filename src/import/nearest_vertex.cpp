#include "import/nearest_vertex.h"

#include <algorithm>
#include <cmath>

namespace amc {

NearestVertex::NearestVertex(const std::vector<Vec3>& positions, double cell)
    : positions_(positions), inverse_cell_(cell > 0 ? 1.0 / cell : 1.0) {
    size_t slots = 16;
    while (slots < 2 * positions.size()) slots *= 2;
    mask_ = slots - 1;
    keys_.assign(3 * slots, 0);
    std::vector<uint32_t> count(slots + 1, 0);
    std::vector<uint8_t> used(slots, 0);
    std::vector<size_t> slot_of_vertex(positions.size());
    for (uint32_t v = 0; v < positions.size(); ++v) {
        const int64_t i = cell_of(positions[v].x), j = cell_of(positions[v].y), k = cell_of(positions[v].z);
        size_t s = slot_of(i, j, k);
        while (used[s] && !(keys_[3 * s] == i && keys_[3 * s + 1] == j && keys_[3 * s + 2] == k)) s = (s + 1) & mask_;
        used[s] = 1;
        keys_[3 * s] = i, keys_[3 * s + 1] = j, keys_[3 * s + 2] = k;
        slot_of_vertex[v] = s;
        ++count[s + 1];
    }
    for (size_t s = 1; s <= slots; ++s) count[s] += count[s - 1];
    start_ = count;
    vertices_.resize(positions.size());
    for (uint32_t v = 0; v < positions.size(); ++v) vertices_[count[slot_of_vertex[v]]++] = v;
}

int64_t NearestVertex::cell_of(double x) const { return int64_t(std::floor(x * inverse_cell_)); }

size_t NearestVertex::slot_of(int64_t i, int64_t j, int64_t k) const {
    uint64_t h = uint64_t(i) * 0x9e3779b97f4a7c15ull ^ uint64_t(j) * 0xbf58476d1ce4e5b9ull ^ uint64_t(k) * 0x94d049bb133111ebull;
    h ^= h >> 31;
    return size_t(h) & mask_;
}

NearestVertex::Range NearestVertex::cell_vertices(int64_t i, int64_t j, int64_t k) const {
    for (size_t s = slot_of(i, j, k);; s = (s + 1) & mask_) {
        if (start_[s] == start_[s + 1]) return {nullptr, nullptr};
        if (keys_[3 * s] == i && keys_[3 * s + 1] == j && keys_[3 * s + 2] == k)
            return {vertices_.data() + start_[s], vertices_.data() + start_[s + 1]};
    }
}

}  // namespace amc
