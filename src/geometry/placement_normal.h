// The line along which the surface remesher places a new vertex (docs/REMESHER.md), which the
// importer casts again to find that vertex (docs/IMPORT.md, "The normal ray, measured").
#pragma once

#include <amc/mesh.h>

#include "common/exact_float.h"

#include <cmath>

namespace amc {

// The direction of the line through the midpoint of the interior edge (a, b) of the elements
// (a, b, c) and (b, a, d): the sum of the two elements' unit normals (a degenerate element adds 0).
// Products rounded (exact_float.h): the remesher and the importer cast the same line in every build.
inline Vec3 placement_normal(Vec3 a, Vec3 b, Vec3 c, Vec3 d) {
    auto unit = [](Vec3 v) {
        const double l = std::sqrt(exact_dot(v, v));
        return l > 0 ? rounded_scaled(1 / l, v) : Vec3{};
    };
    return unit(exact_cross(b - a, c - a)) + unit(exact_cross(a - b, d - b));
}

}  // namespace amc
