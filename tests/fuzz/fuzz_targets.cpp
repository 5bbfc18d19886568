// The list of targets and what they share.
#include "fuzz_targets.h"

#include <xxhash.h>

#include <cstdio>
#include <cstdlib>

namespace amc::fuzz {

const std::vector<Target>& targets() {
    static const std::vector<Target> all = {
        {"amc_decode", amc_decode},
        {"amc_inspect", amc_inspect},
        {"amh_read", amh_read},
        {"hierarchy_stream", hierarchy_stream},
        {"base_connectivity", base_connectivity},
        {"geometry", geometry},
        {"obj_read", obj_read},
        {"off_read", off_read},
        {"ply_read", ply_read},
        {"vtu_read", vtu_read},
        {"round_trip", round_trip},
        {"series_read", series_read},
        {"forest_series_read", forest_series_read},
        {"octree_decode", octree_decode},
        {"leaf_import", leaf_import},
        {"closest_point", closest_point},
        {"nearest_vertex", nearest_vertex},
    };
    return all;
}

void violated(const char* what, const char* file, int line) {
    std::fprintf(stderr, "fuzz property violated: %s (%s:%d)\n", what, file, line);
    std::abort();
}

namespace {

uint32_t get_u32(const uint8_t* p) {
    return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}

void put_u32(uint8_t* p, uint32_t v) {
    for (int i = 0; i < 4; ++i) p[i] = uint8_t(v >> (8 * i));
}

}  // namespace

// The framing of docs/FORMAT.md, 3.1 and 3.2 (7.1 and 8.1 for .amcs and .amq): a header whose last
// four bytes are the XXH32 of the others, then blocks of type, length, payload and XXH32 of those.
std::vector<uint8_t> with_valid_checksums(const uint8_t* data, size_t size, size_t header_size) {
    std::vector<uint8_t> out(data, data + size);
    if (size < header_size) return out;
    put_u32(out.data() + header_size - 4, XXH32(out.data(), header_size - 4, 0));
    size_t pos = header_size;
    while (size - pos >= 9) {
        const uint32_t length = get_u32(out.data() + pos + 1);
        if (length > size - pos - 9) break;
        put_u32(out.data() + pos + 5 + length, XXH32(out.data() + pos, 5 + size_t(length), 0));
        pos += 9 + size_t(length);
    }
    return out;
}

void refine_at_random(Hierarchy& h, ByteReader& in, uint32_t max_nodes, int max_level, bool flip_diagonals) {
    const int operations = in.u8() % 64;
    for (int i = 0; i < operations && h.node_count() < max_nodes; ++i) {
        const NodeId n = in.u32() % h.node_capacity();
        const uint8_t op = in.u8();
        if (!h.is_alive(n)) continue;
        if (op % 4 != 0) {
            if (h.is_leaf(n) && h.level(n) < max_level) h.refine(n);
        } else if (!h.is_leaf(n)) {
            h.coarsen(n);
        }
    }
    for (NodeId n = 0; n < h.node_capacity(); ++n) {
        if (h.is_alive(n) && h.is_leaf(n) && h.hanging_node_count(n) == 2 && flip_diagonals && (in.u8() & 1))
            h.set_diagonal_flipped(n, true);
    }
}

}  // namespace amc::fuzz
