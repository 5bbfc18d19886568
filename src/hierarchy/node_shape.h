// A node's triangle as the refinement drivers measure it against a size field
// (adaptive_refinement.cpp, surface_remeshing.cpp).
#pragma once

#include <amc/hierarchy.h>

namespace amc {

Vec3 node_centroid(const Hierarchy& h, NodeId n);
// The length of its longest edge.
double node_diameter(const Hierarchy& h, NodeId n);

}  // namespace amc
