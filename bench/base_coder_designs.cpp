// base_coder_designs: the designs tried for the base-mesh connectivity coder, side by side
// (docs/BASE_CODER.md, "Designs"). Not a coder: every design is measured as the ideal code length
// of its symbols under the project's adaptive binary models (BitModel::cost_bits, what the
// arithmetic coder reaches within 0.01 %), raw bits counted as such, without the stream's header
// and flush. A conquest of the closed mesh (as the coders close it, base_mesh_closing.h) under a
// gate rule produces, at every gate, the operation and what a decoder knows then; each design
// codes that with its own symbols and contexts.
//
//   base_coder_designs mesh.obj mesh.off ...      (a markdown table, bits per vertex)
//   base_coder_designs --starts N mesh.obj ...    (mode 2's design from N start triangles)
//
// Gate rules: `spiral` (the vertex before the closed one, Touma–Gotsman's order), `max-degree`
// (the loop's vertex with the most decoded triangles: mode 0), `min-free` (the loop's vertex with
// the fewest missing triangles: Alliez–Desbrun; needs the valences), `angle` (the loop's vertex
// with the smallest convex gap) and `angle-r5` (the same within 5 nodes: mode 2).
// Designs: `valence` (Touma–Gotsman: the valence of every new vertex, unary with adaptive
// models, then R and L are implied; splits flagged and offset), `valence-ctx` (the same with the
// valences of the gate's two vertices as context), `degree` (mode 0's C/R/L bits with the
// decoded triangles around the gate's vertices as contexts), `angle` (R and L bits with the class
// of the gap the closing triangle would fill, split tips as "nearest to the predicted vertex"),
// `angle-deg` (class × degree), `angle-sum` (class × remaining triangles estimated from the
// angle sum at the vertex).
#include "coding/entropy/arithmetic_coder.h"
#include "coding/base/base_mesh_closing.h"

#include <amc/mesh.h>
#include <amc/mesh_io.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <vector>

namespace {

using amc::BitModel;
using amc::ClosedMesh;
using amc::kNoVertex;
using amc::Vec3;

enum class Gate { spiral, max_degree, min_free, angle, angle_r5 };
const char* gate_name(Gate g) {
    switch (g) {
        case Gate::spiral: return "spiral";
        case Gate::max_degree: return "max-degree";
        case Gate::min_free: return "min-free";
        case Gate::angle: return "angle";
        case Gate::angle_r5: return "angle-r5";
    }
    return "";
}

// What a decoder knows at a gate u -> v, and what the mesh says happens there.
struct Event {
    enum Kind { start, create, right, left, end, split, merge } kind;
    uint32_t w = 0;                       // closed vertex of the tip
    uint32_t degree_u = 0, degree_v = 0;  // decoded triangles around u, v
    uint32_t valence_u = 0, valence_v = 0;
    uint32_t free_u = 0, free_v = 0;      // triangles missing in the sectors of u and v
    uint32_t length = 0;                  // of the current loop
    double gap_u = -1, gap_v = -1;        // degrees in [0, 360); -1 with a dummy involved
    double angle_sum_u = 0;               // of the decoded triangles at u
    double bend_u = 2, bend_v = 2;        // least cosine between the closing triangle's normal and those behind it (2: unknown)
    double ratio_u = -1, ratio_v = -1;    // closing edge length over the mean of the two border edges
    double pdist_u = -1, pdist_v = -1;    // squared distance of the R (L) tip from the parallelogram, over |u - v|^2
    uint32_t offset_range = 0;            // split or merge offsets
    int nearest_rank = -1;                // split tip among the loop by distance to the prediction
    uint32_t sector_range = 0;            // splits: choices for the tip's two sectors
};

double angle_between(Vec3 x, Vec3 y) {
    const double c = amc::dot(x, y) / std::sqrt(amc::dot(x, x) * amc::dot(y, y));
    return std::acos(std::max(-1.0, std::min(1.0, c))) * 180 / M_PI;
}

// The conquest of a closed mesh under a gate rule; calls `sink` at every gate.
class Conquest {
public:
    Conquest(const ClosedMesh& cm, const std::vector<Vec3>& positions, Gate rule)
        : cm_(cm), rule_(rule), position_(cm.original.size()), located_(cm.original.size(), 0),
          valence_(cm.original.size(), 0), degree_(cm.original.size(), 0), angle_sum_(cm.original.size(), 0),
          seen_(cm.original.size(), 0), done_(cm.triangles.size(), 0), nodes_of_(cm.original.size()) {
        for (size_t x = 0; x < cm.original.size(); ++x) {
            if (cm.original[x] == kNoVertex) continue;
            position_[x] = positions[cm.original[x]];
            located_[x] = 1;
        }
        for (const amc::Triangle& t : cm.triangles)
            for (uint32_t x : t) ++valence_[x];
    }
    uint32_t valence(uint32_t x) const { return valence_[x]; }
    bool dummy(uint32_t x) const { return !located_[x]; }

    // Components start at their first triangle in input order, the first one at triangle `first`
    // with its corners rotated by `rotation` (the start-triangle experiment, --starts).
    void run(const std::function<void(const Event&)>& sink, uint32_t first = 0, uint32_t rotation = 0) {
        for (uint32_t i = 0; i < cm_.real_triangles; ++i) {
            const uint32_t s = (first + i) % cm_.real_triangles;
            if (done_[s]) continue;
            const uint32_t r = i == 0 ? rotation % 3 : 0;
            const amc::Triangle& st = cm_.triangles[s];
            const amc::Triangle t = {st[r], st[(r + 1) % 3], st[(r + 2) % 3]};
            const auto twin = [&](uint32_t k) { return cm_.twin[3 * s + (k + r) % 3]; };
            for (uint32_t x : t) seen_[x] = 1;
            add(s);
            const uint32_t id = loop_ids_++;
            const uint32_t a = node(t[0], twin(2), valence_[t[0]] - 1, id, t[1]);
            const uint32_t c = node(t[2], twin(1), valence_[t[2]] - 1, id, t[0]);
            const uint32_t b = node(t[1], twin(0), valence_[t[1]] - 1, id, t[2]);
            link(a, c);
            link(c, b);
            link(b, a);
            stack_.push_back({a, 3, id});
            Event e;
            e.kind = Event::start;
            sink(e);
            while (!stack_.empty()) step(sink);
        }
    }

private:
    struct Loop {
        uint32_t gate, length, id;
    };
    const ClosedMesh& cm_;
    Gate rule_;
    std::vector<Vec3> position_;
    std::vector<uint8_t> located_;
    std::vector<uint32_t> valence_, degree_;
    std::vector<double> angle_sum_;
    std::vector<uint8_t> seen_, done_;
    std::vector<std::vector<uint32_t>> nodes_of_;
    // Nodes: vertex, links, unprocessed halfedge across the border edge, missing triangles of
    // its sector, loop id, opposite vertex behind the edge, on the border still.
    std::vector<uint32_t> vert_, next_, prev_, out_, free_, loop_, opp_;
    std::vector<uint8_t> alive_;
    std::vector<Loop> stack_;
    uint32_t loop_ids_ = 0;

    uint32_t node(uint32_t v, uint32_t he, uint32_t free, uint32_t loop, uint32_t opp) {
        vert_.push_back(v);
        next_.push_back(kNoVertex);
        prev_.push_back(kNoVertex);
        out_.push_back(he);
        free_.push_back(free);
        loop_.push_back(loop);
        opp_.push_back(opp);
        alive_.push_back(1);
        nodes_of_[v].push_back(uint32_t(vert_.size() - 1));
        return uint32_t(vert_.size() - 1);
    }
    void link(uint32_t a, uint32_t b) {
        next_[a] = b;
        prev_[b] = a;
    }
    void add(uint32_t t) {
        done_[t] = 1;
        const amc::Triangle& tri = cm_.triangles[t];
        for (int k = 0; k < 3; ++k) {
            const uint32_t a = tri[k], b = tri[(k + 1) % 3], c = tri[(k + 2) % 3];
            ++degree_[a];
            if (located_[a] && located_[b] && located_[c])
                angle_sum_[a] += angle_between(position_[b] - position_[a], position_[c] - position_[a]);
        }
    }
    // The gap at u between v and t, oriented by the decoded triangle (v, u, o) behind u -> v.
    double gap(uint32_t u, uint32_t v, uint32_t t, uint32_t o, uint32_t at) const {
        if (!(located_[u] && located_[v] && located_[t] && located_[o])) return -1;
        const Vec3 behind = amc::cross(position_[u] - position_[v], position_[o] - position_[v]);
        const Vec3 closing = amc::cross(position_[v] - position_[u], position_[t] - position_[u]);
        const uint32_t other = at == u ? v : u;
        const double a = angle_between(position_[other] - position_[at], position_[t] - position_[at]);
        return amc::dot(behind, closing) > 0 ? a : 360 - a;
    }
    // Triangle (u, v, t) closing the gap at u, between the decoded triangles (v, u, o1) behind
    // u -> v and (u, t, o2) behind t -> u: the smaller cosine of its normal with theirs, and its
    // edge v - t over the mean of u - v and u - t.
    void closing_shape(uint32_t u, uint32_t v, uint32_t t, uint32_t o1, uint32_t o2, double& bend, double& ratio) const {
        bend = 2;
        ratio = -1;
        if (!(located_[u] && located_[v] && located_[t])) return;
        const Vec3 pu = position_[u], pv = position_[v], pt = position_[t];
        const Vec3 nc = amc::cross(pv - pu, pt - pu);
        auto cosine = [&](uint32_t a, uint32_t b, uint32_t o) {
            if (!located_[o]) return 2.0;
            const Vec3 n = amc::cross(position_[b] - position_[a], position_[o] - position_[a]);
            const double d = std::sqrt(amc::dot(n, n) * amc::dot(nc, nc));
            return d > 0 ? amc::dot(n, nc) / d : 2.0;
        };
        bend = std::min(cosine(v, u, o1), cosine(u, t, o2));
        const double a = std::sqrt(amc::dot(pv - pu, pv - pu)), b = std::sqrt(amc::dot(pt - pu, pt - pu));
        ratio = std::sqrt(amc::dot(pt - pv, pt - pv)) / (0.5 * (a + b));
    }
    double node_gap(uint32_t n) const { return gap(vert_[n], vert_[next_[n]], vert_[prev_[n]], opp_[n], vert_[n]); }
    // Smaller is a better gate.
    double angle_score(uint32_t n) const {
        if (!located_[vert_[n]]) return 1e9;
        const double g = degree_[vert_[n]] < 2 ? 300 : node_gap(n);
        return (g < 0 ? 90 : g) - 1e-3 * std::min<uint32_t>(degree_[vert_[n]], 63);
    }
    void choose_gate(uint32_t p, uint32_t nv) {
        Loop& l = stack_.back();
        l.gate = p;
        if (rule_ == Gate::spiral) return;
        auto better = [&](uint32_t a, uint32_t b) {  // is a a better gate than b
            switch (rule_) {
                case Gate::max_degree: return degree_[vert_[a]] > degree_[vert_[b]];
                case Gate::min_free: return free_[a] < free_[b];
                default: return angle_score(a) < angle_score(b);
            }
        };
        if (rule_ == Gate::angle_r5) {
            uint32_t back = p, ahead = nv;
            const uint32_t count = std::min<uint32_t>(12, l.length);
            for (uint32_t i = 1; i < count; ++i) {
                uint32_t c;
                if (i % 2 == 1) {
                    c = ahead;
                    ahead = next_[ahead];
                } else {
                    back = prev_[back];
                    c = back;
                }
                if (better(c, l.gate)) l.gate = c;
            }
            return;
        }
        uint32_t n = l.gate;
        for (uint32_t i = 1; i < l.length; ++i) {
            n = next_[n];
            if (better(n, l.gate)) l.gate = n;
        }
    }
    uint32_t sector(uint32_t n) const {
        uint32_t he = out_[n], count = 1;
        const uint32_t stop = out_[prev_[n]] / 3;
        while (he / 3 != stop) {
            he = cm_.twin[ClosedMesh::prev_halfedge(he)];
            ++count;
        }
        return count;
    }
    bool sector_holds(uint32_t n, uint32_t t) const {
        uint32_t he = out_[n];
        const uint32_t stop = out_[prev_[n]] / 3;
        for (;;) {
            if (he / 3 == t) return true;
            if (he / 3 == stop) return false;
            he = cm_.twin[ClosedMesh::prev_halfedge(he)];
        }
    }

    void step(const std::function<void(const Event&)>& sink) {
        Loop& l = stack_.back();
        const uint32_t g = l.gate, nv = next_[g], p = prev_[g], nn = next_[nv];
        const uint32_t he = out_[g], t = he / 3;
        const uint32_t u = vert_[g], v = vert_[nv], w = cm_.corner_vertex(ClosedMesh::prev_halfedge(he));
        const uint32_t to_v = cm_.twin[ClosedMesh::next_halfedge(he)], to_w = cm_.twin[ClosedMesh::prev_halfedge(he)];
        Event e;
        e.w = w;
        e.degree_u = degree_[u];
        e.degree_v = degree_[v];
        e.valence_u = valence_[u];
        e.valence_v = valence_[v];
        e.free_u = free_[g];
        e.free_v = free_[nv];
        e.length = l.length;
        e.gap_u = gap(u, v, vert_[p], opp_[g], u);
        e.gap_v = gap(u, v, vert_[nn], opp_[g], v);
        e.angle_sum_u = angle_sum_[u];
        closing_shape(u, v, vert_[p], opp_[g], opp_[p], e.bend_u, e.ratio_u);
        {  // L closes (u, v, nn): behind it (v, u, opp g) and (nn, v, opp nv)
            double b, r;
            closing_shape(v, vert_[nn], u, opp_[nv], opp_[g], b, r);
            e.bend_v = b;
            e.ratio_v = r;
        }
        if (located_[u] && located_[v] && located_[opp_[g]]) {
            const Vec3 pp = position_[u] + position_[v] - position_[opp_[g]];
            const double uv = amc::dot(position_[v] - position_[u], position_[v] - position_[u]);
            auto pd = [&](uint32_t x) { return located_[x] ? amc::dot(position_[x] - pp, position_[x] - pp) / uv : -1.0; };
            e.pdist_u = pd(vert_[p]);
            e.pdist_v = pd(vert_[nn]);
        }
        add(t);
        if (!seen_[w]) {
            seen_[w] = 1;
            e.kind = Event::create;
            sink(e);
            const uint32_t nw = node(w, to_v, valence_[w] - 1, l.id, u);
            opp_[g] = v;
            link(g, nw);
            link(nw, nv);
            out_[g] = to_w;
            --free_[g];
            --free_[nv];
            ++l.length;
            return;
        }
        if (vert_[p] == w && sector_holds(p, t)) {
            e.kind = l.length == 3 ? Event::end : Event::right;
            sink(e);
            if (l.length == 3) {
                alive_[g] = alive_[nv] = alive_[p] = 0;
                stack_.pop_back();
                return;
            }
            alive_[g] = 0;
            link(p, nv);
            out_[p] = to_v;
            opp_[p] = u;
            --free_[p];
            --free_[nv];
            --l.length;
            choose_gate(p, nv);
            return;
        }
        if (vert_[nn] == w && sector_holds(nn, t)) {
            e.kind = Event::left;
            sink(e);
            alive_[nv] = 0;
            link(g, nn);
            out_[g] = to_w;
            opp_[g] = v;
            --free_[g];
            --free_[nn];
            --l.length;
            return;
        }
        uint32_t n = kNoVertex;
        for (uint32_t c : nodes_of_[w])
            if (alive_[c] && sector_holds(c, t)) n = c;
        const uint32_t free_tip = free_[n], pn = prev_[n];
        const bool split = loop_[n] == l.id;
        e.kind = split ? Event::split : Event::merge;
        if (split) {
            e.offset_range = l.length - 4;
            if (located_[u] && located_[v] && located_[opp_[g]]) {
                const Vec3 predicted = position_[u] + position_[v] - position_[opp_[g]];
                auto distance = [&](uint32_t x) {
                    if (!located_[vert_[x]]) return 1e300;
                    const Vec3 d = position_[vert_[x]] - predicted;
                    return amc::dot(d, d);
                };
                int rank = 0;
                uint32_t x = next_[nn];
                for (uint32_t i = 2; i + 3 <= l.length; ++i, x = next_[x])
                    if (x != n && distance(x) < distance(n)) ++rank;
                e.nearest_rank = rank;
            }
        } else {
            for (const Loop& other : stack_)
                if (other.id == loop_[n]) e.offset_range = other.length;
        }
        const uint32_t nw = node(w, to_v, 0, l.id, u);
        opp_[g] = v;
        link(g, n);
        link(pn, nw);
        link(nw, nv);
        out_[g] = to_w;
        --free_[g];
        --free_[nv];
        free_[n] = sector(n);
        free_[nw] = free_tip - 1 - free_[n];
        e.sector_range = free_tip - 1;
        sink(e);
        if (split) {
            const uint32_t id = loop_ids_++;
            uint32_t length = 1;
            for (uint32_t x = nv; x != nw; x = next_[x], ++length) loop_[x] = id;
            loop_[nw] = id;
            l.length -= length - 1;
            stack_.insert(stack_.end() - 1, Loop{nw, length, id});
        } else {
            size_t index = 0;
            for (size_t j = 0; j < stack_.size(); ++j)
                if (stack_[j].id == loop_[n]) index = j;
            const uint32_t other = stack_[index].length;
            uint32_t x = n;
            for (uint32_t i = 0; i < other; ++i, x = next_[x]) loop_[x] = l.id;
            loop_[nw] = l.id;
            stack_.erase(stack_.begin() + std::ptrdiff_t(index));
            stack_.back().length += other + 1;
        }
    }
};

// Ideal adaptive code length of a design's symbols.
class Cost {
public:
    double bits = 0;
    void bit(const std::string& name, uint64_t context, bool b) {
        BitModel& m = models_[name][context];
        bits += m.cost_bits(b);
        m.update(b);
    }
    void raw(double n) { bits += n; }
    void unary(const std::string& name, uint64_t context, uint32_t value) {
        for (uint32_t i = 0; i < 16; ++i) {
            bit(name, context * 64 + i, value != i);
            if (value == i) return;
        }
        raw(2 * std::floor(std::log2(value - 15)) + 1);
    }
    void offset(uint32_t range) { raw(range > 1 ? std::ceil(std::log2(range)) : 0); }

private:
    std::map<std::string, std::map<uint64_t, BitModel>> models_;
};

int angle_class(double gap) {  // as mode 2's classes (FORMAT.md 4.11)
    if (gap < 0) return 0;
    if (gap >= 180) return 1;
    const double bounds[] = {30, 50, 70, 90, 120};
    for (int i = 0; i < 5; ++i)
        if (gap < bounds[i]) return 2 + i;
    return 7;
}

struct Design {
    std::string name;
    Gate rule;
    std::function<void(Cost&, const Event&, const Conquest&, bool holes)> code;
};

void split_or_merge(Cost& c, const Event& e, bool nearest) {
    c.bit("split", 0, e.kind == Event::split);
    if (nearest && e.kind == Event::split && e.nearest_rank >= 0) {
        c.bit("nearest", 0, e.nearest_rank == 0);
        if (e.nearest_rank == 0) return;
    }
    c.offset(e.offset_range);
}

void valence_design(Cost& c, const Event& e, const Conquest& q, bool holes, bool context) {
    if (e.kind == Event::start) return;
    if (e.free_u == 1 || e.free_v == 1) return;  // R, L or E: implied by the valences
    c.bit("new", 0, e.kind == Event::create);
    if (e.kind != Event::create) {
        split_or_merge(c, e, false);
        c.offset(e.sector_range);
        return;
    }
    if (holes) c.bit("dummy", 0, q.dummy(e.w));
    if (q.dummy(e.w)) {
        c.raw(2 * std::floor(std::log2(q.valence(e.w))) + 1);
        return;
    }
    const uint64_t ctx = context ? std::min(e.valence_u, 10u) * 11 + std::min(e.valence_v, 10u) : 0;
    c.unary("valence", ctx, q.valence(e.w) - 3);
}

void degree_design(Cost& c, const Event& e, const Conquest& q, bool holes) {
    if (e.kind == Event::start) return;
    c.bit("C", std::min(e.degree_u, 7u), e.kind == Event::create);
    if (e.kind == Event::create) {
        if (holes) c.bit("dummy", 0, q.dummy(e.w));
        return;
    }
    const bool right = e.kind == Event::right || e.kind == Event::end;
    c.bit("R", std::min(e.degree_u, 7u), right);
    if (right) return;
    if (e.length > 3) {
        c.bit("L", std::min(e.degree_v, 7u), e.kind == Event::left);
        if (e.kind == Event::left) return;
    }
    split_or_merge(c, e, false);
}

enum class AngleContext { angle_class, with_degree, with_sum };
void angle_design(Cost& c, const Event& e, const Conquest& q, bool holes, AngleContext kind) {
    if (e.kind == Event::start) return;
    uint64_t cu = angle_class(e.gap_u), cv = angle_class(e.gap_v);
    if (kind == AngleContext::with_degree) {
        cu = cu * 16 + std::min(e.degree_u, 15u);
        cv = cv * 16 + std::min(e.degree_v, 15u);
    }
    if (kind == AngleContext::with_sum) {
        const double mean = e.degree_u > 0 ? e.angle_sum_u / e.degree_u : 0;
        const double remaining = mean > 0 ? (360 - e.angle_sum_u) / mean : 0;
        cu = cu * 4 + (e.gap_u < 0 || mean <= 0 ? 0 : remaining < 1.5 ? 1 : remaining < 2.5 ? 2 : 3);
    }
    const bool right = e.kind == Event::right || e.kind == Event::end;
    if (e.degree_u >= 2) c.bit("R", cu, right);
    if (right) return;
    if (e.length > 3 && e.degree_v >= 2) {
        c.bit("L", cv, e.kind == Event::left);
        if (e.kind == Event::left) return;
    }
    c.bit("new", 0, e.kind == Event::create);
    if (e.kind == Event::create) {
        if (holes) c.bit("dummy", 0, q.dummy(e.w));
        return;
    }
    split_or_merge(c, e, true);
}


// --study: context variants of mode 2's design (angle, angle-r5), ideal code lengths with fresh
// models, and logistic mixing of several contexts' predictions (doubles: a measurement only).
class MixCost {
public:
    double bits = 0;
    std::map<std::string, double> part;
    double rate = 0.02, init = 0.3;
    // Codes `b` with the logistic mix of the models named by `contexts` (one weight set per
    // `select`), or with the first model alone when there is one.
    void bit(const std::string& name, const std::vector<uint64_t>& contexts, uint64_t select, bool b) {
        std::vector<BitModel*> ms;
        for (size_t i = 0; i < contexts.size(); ++i) ms.push_back(&models_[name + char('0' + i)][contexts[i]]);
        double p;
        if (ms.size() == 1) {
            p = ms[0]->p16() / 65536.0;
        } else {
            std::vector<double>& w = weights_[name][select];
            if (w.empty()) w.assign(ms.size(), init);
            std::vector<double> st(ms.size());
            double dot = 0;
            for (size_t i = 0; i < ms.size(); ++i) {
                const double q = ms[i]->p16() / 65536.0;
                st[i] = std::log(q / (1 - q));
                dot += w[i] * st[i];
            }
            p = 1 / (1 + std::exp(-dot));
            p = std::min(std::max(p, 1.0 / 65536), 1 - 1.0 / 65536);
            for (size_t i = 0; i < ms.size(); ++i) w[i] += rate * ((b ? 1 : 0) - p) * st[i];
        }
        const double c = -std::log2(b ? p : 1 - p);
        bits += c;
        part[name] += c;
        for (BitModel* m : ms) m->update(b);
    }
    void raw(const std::string& name, double n) {
        bits += n;
        part[name] += n;
    }

private:
    std::map<std::string, std::map<uint64_t, BitModel>> models_;
    std::map<std::string, std::map<uint64_t, std::vector<double>>> weights_;
};

int fine_class(double gap) {
    if (gap < 0) return 0;
    if (gap >= 180) return 1;
    const double bounds[] = {20, 30, 40, 50, 60, 70, 80, 90, 105, 120, 140, 160};
    for (int i = 0; i < 12; ++i)
        if (gap < bounds[i]) return 2 + i;
    return 14;
}
uint64_t pdist_bin(double d) { return d < 0 ? 0 : d < 0.25 ? 1 : d < 0.8 ? 2 : 3; }
uint64_t pdist_fine(double d) {
    if (d < 0) return 0;
    const double b[] = {0.05, 0.1, 0.2, 0.35, 0.5, 0.8, 1.2};
    for (int i = 0; i < 7; ++i)
        if (d < b[i]) return 1 + i;
    return 8;
}
uint64_t bend_bin(double c) { return c > 1.5 ? 0 : c > 0.85 ? 1 : c > 0.5 ? 2 : 3; }
uint64_t ratio_bin(double r) { return r < 0 ? 0 : r < 1.2 ? 1 : r < 1.6 ? 2 : 3; }
int coarse_class(double gap) { return gap < 0 ? 0 : gap >= 180 ? 1 : gap < 70 ? 2 : gap < 120 ? 3 : 4; }

struct Variant {
    std::string name;
    // contexts of R, L and new bits
    std::function<std::vector<uint64_t>(const Event&)> r, l, n;
    std::function<uint64_t(const Event&)> select_r = [](const Event& e) { return uint64_t(angle_class(e.gap_u)); };
    std::function<uint64_t(const Event&)> select_l = [](const Event& e) { return uint64_t(angle_class(e.gap_v)); };
};

void variant_design(MixCost& c, const Event& e, const Conquest& q, bool holes, const Variant& v) {
    if (e.kind == Event::start) return;
    const bool right = e.kind == Event::right || e.kind == Event::end;
    if (e.degree_u >= 2) c.bit("R", v.r(e), v.select_r(e), right);
    if (right) return;
    if (e.length > 3 && e.degree_v >= 2) {
        c.bit("L", v.l(e), v.select_l(e), e.kind == Event::left);
        if (e.kind == Event::left) return;
    }
    c.bit("new", v.n(e), 0, e.kind == Event::create);
    if (e.kind == Event::create) {
        if (holes) c.bit("dummy", {0}, 0, q.dummy(e.w));
        return;
    }
    c.bit("split", {0}, 0, e.kind == Event::split);
    if (e.kind == Event::split && e.nearest_rank >= 0) {
        c.bit("nearest", {0}, 0, e.nearest_rank == 0);
        if (e.nearest_rank == 0) return;
    }
    c.raw("offset", e.offset_range > 1 ? std::ceil(std::log2(e.offset_range)) : 0);
}

int run_study(int argc, char** argv, int first_file, double rate, double init) {
    using V = std::vector<uint64_t>;
    auto cu = [](const Event& e) { return uint64_t(angle_class(e.gap_u)); };
    auto cv = [](const Event& e) { return uint64_t(angle_class(e.gap_v)); };
    auto du = [](const Event& e) { return uint64_t(std::min(e.degree_u, 15u)); };
    auto dv = [](const Event& e) { return uint64_t(std::min(e.degree_v, 15u)); };
    auto zero = [](const Event&) { return V{0}; };
    const std::vector<Variant> variants = {
        {"base", [=](const Event& e) { return V{cu(e)}; }, [=](const Event& e) { return V{cv(e)}; }, zero},
        {"deg5", [=](const Event& e) { return V{cu(e) * 16 + std::min<uint64_t>(du(e), 5)}; },
         [=](const Event& e) { return V{cv(e) * 16 + std::min<uint64_t>(dv(e), 5)}; }, zero},
        {"fine", [=](const Event& e) { return V{uint64_t(fine_class(e.gap_u))}; }, [=](const Event& e) { return V{uint64_t(fine_class(e.gap_v))}; }, zero},
        {"uxv", [=](const Event& e) { return V{cu(e) * 8 + uint64_t(coarse_class(e.gap_v))}; },
         [=](const Event& e) { return V{cv(e) * 8 + uint64_t(coarse_class(e.gap_u))}; }, zero},
        {"new2", [=](const Event& e) { return V{cu(e)}; }, [=](const Event& e) { return V{cv(e)}; },
         [=](const Event& e) { return V{uint64_t(coarse_class(e.gap_u) * 8 + coarse_class(e.gap_v))}; }},
        {"newlen", [=](const Event& e) { return V{cu(e)}; }, [=](const Event& e) { return V{cv(e)}; },
         [=](const Event& e) { return V{uint64_t(std::min(e.length, 12u))}; }},
        {"pdist", [=](const Event& e) { return V{cu(e) * 4 + pdist_bin(e.pdist_u)}; }, [=](const Event& e) { return V{cv(e) * 4 + pdist_bin(e.pdist_v)}; }, zero},
        {"pdist-only", [=](const Event& e) { return V{uint64_t(cu(e) <= 1 ? cu(e) : 2 + pdist_fine(e.pdist_u))}; }, [=](const Event& e) { return V{uint64_t(cv(e) <= 1 ? cv(e) : 2 + pdist_fine(e.pdist_v))}; }, zero},
        {"mix-pdist", [=](const Event& e) { return V{cu(e), cu(e) * 4 + pdist_bin(e.pdist_u)}; }, [=](const Event& e) { return V{cv(e), cv(e) * 4 + pdist_bin(e.pdist_v)}; }, zero},
        {"bend3", [=](const Event& e) { return V{cu(e) * 4 + bend_bin(e.bend_u)}; }, [=](const Event& e) { return V{cv(e) * 4 + bend_bin(e.bend_v)}; }, zero},
        {"ratio3", [=](const Event& e) { return V{cu(e) * 4 + ratio_bin(e.ratio_u)}; }, [=](const Event& e) { return V{cv(e) * 4 + ratio_bin(e.ratio_v)}; }, zero},
        {"bendonly", [=](const Event& e) { return V{uint64_t(cu(e) <= 1 ? cu(e) : 2 + bend_bin(e.bend_u))}; }, [=](const Event& e) { return V{uint64_t(cv(e) <= 1 ? cv(e) : 2 + bend_bin(e.bend_v))}; }, zero},
        {"mix-bend", [=](const Event& e) { return V{cu(e), cu(e) * 4 + bend_bin(e.bend_u), cu(e) * 4 + ratio_bin(e.ratio_u)}; },
         [=](const Event& e) { return V{cv(e), cv(e) * 4 + bend_bin(e.bend_v), cv(e) * 4 + ratio_bin(e.ratio_v)}; }, zero},
        {"mix-deg", [=](const Event& e) { return V{cu(e), cu(e) * 16 + du(e)}; }, [=](const Event& e) { return V{cv(e), cv(e) * 16 + dv(e)}; }, zero},
        {"mix-deg-fine", [=](const Event& e) { return V{cu(e), cu(e) * 16 + du(e), uint64_t(fine_class(e.gap_u))}; },
         [=](const Event& e) { return V{cv(e), cv(e) * 16 + dv(e), uint64_t(fine_class(e.gap_v))}; }, zero},
        {"mix-all", [=](const Event& e) { return V{cu(e), cu(e) * 16 + du(e), uint64_t(fine_class(e.gap_u)), cu(e) * 8 + uint64_t(coarse_class(e.gap_v))}; },
         [=](const Event& e) { return V{cv(e), cv(e) * 16 + dv(e), uint64_t(fine_class(e.gap_v)), cv(e) * 8 + uint64_t(coarse_class(e.gap_u))}; },
         [=](const Event& e) { return V{0, uint64_t(coarse_class(e.gap_u) * 8 + coarse_class(e.gap_v))}; }},
    };
    std::printf("| mesh | V |");
    for (const Variant& v : variants) std::printf(" %s |", v.name.c_str());
    std::printf(" base: R / L / new / split+offset |\n|---|--:|");
    for (size_t i = 0; i <= variants.size(); ++i) std::printf("--:|");
    std::printf("\n");
    for (int i = first_file; i < argc; ++i) {
        const amc::TriangleMesh mesh = amc::read_mesh(argv[i]);
        ClosedMesh cm;
        try {
            cm = amc::make_closed(mesh);
        } catch (const amc::EncoderGaveUp&) {
            continue;
        }
        const double v = double(mesh.positions.size());
        std::printf("| %s | %zu |", std::filesystem::path(argv[i]).stem().c_str(), mesh.positions.size());
        std::map<std::string, double> base_part;
        for (size_t k = 0; k < variants.size(); ++k) {
            Conquest q(cm, mesh.positions, Gate::angle_r5);
            MixCost cost;
            cost.rate = rate;
            cost.init = init;
            q.run([&](const Event& e) { variant_design(cost, e, q, cm.dummies > 0, variants[k]); });
            std::printf(" %.3f |", cost.bits / v);
            if (k == 0) base_part = cost.part;
        }
        std::printf(" %.2f / %.2f / %.2f / %.2f |\n", base_part["R"] / v, base_part["L"] / v, base_part["new"] / v,
                    (base_part["split"] + base_part["nearest"] + base_part["offset"]) / v);
        std::fflush(stdout);
    }
    return 0;
}

}  // namespace

// --starts N: mode 2's design (angle, angle-r5) started at N triangles spread over the mesh, each
// in its three rotations: how much the choice of the start triangle is worth.
int run_start_experiment(int starts, int argc, char** argv, int first_file) {
    std::printf("| mesh | V | input order's start | best of %d starts | median | worst |\n|---|--:|--:|--:|--:|--:|\n", 3 * starts);
    for (int i = first_file; i < argc; ++i) {
        const amc::TriangleMesh mesh = amc::read_mesh(argv[i]);
        ClosedMesh cm;
        try {
            cm = amc::make_closed(mesh);
        } catch (const amc::EncoderGaveUp&) {
            std::fprintf(stderr, "%s: not closable\n", argv[i]);
            continue;
        }
        const double v = double(mesh.positions.size());
        std::vector<double> bits;
        for (int k = 0; k < starts; ++k)
            for (uint32_t rotation = 0; rotation < 3; ++rotation) {
                const uint32_t first = uint32_t(uint64_t(k) * cm.real_triangles / uint64_t(starts));
                Conquest q(cm, mesh.positions, Gate::angle_r5);
                Cost cost;
                q.run([&](const Event& e) { angle_design(cost, e, q, cm.dummies > 0, AngleContext::angle_class); }, first, rotation);
                bits.push_back(cost.bits / v);
            }
        const double original = bits[0];
        std::sort(bits.begin(), bits.end());
        std::printf("| %s | %zu | %.3f | %.3f | %.3f | %.3f |\n", std::filesystem::path(argv[i]).stem().c_str(),
                    mesh.positions.size(), original, bits.front(), bits[bits.size() / 2], bits.back());
        std::fflush(stdout);
    }
    return 0;
}

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(stderr, "usage: base_coder_designs [--starts N] mesh.obj ...\n");
        return 2;
    }
    if (std::string(argv[1]) == "--study" && argc > 4)
        return run_study(argc, argv, 4, std::atof(argv[2]), std::atof(argv[3]));
    if (std::string(argv[1]) == "--starts" && argc > 3) return run_start_experiment(std::max(1, std::atoi(argv[2])), argc, argv, 3);
    using namespace std::placeholders;
    const std::vector<Design> designs = {
        {"valence", Gate::min_free, [](Cost& c, const Event& e, const Conquest& q, bool h) { valence_design(c, e, q, h, false); }},
        {"valence-ctx", Gate::min_free, [](Cost& c, const Event& e, const Conquest& q, bool h) { valence_design(c, e, q, h, true); }},
        {"degree", Gate::max_degree, degree_design},
        {"degree", Gate::spiral, degree_design},
        {"angle", Gate::max_degree, [](Cost& c, const Event& e, const Conquest& q, bool h) { angle_design(c, e, q, h, AngleContext::angle_class); }},
        {"angle", Gate::angle, [](Cost& c, const Event& e, const Conquest& q, bool h) { angle_design(c, e, q, h, AngleContext::angle_class); }},
        {"angle", Gate::angle_r5, [](Cost& c, const Event& e, const Conquest& q, bool h) { angle_design(c, e, q, h, AngleContext::angle_class); }},
        {"angle-deg", Gate::angle_r5, [](Cost& c, const Event& e, const Conquest& q, bool h) { angle_design(c, e, q, h, AngleContext::with_degree); }},
        {"angle-sum", Gate::angle_r5, [](Cost& c, const Event& e, const Conquest& q, bool h) { angle_design(c, e, q, h, AngleContext::with_sum); }},
    };
    std::printf("| mesh | V | H0(valence) |");
    for (const Design& d : designs) std::printf(" %s, %s |", d.name.c_str(), gate_name(d.rule));
    std::printf("\n|---|--:|--:|");
    for (size_t i = 0; i < designs.size(); ++i) std::printf("--:|");
    std::printf("\n");
    for (int i = 1; i < argc; ++i) {
        const amc::TriangleMesh mesh = amc::read_mesh(argv[i]);
        ClosedMesh cm;
        try {
            cm = amc::make_closed(mesh);
        } catch (const amc::EncoderGaveUp&) {
            std::fprintf(stderr, "%s: not closable\n", argv[i]);
            continue;
        }
        const double v = double(mesh.positions.size());
        std::vector<uint32_t> valence(cm.original.size(), 0);
        for (const amc::Triangle& t : cm.triangles)
            for (uint32_t x : t) ++valence[x];
        std::map<uint32_t, double> histogram;
        for (uint32_t x : valence) histogram[x] += 1;
        double h0 = 0;
        for (const auto& [value, n] : histogram) h0 -= n * std::log2(n / double(valence.size()));
        std::printf("| %s | %zu | %.3f |", std::filesystem::path(argv[i]).stem().c_str(), mesh.positions.size(), h0 / v);
        for (const Design& d : designs) {
            Conquest q(cm, mesh.positions, d.rule);
            Cost cost;
            q.run([&](const Event& e) { d.code(cost, e, q, cm.dummies > 0); });
            std::printf(" %.3f |", cost.bits / v);
        }
        std::printf("\n");
        std::fflush(stdout);
    }
    return 0;
}
