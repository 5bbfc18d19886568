// Hierarchy decoder: the mirror of hierarchy_encoder.cpp. It grows the forest over the shared base
// mesh level by level, taking each decision from a rule or from the stream.
#include "coding/hierarchy/hierarchy_level_coder.h"
#include "common/check.h"
#include "common/compiler.h"
#include "hierarchy/hierarchy_builder.h"

#include <algorithm>
#include <string>
#include <utility>

namespace amc {

namespace {

HierarchyStreamHeader parse_header(const uint8_t* data, size_t size, uint8_t version) {
    HierarchyStreamHeader header;
    AMC_REQUIRE(read_hierarchy_stream_header(data, size, header) == size, corrupt,
                "hierarchy stream: header has trailing bytes");
    header.version = version;
    return header;
}

// At most how many symbols deciding `level` can read: one a node, none for the nodes
// 1-regularity culls (the incomplete ones); more than any stream holds for a version-1 stream,
// which never takes the fast path. Not inlined nor analysed across calls: GCC's register
// allocation in the traversal is easily upset (see HIERARCHY_CODER.md, Speed).
AMC_NOIPA uint64_t codable_symbols(const Level& level, const HierarchyStreamHeader& header) {
    if (culls_decided_in_turn(header.version)) return UINT64_MAX;
    const uint32_t n = static_cast<uint32_t>(level.size());
    return header.options.cull_one_regularity ? n - level.incomplete_count : n;
}

// Decides `level` with `traversal`, its symbols from `decoder` in `models` (a symbol past
// `symbol_limit` is 0, the context groups are masked by `group_mask`): the general path, for the
// levels where the stored symbols may run out, and for every level of a version-1 stream (which
// goes its own way from here: a test of the version, or a call, in decide_level cost the fast
// path 3.6% more instructions, HIERARCHY_CODER.md, Speed, item 34). A function of its own whose
// locals hold the coder's state while the traversal, inlined, runs: every state byte the
// traversal writes could alias anything reached through a pointer or a reference, which would
// then be reloaded for every node. (Called from decide_level, the traversal had reached the coder
// through its lambdas' references: 12% more instructions per node than the fast path.) No
// interprocedural analysis: what GCC learnt of this function cost decide_level's fast path 9% more
// instructions.
AMC_NOIPA void decide_symbols_general(LevelTraversal& traversal, Level& level, bool uniform_level,
                                      ArithmeticDecoder& decoder, HierarchyModels& level_models,
                                      uint64_t& level_symbols_read, uint64_t symbol_limit, int group_mask) {
    if (traversal.culls_in_turn()) {
        decide_symbols_version1(traversal, level, uniform_level, decoder, level_models, level_symbols_read,
                                symbol_limit, group_mask);
        return;
    }
    ArithmeticDecoder d = decoder;
    HierarchyModels models = level_models;
    uint64_t symbols_read = level_symbols_read;
    traversal.run_newest(
        level, uniform_level,
        [&](uint32_t, int group) {
            if (symbols_read == symbol_limit) return false;
            ++symbols_read;
            return d.decode_with_limit<kHierarchyModelLimit>(models.groups[size_t(group & group_mask)]);
        },
        [&](uint32_t, Fate, bool refined) { return refined; });
    decoder = d;
    level_models = models;
    level_symbols_read = symbols_read;
}

}  // namespace

HierarchyLevelDecoder::HierarchyLevelDecoder(const TriangleMesh& base, const uint8_t* header, size_t header_size,
                                             uint8_t stream_version, uint64_t max_nodes)
    : HierarchyLevelDecoder(base, parse_header(header, header_size, stream_version), max_nodes) {}

HierarchyLevelDecoder::HierarchyLevelDecoder(const TriangleMesh& base, const HierarchyStreamHeader& header,
                                             uint64_t max_nodes)
    : HierarchyLevelDecoder() {
    restart(base, header, max_nodes);
}

void HierarchyLevelDecoder::restart(const TriangleMesh& base, const uint8_t* header, size_t header_size,
                                    uint8_t stream_version, uint64_t max_nodes) {
    restart(base, parse_header(header, header_size, stream_version), max_nodes);
}

void HierarchyLevelDecoder::restart(const TriangleMesh& base, const HierarchyStreamHeader& header, uint64_t max_nodes) {
    h_ = &own_;
    own_.reset(base);
    start(0, own_.root_count(), header, max_nodes);
}

void HierarchyLevelDecoder::restart_in(Hierarchy& target, NodeId first_root, uint32_t roots, const uint8_t* header,
                                       size_t header_size, uint8_t stream_version, uint64_t max_nodes) {
    AMC_REQUIRE(uint64_t(first_root) + roots <= target.root_count(), invalid_input, "hierarchy decoder: roots out of range");
    h_ = &target;
    start(first_root, roots, parse_header(header, header_size, stream_version), max_nodes);
}

void HierarchyLevelDecoder::start(NodeId first_root, uint32_t roots, const HierarchyStreamHeader& header,
                                  uint64_t max_nodes) {
    header_ = header;
    max_nodes_ = max_nodes;
    boundary_vertex_ = nullptr;
    boundary_context_ = nullptr;
    list_corners_ = false;
    place_new_vertices_ = true;
    append_new_positions_ = false;
    lean_ = false;
    lean_at_end_ = false;
    single_stream_ = false;
    next_links_in_room_ = false;
    split_parents_ = nullptr;
    split_parent_count_ = 0;
    slice_ = nullptr;
    // Uniform levels alone would build roots * (4^(U+1) - 1) / 3 nodes: check before.
    uint64_t uniform_nodes = roots, level_nodes = roots;
    for (int l = 0; l < header_.uniform_levels && uniform_nodes <= max_nodes_; ++l) {
        level_nodes *= 4;
        uniform_nodes += level_nodes;
    }
    AMC_REQUIRE(uniform_nodes <= max_nodes_, limit_exceeded,
                "hierarchy stream would build more than " + std::to_string(max_nodes_) + " nodes");
    models_ = HierarchyModels();
    mixed_model_.reset();
    mixed_shapes_ = LevelShapes();  // it keeps the base's edge length once computed
    traversal_.configure(header.options, header.version);
    for (Level& level : decided_) spare_.push_back(std::move(level));
    decided_.clear();
    root_level(*h_, first_root, roots, level_, header.options.cull_one_regularity);
    level_index_ = 0;
    level_base_ = first_root;
    node_count_ = roots;
    vertex_count_ = h_->positions().size();
    symbols_read_ = 0;
    leaf_faces_ = 0;
}

uint64_t HierarchyLevelDecoder::uniform_node_count(int max_level) const {
    const int levels = max_level < 0 ? header_.uniform_levels : std::min(int(header_.uniform_levels), max_level);
    uint64_t nodes = level_size(), level_nodes = nodes;
    for (int l = 0; l < levels; ++l) {
        level_nodes *= 4;
        nodes += level_nodes;
    }
    return nodes;
}

std::vector<NodeId> HierarchyLevelDecoder::level_nodes() const {
    const size_t n = level_size();
    std::vector<NodeId> ids(n);
    for (size_t i = 0; i < n; ++i) ids[i] = level_base_ + NodeId(i);
    return ids;
}

void HierarchyLevelDecoder::decode_level(ArithmeticDecoder& decoder, uint64_t max_refined) {
    const uint64_t vertices_before = vertex_count_;
    decide(decoder, max_refined, true);
    // Node ids are consecutive level by level: the decided level's nodes come right before its
    // children, the last nodes counted.
    const Level& level = decided_.back();
    const NodeId first = level_base_;
    new_vertices_.clear();
    new_vertex_first_ = slice_ != nullptr ? slice_->next_vertex : VertexId(h_->positions().size());
    if (!list_corners_) {
        new_vertices_.reserve(vertex_count_ - vertices_before);  // once per level, not doubling vertex by vertex
        for_each_new_vertex(level, numbering_, [&](uint32_t i, int e) { new_vertices_.emplace_back(first + i, e); });
    }
    // The next level all leaves: this is the last level built, and nothing given back now is
    // faulted in again by a later level of this decode.
    const bool last_built = level_is_all_leaves();
    const bool lean = lean_ || (lean_at_end_ && last_built);
    if (single_stream_ && last_built && decided_.size() == 1) {  // derived and listed: the split reads the rest
        decided_.back().free_all_but_splits();
        numbering_.deallocate();
    }
    if (lean) release_before_build();
    // What the level after this one will not reuse goes before the split faults its children in.
    if (single_stream_ && !last_built) free_before_next_level();
    build_decided_levels();
    if (lean) {
        for (Level& built : spare_)  // the split parents listed stay for new_vertex_corners()
            if (built.refined.data() != split_parents_) built.refined.release_from(0);
        if (last_built) {  // the next level's links served the split alone
            level_.nbr.release_from(0);
            level_.edges.release_from(0);
        }
    }
    if (single_stream_ && last_built) {
        level_.nbr.deallocate();
        level_.edges.deallocate();
    }
    // Before the level's new positions come.
    if (single_stream_) free_before_next_level();
    new_vertex_count_ = appending_positions() ? size_t(vertex_count_ - vertices_before)
                                              : (slice_ != nullptr ? slice_->next_vertex : h_->positions().size()) - new_vertex_first_;
}

void HierarchyLevelDecoder::decide_level(ArithmeticDecoder& decoder, uint64_t max_refined) {
    decide(decoder, max_refined, false);
}

void HierarchyLevelDecoder::decide(ArithmeticDecoder& decoder, uint64_t max_refined, bool built_next) {
    AMC_REQUIRE(!done(), invalid_input, "hierarchy stream: no level left to decode");
    const int l = level_index_;
    uint8_t* state = level_.state();
    const uint32_t n = static_cast<uint32_t>(level_.size());
    // II-C, stream truncation: once the stored symbols are used up, the rest are 0. (Without it no
    // limit: UINT64_MAX - 1, so that no level can seem to have room for codable_symbols' UINT64_MAX.)
    const uint64_t symbol_limit = header_.options.truncate_stream ? header_.symbol_count : UINT64_MAX - 1;
    if (level_is_all_leaves()) {  // and the last: no traversal needed
        if (!level_.leaves_only())
            for (uint32_t i = 0; i < n; ++i) state[i] = uint8_t(state[i] | kDecided);
        level_.refined_count = 0;
        finish_level(false);
        return;
    }
    // The coder's state lives in locals while the level is decided: every state byte the
    // traversal writes could alias a member as far as the compiler knows, and members would be
    // reloaded for every node. Whether a refined node may be refined is checked afterwards.
    ArithmeticDecoder d = decoder;
    HierarchyModels models = models_;
    uint64_t symbols_read = symbols_read_;
    const int group_mask = header_.options.use_contexts ? 0xff : 0;
    // Fast when the level can not code more symbols than are left: at most one a node, and none
    // for the nodes 1-regularity culls (the incomplete ones; this bound makes the second-finest
    // levels of a random refinement fast too). Then every context group has its model, and
    // nothing is tested or masked per symbol. Marked likely and group_mask defined above: GCC's
    // register allocation around this path is fragile (HIERARCHY_CODER.md, Speed, item 29).
    if (mixed_model_ != nullptr) {
        // The mixing mode (FORMAT.md 2.1): the features read this level's nodes in *h_, built by
        // decode_level with their corners placed; node id = level_base_ + local index.
        AMC_REQUIRE(decided_.empty(), invalid_input, "hierarchy stream: the mixing mode decodes one level at a time");
        MixedHierarchyModel& mixed = *mixed_model_;
        LevelShapes& shapes = mixed_shapes_;
        shapes.start_level(n);
        const MixingModel model = mixed.model();
        const Hierarchy& h = *h_;
        const NodeId base = level_base_;
        const Level& current = level_;
        traversal_.run_newest(
            level_, l < header_.uniform_levels,
            [&](uint32_t i, int group) {
                if (symbols_read == symbol_limit) return false;
                ++symbols_read;
                const bool bit = d.decode_with_probability(mixed.p16(mixed_features(h, base + i, current, i, group, shapes, model)));
                mixed.update(bit);
                return bit;
            },
            [&](uint32_t, Fate, bool refined) { return refined; });
    } else if (__builtin_expect(header_.options.use_contexts &&
                                    symbol_limit - symbols_read >= codable_symbols(level_, header_),
                                1)) {
        traversal_.run_newest(
            level_, l < header_.uniform_levels,
            [&](uint32_t, int group) {
                ++symbols_read;
                return d.decode_with_limit<kHierarchyModelLimit>(models.groups[size_t(group)]);
            },
            [&](uint32_t, Fate, bool refined) { return refined; });
    } else {
        decide_symbols_general(traversal_, level_, l < header_.uniform_levels, d, models, symbols_read, symbol_limit,
                               group_mask);
    }
    // The next level's numbering of the refined nodes, the leaves closed by two hanging nodes
    // (their diagonals come next in the stream) and the checks. Errors name the element by its
    // level and canonical index: its node id may not exist yet.
    auto corrupt = [&](uint32_t i, const char* what) {
        return Error(ErrorCode::corrupt, "hierarchy stream is corrupt: element " + std::to_string(i) + " of level " +
                                             std::to_string(l) + what);
    };
    uint32_t* const closures = closures_.reserve(n);
    const DecidedLevelScan scan = scan_decided_level(level_, numbering_, closures);
    const uint32_t closure_count = scan.closures;
    const bool flag_by_rule[3] = {diagonal_flag_by_rule(header_.diagonal_rule, 0),
                                  diagonal_flag_by_rule(header_.diagonal_rule, 1),
                                  diagonal_flag_by_rule(header_.diagonal_rule, 2)};
    for (uint32_t k = 0; k < closure_count; ++k) {
        const uint32_t i = closures[k];
        if (refined_neighbors(state[i]) == 3) throw corrupt(i, " has three hanging nodes but was not refined");
        bool flag = flag_by_rule[unrefined_edge(level_, i)];
        if (header_.orientation_coded) flag ^= d.decode_with_limit<kHierarchyModelLimit>(models.orientation);
        if (flag) level_.flipped.push_back(i);
    }
    const uint32_t count = level_.refined_count;
    if (count > 0 && (scan.refined_incomplete || l >= kMaxLevel)) {
        for (uint32_t i = 0; i < n; ++i) {
            if ((state[i] & kRefined) && (!(state[i] & kComplete) || l >= kMaxLevel))
                throw corrupt(i, " can not be refined");
        }
    }
    AMC_REQUIRE(d.overran() == false, truncated, "hierarchy stream is truncated");
    AMC_REQUIRE(count <= max_refined, corrupt,
                "level " + std::to_string(l) + " refines " + std::to_string(count) +
                    " nodes, more than its block can hold the new vertices of");
    AMC_REQUIRE(node_count_ + uint64_t(4) * count <= max_nodes_, limit_exceeded,
                "hierarchy stream would build more than " + std::to_string(max_nodes_) + " nodes");
    decoder = d;
    models_ = models;
    symbols_read_ = symbols_read;
    finish_level(built_next);
}

bool HierarchyLevelDecoder::all_leaves_from(int level) const {
    // Every symbol left is 0, and with no node of the level refined yet no rule can force one.
    return header_.options.truncate_stream && symbols_read_ == header_.symbol_count && level >= header_.uniform_levels;
}

void HierarchyLevelDecoder::finish_level(bool built_next) {
    node_count_ += uint64_t(4) * level_.refined_count;
    leaf_faces_ += leaf_faces_of_level(level_);
    // The next level takes a spare level's memory only now, once the level before was built and
    // given back: decoded one level at a time, two levels' memory take turns.
    Level next;
    if (!spare_.empty()) {
        next = std::move(spare_.back());
        spare_.pop_back();
        if (single_stream_) next.shrink_for(size_t(4) * level_.refined_count);
    }
    // A next level of leaves alone (the stored symbols used up), split now: nothing but the split
    // reads its links, which go straight into the room of its nodes (the last level's links were
    // a sixth of a decode's peak). Lean or single-stream, deriving them there faults the nodes in
    // while the working memory (about 20 bytes a node of this level) is still there, where the
    // links' own array (12 bytes a node of the next) would have gone back before the split: the
    // room only where the next level is more than twice this one's size (lean) or larger than it
    // (single-stream; docs/BENCHMARKS.md).
    const bool lean = lean_ || lean_at_end_;
    const uint64_t next_nodes = uint64_t(4) * level_.refined_count;
    const bool links_in_room =
        built_next && next_nodes > 0 && all_leaves_from(level_index_ + 1) &&
        next_nodes > (lean ? 2 * uint64_t(level_.size()) : single_stream_ ? uint64_t(level_.size()) : 0);
    if (single_stream_ && built_next && all_leaves_from(level_index_ + 1)) free_before_last_derive(next, links_in_room);
    const ChildLinkRoom room =
        links_in_room ? HierarchyBuilder::open_children(*h_, slice_, level_.refined_count) : ChildLinkRoom{};
    level_.new_vertices = derive_next_level(level_, numbering_, next, header_.options.cull_one_regularity, room);
    next_links_in_room_ = links_in_room;
    vertex_count_ += level_.new_vertices;
    decided_.push_back(std::move(level_));
    level_ = std::move(next);
    ++level_index_;
}

void HierarchyLevelDecoder::free_before_next_level() {
    const int l = level_index_;
    const uint32_t n = uint32_t(level_.size());
    // The spare levels wait for the level after this one (at most 4n nodes), which is not derived
    // when the stored symbols end in this level (the next is all leaves, all_leaves_from): this
    // level reads at most codable_symbols of them, none if uniform. When this level is less than
    // half the spare's, the levels shrink (a graded refinement past its finest region), and the
    // level after is very likely smaller still: a smaller array then, not the spare's pages.
    const bool symbols_may_end =
        header_.options.truncate_stream && l + 1 >= header_.uniform_levels &&
        header_.symbol_count - symbols_read_ <= (l < header_.uniform_levels ? 0 : codable_symbols(level_, header_));
    auto dead = [&](const Level& spare) {
        return symbols_may_end || spare.nbr.capacity() > ScratchArray<Neighbors>::kShrinkFactor * n;
    };
    for (Level& spare : spare_) {
        if (!dead(spare)) continue;
        spare.free_all_but_splits();
        if (spare.refined.data() != split_parents_) spare.refined.deallocate();  // new_vertex_corners() walks them
    }
    // A spare once split, which reads its refined nodes alone (of several decided levels, each
    // one's links are the split of the one before).
    if (decided_.size() == 1 && dead(decided_.back())) {
        Level& decided = decided_.back();
        const bool shrinking = decided.nbr.capacity() > ScratchArray<Neighbors>::kShrinkFactor * n;
        decided.free_all_but_splits();
        // Lean, where the levels shrink, the heap glibc keeps goes too: freed but kept, the
        // largest level's working memory stayed resident to the end (lshape, docs/BENCHMARKS.md).
        if (lean_at_end_ && shrinking) release_free_heap();
    }
    traversal_.shrink_working_memory(n);
    numbering_.shrink_for(n);
    closures_.shrink_for(n);
}

void HierarchyLevelDecoder::free_before_last_derive(Level& next, bool links_in_room) {
    spare_.clear();
    traversal_.free_working_memory();
    closures_.deallocate();
    level_.lowered.deallocate();  // its own derivation's
    if (links_in_room) {  // the last level needs no array of its own
        next.nbr.deallocate();
        next.edges.deallocate();
        next.lowered.deallocate();
        next.refined.deallocate();
    }
}

void HierarchyLevelDecoder::release_before_build() {
    auto release_links = [](Level& level, size_t keep) {
        level.nbr.release_from(keep);
        level.edges.release_from(keep / 4);
        level.lowered.release_from(0);  // derive_next_level's alone
    };
    for (Level& decided : decided_) release_links(decided, 0);
    for (Level& spare : spare_) {
        release_links(spare, 0);
        spare.refined.release_from(0);
    }
    release_links(level_, next_links_in_room_ ? 0 : level_.size());  // in the room: its array is unused
    numbering_.release();
    closures_.release_from(0);
    traversal_.release_working_memory();
}

void HierarchyLevelDecoder::build_decided_levels() {
    split_parents_ = nullptr;
    split_parent_count_ = 0;
    for (size_t k = 0; k < decided_.size(); ++k) {
        Level& level = decided_[k];
        const Level& children = k + 1 < decided_.size() ? decided_[k + 1] : level_;
        // Node ids of the decoder's hierarchy are level_base_ + local index: roots are 0..R-1 and
        // the children of each level are numbered consecutively (no ids are ever freed). The
        // next level's links are the children's links, so the whole level splits in one pass,
        // in canonical order.
        for (const uint32_t i : level.flipped) h_->set_diagonal_flipped(level_base_ + i, true);
        const uint32_t count = level.refined_count;
        uint32_t* parents = level.refined.data();
        for (uint32_t b = 0; b < count; ++b) parents[b] += level_base_;
        const bool in_place = k + 1 == decided_.size() && next_links_in_room_;  // open_children made the room
        const NodeId first_child =
            slice_ != nullptr ? slice_->next_node : h_->node_capacity() - (in_place ? 4 * count : 0);
        LevelSplits splits{parents, count, in_place ? nullptr : children.nbr.data(), in_place ? nullptr : children.edges.data(),
                           boundary_vertex_, boundary_context_};
        splits.links_in_place = in_place;
        splits.slice = slice_;
        splits.new_vertex_count = level.new_vertices;
        // Listed or left unplaced for decode_level's caller, which takes one level at a time.
        if (list_corners_ || !place_new_vertices_) {
            AMC_REQUIRE(decided_.size() == 1, invalid_input, "hierarchy decoder: listed new vertices need decode_level");
            split_parents_ = list_corners_ ? parents : nullptr;  // new_vertex_corners() walks them
            split_parent_count_ = list_corners_ ? count : 0;
            splits.place_new_vertices = place_new_vertices_;
            splits.append_new_positions = appending_positions();
        }
        HierarchyBuilder::split_level(*h_, splits);
        level_base_ = first_child;
    }
    // Their memory serves the levels to come.
    for (Level& level : decided_) spare_.push_back(std::move(level));
    decided_.clear();
}

void HierarchyLevelDecoder::finish() const {
    AMC_REQUIRE(!header_.options.truncate_stream || symbols_read_ == header_.symbol_count, corrupt,
                "hierarchy stream is corrupt: " + std::to_string(header_.symbol_count) + " symbols announced, " +
                    std::to_string(symbols_read_) + " used");
}

Hierarchy decode_hierarchy(const TriangleMesh& base, const uint8_t* data, size_t size,
                           const HierarchyDecodeOptions& options) {
    Hierarchy h;
    HierarchyDecoder().decode(base, data, size, h, options);
    return h;
}

HierarchyDecoder::HierarchyDecoder() = default;
HierarchyDecoder::~HierarchyDecoder() = default;
HierarchyDecoder::HierarchyDecoder(HierarchyDecoder&&) noexcept = default;
HierarchyDecoder& HierarchyDecoder::operator=(HierarchyDecoder&&) noexcept = default;

void HierarchyDecoder::decode(const TriangleMesh& base, const uint8_t* data, size_t size, Hierarchy& out,
                              const HierarchyDecodeOptions& options) {
    AMC_REQUIRE(data != nullptr || size == 0, invalid_input, "hierarchy stream: no data");
    with_allocation_errors_as_limits("hierarchy stream", [&] { decode_stream(base, data, size, out, options); });
}

void HierarchyDecoder::decode_stream(const TriangleMesh& base, const uint8_t* data, size_t size, Hierarchy& out,
                                     const HierarchyDecodeOptions& options) {
    HierarchyStreamHeader header;
    const size_t header_size = read_standalone_stream_header(data, size, header, options.untagged_version);
    if (coder_ == nullptr) coder_ = std::make_unique<HierarchyLevelDecoder>();
    // The coder builds in the memory of `out`; its own hierarchy waits in `out` meanwhile and
    // goes back to it at the end, whatever happens.
    std::swap(coder_->hierarchy(), out);
    struct SwapBack {
        Hierarchy& a;
        Hierarchy& b;
        ~SwapBack() { std::swap(a, b); }
    } swap_back{coder_->hierarchy(), out};
    coder_->restart(base, header, options.max_nodes);
    ArithmeticDecoder decoder(data + header_size, size - header_size);
    // All decisions first, so that the hierarchy is built in memory of its exact final size.
    while (!coder_->done() && coder_->level() != options.max_level) coder_->decide_level(decoder);
    if (coder_->done()) coder_->finish();
    coder_->hierarchy().reserve(coder_->node_count(), coder_->vertex_count());
    coder_->build_decided_levels();
}

}  // namespace amc
