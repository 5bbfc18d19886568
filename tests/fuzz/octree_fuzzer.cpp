// Fuzz target of the octree file (.amq): decode whole and a prefix of its levels, on the input as it
// is and with its checksums made valid. What decodes is a valid forest, its prefix is the forest
// coarsened to that level, and it encodes again into a file that decodes to the same forest.
#include "fuzz_targets.h"

#include <amc/octree.h>

#include <algorithm>

namespace amc::fuzz {
namespace {

constexpr uint64_t kMaxOctants = uint64_t(1) << 16;  // keeps runs short

// The leaves of `forest` with every octant finer than `level` replaced by its ancestor of that level.
std::vector<Octant> coarsened(const OctreeForest& forest, int level, std::vector<uint64_t>& offsets) {
    const int shift = octree_root_log2(forest.dim()) - level;
    const int32_t mask = ~((int32_t(1) << shift) - 1);
    std::vector<Octant> out;
    offsets.assign(1, 0);
    for (uint32_t t = 0; t < forest.tree_count(); ++t) {
        const size_t first = out.size();
        for (uint64_t i = forest.tree_offsets[t]; i < forest.tree_offsets[t + 1]; ++i) {
            Octant o = forest.leaves[i];
            if (o.level > level) o = {o.x & mask, o.y & mask, o.z & mask, int8_t(level)};
            if (out.size() == first || !(out.back() == o)) out.push_back(o);  // Morton order: descendants are adjacent
        }
        offsets.push_back(out.size());
    }
    return out;
}

void decode_file(const uint8_t* data, size_t size) {
    OctreeDecodeOptions options;
    options.max_nodes = kMaxOctants;
    OctreeForest forest;
    try {
        forest = decode_octree_forest(data, size, options);
    } catch (const Error&) {
        options.max_level = int(size % 4);  // refused whole, its first levels may still decode
        try {
            decode_octree_forest(data, size, options);
        } catch (const Error&) {
        }
        return;
    }
    validate_octree_forest(forest, "decoded");  // throws: a finding
    const int depth = count_octree_forest(forest).depth;
    {
        options.max_level = int(size % size_t(depth + 1));
        const OctreeForest prefix = decode_octree_forest(data, size, options);  // throws: a finding
        std::vector<uint64_t> offsets;
        const std::vector<Octant> expected = coarsened(forest, options.max_level, offsets);
        FUZZ_CHECK(prefix.leaves == expected);
        FUZZ_CHECK(prefix.tree_offsets == offsets);
    }
    // What the decoder accepts the encoder accepts (an unbalanced forest without culling by
    // balance), with the switches chosen by the input, and the file decodes to the same forest.
    OctreeEncodeOptions again;
    again.cull_by_balance = octree_balance_violation(forest, OctreeBalance::face).empty();
    const uint8_t bits = size > 0 ? data[size - 1] : 0;
    again.uniform_levels = bits & 1;
    again.truncate = bits & 2;
    again.context_groups = bits & 4;
    again.improved_traversal = bits & 8;
    const std::vector<uint8_t> file = encode_octree_forest(forest, again);
    FUZZ_CHECK(decode_octree_forest(file.data(), file.size()) == forest);
}

}  // namespace

void octree_decode(const uint8_t* data, size_t size) {
    decode_file(data, size);
    const std::vector<uint8_t> repaired = with_valid_checksums(data, size);
    if (!std::equal(repaired.begin(), repaired.end(), data)) decode_file(repaired.data(), repaired.size());
}

}  // namespace amc::fuzz
