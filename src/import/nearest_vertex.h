// Nearest not-yet-used vertex to a point (a uniform hash grid over the leaf vertices).
#pragma once

#include "common/no_index.h"

#include <amc/mesh.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <vector>

namespace amc {

class NearestVertex {
public:

    // `cell` is the grid spacing (about an edge length).
    NearestVertex(const std::vector<Vec3>& positions, double cell);

    // The vertex nearest to p among those for which usable(v) holds, searching up to
    // `max_rings` rings of cells around p; kNoIndex when none is found.
    template <class Usable>
    uint32_t find(Vec3 p, Usable usable, int max_rings = 64) const {
        const int64_t c[3] = {cell_of(p.x), cell_of(p.y), cell_of(p.z)};
        uint32_t best = kNoIndex;
        double best_distance = 0;
        int found_ring = -1;
        for (int r = 0; r <= max_rings; ++r) {
            if (found_ring >= 0 && r > found_ring + 1) break;
            for (int64_t i = -r; i <= r; ++i)
                for (int64_t j = -r; j <= r; ++j)
                    for (int64_t k = -r; k <= r; ++k) {
                        if (std::max(std::llabs(i), std::max(std::llabs(j), std::llabs(k))) != r) continue;
                        for (uint32_t v : cell_vertices(c[0] + i, c[1] + j, c[2] + k)) {
                            const Vec3 d = positions_[v] - p;
                            const double distance = dot(d, d);
                            // usable() last: it may cost more than the distance.
                            if ((best == kNoIndex || distance < best_distance) && usable(v)) {
                                best = v;
                                best_distance = distance;
                                if (found_ring < 0) found_ring = r;
                            }
                        }
                    }
        }
        return best;
    }

private:
    struct Range {
        const uint32_t* begin_;
        const uint32_t* end_;
        const uint32_t* begin() const { return begin_; }
        const uint32_t* end() const { return end_; }
    };
    int64_t cell_of(double x) const;
    size_t slot_of(int64_t i, int64_t j, int64_t k) const;
    Range cell_vertices(int64_t i, int64_t j, int64_t k) const;

    const std::vector<Vec3>& positions_;
    double inverse_cell_;
    size_t mask_ = 0;
    // Hash table of cells: cell keys and the start of each cell's vertices in `vertices_`.
    std::vector<int64_t> keys_;  // 3 per slot; slot empty when start_[slot] == start_[slot + 1]
    std::vector<uint32_t> start_;
    std::vector<uint32_t> vertices_;
};

}  // namespace amc
