#include "import/leaf_halfedges.h"

#include "common/huge_pages.h"

namespace amc {

LeafHalfedges::LeafHalfedges(const TriangleMesh& mesh) {
    if (mesh.triangles.size() >= kApexIsEnd) throw Error("leaf mesh: too many faces");
    const uint32_t n = uint32_t(mesh.positions.size());
    start_.assign(size_t(n) + 2, 0);
    for (const Triangle& t : mesh.triangles) {
        for (uint32_t v : t) ++start_[v + 2];
    }
    for (size_t v = 2; v < start_.size(); ++v) start_[v] += start_[v - 1];
    entries_.reset(new Entry[mesh.triangles.size() * 3]);
    // Read at random (a shuffled mesh): on huge pages a lookup misses the cache, not the TLB too.
    advise_huge_pages(entries_.get(), mesh.triangles.size() * 3 * sizeof(Entry));
    for (uint32_t f = 0; f < mesh.triangles.size(); ++f) {
        const Triangle& t = mesh.triangles[f];
        for (int i = 0; i < 3; ++i) entries_[start_[t[i] + 1]++] = {t[(i + 1) % 3], t[(i + 2) % 3], f};
    }
    start_.pop_back();
    // Which apexes are also out-edge ends (all of them in a closed fan): for_each_neighbor_once.
    for (uint32_t u = 0; u < n; ++u) {
        Entry* const first = entries_.get() + start_[u];
        Entry* const last = entries_.get() + start_[u + 1];
        for (Entry* e = first; e != last; ++e) {
            const uint32_t apex = e->apex;
            const Entry* j = first;
            while (j != last && j->to != apex) ++j;
            if (j != last) e->face |= kApexIsEnd;
        }
    }
}

}  // namespace amc
