#include "import/leaf_halfedges.h"

namespace amc {

LeafHalfedges::LeafHalfedges(const TriangleMesh& mesh) {
    const uint32_t n = uint32_t(mesh.positions.size());
    start_.assign(size_t(n) + 2, 0);
    for (const Triangle& t : mesh.triangles) {
        for (uint32_t v : t) ++start_[v + 2];
    }
    for (size_t v = 2; v < start_.size(); ++v) start_[v] += start_[v - 1];
    entries_.reset(new Entry[mesh.triangles.size() * 3]);
    for (uint32_t f = 0; f < mesh.triangles.size(); ++f) {
        const Triangle& t = mesh.triangles[f];
        for (int i = 0; i < 3; ++i) entries_[start_[t[i] + 1]++] = {t[(i + 1) % 3], t[(i + 2) % 3], f};
    }
    start_.pop_back();
}

}  // namespace amc
