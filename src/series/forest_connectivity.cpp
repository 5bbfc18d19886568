// Forest series connectivity (docs/FORMAT.md 7.11): the .amq coder's walk with contexts from the
// previous frame's forest.
#include "series/forest_connectivity.h"

#include "common/check.h"
#include "octree/octree_traversal.h"

#include <algorithm>

namespace amc {

namespace {

constexpr uint8_t kForestTraversal = kOctreeContextGroups | kOctreeImprovedTraversal;

// The octant of `prev` at the place of each octant of level l of `next` (kNoOctant where prev has
// none), from the parents' counterparts `up` (level l - 1; empty for the roots).
std::vector<uint32_t> counterparts(const OctreeLevels& prev, const OctreeLevel& lv, int l, const std::vector<uint32_t>& up,
                                   const OctreeLevel* next_up) {
    std::vector<uint32_t> out(lv.size(), kNoOctant);
    if (l == 0) {
        for (uint32_t n = 0; n < lv.size(); ++n) out[n] = n;  // the same trees
        return out;
    }
    if (l > prev.depth()) return out;
    const OctreeLevel& prev_up = prev.level(l - 1);
    for (uint32_t n = 0; n < lv.size(); ++n) {
        const uint32_t p = lv.parent[n], q = up[p];
        if (q == kNoOctant || prev_up.first_child[q] == kNoOctant) continue;
        out[n] = prev_up.first_child[q] + (n - next_up->first_child[p]);
    }
    return out;
}

// Class of an octant in the previous frame: 0 absent, 1 leaf, 2 refined into leaves, 3 deeper.
struct PreviousLevel {
    std::vector<uint8_t> cls;      // per octant of the current level
    std::vector<uint8_t> refined;  // cls >= 2
};

PreviousLevel previous_level(const OctreeLevels& prev, int l, const std::vector<uint32_t>& cp) {
    PreviousLevel out;
    out.cls.assign(cp.size(), 0);
    out.refined.assign(cp.size(), 0);
    for (size_t n = 0; n < cp.size(); ++n) {
        if (cp[n] == kNoOctant) continue;
        const uint32_t first = prev.level(l).first_child[cp[n]];
        if (first == kNoOctant) {
            out.cls[n] = 1;
            continue;
        }
        uint8_t c = 2;
        const OctreeLevel& down = prev.level(l + 1);
        for (int k = 0; k < (1 << prev.dim()); ++k) c = down.first_child[first + uint32_t(k)] != kNoOctant ? 3 : c;
        out.cls[n] = c;
        out.refined[n] = 1;
    }
    return out;
}

// The inter-frame context of octant n (FORMAT.md 7.11). `parent_area_changed[p]`: the parent p or
// a face neighbour of it changed its refinement (area_changed of the parents' level).
int inter_context(const OctreeLevel& lv, uint32_t n, int faces, const PreviousLevel& before, const std::vector<uint8_t>& state,
                  const std::vector<uint8_t>& parent_area_changed) {
    int octants = 0, refined_before = 0, changed = 0, refined_now = 0;
    for (int f = 0; f < faces; ++f) {
        const uint32_t q = lv.neighbor[size_t(n) * faces + f];
        if (!is_octant(q)) continue;
        ++octants;
        refined_before += before.refined[q];
        if (state[q] == kUndecided) continue;
        const bool now = state[q] == kDecidedRefined;
        changed += now != (before.refined[q] != 0);
        refined_now += now;
    }
    const int border = refined_before == 0 ? 0 : refined_before == octants ? 2 : 1;
    const int parent = lv.parent[n] == kNoOctant ? 0 : parent_area_changed[lv.parent[n]];
    return (((before.cls[n] * 3 + border) * 3 + std::min(changed, 2)) * 3 + std::min(refined_now, 2)) * 2 + parent;
}

// Per octant of level l (fully decided): did it or a face neighbour change its refinement.
std::vector<uint8_t> area_changed(const OctreeLevel& lv, int faces, const std::vector<uint8_t>& refined_now,
                                  const PreviousLevel& before) {
    std::vector<uint8_t> changed(lv.size());
    for (uint32_t n = 0; n < lv.size(); ++n) changed[n] = (refined_now[n] != 0) != (before.refined[n] != 0);
    std::vector<uint8_t> out(lv.size());
    for (uint32_t n = 0; n < lv.size(); ++n) {
        uint8_t c = changed[n];
        for (int f = 0; f < faces && !c; ++f) {
            const uint32_t q = lv.neighbor[size_t(n) * faces + f];
            c = is_octant(q) && changed[q];
        }
        out[n] = c;
    }
    return out;
}

// One walk for both sides: decide(l, n, model) gives the refinement of a coded octant. `levels`
// grows level by level (the decoder) or holds the forest already (the encoder, which passes
// add = false). Returns the switches' fates.
template <class Code, class Next>
OctreeLevelFates walk(const OctreeLevels* prev, OctreeLevels& levels, uint8_t switches, ForestConnectivityModels& models,
                      Code&& code, Next&& next_level) {
    const int dim = levels.dim(), faces = 2 * dim;
    OctreeTraversal t;
    OctreeLevelFates fates;
    std::vector<uint32_t> cp;
    std::vector<uint8_t> parent_area;
    if (models.key.empty()) models.key.resize(octree_model_count(dim));
    for (int l = 0;; ++l) {
        const OctreeLevel& lv = levels.level(l);
        const OctreeLevel* up = l > 0 ? &levels.level(l - 1) : nullptr;
        PreviousLevel before;
        if (prev) {
            cp = counterparts(*prev, lv, l, cp, up);
            before = previous_level(*prev, l, cp);
        }
        decide_octree_level(up, lv, l, dim, switches, 0, t,
                            [&](uint32_t n, int model) {
                                if (!prev) return code(l, n, models.key[model]);
                                return code(l, n, models.inter[inter_context(lv, n, faces, before, t.state, parent_area)]);
                            },
                            fates);
        std::vector<uint8_t> refined(lv.size());
        bool any = false;
        for (uint32_t n = 0; n < lv.size(); ++n) any |= (refined[n] = t.state[n] == kDecidedRefined) != 0;
        if (prev) parent_area = area_changed(lv, faces, refined, before);
        if (!next_level(l, refined, any)) break;
    }
    return fates;
}

}  // namespace

OctreeLevels encode_forest_connectivity(const OctreeLevels* prev, const OctreeForest& forest, ForestConnectivityModels& models,
                                        std::vector<uint8_t>& out, ForestConnectivityStats* stats) {
    std::vector<std::vector<uint8_t>> refined;
    OctreeLevels levels = octree_levels_of(forest, &refined, UINT64_MAX);
    // The balance rule when the forest keeps it (it may be balanced by corners, or not at all).
    const uint8_t switches = octree_balance_violation(forest, OctreeBalance::face).empty() ? kForestCullByBalance : 0;
    ArithmeticEncoder encoder;
    const OctreeLevelFates fates = walk(
        prev, levels, uint8_t(kForestTraversal | (switches ? kOctreeCullByBalance : 0)), models,
        [&](int l, uint32_t n, BitModel& m) {
            encoder.encode(refined[l][n] != 0, m);
            return refined[l][n] != 0;
        },
        [&](int l, const std::vector<uint8_t>& decided, bool) {
            AMC_REQUIRE(decided == refined[l], invalid_input,
                        "forest series: level " + std::to_string(l) + " breaks the refinement rules");  // a balanced, valid forest keeps them
            return l < levels.depth();
        });
    out.push_back(switches);
    const std::vector<uint8_t> stream = encoder.finish();
    out.insert(out.end(), stream.begin(), stream.end());
    if (stats) {
        stats->coded = fates.coded;
        stats->culled = fates.culled;
    }
    return levels;
}

OctreeLevels decode_forest_connectivity(const TreeConnectivity& conn, const OctreeLevels* prev, ForestConnectivityModels& models,
                                        const uint8_t* data, size_t size, uint64_t octants) {
    AMC_REQUIRE(size >= 1, truncated, "connectivity: an empty section");
    const uint8_t switches = data[0];
    AMC_REQUIRE((switches & ~kForestCullByBalance) == 0, corrupt, "connectivity: unknown switches " + std::to_string(switches));
    OctreeLevels levels(conn);
    AMC_REQUIRE(levels.octant_count() <= octants, corrupt, "connectivity: more trees than the frame's octants");
    ArithmeticDecoder decoder(data + 1, size - 1);
    walk(
        prev, levels, uint8_t(kForestTraversal | (switches ? kOctreeCullByBalance : 0)), models,
        [&](int, uint32_t, BitModel& m) { return decoder.decode(m); },
        [&](int l, const std::vector<uint8_t>& refined, bool any) {
            AMC_REQUIRE(!decoder.overran(), truncated, "connectivity: the stream ends early");
            if (!any) return false;
            uint64_t count = 0;
            for (uint8_t r : refined) count += r;
            AMC_REQUIRE(levels.octant_count() + (count << levels.dim()) <= octants, corrupt,
                        "connectivity: level " + std::to_string(l) + " makes more octants than the frame has");
            levels.add_children(refined, octants);
            return true;
        });
    AMC_REQUIRE(levels.octant_count() == octants, corrupt,
                "connectivity: the forest has " + std::to_string(levels.octant_count()) + " octants, the frame " + std::to_string(octants));
    return levels;
}

uint64_t changed_octants(const OctreeLevels& prev, const OctreeLevels& next) {
    uint64_t kept = 0;
    std::vector<uint32_t> cp;
    for (int l = 0; l <= next.depth(); ++l) {
        cp = counterparts(prev, next.level(l), l, cp, l > 0 ? &next.level(l - 1) : nullptr);
        for (uint32_t c : cp) kept += c != kNoOctant;
    }
    return (next.octant_count() - kept) + (prev.octant_count() - kept);
}

}  // namespace amc
