// The line along which the surface remesher places a new vertex (docs/REMESHER.md), which the
// importer casts again to find that vertex (docs/IMPORT.md, "The normal ray, measured").
#pragma once

#include <amc/mesh.h>

#include <cmath>

namespace amc {

// The direction of the line through the midpoint of the interior edge (a, b) of the elements
// (a, b, c) and (b, a, d): the sum of the two elements' unit normals (a degenerate element adds 0).
inline Vec3 placement_normal(Vec3 a, Vec3 b, Vec3 c, Vec3 d) {
    auto unit = [](Vec3 v) {
        const double l = std::sqrt(dot(v, v));
        return l > 0 ? (1 / l) * v : Vec3{};
    };
    return unit(cross(b - a, c - a)) + unit(cross(a - b, d - b));
}

}  // namespace amc
