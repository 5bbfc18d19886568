// Inter-frame connectivity of a forest series (docs/FORMAT.md 7.11): a frame's quadtree/octree
// forest coded level by level in the .amq coder's order (octree_traversal.h: the rules first,
// then the priority traversal), one "refined?" symbol per octant the rules leave open, in a
// context that knows the previous frame's forest (was the octant there, a leaf, refined with leaf
// children or deeper; how many of its neighbours were refined there; how many decided neighbours
// and how many of its parent's neighbours changed). Keyframes use the .amq contexts alone.
#pragma once

#include "coding/entropy/arithmetic_coder.h"
#include "octree/octree_levels.h"

#include <amc/octree.h>

#include <cstdint>
#include <vector>

namespace amc {

// Models: carried from frame to frame, fresh after a keyframe.
struct ForestConnectivityModels {
    // previous class (4) x neighbours refined there (none, some, all: 3) x decided neighbours
    // that changed (0, 1, 2+) x decided neighbours refined now (0, 1, 2+) x parent's neighbours
    // changed (2)
    static constexpr int kInterContexts = 4 * 3 * 3 * 3 * 2;
    std::vector<BitModel> inter = std::vector<BitModel>(kInterContexts);
    std::vector<BitModel> key;  // octree_model_count(dim), for keyframes
};

// Switches byte of a frame's connectivity section: frozen values.
constexpr uint8_t kForestCullByBalance = 1;  // the .amq coder's balance rule (a face-balanced forest)

struct ForestConnectivityStats {
    uint64_t coded = 0, culled = 0;
};

// Codes `forest`'s refinement against `prev` (null: a keyframe, coded alone) with `models`
// (updated). Writes the switches byte and the arithmetic stream into `out`. Returns the forest's
// levels. `forest` must be valid (validate_octree_forest).
OctreeLevels encode_forest_connectivity(const OctreeLevels* prev, const OctreeForest& forest, ForestConnectivityModels& models,
                                        std::vector<uint8_t>& out, ForestConnectivityStats* stats = nullptr);

// Decodes the levels of a forest over `conn` from a connectivity section (switches byte and
// stream) of `size` bytes. Throws Error (corrupt, truncated) on a section no encoder writes, or
// one that builds other than `octants` octants.
OctreeLevels decode_forest_connectivity(const TreeConnectivity& conn, const OctreeLevels* prev, ForestConnectivityModels& models,
                                        const uint8_t* data, size_t size, uint64_t octants);

// Octants of `next` with no octant at the same place in `prev`, plus the other way round.
uint64_t changed_octants(const OctreeLevels& prev, const OctreeLevels& next);

}  // namespace amc
