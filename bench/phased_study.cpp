// Issue 29 item 3's question, third form: a level-synchronous, phased hierarchy code. Each level's
// split symbols are coded in a few phases fixed by the node's place (its child index, a colouring
// the decoder can compute from the level's links, its ancestry), so that a node's context reads
// only the level above (complete) and the nodes of earlier phases of its own level: every phase
// could decode as a flat loop over an array, with no priority queue. What does it cost in size
// against the paper's improved traversal, and how fast does it decide?
//
//   phased_study FILE.amh...              every design x context set: bytes adaptive and static
//   phased_study --table FILE.amh...      the table of docs/HIERARCHY_CODER.md (a few designs)
//   phased_study --speed RUNS FILE.amh... deep3 (g,cn) coded for real, every decoded bit checked,
//                                         and decided by a prototype against the library's
//                                         deciding, alternating run by run (thread CPU time;
//                                         ONLY=lib, ONLY=proto or ONLY=levels runs one of them,
//                                         for callgrind); "levels alone": the decisions written
//                                         from the hierarchy, then scan and derivation (the part
//                                         of deciding no stream layout removes)
//   phased_study --mixed FILE.amh...      the mixing mode's seventh model (issue 30) in deep3's
//                                         and other phased orders against its two traversals
//                                         (CACHE_DIR=dir: deep3's symbols written for
//                                         bench/trained_states ORDER=deep3)
//   PHASED_DEBUG=phases/contexts          (first form) that design's bits per phase
//   PHASED_DEBUG=mixed[:design]           (--mixed) deep3's (or the design's) bits per phase
//                                         against each traversal's on the same nodes
//
// Every design keeps the paper's rules: 1-regularity culls (incomplete nodes take no symbol),
// uniform levels take none, a node whose three neighbours are known refined when its phase comes
// is refined (the hanging-node rule), the stream ends at its last 1. The roots are coded as the
// improved traversal codes them (Table 2's groups in its order), so the designs differ below the
// roots only. Sizes are exact: "adaptive" codes the symbols through the library's arithmetic coder
// with one BitModel (the coder's window) per context; "static" is the ideal code length under one
// table per level made from that level's counts (a 12-bit probability per context that holds both
// symbols, 2 bits per context slot to say unused / all 0 / all 1 / coded, 12 bits to list each
// context in use) plus the rANS state. The header and orientation bits are the same in every
// design and left out; "stream" is the library's whole hierarchy stream for reference.
//
// Phases (of a node c, child k of parent p; children 0-2 are corners, 3 the center, whose three
// neighbours are its siblings; a corner's other two neighbours are corners of p's neighbours'
// children around the same vertex of p):
//   1      one phase: no same-level context at all
//   c|k    the centers, then the corners
//   k|c    the corners, then the centers (which then know all three neighbours)
//   c|k0|k1|k2   the centers, then the corners by child index (a neighbour of another family
//          with the same index is not known)
//   c|f3   the centers, then the corners in three classes of a proper colouring of the corners'
//          own graph (paths and cycles around the parent level's vertices; greedy in canonical
//          order), so that every corner knows its center and the corners of earlier classes
//   f3|c   those corner classes first, then the centers
//   g4     a greedy proper colouring of the whole level (at most four colours) in canonical order
//   c4|f3  the centers in four classes of a colouring of their parents, then the corners as c|f3
//   cP|f3  the centers whose parent is a center first, then the others in three classes by their
//          parent's corner colour; then the corners as c|f3
//   cPP|cP|f3   cP|f3's first class split again by the grandparent
//   deepD  the same recursion D levels deep (phased_symbols)
// Contexts: g = the paper's group of the neighbours known so far (refined, not refined, unknown;
// a missing neighbour counts as not refined), the phase, r(p) = p's refined neighbours (0-3),
// s(p) = the sum of r(q) over p's neighbours q (0-9, in four bins), two = the refined nodes among
// the known second ring (0-3+), cn = the refined and unknown centers of the neighbouring families
// (a corner: the blocks across its outer edges; a center: its far centers, see deepD),
// d(p) = p's hop distance to a node not refined in the level above (capped at 8).
#include "bench_common.h"
#include "decide_only.h"
#include "mixed_symbols.h"
#include "static_table_cost.h"
#include "coding/entropy/arithmetic_coder.h"
#include "coding/entropy/rans_coder.h"
#include "coding/hierarchy/hierarchy_level_coder.h"
#include "coding/hierarchy/hierarchy_traversal.h"
#include "coding/hierarchy/hierarchy_stream.h"

#include <amc/hierarchy.h>
#include <amc/hierarchy_coder.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace {

using namespace amc;

// One level below the roots as the coder's level forest has it, with its truth.
struct LevelData {
    std::vector<Neighbors> nbr;
    std::vector<uint8_t> truth;
    std::vector<uint8_t> culled;   // decided before the traversal (1-regularity): not refined
    std::vector<uint32_t> parent;  // per block of four: the parent's local index in the level above
    std::vector<NodeId> ids;       // the nodes in h (--mixed: the features read them)
    bool uniform = false;
    uint32_t size() const { return uint32_t(truth.size()); }
};

struct Symbol {
    uint32_t context;
    bool bit;
    uint8_t phase = 0;  // for the breakdown; the roots 255
};

struct Collected {
    std::vector<LevelData> levels;  // levels[0] is the roots' (only nbr and truth are read)
    std::vector<Symbol> roots;      // the improved traversal's root symbols (context = group)
    std::vector<Symbol> improved;   // all of the improved traversal's symbols (context = group)
};

Collected collect(const Hierarchy& h) {
    HierarchyCoderOptions options;
    LevelTraversal traversal(options, kHierarchyStreamVersion);
    Collected out;
    Level level, next;
    RefinedNumbering numbering;
    std::vector<NodeId> ids, next_ids;
    std::vector<uint32_t> prev_refined;
    root_level(h, level, options.cull_one_regularity);
    for (NodeId r = 0; r < h.root_count(); ++r) ids.push_back(r);
    bool uniform_so_far = true;
    while (!level.empty()) {
        const uint32_t n = uint32_t(level.size());
        LevelData& d = out.levels.emplace_back();
        const bool all_refined = read_level(h, ids, n, d.truth, next_ids);
        d.ids = ids;
        d.uniform = uniform_so_far && all_refined;
        uniform_so_far = d.uniform;
        d.nbr.resize(n);
        d.culled.resize(n);
        with_links(level, [&](auto links) {
            for (uint32_t i = 0; i < n; ++i) d.nbr[i] = links.neighbors(i);
        });
        for (uint32_t i = 0; i < n; ++i) d.culled[i] = (level.state()[i] & kDecided) != 0;
        if (!level.is_root_level()) d.parent = prev_refined;
        const bool roots = level.is_root_level();
        traversal.run(
            level, d.uniform,
            [&](uint32_t i, int group) {
                out.improved.push_back({uint32_t(group), d.truth[i] != 0});
                if (roots) out.roots.push_back({uint32_t(group), d.truth[i] != 0});
                return d.truth[i] != 0;
            },
            [&](uint32_t i, Fate, bool) { return d.truth[i] != 0; });
        scan_decided_level(level, numbering, nullptr);
        prev_refined.assign(level.refined.data(), level.refined.data() + level.refined_count);
        derive_next_level(level, numbering, next, options.cull_one_regularity);
        std::swap(level, next);
        std::swap(ids, next_ids);
    }
    return out;
}

enum class Phases { one, center_corner, corner_center, center_k3, center_f3, f3_center, g4, c4_f3, cp_f3, cpp_f3, deep3, deep4, deep6 };
struct PhaseDesign {
    Phases phases;
    const char* name;
};
const PhaseDesign kPhaseDesigns[] = {
    {Phases::one, "1"},           {Phases::center_corner, "c|k"}, {Phases::corner_center, "k|c"},
    {Phases::center_k3, "c|k0|k1|k2"}, {Phases::center_f3, "c|f3"}, {Phases::f3_center, "f3|c"},
    {Phases::g4, "g4"},           {Phases::c4_f3, "c4|f3"},       {Phases::cp_f3, "cP|f3"},
    {Phases::cpp_f3, "cPP|cP|f3"},  {Phases::deep3, "deep3"}, {Phases::deep4, "deep4"}, {Phases::deep6, "deep6"},
};

// Context sets (bit flags): what a node's context holds besides the phase and its center flag.
constexpr unsigned kGroup = 1, kRp = 2, kSp = 4, kRing2 = 8, kCn = 16, kDist = 32;
struct ContextDesign {
    unsigned features;
    const char* name;
};
const ContextDesign kContextDesigns[] = {
    {kGroup, "g"}, {kGroup | kRp, "g,r(p)"}, {kGroup | kRp | kSp, "g,r(p),s(p)"},
    {kGroup | kRp | kRing2, "g,r(p),two"}, {kGroup | kRp | kSp | kRing2, "g,r(p),s(p),two"},
    {kGroup | kRp | kSp | kRing2 | kCn, "g,r(p),s(p),two,cn"}, {kGroup | kRp | kRing2 | kCn, "g,r(p),two,cn"},
    {kGroup | kRp | kRing2 | kCn | kDist, "g,r(p),two,cn,d(p)"}, {kGroup | kRing2 | kCn | kDist, "g,two,cn,d(p)"},
    {kGroup | kCn, "g,cn"}, {kGroup | kRp | kCn, "g,r(p),cn"}, {kGroup | kRing2 | kCn, "g,two,cn"},
};

// The phase of every node of level d (0..), or -1 for a culled node; returns the phase count.
// The greedy proper colouring (canonical order) of a level's corners' graph, -1 for centers.
std::vector<int8_t> corner_colours(const LevelData& d) {
    const uint32_t m = d.size();
    std::vector<int8_t> colour(m, -1);
    for (uint32_t x = 0; x < m; ++x) {
        if ((x & 3) == uint32_t(red_split::kCenter)) continue;
        unsigned used = 0;
        for (int e = 0; e < 3; ++e) {
            const uint32_t q = d.nbr[x].nbr[e];
            if (q == kNoLocal || (q >> 2) == (x >> 2)) continue;
            if (colour[q] >= 0) used |= 1u << colour[q];
        }
        int k = 0;
        while (used & (1u << k)) ++k;
        colour[x] = int8_t(k);
    }
    return colour;
}

int assign_phases(const LevelData& d, const LevelData& up, const LevelData* up2, Phases design, std::vector<int8_t>& phase) {
    const uint32_t n = d.size();
    phase.assign(n, 0);
    int count = 1;
    auto corner_colouring = [&](int first) {
        // Greedy proper colouring of the corners' graph (a corner's neighbours in other blocks),
        // canonical order: at most two such neighbours, so three colours suffice.
        std::vector<int8_t> colour(n, -1);
        for (uint32_t c = 0; c < n; ++c) {
            if ((c & 3) == uint32_t(red_split::kCenter) || d.culled[c]) continue;
            unsigned used = 0;
            for (int e = 0; e < 3; ++e) {
                const uint32_t q = d.nbr[c].nbr[e];
                if (q == kNoLocal || (q >> 2) == (c >> 2)) continue;
                if (colour[q] >= 0) used |= 1u << colour[q];
            }
            int k = 0;
            while (used & (1u << k)) ++k;
            colour[c] = int8_t(k);
            phase[c] = int8_t(first + k);
        }
    };
    switch (design) {
        case Phases::one: break;
        case Phases::center_corner:
            for (uint32_t c = 0; c < n; ++c) phase[c] = (c & 3) == uint32_t(red_split::kCenter) ? 0 : 1;
            count = 2;
            break;
        case Phases::corner_center:
            for (uint32_t c = 0; c < n; ++c) phase[c] = (c & 3) == uint32_t(red_split::kCenter) ? 1 : 0;
            count = 2;
            break;
        case Phases::center_k3:
            for (uint32_t c = 0; c < n; ++c) phase[c] = (c & 3) == uint32_t(red_split::kCenter) ? 0 : int8_t(1 + (c & 3));
            count = 4;
            break;
        case Phases::center_f3:
            for (uint32_t c = 0; c < n; ++c) phase[c] = 0;
            corner_colouring(1);
            count = 4;
            break;
        case Phases::f3_center:
            for (uint32_t c = 0; c < n; ++c) phase[c] = 3;
            corner_colouring(0);
            count = 4;
            break;
        case Phases::c4_f3: {
            // The centers in four classes by a greedy proper colouring of their parents' graph
            // (the refined nodes of the level above, canonical order), then the corners as c|f3.
            const uint32_t blocks = n / 4;
            std::vector<int32_t> block_of(up.size(), -1);
            for (uint32_t b = 0; b < blocks; ++b) block_of[d.parent[b]] = int32_t(b);
            std::vector<int8_t> colour(blocks, -1);
            for (uint32_t b = 0; b < blocks; ++b) {
                unsigned used = 0;
                for (int e = 0; e < 3; ++e) {
                    const uint32_t q = up.nbr[d.parent[b]].nbr[e];
                    if (q != kNoLocal && block_of[q] >= 0 && colour[size_t(block_of[q])] >= 0) used |= 1u << colour[size_t(block_of[q])];
                }
                int k = 0;
                while (used & (1u << k)) ++k;
                colour[b] = int8_t(k);
                phase[4 * b + red_split::kCenter] = int8_t(k);
            }
            corner_colouring(4);
            count = 7;
            break;
        }
        case Phases::cp_f3: {
            // The centers of the families whose parent is a center itself first (no two of them
            // are neighbours), then the other centers in three classes: the corners' colouring
            // (as c|f3's) of the level above, so every later center knows its parent's center
            // sibling's family; then the corners as c|f3. The children of roots: as c4|f3.
            if (up.parent.empty()) return assign_phases(d, up, up2, Phases::c4_f3, phase);
            const uint32_t m = up.size();
            std::vector<int8_t> colour(m, -1);
            for (uint32_t x = 0; x < m; ++x) {
                if ((x & 3) == uint32_t(red_split::kCenter)) continue;
                unsigned used = 0;
                for (int e = 0; e < 3; ++e) {
                    const uint32_t q = up.nbr[x].nbr[e];
                    if (q == kNoLocal || (q >> 2) == (x >> 2)) continue;
                    if (colour[q] >= 0) used |= 1u << colour[q];
                }
                int k = 0;
                while (used & (1u << k)) ++k;
                colour[x] = int8_t(k);
            }
            for (uint32_t b = 0; b < n / 4; ++b) {
                const uint32_t x = d.parent[b];
                phase[4 * b + red_split::kCenter] = (x & 3) == uint32_t(red_split::kCenter) ? 0 : int8_t(1 + colour[x]);
            }
            corner_colouring(4);
            count = 7;
            break;
        }
        case Phases::cpp_f3: {
            // cP|f3 with its first class split again one level up: the centers whose parent and
            // grandparent are centers, then those whose grandparent is a corner, in three classes
            // by the corners' colouring two levels up (each then knows the families of its
            // grandparent's neighbours' center children that came before); then as cP|f3.
            if (up.parent.empty() || up2 == nullptr || up2->parent.empty()) return assign_phases(d, up, up2, Phases::cp_f3, phase);
            const std::vector<int8_t> colour = corner_colours(up), colour2 = corner_colours(*up2);
            for (uint32_t b = 0; b < n / 4; ++b) {
                const uint32_t x = d.parent[b];
                int8_t ph;
                if ((x & 3) != uint32_t(red_split::kCenter)) {
                    ph = int8_t(4 + colour[x]);
                } else {
                    const uint32_t g = up.parent[x >> 2];
                    ph = (g & 3) == uint32_t(red_split::kCenter) ? 0 : int8_t(1 + colour2[g]);
                }
                phase[4 * b + red_split::kCenter] = ph;
            }
            corner_colouring(7);
            count = 10;
            break;
        }
        case Phases::deep3:
        case Phases::deep4:
        case Phases::deep6:
            return 0;  // phased_symbols assigns them (it holds every level)
        case Phases::g4: {
            std::vector<int8_t> colour(n, -1);
            for (uint32_t c = 0; c < n; ++c) {
                if (d.culled[c]) continue;
                unsigned used = 0;
                for (int e = 0; e < 3; ++e) {
                    const uint32_t q = d.nbr[c].nbr[e];
                    if (q != kNoLocal && colour[q] >= 0) used |= 1u << colour[q];
                }
                int k = 0;
                while (used & (1u << k)) ++k;
                colour[c] = int8_t(k);
                phase[c] = int8_t(k);
            }
            count = 4;
            break;
        }
    }
    for (uint32_t c = 0; c < n; ++c) {
        if (d.culled[c]) phase[c] = -1;
    }
    return count;
}

// The symbols of every level below the roots in the design's phases, each with its context.
// Contexts: ((((phase * 2 + center) * 10 + group) * 4 + r(p)) * 4 + s(p) bin) * 4 + two, unused
// features 0.
constexpr uint32_t kContextSlots = 32 * 2 * 10 * 4 * 4 * 4 * 17 * 9;

struct LevelSymbols {
    std::vector<std::vector<Symbol>> levels;  // per level below the roots, in coding order
    uint64_t forced = 0;                      // nodes the hanging-node rule decides
};

LevelSymbols phased_symbols(const Collected& data, Phases design, unsigned features) {
    LevelSymbols out;
    std::vector<int8_t> phase;
    std::vector<uint8_t> known;  // 0 unknown, 1 not refined, 2 refined
    // Every level's corner colouring and each node's block in the next level (deepD).
    std::vector<std::vector<int8_t>> colours(data.levels.size());
    std::vector<std::vector<uint32_t>> blocks(data.levels.size());
    for (size_t m = 0; m < data.levels.size(); ++m) {
        if (m >= 1) colours[m] = corner_colours(data.levels[m]);
        blocks[m].assign(data.levels[m].size(), kNoLocal);
        if (m + 1 < data.levels.size())
            for (uint32_t b = 0; b < data.levels[m + 1].size() / 4; ++b) blocks[m][data.levels[m + 1].parent[b]] = b;
    }
    for (size_t l = 1; l < data.levels.size(); ++l) {
        const LevelData& d = data.levels[l];
        std::vector<Symbol>& symbols = out.levels.emplace_back();
        if (d.uniform) continue;
        const LevelData& up = data.levels[l - 1];
        const uint32_t n = d.size();
        const LevelData* up2 = l >= 2 ? &data.levels[l - 2] : nullptr;
        int phases = assign_phases(d, up, up2, design, phase);
        // For cPP|cP|f3's second to fourth classes: each level l-1 node's block in level l, and
        // each level l-2 node's block in level l-1 (kNoLocal if not refined).
        std::vector<uint32_t> block_here(up.size(), kNoLocal), block_up(up2 ? up2->size() : 0, kNoLocal);
        for (uint32_t b = 0; b < n / 4; ++b) block_here[d.parent[b]] = b;
        if (up2 != nullptr && !up.parent.empty())
            for (uint32_t b = 0; b < up.size() / 4; ++b) block_up[up.parent[b]] = b;
        const bool far_centers = design == Phases::cpp_f3 && up2 != nullptr && !up2->parent.empty();
        // deepD: the centers by how many of their ancestors from the parent up are centers (j,
        // up to D): j = D (or reaching the roots) first, then j = D-1 .. 0, each in three classes
        // by the corners' colouring of the level of the first corner ancestor A; a center of
        // class j knows the families reached from A's neighbours by j+1 center children (its
        // nearest families of earlier classes). Then the corners as c|f3.
        const int depth = design == Phases::deep3 ? 3 : design == Phases::deep4 ? 4 : design == Phases::deep6 ? 6 : 0;
        std::vector<uint32_t> far(depth ? n / 4 * 3 : 0, kNoLocal);  // per block: the far centers
        if (depth) {
            phases = 3 * depth + 4;
            for (uint32_t b = 0; b < n / 4; ++b) {
                size_t m = l - 1;
                uint32_t x = d.parent[b];
                int j = 0;
                while (j < depth && m >= 1 && (x & 3) == uint32_t(red_split::kCenter)) {
                    x = data.levels[m].parent[x >> 2];
                    --m;
                    ++j;
                }
                const uint32_t center = 4 * b + uint32_t(red_split::kCenter);
                if (j == depth || m == 0) {
                    phase[center] = 0;
                    continue;
                }
                phase[center] = int8_t(1 + 3 * (depth - 1 - j) + colours[m][x]);
                for (int e = 0; e < 3; ++e) {
                    uint32_t y = data.levels[m].nbr[x].nbr[e];
                    for (size_t t = m; t < l && y != kNoLocal; ++t) {
                        const uint32_t block = blocks[t][y];
                        y = block == kNoLocal ? kNoLocal : 4 * block + uint32_t(red_split::kCenter);
                    }
                    far[3 * b + uint32_t(e)] = y;
                }
            }
            for (uint32_t c = 0; c < n; ++c) {
                if ((c & 3) != uint32_t(red_split::kCenter)) phase[c] = int8_t(3 * depth + 1 + colours[l][c]);
                if (d.culled[c]) phase[c] = -1;
            }
        }
        known.assign(n, 0);
        for (uint32_t c = 0; c < n; ++c) {
            if (d.culled[c]) known[c] = 1;
        }
        auto kind = [&](uint32_t q) { return q == kNoLocal ? 1 : known[q]; };
        // r(x) in the level above: exact, that level is decided.
        auto r_up = [&](uint32_t p) {
            int r = 0;
            for (int e = 0; e < 3; ++e) {
                const uint32_t q = up.nbr[p].nbr[e];
                r += q != kNoLocal && up.truth[q];
            }
            return r;
        };
        // d(x): hops in the level above from x to the nearest node that is not refined or lacks a
        // neighbour (1 for such a node; 0 for one not refined), capped: flat passes a decoder
        // could make once the level above is decided.
        std::vector<uint8_t> dist(up.size(), 0);
        if (features & kDist) {
            for (uint32_t x = 0; x < up.size(); ++x) {
                if (!up.truth[x]) continue;
                bool edge = false;
                for (int e = 0; e < 3; ++e) {
                    const uint32_t q = up.nbr[x].nbr[e];
                    edge |= q == kNoLocal || !up.truth[q];
                }
                dist[x] = edge ? 1 : 0xff;
            }
            for (int pass = 2; pass <= 8; ++pass) {
                for (uint32_t x = 0; x < up.size(); ++x) {
                    if (dist[x] != 0xff) continue;
                    for (int e = 0; e < 3; ++e) {
                        const uint32_t q = up.nbr[x].nbr[e];
                        if (q != kNoLocal && dist[q] == pass - 1) dist[x] = uint8_t(pass);
                    }
                }
            }
            for (uint8_t& v : dist) v = std::min<uint8_t>(v, 8);
        }
        std::vector<uint32_t> decided;
        for (int ph = 0; ph < phases; ++ph) {
            decided.clear();
            for (uint32_t c = 0; c < n; ++c) {
                if (phase[c] != ph) continue;
                int refined = 0, unrefined = 0;
                for (int e = 0; e < 3; ++e) {
                    const int k = kind(d.nbr[c].nbr[e]);
                    refined += k == 2;
                    unrefined += k == 1;
                }
                decided.push_back(c);
                if (refined == 3) {
                    if (!d.truth[c]) std::fprintf(stderr, "phased_study: a node with three refined neighbours is not refined\n");
                    ++out.forced;
                    continue;
                }
                const uint32_t p = d.parent[c >> 2];
                uint32_t context = uint32_t(ph) * 2 + ((c & 3) == uint32_t(red_split::kCenter));
                context = context * 10 + uint32_t((features & kGroup) ? context_group_of(refined, unrefined) : 0);
                context = context * 4 + uint32_t((features & kRp) ? r_up(p) : 0);
                int s_bin = 0;
                if (features & kSp) {
                    int s = 0;
                    for (int e = 0; e < 3; ++e) {
                        const uint32_t q = up.nbr[p].nbr[e];
                        if (q != kNoLocal) s += r_up(q);
                    }
                    s_bin = s == 0 ? 0 : s <= 4 ? 1 : s <= 7 ? 2 : 3;
                }
                context = context * 4 + uint32_t(s_bin);
                int two = 0;
                if (features & kRing2) {
                    for (int e = 0; e < 3; ++e) {
                        const uint32_t q = d.nbr[c].nbr[e];
                        if (q == kNoLocal) continue;
                        for (int f = 0; f < 3; ++f) {
                            const uint32_t t = d.nbr[q].nbr[f];
                            if (t != c && t != kNoLocal && known[t] == 2) ++two;
                        }
                    }
                }
                context = context * 4 + uint32_t(std::min(two, 3));
                int cn = 0;
                if (features & kCn) {
                    // The centers of the neighbouring families: of p's neighbours' children (a
                    // center), or of the outer neighbours' families (a corner): refined, unknown.
                    int cr = 0, cu = 0, cx = 0;
                    if ((c & 3) == uint32_t(red_split::kCenter)) {
                        // p's neighbours' blocks: the center of the block across each corner's outer edges
                        for (int e = 0; e < 3; ++e) {
                            const uint32_t q = d.nbr[c].nbr[e];
                            for (int f = 0; f < 3; ++f) {
                                const uint32_t u = d.nbr[q].nbr[f];
                                if (u == kNoLocal || (u >> 2) == (c >> 2)) continue;
                                const uint32_t z = (u & ~3u) | uint32_t(red_split::kCenter);
                                ++cx;
                                cr += known[z] == 2;
                                cu += known[z] == 0;
                            }
                        }
                        // each neighbouring family is seen from two corners: halve
                        cr /= 2; cu /= 2; cx /= 2;
                        cn = 1 + std::min(cr, 3) * 4 + std::min(cu, 3);
                    } else {
                        for (int e = 0; e < 3; ++e) {
                            const uint32_t u = d.nbr[c].nbr[e];
                            if (u == kNoLocal || (u >> 2) == (c >> 2)) continue;
                            const uint32_t z = (u & ~3u) | uint32_t(red_split::kCenter);
                            cr += known[z] == 2;
                            cu += known[z] == 0;
                        }
                        cn = 1 + cr * 4 + cu;
                    }
                    (void)cx;
                    if (depth && (c & 3) == uint32_t(red_split::kCenter)) {
                        cr = cu = 0;
                        for (int e = 0; e < 3; ++e) {
                            const uint32_t z = far[3 * (c >> 2) + uint32_t(e)];
                            if (z == kNoLocal) continue;
                            cr += known[z] == 2;
                            cu += known[z] == 0;
                        }
                        cn = ph == 0 ? 0 : 1 + cr * 4 + cu;
                    }
                    if (far_centers && ph >= 1 && ph <= 3) {
                        // The families of the centers of g's neighbours' children (g: c's
                        // grandparent), the nearest first-class families.
                        const uint32_t g = up.parent[p >> 2];
                        cr = cu = 0;
                        for (int e = 0; e < 3; ++e) {
                            const uint32_t g2 = up2->nbr[g].nbr[e];
                            if (g2 == kNoLocal || block_up[g2] == kNoLocal) continue;
                            const uint32_t p2 = 4 * block_up[g2] + uint32_t(red_split::kCenter);
                            if (block_here[p2] == kNoLocal) continue;
                            const uint32_t z = 4 * block_here[p2] + uint32_t(red_split::kCenter);
                            cr += known[z] == 2;
                            cu += known[z] == 0;
                        }
                        cn = 1 + cr * 4 + cu;
                    }
                }
                context = context * 17 + uint32_t(cn);
                context = context * 9 + uint32_t((features & kDist) ? dist[p] : 0);
                symbols.push_back({context, d.truth[c] != 0, uint8_t(ph)});
            }
            for (uint32_t c : decided) known[c] = d.truth[c] ? 2 : 1;
        }
    }
    return out;
}

// Bytes of `symbols` (in order, trailing zeros dropped) through the library's arithmetic coder,
// one adaptive model per context.
size_t adaptive_bytes(const std::vector<Symbol>& symbols, uint32_t contexts) {
    size_t kept = symbols.size();
    while (kept > 0 && !symbols[kept - 1].bit) --kept;
    std::vector<BitModel> models(contexts);
    ArithmeticEncoder encoder;
    for (size_t k = 0; k < kept; ++k) encoder.encode_with_limit<kHierarchyModelLimit>(symbols[k].bit, models[symbols[k].context]);
    return encoder.finish().size();
}

// The adaptive code length of the symbols of each phase (the roots apart), printed: where the bits go.
void print_phase_costs(const std::vector<Symbol>& symbols, uint32_t contexts) {
    std::vector<BitModel> models(contexts);
    double bits[256] = {};
    uint64_t count[256] = {}, ones[256] = {};
    for (const Symbol& s : symbols) {
        BitModel& m = models[s.context];
        bits[s.phase] += m.cost_bits(s.bit);
        ++count[s.phase];
        ones[s.phase] += s.bit;
        m.update_with_limit(s.bit, kHierarchyModelLimit);
    }
    for (int p = 0; p < 256; ++p) {
        if (count[p] == 0) continue;
        std::printf("      phase %3d: %7llu symbols, %5.1f%% ones, %8.0f bits (%.3f a symbol)\n", p, (unsigned long long)count[p],
                    100.0 * double(ones[p]) / double(count[p]), bits[p], bits[p] / double(count[p]));
    }
}

// Ideal code length in bits of one table's symbols: counts[context][bit], the table's own bits added
// to *table_bits (2 bits a slot in use, 12 for a coded probability).
double static_bits(const std::vector<std::array<uint64_t, 2>>& counts, double* table_bits) {
    double bits = 0;
    for (const auto& c : counts) bits += static_slot_bits(c[0], c[1], table_bits);
    return bits;
}

// Static per-level tables; the contexts in use anywhere are the slots every level's table holds
// (a decoder would read the list once).
double static_bytes(const std::vector<Symbol>& roots, const LevelSymbols& levels) {
    double bits = 0, table_bits = 0;
    std::vector<uint8_t> used(kContextSlots, 0);
    for (const auto& level : levels.levels)
        for (const Symbol& s : level) used[s.context] = 1;
    std::vector<uint32_t> slot_of(kContextSlots, 0);
    uint32_t slots = 0;
    for (uint32_t k = 0; k < kContextSlots; ++k)
        if (used[k]) slot_of[k] = slots++;
    table_bits += slots * 12.0;  // the list of contexts in use (an index each)
    {
        std::vector<std::array<uint64_t, 2>> counts(kContextGroupCount, {0, 0});
        for (const Symbol& s : roots) ++counts[s.context][s.bit];
        bits += static_bits(counts, &table_bits);
    }
    for (const auto& level : levels.levels) {
        if (level.empty()) continue;
        std::vector<std::array<uint64_t, 2>> counts(slots, {0, 0});
        for (const Symbol& s : level) ++counts[slot_of[s.context]][s.bit];
        bits += static_bits(counts, &table_bits);
    }
    return (bits + table_bits) / 8 + kRansStateBytes;
}

}  // namespace


// ---- deep3 with the g,cn contexts, coded for real and decided: the speed prototype ----
//
// The decoder's loop as a flat pass per phase: each level's per-block class (depth j and the
// colour of the first corner ancestor) and far families come from the level above's in one pass
// over the blocks; the corners' colouring is one greedy pass; the nodes are bucketed by phase;
// each phase reads only states written before it, and its decisions are written to the states
// (and counted at the neighbours) after it. The roots go through the library's improved
// traversal. Encoder and decoder run the same code (`Code`), so they agree on every context.

constexpr int kProtoDepth = 3;
constexpr int kProtoPhases = 3 * kProtoDepth + 4;
constexpr uint32_t kProtoContexts = uint32_t(kProtoPhases) * 10 * 17;
constexpr uint8_t kTop = 0xff;

struct ProtoBlocks {
    std::vector<uint8_t> depth;   // per block: j (0..kProtoDepth-1) or kTop
    std::vector<uint8_t> colour;  // per block: the colour of its first corner ancestor
    std::vector<uint32_t> far;    // per block: the centers of three far blocks of this level, or kNoLocal
};

struct ProtoDecider {
    Level prev, cur, next;
    RefinedNumbering numbering;
    std::vector<uint32_t> closures;
    ProtoBlocks up_blocks, blocks;  // the classes of this level's blocks, and of the next level's
    std::vector<int8_t> up_colour, colour;  // the corners' colouring of the level above and of this one
    std::vector<uint32_t> order, start;
    std::vector<uint8_t> phase;
    std::vector<BitModel> models;
    HierarchyModels root_models;
    // Symbols the stream still holds (the decoder: its count; everything after is 0).
    uint32_t symbols_left = 0xffffffffu;

    // code(context, node, level) -> bool: the encoder codes the truth, the decoder decodes.
    template <class Code>
    uint64_t run(const Hierarchy& roots_source, uint32_t uniform_levels, Code&& code) {
        models.assign(kProtoContexts, BitModel{});
        root_models = HierarchyModels{};
        HierarchyCoderOptions options;
        LevelTraversal traversal(options, kHierarchyStreamVersion);
        root_level(roots_source, cur, true);
        uint64_t nodes = cur.size();
        uint32_t l = 0;
        while (!cur.empty()) {
            const uint32_t n = uint32_t(cur.size());
            uint8_t* state = cur.state();
            const bool uniform = l < uniform_levels;
            if (uniform || cur.is_root_level()) {
                traversal.run(
                    cur, uniform,
                    [&](uint32_t i, int group) {
                        if (symbols_left == 0) return false;
                        --symbols_left;
                        return code(root_models.groups[size_t(group)], i, l);
                    },
                    [&](uint32_t, Fate, bool refined) { return refined; });
                corner_colours_of(cur, colour);  // for the next level's classes
            } else {
                decide_phases(n, state, l, code);
            }
            closures.resize(n);
            scan_decided_level(cur, numbering, closures.data());
            derive_next_level(cur, numbering, next, true);
            nodes += next.size();
            classes_of_next(cur, next);
            std::swap(prev, cur);
            std::swap(cur, next);
            std::swap(up_colour, colour);
            std::swap(up_blocks, blocks);
            ++l;
        }
        return nodes;
    }

    // The corners' greedy colouring (canonical order), as corner_colours: 0-2 for corners, 3 for
    // centers and in the slot in front (read for a missing neighbour), so that a colour's bit
    // 1 << 3 never blocks a corner colour; a corner not yet coloured reads 3 as well.
    static void corner_colours_of(const Level& level, std::vector<int8_t>& out) {
        const uint32_t n = uint32_t(level.size());
        out.assign(size_t(n) + 1, 3);
        if (level.is_root_level()) return;
        int8_t* colour = out.data() + 1;
        const Neighbors* nbr = level.nbr.data();
        for (uint32_t c = 0; c < n; ++c) {
            if ((c & 3) == uint32_t(red_split::kCenter)) continue;
            const Neighbors node = nbr[c];
            const unsigned used = (1u << colour[int32_t(node.nbr[0])]) | (1u << colour[int32_t(node.nbr[1])]) |
                                  (1u << colour[int32_t(node.nbr[2])]);
            colour[c] = int8_t(__builtin_ctz(~used));
        }
    }

    // The class and far blocks of every block of `below` (derived from `level`, whose numbering
    // is current).
    void classes_of_next(const Level& level, const Level& below) {
        const uint32_t blocks_below = uint32_t(below.size() / 4);
        blocks.depth.resize(blocks_below);
        blocks.colour.resize(blocks_below);
        blocks.far.resize(size_t(blocks_below) * 3);
        const uint32_t* block_of = numbering.block_of();
        const uint32_t* parent = level.refined.data();
        const bool roots = level.is_root_level();
        for (uint32_t b = 0; b < blocks_below; ++b) {
            const uint32_t x = parent[b];
            uint32_t* far = &blocks.far[3 * size_t(b)];
            if (roots) {
                blocks.depth[b] = kTop;
                far[0] = far[1] = far[2] = kNoLocal;
                continue;
            }
            if ((x & 3) != uint32_t(red_split::kCenter)) {
                blocks.depth[b] = 0;
                blocks.colour[b] = uint8_t(colour[size_t(x) + 1]);
                const Neighbors nb = level.nbr.data()[x];
                for (int e = 0; e < 3; ++e) {
                    const uint32_t f = block_of[int32_t(nb.nbr[e])];
                    far[e] = f == kNoLocal ? kNoLocal : 4 * f + uint32_t(red_split::kCenter);
                }
                continue;
            }
            const uint32_t pb = x >> 2;
            const uint8_t j = up_blocks.depth[pb];
            if (j == kTop || j + 1 == kProtoDepth) {
                blocks.depth[b] = kTop;
                far[0] = far[1] = far[2] = kNoLocal;
                continue;
            }
            blocks.depth[b] = uint8_t(j + 1);
            blocks.colour[b] = up_blocks.colour[pb];
            for (int e = 0; e < 3; ++e) {
                const uint32_t f = block_of[int32_t(up_blocks.far[3 * size_t(pb) + size_t(e)])];
                far[e] = f == kNoLocal ? kNoLocal : 4 * f + uint32_t(red_split::kCenter);
            }
        }
    }

    template <class Code>
    void decide_phases(uint32_t n, uint8_t* state, uint32_t l, Code& code) {
        if (symbols_left == 0) {
            // The stream has ended: every node of the level is not refined (none is, so the
            // hanging-node rule forces none); the next level is empty.
            for (uint32_t c = 0; c < n; ++c) state[c] = uint8_t(state[c] | kDecided);
            colour.assign(size_t(n) + 1, 3);
            return;
        }
        const Neighbors* nbr = cur.nbr.data();
        // One pass over the blocks: the corners' greedy colouring (as corner_colours_of), every
        // node's phase and the phases' sizes; then the nodes bucketed by phase (canonical order
        // within a phase).
        colour.assign(size_t(n) + 1, 3);
        int8_t* corner_colour = colour.data() + 1;
        phase.resize(n);
        const uint8_t* depth = up_blocks.depth.data();
        const uint8_t* first_colour = up_blocks.colour.data();
        uint32_t counts[kProtoPhases + 1] = {};
        for (uint32_t b = 0; b < n / 4; ++b) {
            for (uint32_t c = 4 * b; c < 4 * b + 3; ++c) {
                const Neighbors node = nbr[c];
                const unsigned used = (1u << corner_colour[int32_t(node.nbr[0])]) | (1u << corner_colour[int32_t(node.nbr[1])]) |
                                      (1u << corner_colour[int32_t(node.nbr[2])]);
                const int k = __builtin_ctz(~used);
                corner_colour[c] = int8_t(k);
                const uint8_t ph = state[c] & kDecided ? uint8_t(kProtoPhases) : uint8_t(3 * kProtoDepth + 1 + k);
                phase[c] = ph;
                ++counts[ph];
            }
            const uint8_t j = depth[b];
            const uint8_t ph = state[4 * b + 3] & kDecided ? uint8_t(kProtoPhases)
                               : j == kTop                  ? 0
                                                            : uint8_t(1 + 3 * (kProtoDepth - 1 - j) + first_colour[b]);
            phase[4 * b + 3] = ph;
            ++counts[ph];
        }
        start.assign(kProtoPhases + 1, 0);
        for (int k = 0; k < kProtoPhases; ++k) start[size_t(k) + 1] = start[size_t(k)] + counts[k];
        order.resize(start[kProtoPhases] + 1);
        {
            uint32_t at[kProtoPhases + 1];
            for (int k = 0; k < kProtoPhases; ++k) at[k] = start[size_t(k)];
            at[kProtoPhases] = start[kProtoPhases];  // the decided ones go to one spare slot
            uint32_t* out = order.data();
            for (uint32_t c = 0; c < n; ++c) {
                const unsigned k = phase[c];
                out[at[k]] = c;
                at[k] += k != unsigned(kProtoPhases);
            }
        }
        const uint32_t* far = up_blocks.far.data();
        // One node: the hanging-node rule, or its symbol in context (phase, group, cn); its state
        // written at once and counted at its neighbours. No context reads a node of its own phase
        // (the phases are independent sets, and cn reads centers of other classes), so this is
        // the same as writing the phase's decisions after it.
        auto decide = [&](uint32_t c, int ph, const Neighbors& node, unsigned code_bits, unsigned cn) {
            const int group = kContextTable.group[code_bits];
            bool refined = group == 9;  // (3,0,0): the hanging-node rule
            if (!refined && symbols_left != 0) {
                --symbols_left;
                refined = code(models[(uint32_t(ph) * 10 + uint32_t(group)) * 17 + cn], c, l);
            }
            // Counted at the neighbours without a branch (whether a node is refined is a coin
            // flip); a missing neighbour's shared byte takes the count harmlessly (Level::state).
            state[c] = uint8_t(state[c] | kDecided | (refined ? kRefined : 0));
            const uint8_t add = uint8_t(refined ? kRefinedNeighbor : 0);
            for (int e = 0; e < 3; ++e) {
                uint8_t& t = neighbor_state(state, node.nbr[e]);
                t = uint8_t(t + add);
            }
        };
        auto refined_unknown = [](uint8_t s) { return 4 * ((s >> 1) & 1u) + !(s & kDecided); };
        for (int ph = 0; ph < kProtoPhases; ++ph) {
            const uint32_t* first = order.data() + start[size_t(ph)];
            const uint32_t* last = order.data() + start[size_t(ph) + 1];
            if (ph == 0) {
                // The first class of centers: only the siblings (nothing of this level is known).
                for (const uint32_t* it = first; it != last; ++it) {
                    const uint32_t c = *it;
                    const unsigned code_bits = unsigned(state[c - 3] & (kDecided | kRefined)) |
                                               unsigned(state[c - 2] & (kDecided | kRefined)) << 2 |
                                               unsigned(state[c - 1] & (kDecided | kRefined)) << 4;
                    decide(c, 0, nbr[c], code_bits, 0);
                }
            } else if (ph <= 3 * kProtoDepth) {
                // Centers: the neighbours are the siblings; the far centers of earlier classes.
                for (const uint32_t* it = first; it != last; ++it) {
                    const uint32_t c = *it, b = c >> 2;
                    const unsigned code_bits = unsigned(state[c - 3] & (kDecided | kRefined)) |
                                               unsigned(state[c - 2] & (kDecided | kRefined)) << 2 |
                                               unsigned(state[c - 1] & (kDecided | kRefined)) << 4;
                    const uint32_t* f = far + 3 * size_t(b);
                    const unsigned cn = 1 + refined_unknown(state[int32_t(f[0])]) + refined_unknown(state[int32_t(f[1])]) +
                                        refined_unknown(state[int32_t(f[2])]);
                    decide(c, ph, nbr[c], code_bits, cn);
                }
            } else {
                // Corners: the three neighbours; the centers of the blocks across them, less the own.
                for (const uint32_t* it = first; it != last; ++it) {
                    const uint32_t c = *it;
                    const Neighbors node = nbr[c];
                    unsigned code_bits = 0, across = 0;
                    for (int e = 0; e < 3; ++e) {
                        const uint32_t q = node.nbr[e];
                        code_bits |= unsigned(neighbor_state(state, q) & (kDecided | kRefined)) << (2 * e);
                        across += refined_unknown(state[int32_t(q | 3u)]);
                    }
                    decide(c, ph, node, code_bits, 1 + across - refined_unknown(state[c | 3u]));
                }
            }
        }
    }
};

// The prototype's stream: uniform level count, kept symbol count, the arithmetic-coded bytes.
struct ProtoStream {
    uint32_t uniform_levels = 0, kept = 0;
    std::vector<uint8_t> bytes;
};

uint32_t uniform_level_count(const Collected& data) {
    uint32_t u = 0;
    while (u < data.levels.size() && data.levels[u].uniform) ++u;
    return u;
}

ProtoStream encode_proto(const Hierarchy& h, const Collected& data) {
    ProtoStream s;
    s.uniform_levels = uniform_level_count(data);
    ProtoDecider coder;
    struct Coded {
        BitModel* model;
        bool bit;
    };
    // First the symbols (models are only identified here), then the code up to the last 1.
    std::vector<std::pair<uint32_t, bool>> symbols;  // (model index, bit): roots after kProtoContexts
    coder.run(h, s.uniform_levels, [&](BitModel& model, uint32_t i, uint32_t l) {
        const bool bit = data.levels[l].truth[i] != 0;
        const uint32_t index = &model >= coder.models.data() && &model < coder.models.data() + coder.models.size()
                                   ? uint32_t(&model - coder.models.data())
                                   : kProtoContexts + uint32_t(&model - coder.root_models.groups.data());
        symbols.push_back({index, bit});
        return bit;
    });
    size_t kept = symbols.size();
    while (kept > 0 && !symbols[kept - 1].second) --kept;
    s.kept = uint32_t(kept);
    std::vector<BitModel> models(kProtoContexts + kContextGroupCount);
    ArithmeticEncoder encoder;
    for (size_t k = 0; k < kept; ++k) encoder.encode_with_limit<kHierarchyModelLimit>(symbols[k].second, models[symbols[k].first]);
    s.bytes = encoder.finish();
    return s;
}

uint64_t decide_proto(ProtoDecider& decider, const Hierarchy& roots_only, const ProtoStream& s) {
    ArithmeticDecoder d(s.bytes.data(), s.bytes.size());
    decider.symbols_left = s.kept;
    return decider.run(roots_only, s.uniform_levels, [&](BitModel& model, uint32_t, uint32_t) {
        return d.decode_with_limit<kHierarchyModelLimit>(model);
    });
}

// What deciding costs without any traversal or symbol: every level's truth written straight into
// its states (counted at the neighbours), then the library's scan and derivation, as the
// decoders run them. No stream layout can decide for less.
uint64_t levels_only(ProtoDecider& scratch, const Hierarchy& roots_only, const Collected& data) {
    Level& cur = scratch.cur;
    Level& next = scratch.next;
    root_level(roots_only, cur, true);
    uint64_t nodes = cur.size();
    for (size_t l = 0; !cur.empty(); ++l) {
        const uint32_t n = uint32_t(cur.size());
        uint8_t* state = cur.state();
        const uint8_t* truth = data.levels[l].truth.data();
        with_links(cur, [&](auto links) {
            for (uint32_t i = 0; i < n; ++i) {
                if (state[i] & kDecided) continue;
                const bool refined = truth[i] != 0;
                state[i] = uint8_t(state[i] | kDecided | (refined ? kRefined : 0));
                const uint8_t add = uint8_t(refined ? kRefinedNeighbor : 0);
                const Neighbors node = links.neighbors(i);
                for (int e = 0; e < 3; ++e) {
                    uint8_t& t = neighbor_state(state, node.nbr[e]);
                    t = uint8_t(t + add);
                }
            }
        });
        scratch.closures.resize(n);
        scan_decided_level(cur, scratch.numbering, scratch.closures.data());
        derive_next_level(cur, scratch.numbering, next, true);
        nodes += next.size();
        std::swap(cur, next);
    }
    return nodes;
}

// ---- The mixing mode in deep3 order (--mixed; issue 30) ----
//
// The mixing mode's seventh model (MixedHierarchyModel over mixed_features, the library's own)
// codes the same symbols in deep3's order instead of a traversal's: the prototype's order
// (ProtoDecider::run: each decision written at once), each node's features read from the level's
// states as they stand at its turn, so a node of a later phase sees its neighbours on all sides.
// Against it, the library's mixed symbols in the improved and the naive traversal
// (HierarchyLevelEncoder::mixed_symbols). The hierarchy is taken in the decoder's base order
// (in_decoder_order), as files code it. Bytes are the symbols' payload through the library's
// arithmetic coder up to the last 1; the header and the orientation bits, the same in every
// order, are left out (the file's hierarchy bytes less the smaller traversal's payload is that
// rest, for a file the seventh model wrote).

struct MixedSymbol {
    MixedFeatures f;
    bool bit;
    uint8_t phase;     // deep3's phase (0 .. kProtoPhases - 1), kTop for the roots and the traversals' symbols
    uint32_t context;  // deep3's (phase, group, cn) context of the prototype, kProtoContexts + group for the others
    NodeId node;
};

// The library's mixed symbols (the coded ones) of h in `traversal`.
std::vector<MixedSymbol> traversal_mixed_symbols(const Hierarchy& h, Traversal traversal) {
    HierarchyCoderOptions options;
    options.traversal = traversal;
    std::vector<CodedSymbol> trace;
    const HierarchyLevelEncoder coder(h, options, kHierarchyStreamVersion, &trace, true, nullptr, nullptr, false);
    std::vector<MixedSymbol> out;
    for (const auto& [f, bit] : coder.mixed_symbols()) out.push_back({f, bit, kTop, kProtoContexts + f.group, trace[out.size()].node});
    return out;
}

// The symbols of h (collected in `data`) in deep3's order with the seventh model's features, up
// to the last 1.
std::vector<MixedSymbol> deep3_mixed_symbols(const Hierarchy& h, const Collected& data) {
    ProtoDecider coder;
    LevelShapes shapes;
    uint32_t shaped = UINT32_MAX;  // the level `shapes` holds
    std::vector<MixedSymbol> out;
    coder.run(h, uniform_level_count(data), [&](BitModel& model, uint32_t i, uint32_t l) {
        if (l != shaped) shapes.start_level(coder.cur.size()), shaped = l;
        // The prototype's model index is (phase * 10 + group) * 17 + cn; the roots' models are groups.
        int group = 0;
        uint8_t phase = kTop;
        uint32_t context = 0;
        if (&model >= coder.models.data() && &model < coder.models.data() + coder.models.size()) {
            context = uint32_t(&model - coder.models.data());
            group = int(context / 17 % 10);
            phase = uint8_t(context / 170);
        } else {
            group = int(&model - coder.root_models.groups.data());
            context = kProtoContexts + uint32_t(group);
        }
        const bool bit = data.levels[l].truth[i] != 0;
        const NodeId node = data.levels[l].ids[i];
        out.push_back({mixed_features(h, node, coder.cur, i, group, shapes, MixingModel::seventh), bit, phase, context, node});
        return bit;
    });
    size_t kept = out.size();
    while (kept > 0 && !out[kept - 1].bit) --kept;
    out.resize(kept);
    return out;
}

// The same in the phases of one of assign_phases' designs (not deepD): the roots and uniform
// levels as the improved traversal codes them, then each level's nodes phase by phase, canonical
// order within a phase, each decision written at once (the hanging-node rule as everywhere).
std::vector<MixedSymbol> phased_mixed_symbols(const Hierarchy& h, const Collected& data, Phases design) {
    HierarchyCoderOptions options;
    LevelTraversal traversal(options, kHierarchyStreamVersion);
    Level level, next;
    RefinedNumbering numbering;
    LevelShapes shapes;
    std::vector<int8_t> phase;
    std::vector<MixedSymbol> out;
    root_level(h, level, options.cull_one_regularity);
    for (size_t l = 0; !level.empty(); ++l) {
        const LevelData& d = data.levels[l];
        const uint32_t n = uint32_t(level.size());
        uint8_t* state = level.state();
        shapes.start_level(n);
        auto symbol = [&](uint32_t i, int group, uint8_t ph) {
            const bool bit = d.truth[i] != 0;
            out.push_back({mixed_features(h, d.ids[i], level, i, group, shapes, MixingModel::seventh), bit, ph,
                           kProtoContexts + uint32_t(group), d.ids[i]});
            return bit;
        };
        if (level.is_root_level() || d.uniform) {
            traversal.run(
                level, d.uniform, [&](uint32_t i, int group) { return symbol(i, group, kTop); },
                [&](uint32_t i, Fate, bool) { return d.truth[i] != 0; });
        } else {
            const int phases = assign_phases(d, data.levels[l - 1], l >= 2 ? &data.levels[l - 2] : nullptr, design, phase);
            const Neighbors* nbr = level.nbr.data();
            for (int ph = 0; ph < phases; ++ph) {
                for (uint32_t c = 0; c < n; ++c) {
                    if (phase[c] != ph || (state[c] & kDecided)) continue;
                    unsigned code_bits = 0;
                    for (int e = 0; e < 3; ++e) code_bits |= unsigned(neighbor_state(state, nbr[c].nbr[e]) & (kDecided | kRefined)) << (2 * e);
                    const int group = kContextTable.group[code_bits];
                    const bool refined = group == 9 ? true : symbol(c, group, uint8_t(ph));  // (3,0,0): the hanging-node rule
                    state[c] = uint8_t(state[c] | kDecided | (refined ? kRefined : 0));
                    if (refined)
                        for (int e = 0; e < 3; ++e) neighbor_state(state, nbr[c].nbr[e]) += kRefinedNeighbor;
                }
            }
        }
        scan_decided_level(level, numbering, nullptr);
        derive_next_level(level, numbering, next, options.cull_one_regularity);
        std::swap(level, next);
    }
    size_t kept = out.size();
    while (kept > 0 && !out[kept - 1].bit) --kept;
    out.resize(kept);
    return out;
}

// The other phased orders --mixed measures (phased_mixed_symbols): one phase (the naive order
// below the roots), the centers first or last, a colouring of the whole level.
constexpr Phases kMixedDesigns[] = {Phases::one, Phases::corner_center, Phases::center_f3, Phases::f3_center, Phases::g4};

// What a deep3 version could add after the seventh model (study-only stages on its probability):
//   map: averaged with an adaptive map's refinement of it by phase x group (the node's phase says
//        what it knows);
//   cn:  mixed (a 3-input mixer, weight set by phase) with the prototype's adaptive model of the
//        node's (phase, group, cn) context: the far centers, which no mixed feature reads.
enum class Stage { none, map, cn };

// Payload bytes of `symbols` coded by the seventh model (initial states `trained`) and `stage`.
size_t mixed_payload(const std::vector<MixedSymbol>& symbols, Stage stage, const TrainedStateTables& trained = kTrainedStateTables) {
    MixedHierarchyModel model(MixingModel::seventh, trained);
    mixing::ProbabilityMap map((kProtoPhases + 1) * kContextGroupCount, 7);
    std::vector<BitModel> contexts(kProtoContexts + kContextGroupCount);
    constexpr int32_t kStart[3] = {1 << 16, 0, 0};
    mixing::Mixer mixer(3, kProtoPhases + 1, 16, kStart);
    int st[mixing::Mixer::padded(3)] = {};
    ArithmeticEncoder encoder;
    for (const MixedSymbol& s : symbols) {
        uint32_t p = model.p16(s.f);
        const int phase = s.phase == kTop ? kProtoPhases : s.phase;
        if (stage == Stage::map) {
            const uint32_t refined = uint32_t(map.refine(int(p >> 4), phase * kContextGroupCount + s.f.group)) << 4;
            p = std::clamp<uint32_t>((p + refined) / 2, 1, 65535);
        } else if (stage == Stage::cn) {
            st[0] = mixing::stretch(std::clamp(int(p >> 4), 1, 4095));
            st[1] = mixing::stretch(mixing::p12_of(contexts[s.context]));
            st[2] = 256;
            p = std::clamp<uint32_t>(uint32_t(mixer.mix(st, phase)) << 4, 1, 65535);
        }
        encoder.encode_with_probability(s.bit, p);
        model.update(s.bit);
        if (stage == Stage::map) map.update(s.bit);
        if (stage == Stage::cn) {
            mixer.update(st, s.bit);
            contexts[s.context].update_with_limit(s.bit, kHierarchyModelLimit);
        }
    }
    return encoder.finish().size();
}

// PHASED_DEBUG=mixed: where deep3 gains and loses against a traversal, by deep3's phase: each
// node's code length in both orders (the seventh model), summed over the nodes both code.
void print_mixed_phase_costs(const std::vector<MixedSymbol>& deep3, const std::vector<MixedSymbol>& traversal, size_t nodes) {
    auto costs = [&](const std::vector<MixedSymbol>& symbols) {
        std::vector<double> bits(nodes, -1);
        MixedHierarchyModel model(MixingModel::seventh);
        for (const MixedSymbol& s : symbols) {
            const double p = model.p16(s.f) / 65536.0;
            bits[s.node] = -std::log2(s.bit ? p : 1 - p);
            model.update(s.bit);
        }
        return bits;
    };
    const std::vector<double> in_deep3 = costs(deep3), in_traversal = costs(traversal);
    double d[kProtoPhases + 1] = {}, t[kProtoPhases + 1] = {}, only_d = 0, only_t = 0;
    uint64_t count[kProtoPhases + 1] = {}, ones[kProtoPhases + 1] = {};
    for (const MixedSymbol& s : deep3) {
        const int phase = s.phase == kTop ? kProtoPhases : s.phase;
        if (in_traversal[s.node] < 0) {
            only_d += in_deep3[s.node];
            continue;
        }
        d[phase] += in_deep3[s.node], t[phase] += in_traversal[s.node], ++count[phase], ones[phase] += s.bit;
    }
    for (const MixedSymbol& s : traversal)
        if (in_deep3[s.node] < 0) only_t += in_traversal[s.node];
    for (int p = 0; p <= kProtoPhases; ++p) {
        if (count[p] == 0) continue;
        std::fprintf(stderr, "    phase %2d%s: %7llu symbols, %5.1f%% ones, deep3 %8.0f bits, traversal %8.0f bits (%+.1f%%)\n", p,
                     p == kProtoPhases ? " (roots)" : "", (unsigned long long)count[p], 100.0 * double(ones[p]) / double(count[p]), d[p],
                     t[p], 100.0 * (d[p] - t[p]) / t[p]);
    }
    std::fprintf(stderr, "    coded in one order only: deep3 %.0f bits, traversal %.0f bits\n", only_d, only_t);
}

// bench/mixed_symbols.h's cache entry of deep3's symbols (CACHE_DIR/<model>-deep3.mf8), for
// bench/trained_states ORDER=deep3: states trained on them, measured without the model's mesh.
void write_mixed_cache(const std::string& dir, const std::string& name, const Hierarchy& h, const std::vector<MixedSymbol>& symbols) {
    mixed_study::ModelData d;
    d.name = name;
    {
        HierarchyLevelEncoder paper(h, HierarchyCoderOptions{});
        ArithmeticEncoder sink;
        for (int l = 0; l < paper.level_count(); ++l) paper.encode_level(l, sink);
        for (const ContextGroupStats& g : paper.stats().groups) d.paper_bits += g.coded_bits;
    }
    for (const MixedSymbol& s : symbols) d.symbols.push_back({s.f, uint8_t(s.bit)});
    d.library_bits = mixed_study::model_bits(MixingModel::seventh, d.symbols);
    mixed_study::write_cache(std::filesystem::path(dir) / (name + "-deep3.mf8"), d);
}

// The table of docs/HIERARCHY_CODER.md: a few designs per model (--table).
struct TableColumn {
    Phases phases;
    unsigned features;
    bool adaptive;
    const char* name;
};
const TableColumn kTable[] = {
    {Phases::center_corner, kGroup | kRp, true, "c|k g,r(p)"},
    {Phases::center_f3, kGroup | kRp | kRing2, true, "c|f3 g,r(p),two"},
    {Phases::cp_f3, kGroup | kRp | kRing2 | kCn, true, "cP|f3 +cn"},
    {Phases::cpp_f3, kGroup | kRp | kRing2 | kCn, true, "cPP|cP|f3 +cn"},
    {Phases::deep3, kGroup | kRp | kRing2 | kCn, true, "deep3 +cn"},
    {Phases::deep3, kGroup | kCn, true, "deep3 g,cn"},
    {Phases::deep3, kGroup | kCn, false, "deep3 g,cn, static"},
};

int main(int argc, char** argv) {
    int first = 1;
    const bool table = argc > 1 && std::string(argv[1]) == "--table";
    const bool mixed = argc > 1 && std::string(argv[1]) == "--mixed";
    if (table || mixed) first = 2;
    int speed_runs = 0;
    if (argc > 2 && std::string(argv[1]) == "--speed") {
        speed_runs = std::max(1, std::atoi(argv[2]));
        first = 3;
    }
    if (first >= argc) {
        std::fprintf(stderr, "usage: phased_study [--table] FILE.amh...\n");
        return 2;
    }
    const char* debug = std::getenv("PHASED_DEBUG");  // "phases/contexts": that design's cost per phase
    if (mixed) {
        std::printf("| model | file: base + hierarchy | improved | naive | deep3 | deep3 + map | deep3 + cn |");
        for (Phases design : kMixedDesigns)
            for (const PhaseDesign& pd : kPhaseDesigns)
                if (pd.phases == design) {
                    std::string name = pd.name;  // a table cell: '|' escaped
                    for (size_t at = name.find('|'); at != std::string::npos; at = name.find('|', at + 2)) name.insert(at, "\\");
                    std::printf(" %s |", name.c_str());
                }
        std::printf(" improved / naive + map | improved / naive + cn's stage |\n|---|---:|---:|---:|---:|---:|---:|");
        for (size_t k = 0; k < sizeof kMixedDesigns / sizeof kMixedDesigns[0]; ++k) std::printf("---:|");
        std::printf("---:|---:|\n");
    }
    if (table) {
        std::printf("| model | stream | improved |");
        for (const TableColumn& t : kTable) std::printf(" %s |", t.name);
        std::printf("\n|---|---:|---:|");
        for (size_t k = 0; k < sizeof kTable / sizeof kTable[0]; ++k) std::printf("---:|");
        std::printf("\n");
    }
    for (int a = first; a < argc; ++a) {
        const std::string path = argv[a];
        std::optional<Hierarchy> read = read_hierarchy_or_report("phased_study", path);
        if (!read) return 1;
        if (mixed) {
            // Today's mixed file (the smaller traversal, or an older model where it codes smaller).
            EncodeOptions options;
            options.hierarchy_contexts = HierarchyContexts::mixed;
            EncodeStats stats;
            encode(*read, options, &stats);
            const Hierarchy h = in_decoder_order(*read);
            const Collected data = collect(h);
            const std::vector<MixedSymbol> improved = traversal_mixed_symbols(h, Traversal::improved);
            const std::vector<MixedSymbol> naive = traversal_mixed_symbols(h, Traversal::naive);
            const std::vector<MixedSymbol> deep3 = deep3_mixed_symbols(h, data);
            if (const char* dir = std::getenv("CACHE_DIR")) write_mixed_cache(dir, model_name(path), h, deep3);
            const size_t bi = mixed_payload(improved, Stage::none), bn = mixed_payload(naive, Stage::none);
            const double smaller = double(std::min(bi, bn));
            auto ratio = [&](size_t b) { return smaller > 0 ? double(b) / smaller : 0.0; };
            std::printf("| %s | %llu + %llu | %zu | %zu |", model_name(path).c_str(), (unsigned long long)stats.base_connectivity_bytes,
                        (unsigned long long)stats.hierarchy_bytes, bi, bn);
            for (Stage stage : {Stage::none, Stage::map, Stage::cn}) {
                const size_t b = mixed_payload(deep3, stage);
                std::printf(" %zu (%.3f) |", b, ratio(b));
            }
            for (Phases design : kMixedDesigns) {
                const size_t b = mixed_payload(phased_mixed_symbols(h, data, design), Stage::none);
                std::printf(" %zu (%.3f) |", b, ratio(b));
            }
            for (Stage stage : {Stage::map, Stage::cn}) std::printf(" %zu / %zu |", mixed_payload(improved, stage), mixed_payload(naive, stage));
            std::printf("\n");
            std::fflush(stdout);
            if (debug != nullptr && std::string(debug).rfind("mixed", 0) == 0) {
                // "mixed": deep3's phases; "mixed:DESIGN": that design's.
                const std::string name = std::string(debug).size() > 6 ? std::string(debug).substr(6) : "deep3";
                std::vector<MixedSymbol> phased = deep3;
                for (const PhaseDesign& pd : kPhaseDesigns)
                    if (name == pd.name && name != "deep3") phased = phased_mixed_symbols(h, data, pd.phases);
                std::fprintf(stderr, "%s, %s against the improved traversal:\n", model_name(path).c_str(), name.c_str());
                print_mixed_phase_costs(phased, improved, h.node_count());
                std::fprintf(stderr, "%s, %s against the naive traversal:\n", model_name(path).c_str(), name.c_str());
                print_mixed_phase_costs(phased, naive, h.node_count());
            }
            continue;
        }
        const Hierarchy& h = *read;
        const Collected data = collect(h);
        const size_t improved = adaptive_bytes(data.improved, kContextGroupCount);
        if (speed_runs > 0) {
            // deep3 (g,cn) decided by the prototype against the library's deciding of
            // today's stream, alternating run by run (thread CPU time); ONLY=lib or ONLY=proto
            // runs one of them (callgrind).
            const ProtoStream stream = encode_proto(h, data);
            const std::vector<uint8_t> library_bytes = encode_hierarchy(h);
            const Hierarchy roots_only(h.base());
            HierarchyLevelDecoder library;
            ProtoDecider proto;
            // The decoded decisions must be the hierarchy's: decide once, every decoded bit checked.
            {
                ArithmeticDecoder d(stream.bytes.data(), stream.bytes.size());
                proto.symbols_left = stream.kept;
                uint64_t wrong = 0;
                const uint64_t nodes = proto.run(roots_only, stream.uniform_levels, [&](BitModel& model, uint32_t i, uint32_t l) {
                    const bool bit = d.decode_with_limit<kHierarchyModelLimit>(model);
                    wrong += bit != (data.levels[l].truth[i] != 0);
                    return bit;
                });
                if (nodes != h.node_count() || wrong != 0) {
                    std::fprintf(stderr, "%s: the prototype decided %llu nodes, not %u; %llu wrong bits\n", model_name(path).c_str(),
                                 (unsigned long long)nodes, h.node_count(), (unsigned long long)wrong);
                    return 1;
                }
            }
            const char* only = std::getenv("ONLY");
            ProtoDecider bare;
            if (levels_only(bare, roots_only, data) != h.node_count()) {
                std::fprintf(stderr, "%s: the levels alone made a different node count\n", model_name(path).c_str());
                return 1;
            }
            std::vector<double> lib_s, proto_s, ratio, bare_s, bare_share, build_s, bound;
            for (int r = 0; r < speed_runs; ++r) {
                const double t0 = thread_seconds();
                if (only == nullptr || std::string(only) == "lib") decide_library(library, h, library_bytes);
                const double t1 = thread_seconds();
                if (only == nullptr || std::string(only) == "lib") {
                    // The rest of a decode (decode_phases' build phase): the Hierarchy made.
                    library.finish();
                    library.hierarchy().reserve(library.node_count(), library.vertex_count());
                    library.build_decided_levels();
                }
                const double t1b = thread_seconds();
                build_s.push_back(t1b - t1);
                if (only == nullptr || std::string(only) == "proto") decide_proto(proto, roots_only, stream);
                const double t2 = thread_seconds();
                if (only == nullptr || std::string(only) == "levels") levels_only(bare, roots_only, data);
                const double t3 = thread_seconds();
                lib_s.push_back(t1 - t0);
                proto_s.push_back(t2 - t1b);
                bare_s.push_back(t3 - t2);
                ratio.push_back((t1 - t0) / std::max(t2 - t1b, 1e-9));
                bare_share.push_back((t3 - t2) / std::max(t1 - t0, 1e-9));
                // A decode whose deciding took no more than the levels alone, against today's.
                bound.push_back((t1b - t0) / std::max(t3 - t2 + t1b - t1, 1e-9));
            }
            const Range rs = range_of(ratio);
            const Range bs = range_of(bare_share);
            const Range ds = range_of(bound);
            std::printf("%s: %u nodes; stream %zu bytes, deep3 %zu bytes (+ 8 bytes of counts; study %.0f); decide ms library %.2f, "
                        "deep3 %.2f (medians); ratio library/deep3 median %.3f [%.3f-%.3f]; levels alone %.2f ms, "
                        "%.3f [%.3f-%.3f] of the library's; build %.2f ms; decode with the levels alone %.2f [%.2f-%.2f] "
                        "times as fast\n",
                        model_name(path).c_str(), h.node_count(), library_bytes.size(), stream.bytes.size(),
                        [&] {
                            const LevelSymbols levels = phased_symbols(data, Phases::deep3, kGroup | kCn);
                            std::vector<Symbol> all;
                            for (const Symbol& sy : data.roots) all.push_back({kContextSlots + sy.context, sy.bit, 255});
                            for (const auto& level : levels.levels) all.insert(all.end(), level.begin(), level.end());
                            return double(adaptive_bytes(all, kContextSlots + kContextGroupCount));
                        }(),
                        1e3 * median(lib_s), 1e3 * median(proto_s), rs.median, rs.low, rs.high, 1e3 * median(bare_s), bs.median,
                        bs.low, bs.high, 1e3 * median(build_s), ds.median, ds.low, ds.high);
            std::fflush(stdout);
            continue;
        }
        auto design_bytes = [&](Phases phases, unsigned features, bool adaptive, bool print_phases) {
            const LevelSymbols levels = phased_symbols(data, phases, features);
            std::vector<Symbol> all;
            for (const Symbol& s : data.roots) all.push_back({kContextSlots + s.context, s.bit, 255});
            for (const auto& level : levels.levels) all.insert(all.end(), level.begin(), level.end());
            if (print_phases) print_phase_costs(all, kContextSlots + kContextGroupCount);
            return adaptive ? double(adaptive_bytes(all, kContextSlots + kContextGroupCount)) : static_bytes(data.roots, levels);
        };
        if (table) {
            std::printf("| %s | %zu | %zu |", model_name(path).c_str(), encode_hierarchy(h).size(), improved);
            for (const TableColumn& t : kTable) {
                const double bytes = design_bytes(t.phases, t.features, t.adaptive, false);
                std::printf(" %.0f (%.3f) |", bytes, improved ? bytes / double(improved) : 0.0);
            }
            std::printf("\n");
            std::fflush(stdout);
            continue;
        }
        std::printf("%s nodes %u stream %zu improved %zu\n", model_name(path).c_str(), h.node_count(), encode_hierarchy(h).size(),
                    improved);
        for (const PhaseDesign& pd : kPhaseDesigns) {
            for (const ContextDesign& cd : kContextDesigns) {
                const bool print_phases = debug != nullptr && std::string(debug) == std::string(pd.name) + "/" + cd.name;
                const double adaptive = design_bytes(pd.phases, cd.features, true, print_phases);
                const double stat = design_bytes(pd.phases, cd.features, false, false);
                std::printf("  %-11s %-20s adaptive %7.0f (%.3f) static %9.0f (%.3f)\n", pd.name, cd.name, adaptive,
                            improved ? adaptive / double(improved) : 0.0, stat, improved ? stat / double(improved) : 0.0);
            }
        }
        std::fflush(stdout);
    }
    return 0;
}
