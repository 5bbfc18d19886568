// The hierarchy coder one level at a time, so that a container can interleave each level's
// decisions with the positions of the vertices that level creates (progressive stream). The
// one-shot encode_hierarchy / decode_hierarchy of <amc/hierarchy_coder.h> are built on these.
#pragma once

#include "coding/entropy/arithmetic_coder.h"
#include "coding/hierarchy/hierarchy_stream.h"
#include "coding/hierarchy/hierarchy_traversal.h"
#include "coding/hierarchy/mixed_contexts.h"
#include "common/check.h"

#include <amc/hierarchy_coder.h>

#include <memory>
#include <utility>
#include <vector>

namespace amc {

// The diagonal flags of h's leaves closed by two hanging nodes against every rule (what the
// encoder would choose, without coding anything), counted on `threads` threads.
DiagonalExceptions diagonal_exceptions(const Hierarchy& h, unsigned threads = 1);
// The same for h with each root r and its descendants rotated by root_rotation[r] (0-2), as
// reorder_base rotates them: edge e of a rotated node is edge (e + rotation) % 3 of h's node.
DiagonalExceptions diagonal_exceptions(const Hierarchy& h, const std::vector<uint8_t>& root_rotation, unsigned threads = 1);

// One coded hierarchy symbol in the coder's order, for studies of its contexts (bench/context_study).
struct CodedSymbol {
    NodeId node;
    uint8_t group;  // context group
    bool refined;
};

// The mixing mode's newest model (.amc version 20): its features hold every older model's, so an
// encoder computes them once and may code with the older models too (the smallest file is written).
constexpr MixingModel kWrittenMixingModel = MixingModel::seventh;

// A hierarchy read in another base order without copying it (reorder_base's result, as a view):
// root t of the coded forest is h's root old_root[t] with its local indices turned by turn[t] (its
// edge e is h's edge (e + turn[t]) % 3, its child k h's child red_split::kRotatedChild[turn[t]][k],
// turned alike), and `roots` is the base in that order (its roots linked as the coded forest's).
struct TurnedRoots {
    const Hierarchy* roots;
    const std::vector<uint32_t>* old_root;
    const std::vector<uint8_t>* turn;
};

class HierarchyLevelEncoder {
public:
    struct Memory;
    // Decides every node (first pass): fixes the uniform levels, the diagonal rule and the number
    // of coded symbols, so the header is known before any level is coded. `stream_version`: an
    // older hierarchy stream version may be written for tests of the decoder's older paths.
    // `trace`, if given, receives every symbol the first pass decides by coding, in order (the
    // stream keeps the first stats().coded of them).
    // `mixed`: the mixing mode (FORMAT.md 2.1-2.2): symbols coded by MixedHierarchyModel, in its
    // newest model (kWrittenMixingModel), from features of h's structure and positions, which must
    // be the ones the decoder will have.
    // With `turned`, the forest coded is h in that base order (not with `mixed`); level_nodes and
    // new_vertices are then h's nodes and edges.
    // With `memory`, the first pass works in it and the lists the encoder hands out are made in
    // it, given back when the encoder ends (Memory).
    // `older_models`: the mixing mode's features for the models before the sixth too, so that
    // set_mixing_model may choose one (without them a mixed encode takes about 2 % less).
    HierarchyLevelEncoder(const Hierarchy& h, const HierarchyCoderOptions& options,
                          uint8_t stream_version = kHierarchyStreamVersion, std::vector<CodedSymbol>* trace = nullptr,
                          bool mixed = false, const TurnedRoots* turned = nullptr, Memory* memory = nullptr,
                          bool older_models = true);
    ~HierarchyLevelEncoder();
    bool mixed() const { return mixed_; }
    // A coder of the same first pass that has coded no level yet (Error once this one has): the
    // encoder codes the mixing mode's forest in two models from one first pass.
    std::unique_ptr<HierarchyLevelEncoder> fork() const;
    HierarchyLevelEncoder& operator=(const HierarchyLevelEncoder&) = delete;
    // The mixing mode's model encode_level and stats use (kWrittenMixingModel unless set before
    // the first level; the third, the fourth or the fifth).
    void set_mixing_model(MixingModel model) {
        AMC_REQUIRE(older_models_ || model >= MixingModel::sixth, invalid_input,
                    "the hierarchy coder's first pass has no features for the mixing mode's older models");
        mixing_model_ = model;
    }
    MixingModel mixing_model() const { return mixing_model_; }
    const std::vector<uint8_t>& header() const { return header_; }
    int level_count() const { return int(level_ids_.size()); }
    // Nodes of level l (ids in the encoded hierarchy) in canonical order.
    const std::vector<NodeId>& level_nodes(int l) const { return level_ids_[size_t(l)]; }
    // The vertices level l's splits create, as (node, edge) in canonical order at their first
    // appearance (new_vertices_of_level of level_nodes(l)): what the geometry coder codes.
    const std::vector<std::pair<NodeId, int>>& new_vertices(int l) const { return new_vertices_[size_t(l)]; }
    // Codes level l's symbols and orientation bits; levels must be coded in order 0, 1, ...
    void encode_level(int l, ArithmeticEncoder& encoder);
    // Statistics of everything coded so far (all of it after the last level). payload_bytes and
    // header_bytes are left to the caller, who owns the arithmetic coder.
    HierarchyCodeStats stats() const;
    // Faces of the leaf mesh (1 + hanging nodes per leaf), counted by the first pass: stats().faces
    // without its replay of the symbols.
    uint64_t faces() const { return stats_.faces; }
    // The diagonal flags' exceptions to every rule as the coded forest reads them, and with
    // `turned` as h reads them in its own local order (without the turns, diagonal_exceptions(h)):
    // the encoder's choice of keeping the roots' rotations, without passes of its own over h.
    const DiagonalExceptions& diagonal_exceptions() const { return exceptions_; }
    const DiagonalExceptions& unturned_diagonal_exceptions() const { return unturned_exceptions_; }
    // The mixing mode's coded symbols in order, each with its features (bench/mixing_study).
    std::vector<std::pair<MixedFeatures, bool>> mixed_symbols() const;

private:
    struct Event {
        uint8_t group;  // context group, or kOrientationEvent
        uint8_t bit;
    };
    static constexpr uint8_t kOrientationEvent = 0xff;

    // Calls f(model, event) for each event of [begin, end) that the stream holds, with its model
    // in `models`: orientation bits when any is coded, hierarchy symbols up to the kept count
    // (`symbols` counts those passed so far). encode_level codes them, stats() replays them.
    template <class F>
    void for_each_coded(size_t begin, size_t end, HierarchyModels& models, uint64_t& symbols, F&& f) const {
        // Locals: the models' and the coder's stores may alias the members and `symbols`, which
        // were read again (and the count stored) at every symbol.
        const Event* const events = events_.data();
        const uint64_t kept = kept_symbols_;
        const bool orientation_coded = stats_.orientation_coded, use_contexts = options_.use_contexts;
        uint64_t count = symbols;
        for (size_t k = begin; k < end; ++k) {
            const Event e = events[k];
            if (e.group == kOrientationEvent) {
                if (orientation_coded) f(models.orientation, e, k);
                continue;
            }
            if (count == kept) continue;
            ++count;
            f(models.for_group(e.group, use_contexts), e, k);
        }
        symbols = count;
    }
    // The mixing mode's coded symbols of [begin, end): f(probability, event) with the model's
    // update after each.
    template <class F>
    void for_each_mixed(size_t begin, size_t end, HierarchyModels& models, MixedHierarchyModel& mixed,
                        uint64_t& symbols, F&& f) const {
        for_each_coded(begin, end, models, symbols, [&](BitModel& model, Event e, size_t k) {
            if (e.group == kOrientationEvent) {
                f(&model, 0, e);
                return;
            }
            f(nullptr, mixed.p16(mixed_features_[event_feature_[k]]), e);
            mixed.update(e.bit != 0);
        });
    }

    HierarchyCoderOptions options_;
    HierarchyCodeStats stats_;
    DiagonalExceptions exceptions_, unturned_exceptions_;
    std::vector<Event> events_;
    std::vector<size_t> level_end_;  // events of level l end at level_end_[l]
    std::vector<std::vector<NodeId>> level_ids_;
    std::vector<std::vector<std::pair<NodeId, int>>> new_vertices_;
    std::vector<uint8_t> header_;
    HierarchyModels models_;
    uint64_t kept_symbols_ = 0, symbols_written_ = 0;
    int next_level_ = 0;
    bool mixed_ = false;
    bool older_models_ = true;
    MixingModel mixing_model_ = kWrittenMixingModel;
    std::vector<MixedFeatures> mixed_features_;  // mixing mode: per hierarchy symbol event
    std::vector<uint32_t> event_feature_;        // mixing mode: event index -> mixed_features_ index
    // The mixing mode's state, made at the first level coded: null until then, so that fork()'s
    // copy shares none.
    std::shared_ptr<MixedHierarchyModel> mixed_model_;
    Memory* memory_ = nullptr;  // where the lists go back to at the end (null: nowhere)

    HierarchyLevelEncoder(const HierarchyLevelEncoder&) = default;  // fork()'s

public:
    // The working memory of the first pass and the lists an encoder hands out, kept from one
    // encoder to the next (an EncodeContext's): an encoder made over it takes it at its start and
    // gives it back at its end, so that repeated encodes neither allocate it nor fault its pages
    // in again (docs/BENCHMARKS.md, "One-core encode, nineteenth step"). One encoder at a time.
    struct Memory {
        LevelTraversal traversal{HierarchyCoderOptions{}, kHierarchyStreamVersion};
        Level level, next;
        RefinedNumbering numbering;
        std::vector<uint8_t> refined, turns, next_turns;
        std::vector<std::pair<int, bool>> two_hanging;
        std::vector<uint32_t> two_or_more;  // a level's leaves of two or three hanging nodes
        std::vector<std::pair<NodeId, int>> new_vertex_room;  // write_new_vertices' room
        std::vector<size_t> orientation_slots;
        std::vector<Event> events;
        std::vector<size_t> level_end;
        // Given back by the last encoder: level l's lists at index l.
        std::vector<std::vector<NodeId>> level_ids;
        std::vector<std::vector<std::pair<NodeId, int>>> new_vertices;
    };
};

// Decides `level` of a version-1 stream (hierarchy_decoder_v1.cpp) as the decoder's general path
// does the newest version's: symbols from `decoder` in `models`, none past `symbol_limit`, context
// groups masked by `group_mask`.
void decide_symbols_version1(LevelTraversal& traversal, Level& level, bool uniform_level, ArithmeticDecoder& decoder,
                             HierarchyModels& level_models, uint64_t& level_symbols_read, uint64_t symbol_limit,
                             int group_mask);

class HierarchyLevelDecoder {
public:
    // `header` is the hierarchy stream header's fields (exactly their bytes), of `stream_version`.
    // Throws Error on a bad header or when the uniform levels alone would exceed max_nodes.
    HierarchyLevelDecoder(const TriangleMesh& base, const uint8_t* header, size_t header_size, uint8_t stream_version,
                          uint64_t max_nodes);
    HierarchyLevelDecoder(const TriangleMesh& base, const HierarchyStreamHeader& header, uint64_t max_nodes);
    // A decoder with no stream yet (done() until restart).
    HierarchyLevelDecoder() : traversal_(HierarchyCoderOptions{}, kHierarchyStreamVersion) {}
    HierarchyLevelDecoder(const HierarchyLevelDecoder&) = delete;  // h_ may point at own_
    HierarchyLevelDecoder& operator=(const HierarchyLevelDecoder&) = delete;
    // Starts on another stream as the constructor does, keeping the working memory and the
    // memory of hierarchy() (rebuilt over `base`).
    void restart(const TriangleMesh& base, const HierarchyStreamHeader& header, uint64_t max_nodes);
    // The same with the header's bytes, as the first constructor takes them.
    void restart(const TriangleMesh& base, const uint8_t* header, size_t header_size, uint8_t stream_version,
                 uint64_t max_nodes);
    // Starts on a stream of the `roots` roots of `target` from `first_root`, which must be linked
    // among themselves only and unrefined: their levels are built in `target` (hierarchy() until
    // the next restart), their nodes appended to it. `max_nodes` counts these roots and their
    // descendants.
    void restart_in(Hierarchy& target, NodeId first_root, uint32_t roots, const uint8_t* header, size_t header_size,
                    uint8_t stream_version, uint64_t max_nodes);
    // Until the next restart, the new vertex on each boundary edge of a split node is asked of
    // `split.boundary_vertex` (LevelSplits, hierarchy_builder.h).
    void set_boundary_vertices(VertexId (*boundary_vertex)(void*, VertexId, VertexId), void* context) {
        boundary_vertex_ = boundary_vertex;
        boundary_context_ = context;
    }
    // Until the next restart, how decode_level hands over the vertices it creates: with
    // `corners`, as their frame corners (new_vertex_corners()) or their parents' edges
    // (new_vertex_edges()) instead of new_vertices(), which stays empty; with `placed` false, their positions left at zero for the caller to set (a
    // decoder whose geometry sets every one of them); with `appended` too, where the level is
    // built at the hierarchy's end without seam vertices, not even made: the caller appends them
    // in id order (HierarchyBuilder::append_positions) before the next level.
    void set_new_vertex_listing(bool corners, bool placed, bool appended = false) {
        list_corners_ = corners;
        place_new_vertices_ = placed;
        append_new_positions_ = appended;
    }
    // While set (restart clears it), decode_level gives working memory back to the system
    // (release_pages) as soon as no later step reads it, and each level faults its own in again:
    // for the last levels a decoder decodes, whose nodes and positions would otherwise come on top
    // of the working memory of the levels before them (the peak of a decode).
    void set_lean(bool lean) { lean_ = lean; }
    // While set (restart clears it), decode_level is lean (set_lean) for the last level it builds
    // alone, known once the next level is known to be all leaves: a decoder that gives back only
    // what no later level faults in again.
    void set_lean_at_end(bool lean) { lean_at_end_ = lean; }
    // While set (restart clears it), the decoder decodes no other stream: decode_level gives the
    // working memory no later level reads back to the allocator once the level that may be the
    // last to code symbols comes (the storage another stream would have reused), so that the last
    // level's nodes do not come on top of it. Unlike set_lean, no page is given back that the
    // allocator would have handed out again.
    void set_single_stream(bool single) { single_stream_ = single; }
    // Until the next restart, the levels are built in `slice` of hierarchy() (HierarchySlice,
    // hierarchy_builder.h), not at its end: decoders of chunks building one hierarchy at once.
    void set_slice(HierarchySlice* slice) { slice_ = slice; }
    bool done() const { return level_.empty(); }
    int level() const { return level_index_; }
    // Nodes of the current level (ids in hierarchy()) in canonical order.
    std::vector<NodeId> level_nodes() const;
    // Decides the current level from `decoder` (symbols, orientation bits), splits its refined
    // nodes in hierarchy() and moves to the next level. Throws Error on a corrupt stream, and
    // when the level refines more than `max_refined` nodes (a bound the caller knows from its
    // own data, checked before the next level is allocated).
    void decode_level(ArithmeticDecoder& decoder, uint64_t max_refined = UINT64_MAX);
    // The vertices the last decode_level created, as (node, edge) in canonical order at their
    // first appearance (new_vertices_of_level of its level's nodes), positions not yet set.
    const std::vector<std::pair<NodeId, int>>& new_vertices() const { return new_vertices_; }
    // With set_new_vertex_listing(true, ...): the frame corners of the vertices the last
    // decode_level created, vertex new_vertex_first() + k the k-th, new_vertex_count() of them,
    // walked from that level's split parents in hierarchy(): valid until the next decode_level.
    NewVertexCorners new_vertex_corners() const {
        return NewVertexCorners(*h_, split_parents_, split_parent_count_, new_vertex_first_, new_vertex_count_);
    }
    // The same vertices as (parent, edge), walked from the same split parents.
    NewVertexEdges new_vertex_edges() const {
        return NewVertexEdges(*h_, split_parents_, split_parent_count_, new_vertex_first_, new_vertex_count_);
    }
    VertexId new_vertex_first() const { return new_vertex_first_; }
    size_t new_vertex_count() const { return new_vertex_count_; }
    // Switches to the mixing mode (FORMAT.md 2.1: `model` first for .amc versions 8-9, second for
    // version 10, third from version 11) before the first level. Its features read the positions of hierarchy():
    // decode_level only, each level's new positions set before the next level is decoded.
    void use_mixed_contexts(MixingModel model) { mixed_model_ = std::make_unique<MixedHierarchyModel>(model); }
    // decode_level in two halves, for callers that want every decision before building: decide
    // the current level and move to the next (hierarchy() is not touched); then split every
    // decided level in hierarchy(). In between, node_count() and vertex_count() tell the size
    // the hierarchy will have, so it can be reserved at once.
    void decide_level(ArithmeticDecoder& decoder, uint64_t max_refined = UINT64_MAX);
    void build_decided_levels();
    uint64_t node_count() const { return node_count_; }
    uint64_t vertex_count() const { return vertex_count_; }
    // The nodes of the stream's levels 0 .. min(uniform levels, max_level) (max_level < 0: no
    // limit), which every decode builds without reading a symbol (checked against max_nodes).
    uint64_t uniform_node_count(int max_level) const;
    // Faces of the conforming leaf mesh that the leaves of the decided levels have (1 + hanging
    // nodes each): after the last level, the leaf mesh's face count, without a pass over the nodes.
    uint64_t leaf_faces() const { return leaf_faces_; }
    // The current level's nodes are ids level_first() .. level_first() + level_size() - 1
    // (level_nodes() without the list).
    NodeId level_first() const { return level_base_; }
    size_t level_size() const { return decided_.empty() ? level_.size() : decided_.front().size(); }
    // After the last level: every announced symbol must have been used.
    void finish() const;
    Hierarchy& hierarchy() { return *h_; }

private:
    // Starts on the stream over the roots [first_root, first_root + roots) of *h_.
    void start(NodeId first_root, uint32_t roots, const HierarchyStreamHeader& header, uint64_t max_nodes);
    // Whether the current level, not yet decided, is all leaves (and the last): the stored
    // symbols are used up past the uniform levels.
    bool level_is_all_leaves() const { return all_leaves_from(level_index_); }
    // Whether `level` and every level after it are all leaves, once the levels before are decided.
    bool all_leaves_from(int level) const;
    // Counts the decided level's splits (level_.refined, numbered in numbering_) and the vertices
    // they create, and moves to the next level. `built_next`: the splits are made right after, by
    // the same decode_level.
    void finish_level(bool built_next);
    // decide_level; `built_next`: decode_level's, which splits the level right after.
    void decide(ArithmeticDecoder& decoder, uint64_t max_refined, bool built_next);
    // set_lean's release once the decided level is derived and its new vertices listed, before it
    // is built: everything but the level's refined nodes and the next level's links.
    void release_before_build();
    // set_single_stream's frees: before a level is built and again after, of the spare levels
    // (and of the decided level, which the split makes one) when the next level may use up the
    // stored symbols or the levels shrink, and of the scratch far larger than the next level
    // needs (ScratchArray::shrink_for); before the last level is derived, of the working memory
    // its derivation does not read.
    void free_before_next_level();
    void free_before_last_derive(Level& next, bool links_in_room);
    // decide_level for a stream of the newest version, or of version 1 (kVersion1).
    template <bool kVersion1>
    void decide_level_of(ArithmeticDecoder& decoder);
    void decide_level_version1(ArithmeticDecoder& decoder);

    HierarchyStreamHeader header_;
    uint64_t max_nodes_ = 0;
    Hierarchy own_;
    Hierarchy* h_ = &own_;  // the hierarchy built: own_, or restart_in's target
    VertexId (*boundary_vertex_)(void*, VertexId, VertexId) = nullptr;
    void* boundary_context_ = nullptr;
    HierarchySlice* slice_ = nullptr;
    HierarchyModels models_;
    LevelTraversal traversal_;
    Level level_;
    std::vector<Level> decided_;  // decided levels not yet built, oldest first
    std::vector<Level> spare_;    // built levels, whose memory the next levels reuse
    RefinedNumbering numbering_;     // of the level being decided
    std::vector<std::pair<NodeId, int>> new_vertices_;  // of the last decode_level
    bool list_corners_ = false, place_new_vertices_ = true, append_new_positions_ = false;  // set_new_vertex_listing
    bool lean_ = false;                                      // set_lean
    bool lean_at_end_ = false;                               // set_lean_at_end
    bool single_stream_ = false;                             // set_single_stream
    bool next_links_in_room_ = false;  // level_'s links are in the room of its nodes (finish_level)
    bool appending_positions() const {
        return append_new_positions_ && !place_new_vertices_ && slice_ == nullptr && boundary_vertex_ == nullptr;
    }
    // The last decode_level's split parents (ids, in its level's refined list), when listed.
    const NodeId* split_parents_ = nullptr;
    uint32_t split_parent_count_ = 0;
    VertexId new_vertex_first_ = 0;
    size_t new_vertex_count_ = 0;
    ScratchArray<uint32_t> closures_;  // the leaves with two or three hanging nodes
    NodeId level_base_ = 0;  // node id of local index 0 of the oldest level not yet built
    int level_index_ = 0;
    uint64_t node_count_ = 0, vertex_count_ = 0, symbols_read_ = 0, leaf_faces_ = 0;
    std::unique_ptr<MixedHierarchyModel> mixed_model_;  // the mixing mode's state, or null
    LevelShapes mixed_shapes_;                          // the mixing mode's normals and bending of the level
};

}  // namespace amc
