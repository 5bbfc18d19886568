// One block of the inverse step: reading it off the mesh, its fans and the sides around it.
#include "import/level_finder.h"

#include "common/no_index.h"

#include <algorithm>

namespace amc::detail::inverse {

uint32_t LevelFinder::vertex_at(uint32_t half_edge, int offset) const {
    return tri_[half_edge / 3][(half_edge % 3 + uint32_t(offset)) % 3];
}

uint32_t LevelFinder::next_half_edge(uint32_t half_edge, int offset) {
    return half_edge / 3 * 3 + (half_edge % 3 + uint32_t(offset)) % 3;
}

bool LevelFinder::read_block(uint32_t t, Block& b) const {
    b.center = t;
    b.alive = false;
    b.patch = kNoIndex;
    for (int k = 0; k < 3; ++k) {
        // Corner k shares center edge (k+1)%3; its half-edge there runs m_k -> m_{k+2}.
        const uint32_t h = adjacency_.twin(3 * t + uint32_t(k + 1) % 3);
        if (h == kNoHalfEdge) return false;
        b.corner[size_t(k)] = h / 3;
        b.m[size_t(k)] = vertex_at(h, 0);
        b.v[size_t(k)] = vertex_at(h, 2);
        b.first_half[size_t(k)] = next_half_edge(h, 2);
        b.second_half[size_t(k + 2) % 3] = next_half_edge(h, 1);
    }
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            if (b.v[size_t(i)] == b.m[size_t(j)]) return false;
            if (i < j && (b.v[size_t(i)] == b.v[size_t(j)] || b.corner[size_t(i)] == b.corner[size_t(j)])) return false;
        }
        if (b.corner[size_t(i)] == t) return false;
    }
    return true;
}

const Block* LevelFinder::read_shape(uint32_t t) const {
    Block b;
    bool possible = read_block(t, b);
    for (int i = 0; i < 3 && possible; ++i) {
        possible = !forced_old_[b.m[size_t(i)]] && !adjacency_.has_edge(b.v[size_t(i)], b.v[size_t(i + 1) % 3]);
    }
    if (!possible) {
        shape_of_[t] = kImpossible;
        return nullptr;
    }
    for (int i = 0; i < 3; ++i) b.fan[size_t(i)] = walk_fan(b, i);
    shape_of_[t] = uint32_t(shapes_.size());
    shapes_.push_back(b);
    return &shapes_.back();
}

Fan LevelFinder::walk_fan(const Block& b, int i) const {
    Fan fan;
    const uint32_t a = b.v[size_t(i)], m = b.m[size_t(i)];
    const uint32_t back = adjacency_.twin(b.first_half[size_t(i)]);
    uint32_t h = adjacency_.twin(b.second_half[size_t(i)]);  // v_{i+1} -> m
    if (h == kNoHalfEdge || back == kNoHalfEdge) {
        if (h == back && adjacency_.star_size(m) == 3) fan.kind = Fan::boundary;
        return fan;
    }
    for (int k = 0; k < 3; ++k) {
        const uint32_t t = h / 3;
        if (t == b.center || t == b.corner[0] || t == b.corner[1] || t == b.corner[2]) return fan;
        fan.entry[k] = h;
        const uint32_t p = vertex_at(h, 2);
        if (p == a) {
            fan.size = k + 1;
            if (fan.size >= 2 && adjacency_.star_size(m) == uint32_t(3 + fan.size)) fan.kind = Fan::triangles;
            return fan;
        }
        if (k == 2) return fan;
        fan.inner[k] = p;
        h = adjacency_.twin(next_half_edge(h, 1));
        if (h == kNoHalfEdge) return fan;
    }
    return fan;
}

bool LevelFinder::fits(const Block& b) const {
    if (taken(b.center) || banned_[b.center] || repair_banned_[b.center]) return false;
    for (int k = 0; k < 3; ++k) {
        if (taken(b.corner[size_t(k)])) return false;
        const uint32_t m = b.m[size_t(k)];
        if (is_old(m) || is_new(b.v[size_t(k)]) || midpoint_count_[m] > 1) return false;
    }
    return true;
}

bool LevelFinder::has_other_midpoint(uint32_t a, uint32_t b, uint32_t m) const {
    // An edge as one 64-bit key, so that each neighbour costs one comparison per direction.
    auto key = [](uint32_t s, uint32_t t) { return uint64_t(s) | uint64_t(t) << 32; };
    const uint64_t ab = key(a, b), ba = key(b, a);
    auto splits_ab = [&](uint32_t w) {
        const auto [s, t] = first_coarse_edge_[w];  // (kNoIndex, kNoIndex) unless w is a midpoint
        const uint64_t edge = key(s, t);
        return (edge == ab || edge == ba) && w != m;
    };
    // Such a midpoint neighbours both a and b (it halves their edge): the smaller star is searched,
    // since a's alone made the blocks around a vertex of high valence quadratic in it (docs/FUZZING.md).
    const auto star = [&](uint32_t v) { return adjacency_.ends_end(v) - adjacency_.ends_begin(v); };
    const uint32_t v = star(b) < star(a) ? b : a;
    for (const uint32_t* w = adjacency_.ends_begin(v); w != adjacency_.ends_end(v); ++w) {
        if (splits_ab(*w)) return true;
    }
    if (!adjacency_.on_boundary(v)) return false;
    // The neighbour before v along the boundary is only the third vertex of one of its triangles.
    for (const uint32_t* h = adjacency_.outgoing_begin(v); h != adjacency_.outgoing_end(v); ++h) {
        if (splits_ab(vertex_at(*h, 2))) return true;
    }
    return false;
}

bool LevelFinder::place_block(uint32_t t) {
    const Block* shape = possible_block(t);
    if (shape == nullptr || !fits(*shape)) return false;
    // Old once the block is placed: its parent vertices are too (checked before claiming it).
    auto old_once_placed = [&](uint32_t x) { return is_old(x) || x == shape->v[0] || x == shape->v[1] || x == shape->v[2]; };
    for (const Fan& fan : shape->fan) {
        if (fan.kind == Fan::invalid) return false;
        // Neither a block nor a two-hanging-node closure fits two old vertices there.
        if (fan.size == 3 && old_once_placed(fan.inner[0]) && old_once_placed(fan.inner[1])) return false;
    }
    blocks_.push_back(*shape);
    claim(uint32_t(blocks_.size() - 1));
    return true;
}

void LevelFinder::claim(uint32_t index) {
    Block& b = blocks_[index];
    b.alive = true;
    block_of_[b.center] = index;
    for (int k = 0; k < 3; ++k) {
        block_of_[b.corner[size_t(k)]] = index;
        const uint32_t m = b.m[size_t(k)];
        midpoint_block_[m][midpoint_count_[m]++] = index * 3 + uint32_t(k);
        if (midpoint_count_[m] == 1) first_coarse_edge_[m] = {b.v[size_t(k)], b.v[size_t(k + 1) % 3]};
        ++corner_count_[b.v[size_t(k)]];
    }
}

void LevelFinder::release(uint32_t index) {
    Block& b = blocks_[index];
    b.alive = false;
    block_of_[b.center] = kNoIndex;
    for (int k = 0; k < 3; ++k) {
        block_of_[b.corner[size_t(k)]] = kNoIndex;
        const uint32_t m = b.m[size_t(k)];
        auto& slots = midpoint_block_[m];
        const bool was_first = slots[0] / 3 == index;
        if (was_first) slots[0] = slots[1];
        slots[1] = kNoIndex;
        // first_coarse_edge_ is slots[0]'s coarse edge: it changes only with slots[0].
        if (--midpoint_count_[m] == 0) {
            first_coarse_edge_[m] = kNoEdge;
        } else if (was_first) {
            first_coarse_edge_[m] = coarse_edge(slots[0]);
        }
        --corner_count_[b.v[size_t(k)]];
    }
}

void LevelFinder::roll_back(uint32_t size) {
    while (blocks_.size() > size) {
        if (blocks_.back().alive) release(uint32_t(blocks_.size() - 1));
        blocks_.pop_back();
    }
}

uint32_t LevelFinder::turn_cw(uint32_t h) const {
    const uint32_t t = adjacency_.twin(h);
    return t == kNoHalfEdge ? kNoHalfEdge : next_half_edge(t, 1);
}

uint32_t LevelFinder::middle_of_three(uint32_t h, bool ccw, uint32_t last) const {
    uint32_t around[3];
    for (int k = 0; k < 3; ++k) {
        h = ccw ? turn_ccw(h) : turn_cw(h);
        if (h == kNoHalfEdge) return kNoIndex;
        around[k] = h;
    }
    return vertex_at(around[2], ccw ? 2 : 1) == last ? around[1] / 3 : kNoIndex;
}

bool LevelFinder::partner_fits(uint32_t t, uint32_t v, uint32_t from, uint32_t to) const {
    const Block* z = possible_block(t);
    if (z == nullptr || !fits(*z)) return false;
    for (int e = 0; e < 3; ++e) {
        if (z->m[size_t(e)] == v) return z->v[size_t(e)] == from && z->v[size_t(e + 1) % 3] == to;
    }
    return false;
}

uint32_t LevelFinder::closure_partner(const Block& x, int i, const Fan& fan) const {
    if (fan.kind != Fan::triangles) return kNoIndex;
    const uint32_t a = x.v[size_t(i)], b = x.v[size_t(i + 1) % 3];
    if (fan.size == 3) {
        const uint32_t p1 = fan.inner[0], p2 = fan.inner[1];
        // Default diagonal seen from m1: p1 = A (old), p2 = m2 on edge C=a -> A, whose block
        // has edge A -> C; its triangles around p2 run from a to p1, away from the fan.
        if (!is_new(p1) && !is_new(p2) && !is_old(p2) && adjacency_.star_size(p2) == 5) {
            const uint32_t z = middle_of_three(fan.entry[2], true, p1);
            if (z != kNoIndex && partner_fits(z, p2, p1, a)) return z;
        }
        // Flipped diagonal seen from m2: p1 = m1 on edge B=p2 -> C=b, p2 = B (old), whose
        // block has edge C -> B; its triangles around p1 run from b to p2.
        if (!is_new(p1) && !is_old(p1) && !is_new(p2) && adjacency_.star_size(p1) == 5) {
            const uint32_t z = middle_of_three(next_half_edge(fan.entry[0], 2), false, p2);
            if (z != kNoIndex && partner_fits(z, p1, b, p2)) return z;
        }
        return kNoIndex;
    }
    const uint32_t p = fan.inner[0];
    if (is_new(p) || is_old(p) || adjacency_.star_size(p) != 6) return kNoIndex;
    // Flipped diagonal seen from m1 (B=b, C=a): p = m2 on edge a -> A, the third triangle
    // (A, b, p) lies across edge p -> b of the first fan triangle; p's block has edge A -> a.
    uint32_t h = adjacency_.twin(next_half_edge(fan.entry[0], 2));
    if (h != kNoHalfEdge) {
        const uint32_t apex = vertex_at(h, 2);
        const uint32_t z = middle_of_three(fan.entry[1], true, apex);
        if (z != kNoIndex && partner_fits(z, p, apex, a)) return z;
    }
    // Default diagonal seen from m2 (A=a, C=b): p = m1 on edge B -> b, the third triangle
    // (a, B, p) lies across edge a -> p of the second fan triangle; p's block has edge b -> B.
    h = adjacency_.twin(next_half_edge(fan.entry[1], 2));
    if (h != kNoHalfEdge) {
        const uint32_t apex = vertex_at(h, 2);
        const uint32_t z = middle_of_three(next_half_edge(fan.entry[0], 2), false, apex);
        if (z != kNoIndex && partner_fits(z, p, b, apex)) return z;
    }
    return kNoIndex;
}

std::pair<uint32_t, uint32_t> LevelFinder::coarse_edge(uint32_t role) const {
    const Block& z = blocks_[role / 3];
    const int e = int(role % 3);
    return {z.v[size_t(e)], z.v[size_t(e + 1) % 3]};
}

Side LevelFinder::classify(uint32_t index, int i) const {
    const Block& b = blocks_[index];
    Side side;
    const Fan& fan = b.fan[size_t(i)];
    if (fan.kind == Fan::boundary) {
        side.kind = Side::boundary;
        return side;
    }
    if (fan.kind != Fan::triangles) return side;
    const uint32_t other = block_of_[fan.triangle(0)];
    if (other != kNoIndex || block_of_[fan.triangle(1)] != kNoIndex || (fan.size == 3 && block_of_[fan.triangle(2)] != kNoIndex)) {
        if (fan.size == 3 && other != index && block_of_[fan.triangle(1)] == other && block_of_[fan.triangle(2)] == other)
            side.kind = Side::red;
        return side;
    }
    for (int k = 0; k < fan.size; ++k) {
        if (closure_of_[fan.triangle(k)] != kNoIndex && closure_of_[fan.triangle(k)] != b.patch) return side;
    }
    const uint32_t a = b.v[size_t(i)], bb = b.v[size_t(i + 1) % 3];
    side.count = fan.size;
    for (int k = 0; k < fan.size; ++k) side.group[k] = fan.triangle(k);
    if (fan.size == 2) {
        const uint32_t p = fan.inner[0];
        if (!is_new(p)) {  // one hanging node: (b, m, p), (m, a, p)
            side.coarse = {bb, a, p};
            side.emits = true;
        } else {
            const auto [s, t] = only_coarse_edge(p);
            if (s == kNoIndex) return side;
            uint32_t across, apex;
            if (t == a) {
                // m is m1 of a flipped closure (A, B=b, C=a): the third triangle (A, b, p)
                // lies across edge p -> b of the first fan triangle.
                across = adjacency_.twin(next_half_edge(fan.entry[0], 2));
                apex = s;
                side.coarse = {s, bb, a};
                side.emits = true;
            } else if (s == bb) {
                // m is m2 of a default closure (A=a, B, C=b): the third triangle (a, B, p)
                // lies across edge a -> p of the second fan triangle.
                across = adjacency_.twin(next_half_edge(fan.entry[1], 2));
                apex = t;
                side.coarse = {a, t, bb};
            } else {
                return side;
            }
            if (across == kNoHalfEdge || vertex_at(across, 2) != apex || block_of_[across / 3] != kNoIndex ||
                (closure_of_[across / 3] != kNoIndex && closure_of_[across / 3] != b.patch))
                return side;
            side.group[2] = across / 3;
            side.count = 3;
        }
    } else {
        const uint32_t p1 = fan.inner[0], p2 = fan.inner[1];
        if (!is_new(p1) && is_new(p2)) {
            // m is m1 of a default closure (A=p1, B=b, C=a); p2 is m2 on edge C -> A.
            if (only_coarse_edge(p2) != std::make_pair(p1, a)) return side;
            side.coarse = {p1, bb, a};
            side.emits = true;
        } else if (is_new(p1) && !is_new(p2)) {
            // m is m2 of a flipped closure (A=a, B=p2, C=b); p1 is m1 on edge B -> C.
            if (only_coarse_edge(p1) != std::make_pair(bb, p2)) return side;
            side.coarse = {a, p2, bb};
        } else {
            return side;
        }
    }
    const Triangle& q = side.coarse;
    if (q[0] == q[1] || q[1] == q[2] || q[2] == q[0]) return side;
    // No refinement inside the group, and none around it that balance forbids: the block's
    // children beside it have no same-level neighbour there, and the coarse triangle keeps at most
    // two hanging nodes. A refined triangle across a whole edge of the coarse triangle is a
    // same-level node undone in an earlier step (its midpoint is the closure's second hanging
    // node), which a closure of one hanging node can take on its other two edges, once.
    bool refined_across = false;
    for (int k = 0; k < side.count; ++k) {
        const uint32_t g = side.group[k];
        if (!refined_near_[g]) continue;
        if (refined_[g]) return side;
        for (int e = 0; e < 3; ++e) {
            const uint32_t h = adjacency_.twin(3 * g + uint32_t(e));
            if (h == kNoHalfEdge) continue;
            const uint32_t n = h / 3;
            if (!refined_[n] || std::find(side.group, side.group + side.count, n) != side.group + side.count) continue;
            const uint32_t x = tri_[g][size_t(e)], y = tri_[g][size_t(e + 1) % 3];
            const bool whole_other_edge = (x == q[1] && y == q[2]) || (x == q[2] && y == q[0]);
            if (side.count != 2 || !whole_other_edge || refined_across) return side;
            refined_across = true;
        }
    }
    side.kind = Side::green;
    return side;
}

bool LevelFinder::sides_valid(uint32_t index) const {
    const Block& b = blocks_[index];
    // The sides first: they fail more often than the coarse edges, and both only read.
    uint32_t red_neighbor[3];
    for (int i = 0; i < 3; ++i) {
        const Side side = classify(index, i);
        if (side.kind == Side::invalid) return false;
        red_neighbor[i] = side.kind == Side::red ? block_of_[adjacency_.twin(b.second_half[size_t(i)]) / 3]
                                                 : kNoIndex - uint32_t(i);
    }
    // Two blocks glued along all three edges would make two coincident coarse triangles.
    if (red_neighbor[0] == red_neighbor[1] && red_neighbor[1] == red_neighbor[2]) return false;
    for (int i = 0; i < 3; ++i) {
        if (has_other_midpoint(b.v[size_t(i)], b.v[size_t(i + 1) % 3], b.m[size_t(i)])) return false;
    }
    return true;
}

}  // namespace amc::detail::inverse
