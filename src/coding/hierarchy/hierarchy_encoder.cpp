// Hierarchy encoder: decides every node level by level (hierarchy_traversal.h), chooses the
// diagonal rule, truncates trailing zeros, and arithmetic codes what is left, one level at a time.
// Stream layout in docs/FORMAT.md ("hierarchy stream").
#include "coding/hierarchy/hierarchy_level_coder.h"
#include "common/check.h"
#include "hierarchy/hierarchy_builder.h"

#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <utility>

namespace amc {

namespace {

// List l of `kept` (emptied, its capacity kept), or a new one.
template <class T>
std::vector<T> take_list(std::vector<std::vector<T>>& kept, size_t l) {
    if (l >= kept.size()) return {};
    std::vector<T> list = std::move(kept[l]);
    list.clear();
    return list;
}

// Lists back into `kept`, list l at index l.
template <class T>
void give_back_lists(std::vector<std::vector<T>>& lists, std::vector<std::vector<T>>& kept) {
    if (kept.size() < lists.size()) kept.resize(lists.size());
    for (size_t l = 0; l < lists.size(); ++l) kept[l] = std::move(lists[l]);
}

}  // namespace

HierarchyLevelEncoder::HierarchyLevelEncoder(const Hierarchy& h, const HierarchyCoderOptions& options,
                                             uint8_t stream_version, std::vector<CodedSymbol>* trace, bool mixed,
                                             const TurnedRoots* turned, Memory* memory, bool older_models)
    : options_(options), mixed_(mixed), older_models_(older_models) {
    AMC_REQUIRE(!mixed || stream_version == kHierarchyStreamVersion, invalid_input,
                "the hierarchy coder's mixing mode needs the newest hierarchy stream version");
    AMC_REQUIRE(!mixed || turned == nullptr, invalid_input, "the hierarchy coder's mixing mode reads no turned roots");
    HierarchyCodeStats& stats = stats_;
    // Levels 0..U-1 with every node refined (counted on the way: a level is uniform when it and
    // all coarser levels are refined everywhere).
    int uniform_levels = 0;
    uint64_t faces = 0;

    // Pass 1: decide every node in the coder's order and record the events. The traversal runs on
    // the level forest (hierarchy_traversal.h); `ids` maps a level's local indices to h's nodes.
    std::optional<Memory> own;  // without the caller's memory, the pass's own
    if (memory == nullptr) own.emplace();
    Memory& m = memory != nullptr ? *memory : *own;
    memory_ = memory;
    events_.swap(m.events);
    events_.clear();
    level_end_.swap(m.level_end);
    level_end_.clear();
    events_.reserve(h.node_count());
    std::vector<std::pair<int, bool>>& two_hanging = m.two_hanging;  // (unrefined edge, flag) in stream order
    two_hanging.clear();
    static constexpr int kTurnedEdge[6] = {0, 1, 2, 0, 1, 2};  // (e + turn) % 3
    std::vector<size_t>& orientation_slots = m.orientation_slots;  // event index of each two_hanging entry
    orientation_slots.clear();
    LevelTraversal& traversal = m.traversal;
    traversal.configure(options, stream_version);
    Level& level = m.level;
    Level& next = m.next;
    std::vector<NodeId> ids = take_list(m.level_ids, 0), next_ids;
    // Per node of the level: bit 0 refined, bit 1 its diagonal flag, both read while its node is in
    // the cache (the pass over the leaves below missed it again on large levels).
    std::vector<uint8_t>& refined = m.refined;
    RefinedNumbering& numbering = m.numbering;
    LevelShapes shapes;  // mixing mode
    // Each node's turn (none without `turned`).
    std::vector<uint8_t>& turns = m.turns;
    std::vector<uint8_t>& next_turns = m.next_turns;
    turns.clear();
    root_level(turned != nullptr ? *turned->roots : h, level, options.cull_one_regularity);
    ids.resize(h.root_count());
    for (NodeId r = 0; r < h.root_count(); ++r) ids[r] = turned != nullptr ? (*turned->old_root)[r] : r;
    if (turned != nullptr) turns = *turned->turn;
    for (int l = 0; !level.empty(); ++l) {
        const uint32_t n = static_cast<uint32_t>(level.size());
        stats.nodes += n;
        refined.resize(n);
        next_ids = take_list(m.level_ids, size_t(l) + 1);
        next_ids.reserve(4 * size_t(n));  // at most four children a node
        next_turns.clear();
        bool all_refined = true;
        // A refined node needs all its neighbours (Hierarchy::can_split); no stream could say
        // otherwise, and with the 1-regularity rule such nodes start decided as leaves.
        uint32_t unbalanced = n;
        const uint8_t* state = level.state();
        // h's nodes in the level's order are blocks of four at scattered places: 128 nodes ahead
        // keep about 32 blocks on their way (16 left the loop waiting on the node loads).
        constexpr uint32_t kAhead = 128;
        for (uint32_t i = 0; i < n && i < kAhead; ++i) HierarchyBuilder::prefetch(h, ids[i]);
        for (uint32_t i = 0; i < n; ++i) {
            if (i + kAhead < n) HierarchyBuilder::prefetch(h, ids[i + kAhead]);
            const NodeId id = ids[i];
            const bool r = !h.is_leaf(id);
            refined[i] = uint8_t(r | h.diagonal_flipped(id) << 1);
            all_refined &= r;
            if (r && !(state[i] & kComplete) && unbalanced == n) unbalanced = i;
            if (r) {
                const NodeId c = h.child(id, 0);
                // push_back, which inlines (two range inserts here were calls).
                if (turned == nullptr) {
                    for (NodeId k = 0; k < 4; ++k) next_ids.push_back(c + k);
                } else {  // the children in their turned order, turned alike
                    const uint8_t turn = turns[i];
                    const uint8_t* child = red_split::kRotatedChild[turn];
                    for (int k = 0; k < 4; ++k) {
                        next_ids.push_back(c + child[k]);
                        next_turns.push_back(turn);
                    }
                }
            }
        }
        const bool uniform = options.uniform_levels && all_refined && l == uniform_levels && l < kMaxUniformLevels;
        if (uniform) ++uniform_levels;
        if (unbalanced != n)
            throw Error("encode_hierarchy: node " + std::to_string(ids[unbalanced]) + " of level " + std::to_string(l) +
                        " is refined but lacks a neighbour (the hierarchy is not balanced)");
        AMC_REQUIRE(l < kMaxLevel || next_ids.empty(), invalid_input,
                    "encode_hierarchy: a node of level " + std::to_string(l) + " is refined beyond the level cap " +
                        std::to_string(kMaxLevel));
        if (options.cull_one_regularity && !uniform) stats.culled_one_regularity += level.incomplete_count;
        const uint8_t* truth = refined.data();
        if (mixed_) shapes.start_level(n);
        auto force = [&](uint32_t i, Fate fate, bool) {
            switch (fate) {
                case Fate::uniform: ++stats.culled_uniform; break;
                case Fate::hanging_nodes: ++stats.culled_hanging_nodes; break;
                case Fate::coded: break;
            }
            return (truth[i] & 1) != 0;
        };
        if (!mixed_ && trace == nullptr) {
            // The level's symbols (at most one a node) through a local pointer: push_back read and
            // wrote the vector's end in memory at every node, as the state bytes stored between
            // may alias it.
            const size_t before = events_.size();
            events_.resize(before + n);
            Event* out = events_.data() + before;
            traversal.run(
                level, uniform,
                [&](uint32_t i, int group) {
                    const bool r = (truth[i] & 1) != 0;
                    *out++ = {uint8_t(group), uint8_t(r)};
                    return r;
                },
                force);
            events_.resize(size_t(out - events_.data()));
        } else {
            traversal.run(
                level, uniform,
                [&](uint32_t i, int group) {
                    const bool r = (truth[i] & 1) != 0;
                    if (mixed_) {
                        if (event_feature_.size() < events_.size() + 1) event_feature_.resize(events_.size() + 1);
                        event_feature_[events_.size()] = uint32_t(mixed_features_.size());
                        mixed_features_.push_back(mixed_features(h, ids[i], level, i, group, shapes, kWrittenMixingModel, older_models_));
                    }
                    events_.push_back({uint8_t(group), uint8_t(r)});
                    if (trace != nullptr) trace->push_back({ids[i], uint8_t(group), r});
                    return r;
                },
                force);
        }
        // The leaves' faces (a leaf and its hanging nodes' green triangles) in a pass over the
        // states alone, with the leaves of two or three hanging nodes listed, then those.
        std::vector<uint32_t>& two_or_more = m.two_or_more;
        if (two_or_more.size() < n) two_or_more.resize(n);  // no clearing: only the listed part is read
        uint32_t listed = 0;
        uint64_t level_faces = 0;
        for (uint32_t i = 0; i < n; ++i) {
            const uint32_t leaf = (state[i] & kRefined) == 0;
            const uint32_t hanging = uint32_t(refined_neighbors(state[i]));
            level_faces += (1 + hanging) & (0 - leaf);
            two_or_more[listed] = i;
            listed += leaf & uint32_t(hanging >= 2);
        }
        faces += level_faces;
        for (uint32_t j = 0; j < listed; ++j) {
            const uint32_t i = two_or_more[j];
            const int hanging = refined_neighbors(state[i]);
            AMC_REQUIRE(hanging != 3, invalid_input,
                        "encode_hierarchy: node " + std::to_string(ids[i]) + " of level " + std::to_string(l) +
                            " has three hanging nodes but is not refined (the hierarchy is not closed)");
            const int unrefined = unrefined_edge(level, i);
            const bool flipped = (truth[i] >> 1) != 0;
            two_hanging.push_back({unrefined, flipped});
            if (turned != nullptr) unturned_exceptions_.add(kTurnedEdge[unrefined + turns[i]], flipped);
            orientation_slots.push_back(events_.size());
            events_.push_back({kOrientationEvent, 0});
        }
        stats.levels = l + 1;
        level_end_.push_back(events_.size());
        scan_decided_level(level, numbering, nullptr);
        derive_next_level(level, numbering, next, options.cull_one_regularity);
        std::vector<std::pair<NodeId, int>>& created = new_vertices_.emplace_back(take_list(m.new_vertices, size_t(l)));
        // Written into a room that only grows, then copied once (the room holds every edge).
        std::vector<std::pair<NodeId, int>>& room = m.new_vertex_room;
        if (room.size() < 3 * size_t(level.refined_count)) room.resize(3 * size_t(level.refined_count));
        const size_t made = turned != nullptr ? write_new_vertices(level, numbering, room.data(), [&](uint32_t i, int e) {
            return std::pair<NodeId, int>(ids[i], kTurnedEdge[e + turns[i]]);
        })
                                              : write_new_vertices(level, numbering, room.data(), [&](uint32_t i, int e) {
                                                    return std::pair<NodeId, int>(ids[i], e);
                                                });
        created.assign(room.data(), room.data() + made);
        std::swap(level, next);
        level_ids_.push_back(std::move(ids));  // kept whole: no copy of the level's ids
        ids = std::move(next_ids);
        next_ids = std::vector<NodeId>();
        turns.swap(next_turns);
    }
    if (memory != nullptr && level_ids_.size() < m.level_ids.size()) m.level_ids[level_ids_.size()] = std::move(ids);
    stats.uniform_levels = uniform_levels;
    stats.faces = faces;

    // The diagonal rule that leaves the fewest exceptions; orientation bits only if any.
    DiagonalExceptions& tally = exceptions_;
    for (auto [edge, flag] : two_hanging) tally.add(edge, flag);
    stats.diagonal_rule = tally.best();
    stats.two_hanging_leaves = tally.leaves;
    stats.diagonal_exceptions = tally.fewest();
    stats.orientation_coded = stats.diagonal_exceptions > 0;
    for (size_t i = 0; i < two_hanging.size(); ++i) {
        const auto [edge, flag] = two_hanging[i];
        events_[orientation_slots[i]].bit = uint8_t(diagonal_flag_by_rule(stats.diagonal_rule, edge) != flag);
    }

    // Stream truncation (II-C): symbols after the last coded 1 are implied zeros. Found from the
    // end (a pass from the front branched on every symbol's bit, a coin flip).
    const uint64_t symbol_count = events_.size() - orientation_slots.size();
    uint64_t trailing_zeros = 0;
    size_t k = events_.size();
    for (; k > 0; --k) {
        const Event& e = events_[k - 1];
        if (e.group == kOrientationEvent) continue;
        if (e.bit) break;
        ++trailing_zeros;
    }
    kept_symbols_ = k == 0 ? 0 : symbol_count - trailing_zeros;
    if (!options.truncate_stream) kept_symbols_ = symbol_count;
    stats.truncated = symbol_count - kept_symbols_;
    stats.coded = kept_symbols_;

    HierarchyStreamHeader header;
    header.options = options;
    header.uniform_levels = uint8_t(stats.uniform_levels);
    header.diagonal_rule = stats.diagonal_rule;
    header.orientation_coded = stats.orientation_coded;
    header.symbol_count = kept_symbols_;
    header_ = write_hierarchy_stream_header(header);
}

HierarchyLevelEncoder::~HierarchyLevelEncoder() {
    if (memory_ == nullptr) return;
    give_back_lists(level_ids_, memory_->level_ids);
    give_back_lists(new_vertices_, memory_->new_vertices);
    memory_->events.swap(events_);
    memory_->level_end.swap(level_end_);
}

std::unique_ptr<HierarchyLevelEncoder> HierarchyLevelEncoder::fork() const {
    if (next_level_ != 0) throw Error("HierarchyLevelEncoder::fork: a level is coded already");
    std::unique_ptr<HierarchyLevelEncoder> copy(new HierarchyLevelEncoder(*this));
    copy->memory_ = nullptr;  // its lists are copies: the memory goes back once, from this one
    return copy;
}

void HierarchyLevelEncoder::encode_level(int l, ArithmeticEncoder& encoder) {
    if (l != next_level_) throw Error("hierarchy levels must be encoded in order");
    ++next_level_;
    const size_t begin = l == 0 ? 0 : level_end_[size_t(l) - 1];
    if (mixed_) {
        if (mixed_model_ == nullptr) mixed_model_ = std::make_shared<MixedHierarchyModel>(mixing_model_);
        for_each_mixed(begin, level_end_[size_t(l)], models_, *mixed_model_, symbols_written_,
                       [&](BitModel* model, uint32_t p16, Event e) {
                           if (model != nullptr) encoder.encode_with_limit<kHierarchyModelLimit>(e.bit, *model);
                           else encoder.encode_with_probability(e.bit != 0, p16);
                       });
        return;
    }
    for_each_coded(begin, level_end_[size_t(l)], models_, symbols_written_, [&](BitModel& model, Event e, size_t) {
        encoder.encode_with_limit<kHierarchyModelLimit>(e.bit, model);
    });
}

std::vector<std::pair<MixedFeatures, bool>> HierarchyLevelEncoder::mixed_symbols() const {
    std::vector<std::pair<MixedFeatures, bool>> out;
    if (!mixed_) return out;
    HierarchyModels models;
    uint64_t symbols = 0;
    for_each_coded(0, events_.size(), models, symbols, [&](BitModel&, Event e, size_t k) {
        if (e.group != kOrientationEvent) out.emplace_back(mixed_features_[event_feature_[k]], e.bit != 0);
    });
    return out;
}

HierarchyCodeStats HierarchyLevelEncoder::stats() const {
    HierarchyCodeStats stats = stats_;
    // The coded symbols' statistics, by replaying the levels coded so far through models of their
    // own: the same probabilities as the coder's, at no cost to encoders that never ask (the
    // code lengths take a logarithm a symbol, a sixth of the encoding time).
    HierarchyModels models;
    uint64_t symbols = 0;
    const size_t end = next_level_ == 0 ? 0 : level_end_[size_t(next_level_) - 1];
    auto tally = [&](double bits, Event e) {
        if (e.group == kOrientationEvent) {
            stats.orientation_bits += bits;
            return;
        }
        ContextGroupStats& group = stats.groups[e.group];
        group.symbols += 1;
        group.ones += e.bit;
        stats.coded_ones += e.bit;
        group.coded_bits += bits;
    };
    if (mixed_) {
        MixedHierarchyModel mixed(mixing_model_);
        for_each_mixed(0, end, models, mixed, symbols, [&](BitModel* model, uint32_t p16, Event e) {
            if (model != nullptr) {
                tally(model->cost_bits(e.bit), e);
                model->update_with_limit(e.bit, kHierarchyModelLimit);
            } else {
                tally(-std::log2(double(e.bit ? p16 : kProbOne - p16) / double(kProbOne)), e);
            }
        });
    } else {
        for_each_coded(0, end, models, symbols, [&](BitModel& model, Event e, size_t) {
            const double bits = model.cost_bits(e.bit);
            model.update_with_limit(e.bit, kHierarchyModelLimit);
            tally(bits, e);
        });
    }
    stats.conditional_entropy_bits = 0;
    stats.adaptive_code_bits = 0;
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
    stats.header_bytes = header_.size();
    return stats;
}

std::vector<uint8_t> encode_hierarchy(const Hierarchy& h, const HierarchyCoderOptions& options,
                                      HierarchyCodeStats* stats_out) {
    // The structure the stream can hold is checked as the coder goes (balance, closure, level
    // cap); the base mesh here, in linear time of its own (a broken one links roots that no
    // stream describes).
    validate_triangle_mesh(h.base(), "encode_hierarchy: base mesh");
    HierarchyLevelEncoder coder(h, options);
    ArithmeticEncoder encoder;
    for (int l = 0; l < coder.level_count(); ++l) coder.encode_level(l, encoder);
    const std::vector<uint8_t> payload = encoder.finish();
    std::vector<uint8_t> out = hierarchy_stream_tag(kHierarchyStreamVersion);
    out.insert(out.end(), coder.header().begin(), coder.header().end());
    out.insert(out.end(), payload.begin(), payload.end());
    if (stats_out != nullptr) {
        *stats_out = coder.stats();
        stats_out->header_bytes = out.size() - payload.size();  // the tag included
        stats_out->payload_bytes = payload.size();
    }
    return out;
}

}  // namespace amc
