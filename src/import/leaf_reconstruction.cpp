// Top-down reconstruction of the forest from the leaf mesh (docs/IMPORT.md, section 1).
#include "import/leaf_reconstruction.h"

#include "common/exact_float.h"
#include "common/no_index.h"
#include "geometry/closest_point.h"
#include "import/nearest_vertex.h"

#include <algorithm>
#include <cmath>
#include <memory>

#include <string>
#include <vector>

namespace amc {

namespace {


class Reconstruction {
public:
    Reconstruction(Hierarchy& h, const std::vector<uint32_t>& leaf_of_base, const TriangleMesh& leaf,
                   const LeafHalfedges& halfedges, MidpointGuide guide, const PositionIndex& positions,
                   const std::string& what, const UndoSteps* steps, const PickReferee* referee)
        : h_(h), leaf_(leaf), he_(halfedges), guide_(guide), positions_(positions), what_(what), referee_(referee) {
        if (steps) choice_ = std::make_unique<UndoStepChoice>(*steps);
        leaf_of_vertex_.assign(h.positions().size(), kNoIndex);
        vertex_of_leaf_.assign(leaf.positions.size(), kNoIndex);
        for (VertexId v = 0; v < leaf_of_base.size(); ++v) assign(v, leaf_of_base[v]);
    }

    std::vector<uint32_t> run() {
        std::vector<NodeId> level;
        for (NodeId r = 0; r < h_.root_count(); ++r) level.push_back(r);
        std::vector<NodeId> refined, next;
        while (!level.empty()) {
            refined.clear();
            reveals_.clear();
            unsplit_edges_.clear();
            for (NodeId n : level) {
                if (classify(n)) refined.push_back(n);
            }
            for (NodeId n : refined) {
                if (!h_.can_split(n)) fail_node(n, "is refined next to a coarser element (2:1 balance violated)");
                h_.split(n);
            }
            // A leaf edge across which the same-level neighbour is refined: the neighbour's
            // vertex on it is not closed on this side.
            for (const UnsplitEdge& u : unsplit_edges_) {
                const NodeId q = h_.neighbor(u.node, u.edge);
                if (q != kNoNode && !h_.is_leaf(q))
                    fail("face " + std::to_string(he_.face(corner(u.node, u.edge), corner(u.node, (u.edge + 1) % 3))) +
                         " has the edge (" + edge_text(u.node, u.edge) +
                         ") whole, but the element across splits it (T-junction)");
            }
            leaf_of_vertex_.resize(h_.positions().size(), kNoIndex);
            for (const Reveal& r : reveals_) {
                const NodeId q = h_.neighbor(r.node, r.edge);
                if (q == kNoNode || h_.is_leaf(q)) explain_misfit(r.node);
                if (q == kNoNode || h_.is_leaf(q))
                    fail(std::string("vertex ") + std::to_string(r.leaf_vertex) +
                         " lies on an edge whose other side is not refined (T-junction)" +
                         (h_.level(r.node) == 0 ? " (wrong base?)" : ""));
                const VertexId m = h_.midpoint(q, h_.neighbor_edge(r.node, r.edge));
                if (leaf_of_vertex_[m] == kNoIndex) {
                    assign(m, r.leaf_vertex);
                } else if (leaf_of_vertex_[m] != r.leaf_vertex) {
                    fail("vertices " + std::to_string(leaf_of_vertex_[m]) + " and " + std::to_string(r.leaf_vertex) +
                         " both split the edge (" + edge_text(q, h_.neighbor_edge(r.node, r.edge)) + ")");
                }
            }
            next.clear();
            for (NodeId n : refined) {
                for (int e = 0; e < 3; ++e) {
                    const VertexId m = h_.midpoint(n, e);
                    if (leaf_of_vertex_[m] == kNoIndex) assign(m, find_midpoint(n, e));
                }
                for (int k = 0; k < 4; ++k) next.push_back(h_.child(n, k));
            }
            level.swap(next);
        }
        return leaf_of_vertex_;
    }

private:
    struct UnsplitEdge {
        NodeId node;
        int edge;
    };
    struct Reveal {
        NodeId node;
        int edge;
        uint32_t leaf_vertex;
    };

    [[noreturn]] void fail(const std::string& message) const { throw Error(what_ + ": " + message); }

    uint32_t corner(NodeId n, int i) const { return leaf_of_vertex_[h_.vertex(n, i)]; }

    std::string edge_text(NodeId n, int e) const {
        return std::to_string(corner(n, e)) + "," + std::to_string(corner(n, (e + 1) % 3));
    }

    [[noreturn]] void fail_node(NodeId n, const std::string& message) const {
        // A base triangle that does not fit points at the base rather than at the leaf mesh.
        const std::string which = h_.level(n) == 0 ? "the base triangle " + std::to_string(n) + " on vertices ("
                                                   : "the element on vertices (";
        fail(which + std::to_string(corner(n, 0)) + ", " + std::to_string(corner(n, 1)) + ", " +
             std::to_string(corner(n, 2)) + ") " + message + (h_.level(n) == 0 ? " (wrong base?)" : ""));
    }

    void assign(VertexId v, uint32_t l) {
        if (l == kNoIndex) fail("internal: no leaf vertex for hierarchy vertex " + std::to_string(v));
        if (vertex_of_leaf_[l] != kNoIndex)
            fail("vertex " + std::to_string(l) + " would be used twice by the refinement (not a red-green refinement)");
        leaf_of_vertex_[v] = l;
        vertex_of_leaf_[l] = v;
    }

    // Decides whether node n (all corners known) is refined. A leaf keeps at least one edge
    // unsplit (closure), and that edge is then a leaf edge with n on its left; a refined node has
    // none. For a leaf, checks its red or green triangles and notes the hanging nodes, which are
    // the midpoints of the refined neighbours' edges.
    bool classify(NodeId n) {
        const uint32_t p[3] = {corner(n, 0), corner(n, 1), corner(n, 2)};
        bool unsplit[3];
        int count = 0;
        for (int e = 0; e < 3; ++e) {
            unsplit[e] = he_.face(p[e], p[(e + 1) % 3]) != kNoIndex;
            count += unsplit[e];
        }
        if (count == 0) {
            // A refined element has no leaf edge between its corners, in either direction.
            for (int e = 0; e < 3; ++e) {
                const uint32_t across = he_.face(p[(e + 1) % 3], p[e]);
                if (across != kNoIndex)
                    fail("edge (" + edge_text(n, e) + ") of face " + std::to_string(across) +
                         " has nothing on its other side, where the element (" + std::to_string(p[0]) + ", " +
                         std::to_string(p[1]) + ", " + std::to_string(p[2]) +
                         ") is split: a missing face, or a T-junction in face " + std::to_string(across) +
                         (h_.level(n) == 0 ? " (wrong base?)" : ""));
            }
            return true;
        }
        for (int e = 0; e < 3; ++e) {
            if (unsplit[e]) unsplit_edges_.push_back({n, e});
        }
        if (count == 3) {
            if (he_.apex(p[0], p[1]) != p[2]) fail_node(n, "is not a face of the leaf mesh, nor split by it");
        } else if (count == 2) {
            const int e = !unsplit[0] ? 0 : !unsplit[1] ? 1 : 2;  // the split edge
            const uint32_t m = he_.apex(p[(e + 1) % 3], p[(e + 2) % 3]);
            const uint32_t m_other = he_.apex(p[(e + 2) % 3], p[e]);
            if (m == kNoIndex || m_other != m) {
                explain_misfit(n);
                if (m != kNoIndex && m_other != kNoIndex)
                    fail("the edge (" + edge_text(n, e) + ") of the element (" + std::to_string(p[0]) + ", " +
                         std::to_string(p[1]) + ", " + std::to_string(p[2]) + ") carries more than one vertex (" +
                         std::to_string(m_other) + ", " + std::to_string(m) +
                         "): the elements across are more than one level finer (2:1 balance violated)");
                fail_node(n, "has one split edge but no bisection (" + edge_text(n, (e + 1) % 3) + ")");
            }
            reveals_.push_back({n, e, m});
        } else {
            const int u = unsplit[0] ? 0 : unsplit[1] ? 1 : 2;  // the unsplit edge
            const uint32_t a = p[u], b = p[(u + 1) % 3], c = p[(u + 2) % 3];
            const uint32_t w = he_.apex(a, b);
            // Default diagonal m_{u+1}--v_u: (a, b, m1), (a, m1, m2), (m2, m1, c).
            const uint32_t x = he_.apex(a, w);
            const bool as_default = x != kNoIndex && he_.apex(x, w) == c;
            // Flipped diagonal m_{u+2}--v_{u+1}: (a, b, m2), (b, m1, m2), (m2, m1, c).
            const uint32_t y = he_.apex(w, b);
            const bool as_flipped = !as_default && y != kNoIndex && he_.apex(w, y) == c;
            if (as_default) {
                reveals_.push_back({n, (u + 1) % 3, w});
                reveals_.push_back({n, (u + 2) % 3, x});
            } else if (as_flipped) {
                reveals_.push_back({n, (u + 1) % 3, y});
                reveals_.push_back({n, (u + 2) % 3, w});
                h_.set_diagonal_flipped(n, true);
            } else {
                explain_misfit(n);
                fail_node(n, "has two split edges but no green closure on edge (" + edge_text(n, u) + ")");
            }
        }
        return false;
    }

    // A child whose faces do not fit often means that its parent, split on all three edges, was
    // closed by green triangles instead of being split red (closure): a leaf edge then joins a
    // midpoint of the parent to the opposite corner, as bisections and diagonals do.
    void explain_misfit(NodeId n) const {
        const NodeId parent = h_.parent(n);
        if (parent == kNoNode) return;
        for (int k = 0; k < 3; ++k) {
            const uint32_t m = leaf_of_vertex_[h_.midpoint(parent, k)];
            const uint32_t opposite = corner(parent, (k + 2) % 3);
            if (m == kNoIndex) continue;
            uint32_t face = he_.face(m, opposite);
            if (face == kNoIndex) face = he_.face(opposite, m);
            if (face != kNoIndex)
                fail_node(parent, "is split on all three edges but closed by green triangles (face " +
                                      std::to_string(face) + "); three hanging nodes call for the red split");
        }
    }

    // The leaf vertex that splits edge e of refined node n, which no green neighbour revealed.
    uint32_t find_midpoint(NodeId n, int e) {
        const uint32_t a = corner(n, e), b = corner(n, (e + 1) % 3);
        if (guide_ == MidpointGuide::exact) {
            Vec3 m = rounded_scaled(0.5, leaf_.positions[a] + leaf_.positions[b]);  // as the placer computes it
            if (leaf_.single_precision) m = rounded_to_float(m);
            const uint32_t found = positions_.find(m);
            if (found == kNoIndex) fail("no vertex at the midpoint of edge (" + edge_text(n, e) + ")");
            return found;
        }
        // From the connectivity alone where it tells: the halves of the edge are leaf edges.
        const uint32_t common = only_unmatched_common_neighbor(a, b);
        if (common != kNoIndex) return common;
        if (!nearest_) nearest_ = std::make_unique<NearestVertex>(leaf_.positions);
        // The midpoint's leaf neighbours lie in the children of n and of the element across that
        // touch it: of the vertices matched so far, only a, b and those elements' midpoints.
        uint32_t allowed[8] = {a, b, kNoIndex, kNoIndex, kNoIndex, kNoIndex, kNoIndex, kNoIndex};
        const NodeId q = h_.neighbor(n, e);
        for (int k = 0; k < 3; ++k) {
            allowed[2 + k] = leaf_of_vertex_[h_.midpoint(n, k)];
            if (q != kNoNode && !h_.is_leaf(q)) allowed[5 + k] = leaf_of_vertex_[h_.midpoint(q, k)];
        }
        auto may_be_midpoint = [&](uint32_t v) {
            if (vertex_of_leaf_[v] != kNoIndex) return false;
            bool fits = true;
            for_each_neighbor(v, [&](uint32_t w) {
                if (vertex_of_leaf_[w] == kNoIndex) return;
                bool listed = false;
                for (uint32_t x : allowed) listed |= x == w;
                fits &= listed;
            });
            return fits;
        };
        uint32_t found;
        uint32_t nearest[kCandidates];
        uint32_t count = 0;
        if (choice_) {
            count = nearest_->find_nearest(guide_position(n, e), may_be_midpoint, kCandidates, nearest);
            found = choice_->choose(nearest, count, a, b, vertex_of_leaf_);
        } else {
            found = nearest_->find(guide_position(n, e), may_be_midpoint);
            nearest[0] = found;
            count = found != kNoIndex;
        }
        if (referee_ && found != kNoIndex) found = (*referee_)(GuidedPick{h_.level(n), a, b, found, nearest, count});
        if (found == kNoIndex) fail("no vertex left to split the edge (" + edge_text(n, e) + ")");
        return found;
    }

    // Where the guide expects the vertex that splits edge e of n: where midpoint subdivision of
    // the base puts it (the hierarchy's default placer has computed it), or the midpoint of the
    // edge as the leaf mesh places its ends (which follows projected and moved ends; the surface
    // guide then projects it onto the mesh).
    Vec3 guide_position(NodeId n, int e) {
        const uint32_t a = corner(n, e), b = corner(n, (e + 1) % 3);
        Vec3 m = guide_ == MidpointGuide::subdivision ? h_.position(h_.midpoint(n, e))
                                                     : 0.5 * (leaf_.positions[a] + leaf_.positions[b]);
        if (guide_ == MidpointGuide::surface) {
            if (!surface_) surface_ = std::make_unique<ClosestPointQuery>(leaf_);
            m = surface_->closest(m).point;
        }
        return m;
    }

    // Calls f on every leaf-mesh neighbour of u (some twice).
    template <class F>
    void for_each_neighbor(uint32_t u, F f) const {
        for (uint32_t i = 0, d = he_.degree(u); i < d; ++i) {
            f(he_.out_vertex(u, i));
            f(he_.out_apex(u, i));
        }
    }

    // When the children along an edge (a, b) keep their halves unsplit, its midpoint is a common
    // neighbour of a and b, and the only unmatched one: inside the two elements on the edge, a's
    // leaf edges stay in the corner child at a and b's in the corner child at b, which meet only
    // at the midpoint. kNoIndex unless exactly one exists (the final check guards the rest).
    uint32_t only_unmatched_common_neighbor(uint32_t a, uint32_t b) {
        // b's unmatched neighbours listed once, so a's are tested without reading their own
        // edge lists (a cache miss each in a shuffled mesh).
        around_b_.clear();
        for_each_neighbor(b, [&](uint32_t x) {
            if (vertex_of_leaf_[x] == kNoIndex) around_b_.push_back(x);
        });
        uint32_t found = kNoIndex;
        bool ambiguous = false;
        for_each_neighbor(a, [&](uint32_t x) {
            if (x == found || std::find(around_b_.begin(), around_b_.end(), x) == around_b_.end()) return;
            if (found != kNoIndex) ambiguous = true;
            found = x;
        });
        return ambiguous ? kNoIndex : found;
    }

    Hierarchy& h_;
    const TriangleMesh& leaf_;
    const LeafHalfedges& he_;
    const MidpointGuide guide_;
    const PositionIndex& positions_;
    const std::string& what_;
    const PickReferee* referee_;
    // The true vertex is among the four nearest for most wrong nearest picks (docs/IMPORT.md);
    // more candidates let farther ones, outside the two elements on the edge, win.
    static constexpr uint32_t kCandidates = 4;
    std::vector<uint32_t> leaf_of_vertex_;
    std::vector<uint32_t> vertex_of_leaf_;
    std::vector<Reveal> reveals_;
    std::vector<uint32_t> around_b_;  // scratch of only_unmatched_common_neighbor
    std::vector<UnsplitEdge> unsplit_edges_;
    std::unique_ptr<NearestVertex> nearest_;
    std::unique_ptr<ClosestPointQuery> surface_;
    std::unique_ptr<UndoStepChoice> choice_;
};

}  // namespace

std::vector<uint32_t> reconstruct_hierarchy(Hierarchy& h, const std::vector<uint32_t>& leaf_of_base,
                                            const TriangleMesh& leaf, const LeafHalfedges& halfedges,
                                            MidpointGuide guide, const PositionIndex& positions,
                                            const std::string& what, const UndoSteps* steps,
                                            const PickReferee* referee) {
    return Reconstruction(h, leaf_of_base, leaf, halfedges, guide, positions, what, steps, referee).run();
}

}  // namespace amc
