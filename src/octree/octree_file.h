// The .amq file (docs/FORMAT.md section 8): the .amc framing (header, checksummed blocks) with its
// own magic, version and blocks; the metadata and the coarse mesh, written and read with every
// count checked before use.
#pragma once

#include "coding/container.h"

#include <amc/octree.h>

#include <cstdint>
#include <vector>

namespace amc {

// Versions (FORMAT.md 8): a file takes the lowest version that holds what it holds.
constexpr uint8_t kOctreeBaseVersion = 1;      // forests alone, vertices as float64
constexpr uint8_t kOctreeLeafDataVersion = 2;  // + leaf field blocks, quantized vertices
constexpr uint8_t kOctreeNewestVersion = 2;

// Block types of the .amq file: frozen values.
enum class OctreeBlock : uint8_t { end = 0, metadata = 1, connectivity = 2, level = 3, leaf_field = 4 };

extern const FileFraming kOctreeFraming;

// Connectivity block modes: frozen values.
enum class OctreeConnectivityMode : uint8_t {
    glued_by_vertices = 0,  // vertices and tree_to_vertex; the gluing is connectivity_from_vertices'
    explicit_with_vertices = 1,
    explicit_without_vertices = 2,
    brick = 3,  // brick_connectivity(dim, nx, ny, nz, periodic...): sizes and periodicity only
    // Version 2: modes 0 and 1 with the positions on a grid (a step, then grid differences).
    glued_by_quantized_vertices = 4,
    explicit_with_quantized_vertices = 5,
};

struct OctreeMetadata {
    int dim = 2;
    uint64_t trees = 0, octants = 0, leaves = 0, levels = 0;
    uint8_t switches = 0;
    int uniform_levels = 0;
    uint64_t count = 0;  // coded symbols, when truncating
};

std::vector<uint8_t> write_octree_metadata(const OctreeMetadata& m);
// Checks ranges (dimension, switches, levels, U) and the octant limit.
OctreeMetadata read_octree_metadata(const uint8_t* data, size_t size, uint64_t max_octants);

// vertex_step > 0: positions snapped to multiples of it (a quantized mode, version 2) unless the
// connectivity is a brick. Throws Error on a step that is not finite and positive or that gives
// grid indices beyond 2^52.
std::vector<uint8_t> write_octree_connectivity(const TreeConnectivity& conn, double vertex_step = 0);
bool is_quantized_connectivity(const std::vector<uint8_t>& payload);
// The connectivity of `trees` trees of dimension `dim` in a file of `version`, validated.
TreeConnectivity read_octree_connectivity(const uint8_t* data, size_t size, int dim, uint64_t trees, uint8_t version);

}  // namespace amc
