// import_leaf_mesh: base mesh + conforming leaf mesh -> hierarchy (docs/IMPORT.md, section 1).
// Checks the inputs, matches the base vertices, runs the reconstruction (leaf_reconstruction.cpp)
// and compares the extracted leaf mesh with the input, face by face.
#include <amc/import.h>

#include "common/huge_pages.h"
#include "common/keyed_hash.h"
#include "common/no_index.h"
#include "hierarchy/leaf_triangles.h"
#include "import/anchored_reconstruction.h"
#include "import/base_detection.h"
#include "import/leaf_halfedges.h"
#include "import/leaf_reconstruction.h"
#include "import/position_index.h"
#include "import/spatial_order.h"
#include "import/uniform_lattice.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace amc {

namespace {


[[noreturn]] void fail(const std::string& what, const std::string& message) { throw Error(what + ": " + message); }

std::string position_text(Vec3 p) {
    char buffer[96];
    std::snprintf(buffer, sizeof buffer, "(%.9g, %.9g, %.9g)", p.x, p.y, p.z);
    return buffer;
}

std::vector<uint32_t> match_base_vertices(const TriangleMesh& base, const TriangleMesh& leaf,
                                          const std::vector<uint32_t>& leaf_vertex_of_base,
                                          const std::vector<uint32_t>& first_at_base, const std::string& what) {
    const size_t v0 = base.positions.size();
    std::vector<uint32_t> match(v0, kNoIndex);
    // The base vertex of each matched leaf vertex, open addressing over the few base vertices
    // (an array over every leaf vertex faulted in 4 KiB pages for v0 entries).
    size_t slots = 16;
    while (slots < 2 * v0) slots *= 2;
    std::vector<std::pair<uint32_t, uint32_t>> base_of_leaf(slots, {kNoIndex, kNoIndex});  // (leaf, base)
    auto slot_of = [&](uint32_t l) {
        size_t s = size_t((uint64_t(l) * 0x9e3779b97f4a7c15ull) >> 32) & (slots - 1);
        while (base_of_leaf[s].first != kNoIndex && base_of_leaf[s].first != l) s = (s + 1) & (slots - 1);
        return s;
    };
    if (!leaf_vertex_of_base.empty()) {
        if (leaf_vertex_of_base.size() != v0)
            fail(what, "the base vertex map has " + std::to_string(leaf_vertex_of_base.size()) + " entries for " +
                           std::to_string(v0) + " base vertices");
        match = leaf_vertex_of_base;
    } else {
        match = first_at_base;
    }
    for (uint32_t b = 0; b < v0; ++b) {
        const uint32_t l = match[b];
        if (l == kNoIndex)
            fail(what, "base vertex " + std::to_string(b) + " at " + position_text(base.positions[b]) +
                           " is not a vertex of the leaf mesh (wrong base?)");
        if (l >= leaf.positions.size())
            fail(what, "base vertex " + std::to_string(b) + " maps to leaf vertex " + std::to_string(l) + " of " +
                           std::to_string(leaf.positions.size()));
        const size_t s = slot_of(l);
        if (base_of_leaf[s].first == l)
            fail(what, "base vertices " + std::to_string(base_of_leaf[s].second) + " and " + std::to_string(b) +
                           " both map to leaf vertex " + std::to_string(l));
        base_of_leaf[s] = {l, b};
    }
    return match;
}

// The first and second leaf vertex (input order) at exactly each base vertex's position, or
// kNoIndex: one pass over the leaf positions with a table of the few base positions, where an index
// of every leaf position hashes each into a table of eight times their count.
struct LeafAtBase {
    std::vector<uint32_t> first, second;
};
LeafAtBase leaf_vertices_at_base(const std::vector<Vec3>& base, const std::vector<Vec3>& leaf) {
    auto same = [](const Vec3& a, const Vec3& b) { return std::memcmp(&a, &b, sizeof(Vec3)) == 0; };
    size_t slots = 16;
    while (slots < 2 * base.size()) slots *= 2;
    std::vector<uint32_t> table(slots, kNoIndex);  // a base vertex at each distinct position
    const uint64_t key = process_hash_key();      // keyed, as PositionIndex is: the positions are the input's
    auto slot_of = [&](const Vec3& p) {
        uint64_t bits[3];
        std::memcpy(bits, &p, sizeof bits);
        size_t s = size_t(keyed_hash_words(key, bits[0], bits[1], bits[2])) & (slots - 1);
        while (table[s] != kNoIndex && !same(base[table[s]], p)) s = (s + 1) & (slots - 1);
        return s;
    };
    std::vector<uint32_t> at(base.size());  // each base vertex's slot
    for (uint32_t b = 0; b < base.size(); ++b) {
        const size_t s = slot_of(base[b]);
        if (table[s] == kNoIndex) table[s] = b;
        at[b] = uint32_t(s);
    }
    std::vector<uint32_t> first(slots, kNoIndex), second(slots, kNoIndex);
    for (uint32_t l = 0; l < leaf.size(); ++l) {
        const size_t s = slot_of(leaf[l]);
        if (table[s] == kNoIndex) continue;
        if (first[s] == kNoIndex) {
            first[s] = l;
        } else if (second[s] == kNoIndex) {
            second[s] = l;
        }
    }
    LeafAtBase out;
    out.first.reserve(base.size());
    out.second.reserve(base.size());
    for (uint32_t s : at) {
        out.first.push_back(first[s]);
        out.second.push_back(second[s]);
    }
    return out;
}

// first[second[i]] for every i.
std::vector<uint32_t> composed(const std::vector<uint32_t>& first, const std::vector<uint32_t>& second) {
    std::vector<uint32_t> out(second.size());
    for (size_t i = 0; i < second.size(); ++i) out[i] = first[second[i]];
    return out;
}

std::vector<uint32_t> inverse(const std::vector<uint32_t>& order) {
    std::vector<uint32_t> out(order.size());
    for (uint32_t i = 0; i < order.size(); ++i) out[order[i]] = i;
    return out;
}

TriangleMesh renumbered(const TriangleMesh& leaf, const std::vector<uint32_t>& input_of,
                        const std::vector<uint32_t>& import_of) {
    TriangleMesh out;
    out.single_precision = leaf.single_precision;
    // Fresh pages, a fault each per 4 KiB without huge pages: at 10^6 faces as much as the copy.
    reserve_huge(out.positions, input_of.size(), HugePages::written_whole);
    reserve_huge(out.triangles, leaf.triangles.size(), HugePages::written_whole);
    for (uint32_t v : input_of) out.positions.push_back(leaf.positions[v]);
    for (const Triangle& t : leaf.triangles) out.triangles.push_back({import_of[t[0]], import_of[t[1]], import_of[t[2]]});
    return out;
}

// The leaf mesh on base detection's breadth-first vertex numbering, for the ways a refusal spends
// its time in (the anchored way, then the guided ways with its undo steps): on a user's shuffled
// ids nearly every lookup of a large mesh misses the cache. The faces keep their order (the
// anchored way's search depends on it); the position index takes the vertices in the input's
// order and the k-d tree is the input's, renamed (which of two equal candidates is first), so the
// answers are the input numbering's, and messages name the input's vertices (input_of).
// `spatial_search` is the searches of the spatial numbering (SpatialLeaf), whose input ids are
// spatial_input_of.
struct RenumberedLeaf {
    RenumberedLeaf(const TriangleMesh& leaf, const std::vector<uint32_t>& input_leaf_of_base,
                   LeafSearch& spatial_search, const std::vector<uint32_t>& spatial_input_of)
        : input_of(detail::breadth_first_vertices(leaf.triangles, uint32_t(leaf.positions.size()))),
          import_of(inverse(input_of)),
          mesh(renumbered(leaf, input_of, import_of)),
          halfedges(mesh),
          positions(PositionIndex::Deferred{}, mesh.positions, &import_of),  // the exact way does not run here
          import_of_spatial(composed(import_of, spatial_input_of)),
          search(spatial_search, import_of_spatial) {
        leaf_of_base.reserve(input_leaf_of_base.size());
        for (uint32_t l : input_leaf_of_base) leaf_of_base.push_back(import_of[l]);
    }
    const std::vector<uint32_t> input_of, import_of;  // import id -> input id, and back
    const TriangleMesh mesh;
    const LeafHalfedges halfedges;
    const PositionIndex positions;
    const std::vector<uint32_t> import_of_spatial;  // spatial id -> import id
    LeafSearch search;
    std::vector<uint32_t> leaf_of_base;
};

// The node ids 0 .. count - 1, in order, as a range.
struct NodeIdRange {
    NodeId count;
    struct Iterator {
        NodeId n;
        NodeId operator*() const { return n; }
        Iterator& operator++() {
            ++n;
            return *this;
        }
        bool operator!=(Iterator other) const { return n != other.n; }
    };
    Iterator begin() const { return {0}; }
    Iterator end() const { return {count}; }
};

// extract_leaf_mesh(h) must be the input: every leaf triangle an input face with the same
// orientation, every input face one leaf triangle. Read in hierarchy vertex ids, in
// extract_leaf_mesh's order, without its canonical numbering and copies (a tenth of a 10^6-face
// import's instructions and pages).
// `input_of` names leaf vertices in messages.
void verify_leaf_mesh(const Hierarchy& h, const std::vector<uint32_t>& leaf_of_vertex, const TriangleMesh& leaf,
                      const LeafHalfedges& halfedges, const std::vector<uint32_t>& input_of, const std::string& what) {
    // A bit per face: the faces come in the input's order, so each mark is a random access, and
    // 128 KiB per 10^6 faces stay in the cache where a byte each did not.
    std::vector<uint64_t> used((leaf.triangles.size() + 63) / 64, 0);
    auto leaf_vertex = [&](VertexId v) { return v < leaf_of_vertex.size() ? leaf_of_vertex[v] : kNoIndex; };
    // Marks the leaf face that triangle (x, y, z) is; false when it is no face of that orientation
    // or one marked already.
    auto claim = [&](VertexId x, VertexId y, VertexId z) {
        const uint32_t a = leaf_vertex(x), b = leaf_vertex(y), c = leaf_vertex(z);
        const LeafHalfedges::Edge e = (a == kNoIndex || b == kNoIndex) ? LeafHalfedges::Edge{} : halfedges.edge(a, b);
        const uint32_t f = e.face;
        if (f == kNoIndex || e.apex != c || (used[f / 64] >> (f % 64) & 1)) return false;
        used[f / 64] |= uint64_t(1) << (f % 64);
        return true;
    };
    auto first_unused_face = [&] {  // a word at a time; the faces' count if all are used
        size_t w = 0;
        while (w < used.size() && used[w] == ~uint64_t(0)) ++w;
        if (w == used.size()) return leaf.triangles.size();
        return std::min(leaf.triangles.size(), 64 * w + size_t(__builtin_ctzll(~used[w])));
    };
    // Whether every leaf triangle is an unused face, all faces used, read in node id order. With
    // every node live (never coarsened), those are the nodes of the breadth-first order, so the
    // answer is that order's, without computing it (a twentieth of the check). A failure is read
    // again in breadth-first order below, whose first misfit the message names.
    if (h.node_count() == h.node_capacity()) {
        bool fits = true;
        try {
            for_each_leaf_triangle(h, NodeIdRange{h.node_capacity()}, -1, [&](NodeId, VertexId x, VertexId y, VertexId z, bool) {
                fits = fits && claim(x, y, z);
            });
        } catch (const Error&) {  // a leaf with three hanging nodes
            fits = false;
        }
        if (fits && first_unused_face() == leaf.triangles.size()) return;
        std::fill(used.begin(), used.end(), 0);
    }
    auto vertex_text = [&](uint32_t l) { return std::to_string(l == kNoIndex ? l : input_of[l]); };
    for_each_leaf_triangle(h, h.breadth_first_order(), -1, [&](NodeId, VertexId x, VertexId y, VertexId z, bool) {
        if (!claim(x, y, z))
            fail(what, "the reconstruction has a triangle (" + vertex_text(leaf_vertex(x)) + ", " + vertex_text(leaf_vertex(y)) +
                           ", " + vertex_text(leaf_vertex(z)) + ") that is not a face of the leaf mesh");
    });
    const size_t f = first_unused_face();
    if (f < leaf.triangles.size())
        fail(what, "face " + std::to_string(f) + " is not part of a red-green refinement of the base");
}

}  // namespace

ImportedHierarchy import_leaf_mesh(const TriangleMesh& base, const TriangleMesh& leaf,
                                   const std::vector<uint32_t>& leaf_vertex_of_base, const std::string& what) {
    validate_triangle_mesh(base, what + " (base mesh)");
    // The leaf mesh is checked in full only when it does not import: a reconstruction whose
    // extracted leaf mesh equals it proves it a valid mesh. What the reconstruction relies on
    // first: faces, indices in range, finite coordinates.
    if (leaf.triangles.empty() || leaf.triangles.size() > UINT32_MAX / 4) validate_triangle_mesh(leaf, what);
    for (const Triangle& t : leaf.triangles) {
        if (t[0] >= leaf.positions.size() || t[1] >= leaf.positions.size() || t[2] >= leaf.positions.size())
            validate_triangle_mesh(leaf, what);
    }
    for (const Vec3& p : leaf.positions) {
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) validate_triangle_mesh(leaf, what);
    }
    // Every way runs on the leaf mesh in spatial order (spatial_order.h; on a user's shuffled ids
    // nearly every lookup of a large mesh misses the cache) and answers in the input's ids. The
    // faces keep their order, and the position index and the k-d tree take the vertices in the
    // input's order, so every choice (the first of two equal candidates) is the input order's.
    std::vector<uint32_t> spatial_codes;  // the nearest-vertex tree's, in spatial order
    const std::vector<uint32_t> input_of = detail::spatial_vertex_order(leaf.positions, &spatial_codes);  // spatial id -> input id
    const std::vector<uint32_t> spatial_of = inverse(input_of);
    const TriangleMesh spatial = renumbered(leaf, input_of, spatial_of);
    // In input order (sequential reads), built when the exact way looks a second vertex up.
    PositionIndex leaf_positions(PositionIndex::Deferred{}, leaf.positions);
    leaf_positions.rename(spatial.positions, spatial_of);
    // Two vertices at one position are refused where they make the input ambiguous (a base vertex
    // matched by position) or when the import fails; a projection may put two new vertices of a
    // valid refinement on one point.
    auto refuse_duplicate = [&](uint32_t a, uint32_t b) {
        fail(what, "vertices " + std::to_string(a) + " and " + std::to_string(b) + " have the same position " +
                       position_text(leaf.positions[a]) + " (duplicate vertex)");
    };
    LeafAtBase at_base;
    if (leaf_vertex_of_base.empty()) {
        at_base = leaf_vertices_at_base(base.positions, leaf.positions);
        for (size_t b = 0; b < base.positions.size(); ++b) {
            if (at_base.second[b] != kNoIndex) refuse_duplicate(at_base.first[b], at_base.second[b]);
        }
    }
    const std::vector<uint32_t> leaf_of_base =
        match_base_vertices(base, leaf, leaf_vertex_of_base, at_base.first, what);
    const std::vector<uint32_t> spatial_leaf_of_base = composed(spatial_of, leaf_of_base);

    TriangleMesh hierarchy_base;
    hierarchy_base.triangles = base.triangles;
    hierarchy_base.single_precision = leaf.single_precision;
    hierarchy_base.positions.reserve(base.positions.size());
    for (uint32_t l : leaf_of_base) hierarchy_base.positions.push_back(leaf.positions[l]);

    const LeafHalfedges halfedges(spatial);
    ImportedHierarchy out;
    std::vector<uint32_t> leaf_of_vertex;
    // Seven ways in, cheapest first, then three again (below); the first whose result is exactly the
    // leaf mesh wins.
    enum class Way {
        exact_midpoints,  // new vertices at edge midpoints (as amcodec writes them): found by position
        uniform,          // a uniform refinement (semi-regular remeshes): read off the connectivity as grids
        leaf_midpoint,    // the general reconstruction, guided by the midpoint of the edge's leaf vertices
        subdivision,      // the same, guided by midpoint subdivision of the base
        surface,          // the same, guided by the surface: new vertices projected onto it
        normal_ray,       // the same, guided by the normal ray (as the surface remesher places them)
        anchored,         // levels undone bottom-up from the connectivity alone, the base vertices kept
                          // (positions anywhere; not every adaptive mesh yet, docs/IMPORT.md)
    };
    // What the anchored way undid, kept for the guided ways' second round (in renumbered's ids).
    UndoSteps steps;
    LeafSearch search(spatial, &spatial_of, &spatial_codes);
    std::unique_ptr<RenumberedLeaf> renumbered;  // made for the anchored way
    auto guide_of = [](Way way) {
        return way == Way::exact_midpoints ? MidpointGuide::exact
               : way == Way::leaf_midpoint ? MidpointGuide::leaf_midpoint
               : way == Way::subdivision   ? MidpointGuide::subdivision
               : way == Way::normal_ray    ? MidpointGuide::normal_ray
                                           : MidpointGuide::surface;
    };
    // Each attempt starts from a copy of the roots: copied into the last attempt's storage, whose
    // pages are already mapped (a fresh 10^6-face hierarchy faults in about 60 MB).
    const Hierarchy roots(hierarchy_base);
    LeafFacesRead faces_read;
    auto attempt = [&](Way way, bool by_undo_steps, bool vote_on_guides = false) {
        faces_read.filled = false;
        out.hierarchy = roots;
        // A leaf mesh of F faces comes from at most F leaves, so from at most 4F/3 + roots nodes.
        out.hierarchy.reserve(leaf.triangles.size() * 4 / 3 + base.triangles.size() + 4, leaf.positions.size());
        if (way == Way::uniform) {
            leaf_of_vertex = reconstruct_uniform(out.hierarchy, spatial_leaf_of_base, spatial, halfedges);
            if (leaf_of_vertex.empty()) throw Error(what + ": not a uniform refinement");
        } else if (way == Way::anchored || by_undo_steps) {
            if (way == Way::anchored) validate_triangle_mesh(leaf, what);  // the inverse step needs an oriented manifold
            if (!renumbered) renumbered = std::make_unique<RenumberedLeaf>(leaf, leaf_of_base, search, input_of);
            RenumberedLeaf& r = *renumbered;
            if (way == Way::anchored) {
                leaf_of_vertex = reconstruct_anchored(out.hierarchy, r.leaf_of_base, r.mesh, what, &steps);
                if (leaf_of_vertex.empty()) throw Error(what + ": anchored inverse refinement did not reach the base");
            } else {
                leaf_of_vertex = reconstruct_hierarchy(out.hierarchy, r.leaf_of_base, r.mesh, r.halfedges, guide_of(way),
                                                       r.positions, r.search, what, &steps, nullptr, &r.input_of);
            }
            for (uint32_t& l : leaf_of_vertex) {
                if (l != kNoIndex) l = spatial_of[r.input_of[l]];
            }
        } else {
            leaf_of_vertex = reconstruct_hierarchy(out.hierarchy, spatial_leaf_of_base, spatial, halfedges, guide_of(way),
                                                   leaf_positions, search, what, nullptr, nullptr, &input_of,
                                                   vote_on_guides, &faces_read);
        }
        // The leaves' last readings found each face once: their triangles, which the extraction
        // emits as read, are the leaf mesh (docs/IMPORT.md, "The final check"). Otherwise the
        // extraction itself is compared, and its first misfit named.
        if (!faces_read.all_once(spatial.triangles.size()))
            verify_leaf_mesh(out.hierarchy, leaf_of_vertex, spatial, halfedges, input_of, what);
    };
    // The subdivision-guided way's error is the one reported: it goes furthest on most bad input.
    // The guided ways run a second time, their picks decided by the anchored way's undo steps,
    // when the anchored way has not reached the base (it has steps only for a manifold leaf mesh).
    std::string first_error;
    bool midpoints_guessed = false;
    bool done = false;
    const std::pair<Way, bool> ways[] = {
        {Way::exact_midpoints, false}, {Way::uniform, false},  {Way::leaf_midpoint, false}, {Way::subdivision, false},
        {Way::surface, false},         {Way::normal_ray, false}, {Way::anchored, false},    {Way::leaf_midpoint, true},
        {Way::subdivision, true},      {Way::surface, true}};
    // The leaf-midpoint way gives way to the subdivision way when its first levels' revealed
    // midpoints vote for that guide; if the subdivision way fails, the old order resumes.
    enum class Outcome { imported, failed, subdivision_closer };
    auto try_way = [&](Way way, bool by_undo_steps, bool vote_on_guides) {
        try {
            attempt(way, by_undo_steps, vote_on_guides);
            return Outcome::imported;
        } catch (const SubdivisionGuideCloser&) {
            return Outcome::subdivision_closer;
        } catch (const MidpointNotFound&) {
            midpoints_guessed = true;
        } catch (const Error& e) {
            if (way == Way::subdivision && !by_undo_steps) first_error = e.what();
        }
        return Outcome::failed;
    };
    bool subdivision_failed = false;
    for (const auto& [way, by_undo_steps] : ways) {
        if (by_undo_steps && steps.step.empty()) break;
        if (way == Way::subdivision && !by_undo_steps && subdivision_failed) continue;
        Outcome outcome = try_way(way, by_undo_steps, way == Way::leaf_midpoint && !by_undo_steps);
        if (outcome == Outcome::subdivision_closer) {
            outcome = try_way(Way::subdivision, false, false);
            if (outcome != Outcome::imported) {
                subdivision_failed = true;
                outcome = try_way(way, by_undo_steps, false);
            }
        }
        if (outcome == Outcome::imported) {
            done = true;
            break;
        }
    }
    if (!done) {
        uint32_t first = kNoIndex, second = kNoIndex;
        const PositionIndex duplicates(leaf.positions, &first, &second);  // the first two at one position
        if (first != kNoIndex) refuse_duplicate(first, second);
        validate_triangle_mesh(leaf, what);  // a structural fault has the clearer message
        // Where midpoints were guessed, the fault found may be a wrong guess's, not the input's.
        if (midpoints_guessed)
            throw Error(first_error + "; or the leaf mesh is a red-green refinement of the base whose new vertices lie "
                                      "too far from their edges' midpoints for the import to find it (docs/IMPORT.md, "
                                      "\"Limitations\"): imported without the base (amc encode without --base), it "
                                      "is compressed all the same");
        throw Error(first_error);
    }

    out.vertex_of_input.assign(leaf.positions.size(), kNoIndex);
    for (VertexId v = 0; v < leaf_of_vertex.size(); ++v) {
        if (leaf_of_vertex[v] == kNoIndex) continue;
        out.vertex_of_input[input_of[leaf_of_vertex[v]]] = v;
        out.hierarchy.set_position(v, spatial.positions[leaf_of_vertex[v]]);  // the same position, read in order
    }
    for (uint32_t l = 0; l < leaf.positions.size(); ++l) {
        if (out.vertex_of_input[l] == kNoIndex) validate_triangle_mesh(leaf, what);  // an unused vertex
    }
    return out;
}

}  // namespace amc
