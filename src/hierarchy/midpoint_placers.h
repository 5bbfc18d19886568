// The hierarchy's default vertex placers (docs/HIERARCHY.md): the correctly rounded midpoint of an
// edge, rounded to float when the context is non-null (a single-precision hierarchy). Shared by
// split (forest.cpp) and the bulk split_level (level_split.cpp).
#pragma once

#include <amc/mesh.h>

#include "common/exact_float.h"

#include <cfloat>
#include <cmath>

namespace amc {

// 0.5 * (a + b) bit for bit wherever that is finite: the correctly rounded midpoint (halving is
// exact). Where a + b overflows (coordinates beyond DBL_MAX / 2), 0.5 * a + 0.5 * b: exact halves
// of such large values rounded once, the same correctly rounded midpoint, and finite.
inline double midpoint_coordinate(double a, double b) {
    const double s = a + b;
    return std::fabs(s) <= DBL_MAX ? rounded(0.5 * s) : rounded(0.5 * a) + rounded(0.5 * b);
}

inline Vec3 round_if(void* single_precision, Vec3 m) {
    return single_precision != nullptr ? rounded_to_float(m) : m;
}

// The default placer: defined once (forest.cpp), since split_level tells it by its address.
Vec3 midpoint_placer(void* single_precision, Vec3 a, Vec3 b);

// midpoint_placer where no coordinate lies beyond DBL_MAX / 2: then a + b can not overflow.
inline Vec3 near_midpoint_placer(void* single_precision, Vec3 a, Vec3 b) { return round_if(single_precision, rounded_scaled(0.5, a + b)); }

}  // namespace amc
