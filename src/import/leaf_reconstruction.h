// The reconstruction of a hierarchy from its leaf mesh (docs/IMPORT.md, section 1): top-down over
// the forest, level by level.
#pragma once

#include <amc/hierarchy.h>

#include "import/leaf_halfedges.h"
#include "import/position_index.h"
#include "import/undo_steps.h"

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace amc {

class ClosestPointQuery;
class NearestVertex;

// The search trees over the leaf mesh that the position-guided ways use, each built when first
// needed and then shared by every way of one import (a k-d tree costs about as much to build as a
// reconstruction's nearest-vertex queries; a refusal runs six guided ways).
class LeafSearch {
public:
    // The k-d tree takes the vertices in `insertion_order` (NearestVertex), if given; the
    // nearest-vertex tree takes `sorted_codes` (NearestVertex), if given.
    explicit LeafSearch(const TriangleMesh& leaf, const std::vector<uint32_t>* insertion_order = nullptr,
                        const std::vector<uint32_t>* sorted_codes = nullptr);
    // The searches of `input` on its mesh renumbered (`new_id`: input id -> this numbering, the
    // positions and faces otherwise the same): the surface tree is input's (closest points do not
    // depend on the numbering), the k-d tree input's with its ids mapped (the same points in the
    // same order answer the same); neither is built a second time.
    LeafSearch(LeafSearch& input, const std::vector<uint32_t>& new_id);
    ~LeafSearch();
    const NearestVertex& nearest();
    const ClosestPointQuery& surface();

private:
    const TriangleMesh& leaf_;
    const std::vector<uint32_t>* insertion_order_;
    const std::vector<uint32_t>* sorted_codes_ = nullptr;
    LeafSearch* input_ = nullptr;                 // the searches this one renumbers, if any
    const std::vector<uint32_t>* new_id_ = nullptr;
    std::unique_ptr<NearestVertex> nearest_;
    std::unique_ptr<ClosestPointQuery> surface_;
};

// How the reconstruction finds a vertex that no green neighbour reveals (docs/IMPORT.md).
enum class MidpointGuide {
    exact,          // the vertex at the edge's midpoint, bit for bit
    leaf_midpoint,  // the vertex nearest to the midpoint of the edge's end vertices (as the leaf
                    // mesh places them)
    subdivision,    // the vertex nearest to where midpoint subdivision of the base puts it
    surface,        // the vertex nearest to the leaf mesh's surface point closest to the
                    // midpoint of the edge's end vertices (meshes projected onto a surface)
    normal_ray,     // the vertex nearest to where the line through that midpoint along the two
                    // elements' mean normal meets the leaf mesh (normal projection, as the
                    // surface remesher places vertices)
};

// The exact way's refusal when a split edge's midpoint holds no leaf vertex: the input's new
// vertices are not all at midpoints, so the other ways had to guess them.
class MidpointNotFound : public Error {
public:
    using Error::Error;
};

// The leaf-midpoint-guided way's early end (`vote_on_guides`): the midpoints its first levels'
// green leaves revealed lie nearer where midpoint subdivision of the base puts them.
class SubdivisionGuideCloser : public Error {
public:
    using Error::Error;
};

// A guided way's end when its searches for candidates (nearest vertices, the walks comparing
// them) have done more than the mesh's size warrants (Reconstruction::charge_search): not a
// fault of the input, whose other ways go on; not backtracked from.
class SearchBudgetSpent : public Error {
public:
    using Error::Error;
};

// A position-guided pick of the vertex that splits the edge (a, b) of a node of `level`: the
// candidates the choice saw (nearest first; only the pick when no choice was made) and the pick;
// `repaired`: seen again after the level's children have had their say (no candidates then).
struct GuidedPick {
    int level;
    uint32_t a, b, picked;
    const uint32_t* candidates;
    uint32_t candidate_count;
    bool repaired;
};

// Sees every position-guided pick, when it is made and again after the level's repair, and
// returns the vertex to go on with: a bench that knows the true hierarchy counts the wrong picks
// and goes on with the true vertex (bench/import_picks.cpp).
using PickReferee = std::function<uint32_t(const GuidedPick&)>;

// The leaf faces that a reconstruction's last reading of each leaf found, one bit each: its red
// triangle, or its green ones (docs/IMPORT.md, "The final check"). Filled only by the ways that
// read each level once for good (no undo steps, no referee).
struct LeafFacesRead {
    bool filled = false;
    bool twice = false;  // a face found for two leaves
    uint64_t count = 0;  // faces found, with repeats
    std::vector<uint64_t> bits;
    // Every face of the leaf mesh found exactly once: the leaves' triangles are its faces.
    bool all_once(size_t faces) const { return filled && !twice && count == faces; }
};

// Builds the forest of `h` (a hierarchy of unrefined roots over the base, whose vertex i is leaf
// vertex leaf_of_base[i]) so that its leaf mesh is `leaf`; returns the leaf vertex of every
// vertex of `h` (0xffffffff for none). With `exact_midpoints`, the vertex an edge split creates is
// looked up at the edge's midpoint (the fast path for unmoved meshes); without, it is found from
// the connectivity alone. With `steps` (what the anchored inverse refinement undid), a guided pick
// is chosen among the nearest candidates by them (undo_steps.h); `referee` (if given) sees each
// such pick. Throws Error when the leaf mesh
// does not fit, naming leaf vertex l as input_of[l] when input_of is given (the caller's numbering
// of a renumbered leaf mesh); the caller verifies the whole leaf mesh afterwards. With
// `vote_on_guides` (the leaf-midpoint guide), throws SubdivisionGuideCloser when the first levels'
// revealed midpoints lie nearer where the subdivision guide would look. `faces_read` (if given)
// gets the faces of the leaves' readings, where the way fills it (LeafFacesRead).
std::vector<uint32_t> reconstruct_hierarchy(Hierarchy& h, const std::vector<uint32_t>& leaf_of_base,
                                            const TriangleMesh& leaf, const LeafHalfedges& halfedges,
                                            MidpointGuide guide, const PositionIndex& positions,
                                            LeafSearch& search, const std::string& what,
                                            const UndoSteps* steps = nullptr,
                                            const PickReferee* referee = nullptr,
                                            const std::vector<uint32_t>* input_of = nullptr,
                                            bool vote_on_guides = false, LeafFacesRead* faces_read = nullptr);

}  // namespace amc
