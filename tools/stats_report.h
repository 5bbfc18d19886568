// `amc stats`: the paper's Table 1 (removal of redundant symbols, code size with and without
// contexts) and Table 2 (context groups under naive and improved traversal) for hierarchies.
#pragma once

#include <amc/hierarchy.h>

#include <string>

namespace amc {

void print_table1_header();
void print_table1_row(const std::string& name, const Hierarchy& h);
void print_table2(const std::string& name, const Hierarchy& h);
// Encodes and decodes the forest under all 64 combinations of the coder's switches; throws Error
// if any differs. Returns the number of combinations checked.
int verify_all_switch_combinations(const Hierarchy& h);

// `amc report`: size of the .amc file by part, lossless and at 16 and 12 bits, and median encode and
// decode speeds over `runs` runs, one markdown table row per model and mode.
void print_codec_report_header();
void print_codec_report(const std::string& name, const Hierarchy& h, int runs);

}  // namespace amc
