// Base detection: the coarsest base mesh of which a triangle mesh is a red-green refinement,
// found from connectivity alone by undoing one level of refinement at a time
// (inverse_refinement.h) until no level can be undone. Where the mesh has no such structure it is
// its own base. docs/IMPORT.md describes the method and its figures.
#pragma once

#include <amc/hierarchy.h>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace amc {

// A level keeps what it changed, not the mesh it leaves (a search undoes tens of levels of a
// large mesh): that mesh is `made` followed by the triangles of the mesh before it that keep
// every vertex (none is a midpoint of `splits`), in their order (mesh_after).
struct DetectedLevel {
    // Every split undone at this level: parent (v0, v1, v2) and midpoints (m0 on v0 -> v1, m1,
    // m2), as vertex ids of the input mesh.
    std::vector<std::array<uint32_t, 6>> splits;
    uint32_t closures = 0;             // green closures merged into their coarse triangle
    std::vector<Triangle> made;        // the splits' parents and the closures' coarse triangles
    size_t triangles_left = 0;         // the size of the mesh this level leaves
};

struct DetectedBase {
    TriangleMesh base;                          // positions copied from the input mesh
    std::vector<uint32_t> leaf_vertex_of_base;  // base vertex i is input vertex leaf_vertex_of_base[i]
    std::vector<DetectedLevel> levels;          // the levels undone, finest first
    bool found_in_reverse = false;              // the levels were found over the input triangles reversed
};

// The mesh that levels [0, count) of `levels` leave of `leaf` (the triangles they were found over,
// in that order; count 0: `leaf` itself), over vertex ids below vertex_count.
std::vector<Triangle> mesh_after(const std::vector<Triangle>& leaf, const std::vector<DetectedLevel>& levels,
                                 size_t count, uint32_t vertex_count);

// Validates `mesh` (validate_triangle_mesh; `what` names it in messages) and finds its base, on
// up to two of `threads` threads (0: every core; the answer does not depend on it).
DetectedBase detect_base(const TriangleMesh& mesh, const std::string& what = "mesh", unsigned threads = 0);

// Whether a search that left `base` of the `leaf` triangles, undoing `levels` levels, is run again
// over the triangles in reverse order (docs/IMPORT.md, "Searched twice"): its base keeps more than
// 1/16 of them (the true bases of the corpus keep at most 3.1 %), and it either undid at least
// 1/10 of them (an adaptive mesh that a few wrong early readings stopped) or nothing at all (one
// wrong growth can hide a whole level). An irregular mesh, where it reads a few small patches
// only, pays no second search.
bool searched_again(size_t base, size_t leaf, size_t levels);

// The base of `mesh` after undoing only its first `levels` detected levels (0: the mesh itself).
DetectedBase truncated(const TriangleMesh& mesh, DetectedBase detected, size_t levels);

namespace detail {

struct CoarserLevel;

// The level that an inverse step's answer (inverse_refinement.h) undid: its splits, closures and the
// triangles it made, which the answer lists first; `coarser` keeps its mesh and flags.
DetectedLevel detected_level(CoarserLevel& coarser);

// The vertices in breadth-first order over the triangles (input ids; unused vertices last). The
// inverse step reads the labels of a vertex's neighbours at every step: numbered this way they
// share cache lines, where a shuffled input's numbering makes each read a miss. The search never
// compares vertex ids, so the numbering changes no result.
std::vector<uint32_t> breadth_first_vertices(const std::vector<Triangle>& triangles, uint32_t vertex_count);

// Every vertex v of `triangles` replaced by id[v].
void renumber(std::vector<Triangle>& triangles, const std::vector<uint32_t>& id);

// The mesh that `level` leaves of `mesh`, the one before it (see DetectedLevel). `removed` is
// scratch, one zero per vertex, given back zeroed; `kept_from` (if given) receives the index in
// `mesh` of each triangle after the made ones.
std::vector<Triangle> mesh_after_level(const std::vector<Triangle>& mesh, const DetectedLevel& level,
                                       std::vector<uint8_t>& removed, std::vector<uint32_t>* kept_from = nullptr);

}  // namespace detail

}  // namespace amc
