// Neighbours across the corners (2D, 3D) and edges (3D) of the coarse mesh, found through the
// vertices trees share, as p4est's corner and edge connectivity (tree_to_corner, tree_to_edge)
// finds them: every tree around a coarse vertex or edge, however many meet there and whether or
// not they are face neighbours of each other. Used by edge and corner balance.
#pragma once

#include <amc/octree.h>

#include <array>
#include <cstdint>
#include <map>
#include <utility>
#include <vector>

namespace amc {

class TreeCorners {
public:
    struct Place {
        uint32_t tree;
        int32_t c[3];
    };

    // Empty (finds nothing) when `conn` has no vertices or its vertices do not name points (they
    // glue faces that `conn` does not glue so, or more than two faces share them).
    explicit TreeCorners(const TreeConnectivity& conn);

    // c: coordinates at `level` of an octant's neighbour position in `tree`, outside the tree on
    // two or more axes by one octant (the octant touches a coarse corner, or in 3D an edge).
    // Appends the octants of that level in the other trees (and other corners of the same tree)
    // that touch the same coarse vertex, or the same coarse edge at the same place.
    void neighbours(uint32_t tree, int level, const int32_t c[3], std::vector<Place>& out) const;

    // Names what neighbours(tree, level, c) goes around: the coarse vertex, or the coarse edge and
    // the place along it. The same from every octant there, so a caller can go around it once.
    // With `point`, c[along the edge] is a lattice point (0 .. 2^level) rather than an octant.
    using Meeting = std::array<uint32_t, 3>;
    Meeting meeting(uint32_t tree, int level, const int32_t c[3], bool point = false) const;

private:
    struct Around {  // how position c lies outside its tree
        int out_axes = 0;     // on how many axes
        int inside_axis = -1; // 3D, out on two: the axis along the coarse edge
        int corner = 0;       // the tree's corner it is beyond (its edge's low end)
    };
    Around around(int level, const int32_t c[3]) const;

    int dim_ = 2;
    const TreeConnectivity* conn_ = nullptr;
    std::vector<std::vector<std::pair<uint32_t, uint8_t>>> at_vertex_;  // vertex -> (tree, corner)
    // 3D: (lower vertex, higher vertex) -> (tree, edge axis, corner at the edge's low end)
    std::map<std::pair<uint32_t, uint32_t>, std::vector<std::array<uint32_t, 3>>> at_edge_;
};

}  // namespace amc
