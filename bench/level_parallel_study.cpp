// Issue 29 item 3's format question, second form: what would a hierarchy stream built for decode
// speed cost in size? Each level's symbols in flat passes over the level (canonical order within
// a pass), each symbol's context known before its pass starts (its parent's level, decided
// already: no bucket queue, no order that depends on the decoded bits), coded with static
// per-level tables (two frequencies of 12 bits per context, as the interleaved rANS of
// coding/entropy/rans_coder.h codes them) instead of adaptive binary models.
//
//   level_parallel_study FILE.amh...                     sizes: the table of the variants below
//   level_parallel_study --speed RUNS FILE.amh...        variant "2p" coded for real through the
//                                                        interleaved rANS, decoded, checked and
//                                                        timed against the library's decide_level
//
// The paper's rules stay: 1-regularity culls (incomplete nodes take no symbol), uniform levels
// take none; the roots take one static table per context group of Table 2 in canonical order.
// Variants (contexts of a node c, a child of parent p; r(x) = x's refined neighbours, 0..3; the
// "outer" neighbours of a corner child are children of p's neighbours q, whose r(q) is known):
//   1a   one pass, context (center or corner, r(p)): 8; no hanging-node rule (a node with three
//        refined neighbours is coded)
//   1b   one pass, center: r(p); corner: r(p), sum of r(q) over its outer neighbours: 32
//   1c   1b times r(p's parent): 128
//   2p   two passes: corners (as 1b), then centers, whose three neighbours are their siblings,
//        decided now: three refined siblings force the center (the hanging-node rule), else
//        context r(p), refined siblings 0..2: 12
//   2g   2p times r(p's parent): 160
//   2c   two passes: centers first (context r(p)), then corners (as 1b, and whether their center
//        sibling is refined): 60
// Sizes count the symbols and the tables (per level and context 2 bits: unused, all 0, all 1, or
// coded, and 12 bits for a coded one) and the rANS's 8 bytes of state; "improved" is the paper's
// improved traversal's symbols through one adaptive binary coder (as bench/traversal_order_study),
// "stream" the library's whole hierarchy stream (header and orientation bits included).
#include "bench_common.h"
#include "decide_only.h"
#include "static_table_cost.h"
#include "coding/entropy/arithmetic_coder.h"
#include "coding/entropy/rans_coder.h"
#include "coding/hierarchy/hierarchy_level_coder.h"
#include "common/compiler.h"

#include <amc/hierarchy.h>
#include <amc/hierarchy_coder.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <exception>
#include <string>
#include <vector>

namespace {

using namespace amc;

constexpr int kVariants = 6;
const char* const kVariantNames[kVariants] = {"1a", "1b", "1c", "2p", "2g", "2c"};
constexpr int kMaxContexts = 160;

// What a node's context may read: known before its level's passes (the parent level), and the
// two same-level facts a second pass may use.
struct Node {
    uint8_t corner;      // a corner child (else the center, red_split::kCenter)
    uint8_t rp;          // r(p)
    uint8_t grand;       // r(p's parent); 0 for children of roots
    uint8_t sum_rq;      // sum of r(q) over the outer neighbours (corners)
    uint8_t siblings;    // refined siblings among the neighbours (centers: 0..3)
    uint8_t center;      // the center sibling refined (corners)
    bool truth;
};

// The pass (0 or 1) and context of node `n` in `variant`, or pass -1: forced (no symbol).
struct Slot {
    int pass, context;
};
Slot slot_of(int variant, const Node& n) {
    const int corner_b = 4 + n.rp * 7 + n.sum_rq;  // 4..31
    switch (variant) {
        case 0: return {0, n.corner * 4 + n.rp};
        case 1: return {0, n.corner ? corner_b : n.rp};
        case 2: return {0, (n.corner ? corner_b : n.rp) * 4 + n.grand};
        case 3:
            if (n.corner) return {0, corner_b - 4};
            if (n.siblings == 3) return {-1, 0};
            return {1, 28 + n.rp * 3 + n.siblings};
        case 4:
            if (n.corner) return {0, (corner_b - 4) * 4 + n.grand};
            if (n.siblings == 3) return {-1, 0};
            return {1, 112 + (n.rp * 3 + n.siblings) * 4 + n.grand};
        default:
            if (!n.corner) return {0, n.rp};
            return {1, 4 + (corner_b - 4) * 2 + n.center};
    }
}

struct Counts {
    uint64_t n[kMaxContexts][2] = {};
};

// Bits of one level's symbols under static tables made from their counts, and the tables.
double static_bits(const Counts& c, int contexts, double* table_bits) {
    double bits = 0;
    for (int k = 0; k < contexts; ++k) bits += static_slot_bits(c.n[k][0], c.n[k][1], table_bits);
    return bits;
}

int context_group(const Neighbors& node, const uint8_t* state) {
    unsigned code = 0;
    for (int e = 0; e < 3; ++e) code |= unsigned(neighbor_state(state, node.nbr[e]) & (kDecided | kRefined)) << (2 * e);
    return kContextTable.group[code];
}

void set_decided(const Neighbors& node, uint8_t* state, uint32_t i, bool refined) {
    state[i] = uint8_t(state[i] | kDecided | (refined ? kRefined : 0));
    if (refined) {
        for (int e = 0; e < 3; ++e) {
            uint8_t& s = neighbor_state(state, node.nbr[e]);
            s = uint8_t(s + kRefinedNeighbor);
        }
    }
}

// The nodes of every non-uniform level below the roots, level by level, with their context
// facts; the roots' symbols (canonical order, context group, bit) apart.
struct Levels {
    std::vector<std::vector<Node>> levels;
    std::vector<std::pair<int, bool>> roots;  // (group, bit)
};

Levels collect(const Hierarchy& h) {
    const HierarchyCoderOptions options;
    Levels out;
    Level level, next;
    RefinedNumbering numbering;
    std::vector<NodeId> ids, next_ids;
    std::vector<uint8_t> prev_state, prev_grand, grand;
    std::vector<uint32_t> prev_refined;
    root_level(h, level, options.cull_one_regularity);
    for (NodeId r = 0; r < h.root_count(); ++r) ids.push_back(r);
    bool uniform_so_far = true;
    while (!level.empty()) {
        const uint32_t n = uint32_t(level.size());
        uint8_t* state = level.state();
        std::vector<uint8_t> truth;
        const bool all_refined = read_level(h, ids, n, truth, next_ids);
        const bool uniform = uniform_so_far && all_refined;
        uniform_so_far = uniform;
        grand.assign(n, 0);
        with_links(level, [&](auto links) {
            if (level.is_root_level()) {
                // Canonical order, Table 2's groups, the hanging-node rule (uniform: no symbols).
                for (uint32_t i = 0; i < n; ++i) {
                    if (state[i] & kDecided) continue;
                    const Neighbors node = links.neighbors(i);
                    if (!uniform && refined_neighbors(state[i]) != 3) out.roots.push_back({context_group(node, state), truth[i] != 0});
                    set_decided(node, state, i, truth[i] != 0);
                }
                return;
            }
            std::vector<Node> uniform_level;  // no symbols: not listed
            std::vector<Node>& nodes = uniform ? uniform_level : out.levels.emplace_back();
            for (uint32_t c = 0; c < n; ++c) {
                const uint32_t b = c >> 2, p = prev_refined[b];
                grand[c] = uint8_t(refined_neighbors(prev_state[p]));
                if ((state[c] & kDecided) || uniform) continue;
                Node f{};
                f.corner = (c & 3) != uint32_t(red_split::kCenter);
                f.rp = uint8_t(refined_neighbors(prev_state[p]));
                f.grand = prev_grand[p];
                const Neighbors node = links.neighbors(c);
                for (int e = 0; e < 3; ++e) {
                    const uint32_t q = node.nbr[e];
                    if (q == kNoLocal) continue;
                    if ((q >> 2) == b) {
                        f.siblings = uint8_t(f.siblings + (truth[q] != 0));
                        if ((q & 3) == uint32_t(red_split::kCenter)) f.center = truth[q] != 0;
                    } else {
                        f.sum_rq = uint8_t(f.sum_rq + refined_neighbors(prev_state[prev_refined[q >> 2]]));
                    }
                }
                f.truth = truth[c] != 0;
                nodes.push_back(f);
            }
            for (uint32_t i = 0; i < n; ++i) {
                if (!(state[i] & kDecided)) set_decided(links.neighbors(i), state, i, truth[i] != 0);
            }
        });
        scan_decided_level(level, numbering, nullptr);
        prev_state.assign(state, state + n);
        prev_refined.assign(level.refined.data(), level.refined.data() + level.refined_count);
        prev_grand = grand;
        derive_next_level(level, numbering, next, options.cull_one_regularity);
        std::swap(level, next);
        std::swap(ids, next_ids);
    }
    return out;
}

// The improved traversal's symbols through one adaptive coder (bench/traversal_order_study).
size_t improved_bytes(const Hierarchy& h) {
    HierarchyCoderOptions options;
    LevelTraversal traversal(options, kHierarchyStreamVersion);
    ArithmeticEncoder encoder;
    HierarchyModels models;
    struct Symbol {
        uint8_t group;
        bool bit;
    };
    std::vector<Symbol> symbols;
    Level level, next;
    RefinedNumbering numbering;
    std::vector<NodeId> ids, next_ids;
    root_level(h, level, options.cull_one_regularity);
    for (NodeId r = 0; r < h.root_count(); ++r) ids.push_back(r);
    bool uniform_so_far = true;
    while (!level.empty()) {
        const uint32_t n = uint32_t(level.size());
        std::vector<uint8_t> truth;
        const bool all_refined = read_level(h, ids, n, truth, next_ids);
        const bool uniform = uniform_so_far && all_refined;
        uniform_so_far = uniform;
        traversal.run(
            level, uniform,
            [&](uint32_t i, int group) {
                symbols.push_back({uint8_t(group), truth[i] != 0});
                return truth[i] != 0;
            },
            [&](uint32_t i, Fate, bool) { return truth[i] != 0; });
        scan_decided_level(level, numbering, nullptr);
        derive_next_level(level, numbering, next, options.cull_one_regularity);
        std::swap(level, next);
        std::swap(ids, next_ids);
    }
    size_t kept = symbols.size();
    while (kept > 0 && !symbols[kept - 1].bit) --kept;
    for (size_t k = 0; k < kept; ++k) encoder.encode_with_limit<kHierarchyModelLimit>(symbols[k].bit, models.groups[symbols[k].group]);
    return encoder.finish().size();
}

// Bytes of variant v over `data` (symbols, tables, the rANS state).
double variant_bytes(const Levels& data, int v) {
    double table_bits = 0, bits = 0;
    {
        Counts roots;
        for (const auto& [group, bit] : data.roots) ++roots.n[group][bit];
        bits += static_bits(roots, kContextGroupCount, &table_bits);
    }
    for (const std::vector<Node>& level : data.levels) {
        Counts counts;
        for (const Node& n : level) {
            const Slot s = slot_of(v, n);
            if (s.pass < 0) {
                if (!n.truth) std::fprintf(stderr, "level_parallel_study: a forced node is not refined\n");
                continue;
            }
            ++counts.n[s.context][n.truth];
        }
        bits += static_bits(counts, kMaxContexts, &table_bits);
    }
    return (bits + table_bits) / 8 + kRansStateBytes;
}

// ---- Variant 2p coded for real and decoded: the speed prototype ----

constexpr int kPassContexts = 40;  // 28 corner contexts, then 12 center ones (slot_of, variant 3)

// One context's table: unused or constant (no symbol read), or coded through the rANS.
struct ContextTable {
    uint8_t constant = 0;  // 0: coded; 1: always 0; 2: always 1
    RansTable table;
    RansTable::NarrowView view;
};

// The prototype's stream: which levels are uniform, the tables per level, the rANS bytes.
struct Stream2p {
    std::vector<uint8_t> uniform;                  // per level from the roots
    std::vector<ContextTable> roots;               // kContextGroupCount
    std::vector<std::vector<ContextTable>> levels; // per level below the roots: kPassContexts
    std::vector<uint8_t> bytes;
};

void make_tables(const Counts& counts, int contexts, std::vector<ContextTable>& out) {
    out.assign(size_t(contexts), ContextTable{});
    for (int k = 0; k < contexts; ++k) {
        const uint64_t n0 = counts.n[k][0], n1 = counts.n[k][1];
        if (n0 == 0 || n1 == 0) {
            out[size_t(k)].constant = n1 == 0 ? 1 : 2;
            continue;
        }
        out[size_t(k)].table = RansTable::from_counts({n0, n1});
    }
    for (ContextTable& t : out) t.view = t.constant ? RansTable::NarrowView{} : t.table.narrow_view();
}

Stream2p encode_2p(const Hierarchy& h, const Levels& data) {
    Stream2p s;
    // Uniform levels: the header's count (a level every node of which is refined, from the roots on).
    {
        Level level, next;
        RefinedNumbering numbering;
        root_level(h, level, true);
        std::vector<NodeId> ids(h.root_count());
        for (NodeId r = 0; r < h.root_count(); ++r) ids[r] = r;
        bool uniform = true;
        while (uniform) {
            for (NodeId n : ids) uniform &= !h.is_leaf(n);
            if (!uniform) break;
            s.uniform.push_back(1);
            std::vector<NodeId> next_ids;
            for (NodeId n : ids) {
                const NodeId c = h.child(n, 0);
                next_ids.insert(next_ids.end(), {c, c + 1, c + 2, c + 3});
            }
            ids.swap(next_ids);
        }
    }
    Counts roots;
    for (const auto& [group, bit] : data.roots) ++roots.n[group][bit];
    make_tables(roots, kContextGroupCount, s.roots);
    RansEncoder encoder;
    for (const auto& [group, bit] : data.roots)
        if (!s.roots[size_t(group)].constant) encoder.put(s.roots[size_t(group)].table, bit);
    for (const std::vector<Node>& level : data.levels) {
        Counts counts;
        for (const Node& n : level) {
            const Slot slot = slot_of(3, n);
            if (slot.pass >= 0) ++counts.n[slot.context][n.truth];
        }
        std::vector<ContextTable>& tables = s.levels.emplace_back();
        make_tables(counts, kPassContexts, tables);
        for (int pass = 0; pass < 2; ++pass) {
            for (const Node& n : level) {
                const Slot slot = slot_of(3, n);
                if (slot.pass == pass && !tables[size_t(slot.context)].constant) encoder.put(tables[size_t(slot.context)].table, n.truth);
            }
        }
    }
    s.bytes = encoder.finish();
    return s;
}

// Decides every level of variant 2p's stream over the roots of `base` as a decoder would (the
// same steps as HierarchyLevelDecoder::decide_level but the traversal: scan, derivation, counts);
// returns the nodes. Orientation bits are not in the prototype's stream (the library decodes
// them in its scan's loop: a few per thousand nodes).
struct Decoder2p {
    Level prev, cur, next;
    RefinedNumbering numbering;
    std::vector<uint32_t> closures;
    std::vector<uint8_t> rblock;  // r(p) of the level's blocks

    uint64_t decide(const Hierarchy& roots_only, const Stream2p& s) {
        RansDecoder d(s.bytes.data(), s.bytes.size());
        root_level(roots_only, cur, true);
        uint64_t nodes = cur.size();
        size_t l = 0, below = 0;
        unsigned parity = 0;
        auto get = [&](const ContextTable& t) {
            if (t.constant) return t.constant == 2;
            parity ^= 1;
            return (parity ? d.get_with<0>(t.view) : d.get_with<1>(t.view)) != 0;
        };
        while (!cur.empty()) {
            const uint32_t n = uint32_t(cur.size());
            uint8_t* state = cur.state();
            if (l < s.uniform.size()) {
                with_links(cur, [&](auto links) {
                    for (uint32_t i = 0; i < n; ++i) set_decided(links.neighbors(i), state, i, true);
                });
            } else if (cur.is_root_level()) {
                const RootLinks links{cur.roots.data()};
                for (uint32_t i = 0; i < n; ++i) {
                    if (state[i] & kDecided) continue;
                    const Neighbors node = links.neighbors(i);
                    const bool refined = refined_neighbors(state[i]) == 3 || get(s.roots[size_t(context_group(node, state))]);
                    set_decided(node, state, i, refined);
                }
            } else {
                const std::vector<ContextTable>& tables = s.levels[below++];
                const Neighbors* nbr = cur.nbr.data();
                const uint8_t* pstate = prev.state();
                const uint32_t* parent = prev.refined.data();
                // r(p) of every block, once; a refined node counted at its neighbours as soon as
                // it is decided (neither pass reads the counts).
                const uint32_t blocks = n / 4;
                rblock.resize(blocks);
                for (uint32_t b = 0; b < blocks; ++b) rblock[b] = uint8_t(refined_neighbors(pstate[parent[b]]));
                auto decided = [&](uint32_t c, bool refined) {
                    state[c] = uint8_t(state[c] | kDecided | (refined ? kRefined : 0));
                    if (!refined) return;
                    for (int e = 0; e < 3; ++e) {
                        uint8_t& t = neighbor_state(state, nbr[c].nbr[e]);
                        t = uint8_t(t + kRefinedNeighbor);
                    }
                };
                static_assert(red_split::kCenter == 3, "the corners are children 0-2");
                // Pass 1: the corners, contexts from the level above.
                for (uint32_t b = 0; b < blocks; ++b) {
                    const unsigned rp = rblock[b];
                    for (uint32_t c = 4 * b; c < 4 * b + 3; ++c) {
                        if (state[c] & kDecided) continue;
                        unsigned sum = 0;
                        for (int e = 0; e < 3; ++e) {
                            const uint32_t q = nbr[c].nbr[e];
                            sum += q == kNoLocal || (q >> 2) == b ? 0u : rblock[q >> 2];
                        }
                        decided(c, get(tables[rp * 7 + sum]));
                    }
                }
                // Pass 2: the centers, whose neighbours are their siblings.
                for (uint32_t b = 0; b < blocks; ++b) {
                    const uint32_t c = 4 * b + 3;
                    if (state[c] & kDecided) continue;
                    const unsigned siblings = ((state[c - 3] >> 1) & 1u) + ((state[c - 2] >> 1) & 1u) + ((state[c - 1] >> 1) & 1u);
                    decided(c, siblings == 3 || get(tables[28 + rblock[b] * 3 + siblings]));
                }
            }
            closures.resize(n);
            scan_decided_level(cur, numbering, closures.data());
            derive_next_level(cur, numbering, next, true);
            nodes += next.size();
            std::swap(prev, cur);
            std::swap(cur, next);
            ++l;
        }
        return nodes;
    }
};

}  // namespace

int main(int argc, char** argv) {
    int first = 1, speed_runs = 0;
    if (argc > 2 && std::string(argv[1]) == "--speed") {
        speed_runs = std::max(1, std::atoi(argv[2]));
        first = 3;
    }
    if (first >= argc) {
        std::fprintf(stderr, "usage: level_parallel_study [--speed RUNS] FILE.amh...\n");
        return 2;
    }
    if (speed_runs == 0) {
        std::printf("| hierarchy | nodes | leaf faces | stream | improved |");
        for (const char* name : kVariantNames) std::printf(" %s |", name);
        std::printf(" bits per face, improved / 2c |\n|---|---:|---:|---:|---:|");
        for (int v = 0; v < kVariants; ++v) std::printf("---:|");
        std::printf("---:|\n");
    }
    for (int a = first; a < argc; ++a) {
        const std::string path = argv[a];
        std::optional<Hierarchy> read = read_hierarchy_or_report("level_parallel_study", path);
        if (!read) return 1;
        Hierarchy& h = *read;
        const std::string name = model_name(path);
        if (speed_runs == 0) {
            const Levels data = collect(h);
            const size_t improved = improved_bytes(h);
            const double faces = double(extract_leaf_mesh(h).mesh.triangles.size());
            std::printf("| %s | %u | %.0f | %zu | %zu |", name.c_str(), h.node_count(), faces, encode_hierarchy(h).size(), improved);
            for (int v = 0; v < kVariants; ++v) {
                const double bytes = variant_bytes(data, v);
                std::printf(" %.0f (%.3f) |", bytes, improved == 0 ? 0.0 : bytes / double(improved));
            }
            std::printf(" %.3f / %.3f |\n", 8.0 * double(improved) / faces, 8.0 * variant_bytes(data, 5) / faces);
            std::fflush(stdout);
            continue;
        }
        // --speed: variant 2p against the library, alternating run by run (thread CPU time).
        const Levels data = collect(h);
        const Stream2p stream = encode_2p(h, data);
        const std::vector<uint8_t> library_bytes = encode_hierarchy(h);
        const Hierarchy roots_only(h.base());
        HierarchyLevelDecoder coder;
        Decoder2p proto;
        const char* only = std::getenv("ONLY");  // "lib" or "2p": one of them (for callgrind)
        std::vector<double> lib_s, proto_s, ratio;
        for (int r = 0; r < speed_runs; ++r) {
            double t0 = thread_seconds();
            uint64_t lib_nodes = 0, proto_nodes = 0;
            if (only == nullptr || std::string(only) == "lib") lib_nodes = decide_library(coder, h, library_bytes);
            double t1 = thread_seconds();
            if (only == nullptr || std::string(only) == "2p") proto_nodes = proto.decide(roots_only, stream);
            double t2 = thread_seconds();
            if ((only == nullptr && (lib_nodes != h.node_count() || proto_nodes != h.node_count()))) {
                std::fprintf(stderr, "%s: decided %llu / %llu nodes, not %u\n", name.c_str(), (unsigned long long)lib_nodes,
                             (unsigned long long)proto_nodes, h.node_count());
                return 1;
            }
            lib_s.push_back(t1 - t0);
            proto_s.push_back(t2 - t1);
            ratio.push_back((t1 - t0) / (t2 - t1));
        }
        std::printf("%s: %u nodes; library stream %zu bytes, 2p rANS %zu bytes (with tables, estimated: %.0f); decide ms "
                    "library %.2f [%.2f-%.2f], 2p %.2f [%.2f-%.2f]; ratio library/2p median %.2f [%.2f-%.2f]; M nodes/s %.1f / %.1f\n",
                    name.c_str(), h.node_count(), library_bytes.size(), stream.bytes.size(), variant_bytes(data, 3),
                    1e3 * median(lib_s), 1e3 * *std::min_element(lib_s.begin(), lib_s.end()),
                    1e3 * *std::max_element(lib_s.begin(), lib_s.end()), 1e3 * median(proto_s),
                    1e3 * *std::min_element(proto_s.begin(), proto_s.end()), 1e3 * *std::max_element(proto_s.begin(), proto_s.end()),
                    median(ratio), *std::min_element(ratio.begin(), ratio.end()), *std::max_element(ratio.begin(), ratio.end()),
                    h.node_count() / median(lib_s) * 1e-6, h.node_count() / median(proto_s) * 1e-6);
        std::fflush(stdout);
    }
    return 0;
}
