// Octree forest -> .amq file (docs/FORMAT.md section 8): the refinement of every octant, level by
// level, minus what the rules decide, arithmetic-coded in context groups.
#include "coding/entropy/arithmetic_coder.h"
#include "common/check.h"
#include "octree/octree_file.h"
#include "octree/octree_leaf_data.h"
#include "octree/octree_traversal.h"

namespace amc {

namespace {

struct Symbol {
    uint16_t model;
    bool refined;
};

uint8_t switches_of(const OctreeEncodeOptions& o) {
    return uint8_t((o.cull_by_balance ? kOctreeCullByBalance : 0) | (o.uniform_levels ? kOctreeUniformLevels : 0) |
                   (o.truncate ? kOctreeTruncate : 0) | (o.context_groups ? kOctreeContextGroups : 0) |
                   (o.improved_traversal ? kOctreeImprovedTraversal : 0));
}

}  // namespace

std::vector<uint8_t> encode_octree_forest(const OctreeForest& forest, const OctreeEncodeOptions& options, OctreeEncodeStats* stats) {
    validate_octree_forest(forest, "encode_octree_forest");
    // Before the work: a bad step is refused at once.
    const std::vector<uint8_t> conn = write_octree_connectivity(forest.connectivity, options.vertex_step);
    const uint8_t version =
        forest.leaf_data.empty() && !is_quantized_connectivity(conn) ? kOctreeBaseVersion : kOctreeLeafDataVersion;
    const int d = forest.dim();
    std::vector<std::vector<uint8_t>> refined;
    const OctreeLevels levels = octree_levels_of(forest, &refined, UINT64_MAX);
    const int level_count = levels.depth() + 1;

    OctreeMetadata meta;
    meta.dim = d;
    meta.trees = forest.tree_count();
    meta.octants = levels.octant_count();
    meta.leaves = forest.leaves.size();
    meta.levels = uint64_t(level_count);
    meta.switches = switches_of(options);
    if (options.uniform_levels) {
        while (meta.uniform_levels + 1 < level_count) {
            bool all = true;
            for (uint8_t r : refined[meta.uniform_levels]) all &= r != 0;
            if (!all) break;
            ++meta.uniform_levels;
        }
    }

    // The symbols of every level, in traversal order, with their contexts.
    std::vector<std::vector<Symbol>> symbols(level_count);
    OctreeTraversal traversal;
    OctreeLevelFates fates;
    for (int l = 0; l < level_count; ++l) {
        const OctreeLevel& lv = levels.level(l);
        decide_octree_level(l > 0 ? &levels.level(l - 1) : nullptr, lv, l, d, meta.switches, meta.uniform_levels, traversal,
                            [&](uint32_t n, int model) {
                                symbols[l].push_back({uint16_t(model), refined[l][n] != 0});
                                return refined[l][n] != 0;
                            },
                            fates);
        for (uint32_t n = 0; n < lv.size(); ++n) {
            if ((traversal.state[n] == kDecidedRefined) == (refined[l][n] != 0)) continue;
            // Only a rule can disagree with the forest: balance (the level limit is validated).
            throw_error(ErrorCode::invalid_input,
                        "encode_octree_forest: the forest is not 2:1 balanced by faces: tree " + std::to_string(lv.tree[n]) +
                            " octant (" + std::to_string(lv.coord[3 * size_t(n)]) + ", " + std::to_string(lv.coord[3 * size_t(n) + 1]) +
                            ", " + std::to_string(lv.coord[3 * size_t(n) + 2]) + ") of level " + std::to_string(l) +
                            " is refined next to a coarser leaf (balance_octree_forest balances it; "
                            "OctreeEncodeOptions::cull_by_balance = false codes it as it is)");
        }
    }
    uint64_t total = 0, last_one = 0;
    for (const auto& level : symbols)
        for (const Symbol& s : level) {
            ++total;
            if (s.refined) last_one = total;
        }
    meta.count = options.truncate ? last_one : total;

    BlockWriter writer(kOctreeFraming, version, 0);
    writer.add(uint8_t(OctreeBlock::metadata), write_octree_metadata(meta));
    writer.add(uint8_t(OctreeBlock::connectivity), conn);
    std::vector<BitModel> models(octree_model_count(d));
    std::vector<std::vector<uint8_t>> level_payloads(level_count);
    uint64_t coded = 0, level_bytes = 0;
    for (int l = 0; l < level_count; ++l) {
        ArithmeticEncoder encoder;
        for (const Symbol& s : symbols[l]) {
            if (coded == meta.count) break;
            encoder.encode(s.refined, models[s.model]);
            ++coded;
        }
        level_payloads[l] = encoder.finish();
        level_bytes += level_payloads[l].size();
    }
    std::vector<std::vector<uint8_t>> field_payloads;
    uint64_t leaf_data_bytes = 0;
    for (const Field& field : forest.leaf_data) {
        field_payloads.push_back(write_leaf_field(field, forest.leaves));
        leaf_data_bytes += field_payloads.back().size();
    }
    // FORMAT.md 8.5, Bounds: at most kOctreeOctantsPerByte octants per byte after the metadata
    // block; zeros after the last level's symbols (read as the bytes past its end would be) make up
    // what a forest of costless levels lacks.
    const uint64_t after = conn.size() + level_bytes + leaf_data_bytes + (level_count + forest.leaf_data.size() + 2) * kBlockOverhead;
    const uint64_t needed = meta.octants / kOctreeOctantsPerByte + (meta.octants % kOctreeOctantsPerByte != 0);
    if (needed > after) {
        level_payloads.back().resize(level_payloads.back().size() + (needed - after), 0);
        level_bytes += needed - after;
    }
    for (const std::vector<uint8_t>& payload : level_payloads) writer.add(uint8_t(OctreeBlock::level), payload);
    for (const std::vector<uint8_t>& payload : field_payloads) writer.add(uint8_t(OctreeBlock::leaf_field), payload);
    std::vector<uint8_t> file = writer.finish();
    if (stats) {
        stats->nodes = meta.octants;
        stats->leaves = meta.leaves;
        stats->uniform = fates.uniform;
        stats->culled = fates.culled;
        stats->coded = meta.count;
        stats->truncated = fates.coded - meta.count;
        stats->connectivity_bytes = conn.size();
        stats->level_bytes = level_bytes;
        stats->leaf_data_bytes = leaf_data_bytes;
        stats->file_bytes = file.size();
    }
    return file;
}

}  // namespace amc
