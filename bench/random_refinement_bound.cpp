// Issue 30's question about the corpus's random refinement: how many bits does its hierarchy hold,
// whatever the contexts? (docs/HIERARCHY_CODER.md, "The random refinement: what its generator
// leaves to code".)
//
//   random_refinement_bound [--simulate K] [--grid N] [--generate K] [--sequential N [--dump OUT]] [--proposal K [--draws D]] FILE.amh
//
// `amc refine --model random` (refine_randomly, adaptive_refinement.cpp) splits a leaf drawn
// uniformly from the leaves below the level cap, with the forced splits of 1-regularity, until
// the leaf count reaches its target. Embedded in continuous time, every eligible leaf splits at
// rate 1 independently of the others (a Yule process) and the target is a stopping time T; leaves
// at the cap never split. Without the forced splits the trees are independent and a tree's
// probability has a closed recursion over a node's remaining time r = T - birth:
//   leaf at the cap: 1;   other leaf: e^-r;   split node: integral_0^r e^-s prod_children L_c(r - s) ds
// evaluated on a grid of r (log scale; the integral as a running trapezoid sum). The program
// prints:
//  - the code length of FILE's forest under that law at the T that fits it best (a two-pass coder
//    that knows the generator and sends T: every split, forced or not, coded as a free one), and
//  - with --simulate K, the law's entropy: K forests of the same roots, cap and T drawn from the
//    law itself (no forced splits), each coded by the same recursion; the mean code length is the
//    entropy, what no coder of such forests beats on average;
//  - with --proposal K, a lower bound of the generator's entropy by a proposal over the picks'
//    order (pick_steps below; docs/HIERARCHY_CODER.md, "a sequential lower bound of its entropy"),
//    and with --draws D an importance-sampled estimate from above with D draws of the same proposal.
#include "coding/entropy/arithmetic_coder.h"
#include "common/mixing.h"
#include "coding/hierarchy/hierarchy_level_coder.h"

#include <amc/hierarchy.h>
#include <amc/hierarchy_coder.h>
#include <amc/refinement.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using namespace amc;

// A forest as children lists: node i's children are kids[first[i] .. first[i] + 4) or none.
struct Forest {
    std::vector<int> level, first;  // first -1 for a leaf
    std::vector<int> kids;
    std::vector<int> roots;
    int cap = 0;
};

Forest forest_of(const Hierarchy& h) {
    Forest f;
    f.level.assign(h.node_capacity(), 0);
    f.first.assign(h.node_capacity(), -1);
    for (NodeId n = 0; n < h.node_capacity(); ++n) {
        if (!h.is_alive(n)) continue;
        f.level[n] = h.level(n);
        if (!h.is_leaf(n)) {
            f.first[n] = int(f.kids.size());
            for (int k = 0; k < 4; ++k) f.kids.push_back(int(h.child(n, k)));
        }
    }
    for (NodeId r = 0; r < h.root_count(); ++r) f.roots.push_back(int(r));
    f.cap = h.depth();
    return f;
}

class Likelihood {
public:
    Likelihood(const Forest& f, int grid, double r_max) : f_(f), n_(grid), dr_(r_max / (grid - 1)) {}

    // log L_root(r) summed over the roots, on the grid.
    std::vector<double> forest_log() {
        std::vector<double> sum(size_t(n_), 0.0);
        for (int root : f_.roots) {
            const std::vector<double> l = node_log(root);
            for (int i = 0; i < n_; ++i) sum[size_t(i)] += l[size_t(i)];
        }
        return sum;
    }
    double r_at(int i) const { return i * dr_; }

private:
    std::vector<double> node_log(int v) {
        std::vector<double> out(static_cast<size_t>(n_));
        if (f_.first[size_t(v)] < 0) {
            for (int i = 0; i < n_; ++i) out[size_t(i)] = f_.level[size_t(v)] >= f_.cap ? 0.0 : -r_at(i);
            return out;
        }
        std::vector<double> g(size_t(n_), 0.0);
        for (int k = 0; k < 4; ++k) {
            const std::vector<double> c = node_log(f_.kids[size_t(f_.first[size_t(v)] + k)]);
            for (int i = 0; i < n_; ++i) g[size_t(i)] += c[size_t(i)];
        }
        // L(r) = e^-r * integral_0^r e^u g(u) du, scaled by the largest u + log g(u).
        double top = -std::numeric_limits<double>::infinity();
        for (int i = 0; i < n_; ++i) top = std::max(top, r_at(i) + g[size_t(i)]);
        double integral = 0, previous = std::exp(g[0] - top);
        out[0] = -std::numeric_limits<double>::infinity();
        for (int i = 1; i < n_; ++i) {
            const double here = std::exp(r_at(i) + g[size_t(i)] - top);
            integral += 0.5 * dr_ * (previous + here);
            previous = here;
            out[size_t(i)] = integral > 0 ? -r_at(i) + top + std::log(integral) : -std::numeric_limits<double>::infinity();
        }
        return out;
    }

    const Forest& f_;
    int n_;
    double dr_;
};

// The forest's best fit: (bits at the best T, T).
std::pair<double, double> best_fit(const Forest& f, int grid, double r_max) {
    Likelihood like(f, grid, r_max);
    const std::vector<double> l = like.forest_log();
    const size_t best = size_t(std::max_element(l.begin(), l.end()) - l.begin());
    return {-l[best] / std::log(2.0), like.r_at(int(best))};
}

// One forest of the law without forced splits: `roots` trees, every node below `cap` splitting
// after an Exp(1) wait while its birth time plus the wait is below T.
Forest simulate(size_t roots, int cap, double t, std::mt19937_64& random) {
    Forest f;
    f.cap = cap;
    std::exponential_distribution<double> wait(1.0);
    struct Todo {
        int node;
        double birth;
    };
    std::vector<Todo> todo;
    for (size_t r = 0; r < roots; ++r) {
        f.roots.push_back(int(f.level.size()));
        todo.push_back({int(f.level.size()), 0.0});
        f.level.push_back(0), f.first.push_back(-1);
    }
    while (!todo.empty()) {
        const Todo x = todo.back();
        todo.pop_back();
        const int l = f.level[size_t(x.node)];
        if (l >= cap) continue;
        const double split = x.birth + wait(random);
        if (split >= t) continue;
        f.first[size_t(x.node)] = int(f.kids.size());
        for (int k = 0; k < 4; ++k) {
            const int c = int(f.level.size());
            f.kids.push_back(c);
            f.level.push_back(l + 1), f.first.push_back(-1);
            todo.push_back({c, split});
        }
    }
    return f;
}

// The generator itself (refine_randomly's loop and random numbers) on the icosahedron, counting
// what a lower bound of the entropy of its hierarchy X needs. X is a function of the picks, so
//   H(X) = H(picks) - H(picks | X) >= H(picks) - H(m | X) - H(picks | X, m),
// m the number of picks. Each pick is uniform among the E_t leaves below the cap, so H(picks) =
// E[sum_t log2 E_t]; H(m | X) <= log2 |I|, I the split nodes of X; and H(picks | X, m) <=
// E[log2 N(X, m)], N(X, m) the pick sequences of length m that give X. Such a sequence orders a
// set S of m split nodes, ancestors first (a pick is a leaf and every node splits once). S holds
// every split node no rule could have forced (F: a node is forced only if, in X, a same-level
// neighbour has a split child beside it or all three same-level neighbours are split; the rest,
// R, may be picked or forced). So N(X, m) <= C(|R|, m - |F|) * max_S e(S), and the hook length
// formula of forests gives e(S) = m! / prod_{v in S} |S below v|, where |S below v| >= |F below v|
// on F and >= 1 + |F below v| on R (of which S holds m - |F|: the smallest such factors bound it).
struct GeneratorRun {
    double pick_bits = 0;     // sum_t log2 E_t
    double bound_bits = 0;    // log2 |I| + log2 C(|R|, m - |F|) + log2 m! - sum_F log2 |F below v|
    size_t picks = 0, splits = 0, required = 0;
    Hierarchy h;
    std::vector<uint8_t> could_be_forced;  // by node id of h: a split node of R
};

GeneratorRun run_generator(uint32_t target_leaves, int max_level, uint64_t seed) {
    SplitMix64 random{seed};  // as adaptive_refinement.cpp
    GeneratorRun run;
    Hierarchy& h = run.h;
    h.reset(make_icosahedron());
    std::vector<NodeId> candidates = h.leaves();
    std::vector<NodeId> split;
    size_t eligible = candidates.size();
    while (h.leaf_count() < target_leaves && !candidates.empty()) {
        const size_t pick = random.below(candidates.size());
        const NodeId n = candidates[pick];
        if (!h.is_alive(n) || !h.is_leaf(n) || h.level(n) >= max_level) {
            candidates[pick] = candidates.back();
            candidates.pop_back();
            continue;
        }
        run.pick_bits += std::log2(double(eligible));
        ++run.picks;
        split.clear();
        h.refine(n, &split);
        for (NodeId s : split) {
            eligible += (h.level(s) + 1 < max_level ? 4 : 0) - 1;
            for (int k = 0; k < 4; ++k) candidates.push_back(h.child(s, k));
        }
        run.splits += split.size();
    }
    // The split nodes a rule could have forced (R), then F's counts below each F node.
    const std::vector<NodeId> order = h.breadth_first_order();
    std::vector<uint8_t> could_be_forced(h.node_capacity(), 0);
    size_t internal = 0;
    for (NodeId v : order) {
        if (h.is_leaf(v)) continue;
        ++internal;
        int split_neighbours = 0;
        bool beside = false;
        for (int e = 0; e < 3; ++e) {
            const NodeId q = h.neighbor(v, e);
            if (q == kNoNode || h.is_leaf(q)) continue;
            ++split_neighbours;
            for (int k = 0; k < 4 && !beside; ++k) {
                const NodeId c = h.child(q, k);
                if (h.is_leaf(c)) continue;
                for (int f = 0; f < 3; ++f) {
                    const NodeId r = h.neighbor(c, f);
                    if (r != kNoNode && h.parent(r) == v) beside = true;
                }
            }
        }
        if (beside || split_neighbours == 3) could_be_forced[v] = 1, ++run.required;
    }
    std::vector<double> below(h.node_capacity(), 0);  // F nodes in v's subtree, v included
    std::vector<double> r_hooks;                        // an R node's |S below v| >= 1 + F nodes below it
    double log2_hooks = 0;
    run.could_be_forced = could_be_forced;
    for (auto it = order.rbegin(); it != order.rend(); ++it) {
        const NodeId v = *it;
        if (h.is_leaf(v)) continue;
        if (!could_be_forced[v]) {
            below[v] += 1;
            log2_hooks += std::log2(below[v]);
        } else {
            r_hooks.push_back(std::log2(1 + below[v]));
        }
        if (h.parent(v) != kNoNode) below[h.parent(v)] += below[v];
    }
    // S holds m - |F| of the R nodes: at least the smallest of their factors.
    std::sort(r_hooks.begin(), r_hooks.end());
    const size_t from_r = size_t(run.picks) - (internal - run.required);
    for (size_t i = 0; i < from_r && i < r_hooks.size(); ++i) log2_hooks += r_hooks[i];
    const double free_nodes = double(internal - run.required), m = double(run.picks), r = double(run.required);
    auto log2_factorial = [](double x) { return std::lgamma(x + 1) / std::log(2.0); };
    const double choose = log2_factorial(r) - log2_factorial(m - free_nodes) - log2_factorial(r - (m - free_nodes));
    run.bound_bits = std::log2(double(internal)) + choose + log2_factorial(m) - log2_hooks;
    return run;
}

// A tighter lower bound by a sequential proposal (2026-12-05 midday). For any distribution q of
// pick sequences given X, H(picks | X) <= E[-log2 q(picks | X)] (cross-entropy), so
//   H(X) >= E[sum_t log2 E_t + log2 q(picks | X)],
// the expectation over the generator's own runs. q re-runs the picks one by one: at step t it
// draws among A_t, the leaves below the cap that X splits (the true pick is one of them), with
// weight e^theta[c] by the node's class c (R or F, times level); sum_t log2 E_t - log2 q(true
// picks) is then the bound's sample. The classes' counts at every step are kept so that theta can
// be fitted (a conditional logit, concave) on one run and applied to others.
struct PickSteps {
    static constexpr int kSizeBins = 12;  // log2 bins of the X-split nodes in the node's subtree, 1 .. 2048+
    static constexpr int kAgeBins = 12;   // log2 bins of the picks since the node's birth, 0 .. 2047+
    static constexpr int kClasses = 16 * kSizeBins * kAgeBins;  // 8 levels x {F, R} x size x age
    // A_t's nodes per class, sparse: the (class, count) pairs of step t are pairs[first[t] .. first[t + 1]).
    std::vector<std::pair<uint16_t, uint32_t>> pairs;
    std::vector<size_t> first{0};
    std::vector<uint16_t> picked;  // the true pick's class
    double pick_bits = 0;          // sum_t log2 E_t
    size_t steps() const { return picked.size(); }
};

// The split nodes of X in each node's subtree (the node included): a node with much below it was
// picked soon after its birth.
std::vector<uint32_t> split_nodes_below(const Hierarchy& x) {
    std::vector<uint32_t> below(x.node_capacity(), 0);
    const std::vector<NodeId> order = x.breadth_first_order();
    for (auto it = order.rbegin(); it != order.rend(); ++it) {
        const NodeId v = *it;
        if (x.is_leaf(v)) continue;
        below[v] += 1;
        if (x.parent(v) != kNoNode) below[x.parent(v)] += below[v];
    }
    return below;
}

// q's class of a node of A_t.
int pick_class(int level, bool could_be_forced, uint32_t below, int age_bin) {
    int bin = 0;
    while (bin + 1 < PickSteps::kSizeBins && below >= (2u << bin)) ++bin;
    return ((level * 2 + int(could_be_forced)) * PickSteps::kSizeBins + bin) * PickSteps::kAgeBins + age_bin;
}

PickSteps pick_steps(const GeneratorRun& x, uint32_t target_leaves, int max_level, uint64_t seed) {
    SplitMix64 random{seed};
    Hierarchy h(make_icosahedron());
    auto split_in_x = [&](NodeId n) { return n < x.h.node_capacity() && x.h.is_alive(n) && !x.h.is_leaf(n); };
    const std::vector<uint32_t> below = split_nodes_below(x.h);
    std::vector<uint8_t> age_bin(x.h.node_capacity(), 0);
    std::vector<std::vector<NodeId>> due;  // by step: nodes of A whose age bin grows then
    auto class_of = [&](NodeId n) { return pick_class(int(h.level(n)), x.could_be_forced[n] != 0, below[n], age_bin[n]); };
    auto schedule = [&](NodeId n, size_t birth) {  // the step at which n enters its next age bin
        if (age_bin[n] + 1 >= PickSteps::kAgeBins) return;
        const size_t at = birth + (size_t(2) << age_bin[n]) - 1;
        if (due.size() <= at) due.resize(at + 1);
        due[at].push_back(n);
    };
    std::vector<uint32_t> birth(x.h.node_capacity(), 0);
    PickSteps steps;
    std::vector<uint32_t> in_a(PickSteps::kClasses, 0);
    auto enter = [&](NodeId n, size_t t) {
        if (!split_in_x(n) || h.level(n) >= max_level) return;
        birth[n] = uint32_t(t), age_bin[n] = 0;
        ++in_a[size_t(class_of(n))];
        schedule(n, t);
    };
    std::vector<NodeId> candidates = h.leaves();
    for (NodeId n : candidates) enter(n, 0);
    std::vector<NodeId> split;
    size_t eligible = candidates.size();
    while (h.leaf_count() < target_leaves && !candidates.empty()) {
        const size_t pick = random.below(candidates.size());
        const NodeId n = candidates[pick];
        if (!h.is_alive(n) || !h.is_leaf(n) || h.level(n) >= max_level) {
            candidates[pick] = candidates.back();
            candidates.pop_back();
            continue;
        }
        if (!split_in_x(n)) throw std::runtime_error("pick_steps: a pick X does not split (the runs differ)");
        const size_t t = steps.steps();
        if (t < due.size()) {
            for (NodeId a : due[t]) {
                if (!h.is_leaf(a)) continue;  // split since: no longer in A
                --in_a[size_t(class_of(a))];
                ++age_bin[a];
                ++in_a[size_t(class_of(a))];
                schedule(a, birth[a]);
            }
            std::vector<NodeId>().swap(due[t]);
        }
        steps.pick_bits += std::log2(double(eligible));
        for (size_t c = 0; c < in_a.size(); ++c)
            if (in_a[c]) steps.pairs.push_back({uint16_t(c), in_a[c]});
        steps.first.push_back(steps.pairs.size());
        steps.picked.push_back(uint16_t(class_of(n)));
        split.clear();
        h.refine(n, &split);
        for (NodeId s : split) {
            eligible += (h.level(s) + 1 < max_level ? 4 : 0) - 1;
            --in_a[size_t(class_of(s))];
            for (int k = 0; k < 4; ++k) {
                const NodeId c = h.child(s, k);
                candidates.push_back(c);
                enter(c, t + 1);
            }
        }
    }
    return steps;
}

using ClassWeights = std::vector<double>;  // theta by class: q draws a node of A_t with weight e^theta

// -log2 q(true picks | X) under class weights e^theta.
double proposal_bits(const PickSteps& s, const ClassWeights& theta) {
    std::vector<double> e(theta.size());
    for (size_t c = 0; c < theta.size(); ++c) e[c] = std::exp(theta[c]);
    double nats = 0;
    for (size_t t = 0; t < s.steps(); ++t) {
        double z = 0;
        for (size_t k = s.first[t]; k < s.first[t + 1]; ++k) z += s.pairs[k].second * e[s.pairs[k].first];
        nats += std::log(z) - theta[s.picked[t]];
    }
    return nats / std::log(2.0);
}

// theta maximising log q(true picks | X) - theta^2 / 2 on `s` (diagonal Newton steps, halved until
// they gain; the penalty keeps classes seldom seen near 0).
ClassWeights fit_proposal(const PickSteps& s) {
    ClassWeights theta(PickSteps::kClasses, 0.0);
    auto objective = [&](const ClassWeights& th) {
        double penalty = 0;
        for (double v : th) penalty += v * v / 2;
        return proposal_bits(s, th) * std::log(2.0) + penalty;
    };
    double best = objective(theta);
    for (int it = 0; it < 60; ++it) {
        std::vector<double> grad(theta.size(), 0.0), hess(theta.size(), 1.0), e(theta.size());
        for (size_t c = 0; c < theta.size(); ++c) e[c] = std::exp(theta[c]), grad[c] = -theta[c];
        for (size_t t = 0; t < s.steps(); ++t) {
            double z = 0;
            for (size_t k = s.first[t]; k < s.first[t + 1]; ++k) z += s.pairs[k].second * e[s.pairs[k].first];
            for (size_t k = s.first[t]; k < s.first[t + 1]; ++k) {
                const double share = s.pairs[k].second * e[s.pairs[k].first] / z;
                grad[s.pairs[k].first] -= share;
                hess[s.pairs[k].first] += share * (1 - share);
            }
            grad[s.picked[t]] += 1;
        }
        bool gained = false;
        for (double alpha = 1; alpha > 1e-3 && !gained; alpha /= 2) {
            ClassWeights next = theta;
            for (size_t c = 0; c < theta.size(); ++c) next[c] += alpha * grad[c] / hess[c];
            const double b = objective(next);
            if (b < best - 1e-6) theta = next, best = b, gained = true;
        }
        if (!gained) break;
    }
    return theta;
}

// An estimate from above with the same q (importance sampling): P(X) = E_q[P(picks) / q(picks | X)]
// over pick sequences drawn from q given X (0 for one that would stop before X is complete), so
// -log2 of the mean of w = P / q over draws is, in expectation, at least -log2 P(X) (Jensen), and
// over runs of the generator at least H(X). Returns -log2 w of each draw (infinity for a draw the
// generator could not make).
std::vector<double> sampled_log_weights(const GeneratorRun& x, const ClassWeights& theta, uint32_t target_leaves, int max_level,
                                        uint64_t seed, int draws) {
    const std::vector<uint32_t> below = split_nodes_below(x.h);
    auto split_in_x = [&](NodeId n) { return x.h.is_alive(n) && !x.h.is_leaf(n); };
    size_t x_splits = 0;
    for (NodeId n = 0; n < x.h.node_capacity(); ++n) x_splits += split_in_x(n);
    std::vector<double> e(theta.size());
    for (size_t c = 0; c < theta.size(); ++c) e[c] = std::exp(theta[c]);
    std::mt19937_64 random(seed);
    std::vector<double> out;
    for (int d = 0; d < draws; ++d) {
        Hierarchy h(make_icosahedron());
        std::vector<NodeId> in_x(h.node_capacity(), kNoNode);  // this run's node -> X's node
        for (NodeId r = 0; r < h.root_count(); ++r) in_x[r] = r;
        std::vector<std::vector<NodeId>> members(PickSteps::kClasses);  // A_t by class
        std::vector<uint32_t> slot, birth;
        std::vector<uint8_t> age_bin;
        std::vector<int> class_now;
        std::vector<std::vector<NodeId>> due;
        auto grow = [&](NodeId n) {
            if (n >= slot.size()) slot.resize(n + 1), birth.resize(n + 1), age_bin.resize(n + 1), class_now.resize(n + 1, -1);
        };
        auto add = [&](NodeId n) {
            const int c = pick_class(int(h.level(n)), x.could_be_forced[in_x[n]] != 0, below[in_x[n]], age_bin[n]);
            class_now[n] = c, slot[n] = uint32_t(members[size_t(c)].size());
            members[size_t(c)].push_back(n);
        };
        auto remove = [&](NodeId n) {
            std::vector<NodeId>& m = members[size_t(class_now[n])];
            const NodeId last = m.back();
            m[slot[n]] = last, slot[last] = slot[n];
            m.pop_back();
            class_now[n] = -1;
        };
        auto schedule = [&](NodeId n) {
            if (age_bin[n] + 1 >= PickSteps::kAgeBins) return;
            const size_t at = birth[n] + (size_t(2) << age_bin[n]) - 1;
            if (due.size() <= at) due.resize(at + 1);
            due[at].push_back(n);
        };
        auto enter = [&](NodeId n, size_t t) {
            grow(n);
            if (in_x[n] == kNoNode || !split_in_x(in_x[n]) || h.level(n) >= max_level) return;
            birth[n] = uint32_t(t), age_bin[n] = 0;
            add(n);
            schedule(n);
        };
        for (NodeId r = 0; r < h.root_count(); ++r) enter(r, 0);
        size_t eligible = h.root_count(), remaining = x_splits;
        double bits = 0;  // -log2 w
        std::vector<NodeId> split;
        for (size_t t = 0; remaining > 0; ++t) {
            if (h.leaf_count() >= target_leaves) {  // the generator stops here, before X
                bits = std::numeric_limits<double>::infinity();
                break;
            }
            if (t < due.size()) {
                for (NodeId a : due[t]) {
                    if (class_now[a] < 0) continue;  // split since
                    remove(a);
                    ++age_bin[a];
                    add(a);
                    schedule(a);
                }
                std::vector<NodeId>().swap(due[t]);
            }
            double z = 0;
            for (size_t c = 0; c < members.size(); ++c) z += double(members[c].size()) * e[c];
            double u = std::uniform_real_distribution<double>(0, z)(random);
            size_t c = members.size() - 1;
            while (members[c].empty()) --c;  // the last class that has nodes (A_t is not empty: X is not complete)
            for (size_t k = 0; k < c; ++k) {
                const double share = double(members[k].size()) * e[k];
                if (u < share && !members[k].empty()) {
                    c = k;
                    break;
                }
                u -= share;
            }
            const NodeId n = members[c][std::uniform_int_distribution<size_t>(0, members[c].size() - 1)(random)];
            bits += std::log2(double(eligible)) + std::log2(e[c] / z);
            split.clear();
            h.refine(n, &split);
            for (NodeId s : split) {
                eligible += (h.level(s) + 1 < max_level ? 4 : 0) - 1;
                if (class_now[s] < 0) throw std::runtime_error("sampled_log_weights: a split outside X");
                remove(s);
                --remaining;
                for (int k = 0; k < 4; ++k) {
                    const NodeId child = h.child(s, k);
                    grow(child);
                    if (child >= in_x.size()) in_x.resize(child + 1, kNoNode);
                    in_x[child] = x.h.child(in_x[s], k);
                    enter(child, t + 1);
                }
            }
        }
        out.push_back(bits);
    }
    return out;
}

// A coder of the coder's own symbols (paper's rules and order) whose probability is the law's
// posterior: a node v of level l splits iff its clock fires within its remaining time R_v, so
// P(v splits | R_v) = 1 - e^-R_v (0 at the cap); its siblings share R_v = R_p - W_p. Before level l,
// the forest cut at level l - 1 is known: messages up (each node's cut subtree given its remaining
// time at birth) and down (the rest of the forest's) give R_p's posterior, hence R_v's; the
// siblings coded so far multiply into it. Nodes the rules imply and the cousins coded so far at
// level l are not used. Returns the code length in bits of the symbols of `trace`, and through
// `paper_bits` their code length under the paper's ten groups (adaptive, as the coder's models).
double law_coder_bits(const Hierarchy& h, const std::vector<CodedSymbol>& trace, double t, int grid, int cap,
                      double* paper_bits, double* both_bits, std::vector<double>* posterior) {
    posterior->assign(trace.size(), 0.0);
    std::vector<BitModel> both(10 * 32);  // adaptive models by group x the posterior's bin
    const int n = grid;
    const double dr = t / (n - 1);  // grid of remaining time 0 .. T
    std::vector<double> e_minus(static_cast<size_t>(n));
    for (int i = 0; i < n; ++i) e_minus[size_t(i)] = std::exp(-i * dr);
    using Row = std::vector<double>;
    auto normalise = [](Row& r) {
        double top = 0;
        for (double x : r) top = std::max(top, x);
        if (top > 0)
            for (double& x : r) x /= top;
    };
    // W convolution towards less remaining time: out(r') = integral_{r >= r'} in(r) e^-(r - r') dr.
    auto wait_down = [&](const Row& in) {
        Row out(static_cast<size_t>(n), 0.0);
        double acc = 0;
        for (int i = n - 1; i >= 0; --i) {
            acc = acc * std::exp(-dr) + in[size_t(i)] * dr;
            out[size_t(i)] = acc;
        }
        return out;
    };
    // W convolution towards more remaining time: out(r) = integral_0^r e^-s in(r - s) ds.
    auto wait_up = [&](const Row& in) {
        Row out(static_cast<size_t>(n), 0.0);
        double acc = 0;
        for (int i = 0; i < n; ++i) {
            acc = acc * std::exp(-dr) + in[size_t(i)] * dr;
            out[size_t(i)] = acc;
        }
        return out;
    };
    std::vector<int> level_of_symbol(trace.size());
    int deepest = 0;
    for (size_t i = 0; i < trace.size(); ++i) deepest = std::max(deepest, h.level(trace[i].node));
    std::vector<std::vector<size_t>> by_level(size_t(deepest) + 1);
    for (size_t i = 0; i < trace.size(); ++i) by_level[size_t(h.level(trace[i].node))].push_back(i);
    std::vector<double> cost(trace.size(), 0.0);
    const std::vector<NodeId> order = h.breadth_first_order();
    for (int l = 0; l <= deepest; ++l) {
        if (by_level[size_t(l)].empty()) continue;
        // Posterior of each level-l node's remaining time at birth, shared by siblings (by parent;
        // roots: the delta at T).
        std::vector<Row> up(h.node_capacity()), child_prior(h.node_capacity());
        if (l > 0) {
            // Up: nodes of levels <= l - 1, finest first.
            for (auto it = order.rbegin(); it != order.rend(); ++it) {
                const NodeId u = *it;
                if (h.level(u) > l - 1) continue;
                Row r(static_cast<size_t>(n));
                if (h.is_leaf(u)) {
                    for (int i = 0; i < n; ++i) r[size_t(i)] = h.level(u) >= cap ? 1.0 : e_minus[size_t(i)];
                } else if (h.level(u) == l - 1) {
                    for (int i = 0; i < n; ++i) r[size_t(i)] = 1 - e_minus[size_t(i)];
                } else {
                    Row g(static_cast<size_t>(n), 1.0);
                    for (int k = 0; k < 4; ++k)
                        for (int i = 0; i < n; ++i) g[size_t(i)] *= up[h.child(u, k)][size_t(i)];
                    r = wait_up(g);
                }
                normalise(r);
                up[u] = std::move(r);
            }
            // Down: the density of each node's remaining time at birth given everything outside
            // its cut subtree; level l - 1's refined nodes pass their children's.
            std::vector<Row> down(h.node_capacity());
            for (NodeId u : order) {
                if (h.level(u) > l - 1) continue;
                if (h.parent(u) == kNoNode) {
                    down[u].assign(size_t(n), 0.0);
                    down[u][size_t(n - 1)] = 1.0;
                }
                if (h.is_leaf(u)) continue;
                // The children's remaining time density, before the children's own subtrees.
                Row born = wait_down(down[u]);
                if (h.level(u) == l - 1) {
                    normalise(born);
                    child_prior[u] = std::move(born);
                    continue;
                }
                for (int k = 0; k < 4; ++k) {
                    Row d = born;
                    for (int j = 0; j < 4; ++j)
                        if (j != k)
                            for (int i = 0; i < n; ++i) d[size_t(i)] *= up[h.child(u, j)][size_t(i)];
                    normalise(d);
                    down[h.child(u, k)] = std::move(d);
                }
                down[u].clear(), up[u].clear();
            }
        }
        for (size_t i : by_level[size_t(l)]) {
            const NodeId v = trace[i].node;
            const NodeId p = h.parent(v);
            double refined = 0, total = 0;
            if (p == kNoNode) {
                refined = 1 - e_minus[size_t(n - 1)], total = 1;
            } else {
                const Row& g = child_prior[p];
                for (int k = 0; k < n; ++k) total += g[size_t(k)], refined += g[size_t(k)] * (1 - e_minus[size_t(k)]);
            }
            double q = l >= cap ? 0.0 : refined / std::max(total, 1e-300);
            q = std::clamp(q, 1.0 / 4096, 4095.0 / 4096);
            cost[i] = -std::log2(trace[i].refined ? q : 1 - q);
            (*posterior)[i] = q;
            {
                const int bin = std::clamp(int(std::floor(2 * std::log2(q / (1 - q)))) + 16, 0, 31);
                BitModel& m = both[size_t(trace[i].group) * 32 + size_t(bin)];
                *both_bits += m.cost_bits(trace[i].refined);
                m.update(trace[i].refined);
            }
            if (p != kNoNode) {
                Row& g = child_prior[p];
                for (int k = 0; k < n; ++k) g[size_t(k)] *= trace[i].refined ? 1 - e_minus[size_t(k)] : e_minus[size_t(k)];
                normalise(g);
            }
        }
    }
    double bits = 0;
    for (double c : cost) bits += c;
    std::vector<BitModel> groups(10);
    *paper_bits = 0;
    for (const CodedSymbol& c : trace) {
        *paper_bits += groups[c.group].cost_bits(c.refined);
        groups[c.group].update(c.refined);
    }
    return bits;
}

size_t leaves_of(const Forest& f) {
    return size_t(std::count(f.first.begin(), f.first.end(), -1));
}

}  // namespace

int main(int argc, char** argv) {
    try {
        int simulations = 0, grid = 4001, generate = 0, sequential = 0, proposal = 0, draws = 0;
        std::string path, dump;
        for (int a = 1; a < argc; ++a) {
            const std::string arg = argv[a];
            if (arg == "--simulate" && a + 1 < argc) simulations = std::atoi(argv[++a]);
            else if (arg == "--grid" && a + 1 < argc) grid = std::atoi(argv[++a]);
            else if (arg == "--generate" && a + 1 < argc) generate = std::atoi(argv[++a]);
            else if (arg == "--sequential" && a + 1 < argc) sequential = std::atoi(argv[++a]);
            else if (arg == "--proposal" && a + 1 < argc) proposal = std::atoi(argv[++a]);
            else if (arg == "--draws" && a + 1 < argc) draws = std::atoi(argv[++a]);
            else if (arg == "--dump" && a + 1 < argc) dump = argv[++a];
            else path = arg;
        }
        if (path.empty() || grid < 16) {
            std::fprintf(stderr, "usage: random_refinement_bound [--simulate K] [--grid N] [--generate K] [--sequential N [--dump OUT]] [--proposal K [--draws D]] FILE.amh\n");
            return 2;
        }
        const double r_max = 12.0;
        const Hierarchy file = read_hierarchy(path);
        // --generate K: the generator's own run at seed 7 (the corpus's, checked to give FILE) and K - 1
        // more seeds, with the entropy bound.
        for (int k = 0; k < generate; ++k) {
            const uint64_t seed = k == 0 ? 7 : 1000 + uint64_t(k);
            const GeneratorRun run = run_generator(uint32_t(150000), file.depth(), seed);
            Hierarchy library_run(make_icosahedron());  // the copy above must stay refine_randomly's loop
            refine_randomly(library_run, uint32_t(150000), file.depth(), seed);
            if (!identical(run.h, library_run)) {
                std::fprintf(stderr, "random_refinement_bound: the generator copy no longer matches refine_randomly (seed %llu)\n",
                             (unsigned long long)seed);
                return 1;
            }
            std::printf("generator, seed %llu%s: %zu picks, %zu splits (%zu forced), %zu split nodes a rule could force;"
                        " sum log2 E_t %.0f bits, log2 |I| + log2 N(X, m) <= %.0f bits, so H(X) >= %.0f bits = %.0f bytes\n",
                        (unsigned long long)seed, k == 0 ? (identical(run.h, file) ? " (= FILE)" : " (differs from FILE)") : "",
                        run.picks, run.splits, run.splits - run.picks, run.required, run.pick_bits, run.bound_bits,
                        run.pick_bits - run.bound_bits, (run.pick_bits - run.bound_bits) / 8);
            std::fflush(stdout);
        }
        // --proposal K: the sequential bound on seed 7 and K - 1 more seeds; theta fitted on seed 7.
        ClassWeights theta(PickSteps::kClasses, 0.0);
        for (int k = 0; k < proposal; ++k) {
            const uint64_t seed = k == 0 ? 7 : 1000 + uint64_t(k);
            const GeneratorRun run = run_generator(uint32_t(150000), file.depth(), seed);
            const PickSteps steps = pick_steps(run, uint32_t(150000), file.depth(), seed);
            const double uniform = proposal_bits(steps, ClassWeights(PickSteps::kClasses, 0.0));
            if (k == 0) theta = fit_proposal(steps);
            const double fitted = proposal_bits(steps, theta);
            std::printf("sequential bound, seed %llu: %zu picks, sum log2 E_t %.0f bits; -log2 q(picks | X): uniform over A_t %.0f,"
                        " by class (fitted on seed 7) %.0f; so H(X) >= %.0f / %.0f bits = %.0f / %.0f bytes\n",
                        (unsigned long long)seed, steps.steps(), steps.pick_bits, uniform, fitted, steps.pick_bits - uniform,
                        steps.pick_bits - fitted, (steps.pick_bits - uniform) / 8, (steps.pick_bits - fitted) / 8);
            if (draws > 0) {
                const std::vector<double> b = sampled_log_weights(run, theta, uint32_t(150000), file.depth(), seed + 1, draws);
                double least = std::numeric_limits<double>::infinity(), sum = 0, sum2 = 0;
                int finite = 0;
                for (double x : b)
                    if (std::isfinite(x)) least = std::min(least, x), sum += x, sum2 += x * x, ++finite;
                double mean_w = 0;  // mean of 2^(least - b), then -log2 mean w = least - log2(mean)
                for (double x : b) mean_w += std::isfinite(x) ? std::exp2(least - x) : 0.0;
                mean_w /= double(b.size());
                const double m = finite ? sum / finite : 0, sd = finite > 1 ? std::sqrt(std::max(0.0, sum2 / finite - m * m)) : 0;
                std::printf("  importance sampling, %d draws of q (%d complete X): -log2 P(X) <~ %.0f bits = %.0f bytes; -log2 w"
                            " per draw mean %.0f, sd %.0f, least %.0f bits\n",
                            draws, finite, least - std::log2(mean_w), (least - std::log2(mean_w)) / 8, m, sd, least);
            }
            std::fflush(stdout);
        }
        const Forest f = forest_of(file);
        const auto [bits, t] = best_fit(f, grid, r_max);
        if (sequential > 0) {
            std::vector<CodedSymbol> trace;
            const HierarchyLevelEncoder encoder(file, HierarchyCoderOptions{}, kHierarchyStreamVersion, &trace);
            double paper = 0, both = 0;
            std::vector<double> posterior;
            const double law = law_coder_bits(file, trace, t, sequential, file.depth(), &paper, &both, &posterior);
            if (!dump.empty()) {  // node id and posterior of each symbol, for bench/model_study's LAW_DIR
                std::FILE* out = std::fopen(dump.c_str(), "wb");
                if (!out) throw std::runtime_error("cannot write " + dump);
                for (size_t i = 0; i < trace.size(); ++i) {
                    const uint32_t node = trace[i].node;
                    const float q = float(posterior[i]);
                    std::fwrite(&node, 4, 1, out), std::fwrite(&q, 4, 1, out);
                }
                std::fclose(out);
            }
            std::printf("the coder's %zu symbols (paper's rules and order): paper's groups %.0f bits = %.0f bytes, the law's"
                        " posterior at T %.4f %.0f bits = %.0f bytes, adaptive models by group x posterior (half-octave odds bins)"
                        " %.0f bits = %.0f bytes\n",
                        trace.size(), paper, paper / 8, t, law, law / 8, both, both / 8);
        }
        std::printf("%s: %zu roots, cap %d, %zu nodes, %zu leaves\n", path.c_str(), f.roots.size(), f.cap, f.level.size(),
                    leaves_of(f));
        std::printf("  under the law (every split free), best T %.4f: %.0f bits = %.0f bytes\n", t, bits, bits / 8);
        std::mt19937_64 random(1);
        double sum = 0, sum2 = 0, leaves = 0;
        for (int k = 0; k < simulations; ++k) {
            const Forest s = simulate(f.roots.size(), f.cap, t, random);
            Likelihood like(s, grid, r_max);
            const std::vector<double> l = like.forest_log();
            const int at = int(std::lround(t / r_max * (grid - 1)));
            const double b = -l[size_t(at)] / std::log(2.0);
            sum += b, sum2 += b * b, leaves += double(leaves_of(s));
        }
        if (simulations > 0) {
            const double mean = sum / simulations, sd = std::sqrt(std::max(0.0, sum2 / simulations - mean * mean));
            std::printf("  the law's entropy at that T (%d forests, %.0f leaves on average): %.0f bits = %.0f bytes (sd %.0f bits)\n",
                        simulations, leaves / simulations, mean, mean / 8, sd);
        }
    } catch (const std::exception& e) {
        std::fprintf(stderr, "error: %s\n", e.what());
        return 1;
    }
    return 0;
}
