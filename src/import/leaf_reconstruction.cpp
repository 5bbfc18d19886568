// Top-down reconstruction of the forest from the leaf mesh (docs/IMPORT.md, section 1).
#include "import/leaf_reconstruction.h"

#include "common/compiler.h"
#include "common/exact_float.h"
#include "geometry/placement_normal.h"
#include "hierarchy/hierarchy_builder.h"
#include "hierarchy/midpoint_placers.h"
#include "import/reconstruction.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace amc {

LeafSearch::LeafSearch(const TriangleMesh& leaf, const std::vector<uint32_t>* insertion_order,
                       const std::vector<uint32_t>* sorted_codes)
    : leaf_(leaf), insertion_order_(insertion_order), sorted_codes_(sorted_codes) {}
LeafSearch::LeafSearch(LeafSearch& input, const std::vector<uint32_t>& new_id)
    : leaf_(input.leaf_), insertion_order_(nullptr), input_(&input), new_id_(&new_id) {}
LeafSearch::~LeafSearch() = default;

const NearestVertex& LeafSearch::nearest() {
    if (!nearest_) {
        nearest_ = input_ ? std::make_unique<NearestVertex>(input_->nearest(), *new_id_)
                          : std::make_unique<NearestVertex>(leaf_.positions, insertion_order_, sorted_codes_);
    }
    return *nearest_;
}

const ClosestPointQuery& LeafSearch::surface() {
    if (input_) return input_->surface();
    if (!surface_) surface_ = std::make_unique<ClosestPointQuery>(leaf_);
    return *surface_;
}

std::vector<uint32_t> Reconstruction::run() {
    std::vector<NodeId> level, next;
    for (NodeId r = 0; r < h_.root_count(); ++r) level.push_back(r);
    int depth = 0;
    while (!level.empty()) {
        remember(depth, level);
        if (judges_picks() && certify_picks(depth, level)) continue;
        try {
            reconstruct_level(level, next);
        } catch (const SearchBudgetSpent&) {
            throw;
        } catch (const Error& e) {
            if (!judges_picks()) throw;
            if (!backtrack(depth, level, read_failed_, e.what())) throw Error(first_error_);
            continue;
        }
        level_done(depth);
        level.swap(next);
        ++depth;
    }
    return std::move(leaf_of_vertex_);  // run() is the reconstruction's last use (a copy: 4 bytes a vertex)
}

void Reconstruction::reconstruct_level(std::vector<NodeId>& level, std::vector<NodeId>& next) {
    std::vector<NodeId>& refined = refined_;
    read_failed_ = true;
    read_level_or_repair(level, refined);
    read_failed_ = false;
    if (faces_read_) add_level_faces();
    split_refined(refined);
    leaf_of_vertex_.resize(h_.positions().size(), kNoIndex);
    for (const Reveal& r : reveals_) {
        const NodeId q = h_.neighbor(r.node, r.edge);
        const VertexId m = h_.midpoint(q, h_.neighbor_edge(r.node, r.edge));
        failed_node_ = r.node;
        if (leaf_of_vertex_[m] == kNoIndex) {
            assign(m, r.leaf_vertex);
        } else if (leaf_of_vertex_[m] != r.leaf_vertex) {
            fail("vertices " + vertex_text(leaf_of_vertex_[m]) + " and " + vertex_text(r.leaf_vertex) +
                 " both split the edge (" + edge_text(q, h_.neighbor_edge(r.node, r.edge)) + ")");
        }
    }
    if (vote_on_guides_) {
        vote_on_guides();
        if (votes_leaf_ + votes_subdivision_ >= kMinVotes) decide_guides();
    }
    next.resize(4 * refined.size());  // written through a pointer: push_back checked its room per child
    NodeId* children = next.data();
    for (NodeId n : refined) {
        failed_node_ = n;
        for (int e = 0; e < 3; ++e) {
            const VertexId m = h_.midpoint(n, e);
            if (leaf_of_vertex_[m] == kNoIndex) assign(m, find_midpoint(n, e));
        }
        for (int k = 0; k < 4; ++k) children[k] = h_.child(n, k);
        children += 4;
    }
    failed_node_ = kNoNode;
}

void Reconstruction::add_level_faces() {
    std::vector<uint64_t>& bits = faces_read_->bits;
    uint64_t twice = 0;
    for (const uint32_t* f_at = level_faces_.get(); f_at != level_faces_end_; ++f_at) {
        const uint32_t f = *f_at;
        const uint64_t bit = uint64_t(1) << (f % 64);
        twice |= bits[f / 64] & bit;
        bits[f / 64] |= bit;
    }
    faces_read_->twice |= twice != 0;
    faces_read_->count += uint64_t(level_faces_end_ - level_faces_.get());
}

void Reconstruction::vote_on_guides() {
    for (const Reveal& r : reveals_) {
        // Level 0's midpoints split base edges, where both guides put them at the same point.
        if (h_.level(r.node) == 0) continue;
        const int e = r.edge, f = (e + 1) % 3;
        const Vec3& at = leaf_.positions[r.leaf_vertex];
        const Vec3 d_leaf = at - rounded_scaled(0.5, leaf_.positions[corner(r.node, e)] + leaf_.positions[corner(r.node, f)]);
        const Vec3 d_subdivision = at - rounded_scaled(0.5, h_.position(h_.vertex(r.node, e)) + h_.position(h_.vertex(r.node, f)));
        const double leaf = exact_dot(d_leaf, d_leaf), subdivision = exact_dot(d_subdivision, d_subdivision);
        votes_leaf_ += leaf < subdivision;
        votes_subdivision_ += subdivision < leaf;
    }
}

void Reconstruction::decide_guides() {
    vote_on_guides_ = false;
    if (votes_leaf_ + votes_subdivision_ >= kMinVotes && votes_subdivision_ >= kVoteRatio * votes_leaf_)
        throw SubdivisionGuideCloser(what_ + ": the subdivision guide is closer");
}

void Reconstruction::read_level_or_repair(const std::vector<NodeId>& level, std::vector<NodeId>& refined) {
    bool misfit = false;
    try {
        read_level(level, refined);
    } catch (const Error&) {
        if (guided_.empty()) throw;
        misfit = true;
    }
    if (misfit && vote_on_guides_) {  // the reveals read before the misfit
        vote_on_guides();
        decide_guides();
    }
    if (misfit) repair_picks();
    if (referee_ && referee_after_repair()) misfit = true;
    guided_clear();
    if (misfit) read_level(level, refined);  // the first misfit left is the error
}

void Reconstruction::read_level(const std::vector<NodeId>& level, std::vector<NodeId>& refined) {
    refined.clear();
    reveals_.clear();
    if (faces_read_) {
        if (level_faces_room_ < 3 * level.size()) {
            level_faces_room_ = 3 * level.size();
            level_faces_.reset(new uint32_t[level_faces_room_]);
        }
        level_faces_end_ = level_faces_.get();
    }
    for (NodeId n : level) {
        if (classify(n)) refined.push_back(n);
    }
    mark_refined(refined);
    auto is_refined = [&](NodeId q) {
        return q != kNoNode && refined_index_[q] != kNoIndex;  // sized to every node (mark_refined)
    };
    try {
        for (NodeId n : refined) {
            if (!h_.can_split(n)) fail_node(n, "is refined next to a coarser element (2:1 balance violated)");
        }
        // A leaf edge across which the same-level neighbour is refined needs no test of its own:
        // that neighbour's reading (classify, every node of the level before this) found the
        // edge a leaf edge in its reverse direction and refused it ("nothing on its other side").
        for (const Reveal& r : reveals_) {
            if (!is_refined(h_.neighbor(r.node, r.edge))) {
                explain_misfit(r.node);
                fail(std::string("vertex ") + vertex_text(r.leaf_vertex) +
                     " lies on an edge whose other side is not refined (T-junction)" +
                     (h_.level(r.node) == 0 ? " (wrong base?)" : ""));
            }
            if (vertex_of_leaf_[r.leaf_vertex] != kNoIndex)
                fail("vertex " + vertex_text(r.leaf_vertex) +
                     " would be used twice by the refinement (not a red-green refinement)");
        }
    } catch (const Error&) {
        unmark_refined(refined);
        throw;
    }
    unmark_refined(refined);
}

void Reconstruction::mark_refined(const std::vector<NodeId>& refined) {
    // Sized once for every node the hierarchy can hold (grown a node at a time, its resizes were
    // 1% of a 10^6-face import's instructions).
    if (refined_index_.size() < h_.node_capacity()) refined_index_.resize(h_.node_capacity(), kNoIndex);
    for (uint32_t i = 0; i < refined.size(); ++i) refined_index_[refined[i]] = i;
}

void Reconstruction::unmark_refined(const std::vector<NodeId>& refined) {
    for (NodeId n : refined) refined_index_[n] = kNoIndex;
}

void Reconstruction::split_refined(const std::vector<NodeId>& refined) {
    const uint32_t count = uint32_t(refined.size());
    if (count == 0) return;
    mark_refined(refined);
    // A same-level neighbour outside the list is a leaf (the level is read whole before it is
    // split), which split_level's links assume; otherwise node at a time, as it always did.
    for (NodeId n : refined) {
        for (int e = 0; e < 3; ++e) {
            const NodeId q = h_.neighbor(n, e);
            if (q != kNoNode && refined_index_[q] == kNoIndex && !h_.is_leaf(q)) {
                unmark_refined(refined);
                for (NodeId x : refined) h_.split(x);
                return;
            }
        }
    }
    // The children's links as local indices (child k of refined[i] is 4 i + k), written into the
    // room of the children themselves.
    const ChildLinkRoom room = HierarchyBuilder::open_children(h_, nullptr, count);
    for (uint32_t i = 0; i < count; ++i) {
        const NodeId n = refined[i];
        uint32_t* const words = room.words + ChildLinkRoom::kStride * 4 * size_t(i);
        auto link = [words](int k, int e) -> uint32_t& {
            return words[ChildLinkRoom::kStride * size_t(k) + size_t(e)];
        };
        for (int w = 0; w < 12; ++w) {  // a constant table: unrolled to the six sibling words
            const red_split::LinkSource s = red_split::kLinkSources.of[w];
            if (s.kind == red_split::LinkSource::kSibling) link(w / 3, w % 3) = 4 * i + s.sibling;
        }
        // The edge runs the other way in the neighbour: the first half of ours is the second of its.
        for (int e = 0; e < 3; ++e) {
            const NodeId q = h_.neighbor(n, e);
            const uint32_t j = q == kNoNode ? kNoIndex : refined_index_[q];
            const int eq = h_.neighbor_edge(n, e);
            link(red_split::kFirstHalfChild[e], e) = j == kNoIndex ? kNoNode : 4 * j + red_split::kSecondHalfChild[eq];
            link(red_split::kSecondHalfChild[e], e) = j == kNoIndex ? kNoNode : 4 * j + red_split::kFirstHalfChild[eq];
        }
    }
    unmark_refined(refined);
    LevelSplits splits{refined.data(), count, nullptr};
    splits.links_in_place = true;
    HierarchyBuilder::split_level(h_, splits);
}

Reconstruction::Reading Reconstruction::read(const uint32_t p[3]) const { return read_inline(p); }

AMC_ALWAYS_INLINE Reconstruction::Reading Reconstruction::read_inline(const uint32_t p[3]) const {
    // p[e] -> p[e+1], looked up once, before r is written (its stores may alias the index's arrays).
    const LeafHalfedges::Edge ahead[3] = {he_.edge(p[0], p[1]), he_.edge(p[1], p[2]), he_.edge(p[2], p[0])};
    Reading r;
    for (int e = 0; e < 3; ++e) {
        r.unsplit[e] = ahead[e].face != kNoIndex;
        r.unsplit_count += r.unsplit[e];
    }
    auto reveal = [&](int e, uint32_t v) {
        r.reveal_edge[r.reveal_count] = e;
        r.reveal_vertex[r.reveal_count++] = v;
    };
    if (r.unsplit_count == 0) {
        // A refined element has no leaf edge between its corners, in either direction.
        for (int e = 0; e < 3; ++e) {
            const uint32_t across = he_.face(p[(e + 1) % 3], p[e]);
            if (across != kNoIndex) {
                r.fault = Reading::edge_across;
                r.fault_edge = e;
                r.fault_detail[0] = across;
                return r;
            }
        }
    } else if (r.unsplit_count == 3) {
        if (ahead[0].apex != p[2]) r.fault = Reading::not_a_face;
        r.faces[r.face_count++] = ahead[0].face;
    } else if (r.unsplit_count == 2) {
        const int e = !r.unsplit[0] ? 0 : !r.unsplit[1] ? 1 : 2;  // the split edge
        const uint32_t m = ahead[(e + 1) % 3].apex;
        const uint32_t m_other = ahead[(e + 2) % 3].apex;
        r.fault_edge = e;
        if (m == kNoIndex || m_other != m) {
            r.fault = m != kNoIndex && m_other != kNoIndex ? Reading::two_vertices : Reading::no_bisection;
            r.fault_detail[0] = m_other;
            r.fault_detail[1] = m;
        } else {
            reveal(e, m);
            r.faces[r.face_count++] = ahead[(e + 1) % 3].face;
            r.faces[r.face_count++] = ahead[(e + 2) % 3].face;
        }
    } else {
        const int u = r.unsplit[0] ? 0 : r.unsplit[1] ? 1 : 2;  // the unsplit edge
        const uint32_t a = p[u], b = p[(u + 1) % 3], c = p[(u + 2) % 3];
        const uint32_t w = ahead[u].apex;
        // Default diagonal m_{u+1}--v_u: (a, b, m1), (a, m1, m2), (m2, m1, c).
        const LeafHalfedges::Edge aw = he_.edge(a, w);
        const uint32_t x = aw.apex;
        const LeafHalfedges::Edge xw = x != kNoIndex ? he_.edge(x, w) : LeafHalfedges::Edge{};
        const bool as_default = x != kNoIndex && xw.apex == c;
        // Flipped diagonal m_{u+2}--v_{u+1}: (a, b, m2), (b, m1, m2), (m2, m1, c).
        const LeafHalfedges::Edge wb = as_default ? LeafHalfedges::Edge{} : he_.edge(w, b);
        const uint32_t y = wb.apex;
        const LeafHalfedges::Edge wy = !as_default && y != kNoIndex ? he_.edge(w, y) : LeafHalfedges::Edge{};
        const bool as_flipped = !as_default && y != kNoIndex && wy.apex == c;
        r.fault_edge = u;
        r.faces[r.face_count++] = ahead[u].face;
        if (as_default) {
            reveal((u + 1) % 3, w);
            reveal((u + 2) % 3, x);
            r.faces[r.face_count++] = aw.face;
            r.faces[r.face_count++] = xw.face;
        } else if (as_flipped) {
            reveal((u + 1) % 3, y);
            reveal((u + 2) % 3, w);
            r.flipped = true;
            r.faces[r.face_count++] = wb.face;
            r.faces[r.face_count++] = wy.face;
        } else {
            r.fault = Reading::no_closure;
        }
    }
    return r;
}

bool Reconstruction::classify(NodeId n) {
    const uint32_t p[3] = {corner(n, 0), corner(n, 1), corner(n, 2)};
    const Reading r = read_inline(p);
    // The messages out of line: their strings made every reading save and restore registers.
    if (__builtin_expect(r.fault != Reading::none, 0)) fail_reading(n, p, r);
    return take_reading(n, r);
}

void Reconstruction::fail_reading(NodeId n, const uint32_t p[3], const Reading& r) const {
    switch (r.fault) {
        case Reading::none:
            break;
        case Reading::edge_across:
            fail("edge (" + edge_text(n, r.fault_edge) + ") of face " + std::to_string(r.fault_detail[0]) +
                 " has nothing on its other side, where the element (" + vertex_text(p[0]) + ", " +
                 vertex_text(p[1]) + ", " + vertex_text(p[2]) +
                 ") is split: a missing face, or a T-junction in face " + std::to_string(r.fault_detail[0]) +
                 (h_.level(n) == 0 ? " (wrong base?)" : ""));
        case Reading::not_a_face:
            fail_node(n, "is not a face of the leaf mesh, nor split by it");
        case Reading::two_vertices:
            explain_misfit(n);
            fail("the edge (" + edge_text(n, r.fault_edge) + ") of the element (" + vertex_text(p[0]) + ", " +
                 vertex_text(p[1]) + ", " + vertex_text(p[2]) + ") carries more than one vertex (" +
                 vertex_text(r.fault_detail[0]) + ", " + vertex_text(r.fault_detail[1]) +
                 "): the elements across are more than one level finer (2:1 balance violated)");
        case Reading::no_bisection:
            explain_misfit(n);
            fail_node(n, "has one split edge but no bisection (" + edge_text(n, (r.fault_edge + 1) % 3) + ")");
        case Reading::no_closure:
            explain_misfit(n);
            fail_node(n, "has two split edges but no green closure on edge (" + edge_text(n, r.fault_edge) + ")");
    }
    fail("internal: a reading without a fault taken for one");
}

bool Reconstruction::take_reading(NodeId n, const Reading& r) {
    if (r.unsplit_count == 0) return true;
    for (int i = 0; i < r.reveal_count; ++i) reveals_.push_back({n, r.reveal_edge[i], r.reveal_vertex[i]});
    if (faces_read_) {  // all three written (room for them), face_count kept: no loop, no call
        level_faces_end_[0] = r.faces[0];
        level_faces_end_[1] = r.faces[1];
        level_faces_end_[2] = r.faces[2];
        level_faces_end_ += r.face_count;
    }
    // A level read again after a repair may read otherwise; written only on a change (an out-of-line call).
    if (h_.diagonal_flipped(n) != r.flipped) h_.set_diagonal_flipped(n, r.flipped);
    return false;
}

void Reconstruction::explain_misfit(NodeId n) const {
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

uint32_t Reconstruction::find_midpoint(NodeId n, int e) {
    const uint32_t a = corner(n, e), b = corner(n, (e + 1) % 3);
    if (guide_ == MidpointGuide::exact) {
        Vec3 m = midpoint_placer(nullptr, leaf_.positions[a], leaf_.positions[b]);  // finite beyond DBL_MAX / 2 too
        if (leaf_.single_precision) m = rounded_to_float(m);
        const uint32_t found = positions_.find(m);
        if (found == kNoIndex)
            throw MidpointNotFound(what_ + ": no vertex at the midpoint of edge (" + edge_text(n, e) + ")");
        return found;
    }
    if (!forced_.empty()) {  // a retry's vertex (pick_backtrack.cpp), while it is free
        const auto it = forced_.find(edge_key(a, b));
        if (it != forced_.end() && vertex_of_leaf_[it->second] == kNoIndex) {
            note_pick(h_.midpoint(n, e), n, e);
            return it->second;
        }
    }
    // From the connectivity alone where it tells: the halves of the edge are leaf edges.
    const uint32_t common = only_unmatched_common_neighbor(a, b);
    if (common != kNoIndex) return common;
    const MidpointTest may_be_midpoint(*this, n, e);
    uint32_t found;
    uint32_t nearest[kCandidates];
    uint32_t count = 0;
    const double limit = pick_search_limit(a, b);
    if (choice_) {
        count = nearest_usable(guide_position(n, e), may_be_midpoint, kCandidates, nearest, limit);
        const uint32_t kept = on_shortest_chains(nearest, count, a, b);
        const uint64_t walked = choice_->walked();
        found = choice_->choose(nearest, kept, a, b, vertex_of_leaf_);
        charge_search(walked_, choice_->walked() - walked, kWalkedPerFace);
    } else {
        count = nearest_usable(guide_position(n, e), may_be_midpoint, 1, nearest, limit);
        found = count ? nearest[0] : kNoIndex;
    }
    if (referee_ && found != kNoIndex) found = (*referee_)(GuidedPick{h_.level(n), a, b, found, nearest, count, false});
    if (found == kNoIndex) fail("no vertex left to split the edge (" + edge_text(n, e) + ")");
    note_guided(h_.midpoint(n, e), n, e);
    note_pick(h_.midpoint(n, e), n, e);
    return found;
}

uint32_t Reconstruction::on_shortest_chains(uint32_t* candidates, uint32_t count, uint32_t a, uint32_t b) {
    if (count < 2) return count;
    if (!detour_) detour_ = std::make_unique<LeafDetour>(he_);
    const uint64_t walked = detour_->walked();
    const uint32_t kept = detour_->keep_least_detour(a, b, kChainHops, candidates, count);
    charge_search(walked_, detour_->walked() - walked, kWalkedPerFace);
    return kept;
}

Vec3 Reconstruction::guide_position(NodeId n, int e) {
    const uint32_t a = corner(n, e), b = corner(n, (e + 1) % 3);
    Vec3 m = guide_ == MidpointGuide::subdivision ? h_.position(h_.midpoint(n, e))
                                                 : 0.5 * (leaf_.positions[a] + leaf_.positions[b]);
    if (guide_ == MidpointGuide::surface) {
        m = search_.surface().closest(m).point;
    } else if (guide_ == MidpointGuide::normal_ray) {
        m = normal_ray_hit(n, e, m);
    }
    return m;
}

Vec3 Reconstruction::normal_ray_hit(NodeId n, int e, Vec3 mid) {
    const uint32_t a = corner(n, e), b = corner(n, (e + 1) % 3), c = corner(n, (e + 2) % 3);
    const NodeId q = h_.neighbor(n, e);
    const uint32_t d = q == kNoNode ? kNoIndex : corner(q, (h_.neighbor_edge(n, e) + 2) % 3);
    // A boundary edge's vertex lies on the boundary curve, not along a normal: the midpoint.
    if (c == kNoIndex || d == kNoIndex) return mid;
    const std::vector<Vec3>& p = leaf_.positions;
    // The remesher's line, as far as the edge is long. The tolerance keeps a line through a vertex
    // (the remesher's vertex, unless it moved it later) from slipping between that vertex's triangles.
    const Vec3 normal = placement_normal(p[a], p[b], p[c], p[d]);
    const auto hit = search_.surface().intersect_line(mid, normal, std::sqrt(exact_dot(p[b] - p[a], p[b] - p[a])), 1e-9);
    return hit ? hit->point : mid;
}

uint32_t Reconstruction::only_unmatched_common_neighbor(uint32_t a, uint32_t b) {
    // b's unmatched neighbours stamped, so each of a's is tested with one read, without reading
    // its own edge list (a cache miss each in a shuffled mesh) or searching a list of b's.
    if (near_b_.empty()) near_b_.assign(leaf_.positions.size(), 0);
    if (++stamp_ == 0) {  // wrapped: no stamp of an earlier call may match
        std::fill(near_b_.begin(), near_b_.end(), 0);
        stamp_ = 1;
    }
    bool any = false;
    he_.for_each_neighbor_once(b, [&](uint32_t x) {
        if (vertex_of_leaf_[x] != kNoIndex) return;
        near_b_[x] = stamp_;
        any = true;
    });
    if (!any) return kNoIndex;
    uint32_t found = kNoIndex;
    const bool unique = he_.every_neighbor(a, [&](uint32_t x) {
        if (x == found || near_b_[x] != stamp_) return true;
        if (found != kNoIndex) return false;  // a second one
        found = x;
        return true;
    });
    return unique ? found : kNoIndex;
}

std::vector<uint32_t> reconstruct_hierarchy(Hierarchy& h, const std::vector<uint32_t>& leaf_of_base,
                                            const TriangleMesh& leaf, const LeafHalfedges& halfedges,
                                            MidpointGuide guide, const PositionIndex& positions,
                                            LeafSearch& search, const std::string& what, const UndoSteps* steps,
                                            const PickReferee* referee, const std::vector<uint32_t>* input_of,
                                            bool vote_on_guides, LeafFacesRead* faces_read) {
    return Reconstruction(h, leaf_of_base, leaf, halfedges, guide, positions, search, what, steps, referee, input_of,
                          vote_on_guides, faces_read)
        .run();
}

}  // namespace amc
