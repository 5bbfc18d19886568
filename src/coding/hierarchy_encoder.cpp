// Hierarchy encoder: decides every node level by level (hierarchy_traversal.h), chooses the
// diagonal rule, truncates trailing zeros, and arithmetic codes what is left. Stream layout in
// docs/FORMAT.md ("hierarchy stream").
#include "coding/arithmetic_coder.h"
#include "coding/hierarchy_stream.h"
#include "coding/hierarchy_traversal.h"

namespace amc {

namespace {

// One decision in stream order: a hierarchy symbol or an orientation bit.
struct Event {
    uint8_t group;  // context group, or kOrientationEvent
    uint8_t bit;
};
constexpr uint8_t kOrientationEvent = 0xff;

// Levels 0..U-1 with every node refined.
int count_uniform_levels(const Hierarchy& h) {
    std::vector<NodeId> level, next;
    for (NodeId r = 0; r < h.root_count(); ++r) level.push_back(r);
    int uniform = 0;
    while (!level.empty() && uniform < kMaxUniformLevels) {
        for (NodeId n : level) {
            if (h.is_leaf(n)) return uniform;
        }
        ++uniform;
        next_level(h, level, next);
        level.swap(next);
    }
    return uniform;
}

}  // namespace

std::vector<uint8_t> encode_hierarchy(const Hierarchy& h, const HierarchyCoderOptions& options,
                                      HierarchyCodeStats* stats_out) {
    HierarchyCodeStats stats;
    stats.uniform_levels = options.uniform_levels ? count_uniform_levels(h) : 0;

    // Pass 1: decide every node in the coder's order and record the events.
    std::vector<Event> events;
    std::vector<std::pair<int, bool>> two_hanging;  // (unrefined edge, flag) in stream order
    std::vector<size_t> orientation_slots;         // event index of each two_hanging entry
    LevelTraversal traversal(options);
    std::vector<NodeId> level, next;
    for (NodeId r = 0; r < h.root_count(); ++r) level.push_back(r);
    for (int l = 0; !level.empty(); ++l) {
        stats.nodes += level.size();
        traversal.run(
            h, level, l < stats.uniform_levels,
            [&](NodeId n, int group) {
                const bool refined = !h.is_leaf(n);
                events.push_back({uint8_t(group), uint8_t(refined)});
                return refined;
            },
            [&](NodeId, Fate fate, bool) {
                switch (fate) {
                    case Fate::uniform: ++stats.culled_uniform; break;
                    case Fate::one_regularity: ++stats.culled_one_regularity; break;
                    case Fate::hanging_nodes: ++stats.culled_hanging_nodes; break;
                    case Fate::coded: break;
                }
            });
        for (NodeId n : level) {
            if (h.is_leaf(n) && h.hanging_node_count(n) == 2) {
                two_hanging.push_back({unrefined_edge(h, n), h.diagonal_flipped(n)});
                orientation_slots.push_back(events.size());
                events.push_back({kOrientationEvent, 0});
            }
        }
        stats.levels = l + 1;
        next_level(h, level, next);
        level.swap(next);
    }

    // The diagonal rule that leaves the fewest exceptions; orientation bits only if any.
    uint64_t best_exceptions = UINT64_MAX;
    for (int r = 0; r < kDiagonalRuleCount; ++r) {
        uint64_t exceptions = 0;
        for (auto [edge, flag] : two_hanging) exceptions += diagonal_flag_by_rule(DiagonalRule(r), edge) != flag;
        if (exceptions < best_exceptions) {
            best_exceptions = exceptions;
            stats.diagonal_rule = DiagonalRule(r);
        }
    }
    stats.two_hanging_leaves = two_hanging.size();
    stats.diagonal_exceptions = two_hanging.empty() ? 0 : best_exceptions;
    stats.orientation_coded = stats.diagonal_exceptions > 0;
    for (size_t i = 0; i < two_hanging.size(); ++i) {
        const auto [edge, flag] = two_hanging[i];
        events[orientation_slots[i]].bit = uint8_t(diagonal_flag_by_rule(stats.diagonal_rule, edge) != flag);
    }

    // Stream truncation (II-C): symbols after the last coded 1 are implied zeros.
    uint64_t symbol_count = 0, kept_symbols = 0;
    for (const Event& e : events) {
        if (e.group == kOrientationEvent) continue;
        ++symbol_count;
        if (e.bit) kept_symbols = symbol_count;
    }
    if (!options.truncate_stream) kept_symbols = symbol_count;
    stats.truncated = symbol_count - kept_symbols;
    stats.coded = kept_symbols;

    // Pass 2: arithmetic coding.
    HierarchyStreamHeader header;
    header.options = options;
    header.uniform_levels = uint8_t(stats.uniform_levels);
    header.diagonal_rule = stats.diagonal_rule;
    header.orientation_coded = stats.orientation_coded;
    header.symbol_count = kept_symbols;
    std::vector<uint8_t> out = write_hierarchy_stream_header(header);
    stats.header_bytes = out.size();

    HierarchyModels models;
    ArithmeticEncoder encoder;
    uint64_t symbols_written = 0;
    for (const Event& e : events) {
        if (e.group == kOrientationEvent) {
            if (!stats.orientation_coded) continue;
            stats.orientation_bits += models.orientation.cost_bits(e.bit);
            encoder.encode(e.bit, models.orientation);
            continue;
        }
        if (symbols_written == kept_symbols) continue;
        ++symbols_written;
        BitModel& model = models.for_group(e.group, options.use_contexts);
        ContextGroupStats& group = stats.groups[e.group];
        group.symbols += 1;
        group.ones += e.bit;
        stats.coded_ones += e.bit;
        group.coded_bits += model.cost_bits(e.bit);
        encoder.encode(e.bit, model);
    }
    const std::vector<uint8_t> payload = encoder.finish();
    out.insert(out.end(), payload.begin(), payload.end());
    stats.payload_bytes = payload.size();

    for (int g = 0; g < kContextGroupCount; ++g) {
        ContextGroupStats& group = stats.groups[g];
        for (int x = 0; x <= 3; ++x) {
            for (int y = 0; x + y <= 3; ++y) {
                if (context_group_of(x, y) == g) {
                    group.refined = x;
                    group.unrefined = y;
                    group.unknown = 3 - x - y;
                }
            }
        }
        stats.conditional_entropy_bits += binary_entropy_bits(group.ones, group.symbols);
        stats.adaptive_code_bits += group.coded_bits;
    }
    stats.adaptive_code_bits += stats.orientation_bits;
    if (stats_out != nullptr) {
        stats.faces = 0;
        for (NodeId n : h.leaves()) stats.faces += 1 + uint64_t(h.hanging_node_count(n));
        *stats_out = stats;
    }
    return out;
}

}  // namespace amc
