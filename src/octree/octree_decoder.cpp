// .amq file -> octree forest (docs/FORMAT.md section 8.5): the mirror of octree_encoder.cpp, with
// every count checked before it is used.
#include "coding/entropy/arithmetic_coder.h"
#include "common/check.h"
#include "octree/octree_file.h"
#include "octree/octree_leaf_data.h"
#include "octree/octree_traversal.h"

#include <set>
#include <string>

namespace amc {

namespace {

Block next_block(BlockReader& reader) {
    Block block{};
    AMC_REQUIRE(reader.next(block), truncated, "file ends before its end block");
    return block;
}

Block next_block(BlockReader& reader, OctreeBlock expected) {
    const Block block = next_block(reader);
    AMC_REQUIRE(uint8_t(block.type) == uint8_t(expected), corrupt,
                "block at byte " + std::to_string(block.offset) + ": expected a " +
                    kOctreeFraming.block_name(uint8_t(expected)) + " block, found a " + kOctreeFraming.block_name(uint8_t(block.type)) +
                    " block");
    return block;
}

}  // namespace

void check_octree_file_start(const uint8_t* data, size_t size) {
    const BlockReader header(data, size, kOctreeFraming);  // decode_octree_forest's first check
    (void)header;
}

OctreeForest decode_octree_forest(const uint8_t* data, size_t size, const OctreeDecodeOptions& options) {
    return with_allocation_errors_as_limits("decode_octree_forest", [&]() {
        BlockReader reader(data, size, kOctreeFraming);
        Block block = next_block(reader, OctreeBlock::metadata);
        const OctreeMetadata meta = read_octree_metadata(block.payload, block.size, options.max_nodes);
        // FORMAT.md 8.5, Bounds: the bytes after the metadata back the octants, whose memory (about
        // 50 bytes each) would otherwise grow without them (uniform levels, truncation, bricks).
        const uint64_t per_byte = options.max_octants_per_byte;
        const uint64_t after = reader.remaining();
        AMC_REQUIRE(per_byte == 0 || meta.octants / per_byte + (meta.octants % per_byte != 0) <= after, limit_exceeded,
                    "metadata block: " + std::to_string(meta.octants) + " octants in the " + std::to_string(after) +
                        " bytes after it, more than the limit of " + std::to_string(per_byte) +
                        " octants per byte (OctreeDecodeOptions::max_octants_per_byte)");
        block = next_block(reader, OctreeBlock::connectivity);
        const TreeConnectivity conn = read_octree_connectivity(block.payload, block.size, meta.dim, meta.trees, reader.version());

        OctreeLevels levels(conn);
        std::vector<BitModel> models(octree_model_count(meta.dim));
        OctreeTraversal traversal;
        OctreeLevelFates fates;
        uint64_t read = 0;
        const bool truncating = meta.switches & kOctreeTruncate;
        for (int l = 0; l < int(meta.levels); ++l) {
            block = next_block(reader, OctreeBlock::level);
            if (options.max_level >= 0 && l >= options.max_level) return levels.leaves(conn);  // progressive: levels 0 .. l
            ArithmeticDecoder decoder(block.payload, block.size);
            decide_octree_level(l > 0 ? &levels.level(l - 1) : nullptr, levels.level(l), l, meta.dim, meta.switches, meta.uniform_levels, traversal,
                                [&](uint32_t, int model) {
                                    if (truncating && read == meta.count) return false;
                                    ++read;
                                    return decoder.decode(models[model]);
                                },
                                fates);
            AMC_REQUIRE(!decoder.overran(), truncated, "level block " + std::to_string(l) + ": the symbols run past its end");
            std::vector<uint8_t>& refined = traversal.state;
            uint64_t refined_count = 0;
            for (uint8_t& s : refined) {
                s = s == kDecidedRefined;
                refined_count += s;
            }
            if (l + 1 == int(meta.levels)) {
                AMC_REQUIRE(refined_count == 0, corrupt, "the last level block refines " + std::to_string(refined_count) + " octants");
                break;
            }
            AMC_REQUIRE(refined_count > 0, corrupt, "level block " + std::to_string(l) + " refines no octant, but more levels follow");
            AMC_REQUIRE(levels.octant_count() + (refined_count << meta.dim) <= meta.octants, corrupt,
                        "level block " + std::to_string(l) + ": more octants than the metadata announces");
            levels.add_children(refined, meta.octants);
        }
        AMC_REQUIRE(!truncating || read == meta.count, corrupt,
                    "the level blocks hold " + std::to_string(read) + " symbols, the metadata announces " + std::to_string(meta.count));
        AMC_REQUIRE(levels.octant_count() == meta.octants, corrupt,
                    "the forest has " + std::to_string(levels.octant_count()) + " octants, the metadata announces " +
                        std::to_string(meta.octants));
        OctreeForest forest = levels.leaves(conn);
        // Leaf field blocks (version 2), then the end block.
        uint64_t values = 0;
        // Ordered, as the encoder's check (validate_leaf_fields): std::hash of a string is unkeyed,
        // and names chosen to share it made this set quadratic in the fields.
        std::set<std::string> names;
        for (block = next_block(reader); uint8_t(block.type) != uint8_t(OctreeBlock::end); block = next_block(reader)) {
            AMC_REQUIRE(uint8_t(block.type) == uint8_t(OctreeBlock::leaf_field), corrupt,
                        "block at byte " + std::to_string(block.offset) + ": expected a leaf field or end block, found a " +
                            kOctreeFraming.block_name(uint8_t(block.type)) + " block");
            AMC_REQUIRE(values <= options.max_leaf_values, limit_exceeded, "the leaf fields hold more values than the limit");
            Field field = read_leaf_field(block.payload, block.size, forest.leaves, options.max_leaf_values - values);
            values += field.value_count();
            AMC_REQUIRE(names.insert(field.name).second, corrupt, "two leaf fields named \"" + field.name + "\"");
            forest.leaf_data.push_back(std::move(field));
        }
        return forest;
    });
}

}  // namespace amc
