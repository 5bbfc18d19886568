// Context designs for the inter-frame connectivity of a series frame (docs/SERIES.md, "How the
// contexts were chosen"): walks every frame of a sequence against the frame before it in the
// order of FORMAT.md 7.6, records for each coded "refined?" symbol what the decoder knows at that
// point (the previous frame's class, neighbours, changes, the solver's error indicator of the
// previous frame), and prints, per design, the static conditional entropy H(X|ctx) and the
// adaptive code length (BitModel; models fresh per frame, carried from frame to frame, and
// carried with a prior), against the same frames coded alone (encode_hierarchy). The designs
// approximate the format's (libm log2, thresholds fitted on the coded symbols); the codec's own
// figures are series_bench's.
//
//   series_context_designs [--scenario lshape|rotating|front] [--frames N] [--target ELEMENTS]
//                          [--max-level L] [--bins B (indicator bins per octave, default 2)]
#include <amc/hierarchy_coder.h>
#include <amc/refinement.h>
#include <amc/simulation.h>

#include "coding/entropy/arithmetic_coder.h"
#include "series/frame_connectivity.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <map>
#include <string>
#include <vector>

using namespace amc;

namespace {

int kBinsPerOctave = 2;

struct Symbol {
    int frame;
    int cls, level;
    int dec_changed, dec_refined, decided;
    int parent_area;
    int prev_nbr_refined, prev_nbr_coarser;  // neighbours of cp(n) (or of cp(parent) for class 0) in P
    int changed_before, nbr_changed_before;  // cp(n) changed in the transition before, and its neighbours
    int siblings_changed;
    int indicator;  // bin of the reference's indicator at cp(n) (-1 none)
    double ratio;   // the indicator over the mean (-1 none)
    bool bit;
};

int previous_class(const Hierarchy& prev, NodeId p) {
    if (p == kNoNode) return 0;
    if (prev.is_leaf(p)) return 1;
    for (int k = 0; k < 4; ++k)
        if (!prev.is_leaf(prev.child(p, k))) return 3;
    return 2;
}

// changed[p] for the nodes of `prev`: refined there and not in pprev, or the other way round.
std::vector<uint8_t> changed_in(const Hierarchy& pprev, const Hierarchy& prev) {
    std::vector<uint8_t> out(prev.node_capacity(), 0);
    if (pprev.root_count() == 0) return out;
    const Counterparts cp = match_nodes(pprev, prev);
    for (NodeId n : prev.breadth_first_order()) {
        const bool before = cp[n] != kNoNode && !pprev.is_leaf(cp[n]);
        out[n] = before != !prev.is_leaf(n);
    }
    return out;
}

// Per node of prev: the largest indicator² over its cells (a leaf) or its children's cells (a node
// refined with leaf children), over the mean indicator² of the frame, as a bin of half powers of two.
std::vector<double> last_ratio;
std::vector<int> indicator_bins(const Hierarchy& prev, const std::vector<double>& eta) {
    std::vector<double> value(prev.node_capacity(), -1);
    if (eta.empty()) return std::vector<int>(prev.node_capacity(), -1);
    double mean = 0;
    for (double e : eta) mean += e * e;
    mean /= double(eta.size());
    size_t cell = 0;
    for (NodeId n : prev.breadth_first_order()) {
        if (!prev.is_leaf(n)) continue;
        double m = 0;
        for (int k = 0; k <= prev.hanging_node_count(n); ++k, ++cell) m = std::max(m, eta.at(cell) * eta.at(cell));
        value[n] = m;
        const NodeId parent = prev.parent(n);
        if (parent != kNoNode) value[parent] = std::max(value[parent], m);
    }
    std::vector<int> bins(prev.node_capacity(), -1);
    last_ratio.assign(prev.node_capacity(), -1);
    for (NodeId n = 0; n < prev.node_capacity(); ++n) if (value[n] >= 0) last_ratio[n] = value[n] / mean;
    for (NodeId n = 0; n < prev.node_capacity(); ++n) {
        if (value[n] < 0) continue;
        const double r = value[n] / mean;
        const int b = r <= 0 ? 0 : int(std::floor(kBinsPerOctave * std::log2(r))) + 7 * kBinsPerOctave;
        bins[n] = std::max(0, std::min(b, 11 * kBinsPerOctave - 1));
    }
    return bins;
}

void collect(int frame, const Hierarchy& pprev, const Hierarchy& prev, const Hierarchy& h, const std::vector<double>& eta,
             std::vector<Symbol>& out, uint64_t& forced) {
    const std::vector<int> bins = indicator_bins(prev, eta);
    const Counterparts cp = match_nodes(prev, h);
    const std::vector<uint8_t> before = changed_in(pprev, prev);
    constexpr uint8_t kDecided = 1, kRefined = 2, kChanged = 4;
    std::vector<uint8_t> state(h.node_capacity(), 0);
    auto changed = [&](NodeId q) { return q != kNoNode && (state[q] & kChanged); };
    std::vector<NodeId> level, next;
    for (NodeId r = 0; r < h.root_count(); ++r) level.push_back(r);
    while (!level.empty()) {
        next.clear();
        for (NodeId n : level) {
            const NodeId p = cp[n];
            const int cls = previous_class(prev, p);
            const bool refined = !h.is_leaf(n);
            int refined_neighbors = 0;
            bool complete = true;
            for (int e = 0; e < 3; ++e) {
                const NodeId q = h.neighbor(n, e);
                if (q == kNoNode) complete &= h.is_boundary_edge(n, e);
                else if ((state[q] & (kDecided | kRefined)) == (kDecided | kRefined)) ++refined_neighbors;
            }
            if (!complete || h.level(n) >= kMaxLevel || refined_neighbors == 3) {
                ++forced;
            } else {
                Symbol s{};
                s.frame = frame;
                s.cls = cls;
                s.level = h.level(n);
                for (int e = 0; e < 3; ++e) {
                    const NodeId q = h.neighbor(n, e);
                    if (q == kNoNode || !(state[q] & kDecided)) continue;
                    ++s.decided;
                    s.dec_changed += bool(state[q] & kChanged);
                    s.dec_refined += bool(state[q] & kRefined);
                }
                const NodeId parent = h.parent(n);
                if (parent != kNoNode) {
                    s.parent_area = changed(parent);
                    for (int e = 0; e < 3; ++e) s.parent_area |= changed(h.neighbor(parent, e));
                    for (int k = 0; k < 4; ++k) {
                        const NodeId c = h.child(parent, k);
                        if (c != n && (state[c] & kDecided)) s.siblings_changed += bool(state[c] & kChanged);
                    }
                }
                NodeId where = p;
                if (where == kNoNode && parent != kNoNode) where = cp[parent];
                if (where != kNoNode) {
                    for (int e = 0; e < 3; ++e) {
                        const NodeId q = prev.neighbor(where, e);
                        if (q == kNoNode) s.prev_nbr_coarser += !prev.is_boundary_edge(where, e);
                        else {
                            s.prev_nbr_refined += !prev.is_leaf(q);
                            s.nbr_changed_before += before[q];
                        }
                    }
                    s.changed_before = before[where];
                }
                s.indicator = p != kNoNode && previous_class(prev, p) <= 2 ? bins[p] : -1;
                s.ratio = p != kNoNode && previous_class(prev, p) <= 2 && !last_ratio.empty() ? last_ratio[p] : -1;
                s.bit = refined;
                out.push_back(s);
            }
            state[n] = uint8_t(kDecided | (refined ? kRefined : 0) | (refined != (cls >= 2) ? kChanged : 0));
            if (refined)
                for (int k = 0; k < 4; ++k) next.push_back(h.child(n, k));
        }
        level.swap(next);
    }
}

struct Design {
    const char* name;
    std::function<int(const Symbol&)> ctx;
};

}  // namespace

int main(int argc, char** argv) {
    std::string scenario = "lshape";
    int frames = 100, max_level = 10;
    uint32_t target = 5000;
    for (int i = 1; i + 1 < argc; i += 2) {
        const std::string a = argv[i];
        if (a == "--scenario") scenario = argv[i + 1];
        else if (a == "--frames") frames = std::atoi(argv[i + 1]);
        else if (a == "--target") target = uint32_t(std::atoi(argv[i + 1]));
        else if (a == "--max-level") max_level = std::atoi(argv[i + 1]);
        else if (a == "--bins") kBinsPerOctave = std::atoi(argv[i + 1]);
        else return 2;
    }
    std::vector<Hierarchy> seq;
    std::vector<std::vector<double>> etas;
    if (scenario == "front") {
        seq = make_moving_front_sequence(frames, max_level);
    } else {
        HeatRunOptions options;
        options.scenario = scenario == "rotating" ? HeatScenario::rotating : HeatScenario::lshape;
        options.frames = frames;
        options.max_level = max_level;
        options.target_elements = target;
        run_heat_simulation(options, [&](const SimulationFrame& f) {
            seq.push_back(*f.hierarchy);
            etas.push_back(f.fields[1].values);
        });
    }
    std::vector<Symbol> symbols;
    std::vector<uint64_t> intra(seq.size(), 0);
    uint64_t forced = 0, intra_total = 0;
    const Hierarchy none;
    for (size_t k = 1; k < seq.size(); ++k) {
        collect(int(k), k >= 2 ? seq[k - 2] : none, seq[k - 1], seq[k], etas.empty() ? std::vector<double>() : etas[k - 1],
                symbols, forced);
        intra[k] = encode_hierarchy(seq[k]).size();
        intra_total += intra[k];
    }
    // The encoder's shift: the smallest ratio of a leaf that was refined, per frame.
    std::map<int, double> lowest;
    for (const Symbol& s : symbols)
        if (s.cls == 1 && s.bit && s.ratio > 0) lowest[s.frame] = lowest.count(s.frame) ? std::min(lowest[s.frame], s.ratio) : s.ratio;
    auto shifted_bin = [&](const Symbol& s, int per_octave) {
        if (s.ratio < 0) return 0;
        if (s.ratio == 0) return 1;
        const double base = lowest.count(s.frame) ? lowest[s.frame] : 1.0;
        const int b = int(std::floor(per_octave * std::log2(s.ratio / base))) + 8 * per_octave;
        return 2 + std::max(0, std::min(b, 10 * per_octave));
    };
    // Thresholds the encoder would send: per frame and class (1: refine when above, 2: stay
    // refined when above), in eighths of an octave of the ratio, the split with the fewest errors.
    std::map<std::pair<int, int>, int> threshold;
    {
        std::map<std::pair<int, int>, std::vector<std::pair<int, bool>>> by;
        for (const Symbol& s : symbols)
            if ((s.cls == 1 || s.cls == 2) && s.ratio > 0)
                by[{s.frame, s.cls}].push_back({int(std::floor(8 * std::log2(s.ratio))), s.bit});
        for (auto& kv : by) {
            auto& v = kv.second;
            std::sort(v.begin(), v.end());
            // errors(t) = ones below t + zeros at or above t; t from v's values.
            int ones_below = 0, zeros_above = 0;
            for (auto& x : v) zeros_above += !x.second;
            int best = zeros_above, best_t = v.front().first;
            for (size_t i = 0; i < v.size(); ++i) {
                ones_below += v[i].second;
                zeros_above -= !v[i].second;
                const int t = v[i].first + 1;
                if (i + 1 < v.size() && v[i + 1].first == v[i].first) continue;
                if (ones_below + zeros_above < best) best = ones_below + zeros_above, best_t = t;
            }
            threshold[kv.first] = best_t;
        }
    }
    auto relative_bin = [&](const Symbol& s) {
        if (s.ratio < 0 || s.cls == 0 || s.cls == 3) return 0;
        if (s.ratio == 0) return 1;
        auto it = threshold.find({s.frame, s.cls});
        const int t = it == threshold.end() ? 0 : it->second;
        const int d = int(std::floor(8 * std::log2(s.ratio))) - t;
        // (-inf,-16) [-16,-8) [-8,-4) [-4,-2) -2 -1 0 1 [2,4) [4,8) [8,16) [16,inf)
        const int b = d < -16 ? 0 : d < -8 ? 1 : d < -4 ? 2 : d < -2 ? 3 : d < 2 ? 6 + d : d < 4 ? 8 : d < 8 ? 9 : d < 16 ? 10 : 11;
        return 2 + b;
    };
    std::printf("# %s: %zu frames, %zu coded symbols, %llu forced; frames 1.. coded alone: %llu bytes\n",
                scenario.c_str(), seq.size(), symbols.size(), (unsigned long long)forced,
                (unsigned long long)intra_total);

    auto cap = [](int v, int m) { return std::min(v, m); };
    const std::vector<Design> designs = {
        {"v1: cls, changed/refined decided nbrs, parent area", [&](const Symbol& s) {
             return (s.cls * 3 + cap(s.cls == 0 ? s.dec_refined : s.dec_changed, 2)) * 2 + s.parent_area; }},
        {"cls only", [&](const Symbol& s) { return s.cls; }},
        {"v1 + prev nbrs refined", [&](const Symbol& s) {
             return ((s.cls * 3 + cap(s.cls == 0 ? s.dec_refined : s.dec_changed, 2)) * 2 + s.parent_area) * 4 +
                    s.prev_nbr_refined; }},
        {"v1 + prev nbrs refined + coarser", [&](const Symbol& s) {
             return (((s.cls * 3 + cap(s.cls == 0 ? s.dec_refined : s.dec_changed, 2)) * 2 + s.parent_area) * 4 +
                     s.prev_nbr_refined) * 4 + s.prev_nbr_coarser; }},
        {"v1 + changed before", [&](const Symbol& s) {
             return (((s.cls * 3 + cap(s.cls == 0 ? s.dec_refined : s.dec_changed, 2)) * 2 + s.parent_area) * 2 +
                     s.changed_before) * 3 + cap(s.nbr_changed_before, 2); }},
        {"v1 + prev nbrs + changed before", [&](const Symbol& s) {
             return ((((s.cls * 3 + cap(s.cls == 0 ? s.dec_refined : s.dec_changed, 2)) * 2 + s.parent_area) * 4 +
                      s.prev_nbr_refined) * 2 + s.changed_before) * 3 + cap(s.nbr_changed_before, 2); }},
        {"cls, boundary(prev nbrs), any nbr/parent change", [&](const Symbol& s) {
             const int boundary = s.cls == 1 ? s.prev_nbr_refined > 0 : s.cls >= 2 ? (s.prev_nbr_refined < 3 || s.prev_nbr_coarser > 0) : cap(s.dec_refined, 2);
             return ((s.cls * 3 + boundary) * 3 + cap(s.dec_changed + s.siblings_changed, 2)) * 2 + s.parent_area; }},
        {"cls, boundary, nbr change, parent, changed before", [&](const Symbol& s) {
             const int boundary = s.cls == 1 ? s.prev_nbr_refined > 0 : s.cls >= 2 ? (s.prev_nbr_refined < 3 || s.prev_nbr_coarser > 0) : cap(s.dec_refined, 2);
             return ((((s.cls * 3 + boundary) * 3 + cap(s.dec_changed + s.siblings_changed, 2)) * 2 + s.parent_area) * 2 +
                     (s.changed_before || s.nbr_changed_before > 0)); }},
        {"cls, indicator bin", [&](const Symbol& s) { return s.cls * 100 + s.indicator + 1; }},
        {"cls, indicator bin, nbr change, parent", [&](const Symbol& s) {
             return ((s.cls * 100 + s.indicator + 1) * 3 + cap(s.dec_changed, 2)) * 2 + s.parent_area; }},
        {"cls, indicator bin, border, nbr change, parent", [&](const Symbol& s) {
             const int boundary = s.cls == 1 ? s.prev_nbr_refined > 0 : s.cls >= 2 ? (s.prev_nbr_refined < 3 || s.prev_nbr_coarser > 0) : cap(s.dec_refined, 2);
             return (((s.cls * 100 + s.indicator + 1) * 3 + boundary) * 3 + cap(s.dec_changed, 2)) * 2 + s.parent_area; }},
        {"shifted half bins: cls, bin, border, nbr change, parent", [&](const Symbol& s) {
             const int boundary = s.cls == 1 ? s.prev_nbr_refined > 0 : s.cls >= 2 ? (s.prev_nbr_refined < 3 || s.prev_nbr_coarser > 0) : cap(s.dec_refined, 2);
             return (((s.cls * 100 + shifted_bin(s, 2)) * 3 + boundary) * 3 + cap(s.dec_changed, 2)) * 2 + s.parent_area; }},
        {"shifted quarter bins: cls, bin, border, nbr change, parent", [&](const Symbol& s) {
             const int boundary = s.cls == 1 ? s.prev_nbr_refined > 0 : s.cls >= 2 ? (s.prev_nbr_refined < 3 || s.prev_nbr_coarser > 0) : cap(s.dec_refined, 2);
             return (((s.cls * 100 + shifted_bin(s, 4)) * 3 + boundary) * 3 + cap(s.dec_changed, 2)) * 2 + s.parent_area; }},
        {"v2: threshold-relative bins, cls, border, nbr change, parent", [&](const Symbol& s) {
             const int boundary = s.cls == 1 ? s.prev_nbr_refined > 0 : s.cls >= 2 ? (s.prev_nbr_refined < 3 || s.prev_nbr_coarser > 0) : cap(s.dec_refined, 2);
             return (((s.cls * 100 + relative_bin(s)) * 3 + boundary) * 3 + cap(s.dec_changed, 2)) * 2 + s.parent_area; }},
        {"threshold-relative bins: cls, bin", [&](const Symbol& s) { return s.cls * 100 + relative_bin(s); }},
        {"... + level/4", [&](const Symbol& s) {
             const int boundary = s.cls == 1 ? s.prev_nbr_refined > 0 : s.cls >= 2 ? (s.prev_nbr_refined < 3 || s.prev_nbr_coarser > 0) : cap(s.dec_refined, 2);
             return (((((s.cls * 3 + boundary) * 3 + cap(s.dec_changed + s.siblings_changed, 2)) * 2 + s.parent_area) * 2 +
                     (s.changed_before || s.nbr_changed_before > 0)) * 4) + cap(s.level / 3, 3); }},
    };
    for (const Design& d : designs) {
        std::map<int, std::pair<uint64_t, uint64_t>> counts;  // ctx -> ones, n
        std::map<int, BitModel> carried, prior;
        double prior_bits = 0;
        std::map<int, BitModel> fresh;
        double fresh_bits = 0, carried_bits = 0, carried_unchanged = 0;
        uint64_t unchanged = 0;
        int frame = -1;
        for (const Symbol& s : symbols) {
            if (s.frame != frame) fresh.clear(), frame = s.frame;
            const int c = d.ctx(s);
            auto& cnt = counts[c];
            cnt.first += s.bit;
            ++cnt.second;
            fresh_bits += fresh[c].cost_bits(s.bit);
            fresh[c].update(s.bit);
            carried_bits += carried[c].cost_bits(s.bit);
            if (!prior.count(c)) {
                BitModel m;
                m.p = s.cls >= 2 ? 0xF8000000u : 0x08000000u;  // 31/32 or 1/32
                m.n = 2;
                prior[c] = m;
            }
            prior_bits += prior[c].cost_bits(s.bit);
            prior[c].update(s.bit);
            if (s.bit == (s.cls >= 2)) carried_unchanged += carried[c].cost_bits(s.bit), ++unchanged;
            carried[c].update(s.bit);
        }
        double h = 0;
        for (const auto& kv : counts) h += binary_entropy_bits(kv.second.first, kv.second.second);
        std::printf("%-55s ctx %4zu  H(X|ctx) %8.0f B  adaptive fresh %8.0f B (%.1f%% of alone)  carried %8.0f B (%.1f%%), of which %.0f B on %llu unchanged nodes; with priors %.0f B\n",
                    d.name, counts.size(), h / 8, fresh_bits / 8, 100 * fresh_bits / 8 / double(intra_total),
                    carried_bits / 8, 100 * carried_bits / 8 / double(intra_total), carried_unchanged / 8,
                    (unsigned long long)unchanged, prior_bits / 8);
    }
    return 0;
}
