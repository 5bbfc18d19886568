// Table 1 and Table 2 of the paper, computed by running the coder with and without each feature.
#include "stats_report.h"

#include <amc/hierarchy_coder.h>

#include <cstdio>

namespace amc {

namespace {

double percent(uint64_t part, uint64_t whole) { return whole == 0 ? 0.0 : 100.0 * double(part) / double(whole); }

}  // namespace

void print_table1_header() {
    std::printf("%-24s %8s %8s %8s %8s %8s %8s %16s %20s %10s %10s %8s\n", "model", "f", "#nodes", "drop0s", "hanging",
                "1-regul.", "uniform", "#left", "code bits (no ctx)", "H(X|ctx)", "naive", "gain");
}

// Columns as in the paper's Table 1: the share of nodes each rule removes, the symbols left, and
// the code size in bits with (and without) context groups; then the empirical conditional entropy
// bound of the coded symbols and the naive traversal's code size for comparison.
void print_table1_row(const std::string& name, const Hierarchy& h) {
    HierarchyCodeStats full, no_context, naive;
    HierarchyCoderOptions options;
    encode_hierarchy(h, options, &full);
    options.use_contexts = false;
    encode_hierarchy(h, options, &no_context);
    options.use_contexts = true;
    options.traversal = Traversal::naive;
    encode_hierarchy(h, options, &naive);
    char left[64], code[64];
    std::snprintf(left, sizeof left, "%.0f%% (%lu)", percent(full.coded, full.nodes), (unsigned long)full.coded);
    std::snprintf(code, sizeof code, "%lu (%lu)", (unsigned long)(full.payload_bytes * 8),
                  (unsigned long)(no_context.payload_bytes * 8));
    std::printf("%-24s %8lu %8lu %7.1f%% %7.1f%% %7.1f%% %7.1f%% %16s %20s %10.0f %10lu %7.1f%%\n", name.c_str(),
                (unsigned long)full.faces, (unsigned long)full.nodes, percent(full.truncated, full.nodes),
                percent(full.culled_hanging_nodes, full.nodes), percent(full.culled_one_regularity, full.nodes),
                percent(full.culled_uniform, full.nodes), left, code, full.conditional_entropy_bits,
                (unsigned long)(naive.payload_bytes * 8),
                100.0 * (1.0 - double(full.payload_bytes) / double(naive.payload_bytes)));
}

void print_table2(const std::string& name, const Hierarchy& h) {
    HierarchyCodeStats by_traversal[2];
    HierarchyCoderOptions options;
    options.traversal = Traversal::naive;
    encode_hierarchy(h, options, &by_traversal[0]);
    options.traversal = Traversal::improved;
    encode_hierarchy(h, options, &by_traversal[1]);
    std::printf("%s: context groups (refined, not refined, unknown neighbours)\n", name.c_str());
    std::printf("%-10s | %9s %6s %10s | %9s %6s %10s\n", "group", "naive", "%1's", "bits/symb", "improved", "%1's",
                "bits/symb");
    static const int order[] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9};
    for (int g : order) {
        const ContextGroupStats& a = by_traversal[0].groups[g];
        const ContextGroupStats& b = by_traversal[1].groups[g];
        if (g == 9 && a.symbols == 0 && b.symbols == 0) continue;  // (3,0,0): always culled
        std::printf("(%d, %d, %d)  | %9lu %5.0f%% %10.2f | %9lu %5.0f%% %10.2f\n", a.refined, a.unrefined, a.unknown,
                    (unsigned long)a.symbols, percent(a.ones, a.symbols), a.symbols ? a.coded_bits / a.symbols : 0.0,
                    (unsigned long)b.symbols, percent(b.ones, b.symbols), b.symbols ? b.coded_bits / b.symbols : 0.0);
    }
    for (int t = 0; t < 2; ++t) {
        const HierarchyCodeStats& s = by_traversal[t];
        const uint64_t culled = s.nodes - s.coded;
        std::printf("%-10s   culled %lu, total %lu, %.3f bits/node; H(X|ctx) %.0f bits, coded %lu bits (%+.2f%%), "
                    "orientation %.0f bits (%lu of %lu two-hanging leaves off rule %d)\n",
                    t == 0 ? "naive" : "improved", (unsigned long)culled, (unsigned long)s.nodes,
                    double(s.payload_bytes * 8) / double(s.nodes), s.conditional_entropy_bits,
                    (unsigned long)(s.payload_bytes * 8),
                    100.0 * (double(s.payload_bytes * 8) / s.conditional_entropy_bits - 1.0), s.orientation_bits,
                    (unsigned long)s.diagonal_exceptions, (unsigned long)s.two_hanging_leaves, int(s.diagonal_rule));
    }
}

}  // namespace amc
