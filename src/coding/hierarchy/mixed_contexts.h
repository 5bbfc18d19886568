// The hierarchy coder's mixing mode (.amc version 8, docs/FORMAT.md section 2.1; its second model,
// version 10, section 2.2; its third, version 11, section 2.3; its fourth, version 16, section 2.4; its fifth, version 17,
// section 2.5; its sixth, version 19, section 2.6; its seventh, version 20, section 2.7): each coded symbol's probability comes from adaptive models under
// contexts richer than the paper's groups — the node's structure one level up, its decided
// neighbours and their neighbours, and the decoded geometry around it — mixed by logistic mixing
// (context_mixing.h) and refined by adaptive probability maps. Measured in
// docs/HIERARCHY_CODER.md, "Contexts beyond Table 2".
#pragma once

#include "coding/entropy/arithmetic_coder.h"
#include "coding/hierarchy/context_mixing.h"
#include "coding/hierarchy/level_forest.h"
#include "coding/hierarchy/trained_states.h"

#include <amc/hierarchy.h>

#include <array>
#include <cstdint>
#include <vector>

namespace amc {

// Which model of the mixing mode a stream is coded with: version 8's (FORMAT.md 2.1), version 10's
// (2.2), which adds the last coded bits, bit histories and the curvature of the neighbours,
// version 11's (2.3), which adds the node's size and a Gauss curvature, a fourth mixer and mixers
// that start from trained weights, or version 16's (2.4), which adds the curvatures of a quadric
// through the node's corners and its neighbours' far corners and leaves out seven direct inputs,
// or version 17's (2.5), which adds the local threshold against the coded nodes two rings around,
// or version 19's (2.6), which adds the quadric's means over the node and its neighbours, or
// version 20's (2.7), the sixth whose geometric tables start at trained states.
enum class MixingModel : uint8_t { first = 1, second = 2, third = 3, fourth = 4, fifth = 5, sixth = 6, seventh = 7 };

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
    uint8_t ring_max;     // second model: the largest of mean_curv's value over the node and its neighbours, binned alike
    uint8_t ring_mean;    // second model: their mean, binned alike
    uint8_t size;         // third model: log bin of the longest edge times 2^level over the base's mean longest edge, 0..63
    uint8_t gauss;        // third model: log bin of the neighbours' normals' spread (a Gauss curvature) times the longest edge^2, 0..63
    uint8_t quad_mean;    // fourth model: log bin of |mean curvature| times the longest edge of the quadric through the corners and the neighbours' far corners, 0..63
    uint8_t quad_gauss;   // fourth model: the same of the root of its |Gauss curvature|, 0..63
    // Fifth model, over the same-level nodes one and two edges away whose symbols came before this
    // node's: half-octave bins of mean_curv's value against the least of the refined ones' and the
    // largest of the others' (0..31, 0 for none), and how many of each (at most 7).
    uint8_t thr_refined, thr_unrefined, coded_refined, coded_unrefined;
    // Sixth model: quarter-octave bins of the fourth model's quadric's |mean curvature| and root of
    // |Gauss curvature| times the longest edge, each averaged over the node and its same-level
    // neighbours (0..63), and the fifth model's local threshold on that mean (0..31).
    uint8_t ring_quad_mean, ring_quad_gauss, quad_refined, quad_unrefined;
};

// The unit normals and curvatures of one level's nodes by local index, each computed once: the
// bending features read the normal of every coded node and of its same-level neighbours, so
// without this each normal was computed up to four times (and the second model's ring features
// read the neighbours' curvatures). start_level forgets the previous level's (the decoder reuses
// node ids from stream to stream).
class LevelShapes {
public:
    void start_level(size_t nodes);
    // The unit normal of node `node` (local index `local` of the current level); zero for a
    // degenerate triangle.
    Vec3 normal(const Hierarchy& h, NodeId node, uint32_t local);
    // bend_sum's, mean_curv's and gauss's values before binning (mixed_features): the summed
    // chords between the node's unit normal and its same-level neighbours', a discrete mean
    // curvature of the node times its longest edge (0 for a degenerate triangle), the longest
    // edge, and |det| of the three neighbours' unit normals times the longest edge squared over
    // twice the area (0 without three neighbours or for a degenerate triangle).
    struct Bending {
        double chord_sum, curvature, longest, gauss;
    };
    Bending bending(const Hierarchy& h, NodeId node, uint32_t local, const Level& level);
    // The mean of the roots' longest edges (in root order), computed on first use: the third
    // model's unit of size.
    double base_edge(const Hierarchy& h);
    // The fourth model's quadric_curvatures of node `node` (local index `local`), computed once;
    // `longest` its longest edge if known (else negative).
    std::array<double, 2> quadric(const Hierarchy& h, NodeId node, uint32_t local, double longest = -1) {
        if (local < quadric_.size() && quadric_stamp_[local] == current_) return quadric_[local];
        return new_quadric(h, node, local, longest);
    }
    // Fifth model: node `local` of the level had its symbol coded, with mean_curv's value `curvature`
    // (and, sixth model, ring_quad_mean's value `quad`).
    void mark_coded(uint32_t local, double curvature, double quad = 0) {
        if (local < coded_curvature_.size()) coded_curvature_[local] = curvature, coded_quad_[local] = quad;
    }
    // Per local index of the level, mean_curv's value of a coded node, kUncoded for the others
    // (a value is >= 0 or NaN).
    static constexpr double kUncoded = -1.0;
    const double* coded_curvatures() const { return coded_curvature_.data(); }
    const double* coded_quads() const { return coded_quad_.data(); }

private:
    std::array<double, 2> new_quadric(const Hierarchy& h, NodeId node, uint32_t local, double longest);
    std::vector<Vec3> normal_;
    std::vector<Bending> bending_;
    std::vector<std::array<double, 2>> quadric_;
    std::vector<uint32_t> stamp_, bending_stamp_, quadric_stamp_;
    std::vector<double> coded_curvature_, coded_quad_;  // normal_[i] is this level's when stamp_[i] == current_
    uint32_t current_ = 0;
    double base_edge_ = -1;
};

// The fourth model's quadric (FORMAT.md 2.4): the height over node n's plane that vanishes at n's
// corners and passes through the corner of each same-level neighbour away from n; its |mean
// curvature| and the root of its |Gauss curvature| at second order (the slope left out), each
// times `longest`. {0, 0} without three neighbours or for a degenerate fit.
std::array<double, 2> quadric_curvatures(const Hierarchy& h, NodeId n, double longest);


// The features of node `n` of `h` (coarser levels whole, n's corners placed) that do not depend
// on the traversal, and those that do from the level's state bytes: `i` is n's local index in
// `level`, whose neighbours' states are as decided so far. `shapes` is started on `level`. The
// ring features are computed for the second and later models, size and gauss for the third and
// later, quad_mean and quad_gauss for the fourth and later, the thresholds for the fifth and later
// (which mark n coded in `shapes`), the quadric's ring means for the sixth and seventh (which leave out the
// ring features unless `older_too`: an encoder's features serve every older model as well).
MixedFeatures mixed_features(const Hierarchy& h, NodeId n, const Level& level, uint32_t i, int group, LevelShapes& shapes,
                             MixingModel model, bool older_too = false);

// The models, mixer and probability map of the mixing mode; one per stream, persisting from level
// to level.
class MixedHierarchyModel {
public:
    static constexpr int kInputs = 16;         // the first model's direct models
    static constexpr int kHistoryInputs = 3;   // the second model's direct models of the last coded bits
    static constexpr int kRingInputs = 2;      // and of the neighbours' curvature
    static constexpr int kDirect = kInputs + kHistoryInputs + kRingInputs;
    static constexpr int kIndirectInputs = 3;  // bit histories of three direct contexts
    static constexpr int kSecondInputs = kDirect + kIndirectInputs;
    static constexpr int kMaps = 5;            // the second model's probability maps
    static constexpr int kSizeInputs = 4;      // the third model's direct models of size and Gauss curvature
    static constexpr int kThirdDirect = kDirect + kSizeInputs;
    static constexpr int kThirdInputs = kSecondInputs + kSizeInputs;
    static constexpr int kQuadricInputs = 3;   // the fourth model's direct models of the quadric's curvatures
    static constexpr int kFourthDirect = kThirdDirect + kQuadricInputs;
    static constexpr int kFourthKept = 14;     // the fourth model's direct models of tables 0-20
    static constexpr int kFourthLater = 6;     // and of tables 21-27
    static constexpr int kFourthInputs = kFourthKept + kIndirectInputs + kFourthLater;
    static constexpr int kThresholdInputs = 3;  // the fifth model's direct models of the local threshold
    static constexpr int kFifthDirect = kFourthDirect + kThresholdInputs;
    static constexpr int kFifthKept = 7;        // the fifth model's direct models of tables 0-20
    static constexpr int kFifthLater = 9;       // and of tables 21-30
    static constexpr int kFifthInputs = kFifthKept + kIndirectInputs + kFifthLater;
    static constexpr int kRingQuadricInputs = 4;        // the sixth model's direct models of the quadric's ring means
    static constexpr int kSixthDirect = kFifthDirect + kRingQuadricInputs;
    static constexpr int kSixthKept = 3;         // the sixth model's direct models of tables 0-20
    static constexpr int kSixthLater = 12;       // and of tables 21-34
    static constexpr int kSixthInputs = kSixthKept + kIndirectInputs + kSixthLater;
    // `trained`: the seventh model's initial states (the coder's; bench/trained_states passes others
    // to measure them on models left out of their training).
    explicit MixedHierarchyModel(MixingModel model, const TrainedStateTables& trained = kTrainedStateTables);
    MixingModel model() const { return model_; }
    // The 16-bit probability of a one for a symbol with these features (remembered for update).
    uint32_t p16(const MixedFeatures& f);
    void update(bool bit);
    // The slot of direct table `table` (FORMAT.md's numbers) the last p16 read, for the tables its
    // model reads (bench/trained_states counts the training symbols by it).
    uint32_t slot(int table) const { return slot_[size_t(table)]; }
    // The slots of direct table `table` (0 for a table its model does not read).
    size_t table_size(int table) const { return models_[size_t(table)].size(); }
    // The slots of the first model's direct models for these features (FORMAT.md 2.1).
    static std::array<uint32_t, kInputs> direct_slots(const MixedFeatures& f);

private:
    // The second and third models' probability (FORMAT.md 2.2, 2.3), 12 bits.
    int later_model_p12(const MixedFeatures& f);
    // The fourth, fifth and sixth models' (FORMAT.md 2.4-2.6), 12 bits, and their direct models'
    // update (templates: each model's table lists are constants, as the loops over them are unrolled).
    template <MixingModel kModel>
    int fourth_model_p12(const MixedFeatures& f);
    template <MixingModel kModel>
    void update_fourth_tables(bool bit);
    // The bit histories' inputs into st_ from `first` on (second and later models).
    void history_inputs(uint32_t group, int first);

    MixingModel model_;
    std::array<std::vector<BitModel>, kSixthDirect> models_;
    std::array<uint32_t, kSixthDirect> slot_{};
    // Stretched inputs: the direct models 0-20, the bit histories, the third model's direct
    // models 21-24, then the bias (fourth model: the kept direct models of 0-20, the bit
    // histories, direct models 21-27, the bias).
    std::array<int, mixing::Mixer::padded(kThirdInputs + 1)> st_{};
    // Second model: per context of direct models 1, 4 and 11 its last bits (up to 7, led by a 1),
    // and per such input an adaptive probability of each group x history.
    std::array<std::vector<uint8_t>, kIndirectInputs> histories_;
    std::array<std::vector<BitModel>, kIndirectInputs> history_maps_;
    std::array<uint32_t, kIndirectInputs> history_context_{}, history_map_slot_{};
    uint32_t last_bits_ = 0;  // the stream's coded bits, the newest lowest
    mixing::Mixer mixer_a_, mixer_b_, mixer_c_, mixer_d_;  // FORMAT.md's mixers A, B, C, D (D: third model)
    std::vector<mixing::ProbabilityMap> maps_;
    std::array<int, kMaps> map_context_{};
    int p_mix_ = 2048;
};

}  // namespace amc
