// Issue 29 item 3's question about the stream layout: could a fixed visiting order, which a decoder
// runs as flat passes over a level's arrays (no bucket queue, no order that depends on the decoded
// bits), code the hierarchy symbols within 2% of the paper's improved traversal?
//
//   traversal_order_study FILE.amh...
//
// For every hierarchy, every level is decided in each order below with the paper's rules
// (1-regularity culls decided first, the hanging-node rule, uniform levels skipped) and the ten
// context groups, and the coded symbols go through one adaptive arithmetic encoder, trailing
// zeros dropped (stream truncation). The improved and naive orders are the library's traversal
// (LevelTraversal); the others are passes over the blocks of four siblings:
//   canonical      node 0, 1, 2, ... (the naive traversal, by this program's loop: a check)
//   child 0..3     every block's child 0, then every block's child 1, 2, 3
//   child 1230     every block's child 1, 2, 3, then child 0 (the center child, whose three
//                  neighbours are its siblings, last)
//   two passes     every block's children with an even canonical block index, then the odd ones
//   blocks 1230    block by block in canonical order, each block's children 1, 2, 3, then 0
// Orientation bits and the header are the same in every order and are not counted. Prints bytes
// per order and the ratio to the improved traversal's.
#include "bench_common.h"
#include "coding/entropy/arithmetic_coder.h"
#include "coding/hierarchy/hierarchy_level_coder.h"

#include <amc/hierarchy.h>
#include <amc/hierarchy_coder.h>

#include <cstdio>
#include <exception>
#include <string>
#include <vector>

namespace {

using namespace amc;

struct Symbol {
    uint8_t group;
    bool bit;
};

enum class Order { improved, naive, canonical, child_0123, child_1230, two_passes, blocks_1230 };
constexpr int kOrders = 7;
const char* const kOrderNames[kOrders] = {"improved",   "naive",      "canonical", "child 0123",
                                          "child 1230", "two passes", "blocks 1230"};

int context_group(const Neighbors& node, const uint8_t* state) {
    unsigned code = 0;
    for (int e = 0; e < 3; ++e) code |= unsigned(neighbor_state(state, node.nbr[e]) & (kDecided | kRefined)) << (2 * e);
    return kContextTable.group[code];
}

// Node i decided in its turn: culled by the hanging-node rule or coded.
template <class Links>
void decide_in_turn(Links links, uint8_t* state, uint32_t i, bool truth, std::vector<Symbol>& out) {
    if (state[i] & kDecided) return;  // culled by 1-regularity when the level was made
    const Neighbors node = links.neighbors(i);
    if (refined_neighbors(state[i]) == 3) {
        truth = true;  // hanging-node rule (the hierarchy agrees: it is closed)
    } else {
        out.push_back({uint8_t(context_group(node, state)), truth});
    }
    state[i] = uint8_t(state[i] | kDecided | (truth ? kRefined : 0));
    if (truth) {
        for (int e = 0; e < 3; ++e) {
            uint8_t& s = neighbor_state(state, node.nbr[e]);
            s = uint8_t(s + kRefinedNeighbor);
        }
    }
}

// Every coded symbol of `h` in `order`, level by level.
std::vector<Symbol> symbols_in_order(const Hierarchy& h, Order order) {
    HierarchyCoderOptions options;
    options.traversal = order == Order::naive ? Traversal::naive : Traversal::improved;
    LevelTraversal traversal(options, kHierarchyStreamVersion);
    std::vector<Symbol> out;
    Level level, next;
    RefinedNumbering numbering;
    std::vector<NodeId> ids, next_ids;
    std::vector<uint8_t> truth;
    root_level(h, level, options.cull_one_regularity);
    for (NodeId r = 0; r < h.root_count(); ++r) ids.push_back(r);
    bool uniform_so_far = true;
    while (!level.empty()) {
        const uint32_t n = uint32_t(level.size());
        const bool all_refined = read_level(h, ids, n, truth, next_ids);
        const bool uniform = uniform_so_far && all_refined;  // levels below the header's U
        uniform_so_far = uniform;
        if (uniform || order == Order::improved || order == Order::naive || level.is_root_level()) {
            traversal.run(
                level, uniform,
                [&](uint32_t i, int group) {
                    out.push_back({uint8_t(group), truth[i] != 0});
                    return truth[i] != 0;
                },
                [&](uint32_t i, Fate, bool) { return truth[i] != 0; });
        } else {
            uint8_t* state = level.state();
            const BlockLinks links{level.nbr.data(), level.edges.data()};
            const uint32_t blocks = n / 4;
            auto visit = [&](uint32_t i) { decide_in_turn(links, state, i, truth[i] != 0, out); };
            switch (order) {
                case Order::canonical:
                    for (uint32_t i = 0; i < n; ++i) visit(i);
                    break;
                case Order::child_0123:
                case Order::child_1230:
                    for (int k = 0; k < 4; ++k) {
                        const uint32_t child = order == Order::child_0123 ? uint32_t(k) : uint32_t((k + 1) & 3);
                        for (uint32_t b = 0; b < blocks; ++b) visit(4 * b + child);
                    }
                    break;
                case Order::two_passes:
                    for (uint32_t parity = 0; parity < 2; ++parity) {
                        for (uint32_t b = parity; b < blocks; b += 2) {
                            for (uint32_t k = 0; k < 4; ++k) visit(4 * b + k);
                        }
                    }
                    break;
                case Order::blocks_1230:
                    for (uint32_t b = 0; b < blocks; ++b) {
                        for (uint32_t k = 1; k <= 4; ++k) visit(4 * b + (k & 3));
                    }
                    break;
                default:
                    break;
            }
        }
        scan_decided_level(level, numbering, nullptr);
        derive_next_level(level, numbering, next, options.cull_one_regularity);
        std::swap(level, next);
        std::swap(ids, next_ids);
    }
    return out;
}

// Bytes of the symbols through one adaptive binary model per context group, trailing zeros dropped.
size_t coded_bytes(const std::vector<Symbol>& symbols) {
    size_t kept = symbols.size();
    while (kept > 0 && !symbols[kept - 1].bit) --kept;
    ArithmeticEncoder encoder;
    HierarchyModels models;
    for (size_t k = 0; k < kept; ++k)
        encoder.encode_with_limit<kHierarchyModelLimit>(symbols[k].bit, models.groups[symbols[k].group]);
    return encoder.finish().size();
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(stderr, "usage: traversal_order_study FILE.amh...\n");
        return 2;
    }
    std::printf("| hierarchy | nodes |");
    for (const char* name : kOrderNames) std::printf(" %s |", name);
    std::printf("\n|---|---:|");
    for (int o = 0; o < kOrders; ++o) std::printf("---:|");
    std::printf("\n");
    for (int a = 1; a < argc; ++a) {
        const std::string path = argv[a];
        std::optional<Hierarchy> read = read_hierarchy_or_report("traversal_order_study", path);
        if (!read) return 1;
        Hierarchy& h = *read;
        const std::string name = model_name(path);
        std::printf("| %s | %u |", name.c_str(), h.node_count());
        size_t improved = 0;
        for (int o = 0; o < kOrders; ++o) {
            const size_t bytes = coded_bytes(symbols_in_order(h, Order(o)));
            if (o == 0) {
                improved = bytes;
                std::printf(" %zu |", bytes);
            } else {
                std::printf(" %zu (%.3f) |", bytes, improved == 0 ? 0.0 : double(bytes) / double(improved));
            }
        }
        std::printf("\n");
        std::fflush(stdout);
    }
    return 0;
}
