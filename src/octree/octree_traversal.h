// The level-wise decisions of the octree coder (docs/FORMAT.md section 8.4), shared by encoder
// and decoder so that both walk the same order with the same contexts: the octants a rule decides
// (uniform levels, balance, the level limit) first, then the others in Morton order or by the
// paper's priority traversal (II-E), each coded in the context group of its face neighbours'
// states (II-D).
#pragma once

#include "octree/octree_levels.h"

#include <cstdint>
#include <vector>

namespace amc {

// Switches byte of the .amq metadata: frozen values.
constexpr uint8_t kOctreeCullByBalance = 1;
constexpr uint8_t kOctreeUniformLevels = 2;
constexpr uint8_t kOctreeTruncate = 4;
constexpr uint8_t kOctreeContextGroups = 8;
constexpr uint8_t kOctreeImprovedTraversal = 16;
constexpr uint8_t kOctreeKnownSwitches = 31;

// Context of an octant (docs/FORMAT.md 8.4): of its 2 * dim face neighbours, r decided refined
// and u decided unrefined, boundary or coarser (the paper's context groups, II-D); p of its
// parent's face neighbours refined or boundary; s of its siblings decided refined:
// model ((r * (2 dim + 1) + u) * (2 dim + 1) + p) * 2^dim + s.
constexpr int octree_model_count(int dim) { return (2 * dim + 1) * (2 * dim + 1) * (2 * dim + 1) * (1 << dim); }

enum : uint8_t { kUndecided = 0, kDecidedRefined = 1, kDecidedLeaf = 2 };

struct OctreeLevelFates {
    uint64_t uniform = 0, culled = 0, coded = 0;
};

// Scratch memory kept from level to level.
struct OctreeTraversal {
    std::vector<uint8_t> state, priority;
    std::vector<std::vector<uint32_t>> stacks;
};

// Decides every octant of level l, whose parents are the octants of `up` (null for the roots);
// code(n, model) gives the refinement of an octant the stream holds a symbol for. Afterwards
// t.state[n] is kDecidedRefined or kDecidedLeaf.
template <class Code>
void decide_octree_level(const OctreeLevel* up, const OctreeLevel& lv, int l, int dim, uint8_t switches, int uniform_levels,
                         OctreeTraversal& t, Code&& code, OctreeLevelFates& fates) {
    const uint32_t count = uint32_t(lv.size());
    const int faces = 2 * dim;
    t.state.assign(count, kUndecided);
    if ((switches & kOctreeUniformLevels) && l < uniform_levels) {
        t.state.assign(count, kDecidedRefined);
        fates.uniform += count;
        return;
    }
    // Rules first: balance (a missing neighbour of the same level) and the level limit.
    const bool at_limit = l >= octree_max_level(dim);
    for (uint32_t n = 0; n < count; ++n) {
        bool culled = at_limit;
        if (switches & kOctreeCullByBalance)
            for (int f = 0; f < faces; ++f) culled |= lv.neighbor[size_t(n) * faces + f] == kCoarserRegion;
        if (culled) {
            t.state[n] = kDecidedLeaf;
            ++fates.culled;
        }
    }
    auto decide = [&](uint32_t n) {
        int refined = 0, unrefined = 0;
        for (int f = 0; f < faces; ++f) {
            const uint32_t q = lv.neighbor[size_t(n) * faces + f];
            if (!is_octant(q) || t.state[q] == kDecidedLeaf) ++unrefined;
            else if (t.state[q] == kDecidedRefined) ++refined;
        }
        int model = 0;
        if (switches & kOctreeContextGroups) {
            int parent_side = 0, siblings = 0;
            if (up) {
                const uint32_t p = lv.parent[n];
                for (int f = 0; f < faces; ++f) {
                    const uint32_t q = up->neighbor[size_t(p) * faces + f];
                    parent_side += q == kTreeBoundary || (is_octant(q) && up->first_child[q] != kNoOctant);
                }
                const uint32_t first = up->first_child[p];
                for (int c = 0; c < (1 << dim); ++c) siblings += t.state[first + c] == kDecidedRefined;
            }
            model = ((refined * (faces + 1) + unrefined) * (faces + 1) + parent_side) * (1 << dim) + siblings;
        }
        t.state[n] = code(n, model) ? kDecidedRefined : kDecidedLeaf;
        ++fates.coded;
    };
    if (!(switches & kOctreeImprovedTraversal)) {
        for (uint32_t n = 0; n < count; ++n)
            if (t.state[n] == kUndecided) decide(n);
        return;
    }
    // Priority traversal: priority 2 * dim minus the faces already known, at least 1; stacks
    // filled in reverse so that each pops in canonical order.
    t.priority.assign(count, 0);
    t.stacks.resize(faces + 1);
    for (auto& s : t.stacks) s.clear();
    for (uint32_t n = count; n-- > 0;) {
        if (t.state[n] != kUndecided) continue;
        int known = 0;
        for (int f = 0; f < faces; ++f) {
            const uint32_t q = lv.neighbor[size_t(n) * faces + f];
            known += !is_octant(q) || t.state[q] != kUndecided;
        }
        const int p = faces - known < 1 ? 1 : faces - known;
        t.priority[n] = uint8_t(p);
        t.stacks[p].push_back(n);
    }
    int lowest = 1;
    for (;;) {
        while (lowest <= faces && t.stacks[lowest].empty()) ++lowest;
        if (lowest > faces) break;
        const uint32_t n = t.stacks[lowest].back();
        t.stacks[lowest].pop_back();
        if (t.state[n] != kUndecided || t.priority[n] != lowest) continue;
        decide(n);
        for (int f = 0; f < faces; ++f) {
            const uint32_t q = lv.neighbor[size_t(n) * faces + f];
            if (!is_octant(q) || t.state[q] != kUndecided || t.priority[q] <= 1) continue;
            const int p = t.priority[q] - 1;
            t.priority[q] = uint8_t(p);
            t.stacks[p].push_back(q);
            if (p < lowest) lowest = p;
        }
    }
}

}  // namespace amc
