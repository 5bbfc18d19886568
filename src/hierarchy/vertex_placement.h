// Where the surface remesher puts the vertices that refinement creates: projected onto the
// reference as they are made (VertexPlacement), then corrected on the finished leaf mesh
// (correct_placements) so that no triangle folds over or falls below its quality bound and no two
// vertices coincide. Internal to remesh_adaptively (surface_remeshing.cpp, docs/REMESHER.md).
#pragma once

#include <amc/hierarchy.h>

#include "geometry/reference_surface.h"

#include <cstdint>
#include <unordered_set>
#include <vector>

namespace amc {

// What the remesher knows of every vertex it created: the edge it splits and where it went
// relative to that edge's midpoint. The correction moves a vertex back towards the midpoint in
// kSteps steps (step s keeps the fraction 1 - s / kSteps of the offset).
struct Placements {
    static constexpr uint8_t kSteps = 8;
    std::vector<VertexId> end_a, end_b;  // kNoVertex for base vertices
    std::vector<Vec3> offset;
    std::vector<uint8_t> step;

    void grow(size_t vertex_count);
    bool is_placed(VertexId v) const { return v < end_a.size() && end_a[v] != kNoVertex; }
};

// Hash of an exact position, for the sets that keep two vertices off one point.
struct PositionHash {
    size_t operator()(Vec3 p) const;
};

class VertexPlacement {
public:
    VertexPlacement(Hierarchy& h, const ReferenceSurface& surface);

    // Places the vertices that refine() created when it split `split` (in split order, so every
    // split node's corners are placed before its midpoints). A new vertex on an interior edge goes
    // where the line through the edge's midpoint along the two elements' mean normal meets the
    // reference (normal projection), else to the nearest point of the reference facing that way,
    // else halfway there; the first of these that leaves both elements' halves within
    // kPlacementTiltDegrees of their flat orientation and with a fifth of their flat quality (and
    // is no other vertex's position) is taken, else the midpoint. A boundary edge's vertex goes to
    // the nearest point of the reference's boundary.
    void place(const std::vector<NodeId>& split);

    Placements& placements() { return placements_; }

private:
    void place_midpoint(NodeId s, int e, VertexId m);

    Hierarchy& h_;
    const ReferenceSurface& surface_;
    const bool single_;
    Placements placements_;
    std::unordered_set<Vec3, PositionHash> taken_;
};

struct CorrectionResult {
    uint32_t moved = 0;      // vertices moved (slid along the surface or pulled back)
    uint32_t slides = 0;     // moves along the surface
    uint32_t steps = 0;      // steps back towards a midpoint
    uint32_t flattened = 0;  // nodes whose corners were sent to their midpoints at once
    uint32_t inherited_fold_overs = 0;  // fold-overs that the flat subdivision of the base has too
};

// Corrects the placed vertices of `h` until no leaf-mesh triangle is below its quality bound
// (min(min_quality, a third of its base triangle's quality)), no two leaf-mesh triangles fold
// over (unless the base folds there too) and no two vertices coincide:
//  1. the corners of bad triangles slide along the surface towards the centroid of their
//     triangles where that leaves less badness around them;
//  2. every triangle still bad moves one of its corners a step back towards its edge midpoint
//     (the shortest move among those that leave less badness around it, else the shortest); a
//     triangle none of whose corners can move sends the corners of its node, or of its nearest
//     ancestor that still has movable ones, to their midpoints.
// Steps only grow, so this ends, and with every vertex at its midpoint the leaf mesh is the flat
// red-green subdivision of the base: its triangles have at least a third of their base
// triangle's quality (the worst of red-green's shapes) and fold over only where the base does.
CorrectionResult correct_placements(Hierarchy& h, Placements& placements, const ReferenceSurface& surface,
                                    double min_quality);

// Leaves with a leaf-mesh triangle that folds over with a neighbour.
std::vector<NodeId> leaves_with_fold_overs(const Hierarchy& h);

}  // namespace amc
