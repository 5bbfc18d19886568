// The inverse step's level search (docs/IMPORT.md, "Leaf mesh alone"): blocks, patches and the
// search that commits them; inverse_refinement.cpp drives it, level_finder.cpp and
// level_finder_blocks.cpp define it.
#pragma once

#include "import/inverse_refinement.h"
#include "common/no_index.h"
#include "import/triangle_adjacency.h"

#include <array>
#include <atomic>
#include <cstdint>
#include <utility>
#include <vector>

namespace amc::detail::inverse {

// The inverse step (docs/IMPORT.md, "Leaf mesh alone").
//
// A block is the hypothesis "this triangle is the center of a 1-to-4 split": its three vertices
// become midpoints (removed), its three apexes stay. Blocks come in patches: where a midpoint
// has a block on both sides, or where two blocks share a closure of two hanging nodes, they must
// be undone in the same step (undoing one alone leaves a midpoint without closure, or makes a
// closure that the other can never join). So patches are grown whole from a seed, following every
// midpoint into the block across it, and kept only if every side of every block is then valid:
// the boundary, another block of the patch, or a green closure of one or two hanging nodes.
// Where a side may be read two ways (the block across, or a closure of two hanging nodes with a
// block beyond), a patch is grown under two preference orders.
//
// The valid patches are committed best first (most vertices removed), as in Taubin's detection of
// uniform subdivision connectivity, where the largest consistent reading wins; then each
// committed patch is taken out and its neighbourhood solved again without it, and the better of
// the two stays.
//
// Conventions (docs/HIERARCHY.md): a block's parent is (v0, v1, v2), midpoint m_i lies on edge
// v_i -> v_{i+1}; "corner k" is the block's triangle at v_k, the center the one of the three
// midpoints. These are leaf triangles in the mesh's own vertex order: which child of the split
// each becomes is red_split.h's business (the hierarchy is built from the splits' points).


// The triangles around midpoint m_i outside its block, walked from v_{i+1} to v_i.
struct Fan {
    enum Kind : uint8_t { invalid, boundary, triangles } kind = invalid;
    uint8_t size = 0;        // 2 or 3 triangles
    uint32_t entry[3] = {};  // the half-edge by which the walk entered each (x -> m)
    uint32_t inner[2] = {};  // the vertices between consecutive fan triangles
    // Triangle k of the fan, the one its entry half-edge belongs to (a block's shape is kept
    // for every triangle read, so the fan stays small).
    uint32_t triangle(int k) const { return entry[k] / 3; }
};

struct Block {
    uint32_t center;
    std::array<uint32_t, 3> corner;       // corner k holds parent vertex v_k
    std::array<uint32_t, 3> v, m;         // parent vertices, midpoints (m_i on v_i -> v_{i+1})
    std::array<uint32_t, 3> first_half;   // half-edge v_i -> m_i (in corner i)
    std::array<uint32_t, 3> second_half;  // half-edge m_i -> v_{i+1} (in corner i+1)
    std::array<Fan, 3> fan;               // around m_i (the mesh alone decides it)
    bool alive;
    uint32_t patch;  // the committed patch it belongs to, or kNoIndex while growing
};

// What lies across a block's edge, once labels are known.
struct Side {
    enum Kind : uint8_t { invalid, boundary, red, green } kind = invalid;
    int count = 0;          // green: triangles of the closure
    uint32_t group[3] = {};
    Triangle coarse = {};   // green: the coarse triangle of the closure
    bool emits = false;     // green: this side (hanging node m1 of the closure) emits it
};

enum class Preference : uint8_t { closure_first, block_first };

// A patch found valid from a seed, with the preference that grew it.
struct Candidate {
    uint32_t removed, center;
    Preference preference;
};

// Blocks committed together: blocks_[first, end).
struct Patch {
    uint32_t first, end;
};

class LevelFinder {
public:
    // `fine`, `refined` and every triangle index in this interface are the caller's; inside,
    // the triangles are numbered for locality (local_order), and wherever the caller's order
    // decides (the order of seeds, ties between candidates, the coarser level's order) it is
    // looked up, so the numbering changes no result.
    // `give_up_retraced`: see undo_refinement_level.
    // `cancel` (if given): once set, commit stops early (its answer is not wanted).
    LevelFinder(const std::vector<Triangle>& fine, const std::vector<uint8_t>& refined, uint32_t vertex_count,
                const std::vector<uint8_t>* kept, bool give_up_retraced = false, const std::atomic<bool>* cancel = nullptr)
        : give_up_retraced_(give_up_retraced), cancel_(cancel), caller_of_(local_order(fine, vertex_count)), local_of_(inverse(caller_of_)), tri_(permuted(fine, caller_of_)),
          refined_(permuted(refined, caller_of_)), adjacency_(tri_, vertex_count), forced_old_(vertex_count, 0),
          midpoint_count_(vertex_count, 0), corner_count_(vertex_count, 0),
          midpoint_block_(vertex_count, {kNoIndex, kNoIndex}), first_coarse_edge_(vertex_count, kNoEdge), block_of_(fine.size(), kNoIndex), closure_of_(fine.size(), kNoIndex),
          pinned_old_(vertex_count, 0), covered_(fine.size(), 0),
          banned_(fine.size(), 0), repair_banned_(fine.size(), 0), deferred_(fine.size(), 0),
          given_up_(give_up_retraced ? fine.size() : 0, 0), shape_of_(fine.size(), kNotRead), refined_near_(tri_.size(), 0) {
        // A midpoint has its block's three triangles on one side and the boundary, another block
        // (three) or a green closure (two or three triangles around it) on the other.
        for (uint32_t v = 0; v < vertex_count; ++v) {
            const uint32_t s = adjacency_.star_size(v);
            const bool can_be_midpoint = adjacency_.on_boundary(v) ? s == 3 : (s == 5 || s == 6);
            forced_old_[v] = !can_be_midpoint || (kept && (*kept)[v]);
        }
        // A closure's triangles need their neighbours' refinement checked only near refined ones.
        for (uint32_t t = 0; t < tri_.size(); ++t) {
            if (!refined_[t]) continue;
            refined_near_[t] = 1;
            for (uint32_t e = 0; e < 3; ++e) {
                const uint32_t h = adjacency_.twin(3 * t + e);
                if (h != kNoHalfEdge) refined_near_[h / 3] = 1;
            }
        }
        // A large mesh's shapes get room for every triangle up front: the allocator maps so large
        // a block, whose pages never read stay unused, where growing would copy the shapes and
        // hold both copies (the peak memory of a uniform mesh's step). A small one's would sit in
        // the heap, whose reused pages are resident.
        constexpr size_t kShapesReserved = size_t(1) << 18;
        if (tri_.size() >= kShapesReserved) shapes_.reserve(tri_.size());
    }

    // Commits patches best first, in rounds (patches that could not grow while other readings were
    // still possible around them may grow once committed patches hold their labels; later rounds
    // seed only near what the last one committed), then improves them. Returns the patch count.
    // `active` (if given) limits the first seeds to the triangles it marks and two rings around
    // them: elsewhere the mesh is what the previous step left unchanged, with nothing to undo.
    size_t commit(const std::vector<uint8_t>* active);

    // Whether `cancel` was set: commit stopped early, what it left is not the step's answer.
    bool cancelled() const { return cancel_ != nullptr && cancel_->load(std::memory_order_relaxed); }

    // The vertices patch `id` removes.
    uint32_t removed_by(size_t id) const;

    // Whether triangle t is the center or a corner of a block that could be placed (its shape
    // and stars allow it), whatever its patch.
    bool could_be_in_block(uint32_t t);

    // Undoes the committed patch `id` (no other patch depends on it: patches are closed).
    void release_patch(size_t id);

    // The triangles of the coarser mesh that patch `id`'s blocks became (see coarser_level).
    std::vector<uint32_t> parents_of(size_t id, const std::vector<uint32_t>& parent_of_block) const;


    // `parent_of_block` (if given) receives, per block, the index of its parent in the result.
    CoarserLevel coarser_level(std::vector<uint32_t>* parent_of_block = nullptr) const;

    // The refined triangles beside the invalid sides of the large growths that failed on a few
    // blocks (in the fans across those sides, or across their edges), in the caller's order: the
    // parents of earlier steps' blocks that stood in the way (docs/IMPORT.md, "One-block patches
    // taken back").
    std::vector<Triangle> blockers() const;

private:
    // ---- numbering -----------------------------------------------------------------------------
    // The caller's triangle indices ordered by each triangle's smallest vertex id: base
    // detection numbers the vertices breadth-first, so triangles that a growth reads together
    // share cache lines, where the caller's order (a shuffled input's) would make each read a miss.
    static std::vector<uint32_t> local_order(const std::vector<Triangle>& fine, uint32_t vertex_count);
    static std::vector<uint32_t> inverse(const std::vector<uint32_t>& order);
    template <typename T>
    static std::vector<T> permuted(const std::vector<T>& values, const std::vector<uint32_t>& order) {
        std::vector<T> out;
        out.reserve(order.size());
        for (uint32_t i : order) out.push_back(values[i]);
        return out;
    }
    // Whether candidate a is worse than b: fewer vertices removed, or as many and a center later
    // in the caller's order.
    bool worse(const Candidate& a, const Candidate& b) const {
        return a.removed != b.removed ? a.removed < b.removed : caller_of_[a.center] > caller_of_[b.center];
    }

    // ---- reading the fine mesh ---------------------------------------------------------------
    uint32_t vertex_at(uint32_t half_edge, int offset) const;
    static uint32_t next_half_edge(uint32_t half_edge, int offset);
    bool is_new(uint32_t v) const { return midpoint_count_[v] != 0; }
    bool is_old(uint32_t v) const { return forced_old_[v] || corner_count_[v] != 0 || pinned_old_[v] != 0; }
    bool taken(uint32_t t) const { return block_of_[t] != kNoIndex || closure_of_[t] != kNoIndex; }

    // The block whose center is t, read off the mesh (no labels consulted), or false.
    bool read_block(uint32_t t, Block& b) const;

    // The block centered at t as read_block reads it, with its fans walked, or nullptr when
    // read_block fails or the mesh alone rules the block out (a midpoint whose star cannot be
    // one's, a coarse edge already an edge). The mesh alone decides it, and growths read the same
    // triangles again and again, so it is read once per triangle and kept. The pointer lasts
    // until the next call.
    const Block* possible_block(uint32_t t) const {
        const uint32_t known = shape_of_[t];
        if (known == kNotRead) return read_shape(t);  // out of line: the kept answer is the common case
        return known == kImpossible ? nullptr : &shapes_[known];
    }
    // possible_block's first reading of t, kept.
    const Block* read_shape(uint32_t t) const;

    Fan walk_fan(const Block& b, int i) const;

    // ---- placing blocks ----------------------------------------------------------------------
    // Whether a block read by possible_block fits the labels (its midpoints not old, its
    // apexes not new); that its coarse edges are not coarse edges of other blocks is checked with
    // the sides, once the patch is grown.
    bool fits(const Block& b) const;

    // Whether a midpoint other than m already splits the coarse edge a-b. It would be a neighbour
    // of a and of b (the halves of its edge), so the smaller of their stars is searched.
    bool has_other_midpoint(uint32_t a, uint32_t b, uint32_t m) const;

    // Places the block centered at t if it fits and each of its sides has a shape a block side
    // can have (the boundary, or a fan of two or three triangles).
    bool place_block(uint32_t t);

    void claim(uint32_t index);

    void release(uint32_t index);

    // Removes the blocks from `size` on.
    void roll_back(uint32_t size);

    // ---- two-hanging-node closures -----------------------------------------------------------
    // Turning around the start vertex of a half-edge: the half-edge from the same vertex in the
    // next triangle counterclockwise / clockwise, or kNoHalfEdge at the boundary.
    uint32_t turn_ccw(uint32_t h) const { return adjacency_.twin(next_half_edge(h, 2)); }
    uint32_t turn_cw(uint32_t h) const;
    // The middle of the three triangles met turning from half-edge h (three turns), if the third
    // ends at vertex `last`.
    uint32_t middle_of_three(uint32_t h, bool ccw, uint32_t last) const;

    // Whether the block centered at t could be placed with midpoint v on its edge from -> to.
    bool partner_fits(uint32_t t, uint32_t v, uint32_t from, uint32_t to) const;

    // The fan across side i of block x may be a closure of two hanging nodes: the hanging node m
    // and an inner vertex p of the fan, which then needs a block on its far side with the right
    // coarse edge. Returns the center of such a block when it can be read off the mesh and fits
    // the labels, else kNoIndex. Names as in docs/HIERARCHY.md: closure of (A, B, C), unrefined edge
    // A -> B, hanging nodes m1 on B -> C and m2 on C -> A.
    uint32_t closure_partner(const Block& x, int i, const Fan& fan) const;

    // ---- sides -------------------------------------------------------------------------------
    // The coarse edge that v splits when v is the midpoint of exactly one block, else kNoEdge.
    std::pair<uint32_t, uint32_t> only_coarse_edge(uint32_t v) const {
        return midpoint_count_[v] == 1 ? first_coarse_edge_[v] : kNoEdge;
    }
    std::pair<uint32_t, uint32_t> coarse_edge(uint32_t role) const;

    // What lies across side i of a block, with the labels as they are.
    Side classify(uint32_t index, int i) const;

    bool sides_valid(uint32_t index) const;

    // ---- patches -----------------------------------------------------------------------------
    // Grows the patch of the block centered at t: breadth-first across every midpoint, into the
    // block across it (the middle of a fan of three) or, where the fan may be a closure of two
    // hanging nodes, into the block of the other hanging node, in the order `preference` says.
    // Keeps the patch when every side of every block is valid and returns the vertices it
    // removes; otherwise removes it and returns 0. `explored` (if given) marks every center
    // placed on the way.
    //
    // A large patch that fails on a few blocks is mostly a true reading with a few wrong turns
    // (docs/IMPORT.md, "Bottom-up, measured against the truth"): the blocks that stand where the
    // invalid sides need a block of their own are banned as centers and the patch is grown again
    // from the same seed, at most kRepairs times, so a seed costs at most kRepairs + 1 growths.
    // A growth is given up as soon as it is hopeless, so most wrong readings stop after a few
    // hundred to a few thousand blocks instead of covering the level.
    uint32_t grow_patch(uint32_t t, Preference preference, bool exploring = false);

    // The blocks that stand in the way of the invalid sides of the `invalid` blocks: those holding
    // a triangle of the fan across an invalid side, and those that made a vertex of the block that
    // would fit across it a midpoint; failing those, the invalid blocks themselves (as centers).
    void collect_suspects(const std::vector<uint32_t>& invalid, std::vector<uint32_t>& suspects) const;
    // visit(i, fan) for every side of the blocks `invalid` that classify() finds invalid and whose
    // fan is made of triangles.
    template <class Visit>
    void for_each_invalid_fan(const std::vector<uint32_t>& invalid, Visit visit) const {
        for (uint32_t i : invalid)
            for (int e = 0; e < 3; ++e)
                if (classify(i, e).kind == Side::invalid && blocks_[i].fan[size_t(e)].kind == Fan::triangles)
                    visit(i, blocks_[i].fan[size_t(e)]);
    }

    // Whether a growth from blocks_[start] is sure enough to fail that growing it further is
    // wasted: of its `settled` blocks (the first half of those placed, whose sides the breadth-
    // first front has passed, so they rarely read differently later), too many are invalid, or,
    // exploring, the seed block itself is; or it has more blocks than growth_limit_.
    // docs/IMPORT.md, "Hopeless growths given up".
    bool hopeless(uint32_t start, uint32_t settled, uint32_t settled_invalid, bool exploring) const;

    // Marks the centers of the growth from blocks_[start] as explored under `preference`.
    void mark_explored(uint32_t start, Preference preference, bool exploring);

    // Marks the centers of the growth from blocks_[start] as those of a reading given up under
    // `preference` in this round (give_up_retraced_ only).
    void mark_given_up(uint32_t start, Preference preference);

    uint32_t grow_patch_once(uint32_t t, Preference preference, bool exploring, std::vector<uint32_t>* suspects);

    // The best patch grown from t under either preference (but those of bit mask `failed`, known
    // to fail), or none; the patch is not kept.
    Candidate best_patch(uint32_t t, bool exploring, uint8_t failed = 0);

    // The patch grown from blocks_[start] (placed, removing `removed` vertices) without its seed
    // when the seed is glued onto it: joined to the other blocks only through closures (no
    // shared midpoint), and the others, grown again from the next block with the seed banned,
    // are the same blocks and valid. A wrong seed read into a true patch that way makes it
    // remove more vertices than the true patch, so best-first would commit it (docs/IMPORT.md,
    // "Glued seeds left out"). Returns the seed and vertices removed of the patch left placed.
    std::pair<uint32_t, uint32_t> without_glued_seed(uint32_t start, Preference preference, uint32_t removed);

    // Grows a patch from every seed not reached by an earlier one, then commits them best first;
    // a patch that earlier commits changed goes back into the queue with its new count.
    uint32_t commit_best_first(const std::vector<uint32_t>& seeds);

    // Seeds every free triangle of `region` (where this step sought patches) once more, for
    // patches of at most kSmallPatch blocks: a growth that failed marks the centers it passed as
    // explored, so a small true patch that a wrong reading reached (and failed with) may never
    // have seeded itself. docs/IMPORT.md, "Small patches sought again". The seeds whose block
    // reads most like the inside of a level go first, so that they, not wrong readings seeded
    // before them, mark the centers they pass explored ("Sweep seeds ordered").
    void commit_small_patches(const std::vector<uint32_t>& region);

    // 0 when no block can be centered at t (possible_block), else 1 + the sides of that block
    // whose fan is the boundary or three triangles around the center of another possible block.
    uint32_t readable_sides(uint32_t t) const;

    // The triangles within two edge-rings of the blocks of patches [first, end) that no block or
    // closure has taken.
    std::vector<uint32_t> free_triangles_near(size_t first);

    // The triangles within `rings` edge-rings of `ring` that no block or closure has taken.
    std::vector<uint32_t> free_near(std::vector<uint32_t> ring, int rings) const;

    // A committed patch holds its closures: their triangles are taken and their vertices stay old,
    // so that later patches cannot change how its sides read.
    void hold(uint32_t id, bool on);

    // Takes each patch of at most 64 blocks out and solves its neighbourhood again without its
    // centers, with growths bounded (a rival is local); keeps the alternative when it removes
    // more vertices (two true isolated blocks beat one wrong pair glued at an old vertex).
    void improve_patches(size_t first);

    const bool give_up_retraced_;
    const std::atomic<bool>* const cancel_;
    std::vector<uint32_t> caller_of_;  // per triangle: its index in the caller's numbering
    std::vector<uint32_t> local_of_;   // per caller's index: the triangle
    std::vector<Triangle> tri_;
    std::vector<uint8_t> refined_;
    TriangleAdjacency adjacency_;
    std::vector<uint8_t> forced_old_;      // per vertex: its star rules out being a midpoint
    std::vector<uint8_t> midpoint_count_;  // per vertex: blocks it is a midpoint of (0-2)
    std::vector<uint32_t> corner_count_;   // per vertex: blocks it is a parent vertex of
    std::vector<std::array<uint32_t, 2>> midpoint_block_;  // block * 3 + edge, per midpoint role
    // Per vertex: coarse_edge(midpoint_block_[v][0]), or kNoEdge when v is no midpoint (one load
    // tells has_other_midpoint, which scans every neighbour of a vertex, and classify both).
    static constexpr std::pair<uint32_t, uint32_t> kNoEdge{kNoIndex, kNoIndex};
    std::vector<std::pair<uint32_t, uint32_t>> first_coarse_edge_;
    std::vector<uint32_t> block_of_;       // per triangle
    std::vector<uint32_t> closure_of_;     // per triangle: block * 3 + side of a committed closure
    std::vector<uint32_t> pinned_old_;     // per vertex: closures of committed patches it is a corner of
    std::vector<uint8_t> covered_;         // per triangle: bit p, a center of a patch grown with preference p
    std::vector<uint8_t> banned_;          // per triangle: not a center (while a patch is improved)
    std::vector<uint8_t> repair_banned_;   // per triangle: not a center (while a patch is grown again)
    std::vector<uint8_t> deferred_;        // per triangle: center of a valid patch left for later
    // Per triangle (give_up_retraced_ only): bit p, a center of an exploring growth under
    // preference p given up in this commit_best_first, on its full sample or as retracing one;
    // given_up_list_ lists them, to clear them.
    std::vector<uint8_t> given_up_;
    std::vector<uint32_t> given_up_list_;
    static constexpr uint32_t kNotRead = kNoIndex, kImpossible = kNoIndex - 1;
    mutable std::vector<uint32_t> shape_of_;  // per triangle: kNotRead, kImpossible or its index in shapes_
    mutable std::vector<Block> shapes_;       // the blocks possible_block has read
    std::vector<uint8_t> refined_near_;       // per triangle: it or a neighbour across an edge is refined
    std::vector<Block> blocks_;
    std::vector<Patch> patches_;
    uint32_t growth_limit_ = kNoIndex;      // blocks: a growth larger than this is given up
    std::vector<uint32_t> blockers_;        // see blockers()
    // While best_patch grows closure first: whether a side met could take the block across as well
    // as the closure partner (block first would grow otherwise), and the centers explored.
    bool preference_mattered_ = true;
    std::vector<uint32_t> explored_;
};

}  // namespace amc::detail::inverse
