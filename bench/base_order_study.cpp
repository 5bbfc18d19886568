// The mixing mode's hierarchy bytes (seventh model, naive and improved traversal) with the base
// connectivity bytes for several start triangles of the base coder's mode 2 (gate radius 5, no
// search), against the encoder's base (bit-exact): how much a base order chosen for the hierarchy
// could save (docs/HIERARCHY_CODER.md, "The traversal of the mixing mode").
//   base_order_study model.amh [candidates, default 16]
#include "coding/base/base_mesh_coder.h"
#include "coding/base/base_stage.h"
#include "coding/hierarchy/hierarchy_level_coder.h"

#include <amc/codec.h>
#include <amc/hierarchy.h>

#include <cstdio>
#include <cstdlib>
#include <numeric>
#include <utility>
#include <vector>

using namespace amc;

static size_t hierarchy_bytes(const Hierarchy& g, Traversal t) {
    HierarchyCoderOptions o;
    o.traversal = t;
    HierarchyLevelEncoder c(g, o, kHierarchyStreamVersion, nullptr, true, nullptr, nullptr, false);
    ArithmeticEncoder sink;
    for (int l = 0; l < c.level_count(); ++l) c.encode_level(l, sink);
    return sink.finish().size();
}

int main(int argc, char** argv) {
    if (argc < 2) return 2;
    const Hierarchy h = read_hierarchy(argv[1]);
    const int k = argc > 2 ? std::atoi(argv[2]) : 16;
    const TriangleMesh& base = h.base();
    const BaseMeshCode searched = base_code_of(h, nullptr, EncodeOptions{});
    const Hierarchy hs = in_base_code_order(h, searched, false).hierarchy;
    std::printf("encoder base %zu naive %zu improved %zu\n", searched.bytes.size(), hierarchy_bytes(hs, Traversal::naive),
                hierarchy_bytes(hs, Traversal::improved));
    const size_t n = base.triangles.size();
    for (int c = 0; c < k; ++c) {
        const size_t t = size_t(c) * n / size_t(k);
        std::vector<uint32_t> perm(n);
        std::iota(perm.begin(), perm.end(), 0u);
        std::swap(perm[0], perm[t]);
        TriangleMesh m = base;
        for (size_t i = 0; i < n; ++i) m.triangles[i] = base.triangles[perm[i]];
        BaseMeshCode code;
        try {
            code = encode_base_connectivity(m, BaseConnectivityMode::angle, false);
        } catch (const std::exception& e) {
            std::printf("start %zu: %s\n", t, e.what());
            continue;
        }
        for (uint32_t& o : code.triangle_order) o = perm[o];
        const Hierarchy g = in_base_code_order(h, code, false).hierarchy;
        std::printf("start %zu base %zu naive %zu improved %zu\n", t, code.bytes.size(), hierarchy_bytes(g, Traversal::naive),
                    hierarchy_bytes(g, Traversal::improved));
        std::fflush(stdout);
    }
    return 0;
}
