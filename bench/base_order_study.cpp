// The base order as an encoder choice (docs/HIERARCHY_CODER.md, "The base order as an encoder
// choice"): for the base coder's order and the orders of base_order_candidates() (mode 2 from N
// start triangles), the whole file's parts at effort 2 in the asked hierarchy mode, the paper
// mode's file in the same order, and the base blocks' bytes (base_blocks_bytes: what efforts 3 and
// 4 rank the orders by).
//   base_order_study model.amh [starts, default 16] [mixed|paper, default mixed] [quantize bits, default 0]
//                    [starts|rotations|radii, default starts]
#include "coding/base/base_stage.h"
#include "coding/base_order_search.h"
#include "coding/geometry/float_coder.h"

#include <amc/codec.h>
#include <amc/hierarchy.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

using namespace amc;

int main(int argc, char** argv) {
    if (argc < 2) return 2;
    const Hierarchy h = read_hierarchy(argv[1]);
    const uint32_t starts = argc > 2 ? uint32_t(std::atoi(argv[2])) : kBaseOrderSearches[0].starts;
    EncodeOptions options;
    options.effort = kMaxGeometryEffort;
    if (argc > 3 && std::strcmp(argv[3], "paper") == 0) options.hierarchy_contexts = HierarchyContexts::paper;
    else options.hierarchy_contexts = HierarchyContexts::mixed;
    options.quantize_bits = argc > 4 ? std::atoi(argv[4]) : 0;
    EncodeOptions paper = options;
    paper.hierarchy_contexts = HierarchyContexts::paper;
    const std::vector<uint8_t> reference = encode(h, options);
    std::printf("order base_conn base_geom hierarchy geometry file paper_hierarchy paper_file base_blocks\n");
    // The base coder codes a quantized file's base on its grid (encode()'s, for a forest without free ids).
    Quantizer grid;
    if (options.quantize_bits != 0) grid = make_quantizer(h.positions(), options.quantize_bits);
    const Quantizer* q = options.quantize_bits != 0 ? &grid : nullptr;
    const TriangleMesh base = base_as_decoded(h, q);
    auto row = [&](const char* name, const BaseMeshCode& code) {
        EncodeStats s, p;
        const std::vector<uint8_t> file = encode_with_base(h, options, code, &s);
        encode_with_base(h, paper, code, &p);
        std::printf("%s %llu %llu %llu %llu %zu %llu %llu %llu\n", name, (unsigned long long)s.base_connectivity_bytes,
                    (unsigned long long)s.base_geometry_bytes, (unsigned long long)s.hierarchy_bytes,
                    (unsigned long long)s.geometry_bytes, file.size(), (unsigned long long)p.hierarchy_bytes,
                    (unsigned long long)p.total_bytes, (unsigned long long)base_blocks_bytes(base, q, code));
        std::fflush(stdout);
        return file;
    };
    const BaseMeshCode own = base_code_of(h, q, options);
    if (row("own", own) != reference) std::printf("(own order's file differs from encode()'s)\n");
    // `rotations` / `radii` (bit-exact only): each start also from its other corners / with gate
    // radii 3, 4, 6 and 7, the base coder's other candidates, not deduplicated.
    const std::string kind = argc > 5 ? argv[5] : "starts";
    if (kind == "rotations" || kind == "radii") {
        const size_t n = h.base().triangles.size();
        for (uint32_t k = 0; k < starts; ++k)
            for (const uint32_t variant : kind == "rotations" ? std::vector<uint32_t>{0, 1, 2} : std::vector<uint32_t>{5, 3, 4, 6, 7}) {
                BaseStart start;
                start.first = uint32_t(uint64_t{k} * n / starts);
                (kind == "rotations" ? start.rotation : start.radius) = variant;
                char name[48];
                std::snprintf(name, sizeof name, "start%u.%s%u", k, kind == "rotations" ? "rotation" : "radius", variant);
                try {
                    row(name, encode_base_connectivity(h.base(), start));
                } catch (const Error&) {
                    std::printf("%s does not fit mode 2\n", name);
                }
            }
        return 0;
    }
    int k = 0;
    for (const BaseMeshCode& code : base_order_candidates(base, own, starts)) {
        char name[32];
        std::snprintf(name, sizeof name, "start%d", k++);
        row(name, code);
    }
    return 0;
}
