// The hierarchy coder's six switches (HierarchyCoderOptions) as the bits the stream header stores
// them in: 0 1-regularity, 1 hanging nodes, 2 uniform levels, 3 truncation, 4 contexts, 5 improved
// traversal. Every combination for the ablation tables, tests and fuzzers; internal.
#pragma once

#include <amc/hierarchy_coder.h>

namespace amc {

constexpr int kCoderSwitchCombinations = 64;
HierarchyCoderOptions coder_options_from_switches(int switches);
int coder_switches(const HierarchyCoderOptions& options);

}  // namespace amc
