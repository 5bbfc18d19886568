// The grid of a quantized file written by ranks (rank_grid.h).
#include "coding/distributed/rank_grid.h"

#include "common/check.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace amc {

namespace {

double axis_of(Vec3 p, int axis) { return axis == 0 ? p.x : axis == 1 ? p.y : p.z; }

bool key_before(const uint64_t (&a)[3], const uint64_t (&b)[3]) { return std::lexicographical_compare(a, a + 3, b, b + 3); }

// Takes p, the vertex of canonical key `key`, into the box; vertices come in canonical order, so
// a tie keeps the first.
void take(RankBox& box, Vec3 p, uint64_t level, uint64_t root, uint64_t ordinal) {
    for (int axis = 0; axis < 3; ++axis) {
        const double x = axis_of(p, axis);
        if (x < box.lo[axis]) {
            box.lo[axis] = x;
            box.lo_key[axis][0] = level;
            box.lo_key[axis][1] = root;
            box.lo_key[axis][2] = ordinal;
        }
        box.hi[axis] = std::max(box.hi[axis], x);
    }
}

Vec3 snapped(const Quantizer& grid, Vec3 p) { return dequantize(grid, snap_to_grid(grid, p)); }

}  // namespace

RankBox rank_box(const TriangleMesh& base, const RankChunk& part) {
    RankBox box;
    for (int axis = 0; axis < 3; ++axis) {
        box.lo[axis] = std::numeric_limits<double>::infinity();
        box.hi[axis] = -std::numeric_limits<double>::infinity();
        std::fill_n(box.lo_key[axis], 3, std::numeric_limits<uint64_t>::max());
    }
    for (size_t v = 0; v < base.positions.size(); ++v) take(box, base.positions[v], 0, 0, v);
    // The midpoints in canonical order: level by level, each node's edges in order, a vertex at its
    // first node.
    const Hierarchy& h = part.chunk;
    std::vector<bool> seen(h.positions().size(), false);
    uint64_t ordinal = 0;
    for (NodeId n : h.breadth_first_order()) {
        if (h.is_leaf(n)) continue;
        for (int e = 0; e < 3; ++e) {
            const VertexId m = h.midpoint(n, e);
            if (seen[m]) continue;
            seen[m] = true;
            take(box, h.position(m), uint64_t(h.level(n)) + 1, part.first_root, ordinal++);
        }
    }
    return box;
}

Quantizer grid_of_ranks(const std::vector<RankBox>& boxes, int bits, const std::string& what) {
    AMC_REQUIRE(!boxes.empty(), invalid_input, what + ": no rank's box");
    RankBox whole = boxes.front();
    for (const RankBox& box : boxes) {
        for (int axis = 0; axis < 3; ++axis) {
            // == holds for +0 and -0: the first in canonical order decides, as in the serial encoder.
            const bool lower = box.lo[axis] < whole.lo[axis] ||
                               (box.lo[axis] == whole.lo[axis] && key_before(box.lo_key[axis], whole.lo_key[axis]));
            if (lower) {
                whole.lo[axis] = box.lo[axis];
                std::copy_n(box.lo_key[axis], 3, whole.lo_key[axis]);
            }
            whole.hi[axis] = std::max(whole.hi[axis], box.hi[axis]);
        }
    }
    try {
        return make_quantizer(Vec3{whole.lo[0], whole.lo[1], whole.lo[2]}, Vec3{whole.hi[0], whole.hi[1], whole.hi[2]}, bits);
    } catch (const Error& e) {
        throw_error(ErrorCode::invalid_input, what + ": " + e.what() +
                                                  " (positions that span more than the double range can only be stored bit-exact)");
    }
}

double snap_to_grid(RankChunk& part, const Quantizer& grid) {
    Hierarchy& h = part.chunk;
    h.set_single_precision(false);
    double error = 0;
    for (VertexId v = 0; v < h.positions().size(); ++v) {
        const Vec3 p = h.position(v), q = snapped(grid, p);
        error = std::max({error, std::abs(p.x - q.x), std::abs(p.y - q.y), std::abs(p.z - q.z)});
        h.set_position(v, q);
    }
    return error;
}

TriangleMesh snapped_base(const TriangleMesh& base, const Quantizer& grid) {
    TriangleMesh out = base;
    out.single_precision = false;
    for (Vec3& p : out.positions) p = snapped(grid, p);
    return out;
}

void snap_to_grid(std::vector<SeamSplit>& splits, const Quantizer& grid) {
    for (SeamSplit& split : splits) split.position = snapped(grid, split.position);
}

}  // namespace amc
