// How the coarse mesh glues its trees: the face corner permutation an orientation stands for, and
// the map of integer coordinates from one tree into its neighbour across a face. Used by the
// connectivity checks, neighbour finding, balance and the coder; the one place that knows p4est's
// orientation rule.
#pragma once

#include <amc/octree.h>

#include <array>
#include <cstdint>
#include <vector>

namespace amc {

// Face corner i of one face touches face corner perm[i] of the other (2 corners in 2D, 4 in 3D).
using FaceCornerPerm = std::array<uint8_t, 4>;

// The permutation of face f glued to face nf with p4est orientation o, or false when o is out of
// range. In 3D, of the 8 symmetries of a square the 4 that glue right-handed trees are left, one
// per orientation (p4est's p8est_face_permutations); in 2D the orientation is the permutation.
bool face_corner_perm(int dim, int f, int nf, int orientation, FaceCornerPerm& perm);
// The orientation p4est writes for face f glued to nf with permutation perm, or -1 when (3D) no
// gluing of right-handed trees has that permutation.
int face_orientation(int dim, int f, int nf, const FaceCornerPerm& perm);

// Across face `face` of a tree: where its coordinates go.
struct FaceGlue {
    uint32_t tree = 0;      // the neighbour tree
    uint8_t face = 0;       // the neighbour's face
    bool boundary = true;   // glued to itself: nothing across
    uint8_t axis_to[3] = {0, 1, 2};  // my axis -> the neighbour's axis (my normal -> its normal)
    bool flip[3] = {false, false, false};  // tangential axes that run backwards there
};

class TreeFaces {
public:
    TreeFaces() = default;
    // `conn` must be valid (validate_connectivity).
    explicit TreeFaces(const TreeConnectivity& conn);

    int dim() const { return dim_; }
    const FaceGlue& glue(uint32_t tree, int face) const { return glue_[size_t(tree) * 2 * dim_ + face]; }

    // Moves coordinates c (at `level`, possibly outside the tree by one octant on some axes) into
    // the tree they lie in, crossing one face per axis that is out of range, lowest axis first.
    // False when a crossing meets the boundary.
    bool wrap(uint32_t& tree, int level, int32_t c[3]) const {
        const int32_t n = int32_t(1) << level;
        for (int step = 0; step < dim_; ++step) {
            int a = 0;
            while (a < dim_ && c[a] >= 0 && c[a] < n) ++a;
            if (a == dim_) return true;
            const int face = 2 * a + (c[a] >= n ? 1 : 0);
            const FaceGlue& g = glue(tree, face);
            if (g.boundary) return false;
            const int32_t outside = c[a] < 0 ? -c[a] : c[a] - (n - 1);  // 1 for a face neighbour
            int32_t out[3] = {0, 0, 0};
            out[g.axis_to[a]] = (g.face & 1) ? n - outside : outside - 1;
            for (int k = 0; k < dim_; ++k) {
                if (k == a) continue;
                out[g.axis_to[k]] = g.flip[k] ? n - 1 - c[k] : c[k];
            }
            c[0] = out[0], c[1] = out[1], c[2] = out[2];
            tree = g.tree;
        }
        int a = 0;
        while (a < dim_ && c[a] >= 0 && c[a] < n) ++a;
        return a == dim_;
    }

private:
    int dim_ = 2;
    std::vector<FaceGlue> glue_;
};

}  // namespace amc
