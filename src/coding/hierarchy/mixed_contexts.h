// The hierarchy coder's mixing mode (.amc version 8, docs/FORMAT.md section 2.1): each coded
// symbol's probability comes from twelve adaptive models under contexts richer than the paper's
// groups — the node's structure one level up, its decided neighbours and their neighbours, and
// the decoded geometry around it — mixed by logistic mixing (context_mixing.h) and refined by an
// adaptive probability map. Measured in docs/HIERARCHY_CODER.md, "Contexts beyond Table 2".
#pragma once

#include "coding/entropy/arithmetic_coder.h"
#include "coding/hierarchy/context_mixing.h"
#include "coding/hierarchy/level_forest.h"

#include <amc/hierarchy.h>

#include <array>
#include <cstdint>
#include <vector>

namespace amc {

// What the decoder knows of a node when its symbol comes.
struct MixedFeatures {
    uint8_t group;        // the paper's context group, 0..9
    uint8_t inner;        // outer child: its edge to the center sibling 0 refined, 1 not, 2 undecided; else 3
    uint8_t ring2;        // decided refined nodes among the neighbours' other neighbours, at most 4
    uint8_t level;        // min(level, 7)
    uint8_t center;       // 1 for a center child
    uint8_t parent_nbrs;  // refined neighbours of the parent, 0..3 (0 for a root)
    uint8_t parent_far;   // outer child: the parent's neighbour away from its corner 0 refined, 1 not; else 2
    uint8_t parent_sibs;  // refined siblings of the parent, 0..3
    uint8_t disp;         // log bin of the largest relative displacement of the parent's midpoints on the node, 0..23
    uint8_t disp_parent;  // the same over the parent's three midpoints
    uint8_t bend_sum;     // log bin of the summed normal chords to the same-level neighbours, 0..31
    uint8_t mean_curv;    // log bin of a discrete mean curvature times the longest edge, 0..63
};

// The unit normals of one level's nodes by local index, each computed once: the bending features
// read the normal of every coded node and of its same-level neighbours, so without this each
// normal was computed up to four times. start_level forgets the previous level's (the decoder
// reuses node ids from stream to stream).
class LevelNormals {
public:
    void start_level(size_t nodes);
    // The unit normal of node `node` (local index `local` of the current level); zero for a
    // degenerate triangle.
    Vec3 get(const Hierarchy& h, NodeId node, uint32_t local);

private:
    std::vector<Vec3> normal_;
    std::vector<uint32_t> stamp_;  // normal_[i] is this level's when stamp_[i] == current_
    uint32_t current_ = 0;
};

// The features of node `n` of `h` (coarser levels whole, n's corners placed) that do not depend
// on the traversal, and those that do from the level's state bytes: `i` is n's local index in
// `level`, whose neighbours' states are as decided so far. `normals` is started on `level`.
MixedFeatures mixed_features(const Hierarchy& h, NodeId n, const Level& level, uint32_t i, int group, LevelNormals& normals);

// The models, mixer and probability map of the mixing mode; one per stream, persisting from level
// to level.
class MixedHierarchyModel {
public:
    static constexpr int kInputs = 16;
    MixedHierarchyModel();
    // The 16-bit probability of a one for a symbol with these features (remembered for update).
    uint32_t p16(const MixedFeatures& f);
    void update(bool bit);

private:
    std::array<std::vector<BitModel>, kInputs> models_;
    std::array<uint32_t, kInputs> slot_{};
    std::array<int, kInputs + 1> st_{};
    mixing::Mixer mixer_, by_level_, by_displacement_;
    mixing::ProbabilityMap apm_;
    int p_mix_ = 2048;
};

}  // namespace amc
