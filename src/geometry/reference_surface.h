// The surface a remesher projects its new vertices onto: the faces of the reference mesh and its
// boundary curves, each behind a closest-point tree.
#pragma once

#include <optional>

#include "amc/mesh.h"
#include "geometry/closest_point.h"

namespace amc {

class ReferenceSurface {
public:
    // Throws Error if the mesh has no triangles.
    explicit ReferenceSurface(const TriangleMesh& reference);

    const ClosestPointQuery& faces() const { return faces_; }
    bool has_boundary() const { return boundary_.has_value(); }

    // The point of the surface nearest to p among the triangles that face `normal` (less than
    // 90 degrees away from it), at most `reach` from p; nullopt if there is none. The normal
    // keeps a point between two sheets of a thin part on the sheet its element approximates.
    std::optional<Vec3> project(Vec3 p, Vec3 normal, double reach) const;
    // The intersection of the line through p along `normal` with the triangles facing `normal`,
    // nearest to p and at most `reach` from it; nullopt if there is none. Unlike the nearest
    // point it does not slide sideways towards whatever part of the surface is closest, so new
    // vertices keep their place between their neighbours (as in normal meshes, Guskov et al. 2000).
    std::optional<Vec3> project_along(Vec3 p, Vec3 normal, double reach) const;
    // The nearest point of the reference's boundary edges at most `reach` from p; nullopt if there
    // is none (or the reference is closed).
    std::optional<Vec3> project_to_boundary(Vec3 p, double reach) const;

private:
    ClosestPointQuery faces_;
    // Boundary edges as zero-area triangles (a, b, b), which the query handles as segments.
    std::optional<ClosestPointQuery> boundary_;
};

}  // namespace amc
