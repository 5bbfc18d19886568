// Closest point on a triangle mesh: the "reference surface" query of the adaptive refinement
// driver, which projects every new vertex (an edge midpoint) onto the fine input mesh.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "amc/mesh.h"

namespace amc {

// The point of triangle (a, b, c) closest to p, by Voronoi regions of the vertices, edges and face
// (Ericson, Real-Time Collision Detection, 5.1.5). `barycentric` receives the weights of a, b, c
// (they sum to 1, each in [0, 1]). Zero-area triangles are handled as their three edges, so the
// result is always finite for finite input.
Vec3 closest_point_on_triangle(Vec3 p, Vec3 a, Vec3 b, Vec3 c, Vec3& barycentric);

// An AABB tree over a triangle mesh answering "closest point on the surface" queries.
//
// The tree is built once in O(n log n): binned SAH split on the longest centroid axis, object
// median splits from depth 48 on (which bounds the depth), at most two triangles per leaf, one
// flat array of 64-byte nodes that each hold both children's boxes. A query is a branch-and-bound
// descent that visits the nearer child first. The query copies what it needs from the mesh (the
// corners of every triangle, in leaf order), so the mesh may be dropped after
// construction. Queries are const and keep no state: any number of threads may query at once.
//
// The triangles around a vertex of high valence (kFanValence or more) are kept out of the box
// tree: near such a vertex the boxes of a fan of long triangles all overlap, and a query there
// would test a constant share of them. They sit as one leaf of the box tree holding a tree of
// direction cones around the vertex (every triangle holds it), searched with the cone's lower
// bound on the distance (intersect_line: a plane through the vertex between the cone and the
// segment), and with boxes as well (docs/REMESHER.md, "Fans of long triangles").
//
// Results are deterministic and independent of the tree: the hit is the triangle of least
// distance, ties broken by the lowest triangle index, exactly as a brute-force loop over all
// triangles calling closest_point_on_triangle() would find it.
class ClosestPointQuery {
public:
    struct Hit {
        Vec3 point;               // closest point on the surface
        uint32_t triangle = 0;    // index into reference.triangles
        double distance_squared = 0;
        Vec3 barycentric;         // weights of the triangle's corners 0, 1, 2 at `point`
    };

    // Throws Error if the mesh has no triangles or a triangle index is out of range.
    explicit ClosestPointQuery(const TriangleMesh& reference);

    Hit closest(Vec3 p) const;
    // As closest(p), adding the boxes and triangles it tested to `tested`: a caller's budget, where
    // a reference of long thin triangles around one vertex has boxes that all overlap there.
    Hit closest(Vec3 p, uint64_t& tested) const;

    // As closest(p), but only among points within `max_distance` of p (inclusive); nullopt if
    // there are none. Faster than closest(p) when the bound prunes most of the tree.
    std::optional<Hit> closest(Vec3 p, double max_distance) const;

    // As closest(p, max_distance), but only among the triangles that face `direction`: those
    // whose unit normal n has dot(n, direction) >= min_cosine * |direction| (zero-area triangles
    // face nowhere). The surface remesher projects with it so that a point between two sheets
    // of a thin part lands on the sheet its element belongs to.
    std::optional<Hit> closest_facing(Vec3 p, Vec3 direction, double min_cosine, double max_distance) const;

    // The intersection of the line {origin + t * direction} with the triangles facing
    // `direction` (as closest_facing with min_cosine 0: dot(n, direction) > 0) of least |t|,
    // among |t| * |direction| <= reach (t finite: one that overflows is no hit); nullopt if there
    // is none. Ties go to the lower triangle index. Hit::distance_squared is the squared distance
    // from origin to the hit point. `tolerance` widens every triangle by that much of its
    // barycentric range, so that a line through a vertex or along an edge is not lost to rounding
    // (the importer's normal ray aims at vertices; the remesher keeps 0). A hit counts only where
    // origin + t * unit direction lies in the triangle's bounding box widened by 16 ulps of its
    // largest coordinate and by 2 * tolerance of its extent: a line (nearly) in a triangle's plane
    // may round to an intersection anywhere in that plane, which is no hit.
    std::optional<Hit> intersect_line(Vec3 origin, Vec3 direction, double reach, double tolerance = 0) const;

    // A vertex with at least this many triangles has its fan searched by direction cones.
    static constexpr uint32_t kFanValence = 32;

    std::size_t triangle_count() const { return triangles_.size(); }
    std::size_t node_count() const { return nodes_.size(); }
    std::size_t fan_count() const { return fans_.size(); }

private:
    // One cache line: the bounds of both children (float, relative to box_origin_, rounded outward)
    // and what they are.
    // A child with count > 0 is a leaf: records [index, index + count); with count == 0 it is
    // the inner node nodes_[index]; with count kFanLeaf it is the fan fans_[index]; index kEmpty
    // marks the missing second child of a tiny tree.
    struct alignas(64) Node {
        float lo[2][3];
        float hi[2][3];
        uint32_t index[2];
        uint32_t count[2];
    };
    struct Record {  // the corners of one triangle, in leaf order
        Vec3 a, b, c;
    };
    // A node of a fan's tree: its triangles' directions from the apex lie within the cone of unit
    // `axis` and half-angle (cosine, sine), widened for rounding (no cone when they span more than
    // a half-space), and their corners within the box (relative to box_origin_). count > 0: records [index, index + count);
    // count == 0: children cone_nodes_[index] and cone_nodes_[index + 1].
    struct ConeNode {
        Vec3 axis;
        double cosine = 0, sine = 0;
        bool has_cone = false;
        float lo[3], hi[3];
        uint32_t index = 0, count = 0;
    };
    struct Fan {
        Vec3 apex;
        uint32_t root;  // into cone_nodes_
        double margin;  // covers the rounding of closest points computed on its triangles, an axis
    };

    void add_record(const TriangleMesh& reference, uint32_t triangle);
    Fan build_fan(const TriangleMesh& reference, uint32_t apex, const std::vector<uint32_t>& triangles);
    double cone_node_distance_squared(const ConeNode& node, Vec3 box_p, Vec3 w, double w_length, double margin) const;
    bool cone_may_meet_segment(const ConeNode& node, Vec3 w0, Vec3 w1, double slack) const;

    template <class Accept>
    std::optional<Hit> search(Vec3 p, double bound_squared, const Accept& accept, uint64_t* tested = nullptr) const;

    // Every box is stored relative to this point near most of the mesh: at 10^9 a float's ulp is 64,
    // so absolute float boxes of a unit-sized mesh there would all be the whole mesh.
    Vec3 box_origin_;
    std::vector<Node> nodes_;           // nodes_[0] is the root
    std::vector<Record> records_;
    std::vector<uint32_t> triangles_;   // triangle index of each record
    std::vector<Vec3> normals_;         // unit normal of each record, zero for zero-area ones
    std::vector<Fan> fans_;
    std::vector<ConeNode> cone_nodes_;
};

}  // namespace amc
