// Points of a forest named once across trees; see forest_points.h.
#include "octree/forest_points.h"

#include "common/check.h"
#include "common/no_index.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace amc {

namespace {

// The coarse vertices of face f of tree t, sorted (empty without vertices).
std::array<uint32_t, 4> face_vertices(const TreeConnectivity& conn, uint32_t t, int f) {
    std::array<uint32_t, 4> v{0, 0, 0, 0};
    const int corners = 1 << conn.dim;
    int k = 0;
    for (int c = 0; c < corners; ++c)
        if (((c >> (f / 2)) & 1) == (f & 1)) v[k++] = conn.tree_to_vertex[size_t(t) * corners + c];
    for (int i = 1; i < k; ++i)  // insertion sort (std::sort of a few elements trips GCC 12's -Warray-bounds)
        for (int j = i; j > 0 && v[j - 1] > v[j]; --j) std::swap(v[j - 1], v[j]);
    return v;
}

}  // namespace

ForestPoints::ForestPoints(const TreeConnectivity& conn)
    : conn_(conn), dim_(conn.dim), n_(int64_t(1) << octree_root_log2(conn.dim)), faces_(conn), corners_(conn), slots_(64) {
    const int faces = 2 * dim_;
    face_in_place_.assign(size_t(conn.tree_count()) * faces, 1);
    if (conn.vertices.empty()) return;  // every tree is the unit tree: no place to tell apart
    for (uint32_t t = 0; t < conn.tree_count(); ++t)
        for (int f = 0; f < faces; ++f) {
            const FaceGlue& g = faces_.glue(t, f);
            if (!g.boundary) face_in_place_[size_t(t) * faces + f] = face_vertices(conn, t, f) == face_vertices(conn, g.tree, g.face);
        }
}

ForestPoints::Key ForestPoints::key(uint32_t tree, const int64_t p[3]) const {
    // 2^root_log2 + 1 values per axis: 31 bits in 2D, 20 in 3D.
    const uint64_t packed = dim_ == 2 ? (uint64_t(p[0]) << 31) | uint64_t(p[1])
                                      : (uint64_t(p[0]) << 40) | (uint64_t(p[1]) << 20) | uint64_t(p[2]);
    return {packed, tree};
}

ForestPoints::Point ForestPoints::find(uint32_t tree, const int64_t p[3]) const {
    const Key k = key(tree, p);
    const size_t mask = slots_.size() - 1;
    for (size_t i = hash(k) & mask;; i = (i + 1) & mask) {
        if (slots_[i].key == k) return slots_[i].point;
        if (slots_[i].key.tree == kNoIndex) return {};
    }
}

void ForestPoints::reserve(size_t places) {
    size_t size = slots_.size();
    while (size < 2 * places) size *= 2;
    if (size == slots_.size()) return;
    std::vector<Slot> old(size);
    old.swap(slots_);
    used_ = 0;
    for (const Slot& s : old)
        if (s.key.tree != kNoIndex) insert(s.key, s.point);
}

void ForestPoints::insert(const Key& key, Point point) {
    if (2 * (used_ + 1) > slots_.size()) reserve(slots_.size());
    const size_t mask = slots_.size() - 1;
    size_t i = hash(key) & mask;
    while (slots_[i].key.tree != kNoIndex && !(slots_[i].key == key)) i = (i + 1) & mask;
    if (slots_[i].key.tree == kNoIndex) ++used_;
    slots_[i] = {key, point};
}

uint32_t ForestPoints::new_position(const Place& place, uint32_t id) {
    AMC_REQUIRE(positions_.size() < kNoIndex, limit_exceeded, "more than 2^32 - 1 points in a conforming leaf mesh");
    const int root = octree_root_log2(dim_);
    positions_.push_back(tree_point(conn_, place.tree, std::ldexp(double(place.p[0]), -root),
                                    std::ldexp(double(place.p[1]), -root), std::ldexp(double(place.p[2]), -root)));
    id_of_position_.push_back(id);
    return uint32_t(positions_.size() - 1);
}

ForestPoints::Point ForestPoints::add_inside(uint32_t tree, const int64_t p[3]) {
    Place place{tree, {p[0], p[1], p[2]}};
    const uint32_t id = next_id_++;
    return {id, new_position(place, id)};
}

size_t ForestPoints::place_index(const Place& place) {
    if (places_.size() <= kSearchedPlaces) {
        for (size_t i = 0; i < places_.size(); ++i)
            if (places_[i].tree == place.tree && std::equal(place.p, place.p + 3, places_[i].p)) return i;
    } else {
        if (index_of_place_.empty())
            for (size_t i = 0; i < places_.size(); ++i)
                index_of_place_.emplace(std::make_pair(key(places_[i].tree, places_[i].p).coords, places_[i].tree), i);
        const auto [it, added] = index_of_place_.emplace(std::make_pair(key(place.tree, place.p).coords, place.tree), places_.size());
        if (!added) return it->second;
    }
    places_.push_back(place);
    parent_.push_back(places_.size() - 1);
    return places_.size() - 1;
}

size_t ForestPoints::root(size_t a) {
    while (parent_[a] != a) a = parent_[a] = parent_[parent_[a]];
    return a;
}

void ForestPoints::join(size_t a, size_t b) {
    a = root(a), b = root(b);
    if (a != b) parent_[std::max(a, b)] = std::min(a, b);  // the first place found stays the root
}

void ForestPoints::collect_places(uint32_t tree, const int64_t p[3]) {
    places_.clear();
    parent_.clear();
    index_of_place_.clear();
    gone_around_.clear();
    place_index({tree, {p[0], p[1], p[2]}});
    for (size_t i = 0; i < places_.size(); ++i) {
        const Place here = places_[i];
        int on_boundary = 0, inside_axis = 0;
        for (int a = 0; a < dim_; ++a) {
            if (here.p[a] != 0 && here.p[a] != n_) {
                inside_axis = a;
                continue;
            }
            ++on_boundary;
            const int face = 2 * a + (here.p[a] == n_ ? 1 : 0);
            const FaceGlue& g = faces_.glue(here.tree, face);
            if (g.boundary) continue;
            Place there{g.tree, {0, 0, 0}};
            there.p[g.axis_to[a]] = (g.face & 1) ? n_ : 0;
            for (int k = 0; k < dim_; ++k)
                if (k != a) there.p[g.axis_to[k]] = g.flip[k] ? n_ - here.p[k] : here.p[k];
            const size_t j = place_index(there);
            if (face_in_place_[size_t(here.tree) * 2 * dim_ + face]) join(i, j);
        }
        // Around a coarse corner or (3D) edge, through the coarse vertices: octants of the finest
        // lattice (unit length) touching it, given as positions just outside this tree.
        if (on_boundary < 2) continue;
        int32_t c[3] = {0, 0, 0};
        for (int a = 0; a < dim_; ++a) c[a] = here.p[a] == 0 ? -1 : here.p[a] == n_ ? int32_t(n_) : int32_t(here.p[a]);
        // Every place at a coarse vertex (edge point) finds the same places around it, which the
        // first one found joined already: once for each.
        if (!conn_.vertices.empty()) {
            const TreeCorners::Meeting around = corners_.meeting(here.tree, octree_root_log2(dim_), c, true);
            if (std::find(gone_around_.begin(), gone_around_.end(), around) != gone_around_.end()) continue;
            gone_around_.push_back(around);
        }
        around_.clear();
        if (on_boundary == dim_) {  // a coarse corner: the octant's corner there is the point
            corners_.neighbours(here.tree, octree_root_log2(dim_), c, around_);
            for (const TreeCorners::Place& o : around_) {
                Place there{o.tree, {0, 0, 0}};
                for (int a = 0; a < dim_; ++a) there.p[a] = o.c[a] == 0 ? 0 : n_;
                join(i, place_index(there));
            }
            continue;
        }
        // 3D, a coarse edge: the point is the end the unit octants on both sides of it share.
        corners_.neighbours(here.tree, octree_root_log2(dim_), c, around_);
        c[inside_axis] -= 1;
        around_next_.clear();
        corners_.neighbours(here.tree, octree_root_log2(dim_), c, around_next_);
        AMC_REQUIRE(around_.size() == around_next_.size(), invalid_input, "coarse edge: the trees around it differ along it");
        for (size_t k = 0; k < around_.size(); ++k) {
            const TreeCorners::Place &o = around_[k], &q = around_next_[k];
            Place there{o.tree, {0, 0, 0}};
            for (int a = 0; a < 3; ++a) there.p[a] = o.c[a] != q.c[a] ? std::max(o.c[a], q.c[a]) : o.c[a] == 0 ? 0 : n_;
            join(i, place_index(there));
        }
    }
}

ForestPoints::Point ForestPoints::add(uint32_t tree, const int64_t p[3]) {
    const Point found = find(tree, p);
    if (found.id != kNoIndex) return found;
    collect_places(tree, p);
    const uint32_t id = next_id_++;
    std::vector<uint32_t> place_of_root(places_.size(), kNoIndex);
    Point first;
    for (size_t i = 0; i < places_.size(); ++i) {
        uint32_t& place = place_of_root[root(i)];
        if (place == kNoIndex) place = new_position(places_[i], id);
        insert(key(places_[i].tree, places_[i].p), Point{id, place});
        if (i == 0) first = {id, place};
    }
    return first;
}

}  // namespace amc
