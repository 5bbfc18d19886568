// Hierarchy decoder: the mirror of hierarchy_encoder.cpp. It grows the forest over the shared base
// mesh level by level, taking each decision from a rule or from the stream.
#include "coding/arithmetic_coder.h"
#include "coding/hierarchy_stream.h"
#include "coding/hierarchy_traversal.h"

#include <string>

namespace amc {

Hierarchy decode_hierarchy(const TriangleMesh& base, const uint8_t* data, size_t size,
                           const HierarchyDecodeOptions& options) {
    HierarchyStreamHeader header;
    const size_t header_size = read_hierarchy_stream_header(data, size, header);
    ArithmeticDecoder decoder(data + header_size, size - header_size);
    HierarchyModels models;
    const bool use_contexts = header.options.use_contexts;

    // Uniform levels alone would build root_count * (4^(U+1) - 1) / 3 nodes: check before.
    uint64_t uniform_nodes = base.triangles.size(), level_nodes = base.triangles.size();
    for (int l = 0; l < header.uniform_levels && uniform_nodes <= options.max_nodes; ++l) {
        level_nodes *= 4;
        uniform_nodes += level_nodes;
    }
    if (uniform_nodes > options.max_nodes)
        throw Error("hierarchy stream would build more than " + std::to_string(options.max_nodes) + " nodes");

    Hierarchy h(base);
    uint64_t symbols_read = 0;
    auto split = [&](NodeId n) {
        if (!h.can_split(n))
            throw Error("hierarchy stream is corrupt: node " + std::to_string(n) + " (level " +
                        std::to_string(h.level(n)) + ") can not be refined");
        if (h.node_count() + 4 > options.max_nodes)
            throw Error("hierarchy stream would build more than " + std::to_string(options.max_nodes) + " nodes");
        h.split(n);
    };

    LevelTraversal traversal(header.options);
    std::vector<NodeId> level, next;
    for (NodeId r = 0; r < h.root_count(); ++r) level.push_back(r);
    for (int l = 0; !level.empty() && l != options.max_level; ++l) {
        traversal.run(
            h, level, l < header.uniform_levels,
            [&](NodeId n, int group) {
                // II-C, stream truncation: once the stored symbols are used up, the rest are 0.
                if (symbols_read == header.symbol_count && header.options.truncate_stream) return false;
                ++symbols_read;
                const bool refined = decoder.decode(models.for_group(group, use_contexts));
                if (refined) split(n);
                return refined;
            },
            [&](NodeId n, Fate, bool refined) {
                if (refined) split(n);
            });
        for (NodeId n : level) {
            if (!h.is_leaf(n)) continue;
            const int hanging = h.hanging_node_count(n);
            if (hanging == 3)
                throw Error("hierarchy stream is corrupt: element " + std::to_string(n) +
                            " has three hanging nodes but was not refined");
            if (hanging == 2) {
                bool flag = diagonal_flag_by_rule(header.diagonal_rule, unrefined_edge(h, n));
                if (header.orientation_coded) flag ^= decoder.decode(models.orientation);
                h.set_diagonal_flipped(n, flag);
            }
        }
        if (decoder.overran()) throw Error("hierarchy stream is truncated");
        next_level(h, level, next);
        level.swap(next);
    }
    if (options.max_level < 0 && header.options.truncate_stream && symbols_read != header.symbol_count)
        throw Error("hierarchy stream is corrupt: " + std::to_string(header.symbol_count) + " symbols announced, " +
                    std::to_string(symbols_read) + " used");
    return h;
}

}  // namespace amc
