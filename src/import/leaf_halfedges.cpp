#include "import/leaf_halfedges.h"

#include "common/huge_pages.h"

#include <algorithm>
#include <vector>

namespace amc {

LeafHalfedges::LeafHalfedges(const TriangleMesh& mesh) {
    if (mesh.triangles.size() >= kApexIsEnd) throw Error("leaf mesh: too many faces");
    const uint32_t n = uint32_t(mesh.positions.size());
    slots_.assign(size_t(n) + 2, Slot{0, 0});
    for (const Triangle& t : mesh.triangles) {
        for (uint32_t v : t) ++slots_[v + 2].start;
    }
    for (size_t v = 2; v < slots_.size(); ++v) slots_[v].start += slots_[v - 1].start;
    entries_.reset(new Entry[mesh.triangles.size() * 3]);
    // Read at random (a shuffled mesh): on huge pages a lookup misses the cache, not the TLB too.
    advise_huge_pages(entries_.get(), mesh.triangles.size() * 3 * sizeof(Entry));
    for (uint32_t f = 0; f < mesh.triangles.size(); ++f) {
        const Triangle& t = mesh.triangles[f];
        for (int i = 0; i < 3; ++i) entries_[slots_[t[i] + 1].start++] = {t[(i + 1) % 3], t[(i + 2) % 3], f};
    }
    slots_.pop_back();
    // Which apexes are also out-edge ends (all of them in a closed fan): for_each_neighbor_once.
    // u's ends are stamped with u: each apex is tested with one read, not a search of the list.
    std::vector<uint32_t> end_of(n, kNoIndex);  // the last vertex seen with this one as an out-edge end
    for (uint32_t u = 0; u < n; ++u) {
        Entry* const first = entries_.get() + slots_[u].start;
        Entry* const last = entries_.get() + slots_[u + 1].start;
        // find bisects a large fan (docs/FUZZING.md); equal ends keep their order, so it finds the
        // entry a scan would.
        if (last - first > kScanned) std::stable_sort(first, last, [](const Entry& x, const Entry& y) { return x.to < y.to; });
        uint32_t ends = 0;
        for (Entry* e = first; e != last; ++e) {
            end_of[e->to] = u;
            ends |= end_bit(e->to);
        }
        slots_[u].ends = ends;
        for (Entry* e = first; e != last; ++e) {
            if (end_of[e->apex] == u) e->face |= kApexIsEnd;
        }
    }
}

}  // namespace amc
