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
#include "import/inverse_refinement.h"

#include "common/no_index.h"
#include "import/triangle_adjacency.h"

#include <algorithm>
#include <array>
#include <utility>

namespace amc::detail {
namespace {


struct Block {
    uint32_t center;
    std::array<uint32_t, 3> corner;       // corner k holds parent vertex v_k
    std::array<uint32_t, 3> v, m;         // parent vertices, midpoints (m_i on v_i -> v_{i+1})
    std::array<uint32_t, 3> first_half;   // half-edge v_i -> m_i (in corner i)
    std::array<uint32_t, 3> second_half;  // half-edge m_i -> v_{i+1} (in corner i+1)
    bool alive;
    uint32_t patch;  // the committed patch it belongs to, or kNoIndex while growing
};

// The triangles around midpoint m_i outside its block, walked from v_{i+1} to v_i.
struct Fan {
    enum Kind : uint8_t { invalid, boundary, triangles } kind = invalid;
    int size = 0;            // 2 or 3 triangles
    uint32_t triangle[3] = {};
    uint32_t entry[3] = {};  // the half-edge by which the walk entered each (x -> m)
    uint32_t inner[2] = {};  // the vertices between consecutive fan triangles
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
    bool operator<(const Candidate& o) const { return removed != o.removed ? removed < o.removed : center > o.center; }
};

// Blocks committed together: blocks_[first, end).
struct Patch {
    uint32_t first, end;
};

class LevelFinder {
public:
    LevelFinder(const std::vector<Triangle>& fine, const std::vector<uint8_t>& refined, uint32_t vertex_count,
                const std::vector<uint8_t>* kept)
        : tri_(fine), refined_(refined), adjacency_(fine, vertex_count), forced_old_(vertex_count, 0),
          midpoint_count_(vertex_count, 0), corner_count_(vertex_count, 0),
          midpoint_block_(vertex_count, {kNoIndex, kNoIndex}), block_of_(fine.size(), kNoIndex), closure_of_(fine.size(), kNoIndex),
          pinned_old_(vertex_count, 0), covered_(fine.size(), 0),
          banned_(fine.size(), 0), repair_banned_(fine.size(), 0), deferred_(fine.size(), 0) {
        // A midpoint has its block's three triangles on one side and the boundary, another block
        // (three) or a green closure (two or three triangles around it) on the other.
        for (uint32_t v = 0; v < vertex_count; ++v) {
            const uint32_t s = adjacency_.star_size(v);
            const bool can_be_midpoint = adjacency_.on_boundary(v) ? s == 3 : (s == 5 || s == 6);
            forced_old_[v] = !can_be_midpoint || (kept && (*kept)[v]);
        }
    }

    // Commits patches best first, in rounds (patches that could not grow while other readings were
    // still possible around them may grow once committed patches hold their labels; later rounds
    // seed only near what the last one committed), then improves them. Returns the patch count.
    // `active` (if given) limits the first seeds to the triangles it marks and two rings around
    // them: elsewhere the mesh is what the previous step left unchanged, with nothing to undo.
    size_t commit(const std::vector<uint8_t>* active) {
        const size_t first = patches_.size();
        std::vector<uint32_t> seeds;
        for (uint32_t t = 0; t < tri_.size(); ++t) {
            if (!active || (*active)[t]) seeds.push_back(t);
        }
        if (active) seeds = free_near(std::move(seeds), 2);
        for (int round = 0; round < 4 && !seeds.empty(); ++round) {
            const size_t before = patches_.size();
            if (commit_best_first(seeds) == 0) break;
            // The next round seeds only near what this one committed.
            seeds = free_triangles_near(before);
        }
        improve_patches(first);
        return patches_.size();
    }

    // The vertices patch `id` removes.
    uint32_t removed_by(size_t id) const {
        uint32_t removed = 0;
        const Patch& patch = patches_[id];
        for (uint32_t i = patch.first; i < patch.end; ++i) {
            if (!blocks_[i].alive) continue;
            for (uint32_t m : blocks_[i].m) removed += midpoint_block_[m][0] / 3 == i || midpoint_block_[m][0] / 3 < patch.first;
        }
        return removed;
    }

    // Whether triangle t is the center or a corner of a block that could be placed (its shape
    // and stars allow it), whatever its patch.
    bool could_be_in_block(uint32_t t) {
        uint32_t centers[4] = {t, kNoIndex, kNoIndex, kNoIndex};
        for (int e = 0; e < 3; ++e) {
            const uint32_t h = adjacency_.twin(3 * t + uint32_t(e));
            if (h != kNoHalfEdge) centers[e + 1] = h / 3;
        }
        for (uint32_t c : centers) {
            if (c == kNoIndex) continue;
            const uint32_t start = uint32_t(blocks_.size());
            if (!place_block(c)) continue;
            roll_back(start);
            return true;
        }
        return false;
    }

    // Undoes the committed patch `id` (no other patch depends on it: patches are closed).
    void release_patch(size_t id) {
        hold(uint32_t(id), false);
        for (uint32_t i = patches_[id].first; i < patches_[id].end; ++i) {
            if (blocks_[i].alive) deferred_[blocks_[i].center] = 1;
        }
        for (uint32_t i = patches_[id].first; i < patches_[id].end; ++i) {
            if (blocks_[i].alive) release(i);
        }
    }

    // The triangles of the coarser mesh that patch `id`'s blocks became (see coarser_level).
    std::vector<uint32_t> parents_of(size_t id, const std::vector<uint32_t>& parent_of_block) const {
        std::vector<uint32_t> parents;
        for (uint32_t i = patches_[id].first; i < patches_[id].end; ++i) {
            if (blocks_[i].alive) parents.push_back(parent_of_block[i]);
        }
        return parents;
    }


    // `parent_of_block` (if given) receives, per block, the index of its parent in the result.
    CoarserLevel coarser_level(std::vector<uint32_t>* parent_of_block = nullptr) const {
        CoarserLevel out;
        if (parent_of_block) parent_of_block->assign(blocks_.size(), kNoIndex);
        std::vector<uint8_t> merged(tri_.size(), 0);
        for (uint32_t index = 0; index < blocks_.size(); ++index) {
            const Block& b = blocks_[index];
            if (!b.alive) continue;
            ++out.red_blocks;
            if (parent_of_block) (*parent_of_block)[index] = uint32_t(out.triangles.size());
            out.triangles.push_back({b.v[0], b.v[1], b.v[2]});
            out.splits.push_back({b.v[0], b.v[1], b.v[2], b.m[0], b.m[1], b.m[2]});
            out.refined.push_back(1);
            out.changed.push_back(1);
            merged[b.center] = 1;
            for (int k = 0; k < 3; ++k) merged[b.corner[size_t(k)]] = 1;
            for (int i = 0; i < 3; ++i) {
                const Side side = classify(index, i);
                if (side.kind == Side::green && side.emits) {
                    ++out.green_groups;
                    out.triangles.push_back(side.coarse);
                    out.refined.push_back(0);
                    out.changed.push_back(1);
                    for (int k = 0; k < side.count; ++k) merged[side.group[k]] = 1;
                }
            }
        }
        if (out.red_blocks == 0) return CoarserLevel{};
        for (uint32_t t = 0; t < tri_.size(); ++t) {
            if (merged[t]) continue;
            out.triangles.push_back(tri_[t]);
            out.refined.push_back(refined_[t]);
            out.changed.push_back(deferred_[t]);
        }
        for (uint32_t v = 0; v < midpoint_count_.size(); ++v) out.removed_vertices += midpoint_count_[v] != 0;
        return out;
    }

private:
    // ---- reading the fine mesh ---------------------------------------------------------------
    uint32_t vertex_at(uint32_t half_edge, int offset) const {
        return tri_[half_edge / 3][(half_edge % 3 + uint32_t(offset)) % 3];
    }
    static uint32_t next_half_edge(uint32_t half_edge, int offset) {
        return half_edge / 3 * 3 + (half_edge % 3 + uint32_t(offset)) % 3;
    }
    bool is_new(uint32_t v) const { return midpoint_count_[v] != 0; }
    bool is_old(uint32_t v) const { return forced_old_[v] || corner_count_[v] != 0 || pinned_old_[v] != 0; }
    bool taken(uint32_t t) const { return block_of_[t] != kNoIndex || closure_of_[t] != kNoIndex; }

    // The block whose center is t, read off the mesh (no labels consulted), or false.
    bool read_block(uint32_t t, Block& b) const {
        b.center = t;
        b.alive = false;
        b.patch = kNoIndex;
        for (int k = 0; k < 3; ++k) {
            // Corner k shares center edge (k+1)%3; its half-edge there runs m_k -> m_{k+2}.
            const uint32_t h = adjacency_.twin(3 * t + uint32_t(k + 1) % 3);
            if (h == kNoHalfEdge) return false;
            b.corner[size_t(k)] = h / 3;
            b.m[size_t(k)] = vertex_at(h, 0);
            b.v[size_t(k)] = vertex_at(h, 2);
            b.first_half[size_t(k)] = next_half_edge(h, 2);
            b.second_half[size_t(k + 2) % 3] = next_half_edge(h, 1);
        }
        for (int i = 0; i < 3; ++i) {
            for (int j = 0; j < 3; ++j) {
                if (b.v[size_t(i)] == b.m[size_t(j)]) return false;
                if (i < j && (b.v[size_t(i)] == b.v[size_t(j)] || b.corner[size_t(i)] == b.corner[size_t(j)])) return false;
            }
            if (b.corner[size_t(i)] == t) return false;
        }
        return true;
    }

    Fan walk_fan(const Block& b, int i) const {
        Fan fan;
        const uint32_t a = b.v[size_t(i)], m = b.m[size_t(i)];
        const uint32_t back = adjacency_.twin(b.first_half[size_t(i)]);
        uint32_t h = adjacency_.twin(b.second_half[size_t(i)]);  // v_{i+1} -> m
        if (h == kNoHalfEdge || back == kNoHalfEdge) {
            if (h == back && adjacency_.star_size(m) == 3) fan.kind = Fan::boundary;
            return fan;
        }
        for (int k = 0; k < 3; ++k) {
            const uint32_t t = h / 3;
            if (t == b.center || t == b.corner[0] || t == b.corner[1] || t == b.corner[2]) return fan;
            fan.triangle[k] = t;
            fan.entry[k] = h;
            const uint32_t p = vertex_at(h, 2);
            if (p == a) {
                fan.size = k + 1;
                if (fan.size >= 2 && adjacency_.star_size(m) == uint32_t(3 + fan.size)) fan.kind = Fan::triangles;
                return fan;
            }
            if (k == 2) return fan;
            fan.inner[k] = p;
            h = adjacency_.twin(next_half_edge(h, 1));
            if (h == kNoHalfEdge) return fan;
        }
        return fan;
    }

    // ---- placing blocks ----------------------------------------------------------------------
    // Whether the block centered at t fits the labels (its midpoints not old, its apexes not
    // new) and the mesh (its coarse edges are not edges already; that they are not coarse edges
    // of other blocks is checked with the sides, once the patch is grown).
    bool fits(const Block& b) const {
        if (taken(b.center) || banned_[b.center] || repair_banned_[b.center]) return false;
        for (int k = 0; k < 3; ++k) {
            if (taken(b.corner[size_t(k)])) return false;
            const uint32_t m = b.m[size_t(k)];
            if (is_old(m) || is_new(b.v[size_t(k)]) || midpoint_count_[m] > 1) return false;
        }
        for (int i = 0; i < 3; ++i) {
            const uint32_t a = b.v[size_t(i)], c = b.v[size_t(i + 1) % 3];
            if (adjacency_.has_edge(a, c)) return false;
        }
        return true;
    }

    // Whether a midpoint other than m already splits the coarse edge a-b. It would be a neighbour
    // of a (the first half of its edge), so a's star is searched.
    bool has_other_midpoint(uint32_t a, uint32_t b, uint32_t m) const {
        for (const uint32_t* h = adjacency_.outgoing_begin(a); h != adjacency_.outgoing_end(a); ++h) {
            for (uint32_t w : {vertex_at(*h, 1), vertex_at(*h, 2)}) {
                if (w == m || midpoint_count_[w] == 0) continue;
                const auto [s, t] = coarse_edge(midpoint_block_[w][0]);
                if ((s == a && t == b) || (s == b && t == a)) return true;
            }
        }
        return false;
    }

    // Places the block centered at t if it fits and each of its sides has a shape a block side
    // can have (the boundary, or a fan of two or three triangles).
    bool place_block(uint32_t t) {
        Block b;
        if (!read_block(t, b) || !fits(b)) return false;
        const uint32_t index = uint32_t(blocks_.size());
        blocks_.push_back(b);
        claim(index);
        for (int i = 0; i < 3; ++i) {
            const Fan fan = walk_fan(blocks_[index], i);
            // Neither a block nor a two-hanging-node closure fits two old vertices there.
            if (fan.kind == Fan::invalid ||
                (fan.size == 3 && is_old(fan.inner[0]) && is_old(fan.inner[1]))) {
                release(index);
                blocks_.pop_back();
                return false;
            }
        }
        return true;
    }

    void claim(uint32_t index) {
        Block& b = blocks_[index];
        b.alive = true;
        block_of_[b.center] = index;
        for (int k = 0; k < 3; ++k) {
            block_of_[b.corner[size_t(k)]] = index;
            const uint32_t m = b.m[size_t(k)];
            midpoint_block_[m][midpoint_count_[m]++] = index * 3 + uint32_t(k);
            ++corner_count_[b.v[size_t(k)]];
        }
    }

    void release(uint32_t index) {
        Block& b = blocks_[index];
        b.alive = false;
        block_of_[b.center] = kNoIndex;
        for (int k = 0; k < 3; ++k) {
            block_of_[b.corner[size_t(k)]] = kNoIndex;
            const uint32_t m = b.m[size_t(k)];
            auto& slots = midpoint_block_[m];
            if (slots[0] / 3 == index) slots[0] = slots[1];
            slots[1] = kNoIndex;
            --midpoint_count_[m];
            --corner_count_[b.v[size_t(k)]];
        }
    }

    // Removes the blocks from `size` on.
    void roll_back(uint32_t size) {
        while (blocks_.size() > size) {
            if (blocks_.back().alive) release(uint32_t(blocks_.size() - 1));
            blocks_.pop_back();
        }
    }

    // ---- two-hanging-node closures -----------------------------------------------------------
    // Turning around the start vertex of a half-edge: the half-edge from the same vertex in the
    // next triangle counterclockwise / clockwise, or kNoHalfEdge at the boundary.
    uint32_t turn_ccw(uint32_t h) const { return adjacency_.twin(next_half_edge(h, 2)); }
    uint32_t turn_cw(uint32_t h) const {
        const uint32_t t = adjacency_.twin(h);
        return t == kNoHalfEdge ? kNoHalfEdge : next_half_edge(t, 1);
    }
    // The middle of the three triangles met turning from half-edge h (three turns), if the third
    // ends at vertex `last`.
    uint32_t middle_of_three(uint32_t h, bool ccw, uint32_t last) const {
        uint32_t around[3];
        for (int k = 0; k < 3; ++k) {
            h = ccw ? turn_ccw(h) : turn_cw(h);
            if (h == kNoHalfEdge) return kNoIndex;
            around[k] = h;
        }
        return vertex_at(around[2], ccw ? 2 : 1) == last ? around[1] / 3 : kNoIndex;
    }

    // Whether the block centered at t could be placed with midpoint v on its edge from -> to.
    bool partner_fits(uint32_t t, uint32_t v, uint32_t from, uint32_t to) const {
        Block z;
        if (!read_block(t, z) || !fits(z)) return false;
        for (int e = 0; e < 3; ++e) {
            if (z.m[size_t(e)] == v) return z.v[size_t(e)] == from && z.v[size_t(e + 1) % 3] == to;
        }
        return false;
    }

    // The fan across side i of block x may be a closure of two hanging nodes: the hanging node m
    // and an inner vertex p of the fan, which then needs a block on its far side with the right
    // coarse edge. Returns the center of such a block when it can be read off the mesh and fits
    // the labels, else kNoIndex. Names as in docs/HIERARCHY.md: closure of (A, B, C), unrefined edge
    // A -> B, hanging nodes m1 on B -> C and m2 on C -> A.
    uint32_t closure_partner(const Block& x, int i, const Fan& fan) const {
        if (fan.kind != Fan::triangles) return kNoIndex;
        const uint32_t a = x.v[size_t(i)], b = x.v[size_t(i + 1) % 3];
        if (fan.size == 3) {
            const uint32_t p1 = fan.inner[0], p2 = fan.inner[1];
            // Default diagonal seen from m1: p1 = A (old), p2 = m2 on edge C=a -> A, whose block
            // has edge A -> C; its triangles around p2 run from a to p1, away from the fan.
            if (!is_new(p1) && !is_new(p2) && !is_old(p2) && adjacency_.star_size(p2) == 5) {
                const uint32_t z = middle_of_three(fan.entry[2], true, p1);
                if (z != kNoIndex && partner_fits(z, p2, p1, a)) return z;
            }
            // Flipped diagonal seen from m2: p1 = m1 on edge B=p2 -> C=b, p2 = B (old), whose
            // block has edge C -> B; its triangles around p1 run from b to p2.
            if (!is_new(p1) && !is_old(p1) && !is_new(p2) && adjacency_.star_size(p1) == 5) {
                const uint32_t z = middle_of_three(next_half_edge(fan.entry[0], 2), false, p2);
                if (z != kNoIndex && partner_fits(z, p1, b, p2)) return z;
            }
            return kNoIndex;
        }
        const uint32_t p = fan.inner[0];
        if (is_new(p) || is_old(p) || adjacency_.star_size(p) != 6) return kNoIndex;
        // Flipped diagonal seen from m1 (B=b, C=a): p = m2 on edge a -> A, the third triangle
        // (A, b, p) lies across edge p -> b of the first fan triangle; p's block has edge A -> a.
        uint32_t h = adjacency_.twin(next_half_edge(fan.entry[0], 2));
        if (h != kNoHalfEdge) {
            const uint32_t apex = vertex_at(h, 2);
            const uint32_t z = middle_of_three(fan.entry[1], true, apex);
            if (z != kNoIndex && partner_fits(z, p, apex, a)) return z;
        }
        // Default diagonal seen from m2 (A=a, C=b): p = m1 on edge B -> b, the third triangle
        // (a, B, p) lies across edge a -> p of the second fan triangle; p's block has edge b -> B.
        h = adjacency_.twin(next_half_edge(fan.entry[1], 2));
        if (h != kNoHalfEdge) {
            const uint32_t apex = vertex_at(h, 2);
            const uint32_t z = middle_of_three(next_half_edge(fan.entry[0], 2), false, apex);
            if (z != kNoIndex && partner_fits(z, p, b, apex)) return z;
        }
        return kNoIndex;
    }

    // ---- sides -------------------------------------------------------------------------------
    // The midpoint role of v: block index * 3 + edge, when v is the midpoint of exactly one block.
    uint32_t only_midpoint_role(uint32_t v) const { return midpoint_count_[v] == 1 ? midpoint_block_[v][0] : kNoIndex; }
    std::pair<uint32_t, uint32_t> coarse_edge(uint32_t role) const {
        const Block& z = blocks_[role / 3];
        const int e = int(role % 3);
        return {z.v[size_t(e)], z.v[size_t(e + 1) % 3]};
    }

    // What lies across side i of a block, with the labels as they are.
    Side classify(uint32_t index, int i) const {
        const Block& b = blocks_[index];
        Side side;
        const Fan fan = walk_fan(b, i);
        if (fan.kind == Fan::boundary) {
            side.kind = Side::boundary;
            return side;
        }
        if (fan.kind != Fan::triangles) return side;
        const uint32_t other = block_of_[fan.triangle[0]];
        if (other != kNoIndex || block_of_[fan.triangle[1]] != kNoIndex || (fan.size == 3 && block_of_[fan.triangle[2]] != kNoIndex)) {
            if (fan.size == 3 && other != index && block_of_[fan.triangle[1]] == other && block_of_[fan.triangle[2]] == other)
                side.kind = Side::red;
            return side;
        }
        for (int k = 0; k < fan.size; ++k) {
            if (closure_of_[fan.triangle[k]] != kNoIndex && closure_of_[fan.triangle[k]] != b.patch) return side;
        }
        const uint32_t a = b.v[size_t(i)], bb = b.v[size_t(i + 1) % 3];
        side.count = fan.size;
        for (int k = 0; k < fan.size; ++k) side.group[k] = fan.triangle[k];
        if (fan.size == 2) {
            const uint32_t p = fan.inner[0];
            if (!is_new(p)) {  // one hanging node: (b, m, p), (m, a, p)
                side.coarse = {bb, a, p};
                side.emits = true;
            } else {
                const uint32_t role = only_midpoint_role(p);
                if (role == kNoIndex) return side;
                const auto [s, t] = coarse_edge(role);
                uint32_t across, apex;
                if (t == a) {
                    // m is m1 of a flipped closure (A, B=b, C=a): the third triangle (A, b, p)
                    // lies across edge p -> b of the first fan triangle.
                    across = adjacency_.twin(next_half_edge(fan.entry[0], 2));
                    apex = s;
                    side.coarse = {s, bb, a};
                    side.emits = true;
                } else if (s == bb) {
                    // m is m2 of a default closure (A=a, B, C=b): the third triangle (a, B, p)
                    // lies across edge a -> p of the second fan triangle.
                    across = adjacency_.twin(next_half_edge(fan.entry[1], 2));
                    apex = t;
                    side.coarse = {a, t, bb};
                } else {
                    return side;
                }
                if (across == kNoHalfEdge || vertex_at(across, 2) != apex || block_of_[across / 3] != kNoIndex ||
                    (closure_of_[across / 3] != kNoIndex && closure_of_[across / 3] != b.patch))
                    return side;
                side.group[2] = across / 3;
                side.count = 3;
            }
        } else {
            const uint32_t p1 = fan.inner[0], p2 = fan.inner[1];
            if (!is_new(p1) && is_new(p2)) {
                // m is m1 of a default closure (A=p1, B=b, C=a); p2 is m2 on edge C -> A.
                const uint32_t role = only_midpoint_role(p2);
                if (role == kNoIndex || coarse_edge(role) != std::make_pair(p1, a)) return side;
                side.coarse = {p1, bb, a};
                side.emits = true;
            } else if (is_new(p1) && !is_new(p2)) {
                // m is m2 of a flipped closure (A=a, B=p2, C=b); p1 is m1 on edge B -> C.
                const uint32_t role = only_midpoint_role(p1);
                if (role == kNoIndex || coarse_edge(role) != std::make_pair(bb, p2)) return side;
                side.coarse = {a, p2, bb};
            } else {
                return side;
            }
        }
        const Triangle& q = side.coarse;
        if (q[0] == q[1] || q[1] == q[2] || q[2] == q[0]) return side;
        // The coarse triangle is a leaf without other hanging nodes, and the block's children
        // beside it have no same-level neighbour there: no refinement inside or around the group.
        for (int k = 0; k < side.count; ++k) {
            const uint32_t g = side.group[k];
            if (refined_[g]) return side;
            for (int e = 0; e < 3; ++e) {
                const uint32_t h = adjacency_.twin(3 * g + uint32_t(e));
                if (h == kNoHalfEdge) continue;
                const uint32_t n = h / 3;
                if (refined_[n] && std::find(side.group, side.group + side.count, n) == side.group + side.count) return side;
            }
        }
        side.kind = Side::green;
        return side;
    }

    bool sides_valid(uint32_t index) const {
        const Block& b = blocks_[index];
        for (int i = 0; i < 3; ++i) {
            if (has_other_midpoint(b.v[size_t(i)], b.v[size_t(i + 1) % 3], b.m[size_t(i)])) return false;
        }
        uint32_t red_neighbor[3];
        for (int i = 0; i < 3; ++i) {
            const Side side = classify(index, i);
            if (side.kind == Side::invalid) return false;
            red_neighbor[i] = side.kind == Side::red ? block_of_[adjacency_.twin(blocks_[index].second_half[size_t(i)]) / 3]
                                                     : kNoIndex - uint32_t(i);
        }
        // Two blocks glued along all three edges would make two coincident coarse triangles.
        return !(red_neighbor[0] == red_neighbor[1] && red_neighbor[1] == red_neighbor[2]);
    }

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
    uint32_t grow_patch(uint32_t t, Preference preference, bool exploring = false) {
        constexpr int kRepairs = 4;
        std::vector<uint32_t> banned, suspects;
        uint32_t removed = 0;
        for (int attempt = 0;; ++attempt) {
            suspects.clear();
            removed = grow_patch_once(t, preference, exploring, attempt < kRepairs ? &suspects : nullptr);
            if (removed != 0 || suspects.empty()) break;
            const size_t before = banned.size();
            for (uint32_t c : suspects) {
                if (!repair_banned_[c]) repair_banned_[c] = 1, banned.push_back(c);
            }
            if (banned.size() == before) break;  // nothing new to take away: the same growth again
        }
        for (uint32_t c : banned) repair_banned_[c] = 0;
        return removed;
    }

    // The blocks of an invalid patch [start, end) that stand in the way of its invalid sides: the
    // blocks holding a triangle of the fan across an invalid side, and those that made a vertex
    // of the block that would fit across it a midpoint; failing those, the invalid blocks.
    void collect_suspects(uint32_t start, std::vector<uint32_t>& suspects) const {
        constexpr size_t kRepairableShare = 16;  // at most one block in 16 invalid
        std::vector<uint32_t> invalid;
        for (uint32_t i = start; i < blocks_.size(); ++i) {
            if (sides_valid(i)) continue;
            invalid.push_back(blocks_[i].center);
            for (int e = 0; e < 3; ++e) {
                if (classify(i, e).kind != Side::invalid) continue;
                const Fan fan = walk_fan(blocks_[i], e);
                if (fan.kind != Fan::triangles) continue;
                for (int k = 0; k < fan.size; ++k) {
                    const uint32_t owner = block_of_[fan.triangle[k]];
                    if (owner != kNoIndex && owner != i) suspects.push_back(blocks_[owner].center);
                }
                Block across;
                if (fan.size != 3 || !read_block(fan.triangle[1], across)) continue;
                for (uint32_t v : across.v) {
                    for (uint8_t k = 0; k < midpoint_count_[v]; ++k) suspects.push_back(blocks_[midpoint_block_[v][k] / 3].center);
                }
            }
        }
        // Many invalid blocks: a wrong reading, not a true one with a few wrong turns.
        if (invalid.size() * kRepairableShare > blocks_.size() - start) {
            suspects.clear();
            return;
        }
        if (suspects.empty()) suspects = std::move(invalid);
    }

    uint32_t grow_patch_once(uint32_t t, Preference preference, bool exploring, std::vector<uint32_t>* suspects) {
        constexpr uint32_t kRepairable = 16;  // blocks: smaller patches are taken or dropped whole
        const uint32_t start = uint32_t(blocks_.size());
        if (!place_block(t)) return 0;
        for (uint32_t next = start; next < blocks_.size(); ++next) {
            for (int i = 0; i < 3; ++i) {
                const Fan fan = walk_fan(blocks_[next], i);
                if (fan.kind != Fan::triangles || block_of_[fan.triangle[1]] != kNoIndex) continue;
                if (preference == Preference::closure_first) {
                    const uint32_t partner = closure_partner(blocks_[next], i, fan);
                    if (partner != kNoIndex && place_block(partner)) continue;
                    if (fan.size == 3) place_block(fan.triangle[1]);
                } else if (fan.size == 3 && !place_block(fan.triangle[1])) {
                    const uint32_t partner = closure_partner(blocks_[next], i, fan);
                    if (partner != kNoIndex) place_block(partner);
                }
            }
        }
        // Growth from any center of this patch would give the same patch under this preference:
        // those centers need not seed again (this keeps the search linear).
        if (exploring) {
            const uint8_t bit = uint8_t(1u << int(preference));
            for (uint32_t i = start; i < blocks_.size(); ++i) covered_[blocks_[i].center] |= bit;
        }
        for (uint32_t i = start; i < blocks_.size(); ++i) {
            if (!sides_valid(i)) {
                if (suspects && blocks_.size() - start >= kRepairable) collect_suspects(start, *suspects);
                roll_back(start);
                return 0;
            }
        }
        // A valid patch: no other reading needs to seed inside it.
        if (exploring) {
            for (uint32_t i = start; i < blocks_.size(); ++i) {
                covered_[blocks_[i].center] = 3;
                for (uint32_t c : blocks_[i].corner) covered_[c] = 3;
            }
        }
        uint32_t removed = 0;
        for (uint32_t i = start; i < blocks_.size(); ++i) {
            for (int e = 0; e < 3; ++e) {
                const auto& slots = midpoint_block_[blocks_[i].m[size_t(e)]];
                removed += slots[0] / 3 == i || (slots[0] / 3 < start && slots[1] / 3 == i);  // count each once
            }
        }
        return removed;
    }

    // The best patch grown from t under either preference, or none; the patch is not kept.
    Candidate best_patch(uint32_t t, bool exploring) {
        Candidate best{0, t, Preference::closure_first};
        for (Preference preference : {Preference::closure_first, Preference::block_first}) {
            if (exploring && (covered_[t] >> int(preference)) & 1) continue;
            const uint32_t start = uint32_t(blocks_.size());
            const uint32_t removed = grow_patch(t, preference, exploring);
            roll_back(start);
            if (removed > best.removed) best = {removed, t, preference};
        }
        return best;
    }

    // Grows a patch from every seed not reached by an earlier one, then commits them best first;
    // a patch that earlier commits changed goes back into the queue with its new count.
    uint32_t commit_best_first(const std::vector<uint32_t>& seeds) {
        std::vector<Candidate> queue;
        for (uint32_t t : seeds) covered_[t] = 0;
        for (uint32_t t : seeds) {
            if (covered_[t] == 3 || block_of_[t] != kNoIndex) continue;
            const Candidate c = best_patch(t, true);
            if (c.removed > 0) queue.push_back(c);
        }
        std::make_heap(queue.begin(), queue.end());
        uint32_t total = 0;
        while (!queue.empty()) {
            std::pop_heap(queue.begin(), queue.end());
            Candidate c = queue.back();
            queue.pop_back();
            const uint32_t start = uint32_t(blocks_.size());
            c.removed = grow_patch(c.center, c.preference);
            if (c.removed > 0 && (queue.empty() || !(c < queue.front()))) {
                patches_.push_back({start, uint32_t(blocks_.size())});
                hold(uint32_t(patches_.size() - 1), true);
                total += c.removed;
                continue;
            }
            roll_back(start);
            if (c.removed == 0) c = best_patch(c.center, false);
            if (c.removed == 0) {
                deferred_[c.center] = 1;  // valid once: worth a seed in the next step
                continue;
            }
            queue.push_back(c);
            std::push_heap(queue.begin(), queue.end());
        }
        return total;
    }

    // The triangles within two edge-rings of the blocks of patches [first, end) that no block or
    // closure has taken.
    std::vector<uint32_t> free_triangles_near(size_t first) {
        std::vector<uint32_t> ring;
        for (size_t id = first; id < patches_.size(); ++id) {
            for (uint32_t i = patches_[id].first; i < patches_[id].end; ++i) {
                if (!blocks_[i].alive) continue;
                ring.push_back(blocks_[i].center);
                for (uint32_t c : blocks_[i].corner) ring.push_back(c);
            }
        }
        return free_near(std::move(ring), 2);
    }

    // The triangles within `rings` edge-rings of `ring` that no block or closure has taken.
    std::vector<uint32_t> free_near(std::vector<uint32_t> ring, int rings) const {
        for (int step = 0; step < rings; ++step) {
            const size_t count = ring.size();
            for (size_t k = 0; k < count; ++k) {
                for (int e = 0; e < 3; ++e) {
                    const uint32_t h = adjacency_.twin(3 * ring[k] + uint32_t(e));
                    if (h != kNoHalfEdge) ring.push_back(h / 3);
                }
            }
            std::sort(ring.begin(), ring.end());
            ring.erase(std::unique(ring.begin(), ring.end()), ring.end());
        }
        ring.erase(std::remove_if(ring.begin(), ring.end(), [&](uint32_t t) { return taken(t); }), ring.end());
        return ring;
    }

    // A committed patch holds its closures: their triangles are taken and their vertices stay old,
    // so that later patches cannot change how its sides read.
    void hold(uint32_t id, bool on) {
        const Patch& patch = patches_[id];
        std::vector<Side> sides;
        // Read with the patch's id on its blocks (the triangles it holds carry that id, so a
        // release reads its closures as such), then set.
        for (uint32_t i = patch.first; i < patch.end; ++i) {
            if (blocks_[i].alive) blocks_[i].patch = id;
        }
        for (uint32_t i = patch.first; i < patch.end; ++i) {
            if (!blocks_[i].alive) continue;
            for (int e = 0; e < 3; ++e) {
                sides.push_back(classify(i, e));
            }
            if (!on) blocks_[i].patch = kNoIndex;
        }
        for (const Side& side : sides) {
            if (side.kind != Side::green) continue;
            for (int k = 0; k < side.count; ++k) closure_of_[side.group[k]] = on ? id : kNoIndex;
            for (uint32_t v : side.coarse) on ? ++pinned_old_[v] : --pinned_old_[v];
        }
    }

    // Takes each patch out and solves its neighbourhood again without its centers; keeps the
    // alternative when it removes more vertices (two true isolated blocks beat one wrong pair
    // glued at an old vertex).
    void improve_patches(size_t first) {
        const size_t count = patches_.size();
        for (size_t r = first; r < count; ++r) {
            const Patch patch = patches_[r];
            uint32_t before = 0;
            std::vector<uint32_t> seeds, taken;
            for (uint32_t i = patch.first; i < patch.end; ++i) {
                const Block& b = blocks_[i];
                if (!b.alive) continue;
                taken.push_back(i);
                for (uint32_t t : {b.center, b.corner[0], b.corner[1], b.corner[2]}) {
                    seeds.push_back(t);
                    for (int e = 0; e < 3; ++e) {
                        const uint32_t h = adjacency_.twin(3 * t + uint32_t(e));
                        if (h != kNoHalfEdge) seeds.push_back(h / 3);
                    }
                }
                for (uint32_t m : b.m) before += midpoint_block_[m][0] / 3 == i || midpoint_block_[m][0] / 3 < patch.first;
            }
            if (taken.empty() || taken.size() > 64) continue;  // large patches have no rival nearby
            std::sort(seeds.begin(), seeds.end());
            seeds.erase(std::unique(seeds.begin(), seeds.end()), seeds.end());
            hold(uint32_t(r), false);
            for (uint32_t i : taken) release(i), banned_[blocks_[i].center] = 1;
            const uint32_t start = uint32_t(blocks_.size());
            const size_t patches_before = patches_.size();
            const uint32_t after = commit_best_first(seeds);
            for (uint32_t i : taken) banned_[blocks_[i].center] = 0;
            if (after > before) continue;
            for (size_t k = patches_.size(); k-- > patches_before;) hold(uint32_t(k), false);
            roll_back(start);
            patches_.resize(patches_before);
            for (uint32_t i : taken) claim(i);
            hold(uint32_t(r), true);
        }
    }

    const std::vector<Triangle>& tri_;
    const std::vector<uint8_t>& refined_;
    TriangleAdjacency adjacency_;
    std::vector<uint8_t> forced_old_;      // per vertex: its star rules out being a midpoint
    std::vector<uint8_t> midpoint_count_;  // per vertex: blocks it is a midpoint of (0-2)
    std::vector<uint32_t> corner_count_;   // per vertex: blocks it is a parent vertex of
    std::vector<std::array<uint32_t, 2>> midpoint_block_;  // block * 3 + edge, per midpoint role
    std::vector<uint32_t> block_of_;       // per triangle
    std::vector<uint32_t> closure_of_;     // per triangle: block * 3 + side of a committed closure
    std::vector<uint32_t> pinned_old_;     // per vertex: closures of committed patches it is a corner of
    std::vector<uint8_t> covered_;         // per triangle: bit p, a center of a patch grown with preference p
    std::vector<uint8_t> banned_;          // per triangle: not a center (while a patch is improved)
    std::vector<uint8_t> repair_banned_;   // per triangle: not a center (while a patch is grown again)
    std::vector<uint8_t> deferred_;        // per triangle: center of a valid patch left for later
    std::vector<Block> blocks_;
    std::vector<Patch> patches_;
};

}  // namespace

CoarserLevel undo_refinement_level(const std::vector<Triangle>& fine, const std::vector<uint8_t>& refined,
                                   uint32_t vertex_count, const std::vector<uint8_t>* active,
                                   const std::vector<uint8_t>* kept) {
    // Large patches first: they are what a level looks like where the mesh is finest. Small
    // ones are also what wrong readings look like where it is not finest yet (the true blocks
    // there become valid only once the finer ones around are undone), so a small patch is kept
    // only when the next level confirms it: one of its parents lies in a valid patch there.
    LevelFinder finder(fine, refined, vertex_count, kept);
    constexpr uint32_t kLarge = 12;  // vertices removed: four blocks or more
    const size_t all = finder.commit(active);
    std::vector<size_t> small;
    for (size_t id = 0; id < all; ++id) {
        if (finder.removed_by(id) < kLarge) small.push_back(id);
    }
    if (small.empty()) return finder.coarser_level();
    std::vector<uint32_t> parent_of_block;
    CoarserLevel trial = finder.coarser_level(&parent_of_block);
    LevelFinder next(trial.triangles, trial.refined, vertex_count, kept);
    std::vector<uint8_t> confirmed(small.size(), 0);
    for (size_t k = 0; k < small.size(); ++k) {
        for (uint32_t parent : finder.parents_of(small[k], parent_of_block)) {
            if (next.could_be_in_block(parent)) {
                confirmed[k] = 1;
                break;
            }
        }
    }
    // Nothing confirmed and nothing large: the small patches are all there is (the top level).
    if (all == small.size() && std::count(confirmed.begin(), confirmed.end(), 1) == 0) return trial;
    for (size_t k = 0; k < small.size(); ++k) {
        if (!confirmed[k]) finder.release_patch(small[k]);
    }
    return finder.coarser_level();
}

}  // namespace amc::detail
