// Contexts beyond the paper's Table 2, measured (issue 30; docs/HIERARCHY_CODER.md, "Contexts
// beyond Table 2"): each model's coded hierarchy symbols, in the coder's order, coded again with the
// coder's own adaptive bit model (BitModel) under richer contexts; the table gives bits per design.
// Every feature is known to a decoder of an .amc file before the node's symbol: the coarser levels
// whole, the node's context group, and the positions of the node's corners (level block l - 1
// holds them, docs/FORMAT.md 3.6).
//   context_study model.amh ...
#include <amc/hierarchy.h>

#include "coding/entropy/arithmetic_coder.h"
#include "coding/hierarchy/context_groups.h"
#include "coding/hierarchy/hierarchy_level_coder.h"

#include <algorithm>
#include <array>
#include <cstdlib>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace {

using namespace amc;

// What a decoder knows of node n when its symbol comes.
struct Features {
    int group;        // the paper's context group (0..9)
    int center;       // 1 for the center child
    int parent_refined_neighbors;  // of the parent's three neighbours, how many are refined (0..3)
    int level;        // min(level, 7)
    int bend4, bend8;  // quantile (within the level) of the largest angle between n's normal and a same-level neighbour's
    int bend_log;      // that angle on a log scale (half octaves), the same bins at every level
    int bend_size_log; // the angle times n's longest edge over the base's, log scale: curvature times size
    int bend_sum_log;  // the sum of the three angles (a missing neighbour adds 0), log scale
};

Vec3 unit_normal(const Hierarchy& h, NodeId n) {
    const Vec3 a = h.position(h.vertex(n, 0)), b = h.position(h.vertex(n, 1)), c = h.position(h.vertex(n, 2));
    const Vec3 u = b - a, v = c - a;
    const Vec3 x{u.y * v.z - u.z * v.y, u.z * v.x - u.x * v.z, u.x * v.y - u.y * v.x};
    const double len = std::sqrt(dot(x, x));
    return len > 0 ? (1.0 / len) * x : Vec3{0, 0, 0};
}

// The angles between n's normal and its same-level neighbours' normals (0 where none).
std::array<double, 3> neighbor_angles(const Hierarchy& h, NodeId n) {
    const Vec3 normal = unit_normal(h, n);
    std::array<double, 3> angles{};
    for (int e = 0; e < 3; ++e) {
        const NodeId q = h.neighbor(n, e);
        if (q != kNoNode) angles[size_t(e)] = std::acos(std::clamp(dot(normal, unit_normal(h, q)), -1.0, 1.0));
    }
    return angles;
}

double bend(const Hierarchy& h, NodeId n) {
    const std::array<double, 3> a = neighbor_angles(h, n);
    return std::max({a[0], a[1], a[2]});
}

double bend_sum(const Hierarchy& h, NodeId n) {
    const std::array<double, 3> a = neighbor_angles(h, n);
    return a[0] + a[1] + a[2];
}

// The bin (0..bins-1) of each value among the sorted values of its level.
int quantile_bin(const std::vector<double>& sorted, double value, int bins) {
    if (sorted.empty()) return 0;
    const size_t rank = size_t(std::lower_bound(sorted.begin(), sorted.end(), value) - sorted.begin());
    return std::min(bins - 1, int(rank * size_t(bins) / sorted.size()));
}

struct Design {
    const char* name;
    std::function<int(const Features&)> context;  // any non-negative index
    std::vector<std::function<int(const Features&)>> mixed = {};  // if not empty: these contexts' models mixed
};

double code_length(const std::vector<Features>& features, const std::vector<bool>& bits,
                   const std::function<int(const Features&)>& context) {
    std::vector<BitModel> models;
    double total = 0;
    for (size_t i = 0; i < bits.size(); ++i) {
        const size_t c = size_t(context(features[i]));
        if (c >= models.size()) models.resize(c + 1);
        BitModel& m = models[c];
        const double p1 = double(m.p16()) / 65536.0;
        total -= std::log2(bits[i] ? p1 : 1.0 - p1);
        m.update(bits[i]);
    }
    return total;
}

// Logistic mixing (as in PAQ): each design's adaptive model gives a probability; their stretched
// values are weighted by weights chosen by the context group and trained online.
double mixed_code_length(const std::vector<Features>& features, const std::vector<bool>& bits,
                         const std::vector<std::function<int(const Features&)>>& contexts, double rate) {
    const size_t k = contexts.size();
    std::vector<std::vector<BitModel>> models(k);
    std::vector<std::vector<double>> weights(kContextGroupCount, std::vector<double>(k, 1.0 / double(k)));
    double total = 0;
    std::vector<double> st(k);
    std::vector<size_t> c(k);
    for (size_t i = 0; i < bits.size(); ++i) {
        double dotp = 0;
        std::vector<double>& w = weights[size_t(features[i].group)];
        for (size_t j = 0; j < k; ++j) {
            c[j] = size_t(contexts[j](features[i]));
            if (c[j] >= models[j].size()) models[j].resize(c[j] + 1);
            const double p = std::clamp(double(models[j][c[j]].p16()) / 65536.0, 1e-4, 1 - 1e-4);
            st[j] = std::log(p / (1 - p));
            dotp += w[j] * st[j];
        }
        const double p1 = std::clamp(1.0 / (1.0 + std::exp(-dotp)), 1.0 / 4096, 1 - 1.0 / 4096);
        total -= std::log2(bits[i] ? p1 : 1.0 - p1);
        const double err = (bits[i] ? 1.0 : 0.0) - p1;
        for (size_t j = 0; j < k; ++j) {
            w[j] += rate * err * st[j];
            models[j][c[j]].update(bits[i]);
        }
    }
    return total;
}

}  // namespace

int main(int argc, char** argv) {
    const double kMixRate = std::getenv("MIX_RATE") ? std::atof(std::getenv("MIX_RATE")) : 0.005;
    const std::vector<Design> designs = {
        {"group (Table 2)", [](const Features& f) { return f.group; }},
        {"group x center", [](const Features& f) { return f.group * 2 + f.center; }},
        {"group x parent's refined nbrs", [](const Features& f) { return f.group * 4 + f.parent_refined_neighbors; }},
        {"group x level", [](const Features& f) { return f.group * 8 + f.level; }},
        {"group x bend4", [](const Features& f) { return f.group * 4 + f.bend4; }},
        {"group x bend8", [](const Features& f) { return f.group * 8 + f.bend8; }},
        {"group x center x parent nbrs", [](const Features& f) { return (f.group * 2 + f.center) * 4 + f.parent_refined_neighbors; }},
        {"group x bend4 x parent nbrs", [](const Features& f) { return (f.group * 4 + f.bend4) * 4 + f.parent_refined_neighbors; }},
        {"group x log bend", [](const Features& f) { return f.group * 32 + f.bend_log; }},
        {"group x log bend*size", [](const Features& f) { return f.group * 32 + f.bend_size_log; }},
        {"group x log bend sum", [](const Features& f) { return f.group * 32 + f.bend_sum_log; }},
        {"group x log bend sum x level", [](const Features& f) { return (f.group * 32 + f.bend_sum_log) * 8 + f.level; }},
        {"log bend sum x level (no group)", [](const Features& f) { return f.bend_sum_log * 8 + f.level; }},
        {"group x log bend*size x parent nbrs", [](const Features& f) { return (f.group * 32 + f.bend_size_log) * 4 + f.parent_refined_neighbors; }},
        {"group x log bend x parent nbrs", [](const Features& f) { return (f.group * 32 + f.bend_log) * 4 + f.parent_refined_neighbors; }},
        {"group x bend8 x center x parent", [](const Features& f) {
             return ((f.group * 8 + f.bend8) * 2 + f.center) * 4 + f.parent_refined_neighbors;
         }},
        {"mix: group, group x log bend*size, group x parent nbrs, group x level", nullptr,
         {[](const Features& f) { return f.group; }, [](const Features& f) { return f.group * 32 + f.bend_size_log; },
          [](const Features& f) { return f.group * 4 + f.parent_refined_neighbors; },
          [](const Features& f) { return f.group * 8 + f.level; }}},
        {"mix: the above and group x log bend sum x level", nullptr,
         {[](const Features& f) { return f.group; }, [](const Features& f) { return f.group * 32 + f.bend_size_log; },
          [](const Features& f) { return f.group * 4 + f.parent_refined_neighbors; },
          [](const Features& f) { return f.group * 8 + f.level; },
          [](const Features& f) { return (f.group * 32 + f.bend_sum_log) * 8 + f.level; }}},
    };
    std::vector<std::string> names;
    std::vector<size_t> symbols;
    std::vector<std::vector<double>> bits_of;  // [design][model]
    bits_of.resize(designs.size());
    std::vector<double> totals(designs.size(), 0.0);
    for (int a = 1; a < argc; ++a) {
        const Hierarchy h = read_hierarchy(argv[a]);
        std::vector<CodedSymbol> trace;
        const HierarchyLevelEncoder encoder(h, HierarchyCoderOptions{}, kHierarchyStreamVersion, &trace);
        trace.resize(size_t(encoder.stats().coded));  // symbols after the last coded 1 are not in the stream
        // Bend quantiles per level, over every node of the level.
        std::vector<std::vector<double>> bends_of_level;
        for (NodeId n : h.breadth_first_order()) {
            const size_t l = size_t(h.level(n));
            if (bends_of_level.size() <= l) bends_of_level.resize(l + 1);
            bends_of_level[l].push_back(bend(h, n));
        }
        for (auto& v : bends_of_level) std::sort(v.begin(), v.end());
        double base_edge = 0;  // the base mesh's mean edge length
        for (const Triangle& t : h.base().triangles) {
            const Vec3 d = h.base().positions[t[0]] - h.base().positions[t[1]];
            base_edge += std::sqrt(dot(d, d));
        }
        base_edge /= double(std::max<size_t>(1, h.base().triangles.size()));
        std::vector<Features> features;
        std::vector<bool> bits;
        for (const CodedSymbol& s : trace) {
            Features f{};
            f.group = s.group;
            f.center = h.child_index(s.node) == amc::red_split::kCenter;
            const NodeId p = h.parent(s.node);
            if (p != kNoNode) {
                for (int e = 0; e < 3; ++e) {
                    const NodeId q = h.neighbor(p, e);
                    f.parent_refined_neighbors += q != kNoNode && !h.is_leaf(q);
                }
            }
            f.level = std::min(h.level(s.node), 7);
            const double b = bend(h, s.node);
            const auto& sorted = bends_of_level[size_t(h.level(s.node))];
            f.bend4 = quantile_bin(sorted, b, 4);
            f.bend8 = quantile_bin(sorted, b, 8);
            f.bend_log = b <= 0 ? 0 : std::clamp(int(std::floor(2 * std::log2(b))) + 24, 0, 31);
            const double sum = bend_sum(h, s.node);
            f.bend_sum_log = sum <= 0 ? 0 : std::clamp(int(std::floor(2 * std::log2(sum))) + 24, 0, 31);
            double longest = 0;
            for (int e = 0; e < 3; ++e) {
                const Vec3 d = h.position(h.vertex(s.node, e)) - h.position(h.vertex(s.node, (e + 1) % 3));
                longest = std::max(longest, std::sqrt(dot(d, d)));
            }
            const double size = longest / base_edge;
            f.bend_size_log = b <= 0 ? 0 : std::clamp(int(std::floor(2 * std::log2(b * size))) + 28, 0, 31);
            features.push_back(f);
            bits.push_back(s.refined);
        }
        names.push_back(std::filesystem::path(argv[a]).stem().string());
        symbols.push_back(bits.size());
        for (size_t d = 0; d < designs.size(); ++d) {
            const double bits_d = designs[d].mixed.empty() ? code_length(features, bits, designs[d].context)
                                                            : mixed_code_length(features, bits, designs[d].mixed, kMixRate);
            totals[d] += bits_d;
            bits_of[d].push_back(bits_d);
        }
    }
    // Markdown: the baseline in bits, every other design as the change against it.
    std::printf("| context | all |");
    for (const std::string& n : names) std::printf(" %s |", n.c_str());
    std::printf("\n|---|---:|");
    for (size_t m = 0; m < names.size(); ++m) std::printf("---:|");
    std::printf("\n| symbols coded | |");
    for (size_t m = 0; m < names.size(); ++m) std::printf(" %zu |", symbols[m]);
    for (size_t d = 0; d < designs.size(); ++d) {
        std::printf("\n| %s |", designs[d].name);
        if (d == 0) {
            std::printf(" %.0f bits |", totals[0]);
            for (size_t m = 0; m < names.size(); ++m) std::printf(" %.0f |", bits_of[0][m]);
        } else {
            std::printf(" %+.1f%% |", 100.0 * (totals[d] - totals[0]) / totals[0]);
            for (size_t m = 0; m < names.size(); ++m)
                std::printf(" %+.1f%% |", 100.0 * (bits_of[d][m] - bits_of[0][m]) / bits_of[0][m]);
        }
    }
    std::printf("\n\n");
    // The same, summed by kind: curvature-adaptive surface remeshes (corpus names *_mean, *_gauss)
    // and the others (planar finite-element and random models).
    auto is_surface = [&](size_t m) {
        return names[m].find("_mean") != std::string::npos || names[m].find("_gauss") != std::string::npos;
    };
    std::printf("| context | all | surface remeshes | range | other models | range |\n|---|---:|---:|---|---:|---|");
    for (size_t d = 0; d < designs.size(); ++d) {
        double sum[2] = {0, 0}, base[2] = {0, 0}, low[2] = {1e9, 1e9}, high[2] = {-1e9, -1e9};
        for (size_t m = 0; m < names.size(); ++m) {
            const int kind = is_surface(m) ? 0 : 1;
            sum[kind] += bits_of[d][m];
            base[kind] += bits_of[0][m];
            if (bits_of[0][m] <= 0) continue;
            const double change = 100.0 * (bits_of[d][m] - bits_of[0][m]) / bits_of[0][m];
            low[kind] = std::min(low[kind], change);
            high[kind] = std::max(high[kind], change);
        }
        std::printf("\n| %s | %+.1f%% |", designs[d].name, 100.0 * (totals[d] - totals[0]) / totals[0]);
        for (int kind = 0; kind < 2; ++kind) {
            if (base[kind] <= 0) {
                std::printf(" | |");
                continue;
            }
            std::printf(" %+.1f%% | %+.1f%% .. %+.1f%% |", 100.0 * (sum[kind] - base[kind]) / base[kind], low[kind], high[kind]);
        }
    }
    std::printf("\n");
    return 0;
}
