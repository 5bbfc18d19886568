// The points of a forest in space, each named once whichever trees it lies in: lattice points of
// the trees (integer coordinates 0 .. 2^root_log2 on each axis, the corners of octants of every
// level). A point on a tree's face, edge or corner has a place in every tree around it — across
// glued faces with their orientation, and around coarse edges and corners through the shared
// coarse vertices (tree_corners.h) — and one id. Where a gluing joins faces that lie apart in
// space (periodic bricks), the places stay one point of the forest but become separate points
// in space, so that the mesh is conforming across the gluing and still drawn where it lies.
#pragma once

#include "common/keyed_hash.h"
#include "common/no_index.h"
#include "octree/tree_corners.h"
#include "octree/tree_faces.h"

#include <amc/octree.h>

#include <array>
#include <cstdint>
#include <map>
#include <utility>
#include <vector>

namespace amc {

class ForestPoints {
public:
    struct Point {
        uint32_t id = kNoIndex;     // the point of the forest (ids count from 0 in the order points are added)
        uint32_t place = kNoIndex;  // the point in space (index into positions())
    };

    // `conn` must be valid (validate_connectivity) and outlive this.
    explicit ForestPoints(const TreeConnectivity& conn);

    // Room for this many places without growing.
    void reserve(size_t places);
    // The point at lattice coordinates p of `tree`, added with all its places when new.
    Point add(uint32_t tree, const int64_t p[3]);
    // A new point strictly inside a tree, which no other place can name (a cell centre).
    Point add_inside(uint32_t tree, const int64_t p[3]);
    // The point at (tree, p), or {kNoIndex, kNoIndex} when it was not added.
    Point find(uint32_t tree, const int64_t p[3]) const;

    uint32_t size() const { return next_id_; }                      // points of the forest
    const std::vector<Vec3>& positions() const { return positions_; }  // points in space
    const std::vector<uint32_t>& id_of_position() const { return id_of_position_; }

private:
    struct Key {
        uint64_t coords;
        uint32_t tree;
        bool operator==(const Key& o) const { return coords == o.coords && tree == o.tree; }
    };
    // Open addressing with linear probing: one cache line per lookup, where std::unordered_map's
    // nodes took two or more misses (the lookups are most of the extraction's time).
    struct Slot {
        Key key{0, kNoIndex};  // tree kNoIndex: empty
        Point point;
    };
    // Keyed: a forest can refine to points whose unkeyed mix shares a run of slots (found offline).
    uint64_t hash(const Key& k) const {
        return splitmix64_mix(k.coords ^ (uint64_t(k.tree) * kGoldenGamma) ^ hash_key_);
    }
    struct Place {
        uint32_t tree;
        int64_t p[3];
    };

    Key key(uint32_t tree, const int64_t p[3]) const;
    uint32_t new_position(const Place& place, uint32_t id);
    // Index of `place` in places_, appended (with its own union-find root) when new.
    size_t place_index(const Place& place);
    void join(size_t a, size_t b);
    size_t root(size_t a);
    void collect_places(uint32_t tree, const int64_t p[3]);

    const TreeConnectivity& conn_;
    int dim_;
    int64_t n_;  // 2^root_log2: the tree's length in lattice units
    TreeFaces faces_;
    TreeCorners corners_;
    std::vector<uint8_t> face_in_place_;  // per tree face: the face across is at the same place in space
    void insert(const Key& key, Point point);
    const uint64_t hash_key_ = process_hash_key();
    std::vector<Slot> slots_;  // a power of two, at most half full
    size_t used_ = 0;
    std::vector<Vec3> positions_;
    std::vector<uint32_t> id_of_position_;
    uint32_t next_id_ = 0;
    // Scratch of add(): the places of one point and the union-find of those at one place in space.
    std::vector<Place> places_;
    std::vector<size_t> parent_;
    std::vector<TreeCorners::Place> around_, around_next_;
    // Around a coarse vertex or edge of many trees: places_ looked up, not searched, beyond
    // kSearchedPlaces, and each coarse vertex (edge point) gone around once; else cubic in the trees.
    static constexpr size_t kSearchedPlaces = 32;
    std::map<std::pair<uint64_t, uint32_t>, size_t> index_of_place_;
    std::vector<TreeCorners::Meeting> gone_around_;  // the coarse vertices and edge points gone around
};

}  // namespace amc
