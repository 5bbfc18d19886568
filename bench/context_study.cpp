// Contexts beyond the paper's Table 2, measured (issue 30; docs/HIERARCHY_CODER.md, "Contexts
// beyond Table 2"): each model's coded hierarchy symbols, in the coder's order, coded again with the
// coder's own adaptive bit model (BitModel) under richer contexts; the table gives bits per design.
// Every feature is known to a decoder of an .amc file before the node's symbol: the coarser levels
// whole, the node's context group, and the positions of the node's corners (level block l - 1
// holds them, docs/FORMAT.md 3.6). The integer designs use the mixer of the coder's mixing mode
// (context_mixing.h); LIBRARY_MIX=1 adds a row with the exact code length of the mixing mode itself
// (.amc version 8); OLD_DESIGNS=1 prints the sixteenth session's designs instead.
//   [LIBRARY_MIX=1] [OLD_DESIGNS=1] context_study model.amh ...
#include <amc/hierarchy.h>

#include "coding/entropy/arithmetic_coder.h"
#include "coding/hierarchy/context_groups.h"
#include "coding/hierarchy/context_mixing.h"
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
    // Structure (issue 30): only what the decoder knows when the symbol comes.
    int child;          // child index 0..3 (3 = center), 4 for a root
    int inner_state;    // outer child: its edge to the center sibling, 0 refined, 1 not, 2 unknown; center: 3
    int parent_far;     // outer child: the parent's neighbour across the edge away from its corner: 0 refined, 1 not/none; center 2
    int parent_siblings;  // refined siblings of the parent (0..3)
    int ring2;          // decided refined nodes among the neighbours' other neighbours (0..4)
    int disp;           // log of the relative displacement of the parent's edge midpoints next to the node (0..23)
    int disp_parent;    // the same over all three of the parent's edges
    int mean_curv;      // log of a discrete mean curvature at the node times its diameter (0..31)
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

// Relative displacement of the midpoint of p's edge e from the middle of the edge's ends, squared.
double displacement2(const Hierarchy& h, NodeId p, int e) {
    const Vec3 a = h.position(h.vertex(p, e)), b = h.position(h.vertex(p, (e + 1) % 3));
    const Vec3 m = h.position(h.midpoint(p, e));
    const Vec3 d = m - 0.5 * (a + b), edge = b - a;
    const double l2 = dot(edge, edge);
    return l2 > 0 ? dot(d, d) / l2 : 0;
}

// Half-octave bins of a squared ratio (quarter octaves of the ratio): 0 for 0, else 1..23.
int log_bin(double r2) {
    if (!(r2 > 0)) return 0;
    int e = 0;
    const double m = std::frexp(r2, &e);  // r2 = m 2^e, m in [0.5, 1)
    return std::clamp(2 * e + (m >= 0.7071067811865476) + 26, 1, 23);
}

using ContextOf = std::function<int(const Features&)>;

// The integer mixer of the coder's mixing mode (context_mixing.h): these contexts' adaptive models
// (window 2^limit_log2), weights chosen by `set`, then an APM by `apm` (none if null).
struct IntegerMix {
    std::vector<ContextOf> inputs;
    ContextOf set;
    int sets;
    int rate = 6;
    int limit_log2 = BitModel::kDefaultLimitLog2;
    ContextOf apm = nullptr;
    int apm_contexts = 0;
    int apm_rate = 7;
    int apm_share = 2;  // the final probability: (mix * (4 - share) + apm * share) / 4
};

struct Design {
    const char* name;
    ContextOf context;  // any non-negative index
    std::vector<ContextOf> mixed = {};  // if not empty: these contexts' models mixed
    IntegerMix integer = {};  // if it has inputs: this integer mixer
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

double integer_mixed_code_length(const std::vector<Features>& features, const std::vector<bool>& bits,
                                 const IntegerMix& mix) {
    const size_t k = mix.inputs.size();
    std::vector<std::vector<BitModel>> models(k);
    mixing::Mixer mixer(int(k) + 1, mix.sets, mix.rate);
    mixing::ProbabilityMap apm(std::max(1, mix.apm_contexts), mix.apm_rate);
    std::vector<int> st(size_t(mixing::Mixer::padded(int(k) + 1)));
    std::vector<size_t> c(k);
    double total = 0;
    for (size_t i = 0; i < bits.size(); ++i) {
        for (size_t j = 0; j < k; ++j) {
            c[j] = size_t(mix.inputs[j](features[i]));
            if (c[j] >= models[j].size()) models[j].resize(c[j] + 1, BitModel(mix.limit_log2));
            st[j] = mixing::stretch(mixing::p12_of(models[j][c[j]]));
        }
        st[k] = 256;  // bias
        int p = mixer.mix(st.data(), mix.set(features[i]));
        if (mix.apm) p = (p * (4 - mix.apm_share) + apm.refine(p, mix.apm(features[i])) * mix.apm_share + 2) >> 2;
        p = std::clamp(p, 1, 4095);
        total -= std::log2(bits[i] ? p / 4096.0 : 1.0 - p / 4096.0);
        mixer.update(st.data(), bits[i]);
        if (mix.apm) apm.update(bits[i]);
        for (size_t j = 0; j < k; ++j) models[j][c[j]].update(bits[i]);
    }
    return total;
}

}  // namespace

int main(int argc, char** argv) {
    const double kMixRate = std::getenv("MIX_RATE") ? std::atof(std::getenv("MIX_RATE")) : 0.005;
    auto G = [](const Features& f) { return f.group; };
    auto GC = [](const Features& f) { return f.group * 4 + f.inner_state; };
    auto GP = [](const Features& f) { return f.group * 4 + f.parent_refined_neighbors; };
    auto GL = [](const Features& f) { return f.group * 8 + f.level; };
    auto GR = [](const Features& f) { return f.group * 5 + f.ring2; };
    auto GF = [](const Features& f) { return (f.group * 3 + f.parent_far) * 4 + f.parent_siblings; };
    auto GD = [](const Features& f) { return f.group * 24 + f.disp; };
    auto GDP = [](const Features& f) { return (f.group * 24 + f.disp_parent) * 4 + f.inner_state; };
    auto GDL = [](const Features& f) { return (f.group * 24 + f.disp) * 8 + f.level; };
    auto GBS = [](const Features& f) { return f.group * 32 + f.bend_size_log; };
    auto GBL = [](const Features& f) { return (f.group * 32 + f.bend_sum_log) * 8 + f.level; };
    const std::vector<ContextOf> structural = {G, GC, GP, GL, GR, GF};
    std::vector<ContextOf> geometric = structural;
    for (const ContextOf& c : {ContextOf(GD), ContextOf(GDP), ContextOf(GDL), ContextOf(GBS), ContextOf(GBL)})
        geometric.push_back(c);
    std::vector<ContextOf> geometric2 = geometric;
    geometric2.push_back([](const Features& f) { return f.group * 64 + f.mean_curv; });
    geometric2.push_back([](const Features& f) { return ((f.group * 64 + f.mean_curv) * 8 + f.level) * 2 + (f.child == 3); });
    auto sets_child = [](IntegerMix m) {
        m.set = [](const Features& f) { return f.group * 5 + f.child; };
        m.sets = kContextGroupCount * 5;
        return m;
    };
    auto mixer_of = [&](std::vector<ContextOf> inputs, int rate, int limit, bool apm, int share = 2) {
        IntegerMix m;
        m.inputs = std::move(inputs);
        m.set = G;
        m.sets = kContextGroupCount;
        m.rate = rate;
        m.limit_log2 = limit;
        if (apm) {
            m.apm = GC;
            m.apm_contexts = kContextGroupCount * 4;
            m.apm_share = share;
        }
        return m;
    };
    const std::vector<Design> new_designs = {
        {"group (Table 2)", G},
        {"group x inner edge", GC},
        {"group x ring 2", GR},
        {"group x parent far x parent siblings", GF},
        {"group x disp", GD},
        {"group x disp parent x inner", GDP},
        {"group x disp x level", GDL},
        {"group x mean curv", [](const Features& f) { return f.group * 64 + f.mean_curv; }},
        {"group x mean curv x level", [](const Features& f) { return (f.group * 64 + f.mean_curv) * 8 + f.level; }},
        {"int mix: structural + geometric + APM, rate 12, window 2^8", nullptr, {}, mixer_of(geometric, 12, 8, true)},
        {"int mix: + mean curv (2)", nullptr, {}, mixer_of(geometric2, 12, 8, true)},
        {"int mix: + mean curv, sets group x child", nullptr, {}, sets_child(mixer_of(geometric2, 12, 8, true))},
        {"int mix: + mean curv, rate 16", nullptr, {}, mixer_of(geometric2, 16, 8, true)},
        {"int mix: + mean curv, APM share 1", nullptr, {}, mixer_of(geometric2, 12, 8, true, 1)},
        {"int mix: + mean curv, APM share 3", nullptr, {}, mixer_of(geometric2, 12, 8, true, 3)},
    };
    const std::vector<Design> old_designs = {
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
    const std::vector<Design>& designs = std::getenv("OLD_DESIGNS") ? old_designs : new_designs;
    std::vector<std::string> names;
    std::vector<double> library_mix;
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
        // When each node was decided: coded nodes at their trace position, the nodes 1-regularity
        // culls before their level (-1), the rest (hanging-node rule) counted as never.
        std::vector<int64_t> decided_at(h.node_capacity(), INT64_MAX);
        for (size_t t = 0; t < trace.size(); ++t) decided_at[trace[t].node] = int64_t(t);
        for (NodeId n : h.breadth_first_order()) {
            if (!h.has_all_neighbors(n)) decided_at[n] = -1;
        }
        int64_t now = 0;
        auto known = [&](NodeId q) { return q != kNoNode && decided_at[q] < now; };
        for (const CodedSymbol& s : trace) {
            now = decided_at[s.node];
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
            const int k = h.child_index(s.node);
            f.child = k < 0 ? 4 : k;
            f.inner_state = 3;
            f.parent_far = 2;
            if (k >= 0 && k != amc::red_split::kCenter) {
                // The outer child k's edge (k + 1) % 3 is its inner edge, to the center sibling.
                const NodeId q = h.neighbor(s.node, (k + 1) % 3);
                f.inner_state = !known(q) ? 2 : h.is_leaf(q) ? 1 : 0;
                const NodeId pf = h.neighbor(p, (k + 1) % 3);
                f.parent_far = pf != kNoNode && !h.is_leaf(pf) ? 0 : 1;
            }
            if (p != kNoNode && h.parent(p) != kNoNode) {
                const NodeId g = h.parent(p);
                for (int c = 0; c < 4; ++c) f.parent_siblings += h.child(g, c) != p && !h.is_leaf(h.child(g, c));
            }
            for (int e = 0; e < 3; ++e) {
                const NodeId q = h.neighbor(s.node, e);
                if (q == kNoNode) continue;
                for (int eq = 0; eq < 3; ++eq) {
                    const NodeId r = h.neighbor(q, eq);
                    if (r != s.node && known(r) && !h.is_leaf(r)) ++f.ring2;
                }
            }
            f.ring2 = std::min(f.ring2, 4);
            if (p != kNoNode) {
                double near = 0, all = 0;
                for (int e = 0; e < 3; ++e) {
                    const double r2 = displacement2(h, p, e);
                    all = std::max(all, r2);
                    if (k == amc::red_split::kCenter || e == k || e == (k + 2) % 3) near = std::max(near, r2);
                }
                f.disp = log_bin(near);
                f.disp_parent = log_bin(all);
            }
            {
                // H ~ sum over edges of angle * length / (4 area); times the longest edge.
                const std::array<double, 3> a = neighbor_angles(h, s.node);
                const Vec3 A = h.position(h.vertex(s.node, 0)), B = h.position(h.vertex(s.node, 1)),
                           C = h.position(h.vertex(s.node, 2));
                const Vec3 u = B - A, v = C - A;
                const Vec3 x{u.y * v.z - u.z * v.y, u.z * v.x - u.x * v.z, u.x * v.y - u.y * v.x};
                const double area = 0.5 * std::sqrt(dot(x, x));
                double sum = 0, longest = 0;
                for (int e = 0; e < 3; ++e) {
                    const Vec3 d = h.position(h.vertex(s.node, (e + 1) % 3)) - h.position(h.vertex(s.node, e));
                    const double len = std::sqrt(dot(d, d));
                    sum += a[size_t(e)] * len;
                    longest = std::max(longest, len);
                }
                const double hd = area > 0 ? sum * longest / (4 * area) : 0;
                f.mean_curv = hd <= 0 ? 0 : std::clamp(int(std::floor(4 * std::log2(hd))) + 40, 1, 63);
            }
            features.push_back(f);
            bits.push_back(s.refined);
        }
        if (std::getenv("LIBRARY_MIX")) {
            // The coder's own mixing mode (.amc version 8), its exact adaptive code length.
            const HierarchyLevelEncoder mixed(h, HierarchyCoderOptions{}, kHierarchyStreamVersion, nullptr, true);
            HierarchyLevelEncoder& m = const_cast<HierarchyLevelEncoder&>(mixed);
            ArithmeticEncoder sink;
            for (int l = 0; l < m.level_count(); ++l) m.encode_level(l, sink);
            const HierarchyCodeStats st = m.stats();
            double coded = 0;
            for (const ContextGroupStats& g : st.groups) coded += g.coded_bits;
            library_mix.push_back(coded);
        }
        names.push_back(std::filesystem::path(argv[a]).stem().string());
        symbols.push_back(bits.size());
        for (size_t d = 0; d < designs.size(); ++d) {
            const double bits_d = !designs[d].integer.inputs.empty()
                                      ? integer_mixed_code_length(features, bits, designs[d].integer)
                                  : designs[d].mixed.empty() ? code_length(features, bits, designs[d].context)
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
    if (!library_mix.empty()) {
        double sum = 0;
        for (double b : library_mix) sum += b;
        std::printf("\n| mixing mode (library, .amc v8) | %+.1f%% |", 100.0 * (sum - totals[0]) / totals[0]);
        for (size_t m = 0; m < names.size(); ++m) std::printf(" %+.1f%% |", 100.0 * (library_mix[m] - bits_of[0][m]) / bits_of[0][m]);
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
