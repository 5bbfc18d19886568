// The top-down reconstruction of a hierarchy from its leaf mesh (docs/IMPORT.md, section 1), its
// state shared by the levels (leaf_reconstruction.cpp), the repair of guided picks that the
// next level contradicts (pick_repair.cpp) and the return to an earlier level when a level further
// down contradicts them (pick_backtrack.cpp). Internal to leaf_reconstruction.h's function.
#pragma once

#include "common/compiler.h"
#include "common/huge_pages.h"
#include "common/no_index.h"
#include "geometry/closest_point.h"
#include "import/leaf_detour.h"
#include "import/leaf_reconstruction.h"
#include "import/nearest_vertex.h"

#include <algorithm>
#include <limits>
#include <memory>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

namespace amc {

class Reconstruction {
public:
    Reconstruction(Hierarchy& h, const std::vector<uint32_t>& leaf_of_base, const TriangleMesh& leaf,
                   const LeafHalfedges& halfedges, MidpointGuide guide, const PositionIndex& positions,
                   LeafSearch& search, const std::string& what, const UndoSteps* steps, const PickReferee* referee,
                   const std::vector<uint32_t>* input_of, bool vote_on_guides = false,
                   LeafFacesRead* faces_read = nullptr)
        : vote_on_guides_(vote_on_guides && guide == MidpointGuide::leaf_midpoint), h_(h), leaf_(leaf), he_(halfedges),
          guide_(guide), positions_(positions), search_(search), what_(what), referee_(referee), input_of_(input_of) {
        if (steps) choice_ = std::make_unique<UndoStepChoice>(*steps);
        // Without undo steps or a referee each level's last reading is final (no level is gone
        // back to, no local reconstruction reads it).
        if (faces_read && !steps && !referee) {
            faces_read_ = faces_read;
            *faces_read_ = LeafFacesRead{};
            faces_read_->filled = true;
            faces_read_->bits.assign((leaf.triangles.size() + 63) / 64, 0);
        }
        // A level's reveals are at most two per node, and a node is a leaf face at most once:
        // room for the largest level, offered to huge pages
        // (grown by doubling, their copies and fresh 4 KiB pages were a third of the page
        // faults of a 10^6-face import). Only the pages a level writes become resident.
        reserve_huge(reveals_, 2 * leaf.triangles.size());
        // Each hierarchy vertex has a leaf vertex of its own: room for all of them once (grown a
        // level at a time, these arrays were copied about twice over, 2% of an import).
        leaf_of_vertex_.reserve(leaf.positions.size());
        leaf_of_vertex_.assign(h.positions().size(), kNoIndex);
        vertex_of_leaf_.assign(leaf.positions.size(), kNoIndex);
        for (VertexId v = 0; v < leaf_of_base.size(); ++v) assign(v, leaf_of_base[v]);
    }

    // The leaf vertex of each hierarchy vertex (kNoIndex: none); once per reconstruction.
    std::vector<uint32_t> run();

private:
    struct Reveal {
        NodeId node;
        int edge;
        uint32_t leaf_vertex;
    };
    struct GuidedSlot {
        NodeId node;
        int edge;
    };
    // The reconstruction as it stood before a level was read (pick_backtrack.cpp).
    struct LevelState {
        Hierarchy h;
        std::vector<uint32_t> leaf_of_vertex, vertex_of_leaf, guided_of_vertex;
        std::vector<GuidedSlot> guided;
        std::vector<int8_t> pick_level;
        std::vector<uint64_t> pick_edge;
        std::vector<NodeId> level;
    };
    // Another vertex for the edge (a, b) of a node of `level`, tried by going back to that level;
    // when another pick of the level holds it, that pick's edge gets the vertex (a, b) had.
    struct Retry {
        int level;
        uint32_t a, b, vertex;
        uint64_t swap_edge;  // 0: none
        uint32_t swap_vertex;
    };
    // The forced vertices a retry replaced (kNoIndex: none), to put back.
    struct ForcedBefore {
        uint64_t edge[2] = {0, 0};
        uint32_t vertex[2] = {0, 0};
        int count = 0;
    };

    [[noreturn]] void fail(const std::string& message) const { throw Error(what_ + ": " + message); }

    uint32_t corner(NodeId n, int i) const { return leaf_of_vertex_[h_.vertex(n, i)]; }
    // n's corners as leaf vertices; false if one has none yet (a midpoint above it was not found).
    bool known_corners(NodeId n, uint32_t p[3]) const {
        for (int i = 0; i < 3; ++i) p[i] = corner(n, i);
        return p[0] != kNoIndex && p[1] != kNoIndex && p[2] != kNoIndex;
    }

    // The squared distance from the guide within which a guided pick of the edge (a, b) is sought:
    // twice the edge's length. Where too few vertices pass the midpoint test (every vertex taken
    // under a wrong pick, or a fine region's vertices around a coarse edge), an unbounded search
    // visits the whole tree, which made large graded meshes quadratic.
    double pick_search_limit(uint32_t a, uint32_t b) const {
        const Vec3 ab = leaf_.positions[b] - leaf_.positions[a];
        return 4 * exact_dot(ab, ab);
    }

    // The up to `count` usable leaf vertices nearest to p (NearestVertex::find_nearest), charged
    // to the way's budget of examined vertices.
    template <class Usable>
    uint32_t nearest_usable(Vec3 p, Usable&& usable, uint32_t count, uint32_t* out,
                            double max_squared_distance = std::numeric_limits<double>::infinity()) {
        const NearestVertex& nearest = search_.nearest();
        const uint64_t before = nearest.examined();
        const uint32_t found = nearest.find_nearest(p, usable, count, out, max_squared_distance);
        charge_search(examined_, nearest.examined() - before, kExaminedPerFace);
        return found;
    }
    // The searches for a pick's candidates within budgets per leaf face (and a floor for small
    // meshes): where many vertices lie at one distance from the guides (all at one point, say),
    // every search examines them all, and a way would take time quadratic in the mesh. The
    // corpus's and held-out models' imports, at moves 0 and 0.3, examine at most 532 vertices a
    // face in a way and walk at most 1,457 entries a face comparing candidates (UndoStepChoice,
    // LeafDetour).
    void charge_search(uint64_t& spent, uint64_t work, uint64_t per_face) {
        spent += work;
        if (spent > per_face * leaf_.triangles.size() + kSearchFloor)
            throw SearchBudgetSpent(what_ + ": the positions do not guide the reconstruction (its searches for "
                                            "candidates took " + std::to_string(spent) +
                                    " steps; many vertices at one place?)");
    }
    static constexpr uint64_t kExaminedPerFace = 2048;
    static constexpr uint64_t kWalkedPerFace = 8192;
    static constexpr uint64_t kSearchFloor = uint64_t(1) << 20;
    uint64_t examined_ = 0, walked_ = 0;

    // Leaf vertex l as the caller numbers it (messages name the input's vertices).
    std::string vertex_text(uint32_t l) const {
        return std::to_string(input_of_ && l != kNoIndex ? (*input_of_)[l] : l);
    }
    std::string edge_text(NodeId n, int e) const {
        return vertex_text(corner(n, e)) + "," + vertex_text(corner(n, (e + 1) % 3));
    }

    [[noreturn]] void fail_node(NodeId n, const std::string& message) const {
        // A base triangle that does not fit points at the base rather than at the leaf mesh.
        const std::string which = h_.level(n) == 0 ? "the base triangle " + std::to_string(n) + " on vertices ("
                                                   : "the element on vertices (";
        fail(which + vertex_text(corner(n, 0)) + ", " + vertex_text(corner(n, 1)) + ", " +
             vertex_text(corner(n, 2)) + ") " + message + (h_.level(n) == 0 ? " (wrong base?)" : ""));
    }

    void unassign(VertexId v) {
        vertex_of_leaf_[leaf_of_vertex_[v]] = kNoIndex;
        leaf_of_vertex_[v] = kNoIndex;
    }

    void assign(VertexId v, uint32_t l) {
        if (l == kNoIndex) fail("internal: no leaf vertex for hierarchy vertex " + std::to_string(v));
        if (vertex_of_leaf_[l] != kNoIndex)
            fail("vertex " + vertex_text(l) + " would be used twice by the refinement (not a red-green refinement)");
        leaf_of_vertex_[v] = l;
        vertex_of_leaf_[l] = v;
    }

    // What the leaf mesh says of a node whose corners are the leaf vertices p: refined (no leaf
    // edge between its corners), or a leaf with its unsplit edges, the hanging nodes they reveal
    // and its diagonal, or a fault. Reads nothing else, so a pick can be tried and taken back.
    struct Reading {
        enum Fault { none, edge_across, not_a_face, two_vertices, no_bisection, no_closure } fault = none;
        int unsplit_count = 0;
        bool unsplit[3] = {false, false, false};
        int reveal_count = 0;
        int reveal_edge[2] = {0, 0};
        uint32_t reveal_vertex[2] = {kNoIndex, kNoIndex};
        bool flipped = false;
        int face_count = 0;
        uint32_t faces[3] = {0, 0, 0};  // a leaf's faces: its triangle, or its green ones
        int fault_edge = 0;
        uint32_t fault_detail[2] = {kNoIndex, kNoIndex};  // edge_across: the face; two_vertices: both
        bool refined() const { return fault == none && unsplit_count == 0; }
    };

    // Whether an unmatched leaf vertex may split edge e of n: the midpoint's leaf neighbours lie
    // in the children of n and of the element across that touch it, so of the vertices matched
    // so far, only a, b and those elements' midpoints.
    class MidpointTest {
    public:
        // With `swaps`, a vertex that another guided pick of this level holds passes too.
        MidpointTest(const Reconstruction& r, NodeId n, int e, bool swaps = false) : r_(r), swaps_(swaps) {
            const Hierarchy& h = r.h_;
            allowed_[0] = r.corner(n, e);
            allowed_[1] = r.corner(n, (e + 1) % 3);
            const NodeId q = h.neighbor(n, e);
            for (int k = 0; k < 3; ++k) {
                allowed_[2 + k] = r.leaf_of_vertex_[h.midpoint(n, k)];
                allowed_[5 + k] = q != kNoNode && !h.is_leaf(q) ? r.leaf_of_vertex_[h.midpoint(q, k)] : kNoIndex;
            }
        }
        bool operator()(uint32_t v) const {
            const uint32_t owner = r_.vertex_of_leaf_[v];
            if (owner != kNoIndex && !(swaps_ && r_.guided(owner))) return false;
            return r_.he_.every_neighbor(v, [&](uint32_t w) {
                if (r_.vertex_of_leaf_[w] == kNoIndex) return true;
                bool listed = false;
                for (uint32_t x : allowed_) listed |= x == w;
                return listed;
            });
        }

    private:
        const Reconstruction& r_;
        const bool swaps_;
        uint32_t allowed_[8];
    };

    bool guided(VertexId v) const { return v < guided_of_vertex_.size() && guided_of_vertex_[v] != kNoIndex; }

    static void add_once(std::vector<NodeId>& list, NodeId y) {
        if (y != kNoNode && std::find(list.begin(), list.end(), y) == list.end()) list.push_back(y);
    }

    // Guided pick v given leaf vertex `to`, the guided pick holding `to` (if any) v's old one.
    struct Move {
        VertexId v = kNoIndex;
        uint32_t from = kNoIndex, to = kNoIndex;
        int gain = 0;  // misfits removed
    };
    void take_back(const Move& m) { make(Move{m.v, m.to, m.from, 0}); }

    // Calls f on every leaf-mesh neighbour of u (some twice), in the index's order: joint_candidates
    // keeps them in the order first met (the others call he_.for_each_neighbor_once).
    template <class F>
    void for_each_neighbor(uint32_t u, F f) const {
        for (uint32_t i = 0, d = he_.degree(u); i < d; ++i) {
            f(he_.out_vertex(u, i));
            f(he_.out_apex(u, i));
        }
    }

    Reading read(const uint32_t p[3]) const;
    // read's body, inlined into classify (used in leaf_reconstruction.cpp only); read is it out of line.
    Reading read_inline(const uint32_t p[3]) const;
    // One level: read (repairing the previous level's picks), split, its midpoints found; `next`
    // gets the children.
    void reconstruct_level(std::vector<NodeId>& level, std::vector<NodeId>& next);
    // Splits a level's refined nodes in one pass (HierarchyBuilder::split_level): the node ids,
    // vertex ids, positions and links of split() node by node.
    void split_refined(const std::vector<NodeId>& refined);
    void mark_refined(const std::vector<NodeId>& refined);    // refined_index_
    void unmark_refined(const std::vector<NodeId>& refined);
    // Keeps the state before level `depth` is read (from the first failure on; before that
    // level 0's, to start again from, and those the certification of picks goes back to).
    void remember(int depth, const std::vector<NodeId>& level);
    void restore(int depth, std::vector<NodeId>& level);
    // After level `depth` failed (in its reading, or after it) with `error`: goes back to an
    // earlier level with another vertex for one of the guided picks above the first misfit
    // (restoring `depth` and `level`), judging the retry made before, if any, by this failure.
    // False when no retry is left within the budget.
    bool backtrack(int& depth, std::vector<NodeId>& level, bool read_failed, const std::string& error);
    // A retry that gets past the level it was made for is kept.
    void level_done(int depth) {
        if (depth == retry_depth_) retry_open_ = false, retry_depth_ = -1;
    }
    // The retries for the guided picks above misfit x of level `depth`, nearest levels first.
    void plan_retries(int depth, NodeId x);
    bool start_next_retry(int& depth, std::vector<NodeId>& level);
    int misfit_count(const std::vector<NodeId>& level) const;
    // After level depth - 1 (one of the first kCertifiedLevels) is split: its guided picks judged
    // by their subtrees (pick_certify.cpp); a pick whose subtree does not close while another
    // candidate's does is forced to that candidate and the level made again (depth set back,
    // true). At most kCertifyRounds times per level.
    bool certify_picks(int& depth, std::vector<NodeId>& level);
    // The nodes a judgement reconstructs: the first `inner` of `region` and every node around
    // their corners (a fan cut short stalls the corner children: no same-level neighbour).
    void add_corner_fans(std::vector<NodeId>& region, size_t inner) const;
    static constexpr int kCertifiedLevels = 4;  // levels 0-3: the wrong picks that go unseen
    static constexpr int kCertifyRounds = 4;
    static constexpr int kCertifyHorizon = 5;   // levels judged below a pick (the corpus's depth)
    static constexpr size_t kMaxJudgedRegion = 96;
    // The certification's work (as work_ counts it) per leaf face: the corpus's surface models
    // take 15-20; where most picks misfit (vertices placed anywhere) single changes repair little.
    static constexpr uint64_t kCertifyWorkPerFace = 32;
    uint64_t certify_work_ = 0;
    bool certify_over_budget(uint64_t more) const {
        return certify_work_ + more > kCertifyWorkPerFace * leaf_.triangles.size();
    }
    std::vector<int> certify_rounds_;           // per level
    int certifying_level_ = -1;
    std::vector<uint64_t> judged_picks_;    // retry_key of the picks judged alone in its rounds, sorted
    std::vector<NodeId> changed_regions_;   // the two elements of each of the last round's changes
    std::vector<NodeId> misfits_of_level_;  // the level's nodes, in the order of level_misfits_
    std::vector<int> level_misfits_;        // per node: misfits under it in the last whole reconstruction
    // From the state before level `from` (the caller's, restored), reconstructs only the
    // descendants of `region` (nodes of that level) down to level `depth`, leniently, and counts
    // the misfits among those of its first `inner` nodes (in `per_inner` by inner node, when
    // given), stopping once they reach `cap`; then takes back everything it changed (undo_local),
    // so trials from one state need one restore.
    int local_misfits(int from, int depth, const std::vector<NodeId>& region, size_t inner, int cap = kNoCap,
                      std::vector<int>* per_inner = nullptr);
    static constexpr int kNoCap = 1 << 30;
    // What a local reconstruction changed, to take back: the nodes it split (in order), the
    // diagonal flags of older nodes it read, the leaf vertices it matched, the sizes before.
    struct LocalUndo {
        std::vector<NodeId> splits;
        std::vector<std::pair<NodeId, bool>> flags;
        std::vector<std::pair<VertexId, uint32_t>> matched;  // hierarchy vertex, leaf vertex
        NodeId nodes = 0;
        size_t vertices = 0, guided = 0, guided_of_vertex = 0, picks = 0;
    };
    void undo_local();
    LocalUndo local_undo_;
    // Joint moves (pick_joint.cpp): a judged pick's candidate forced together with other picks
    // that its subtree's misfits blame (of the level and below), certified by the same
    // zero-misfit test. The guided pick (of level blame_from_ or finer) a misfit blames, with
    // how many misfits blame it; collected by local_misfits while blames_ is set.
    struct Blame {
        int level;
        uint32_t a, b, vertex;
        int count;
    };
    std::vector<Blame>* blames_ = nullptr;
    int blame_from_ = 0;
    std::vector<VertexId> blamed_;  // scratch
    void blame_vertex(VertexId v);
    // The guided corners of misfitting node n (under inner node `owner`; the context is not blamed).
    void blame_node(uint32_t owner, NodeId n) {
        if (!blames_ || owner == kNoIndex) return;
        for (int i = 0; i < 3; ++i) blame_vertex(h_.vertex(n, i));
    }
    // Whether `first` (a candidate for a pick of `level` whose own subtree misfits) and at most
    // kJointMoves - 1 more moves of blamed picks close the subtree of region's first `inner`
    // nodes; `moves` gets them. `misfits` is first's count. Forces nothing on return.
    bool closes_jointly(int level, const std::vector<NodeId>& region, size_t inner, const Retry& first, int misfits,
                        std::vector<Retry>& moves);
    // For a judged pick of `level` (as_made) none of whose candidates (`retries`) closes alone:
    // the candidate leaving the fewest misfits (fewer than the pick, at most kJointMisfits) and
    // the moves closes_jointly adds to it; when the group closes while the pick as made does not,
    // even with the same search, its moves of `level` are appended to `changes` (true).
    bool joint_move(int level, const std::vector<NodeId>& region, size_t inner, const Retry& as_made,
                    const Retry* retries, uint32_t count, std::vector<Retry>& changes);
    // Other vertices for a pick of edge (a, b) holding `vertex`: the nearest free ones to the
    // edge's midpoint and the pick's free leaf-mesh neighbours.
    uint32_t joint_candidates(uint32_t a, uint32_t b, uint32_t vertex, uint32_t* out);
    static constexpr int kJointMisfits = 16;     // a candidate leaving more is not moved jointly
    static constexpr int kJointMoves = 4;        // a candidate and up to three blamed picks
    static constexpr int kJointSuspects = 3;     // blamed picks tried per move, most blamed first
    static constexpr uint32_t kMaxJointCandidates = NearestVertex::kMaxCount + 16;
    // Their own work (as work_ counts it) per leaf face: fandisk_gauss takes about 15; a refusal spends it all.
    static constexpr uint64_t kJointWorkPerFace = 20;
    uint64_t joint_work_ = 0;
    bool joint_over_budget() const { return joint_work_ > kJointWorkPerFace * leaf_.triangles.size(); }
    // Notes that hierarchy vertex m, the midpoint of edge e of n, was picked by position or by a
    // retry.
    void note_pick(VertexId m, NodeId n, int e) {
        if (pick_level_.size() <= m) {
            pick_level_.reserve(leaf_.positions.size());  // as leaf_of_vertex_
            pick_edge_.reserve(leaf_.positions.size());
            pick_level_.resize(h_.positions().size(), -1);
            pick_edge_.resize(h_.positions().size(), 0);
        }
        pick_level_[m] = int8_t(h_.level(n));
        pick_edge_[m] = edge_key(corner(n, e), corner(n, (e + 1) % 3));
    }
    ForcedBefore force(const Retry& r);
    void put_back(const ForcedBefore& before);
    static uint64_t edge_key(uint32_t a, uint32_t b) {
        return a < b ? (uint64_t(a) << 32) | b : (uint64_t(b) << 32) | a;
    }
    // A hash of an edge and a vertex (a retry made; a misfit by its corners): a collision only
    // skips a retry.
    static uint64_t retry_key(uint32_t a, uint32_t b, uint32_t v) {
        return edge_key(a, b) ^ (uint64_t(v) * 0x9e3779b97f4a7c15ull);
    }
    // Reads a level's nodes (classify) and checks them against each other before anything is
    // split: balance, T-junctions, hanging nodes. Throws on the first misfit.
    void read_level(const std::vector<NodeId>& level, std::vector<NodeId>& refined);
    // read_level; on a misfit, the previous level's guided picks are repaired first and the level
    // read again (the guided picks are final after this).
    void read_level_or_repair(const std::vector<NodeId>& level, std::vector<NodeId>& refined);
    // Decides whether node n (all corners known) is refined. A leaf keeps at least one edge
    // unsplit (closure), and that edge is then a leaf edge with n on its left; a refined node has
    // none. For a leaf, checks its red or green triangles and notes the hanging nodes, which are
    // the midpoints of the refined neighbours' edges.
    bool classify(NodeId n);
    // classify's refusal of reading r of n (corners p), whose fault the message names.
    [[noreturn]] AMC_NOIPA void fail_reading(NodeId n, const uint32_t p[3], const Reading& r) const;
    // classify's bookkeeping for a reading without a fault (a leaf's unsplit edges, reveals and
    // diagonal); true when n reads refined. A lenient reconstruction (local_misfits) counts a
    // fault instead of throwing its message (a refusal's judgements read thousands of misfits).
    bool take_reading(NodeId n, const Reading& r);
    // A child whose faces do not fit often means that its parent, split on all three edges, was
    // closed by green triangles instead of being split red (closure): a leaf edge then joins a
    // midpoint of the parent to the opposite corner, as bisections and diagonals do.
    void explain_misfit(NodeId n) const;
    // The leaf vertex that splits edge e of refined node n, which no green neighbour revealed.
    uint32_t find_midpoint(NodeId n, int e);
    // Where a and b are a few hops apart (the fine levels), keeps (in order, at the front) the
    // candidates with the least detour off the shortest paths from a to b; returns how many.
    uint32_t on_shortest_chains(uint32_t* candidates, uint32_t count, uint32_t a, uint32_t b);
    // Where the guide expects the vertex that splits edge e of n: where midpoint subdivision of
    // the base puts it (the hierarchy's default placer has computed it), or the midpoint of the
    // edge as the leaf mesh places its ends (which follows projected and moved ends; the surface
    // guide then projects it onto the mesh, the normal-ray guide casts the remesher's line from it).
    Vec3 guide_position(NodeId n, int e);
    // Where the line through `mid` (edge e of n's midpoint) along the mean normal of n and the
    // element across meets the leaf mesh, nearest `mid`; `mid` when it meets nothing within reach.
    Vec3 normal_ray_hit(NodeId n, int e, Vec3 mid);
    // When the children along an edge (a, b) keep their halves unsplit, its midpoint is a common
    // neighbour of a and b, and the only unmatched one: inside the two elements on the edge, a's
    // leaf edges stay in the corner child at a and b's in the corner child at b, which meet only
    // at the midpoint. kNoIndex unless exactly one exists (the final check guards the rest).
    uint32_t only_unmatched_common_neighbor(uint32_t a, uint32_t b);
    // A guided pick made in this level, which a misfit of the children may take back.
    void note_guided(VertexId m, NodeId n, int e);
    // Whether child x of this level's refined nodes reads as the leaf mesh allows, as far as it
    // and its neighbours tell (what the next level's classify and reveals will check): the
    // guided picks among the corners of the nodes involved go to `suspects`.
    bool fits(NodeId x, std::vector<VertexId>* suspects) const;
    // Takes back guided picks of this level that its children (the next level) contradict:
    // for a child that does not fit, each guided pick among the corners involved is replaced by
    // the candidate that leaves the fewest children around it misfitting, if that is fewer.
    void repair_picks();
    // The guided picks are final (the next level has read them).
    void guided_clear();
    // The referee's answers for the repaired picks, applied together (one may free another's);
    // whether it changed any.
    bool referee_after_repair();
    // The children that the leaf vertex of v can change: those of the two elements on its edge
    // and the same-level neighbours whose checks read them.
    void add_around(VertexId v);
    // Makes the move (v takes `to`; the guided pick holding `to`, if any, takes v's old vertex).
    void make(const Move& m);
    // Of the candidates for guided pick v (the nearest eight, also those another guided pick of
    // this level holds: then the two swap), the one that leaves the fewest children around
    // misfitting. Swaps undo the picks of neighbouring edges that took each other's vertex
    // (measured: most wrong picks of the finest levels).
    Move best_move(VertexId v, NodeId misfit);

    // The leaf-midpoint way's revealed midpoints (known for certain; below level 0) as a vote between
    // the guides, each for the guide that puts it nearer; decided at the first level with kMinVotes
    // in all, or at the first misfit: SubdivisionGuideCloser when subdivision has kVoteRatio times
    // leaf's votes (docs/IMPORT.md, "Complexity and speed": the margin to the corpus's surface models).
    void vote_on_guides();
    void decide_guides();
    static constexpr uint64_t kMinVotes = 16;
    static constexpr uint64_t kVoteRatio = 2;
    bool vote_on_guides_;
    uint64_t votes_leaf_ = 0, votes_subdivision_ = 0;

    Hierarchy& h_;
    const TriangleMesh& leaf_;
    const LeafHalfedges& he_;
    const MidpointGuide guide_;
    const PositionIndex& positions_;
    LeafSearch& search_;
    const std::string& what_;
    const PickReferee* referee_;
    const std::vector<uint32_t>* input_of_;  // the caller's number of each leaf vertex (null: the same)
    // The true vertex is among the four nearest for most wrong nearest picks (docs/IMPORT.md);
    // more candidates let farther ones, outside the two elements on the edge, win.
    static constexpr uint32_t kCandidates = 4;
    // A misfit's repair looks further: the true vertex is among the eight nearest for most wrong
    // picks (docs/IMPORT.md), and only a candidate that fits the children better replaces a pick.
    static constexpr uint32_t kRepairCandidates = 8;
    static constexpr int kRepairPasses = 3;
    static constexpr int kChainHops = 4;  // "a few hops": the edges of the finest levels
    // Backtracking (pick_backtrack.cpp): how far up a contradiction is traced; the retries per
    // failure; and the work allowed, in node and vertex records copied or read, per leaf face (a
    // whole reconstruction that keeps its levels copies about ten per face).
    static constexpr int kBacktrackLevels = 3;
    static constexpr int kRetriesPerFailure = 8;
    static constexpr uint64_t kWorkPerFace = 256;
    static constexpr int kMaxMisfits = 16;  // a level misfitting more is given up
    uint64_t work_ = 0;
    std::vector<NodeId> local_level_;  // scratch of local_misfits
    // Way 5's first attempt (docs/IMPORT.md) certifies its coarse picks and returns to the level
    // of a pick that a level further down contradicts.
    bool judges_picks() const { return choice_ && guide_ == MidpointGuide::leaf_midpoint && !referee_; }
    bool over_budget() const { return work_ > kWorkPerFace * leaf_.triangles.size(); }
    uint64_t state_size() const { return h_.node_capacity() + leaf_.positions.size(); }
    bool keep_levels_ = false;                 // snapshots of every level (after a first failure)
    std::vector<LevelState> states_;          // per depth, while kept
    std::vector<int8_t> pick_level_;          // per hierarchy vertex: level of its guided pick, or -1
    std::vector<uint64_t> pick_edge_;         // and its edge (edge_key)
    std::unordered_map<uint64_t, uint32_t> forced_;  // edge -> the vertex a retry gives it
    std::unordered_set<uint64_t> tried_;             // retry_key of the retries made
    std::unordered_set<uint64_t> planned_;            // misfits (their corners) retries were planned for
    bool kept_since_round_ = false;                  // a retry kept since planned_ was cleared
    std::vector<Retry> retries_;                      // those planned for the failure being worked on
    size_t next_retry_ = 0;
    int plan_floor_ = 0;       // the highest level the plan's retries restored
    int retry_depth_ = -1;     // the failing level the planned retries must get past (-1: none)
    int retry_misfits_ = 0;    // its misfits before the retries
    bool retry_open_ = false;  // a retry is applied and not judged yet
    ForcedBefore open_before_;  // of the retry applied
    std::string first_error_;  // reported when the retries do not help
    std::unique_ptr<LeafDetour> detour_;
    std::vector<GuidedSlot> guided_;          // the guided picks of the level last split, until the next reads
    std::vector<uint32_t> guided_of_vertex_;  // per hierarchy vertex: its index in guided_, or kNoIndex
    std::vector<VertexId> suspects_;          // scratch of repair_picks
    std::vector<NodeId> around_;              // scratch of best_move
    std::vector<uint32_t> leaf_of_vertex_;
    std::vector<uint32_t> vertex_of_leaf_;
    std::vector<Reveal> reveals_;
    std::vector<uint32_t> near_b_;  // per leaf vertex: the stamp of the last call that found it next to b
    uint32_t stamp_ = 0;            // (only_unmatched_common_neighbor)
    LeafFacesRead* faces_read_ = nullptr;  // the caller's, when every reading is final (the constructor)
    // The faces of the leaves of the level read last: room for three per node of the level
    // (written through a pointer: a vector's insert was a call per leaf).
    std::unique_ptr<uint32_t[]> level_faces_;
    size_t level_faces_room_ = 0;
    uint32_t* level_faces_end_ = nullptr;
    // The faces of a level's leaves (its last reading: final) added to faces_read_.
    void add_level_faces();
    std::vector<NodeId> refined_;        // scratch of reconstruct_level
    bool read_failed_ = false;           // reconstruct_level failed while reading its level
    NodeId failed_node_ = kNoNode;       // else the node of the level whose vertices did not fit
    // Per node: its index in the list of refined nodes being read or split, or kNoIndex.
    std::vector<uint32_t> refined_index_;
    std::unique_ptr<UndoStepChoice> choice_;
};

}  // namespace amc
