// The hierarchy decoder's path for streams of version 1 (docs/FORMAT.md, section 2, "Version 1"):
// decide_symbols_general of hierarchy_decoder.cpp on version 1's traversal, which every level of
// such a stream takes. In a file of its own, so that the decoder's file holds the newest version's
// traversal only and its fast path is compiled as before version 1 came back (HIERARCHY_CODER.md,
// Speed, item 34).
#include "coding/hierarchy/hierarchy_level_coder.h"

namespace amc {

void decide_symbols_version1(LevelTraversal& traversal, Level& level, bool uniform_level, ArithmeticDecoder& decoder,
                             HierarchyModels& level_models, uint64_t& level_symbols_read, uint64_t symbol_limit,
                             int group_mask) {
    ArithmeticDecoder d = decoder;
    HierarchyModels models = level_models;
    uint64_t symbols_read = level_symbols_read;
    traversal.run_version1(
        level, uniform_level,
        [&](uint32_t, int group) {
            if (symbols_read == symbol_limit) return false;
            ++symbols_read;
            return d.decode_with_limit<kHierarchyModelLimit>(models.groups[size_t(group & group_mask)]);
        },
        [&](uint32_t, Fate, bool refined) { return refined; });
    decoder = d;
    level_models = models;
    level_symbols_read = symbols_read;
}

}  // namespace amc
