// Table 1 and Table 2 of the paper, computed by running the coder with and without each feature.
#include "stats_report.h"

#include <amc/hierarchy_coder.h>

#include "coding/hierarchy/coder_switches.h"

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

int verify_all_switch_combinations(const Hierarchy& h) {
    const std::vector<NodeId> order = h.breadth_first_order();
    const LeafMesh leaf = extract_leaf_mesh(h);
    int combinations = 0;
    for (int bits = 0; bits < kCoderSwitchCombinations; ++bits) {
        const HierarchyCoderOptions o = coder_options_from_switches(bits);
        const std::vector<uint8_t> bytes = encode_hierarchy(h, o);
        const Hierarchy back = decode_hierarchy(h.base(), bytes.data(), bytes.size());
        const std::vector<NodeId> back_order = back.breadth_first_order();
        bool same = back_order.size() == order.size();
        for (size_t i = 0; same && i < order.size(); ++i) {
            same = h.is_leaf(order[i]) == back.is_leaf(back_order[i]) &&
                   (!h.is_leaf(order[i]) || h.hanging_node_count(order[i]) != 2 ||
                    h.diagonal_flipped(order[i]) == back.diagonal_flipped(back_order[i]));
        }
        same = same && extract_leaf_mesh(back).mesh.triangles == leaf.mesh.triangles;
        if (!same) throw Error("hierarchy round trip differs under switch combination " + std::to_string(bits));
        ++combinations;
    }
    return combinations;
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

// ---- amc report: the .amc file per model and coordinate mode ----------------------------------

#include <amc/codec.h>

#include <algorithm>
#include <chrono>

namespace amc {

namespace {

double median_seconds(std::vector<double> samples) {
    std::sort(samples.begin(), samples.end());
    return samples[samples.size() / 2];
}

}  // namespace

void print_codec_report_header() {
    std::printf("| model | faces | vertices | coordinates | total bytes | connectivity bytes (base + hierarchy) | "
                "geometry bytes | bits/face | bits/vertex | conn. bits/face | max error | encode M faces/s | decode M faces/s |\n");
    std::printf("|---|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
}

void print_codec_report(const std::string& name, const Hierarchy& h, int runs) {
    for (int bits : {0, 16, 12}) {
        EncodeOptions options;
        options.quantize_bits = bits;
        EncodeStats stats;
        std::vector<uint8_t> bytes;
        std::vector<double> encode_times, decode_times;
        for (int r = 0; r < runs; ++r) {
            auto t0 = std::chrono::steady_clock::now();
            bytes = encode(h, options, &stats);
            auto t1 = std::chrono::steady_clock::now();
            const Hierarchy back = decode(bytes.data(), bytes.size());
            auto t2 = std::chrono::steady_clock::now();
            if (back.node_count() != h.node_count()) throw Error(name + ": decoded node count differs");
            if (bits == 0 && r == 0 && !identical(back, in_decoder_order(h)))
                throw Error(name + ": the lossless round trip is not bit-exact");
            encode_times.push_back(std::chrono::duration<double>(t1 - t0).count());
            decode_times.push_back(std::chrono::duration<double>(t2 - t1).count());
        }
        const uint64_t connectivity = stats.base_connectivity_bytes + stats.hierarchy_bytes;
        const uint64_t geometry = stats.base_geometry_bytes + stats.geometry_bytes;
        const std::string mode = bits == 0 ? (h.single_precision() ? "float32 exact" : "float64 exact") : std::to_string(bits) + " bits";
        std::printf("| %s | %lu | %lu | %s | %zu | %lu (%lu + %lu) | %lu | %.2f | %.2f | %.3f | %.3g | %.2f | %.2f |\n",
                    name.c_str(), (unsigned long)stats.faces, (unsigned long)stats.vertices, mode.c_str(), bytes.size(),
                    (unsigned long)connectivity, (unsigned long)stats.base_connectivity_bytes,
                    (unsigned long)stats.hierarchy_bytes, (unsigned long)geometry, 8.0 * bytes.size() / double(stats.faces),
                    8.0 * bytes.size() / double(stats.vertices), 8.0 * connectivity / double(stats.faces), stats.max_error,
                    stats.faces / median_seconds(encode_times) / 1e6, stats.faces / median_seconds(decode_times) / 1e6);
    }
}

}  // namespace amc
