// Designs beyond the mixing mode's second model (issue 30; docs/HIERARCHY_CODER.md, "The third
// model"): each model's coded symbols with the coder's features (mixed_symbols.h), coded again by
// the second model (.amc version 10, FORMAT.md 2.2) re-implemented here with switches and with
// study-only features (Extra); exact adaptive code lengths, so one run gives the table. The first
// row is the coder's own newest model (the third, version 11); the re-implementation's default must
// equal the coder's second model (checked). ONLY=text runs only the designs whose name holds it (or one of a|b|c);
// CACHE_DIR as bench/mixing_study; WEIGHTS_OUT=prefix writes the mixers' weights the models end
// with (averaged over the models) for each design with trained start weights, WEIGHTS_IN=prefix
// starts those designs from such files instead of leaving each model out of its own start.
// Designs with trained initial states ("P:") count each model table's slots over the training
// models: TRAIN=stem,stem,... names them, else each model trains on the other meshes' models.
// LAW_DIR=dir reads the random refinement's law posterior (bench/random_refinement_bound --dump).
// Designs "T:" to "Q:" (2026-12-04 evening): local thresholds, the quadric's curvatures and the
// fourth model (docs/HIERARCHY_CODER.md, "The fourth model"); "Q:" equals the coder's fourth model
// with WEIGHTS_IN of its own WEIGHTS_OUT. Designs "E:" to "Y:" (2026-12-04 night): the local
// threshold against coded nodes, SSE stages, a fifth mixer and the fifth model ("The fifth model");
// "W:" equals the coder's fifth model with WEIGHTS_IN of the third "Y:" design's WEIGHTS_OUT.
// Designs "S:", "K6:", "G6:", "C6" (2026-12-05): wider quadrics (least squares over two rings, the
// quadric's ring means), SSE after the final mean, mixer sets by level band, the refinement two
// levels up, and the sixth model ("C6h: C6d without 0 5"; docs/HIERARCHY_CODER.md, "The sixth model").
// Designs "R7:" (2026-12-05 morning): the sixth model plus its own errors as contexts (the
// probability it gave the parent's symbol, the residuals of the coded nodes two edges around,
// filled while coding from Links), slower or confidence-scaled fresh slots, trained initial states
// and its learning-cost bound ("Beyond the sixth model"). Designs "A21:" (2026-12-05 midday): the
// seventh model's form plus its own residual, per-file rates, SSE, per-set trained mixer starts
// ("Beyond the seventh model"). PER_LEVEL=name prints that design's bits per level to stderr.
//   [CACHE_DIR=dir] [ONLY=text] [WEIGHTS_OUT=prefix | WEIGHTS_IN=prefix] [TRAIN=...] [LAW_DIR=dir] model_study model.amh ...
#include "mixed_symbols.h"

#include "coding/hierarchy/context_mixing.h"

#include <array>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

namespace {

using namespace amc;
using mixed_study::ModelData;
using mixed_study::Symbol;

// Study-only features of each coded symbol's node n, all known to a decoder when the symbol comes.
struct Extra {
    uint8_t parent_curv = 0;  // the curvature feature of n's parent at its level, quarter octaves
    uint8_t gauss = 0;        // |det| of the neighbours' unit normals times the longest edge^2 over the area, quarter octaves
    uint8_t size = 0;         // n's longest edge over the level's mean longest edge, quarter octaves around 32
    uint8_t grand_curv = 0;   // the grandparent's curvature feature
    uint8_t base_size = 0;    // n's longest edge times 2^level over the base's mean longest edge, quarter octaves around 32
    // Known only if each split's new vertices were coded right after its symbol (not so in any
    // format yet): the largest displacement of a midpoint on n's edges from its chord's midpoint,
    // over its length, among same-level neighbours split before n's symbol; and how many there are.
    uint8_t nb_disp = 0;
    uint8_t nb_known = 0;
    // The random refinement only: its generator's law's posterior of the node's split (bench/
    // random_refinement_bound --dump, read from LAW_DIR/<model>.law), half-octave odds bins, 1..32
    // (0: none).
    uint8_t law = 0;
    // Local threshold: n's estimated priority (its curvature feature: curvature times longest edge)
    // against those of same-level neighbours whose symbol came before n's, refined (the least of
    // them) and not refined (the largest): half-octave bins of the ratio around 16, 0 for none.
    // *2: over the neighbours and their neighbours; p: the parent's coded same-level neighbours;
    // g: the same on the Gauss estimate (sqrt of gauss' value).
    uint8_t thr_ref = 0, thr_unref = 0, thr_ref2 = 0, thr_unref2 = 0, thr_pref = 0, thr_punref = 0, g_ref = 0, g_unref = 0;
    // A quadric z(x, y) through n's corners and its neighbours' far corners, in n's frame: |H| L,
    // sqrt|K| L and the larger principal curvature times L, quarter octaves around 40.
    uint8_t quad_h = 0, quad_k = 0, quad_max = 0;
    // |signed dihedral mean curvature| times L (each edge's chord signed by the neighbour's far
    // corner above or below n's plane), quarter octaves; threshold bins on quad H's estimate.
    uint8_t sdh = 0, qthr_ref2 = 0, qthr_unref2 = 0;
    // quad_h and quad_k without the slope terms: (A + C) L, sqrt|4AC - B^2| L.
    uint8_t flat_h = 0, flat_k = 0;
    // Session of 2026-12-04 night: the ring-2 local threshold on the quadric's sqrt|K| L (as
    // qthr_*2 on |H| L), and on |H| L and sqrt|K| L over the ring-1 coded neighbours only.
    uint8_t kthr_ref2 = 0, kthr_unref2 = 0, qthr_ref = 0, qthr_unref = 0;
    // How many coded ring-2 nodes are refined / not (capped at 7).
    uint8_t coded_ref2 = 0, coded_unref2 = 0;
    // Session of 2026-12-05: a least-squares quadric over the corners of the same-level nodes up
    // to two edges away (about 12 points, slope included), |H| L and sqrt|K| L, quarter octaves;
    // the ring-2 local threshold on its |H| L; the refinement one and two levels up: the
    // grandparent's refined neighbours (0..3, 4 none), the refined share of the parent's and the
    // grandparent's same-level nodes up to two edges away (1..9, 0 none).
    uint8_t star_h = 0, star_k = 0, sthr_ref2 = 0, sthr_unref2 = 0, gp_nbrs = 4, p_ring = 0, g_ring = 0;
    // The same fit over three rings (star3_*), and the coder's constrained form over two (cstar_*)
    // and three (cstar3_*).
    uint8_t star3_h = 0, star3_k = 0, cstar_h = 0, cstar_k = 0, cstar3_h = 0, cstar3_k = 0;
    // The 6-point quadric's |H| L and sqrt|K| L (each node's own L) averaged over n and the nodes
    // one edge away (qr1_*) or up to two (qr2_*); and the constrained 6-point form (the coder's
    // quad_mean) likewise (cq1_*, cq2_*).
    uint8_t qr1_h = 0, qr1_k = 0, qr2_h = 0, qr2_k = 0, cq1_h = 0, cq1_k = 0, cq2_h = 0, cq2_k = 0;
    // The ring-2 local threshold on cq1's |H| L value (as thr_ref2 on the curvature feature).
    uint8_t cthr_ref2 = 0, cthr_unref2 = 0;
    // Session of 2026-12-05 morning (designs "R7:"): the model's own errors as contexts, filled
    // while coding (Study::code; not in the cache): the stretched probability the study's model
    // gave n's parent's symbol (1..16, 0 when the parent was not coded), and over the same-level
    // nodes up to two edges away coded before n: the summed residual (bit - p) in half units
    // around 8 (1..15, 0 for none), the same over its deviation (z), the residual over the nodes
    // one edge away alone, and how many (at most 7).
    uint8_t dyn_parent = 0, dyn_resid = 0, dyn_z = 0, dyn_resid1 = 0, dyn_count = 0;
};

// Which earlier symbols a symbol's dynamic features read: its parent's and those of the coded
// same-level nodes up to two edges away (ring-1 ones first), by symbol index.
struct Links {
    int32_t parent = -1;
    uint8_t ring1 = 0, all = 0;
    int32_t earlier[12] = {};
};

constexpr size_t kCachedExtra = offsetof(Extra, dyn_parent);

// sqrt of the Gauss estimate of node m (|det| of its neighbours' unit normals times L^2 over the
// twice area), 0 without three neighbours.
double gauss_estimate(const Hierarchy& h, NodeId m);

// The half-octave bin of a / b around 16, 1..31; 0 when b is not > 0 (no comparison).
uint8_t ratio_bin(double a, double b) {
    if (!(b > 0)) return 0;
    if (!(a > 0)) return 1;
    return uint8_t(std::clamp(int(std::floor(2 * std::log2(a / b))) + 16, 1, 31));
}

// Solves the 6x6 system m x = r by elimination with partial pivoting; false when singular.
bool solve6(double m[6][6], double r[6], double x[6]) {
    for (int c = 0; c < 6; ++c) {
        int best = c;
        for (int i = c + 1; i < 6; ++i)
            if (std::fabs(m[i][c]) > std::fabs(m[best][c])) best = i;
        if (!(std::fabs(m[best][c]) > 1e-300)) return false;
        std::swap(m[c], m[best]);
        std::swap(r[c], r[best]);
        for (int i = c + 1; i < 6; ++i) {
            const double f = m[i][c] / m[c][c];
            for (int j = c; j < 6; ++j) m[i][j] -= f * m[c][j];
            r[i] -= f * r[c];
        }
    }
    for (int i = 5; i >= 0; --i) {
        double v = r[i];
        for (int j = i + 1; j < 6; ++j) v -= m[i][j] * x[j];
        x[i] = v / m[i][i];
    }
    return true;
}

Vec3 unit_normal_of(const Hierarchy& h, NodeId m, double* twice_area = nullptr) {
    const Vec3 a = h.position(h.vertex(m, 0)), u = h.position(h.vertex(m, 1)) - a, v = h.position(h.vertex(m, 2)) - a;
    const Vec3 x{u.y * v.z - u.z * v.y, u.z * v.x - u.x * v.z, u.x * v.y - u.y * v.x};
    const double len = std::sqrt(dot(x, x));
    if (twice_area) *twice_area = len;
    return len > 0 ? (1.0 / len) * x : Vec3{0, 0, 0};
}

double longest_edge(const Hierarchy& h, NodeId m) {
    double longest = 0;
    for (int e = 0; e < 3; ++e) {
        const Vec3 d = h.position(h.vertex(m, (e + 1) % 3)) - h.position(h.vertex(m, e));
        longest = std::max(longest, std::sqrt(dot(d, d)));
    }
    return longest;
}

double gauss_estimate(const Hierarchy& h, NodeId m) {
    double twice_area = 0;
    unit_normal_of(h, m, &twice_area);
    Vec3 nn[3] = {};
    for (int e = 0; e < 3; ++e) {
        const NodeId q = h.neighbor(m, e);
        if (q == kNoNode) return 0;
        nn[e] = unit_normal_of(h, q);
    }
    if (!(twice_area > 0)) return 0;
    const double L = longest_edge(h, m);
    const Vec3 c{nn[1].y * nn[2].z - nn[1].z * nn[2].y, nn[1].z * nn[2].x - nn[1].x * nn[2].z, nn[1].x * nn[2].y - nn[1].y * nn[2].x};
    return std::sqrt(std::abs(dot(nn[0], c)) * L * L / twice_area);
}

bool quadric_curvatures(const Hierarchy& h, NodeId n, double* Hout, double* Kout, double* flat = nullptr) {
    Vec3 pts[6];
    for (int e = 0; e < 3; ++e) {
        pts[e] = h.position(h.vertex(n, e));
        const NodeId q = h.neighbor(n, e);
        if (q == kNoNode) return false;
        pts[3 + e] = h.position(h.vertex(q, (h.neighbor_edge(n, e) + 2) % 3));
    }
    double twice_area = 0;
    const Vec3 nrm = unit_normal_of(h, n, &twice_area);
    if (!(twice_area > 0)) return false;
    const Vec3 c = (1.0 / 3.0) * (pts[0] + pts[1] + pts[2]);
    Vec3 u = pts[1] - pts[0];
    u = (1.0 / std::sqrt(dot(u, u))) * u;
    const Vec3 w{nrm.y * u.z - nrm.z * u.y, nrm.z * u.x - nrm.x * u.z, nrm.x * u.y - nrm.y * u.x};
    double m[6][6], r[6], sol[6];
    for (int k = 0; k < 6; ++k) {
        const Vec3 d = pts[k] - c;
        const double px = dot(d, u), py = dot(d, w);
        m[k][0] = px * px, m[k][1] = px * py, m[k][2] = py * py, m[k][3] = px, m[k][4] = py, m[k][5] = 1;
        r[k] = dot(d, nrm);
    }
    if (!solve6(m, r, sol)) return false;
    const double A = sol[0], B = sol[1], C = sol[2], D = sol[3], E = sol[4];
    const double g2 = 1 + D * D + E * E;
    if (flat) flat[0] = A + C, flat[1] = 4 * A * C - B * B;
    *Hout = ((1 + E * E) * A - D * E * B + (1 + D * D) * C) / std::pow(g2, 1.5);
    *Kout = (4 * A * C - B * B) / (g2 * g2);
    return std::isfinite(*Hout) && std::isfinite(*Kout);
}

double signed_dihedral(const Hierarchy& h, NodeId n) {
    double twice_area = 0;
    const Vec3 own = unit_normal_of(h, n, &twice_area);
    if (!(twice_area > 0)) return 0;
    double sum = 0;
    for (int e = 0; e < 3; ++e) {
        const Vec3 a = h.position(h.vertex(n, e)), b = h.position(h.vertex(n, (e + 1) % 3));
        const NodeId q = h.neighbor(n, e);
        if (q == kNoNode) continue;
        const Vec3 far = h.position(h.vertex(q, (h.neighbor_edge(n, e) + 2) % 3));
        const Vec3 c = own - unit_normal_of(h, q);
        const double chord = std::sqrt(dot(c, c)), len = std::sqrt(dot(b - a, b - a));
        sum += (dot(own, far - a) > 0 ? 1 : -1) * chord * len;
    }
    return std::fabs(sum) * longest_edge(h, n) / (2 * twice_area);
}

// The same-level nodes up to `depth` edges from n (n first, each once).
std::vector<NodeId> rings(const Hierarchy& h, NodeId n, int depth) {
    std::vector<NodeId> seen = {n};
    size_t begin = 0;
    for (int d = 0; d < depth; ++d) {
        const size_t end = seen.size();
        for (size_t k = begin; k < end; ++k)
            for (int e = 0; e < 3; ++e) {
                const NodeId q = h.neighbor(seen[k], e);
                if (q != kNoNode && std::find(seen.begin(), seen.end(), q) == seen.end()) seen.push_back(q);
            }
        begin = end;
    }
    return seen;
}
std::vector<NodeId> two_rings(const Hierarchy& h, NodeId n) { return rings(h, n, 2); }

// |H| L and sqrt|K| L of a least-squares quadric over the corners of rings(n, depth), L n's
// longest edge: `constrained` the coder's form (a height over n's plane vanishing at n's corners,
// three unknowns), else z = A x^2 + B xy + C y^2 + D x + E y + F in n's frame (slope included);
// false with too few points or a singular fit.
bool star_fit(const Hierarchy& h, NodeId n, int depth, bool constrained, double* hl, double* kl) {
    std::vector<VertexId> pts;
    for (NodeId m : rings(h, n, depth))
        for (int c = 0; c < 3; ++c)
            if (std::find(pts.begin(), pts.end(), h.vertex(m, c)) == pts.end()) pts.push_back(h.vertex(m, c));
    double twice_area = 0;
    const Vec3 nrm = unit_normal_of(h, n, &twice_area);
    const double L = longest_edge(h, n);
    if (!(twice_area > 0) || !(L > 0)) return false;
    if (constrained) {
        if (pts.size() < 6) return false;
        const Vec3 v0 = h.position(h.vertex(n, 0));
        const Vec3 e1 = h.position(h.vertex(n, 1)) - v0, e2 = h.position(h.vertex(n, 2)) - v0;
        const Vec3 x{e1.y * e2.z - e1.z * e2.y, e1.z * e2.x - e1.x * e2.z, e1.x * e2.y - e1.y * e2.x};
        const double a2 = dot(x, x);
        const Vec3 c1{e2.y * x.z - e2.z * x.y, e2.z * x.x - e2.x * x.z, e2.x * x.y - e2.y * x.x};
        const Vec3 c2{x.y * e1.z - x.z * e1.y, x.z * e1.x - x.x * e1.z, x.x * e1.y - x.y * e1.x};
        const Vec3 g1 = (1.0 / a2) * c1, g2 = (1.0 / a2) * c2;
        double m[3][3] = {}, t[3] = {};
        for (VertexId v : pts) {
            const Vec3 r = h.position(v) - v0;
            const double b1 = dot(r, g1), b2 = dot(r, g2), b0 = 1 - b1 - b2;
            const double row[3] = {b0 * b1, b1 * b2, b2 * b0}, z = dot(r, nrm);
            for (int i = 0; i < 3; ++i) {
                for (int j = 0; j < 3; ++j) m[i][j] += row[i] * row[j];
                t[i] += row[i] * z;
            }
        }
        const double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
        if (!(std::fabs(det) > 0)) return false;
        double a[3];
        for (int k = 0; k < 3; ++k) {
            double mk[3][3];
            for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j) mk[i][j] = j == k ? t[i] : m[i][j];
            a[k] = (mk[0][0] * (mk[1][1] * mk[2][2] - mk[1][2] * mk[2][1]) - mk[0][1] * (mk[1][0] * mk[2][2] - mk[1][2] * mk[2][0]) +
                    mk[0][2] * (mk[1][0] * mk[2][1] - mk[1][1] * mk[2][0])) / det;
        }
        const double P = -2 * a[0], R = -2 * a[2], Q = (a[1] - a[0]) - a[2];
        const double mean = (P * dot(g1, g1) + 2 * Q * dot(g1, g2) + R * dot(g2, g2)) * 0.5;
        const double gauss = (P * R - Q * Q) / a2;
        if (!std::isfinite(mean) || !std::isfinite(gauss)) return false;
        *hl = std::fabs(mean) * L, *kl = std::sqrt(std::fabs(gauss)) * L;
        return true;
    }
    if (pts.size() < 7) return false;
    const Vec3 c = (1.0 / 3.0) * (h.position(h.vertex(n, 0)) + h.position(h.vertex(n, 1)) + h.position(h.vertex(n, 2)));
    Vec3 u = h.position(h.vertex(n, 1)) - h.position(h.vertex(n, 0));
    u = (1.0 / std::sqrt(dot(u, u))) * u;
    const Vec3 w{nrm.y * u.z - nrm.z * u.y, nrm.z * u.x - nrm.x * u.z, nrm.x * u.y - nrm.y * u.x};
    double m[6][6] = {}, r[6] = {}, sol[6];
    for (VertexId v : pts) {
        const Vec3 d = (1.0 / L) * (h.position(v) - c);
        const double px = dot(d, u), py = dot(d, w), z = dot(d, nrm);
        const double row[6] = {px * px, px * py, py * py, px, py, 1};
        for (int i = 0; i < 6; ++i) {
            for (int j = 0; j < 6; ++j) m[i][j] += row[i] * row[j];
            r[i] += row[i] * z;
        }
    }
    if (!solve6(m, r, sol)) return false;
    const double A = sol[0], B = sol[1], C = sol[2], D = sol[3], E = sol[4];
    const double g2 = 1 + D * D + E * E;
    const double H = ((1 + E * E) * A - D * E * B + (1 + D * D) * C) / std::pow(g2, 1.5);
    const double K = (4 * A * C - B * B) / (g2 * g2);
    if (!std::isfinite(H) || !std::isfinite(K)) return false;
    *hl = std::fabs(H), *kl = std::sqrt(std::fabs(K));
    return true;
}
bool star_quadric(const Hierarchy& h, NodeId n, double* hl, double* kl) { return star_fit(h, n, 2, false, hl, kl); }

// 1 + 8 x the refined share of two_rings(m) without m (all decided: a coarser level), 0 for none.
uint8_t refined_share(const Hierarchy& h, NodeId m) {
    int refined = 0, total = 0;
    for (NodeId q : two_rings(h, m))
        if (q != m) refined += !h.is_leaf(q), ++total;
    return total ? uint8_t(1 + (8 * refined + total / 2) / total) : 0;
}

std::vector<Extra> extra_features(const std::string& path, const std::filesystem::path& cache, size_t count) {
    const std::filesystem::path file = cache / (std::filesystem::path(path).stem().string() + ".x10");
    std::vector<Extra> out(count);
    if (std::ifstream in{file, std::ios::binary}) {
        for (Extra& x : out) in.read(reinterpret_cast<char*>(&x), std::streamsize(kCachedExtra));
        if (in) return out;
    }
    const Hierarchy h = read_hierarchy(path);
    std::vector<CodedSymbol> trace;
    const HierarchyLevelEncoder mixed(h, HierarchyCoderOptions{}, kHierarchyStreamVersion, &trace, true);
    std::vector<double> level_sum(64, 0), level_count(64, 0);
    for (NodeId n = 0; n < NodeId(h.node_count()); ++n) {
        const int l = std::min(h.level(n), 63);
        level_sum[size_t(l)] += longest_edge(h, n);
        level_count[size_t(l)] += 1;
    }
    std::vector<size_t> symbol_of(h.node_count(), SIZE_MAX);
    for (size_t i = 0; i < trace.size(); ++i) symbol_of[trace[i].node] = std::min(symbol_of[trace[i].node], i);
    std::vector<uint8_t> law_of(h.node_capacity(), 0);
    std::vector<double> star_h(h.node_capacity(), std::nan(""));
    std::vector<double> cq1_of(h.node_capacity(), 0);
    std::vector<std::array<double, 4>> quad_memo(h.node_capacity(), {std::nan(""), 0, 0, 0});
    if (const char* dir = std::getenv("LAW_DIR")) {
        std::ifstream in(std::filesystem::path(dir) / (std::filesystem::path(path).stem().string() + ".law"), std::ios::binary);
        uint32_t node = 0;
        float q = 0;
        while (in.read(reinterpret_cast<char*>(&node), 4) && in.read(reinterpret_cast<char*>(&q), 4))
            if (node < law_of.size()) law_of[node] = uint8_t(std::clamp(int(std::floor(2 * std::log2(q / (1 - q)))) + 17, 1, 32));
    }
    for (size_t i = 0; i < count && i < trace.size(); ++i) {
        const NodeId n = trace[i].node;
        Extra& x = out[i];
        x.law = law_of[n];
        double largest = 0;
        for (int e = 0; e < 3; ++e) {
            const NodeId q = h.neighbor(n, e);
            if (q == kNoNode || h.is_leaf(q) || symbol_of[q] >= i) continue;
            const Vec3 a = h.position(h.vertex(n, e)), b = h.position(h.vertex(n, (e + 1) % 3));
            const Vec3 d = h.position(h.midpoint(q, h.neighbor_edge(n, e))) - 0.5 * (a + b);
            const Vec3 chord = b - a;
            largest = std::max(largest, std::sqrt(dot(d, d) / dot(chord, chord)));
            ++x.nb_known;
        }
        if (x.nb_known) x.nb_disp = uint8_t(std::max(1, mixed_study::quarter_bin(largest)));
        {
            // Local threshold comparisons against coded same-level nodes decided before n.
            const double own = mixed_study::raw_curvature(h, n), own_g = gauss_estimate(h, n);
            double min_ref = -1, max_unref = -1, min_ref2 = -1, max_unref2 = -1, gmin_ref = -1, gmax_unref = -1;
            auto take = [&](NodeId q, bool ring1) {
                if (q == kNoNode || q == n || symbol_of[q] >= i) return;
                const double c = mixed_study::raw_curvature(h, q), g = gauss_estimate(h, q);
                if (!h.is_leaf(q)) {
                    if (ring1) min_ref = min_ref < 0 ? c : std::min(min_ref, c), gmin_ref = gmin_ref < 0 ? g : std::min(gmin_ref, g);
                    min_ref2 = min_ref2 < 0 ? c : std::min(min_ref2, c);
                } else {
                    if (ring1) max_unref = std::max(max_unref, c), gmax_unref = std::max(gmax_unref, g);
                    max_unref2 = std::max(max_unref2, c);
                }
            };
            for (int e = 0; e < 3; ++e) {
                const NodeId q = h.neighbor(n, e);
                if (q == kNoNode) continue;
                take(q, true);
                for (int f = 0; f < 3; ++f) take(h.neighbor(q, f), false);
            }
            x.thr_ref = ratio_bin(own, min_ref), x.thr_unref = ratio_bin(own, max_unref);
            x.thr_ref2 = ratio_bin(own, min_ref2), x.thr_unref2 = ratio_bin(own, max_unref2);
            x.g_ref = ratio_bin(own_g, gmin_ref), x.g_unref = ratio_bin(own_g, gmax_unref);
            const NodeId par = h.parent(n);
            if (par != kNoNode) {
                double pmin = -1, pmax = -1;
                for (int e = 0; e < 3; ++e) {
                    const NodeId q = h.neighbor(par, e);
                    if (q == kNoNode || symbol_of[q] == SIZE_MAX) continue;
                    const double c = mixed_study::raw_curvature(h, q);
                    if (!h.is_leaf(q)) pmin = pmin < 0 ? c : std::min(pmin, c);
                    else pmax = std::max(pmax, c);
                }
                x.thr_pref = ratio_bin(own, pmin), x.thr_punref = ratio_bin(own, pmax);
            }
        }
        {
            double H = 0, K = 0, flat[2] = {0, 0};
            if (quadric_curvatures(h, n, &H, &K, flat)) {
                x.flat_h = uint8_t(mixed_study::quarter_bin(std::fabs(flat[0]) * longest_edge(h, n)));
                x.flat_k = uint8_t(mixed_study::quarter_bin(std::sqrt(std::fabs(flat[1])) * longest_edge(h, n)));
                const double L = longest_edge(h, n);
                x.quad_h = uint8_t(mixed_study::quarter_bin(std::fabs(H) * L));
                x.quad_k = uint8_t(mixed_study::quarter_bin(std::sqrt(std::fabs(K)) * L));
                x.quad_max = uint8_t(mixed_study::quarter_bin((std::fabs(H) + std::sqrt(std::max(H * H - K, 0.0))) * L));
            }
            x.sdh = uint8_t(mixed_study::quarter_bin(signed_dihedral(h, n)));
            double min_ref = -1, max_unref = -1, kmin_ref = -1, kmax_unref = -1, min_ref1 = -1, max_unref1 = -1;
            int nref = 0, nunref = 0;
            const double own = std::fabs(H) * longest_edge(h, n), own_k = std::sqrt(std::fabs(K)) * longest_edge(h, n);
            auto take = [&](NodeId q, bool ring1) {
                if (q == kNoNode || q == n || symbol_of[q] >= i) return;
                double qh = 0, qk = 0;
                quadric_curvatures(h, q, &qh, &qk);
                const double c = std::fabs(qh) * longest_edge(h, q), ck = std::sqrt(std::fabs(qk)) * longest_edge(h, q);
                if (!h.is_leaf(q)) {
                    min_ref = min_ref < 0 ? c : std::min(min_ref, c), kmin_ref = kmin_ref < 0 ? ck : std::min(kmin_ref, ck), ++nref;
                    if (ring1) min_ref1 = min_ref1 < 0 ? c : std::min(min_ref1, c);
                } else {
                    max_unref = std::max(max_unref, c), kmax_unref = std::max(kmax_unref, ck), ++nunref;
                    if (ring1) max_unref1 = std::max(max_unref1, c);
                }
            };
            for (int e = 0; e < 3; ++e) {
                const NodeId q = h.neighbor(n, e);
                if (q == kNoNode) continue;
                take(q, true);
                for (int f = 0; f < 3; ++f) take(h.neighbor(q, f), false);
            }
            x.qthr_ref2 = ratio_bin(own, min_ref), x.qthr_unref2 = ratio_bin(own, max_unref);
            x.kthr_ref2 = ratio_bin(own_k, kmin_ref), x.kthr_unref2 = ratio_bin(own_k, kmax_unref);
            x.qthr_ref = ratio_bin(own, min_ref1), x.qthr_unref = ratio_bin(own, max_unref1);
            x.coded_ref2 = uint8_t(std::min(nref, 7)), x.coded_unref2 = uint8_t(std::min(nunref, 7));
        }
        {
            auto star_h_of = [&](NodeId m) {
                if (std::isnan(star_h[m])) {
                    double hl = 0, kl = 0;
                    if (!star_quadric(h, m, &hl, &kl)) hl = 0;
                    star_h[m] = hl;
                }
                return star_h[m];
            };
            double hl = 0, kl = 0;
            if (star_fit(h, n, 3, false, &hl, &kl)) x.star3_h = uint8_t(mixed_study::quarter_bin(hl)), x.star3_k = uint8_t(mixed_study::quarter_bin(kl));
            if (star_fit(h, n, 2, true, &hl, &kl)) x.cstar_h = uint8_t(mixed_study::quarter_bin(hl)), x.cstar_k = uint8_t(mixed_study::quarter_bin(kl));
            if (star_fit(h, n, 3, true, &hl, &kl)) x.cstar3_h = uint8_t(mixed_study::quarter_bin(hl)), x.cstar3_k = uint8_t(mixed_study::quarter_bin(kl));
            if (star_quadric(h, n, &hl, &kl)) {
                x.star_h = uint8_t(mixed_study::quarter_bin(hl));
                x.star_k = uint8_t(mixed_study::quarter_bin(kl));
                star_h[n] = hl;
            } else {
                star_h[n] = 0;
            }
            double min_ref = -1, max_unref = -1;
            for (NodeId q : two_rings(h, n)) {
                if (q == n || symbol_of[q] >= i) continue;
                const double cq = star_h_of(q);
                if (!h.is_leaf(q)) min_ref = min_ref < 0 ? cq : std::min(min_ref, cq);
                else max_unref = std::max(max_unref, cq);
            }
            x.sthr_ref2 = ratio_bin(star_h[n], min_ref), x.sthr_unref2 = ratio_bin(star_h[n], max_unref);
            {
                double sums[4][2] = {};
                int counts[2] = {0, 0};
                const std::vector<NodeId> around = two_rings(h, n);
                for (size_t k = 0; k < around.size(); ++k) {
                    const NodeId q = around[k];
                    if (std::isnan(quad_memo[q][0])) {
                        double qh = 0, qk = 0;
                        if (!quadric_curvatures(h, q, &qh, &qk)) qh = qk = 0;
                        const double L = longest_edge(h, q);
                        quad_memo[q][0] = std::fabs(qh) * L, quad_memo[q][1] = std::sqrt(std::fabs(qk)) * L;
                        double ch = 0, ck = 0;
                        if (!star_fit(h, q, 1, true, &ch, &ck)) ch = ck = 0;
                        quad_memo[q][2] = ch, quad_memo[q][3] = ck;
                    }
                    const bool ring1 = k <= 3 && (k == 0 || h.neighbor(n, 0) == q || h.neighbor(n, 1) == q || h.neighbor(n, 2) == q);
                    for (int j = 0; j < 4; ++j) {
                        if (ring1) sums[j][0] += quad_memo[q][size_t(j)];
                        sums[j][1] += quad_memo[q][size_t(j)];
                    }
                    counts[0] += ring1, counts[1] += 1;
                }
                auto bin = [](double v) { return uint8_t(mixed_study::quarter_bin(v)); };
                x.qr1_h = bin(sums[0][0] / counts[0]), x.qr1_k = bin(sums[1][0] / counts[0]);
                x.qr2_h = bin(sums[0][1] / counts[1]), x.qr2_k = bin(sums[1][1] / counts[1]);
                x.cq1_h = bin(sums[2][0] / counts[0]), x.cq1_k = bin(sums[3][0] / counts[0]);
                x.cq2_h = bin(sums[2][1] / counts[1]), x.cq2_k = bin(sums[3][1] / counts[1]);
                cq1_of[n] = sums[2][0] / counts[0];
                double min_ref = -1, max_unref = -1;
                for (NodeId q : around) {
                    if (q == n || symbol_of[q] >= i) continue;
                    const double cq = cq1_of[q];  // coded before n: computed then
                    if (!h.is_leaf(q)) min_ref = min_ref < 0 ? cq : std::min(min_ref, cq);
                    else max_unref = std::max(max_unref, cq);
                }
                x.cthr_ref2 = ratio_bin(cq1_of[n], min_ref), x.cthr_unref2 = ratio_bin(cq1_of[n], max_unref);
            }
            const NodeId par = h.parent(n);
            if (par != kNoNode) {
                x.p_ring = refined_share(h, par);
                const NodeId gp = h.parent(par);
                if (gp != kNoNode) {
                    x.g_ring = refined_share(h, gp);
                    int r = 0;
                    for (int e = 0; e < 3; ++e) {
                        const NodeId q = h.neighbor(gp, e);
                        r += q != kNoNode && !h.is_leaf(q);
                    }
                    x.gp_nbrs = uint8_t(r);
                }
            }
        }
        const NodeId p = h.parent(n);
        if (p != kNoNode) {
            x.parent_curv = uint8_t(mixed_study::quarter_bin(mixed_study::raw_curvature(h, p)));
            const NodeId g = h.parent(p);
            if (g != kNoNode) x.grand_curv = uint8_t(mixed_study::quarter_bin(mixed_study::raw_curvature(h, g)));
        }
        double twice_area = 0;
        unit_normal_of(h, n, &twice_area);
        Vec3 nn[3] = {};
        bool all = true;
        for (int e = 0; e < 3; ++e) {
            const NodeId q = h.neighbor(n, e);
            if (q == kNoNode) all = false;
            else nn[e] = unit_normal_of(h, q);
        }
        const double longest = longest_edge(h, n);
        if (all && twice_area > 0) {
            const Vec3 c{nn[1].y * nn[2].z - nn[1].z * nn[2].y, nn[1].z * nn[2].x - nn[1].x * nn[2].z, nn[1].x * nn[2].y - nn[1].y * nn[2].x};
            x.gauss = uint8_t(std::clamp(mixed_study::quarter_bin(std::abs(dot(nn[0], c)) * longest * longest / twice_area) + 10, 0, 63));
            if (std::abs(dot(nn[0], c)) == 0) x.gauss = 0;
        }
        const int l = std::min(h.level(n), 63);
        const double mean = level_sum[size_t(l)] / std::max(1.0, level_count[size_t(l)]);
        if (longest > 0 && mean > 0) x.size = uint8_t(std::clamp(int(std::floor(4 * std::log2(longest / mean))) + 32, 1, 63));
        if (longest > 0 && level_sum[0] > 0)
            x.base_size = uint8_t(std::clamp(int(std::floor(4 * std::log2(std::ldexp(longest, h.level(n)) / (level_sum[0] / level_count[0])))) + 32, 1, 63));
    }
    std::ofstream cached(file, std::ios::binary);
    for (const Extra& x : out) cached.write(reinterpret_cast<const char*>(&x), std::streamsize(kCachedExtra));
    return out;
}

// The Links of each coded symbol (cached as <stem>.lk7).
std::vector<Links> links_of(const std::string& path, const std::filesystem::path& cache, size_t count) {
    const std::filesystem::path file = cache / (std::filesystem::path(path).stem().string() + ".lk7");
    std::vector<Links> out(count);
    if (std::ifstream in{file, std::ios::binary}) {
        in.read(reinterpret_cast<char*>(out.data()), std::streamsize(count * sizeof(Links)));
        if (in) return out;
    }
    const Hierarchy h = read_hierarchy(path);
    std::vector<CodedSymbol> trace;
    const HierarchyLevelEncoder mixed(h, HierarchyCoderOptions{}, kHierarchyStreamVersion, &trace, true);
    std::vector<size_t> symbol_of(h.node_capacity(), SIZE_MAX);
    for (size_t i = 0; i < trace.size(); ++i) symbol_of[trace[i].node] = std::min(symbol_of[trace[i].node], i);
    for (size_t i = 0; i < count && i < trace.size(); ++i) {
        const NodeId n = trace[i].node;
        Links& k = out[i];
        const NodeId p = h.parent(n);
        if (p != kNoNode && symbol_of[p] < i) k.parent = int32_t(symbol_of[p]);
        std::vector<NodeId> around = two_rings(h, n);
        auto take = [&](NodeId q) {
            if (q == n || symbol_of[q] >= i || k.all >= 12) return;
            for (int j = 0; j < k.all; ++j)
                if (k.earlier[j] == int32_t(symbol_of[q])) return;
            k.earlier[k.all++] = int32_t(symbol_of[q]);
        };
        for (int e = 0; e < 3; ++e)
            if (h.neighbor(n, e) != kNoNode) take(h.neighbor(n, e));
        k.ring1 = k.all;
        for (NodeId q : around) take(q);
    }
    std::ofstream(file, std::ios::binary).write(reinterpret_cast<const char*>(out.data()), std::streamsize(count * sizeof(Links)));
    return out;
}

struct Counts;

struct Options {
    int window_log2 = 8;       // direct models
    int extra_window_log2 = 8; // extra direct models
    int history_log2 = 6;      // the bit histories' models
    int mixer_rate = 24;
    int map_rate = 7;
    int boost = 0;             // mixer rate rate + boost * 64 / (uses of the set + 64): faster while a set is young
    int boost_span = 64;
    bool inherit_sets = false; // a weight set of mixers B and C starts, on first use, as mixer A's set g
    int inherit_models = 0;    // a direct model of tables 1..20 starts, on first use, at table 0's p with this count
    int level_cap = -1;        // at a new level every direct model's count is capped here (faster adaptation)
    int level_map = 0;         // 1: a sixth map by 8g + level; 2: the same as a chain after the mean
    int map_share = 3;         // of 4
    bool prime = false;        // code the symbols twice, count the second pass (the learning cost's bound)
    bool trained_start = false;  // mixers start at the weights the other models ended with (leave one out)
    std::array<std::vector<int32_t>, 4> start;  // mixers A, B, C, D (D: B's when not trained with D)
    // Session of 2026-12-05 midday: each weight set of mixers A-D starts at that set's own weights
    // over the other models (averaged by their uses; a set they never used at `start`).
    bool per_set_start = false;
    std::array<std::vector<int32_t>, 4> set_start;  // every set's weights, set after set
    // Extra direct models (window 2^8), each one more mixer input: their contexts.
    std::vector<std::function<uint32_t(const MixedFeatures&, const Extra&)>> extra;
    int mixer_d = 0;  // a fourth mixer: 1 set by base size / 4 x level, 2 by curvature / 4 x level, 3 by gauss / 4 x level
    int extra_set_b = 0;  // 1: mixer B's set by parent_curv / 4 instead of ring_mean / 4
    // Trained initial states (as CABAC's init tables): every direct, extra and history-map model
    // starts at the ones' share its slot had over the training models' symbols, with count
    // min(prior_count, symbols seen there); prior_count 0: flat starts.
    int prior_count = 0;
    bool prior_maps = true;  // also the history maps (else the direct and extra models only)
    bool prior_geometric_only = false;  // only the tables whose context holds a geometric feature
    const Counts* priors = nullptr;
    uint64_t drop = 0;  // inputs (bit j: mixer input j) held at 0, as if removed
    int mixers_off = 0;  // bit 0..3: mixer A..D left out of the mean
    int maps_off = 0;    // bit m: probability map m left out of the mean
    // More probability maps in the mean (SSE stages keyed by a feature): row function, rows.
    std::vector<std::pair<std::function<uint32_t(const MixedFeatures&, const Extra&)>, int>> extra_maps;
    // A fifth mixer (needs mixer_d), weight sets chosen by this function (< mixer_e_sets); starts at A's weights.
    std::function<uint32_t(const MixedFeatures&, const Extra&)> mixer_e;
    int mixer_e_sets = 1;
    // Session of 2026-12-05: an SSE stage after the final mean, rows by this function: p becomes
    // (p (4 - final_share) + map(p) final_share) / 4.
    std::function<uint32_t(const MixedFeatures&, const Extra&)> final_map;
    int final_rows = 0, final_share = 2;
    int a_band = 0;  // mixer A's sets by group x level band: 1: levels 0-2 / 3-4 / 5-7; 2: each level
    // Session of 2026-12-05 morning (learning cost): every direct and extra model starts as if it
    // had seen flat_count symbols at p = 1/2 (a slower KT ramp); confidence k > 0: a direct or
    // extra model's stretched input is scaled by n / (n + k), n the symbols its slot has seen.
    int flat_count = 0;
    int confidence = 0;
    // Bit histories of these extra tables (indices into `extra`), each one more input: the slot's
    // last up to 7 bits, mapped to a probability by an adaptive table per group x history (as the
    // second model's three), a prior learnt from every slot for the slots seen a few times.
    std::vector<int> extra_history;
    int prior_last_extras = 0;  // > 0: trained initial states only for the last this many extra tables
    int prior_skip_last = 0;    // with prior_last_extras: not the last this many of them
    int prior_step = 0;         // > 0: a trained state's probability rounded to multiples of this in the stretched domain
    bool prior_count_fixed = false;  // every reached slot starts with count prior_count (the seventh model's form)
    // > 0: a direct or extra model coded for the first time starts, before its update, at the
    // probability the symbol was coded with, as if it had seen this many symbols (an online prior).
    int fresh_from_final = 0;
};

// Ones and symbols per slot of every model table of a Study (direct, extra, history maps).
struct Counts {
    std::vector<std::vector<std::array<uint32_t, 2>>> tables;
    void add(const Counts& o) {
        if (tables.empty()) {
            tables = o.tables;
            return;
        }
        for (size_t t = 0; t < tables.size(); ++t)
            for (size_t i = 0; i < tables[t].size(); ++i) tables[t][i][0] += o.tables[t][i][0], tables[t][i][1] += o.tables[t][i][1];
    }
};

class Mixer {
public:
    Mixer(int inputs, int sets) : n_(inputs), w_(size_t(inputs) * size_t(sets), (1 << 16) / inputs), uses_(size_t(sets), 0) {}
    bool fresh(int set) const { return uses_[size_t(set)] == 0; }
    // Every set's weights as `w`.
    void start_at(const std::vector<int32_t>& w) {
        for (size_t s = 0; s < uses_.size(); ++s) std::copy_n(w.begin(), n_, &w_[s * size_t(n_)]);
    }
    // The sets' weights averaged, each by its uses.
    std::vector<double> mean_weights() const {
        std::vector<double> m(size_t(n_), 0);
        double total = 0;
        for (size_t s = 0; s < uses_.size(); ++s) {
            total += uses_[s];
            for (int i = 0; i < n_; ++i) m[size_t(i)] += double(uses_[s]) * w_[s * size_t(n_) + size_t(i)];
        }
        for (double& x : m) x /= std::max(1.0, total);
        return m;
    }
    void set_all(const std::vector<int32_t>& w) { std::copy(w.begin(), w.end(), w_.begin()); }
    const std::vector<int32_t>& all_weights() const { return w_; }
    const std::vector<uint32_t>& uses() const { return uses_; }
    int inputs() const { return n_; }
    void copy_set(int to, const Mixer& from, int set) {
        std::copy_n(&from.w_[size_t(set) * size_t(n_)], n_, &w_[size_t(to) * size_t(n_)]);
    }
    int mix(const int* st, int set) {
        set_ = set;
        const int32_t* w = &w_[size_t(set) * size_t(n_)];
        int64_t dot = 0;
        for (int i = 0; i < n_; ++i) dot += int64_t(w[i]) * st[i];
        p_ = mixing::squash(int(std::clamp<int64_t>(dot >> 16, -mixing::kStretchLimit, mixing::kStretchLimit)));
        return p_;
    }
    void update(const int* st, bool bit, const Options& o) {
        uint32_t& uses = uses_[size_t(set_)];
        const int rate = o.mixer_rate + (o.boost ? o.boost * o.boost_span / int(std::min<uint32_t>(uses, 1 << 20) + uint32_t(o.boost_span)) : 0);
        ++uses;
        const int err = ((int(bit) << 12) - p_) * rate;
        int32_t* w = &w_[size_t(set_) * size_t(n_)];
        for (int i = 0; i < n_; ++i) w[i] += (st[i] * err + (1 << 15)) >> 16;
    }

private:
    int n_, set_ = 0, p_ = 2048;
    std::vector<int32_t> w_;
    std::vector<uint32_t> uses_;
};

class Study {
public:
    static constexpr int kBase = MixedHierarchyModel::kInputs;
    static constexpr int kDirect = MixedHierarchyModel::kDirect;
    static constexpr int kFixedInputs = MixedHierarchyModel::kSecondInputs;
    explicit Study(const Options& o)
        : o_(o), inputs_(kFixedInputs + int(o.extra.size()) + int(o.extra_history.size()) + 1), a_(inputs_, 80), b_(inputs_, 16), c_(inputs_, 160), d_(inputs_, 256), e_(inputs_, o.mixer_e_sets), st_(size_t(inputs_)) {
        extra_models_.assign(o.extra.size(), std::vector<BitModel>(1 << 16, BitModel(o.extra_window_log2)));
        extra_slot_.resize(o.extra.size());
        extra_hist_.assign(o.extra_history.size(), std::vector<uint8_t>(1 << 16, uint8_t{1}));
        extra_hist_map_.assign(o.extra_history.size(), std::vector<BitModel>(2560, BitModel(o.history_log2)));
        extra_hist_slot_.resize(o.extra_history.size());
        static constexpr uint32_t kSizes[kDirect] = {10,  40,  40,   80,   50,  120, 240, 960, 1920, 2560, 640,
                                                     10240, 3840, 200, 400, 480, 160, 640, 2560, 640, 5120};
        for (int j = 0; j < kDirect; ++j) models_[size_t(j)].assign(kSizes[j], BitModel(o.window_log2));
        for (int k = 0; k < 3; ++k) {
            histories_[size_t(k)].assign(kSizes[kIndirectOf[k]], uint8_t{1});
            history_maps_[size_t(k)].assign(2560, BitModel(o.history_log2));
        }
        for (int rows : {40, 640, 192, 2560, 200, 80}) maps_.emplace_back(rows, o.map_rate);
        for (const auto& m : o.extra_maps) maps_.emplace_back(m.second, o.map_rate);
        if (o.final_map) maps_.emplace_back(o.final_rows, o.map_rate);
        if (!o.start[0].empty()) a_.start_at(o.start[0]), b_.start_at(o.start[1]), c_.start_at(o.start[2]), d_.start_at(o.start[o.mixer_d && !o.start[3].empty() ? 3 : 1]), e_.start_at(o.start[0]);
        if (!o.set_start[0].empty()) a_.set_all(o.set_start[0]), b_.set_all(o.set_start[1]), c_.set_all(o.set_start[2]), d_.set_all(o.set_start[3]);
        for (std::vector<BitModel>* t : tables()) counts_.tables.emplace_back(t->size(), std::array<uint32_t, 2>{0, 0});
        if (o.flat_count > 0) {
            const std::vector<std::vector<BitModel>*> all = tables();
            for (size_t t = 0; t + 3 < all.size(); ++t)
                for (BitModel& m : *all[t]) m.n = uint16_t(o.flat_count);
        }
        if (o.priors && o.prior_count > 0) {
            const std::vector<std::vector<BitModel>*> all = tables();
            const size_t last = o.prior_maps ? all.size() : all.size() - 3;
            // Direct tables 6-12 and 18-20 and the extra tables read displacement, bending,
            // curvature, size or Gauss bins.
            auto geometric = [&](size_t t) { return (t >= 6 && t <= 12) || (t >= 18 && t < all.size() - 3); };
            for (size_t t = 0; t < last; ++t)
                for (size_t i = 0; i < all[t]->size() && (!o.prior_geometric_only || geometric(t)) &&
                                   (o.prior_last_extras == 0 || (t + 3 + size_t(o.prior_last_extras) >= all.size() &&
                                                                 t + 3 + size_t(o.prior_skip_last) < all.size()));
                     ++i) {
                    const auto [ones, n] = o.priors->tables[t][i];
                    ++prior_slots_[0];
                    if (n == 0) continue;
                    ++prior_slots_[1];
                    BitModel& m = (*all[t])[i];
                    double p = (ones + 0.4) / (n + 0.8);
                    if (o.prior_step > 0) {
                        const double st = std::round(std::log(p / (1 - p)) * 256 / o.prior_step) * o.prior_step / 256;
                        p = 1 / (1 + std::exp(-st));
                    }
                    m.p = uint32_t(std::clamp(p * 4294967296.0, 65536.0, 4294967296.0 - 65536.0));
                    m.n = uint16_t(o.prior_count_fixed ? uint32_t(o.prior_count) : std::min<uint32_t>(uint32_t(o.prior_count), n));
                }
        }
    }
    // The model tables in a fixed order: direct, extra, history maps.
    std::vector<std::vector<BitModel>*> tables() {
        std::vector<std::vector<BitModel>*> all;
        for (auto& t : models_) all.push_back(&t);
        for (auto& t : extra_models_) all.push_back(&t);
        for (auto& t : history_maps_) all.push_back(&t);
        return all;
    }
    Counts counts_;
    std::array<size_t, 2> prior_slots_{};  // slots of the tables with trained initial states, and those the training reached
    const Mixer& mixer(int k) const { return k == 0 ? a_ : k == 1 ? b_ : k == 2 ? c_ : d_; }
    std::array<std::vector<double>, 4> mean_weights() const {
        return {a_.mean_weights(), b_.mean_weights(), c_.mean_weights(), o_.mixer_d ? d_.mean_weights() : std::vector<double>{}};
    }

    std::array<double, 8> level_bits{}, level_symbols{}, level_ones{};
    double code(const std::vector<Symbol>& symbols, const std::vector<Extra>& extra, const std::vector<Links>* links = nullptr) {
        double bits = 0;
        std::vector<int16_t> p_of(symbols.size(), 2048);
        for (int pass = 0; pass < (o_.prime ? 2 : 1); ++pass) {
            bits = 0;
            for (size_t i = 0; i < symbols.size(); ++i) {
                const Symbol& s = symbols[i];
                Extra xi = extra[i];
                if (links) fill_dynamic(xi, (*links)[i], p_of, symbols);
                const int p = p12(s.f, xi);
                p_of[i] = int16_t(p);
                const double b = -std::log2(s.bit ? p / 4096.0 : 1 - p / 4096.0);
                bits += b;
                level_bits[s.f.level] += b, level_symbols[s.f.level] += 1, level_ones[s.f.level] += s.bit;
                update(s.bit);
            }
        }
        return bits;
    }

private:
    static constexpr int kIndirectOf[3] = {1, 4, 11};

    static void fill_dynamic(Extra& x, const Links& k, const std::vector<int16_t>& p_of, const std::vector<Symbol>& symbols) {
        if (k.parent >= 0) x.dyn_parent = uint8_t(1 + std::clamp((mixing::stretch(p_of[size_t(k.parent)]) + 2048) >> 8, 0, 15));
        double d = 0, v = 0, d1 = 0;
        for (int j = 0; j < k.all; ++j) {
            const double p = p_of[size_t(k.earlier[j])] / 4096.0;
            const double r = symbols[size_t(k.earlier[j])].bit - p;
            d += r, v += p * (1 - p);
            if (j < k.ring1) d1 += r;
        }
        x.dyn_count = uint8_t(std::min<int>(k.all, 7));
        if (k.all) {
            x.dyn_resid = uint8_t(std::clamp(int(std::floor(2 * d)) + 8, 1, 15));
            x.dyn_z = uint8_t(std::clamp(int(std::floor(2 * d / std::sqrt(v + 0.05))) + 8, 1, 15));
        }
        if (k.ring1) x.dyn_resid1 = uint8_t(std::clamp(int(std::floor(2 * d1)) + 8, 1, 15));
    }

    int p12(const MixedFeatures& f, const Extra& x) {
        const uint32_t g = f.group;
        if (f.level != level_) {
            level_ = f.level;
            if (o_.level_cap >= 0)
                for (auto& table : models_)
                    for (BitModel& m : table) m.n = uint16_t(std::min<int>(m.n, o_.level_cap));
        }
        const std::array<uint32_t, kBase> direct = MixedHierarchyModel::direct_slots(f);
        std::copy(direct.begin(), direct.end(), slot_.begin());
        const uint32_t last4 = last_ & 15;
        slot_[kBase] = g * 16 + last4;
        slot_[kBase + 1] = (g * 4 + f.inner) * 16 + last4;
        slot_[kBase + 2] = (g * 64 + f.mean_curv) * 4 + (last_ & 3);
        slot_[kBase + 3] = g * 64 + f.ring_max;
        slot_[kBase + 4] = (g * 64 + f.ring_mean) * 8 + f.level;
        for (int j = 0; j < kDirect; ++j) {
            BitModel& m = models_[size_t(j)][slot_[size_t(j)]];
            if (o_.inherit_models && j > 0 && m.n == 0 && m.p == (uint32_t{1} << 31)) {
                m.p = models_[0][g].p;
                m.n = uint16_t(o_.inherit_models);
            }
            st_[size_t(j)] = mixing::stretch(mixing::p12_of(m));
            if (o_.confidence) st_[size_t(j)] = st_[size_t(j)] * int(m.n) / (int(m.n) + o_.confidence);
        }
        for (int k = 0; k < 3; ++k) {
            hctx_[size_t(k)] = slot_[size_t(kIndirectOf[k])];
            hslot_[size_t(k)] = g * 256 + histories_[size_t(k)][hctx_[size_t(k)]];
            st_[size_t(kDirect + k)] = mixing::stretch(mixing::p12_of(history_maps_[size_t(k)][hslot_[size_t(k)]]));
        }
        for (size_t e = 0; e < o_.extra.size(); ++e) {
            extra_slot_[e] = o_.extra[e](f, x) & 0xffff;
            st_[size_t(kFixedInputs) + e] = mixing::stretch(mixing::p12_of(extra_models_[e][extra_slot_[e]]));
            if (o_.confidence) {
                const int n = extra_models_[e][extra_slot_[e]].n;
                st_[size_t(kFixedInputs) + e] = st_[size_t(kFixedInputs) + e] * n / (n + o_.confidence);
            }
        }
        for (size_t k = 0; k < o_.extra_history.size(); ++k) {
            const uint32_t slot = extra_slot_[size_t(o_.extra_history[k])];
            extra_hist_slot_[k] = g * 256 + extra_hist_[k][slot];
            st_[size_t(kFixedInputs) + o_.extra.size() + k] = mixing::stretch(mixing::p12_of(extra_hist_map_[k][extra_hist_slot_[k]]));
        }
        for (int j = 0; j < inputs_ - 1; ++j)
            if (o_.drop >> j & 1) st_[size_t(j)] = 0;
        st_[size_t(inputs_ - 1)] = 256;
        const int set_b = o_.extra_set_b == 4 ? x.cq1_h / 4 : o_.extra_set_b == 3 ? x.star_h / 4 : o_.extra_set_b == 1 ? x.parent_curv / 4 : o_.extra_set_b == 2 ? x.base_size / 4 : f.ring_mean / 4, set_c = int(g * 16 + last4);
        if (o_.inherit_sets) {
            if (b_.fresh(set_b)) b_.copy_set(set_b, a_, int(g));
            if (c_.fresh(set_c)) c_.copy_set(set_c, a_, int(g));
        }
        const int band = o_.a_band == 2 ? f.level : o_.a_band == 1 ? (f.level <= 2 ? 0 : f.level <= 4 ? 1 : 2) : 0;
        const int s1 = mixing::stretch(a_.mix(st_.data(), int(g) + 10 * band));
        const int s2 = mixing::stretch(b_.mix(st_.data(), set_b));
        const int s3 = mixing::stretch(c_.mix(st_.data(), set_c));
        int p_mix = mixing::squash((s1 + s2 + s3) / 3);
        if (o_.mixer_d) {
            const int set = o_.mixer_d == 6 ? int(g) * 16 + f.size / 4 : o_.mixer_d == 4 ? x.base_size / 2 * 8 + f.level : o_.mixer_d == 5 ? int(g) * 16 + x.base_size / 4 : (o_.mixer_d == 1 ? x.base_size : o_.mixer_d == 2 ? f.mean_curv : x.gauss) / 4 * 8 + f.level;
            const int s4 = mixing::stretch(d_.mix(st_.data(), set));
            p_mix = mixing::squash((s1 + s2 + s3 + s4) / 4);
            if (o_.mixer_e) p_mix = mixing::squash((s1 + s2 + s3 + s4 + mixing::stretch(e_.mix(st_.data(), int(o_.mixer_e(f, x))))) / 5);
            if (o_.mixers_off) {
                const int all[4] = {s1, s2, s3, s4};
                int sum = 0, n = 0;
                for (int k = 0; k < 4; ++k)
                    if (!(o_.mixers_off >> k & 1)) sum += all[k], ++n;
                p_mix = mixing::squash(sum / n);
            }
        }
        const int rows[6] = {int(g * 4 + f.inner), int(g * 64 + f.mean_curv), int(f.disp * 8 + f.level), int(g * 256 + (last_ & 255)),
                             int((g * 5 + f.ring2) * 4 + f.parent_nbrs), int(g * 8 + f.level)};
        const int maps = o_.level_map == 1 ? 6 : 5;
        int refined = 0, active = 0;
        for (int m = 0; m < maps; ++m) {
            const int r = maps_[size_t(m)].refine(p_mix, rows[m]);
            if (!(o_.maps_off >> m & 1)) refined += r, ++active;
        }
        for (size_t m = 0; m < o_.extra_maps.size(); ++m) refined += maps_[6 + m].refine(p_mix, int(o_.extra_maps[m].first(f, x))), ++active;
        int p = std::clamp((p_mix * (4 - o_.map_share) + (refined / active) * o_.map_share + 2) >> 2, 1, 4095);
        used_maps_ = maps;
        if (o_.final_map) {
            const int r = maps_[6 + o_.extra_maps.size()].refine(p, int(o_.final_map(f, x)));
            p = std::clamp((p * (4 - o_.final_share) + r * o_.final_share + 2) >> 2, 1, 4095);
        }
        if (o_.level_map == 2) {
            p = std::clamp((p + maps_[5].refine(p, rows[5]) + 1) >> 1, 1, 4095);
            used_maps_ = 6;
        }
        p_final_ = p;
        return p;
    }

    void update(bool bit) {
        if (o_.fresh_from_final > 0) {
            auto start = [&](BitModel& m) {
                if (m.n == 0) m.p = uint32_t(p_final_) << 20, m.n = uint16_t(o_.fresh_from_final);
            };
            for (int j = 0; j < kDirect; ++j) start(models_[size_t(j)][slot_[size_t(j)]]);
            for (size_t e = 0; e < extra_slot_.size(); ++e) start(extra_models_[e][extra_slot_[e]]);
        }
        {
            size_t t = 0;
            for (int j = 0; j < kDirect; ++j, ++t) counts_.tables[t][slot_[size_t(j)]][0] += bit, ++counts_.tables[t][slot_[size_t(j)]][1];
            for (size_t e = 0; e < extra_slot_.size(); ++e, ++t) counts_.tables[t][extra_slot_[e]][0] += bit, ++counts_.tables[t][extra_slot_[e]][1];
            for (int k = 0; k < 3; ++k, ++t) counts_.tables[t][hslot_[size_t(k)]][0] += bit, ++counts_.tables[t][hslot_[size_t(k)]][1];
        }
        a_.update(st_.data(), bit, o_);
        b_.update(st_.data(), bit, o_);
        c_.update(st_.data(), bit, o_);
        if (o_.mixer_d) d_.update(st_.data(), bit, o_);
        if (o_.mixer_e) e_.update(st_.data(), bit, o_);
        for (int m = 0; m < used_maps_; ++m) maps_[size_t(m)].update(bit);
        for (size_t m = 0; m < o_.extra_maps.size(); ++m) maps_[6 + m].update(bit);
        if (o_.final_map) maps_[6 + o_.extra_maps.size()].update(bit);
        for (int j = 0; j < kDirect; ++j) models_[size_t(j)][slot_[size_t(j)]].update(bit);
        for (size_t e = 0; e < extra_slot_.size(); ++e) extra_models_[e][extra_slot_[e]].update(bit);
        for (size_t k = 0; k < o_.extra_history.size(); ++k) {
            extra_hist_map_[k][extra_hist_slot_[k]].update(bit);
            uint8_t& h = extra_hist_[k][extra_slot_[size_t(o_.extra_history[k])]];
            h = uint8_t(h < 128 ? h * 2 + bit : 128 + ((h * 2 + bit) & 127));
        }
        for (int k = 0; k < 3; ++k) {
            history_maps_[size_t(k)][hslot_[size_t(k)]].update(bit);
            uint8_t& h = histories_[size_t(k)][hctx_[size_t(k)]];
            h = uint8_t(h < 128 ? h * 2 + bit : 128 + ((h * 2 + bit) & 127));
        }
        last_ = (last_ << 1) | uint32_t(bit);
    }

    Options o_;
    int inputs_;
    std::array<std::vector<BitModel>, kDirect> models_;
    std::vector<std::vector<BitModel>> extra_models_;
    std::vector<uint32_t> extra_slot_;
    std::vector<std::vector<uint8_t>> extra_hist_;
    std::vector<std::vector<BitModel>> extra_hist_map_;
    std::vector<uint32_t> extra_hist_slot_;
    std::array<std::vector<uint8_t>, 3> histories_;
    std::array<std::vector<BitModel>, 3> history_maps_;
    std::array<uint32_t, 3> hctx_{}, hslot_{};
    std::array<uint32_t, kDirect> slot_{};
    Mixer a_, b_, c_, d_, e_;
    std::vector<int> st_;
    std::vector<mixing::ProbabilityMap> maps_;
    int used_maps_ = 5;
    int p_final_ = 2048;
    uint32_t last_ = 0;
    int level_ = -1;
};

}  // namespace

int main(int argc, char** argv) {
    const std::filesystem::path cache = std::getenv("CACHE_DIR") ? std::getenv("CACHE_DIR") : "/tmp/mixing_study";
    std::vector<ModelData> data;
    std::vector<std::vector<Extra>> extras;
    std::vector<std::vector<Links>> links;
    for (int a = 1; a < argc; ++a) {
        data.push_back(mixed_study::load(argv[a], cache));
        extras.push_back(extra_features(argv[a], cache, data.back().symbols.size()));
        links.push_back(links_of(argv[a], cache, data.back().symbols.size()));
    }
    struct Design {
        std::string name;
        Options o;
    };
    std::vector<Design> designs;
    auto add = [&](const std::string& name, const std::function<void(Options&)>& change) {
        Options o;
        change(o);
        designs.push_back({name, o});
    };
    add("second model (v10), re-implemented", [](Options&) {});
    add("learning cost bound: symbols coded twice, second pass", [](Options& o) { o.prime = true; });
    for (int w : {7, 9}) add("direct window 2^" + std::to_string(w), [w](Options& o) { o.window_log2 = w; });
    for (int w : {5, 7}) add("history window 2^" + std::to_string(w), [w](Options& o) { o.history_log2 = w; });
    for (int r : {16, 32}) add("mixer rate " + std::to_string(r), [r](Options& o) { o.mixer_rate = r; });
    for (int r : {6, 8}) add("map rate " + std::to_string(r), [r](Options& o) { o.map_rate = r; });
    for (int b : {24, 72, 200}) add("mixer boost " + std::to_string(b), [b](Options& o) { o.boost = b; });
    add("mixer boost 72, span 512", [](Options& o) { o.boost = 72, o.boost_span = 512; });
    add("sets B, C inherit A's", [](Options& o) { o.inherit_sets = true; });
    for (int n : {1, 4}) add("models inherit group's p, count " + std::to_string(n), [n](Options& o) { o.inherit_models = n; });
    for (int c : {16, 62}) add("level cap " + std::to_string(c), [c](Options& o) { o.level_cap = c; });
    add("map by group x level", [](Options& o) { o.level_map = 1; });
    add("map chain by group x level", [](Options& o) { o.level_map = 2; });
    using F = const MixedFeatures&;
    using X = const Extra&;
    auto extra = [&](const std::string& name, std::function<uint32_t(F, X)> context) {
        add(name, [context](Options& o) { o.extra.push_back(context); });
    };
    extra("+ parent's curvature x level", [](F f, X x) { return (f.group * 64u + x.parent_curv) * 8 + f.level; });
    extra("+ curvature x parent's curvature", [](F f, X x) { return (f.group * 64u + f.mean_curv) * 16 + x.parent_curv / 4u; });
    extra("+ grandparent's curvature x level", [](F f, X x) { return (f.group * 64u + x.grand_curv) * 8 + f.level; });
    extra("+ gauss x level", [](F f, X x) { return (f.group * 64u + x.gauss) * 8 + f.level; });
    extra("+ gauss x curvature", [](F f, X x) { return (f.group * 64u + x.gauss) * 16 + f.mean_curv / 4u; });
    extra("+ size x level", [](F f, X x) { return (f.group * 64u + x.size) * 8 + f.level; });
    extra("+ curvature x size", [](F f, X x) { return (f.group * 64u + f.mean_curv) * 16 + x.size / 4u; });
    add("trained start weights (leave one out)", [](Options& o) { o.trained_start = true; });
    extra("+ curvature x base size", [](F f, X x) { return (f.group * 64u + f.mean_curv) * 16 + x.base_size / 4u; });
    extra("+ base size x level", [](F f, X x) { return (f.group * 64u + x.base_size) * 8 + f.level; });
    auto both = [](Options& o) {
        o.extra.push_back([](F f, X x) { return (f.group * 64u + f.mean_curv) * 16 + x.size / 4u; });
        o.extra.push_back([](F f, X x) { return (f.group * 64u + x.gauss) * 16 + f.mean_curv / 4u; });
    };
    add("combo: + curvature x size, gauss x curvature", both);
    add("combo: the same, trained start", [&](Options& o) { both(o), o.trained_start = true; });
    add("combo: the same, trained start, rate 16", [&](Options& o) { both(o), o.trained_start = true, o.mixer_rate = 16; });
    add("combo: base size instead, trained start", [&](Options& o) {
        o.extra.push_back([](F f, X x) { return (f.group * 64u + f.mean_curv) * 16 + x.base_size / 4u; });
        o.extra.push_back([](F f, X x) { return (f.group * 64u + x.gauss) * 16 + f.mean_curv / 4u; });
        o.trained_start = true;
    });
    auto sized = [](Options& o) {
        o.extra.push_back([](F f, X x) { return (f.group * 64u + x.base_size) * 8 + f.level; });
        o.extra.push_back([](F f, X x) { return (f.group * 64u + f.mean_curv) * 16 + x.base_size / 4u; });
    };
    add("S: base size x level, curvature x base size", sized);
    add("S: the same + gauss x curvature", [&](Options& o) { sized(o), o.extra.push_back([](F f, X x) { return (f.group * 64u + x.gauss) * 16 + f.mean_curv / 4u; }); });
    add("S: the same, trained start", [&](Options& o) { sized(o), o.trained_start = true; });
    extra("S: base size x level x center x inner", [](F f, X x) { return ((f.group * 64u + x.base_size) * 8 + f.level) * 8 + f.center * 4 + f.inner; });
    extra("S: base size x ring max / 4 x level", [](F f, X x) { return ((f.group * 64u + x.base_size) * 16 + f.ring_max / 4u) * 8 + f.level; });
    extra("S: base size x disp x level", [](F f, X x) { return ((f.group * 64u + x.base_size) * 24 + f.disp) * 8 + f.level; });
    extra("S: level size x level x ring2", [](F f, X x) { return ((f.group * 64u + x.size) * 8 + f.level) * 5 + f.ring2; });
    add("T: S + curvature x base size / 2 x level", [&](Options& o) { sized(o), o.extra.push_back([](F f, X x) { return ((f.group * 64u + f.mean_curv) * 32 + x.base_size / 2u) * 8 + f.level; }); });
    add("T: S + ring mean x base size / 2 x level", [&](Options& o) { sized(o), o.extra.push_back([](F f, X x) { return ((f.group * 64u + f.ring_mean) * 32 + x.base_size / 2u) * 8 + f.level; }); });
    add("T: S, mixer B by base size / 4", [&](Options& o) { sized(o), o.extra_set_b = 2; });
    add("T: S + gauss x level x base size / 4", [&](Options& o) { sized(o), o.extra.push_back([](F f, X x) { return ((f.group * 64u + x.gauss) * 16 + x.base_size / 4u) * 8 + f.level; }); });
    auto v11 = [&](Options& o) {
        sized(o);
        o.extra.push_back([](F f, X x) { return (f.group * 64u + x.gauss) * 16 + f.mean_curv / 4u; });
        o.extra.push_back([](F f, X x) { return ((f.group * 64u + f.ring_mean) * 32 + x.base_size / 2u) * 8 + f.level; });
    };
    add("U: size, gauss, ring mean x size", v11);
    add("U: the same, trained start", [&](Options& o) { v11(o), o.trained_start = true; });
    add("U: the same, trained start, rate 16", [&](Options& o) { v11(o), o.trained_start = true, o.mixer_rate = 16; });
    for (int r : {8, 12}) add("V: U, trained start, rate " + std::to_string(r), [&, r](Options& o) { v11(o), o.trained_start = true, o.mixer_rate = r; });
    add("V: U + ring max x base size / 2 x level, trained, rate 16", [&](Options& o) {
        v11(o), o.trained_start = true, o.mixer_rate = 16;
        o.extra.push_back([](F f, X x) { return ((f.group * 64u + f.ring_max) * 32 + x.base_size / 2u) * 8 + f.level; });
    });
    add("V: U + gauss x base size / 2 x level, trained, rate 16", [&](Options& o) {
        v11(o), o.trained_start = true, o.mixer_rate = 16;
        o.extra.push_back([](F f, X x) { return ((f.group * 64u + x.gauss) * 32 + x.base_size / 2u) * 8 + f.level; });
    });
    add("V: U + base size x inner x center x level, trained, rate 16", [&](Options& o) {
        v11(o), o.trained_start = true, o.mixer_rate = 16;
        o.extra.push_back([](F f, X x) { return ((f.group * 64u + x.base_size) * 8 + f.level) * 8 + f.center * 4 + f.inner; });
    });
    add("V: U, trained, rate 16, window 2^9", [&](Options& o) { v11(o), o.trained_start = true, o.mixer_rate = 16, o.window_log2 = 9; });
    for (int d = 1; d <= 3; ++d)
        add("W: U, trained, rate 16, mixer D " + std::to_string(d), [&, d](Options& o) { v11(o), o.trained_start = true, o.mixer_rate = 16, o.mixer_d = d; });
    add("X: D1, rate 12", [&](Options& o) { v11(o), o.trained_start = true, o.mixer_rate = 12, o.mixer_d = 1; });
    add("X: D4, rate 16", [&](Options& o) { v11(o), o.trained_start = true, o.mixer_rate = 16, o.mixer_d = 4; });
    add("X: D5, rate 16", [&](Options& o) { v11(o), o.trained_start = true, o.mixer_rate = 16, o.mixer_d = 5; });
    add("X: D1, rate 16, + gauss x base size / 2 x level", [&](Options& o) {
        v11(o), o.trained_start = true, o.mixer_rate = 16, o.mixer_d = 1;
        o.extra.push_back([](F f, X x) { return ((f.group * 64u + x.gauss) * 32 + x.base_size / 2u) * 8 + f.level; });
    });
    add("X: D1, rate 16, map share 2", [&](Options& o) { v11(o), o.trained_start = true, o.mixer_rate = 16, o.mixer_d = 1, o.map_share = 2; });
    add("Y: third model (v11)", [&](Options& o) { v11(o), o.trained_start = true, o.mixer_rate = 16, o.mixer_d = 5; });
    // The third model on the coder's own size and gauss features (FORMAT.md 2.3).
    auto coded = [](int gauss_floor) {
        return [gauss_floor](Options& o) {
            o.extra.push_back([](F f, X) { return (f.group * 64u + f.size) * 8 + f.level; });
            o.extra.push_back([](F f, X) { return (f.group * 64u + f.mean_curv) * 16 + f.size / 4u; });
            o.extra.push_back([gauss_floor](F f, X) { return (f.group * 64u + (f.gauss ? std::max<uint32_t>(f.gauss, gauss_floor) : 0u)) * 16 + f.mean_curv / 4u; });
            o.extra.push_back([](F f, X) { return ((f.group * 64u + f.ring_mean) * 32 + f.size / 2u) * 8 + f.level; });
            o.trained_start = true, o.mixer_rate = 16, o.mixer_d = 6;
        };
    };
    add("Z: third model on the coder's features", coded(0));
    add("Z: the same, table 24 without the group", [&](Options& o) {
        coded(0)(o);
        o.extra[3] = [](F f, X) { return (f.ring_mean * 32u + f.size / 2u) * 8 + f.level; };
    });
    add("Z: the same, table 24 by group / 4 (16-bit mask in the study)", [&](Options& o) {
        coded(0)(o);
        o.extra[3] = [](F f, X) { return (((f.group & 3u) * 64 + f.ring_mean) * 32u + f.size / 2u) * 8 + f.level; };
    });
    add("Z: the same, table 24 by center instead of the group", [&](Options& o) {
        coded(0)(o);
        o.extra[3] = [](F f, X) { return ((f.center * 64u + f.ring_mean) * 32u + f.size / 2u) * 8 + f.level; };
    });
    auto no_group = [&](Options& o) {
        coded(0)(o);
        o.extra[3] = [](F f, X) { return (f.ring_mean * 32u + f.size / 2u) * 8 + f.level; };
    };
    add("Z2: 24 and 21 without the group", [&](Options& o) { no_group(o), o.extra[0] = [](F f, X) { return f.size * 8u + f.level; }; });
    add("Z2: 24 and 22 without the group", [&](Options& o) { no_group(o), o.extra[1] = [](F f, X) { return f.mean_curv * 16u + f.size / 4u; }; });
    add("Z2: 24 and 23 without the group", [&](Options& o) { no_group(o), o.extra[2] = [](F f, X) { return f.gauss * 16u + f.mean_curv / 4u; }; });
    add("Z2: 24 without the group, mixer D by size x level", [&](Options& o) { no_group(o), o.mixer_d = 1; });
    add("Z3: 22, 23 and 24 without the group", [&](Options& o) {
        no_group(o);
        o.extra[1] = [](F f, X) { return f.mean_curv * 16u + f.size / 4u; };
        o.extra[2] = [](F f, X) { return f.gauss * 16u + f.mean_curv / 4u; };
    });
    add("Z: the same, Gauss bins from 11", coded(11));
    add("Z: the same, Gauss bins from 21", coded(21));
    add("Z: the same, rate 12", [&](Options& o) { coded(0)(o), o.mixer_rate = 12; });
    add("mixer B by parent's curvature", [](Options& o) { o.extra_set_b = 1; });
    auto third = [&](Options& o) {
        no_group(o);
        o.extra[1] = [](F f, X) { return f.mean_curv * 16u + f.size / 4u; };
        o.extra[2] = [](F f, X) { return f.gauss * 16u + f.mean_curv / 4u; };
    };
    add("N: third + neighbours' midpoint displacement x level", [&](Options& o) {
        third(o), o.extra.push_back([](F f, X x) { return (f.group * 64u + x.nb_disp) * 8 + f.level; });
    });
    add("N: third + nb displacement x size / 2 x level", [&](Options& o) {
        third(o), o.extra.push_back([](F f, X x) { return (x.nb_disp * 32u + f.size / 2u) * 8 + f.level; });
    });
    add("N: third + nb displacement x known x size / 4 x level, + nb displacement x curvature / 4", [&](Options& o) {
        third(o);
        o.extra.push_back([](F f, X x) { return ((x.nb_disp * 4u + x.nb_known) * 16 + f.size / 4u) * 8 + f.level; });
        o.extra.push_back([](F f, X x) { return (f.group * 64u + x.nb_disp) * 16 + f.mean_curv / 4u; });
    });
    add("P: third model (start weights: leave one model out)", third);
    add("Q: third model, symbols coded twice, second pass (its learning cost's bound)", [&](Options& o) { third(o), o.prime = true; });
    for (int c : {2, 4, 8, 16, 32, 64})
        add("P: third + trained initial states, count " + std::to_string(c), [&, c](Options& o) { third(o), o.prior_count = c; });
    for (int c : {2, 4, 8})
        add("P: third + trained initial states of geometric tables only, count " + std::to_string(c), [&, c](Options& o) {
            third(o), o.prior_count = c, o.prior_geometric_only = true;
        });
    for (int c : {8, 32})
        add("P: third + trained initial states of direct models only, count " + std::to_string(c), [&, c](Options& o) {
            third(o), o.prior_count = c, o.prior_maps = false;
        });
    add("R: third + the law's posterior x group", [&](Options& o) {
        third(o);
        o.extra.push_back([](F f, X x) { return f.group * 33u + x.law; });
    });
    add("R: third + the law's posterior x group, + x level", [&](Options& o) {
        third(o);
        o.extra.push_back([](F f, X x) { return f.group * 33u + x.law; });
        o.extra.push_back([](F f, X x) { return x.law * 8u + f.level; });
    });
    // Session of 2026-12-04 evening: local threshold comparisons and quadric curvatures.
    // A design: `base`'s options plus `contexts` as extra tables, named "`label` + `name`".
    auto plus = [&](const std::string& label, std::function<void(Options&)> base) {
        return [&, label, base](const std::string& name, std::vector<std::function<uint32_t(F, X)>> contexts) {
            add(label + " + " + name, [base, contexts](Options& o) {
                base(o);
                for (const auto& c : contexts) o.extra.push_back(c);
            });
        };
    };
    auto third_plus = plus("T: third", third);
    third_plus("ref x unref x group", {[](F f, X x) { return (f.group * 32u + x.thr_ref) * 32 + x.thr_unref; }});
    third_plus("ref x unref x level", {[](F f, X x) { return (f.level * 32u + x.thr_ref) * 32 + x.thr_unref; }});
    third_plus("ref x group, unref x group", {[](F f, X x) { return f.group * 32u + x.thr_ref; }, [](F f, X x) { return f.group * 32u + x.thr_unref; }});
    third_plus("ref2 x unref2 x group", {[](F f, X x) { return (f.group * 32u + x.thr_ref2) * 32 + x.thr_unref2; }});
    third_plus("pref x punref x level", {[](F f, X x) { return (f.level * 32u + x.thr_pref) * 32 + x.thr_punref; }});
    third_plus("gref x gunref x group", {[](F f, X x) { return (f.group * 32u + x.g_ref) * 32 + x.g_unref; }});
    third_plus("ref x unref x group, ref2 x unref2 x level, pref x punref x level", {
        [](F f, X x) { return (f.group * 32u + x.thr_ref) * 32 + x.thr_unref; },
        [](F f, X x) { return (f.level * 32u + x.thr_ref2) * 32 + x.thr_unref2; },
        [](F f, X x) { return (f.level * 32u + x.thr_pref) * 32 + x.thr_punref; }});
    third_plus("quad H x level", {[](F f, X x) { return (f.group * 64u + x.quad_h) * 8 + f.level; }});
    third_plus("quad K x level", {[](F f, X x) { return (f.group * 64u + x.quad_k) * 8 + f.level; }});
    third_plus("quad max x level", {[](F f, X x) { return (f.group * 64u + x.quad_max) * 8 + f.level; }});
    third_plus("quad H x size, quad K x size", {[](F f, X x) { return (x.quad_h * 32u + f.size / 2u) * 8 + f.level; },
                                              [](F f, X x) { return (x.quad_k * 32u + f.size / 2u) * 8 + f.level; }});
    third_plus("sdh x level", {[](F f, X x) { return (f.group * 64u + x.sdh) * 8 + f.level; }});
    third_plus("sdh x size", {[](F f, X x) { return (x.sdh * 32u + f.size / 2u) * 8 + f.level; }});
    third_plus("qthr ref2 x unref2 x group", {[](F f, X x) { return (f.group * 32u + x.qthr_ref2) * 32 + x.qthr_unref2; }});
    third_plus("quad H x level, quad H x size, quad K x size", {[](F f, X x) { return (f.group * 64u + x.quad_h) * 8 + f.level; },
        [](F f, X x) { return (x.quad_h * 32u + f.size / 2u) * 8 + f.level; },
        [](F f, X x) { return (x.quad_k * 32u + f.size / 2u) * 8 + f.level; }});
    third_plus("quad H x size, quad K x size, qthr ref2 x unref2 x group", {
        [](F f, X x) { return (x.quad_h * 32u + f.size / 2u) * 8 + f.level; },
        [](F f, X x) { return (x.quad_k * 32u + f.size / 2u) * 8 + f.level; },
        [](F f, X x) { return (f.group * 32u + x.qthr_ref2) * 32 + x.qthr_unref2; }});
    third_plus("quad H x size, quad K x size, ref2 x unref2 x group", {
        [](F f, X x) { return (x.quad_h * 32u + f.size / 2u) * 8 + f.level; },
        [](F f, X x) { return (x.quad_k * 32u + f.size / 2u) * 8 + f.level; },
        [](F f, X x) { return (f.group * 32u + x.thr_ref2) * 32 + x.thr_unref2; }});
    third_plus("sdh x size, quad K x size", {[](F f, X x) { return (x.sdh * 32u + f.size / 2u) * 8 + f.level; },
        [](F f, X x) { return (x.quad_k * 32u + f.size / 2u) * 8 + f.level; }});
    auto quad2 = [&](Options& o) {
        third(o);
        o.extra.push_back([](F f, X x) { return (x.quad_h * 32u + f.size / 2u) * 8 + f.level; });
        o.extra.push_back([](F f, X x) { return (x.quad_k * 32u + f.size / 2u) * 8 + f.level; });
    };
    add("F: third + flat H x size, flat K x size", [&](Options& o) {
        third(o);
        o.extra.push_back([](F f, X x) { return (x.flat_h * 32u + f.size / 2u) * 8 + f.level; });
        o.extra.push_back([](F f, X x) { return (x.flat_k * 32u + f.size / 2u) * 8 + f.level; });
    });
    add("F: third + flat H x size x level, flat K x size x level, flat H x group x level", [&](Options& o) {
        third(o);
        o.extra.push_back([](F f, X x) { return (x.flat_h * 32u + f.size / 2u) * 8 + f.level; });
        o.extra.push_back([](F f, X x) { return (x.flat_k * 32u + f.size / 2u) * 8 + f.level; });
        o.extra.push_back([](F f, X x) { return (f.group * 64u + x.flat_h) * 8 + f.level; });
    });
    add("F: third + flat H x size x level, flat K x size x level, flat H x flat K", [&](Options& o) {
        third(o);
        o.extra.push_back([](F f, X x) { return (x.flat_h * 32u + f.size / 2u) * 8 + f.level; });
        o.extra.push_back([](F f, X x) { return (x.flat_k * 32u + f.size / 2u) * 8 + f.level; });
        o.extra.push_back([](F f, X x) { return (f.group * 64u + x.flat_h) * 16 + x.flat_k / 4u; });
    });
    auto flat3 = [&](Options& o) {
        third(o);
        o.extra.push_back([](F f, X x) { return (x.flat_h * 32u + f.size / 2u) * 8 + f.level; });
        o.extra.push_back([](F f, X x) { return (x.flat_k * 32u + f.size / 2u) * 8 + f.level; });
        o.extra.push_back([](F f, X x) { return (f.group * 64u + x.flat_h) * 16 + x.flat_k / 4u; });
    };
    auto drops = [](std::initializer_list<int> list) {
        uint64_t d = 0;
        for (int j : list) d |= uint64_t{1} << j;
        return d;
    };
    add("G: flat3 without 8 10 11 12 18", [&](Options& o) { flat3(o), o.drop = drops({8, 10, 11, 12, 18}); });
    add("G: flat3 without 8 10 11 12", [&](Options& o) { flat3(o), o.drop = drops({8, 10, 11, 12}); });
    add("G: flat3 without 1 6 8 10 11 12 18", [&](Options& o) { flat3(o), o.drop = drops({1, 6, 8, 10, 11, 12, 18}); });
    add("G: flat3 without 8 11 12", [&](Options& o) { flat3(o), o.drop = drops({8, 11, 12}); });
    add("G: flat3 + ref2 x unref2, without 8 10 11 12 18", [&](Options& o) {
        flat3(o), o.drop = drops({8, 10, 11, 12, 18});
        o.extra.push_back([](F f, X x) { return (f.group * 32u + x.thr_ref2) * 32 + x.thr_unref2; });
    });
    add("K: fourth model on the coder's features", [&](Options& o) {
        third(o);
        o.extra.push_back([](F f, X) { return (f.quad_mean * 32u + f.size / 2u) * 8 + f.level; });
        o.extra.push_back([](F f, X) { return (f.quad_gauss * 32u + f.size / 2u) * 8 + f.level; });
        o.extra.push_back([](F f, X) { return (f.group * 64u + f.quad_mean) * 16 + f.quad_gauss / 4u; });
        o.drop = drops({1, 6, 8, 10, 11, 12, 18});
    });
    auto fourth = [&](Options& o) {
        third(o);
        o.extra.push_back([](F f, X) { return (f.quad_mean * 32u + f.size / 2u) * 8 + f.level; });
        o.extra.push_back([](F f, X) { return (f.quad_gauss * 32u + f.size / 2u) * 8 + f.level; });
        o.extra.push_back([](F f, X) { return (f.group * 64u + f.quad_mean) * 16 + f.quad_gauss / 4u; });
        o.drop = drops({1, 6, 8, 10, 11, 12, 18});
    };
    auto m = [&](const std::string& name, int mixers_off, int maps_off, std::initializer_list<int> more) {
        const uint64_t extra_drops = drops(more);
        add("M: fourth" + name, [&, mixers_off, maps_off, extra_drops](Options& o) {
            fourth(o), o.mixers_off = mixers_off, o.maps_off = maps_off, o.drop |= extra_drops;
        });
    };
    m(", maps 1 2 off", 0, 6, {});
    m(", maps 1 2 off, without 9", 0, 6, {9});
    m(", maps 1 2 off, without 2 9 15 25", 0, 6, {2, 9, 15, 25});
    m(", maps 1 2 off, without 5 9 15 20", 0, 6, {5, 9, 15, 20});
    m(", maps 1 2 off, without 2 5 9 15", 0, 6, {2, 5, 9, 15});
    m(", mixer A off, maps 1 2 off", 1, 6, {});
    m(", mixer A off, maps 1 2 off, without 2 9 15 25", 1, 6, {2, 9, 15, 25});
    m(", maps 0 1 2 off", 0, 7, {});
    for (int j : {9, 15, 25, 20, 2, 5, 0, 3})
        add("N: fourth, maps 0 1 2 off, without " + std::to_string(j), [&, j](Options& o) { fourth(o), o.maps_off = 7, o.drop |= uint64_t{1} << j; });
    auto pdesign = [&](std::initializer_list<int> dropped) {
        const uint64_t d = drops(dropped);
        std::string name = "P4: fourth, maps 0 1 2 off, without";
        for (int j : dropped) name += " " + std::to_string(j);
        add(name, [&, d](Options& o) { fourth(o), o.maps_off = 7, o.drop = d; });
    };
    add("Q: fourth model as coded (version 16)", [&](Options& o) { fourth(o), o.maps_off = 7, o.drop = drops({1, 6, 8, 10, 11, 12, 18, 25}); });
    pdesign({2, 8, 9, 10, 11, 12, 15, 18});
    pdesign({2, 8, 10, 11, 12, 15, 18, 25});
    pdesign({8, 9, 10, 11, 12, 15, 18, 20});
    pdesign({2, 8, 9, 10, 11, 12, 18, 20});
    pdesign({2, 6, 8, 10, 11, 12, 15, 18});
    pdesign({1, 2, 8, 10, 11, 12, 15, 18});
    pdesign({2, 6, 8, 9, 10, 11, 12, 18});
    add("N: fourth, maps 0 1 2 4 off", [&](Options& o) { fourth(o), o.maps_off = 23; });
    for (int j : {0, 2, 3, 4, 5, 7, 9, 13, 14, 15, 16, 17, 19, 20, 21, 22, 23, 24, 25, 26, 27, 28, 29, 30})
        add("L: fourth without input " + std::to_string(j), [&, j](Options& o) { fourth(o), o.drop |= uint64_t{1} << j; });
    for (int k = 0; k < 4; ++k) add("L: fourth without mixer " + std::to_string(k), [&, k](Options& o) { fourth(o), o.mixers_off = 1 << k; });
    for (int k = 0; k < 5; ++k) add("L: fourth without map " + std::to_string(k), [&, k](Options& o) { fourth(o), o.maps_off = 1 << k; });
    add("H: flat3 without 0 1 3 6 8 10 11 12 18", [&](Options& o) { flat3(o), o.drop = drops({0, 1, 3, 6, 8, 10, 11, 12, 18}); });
    add("H: flat3 without 1 6 8 10 11 12 16 18", [&](Options& o) { flat3(o), o.drop = drops({1, 6, 8, 10, 11, 12, 16, 18}); });
    add("H: flat3 without 1 2 6 8 10 11 12 18", [&](Options& o) { flat3(o), o.drop = drops({1, 2, 6, 8, 10, 11, 12, 18}); });
    add("H: flat3 without 1 6 8 10 11 12 18 22", [&](Options& o) { flat3(o), o.drop = drops({1, 6, 8, 10, 11, 12, 18, 22}); });
    add("H: flat3 without 1 6 8 10 11 12 18, mixer rate 12", [&](Options& o) { flat3(o), o.drop = drops({1, 6, 8, 10, 11, 12, 18}), o.mixer_rate = 12; });
    // Session of 2026-12-04 night (docs/HIERARCHY_CODER.md, "The fifth model"): the fourth
    // model plus local thresholds, SSE stages and a fifth mixer.
    auto fourth_coded = [&](Options& o) { fourth(o), o.maps_off = 7, o.drop = drops({1, 6, 8, 10, 11, 12, 18, 25}); };
    auto e_plus = plus("E: fourth", fourth_coded);
    e_plus("ref2 x unref2 x group", {[](F f, X x) { return (f.group * 32u + x.thr_ref2) * 32 + x.thr_unref2; }});
    e_plus("ref2 x unref2 x level", {[](F f, X x) { return (f.level * 32u + x.thr_ref2) * 32 + x.thr_unref2; }});
    e_plus("qref2 x qunref2 x group", {[](F f, X x) { return (f.group * 32u + x.qthr_ref2) * 32 + x.qthr_unref2; }});
    e_plus("kref2 x kunref2 x group", {[](F f, X x) { return (f.group * 32u + x.kthr_ref2) * 32 + x.kthr_unref2; }});
    e_plus("qref x qunref x group", {[](F f, X x) { return (f.group * 32u + x.qthr_ref) * 32 + x.qthr_unref; }});
    e_plus("ref2 x unref2 x group, kref2 x kunref2 x group", {[](F f, X x) { return (f.group * 32u + x.thr_ref2) * 32 + x.thr_unref2; },
        [](F f, X x) { return (f.group * 32u + x.kthr_ref2) * 32 + x.kthr_unref2; }});
    e_plus("qref2 x qunref2 x group, kref2 x kunref2 x group", {[](F f, X x) { return (f.group * 32u + x.qthr_ref2) * 32 + x.qthr_unref2; },
        [](F f, X x) { return (f.group * 32u + x.kthr_ref2) * 32 + x.kthr_unref2; }});
    e_plus("coded ref2 x unref2 x group x level", {[](F f, X x) { return ((f.group * 8u + x.coded_ref2) * 8 + x.coded_unref2) * 8 + f.level; }});
    auto thr_level = [](F f, X x) { return (f.level * 32u + x.thr_ref2) * 32 + x.thr_unref2; };
    auto coded_counts = [](F f, X x) { return ((f.group * 8u + x.coded_ref2) * 8 + x.coded_unref2) * 8 + f.level; };
    e_plus("C1: ref2 x unref2 x level, coded ref2 x unref2 x group x level", {thr_level, coded_counts});
    e_plus("C3: C1 + kref2 x kunref2 x group", {thr_level, coded_counts, [](F f, X x) { return (f.group * 32u + x.kthr_ref2) * 32 + x.kthr_unref2; }});
    e_plus("C6: ref2 x unref2 x coded ref2 x unref2 (no group, no level)", {[](F, X x) { return ((x.thr_ref2 * 32u + x.thr_unref2) * 8 + x.coded_ref2) * 8 + x.coded_unref2; }});
    e_plus("C7: ref2 x unref2 x level, coded ref2 x unref2 x group", {thr_level, [](F f, X x) { return (f.group * 8u + x.coded_ref2) * 8 + x.coded_unref2; }});
    e_plus("C8: ref2 x unref2 x level, coded ref2 x unref2 x group x level, ref2 x unref2 x size / 4", {thr_level, coded_counts,
        [](F f, X x) { return (f.size / 4u * 32 + x.thr_ref2) * 32 + x.thr_unref2; }});
    auto coded_group = [](F f, X x) { return (f.group * 8u + x.coded_ref2) * 8 + x.coded_unref2; };
    auto fifth_without = [&](std::initializer_list<int> dropped) {
        const uint64_t d = drops(dropped);
        std::string name = "F: fourth + C7 without";
        for (int j : dropped) name += " " + std::to_string(j);
        add(name, [&, d](Options& o) { fourth_coded(o), o.extra.push_back(thr_level), o.extra.push_back(coded_group), o.drop |= d; });
    };
    fifth_without({4, 14});
    fifth_without({13, 14});
    fifth_without({14, 16});
    fifth_without({4, 13, 14});
    fifth_without({2, 4, 14});
    fifth_without({4, 14, 15});
    add("F: fourth + C7 + coded ref2 x unref2 x group x inner, without 4 13 14", [&](Options& o) {
        fourth_coded(o), o.extra.push_back(thr_level), o.extra.push_back(coded_group), o.drop |= drops({4, 13, 14});
        o.extra.push_back([](F f, X x) { return ((f.group * 8u + x.coded_ref2) * 8 + x.coded_unref2) * 4 + f.inner; });
    });
    auto coded_inner = [](F f, X x) { return ((f.group * 8u + x.coded_ref2) * 8 + x.coded_unref2) * 4 + f.inner; };
    add("V: fifth model as coded (version 17)", [&](Options& o) {
        fourth_coded(o), o.extra.push_back(thr_level), o.extra.push_back(coded_group), o.extra.push_back(coded_inner);
        o.drop |= drops({4, 13, 14});
    });
    add("V: fifth without coded x group (22 inputs)", [&](Options& o) {
        fourth_coded(o), o.extra.push_back(thr_level), o.extra.push_back(coded_inner);
        o.drop |= drops({4, 13, 14});
    });
    auto fifth_coded = [&](Options& o) {
        fourth_coded(o);
        o.extra.push_back(thr_level), o.extra.push_back(coded_group), o.extra.push_back(coded_inner);
        o.drop |= drops({4, 13, 14});
    };
    for (auto dropped : {std::vector<int>{0, 2, 15, 16}, std::vector<int>{0, 2, 5, 16}, std::vector<int>{2, 9, 15, 16}, std::vector<int>{0, 2, 16}}) {
        uint64_t d = 0;
        std::string name = "Y: fifth without";
        for (int j : dropped) d |= uint64_t{1} << j, name += " " + std::to_string(j);
        add(name, [&, d](Options& o) { fifth_coded(o), o.drop |= d; });
    }
    for (int j : {0, 2, 3, 5, 7, 9, 15, 16, 17, 19, 20, 21, 22, 23, 24, 26, 27, 28, 29, 30, 31, 32, 33})
        add("X: fifth without input " + std::to_string(j), [&, j](Options& o) { fifth_coded(o), o.drop |= uint64_t{1} << j; });
    // The fifth model on the coder's own threshold features: with WEIGHTS_IN of the third Y
    // design's WEIGHTS_OUT (copied to this design's index) it equals the coder's.
    add("W: fifth model on the coder's features", [&](Options& o) {
        fourth_coded(o);
        o.extra.push_back([](F f, X) { return (f.level * 32u + f.thr_refined) * 32 + f.thr_unrefined; });
        o.extra.push_back([](F f, X) { return (f.group * 8u + f.coded_refined) * 8 + f.coded_unrefined; });
        o.extra.push_back([](F f, X) { return ((f.group * 8u + f.coded_refined) * 8 + f.coded_unrefined) * 4 + f.inner; });
        o.drop |= drops({2, 4, 9, 13, 14, 15, 16});
    });
    add("E: fourth + C5: C1 + mixer E by ref2 / 4 x unref2 / 4", [&](Options& o) {
        fourth_coded(o), o.extra.push_back(thr_level), o.extra.push_back(coded_counts);
        o.mixer_e = [](F, X x) { return x.thr_ref2 / 4u * 8 + x.thr_unref2 / 4u; }, o.mixer_e_sets = 64;
    });
    for (int j : {0, 2, 3, 4, 5, 7, 9, 13, 14, 15, 16, 17, 19, 20})
        add("E: fourth + C1 without input " + std::to_string(j), [&, j](Options& o) {
            fourth_coded(o), o.extra.push_back(thr_level), o.extra.push_back(coded_counts), o.drop |= uint64_t{1} << j;
        });
    auto e_map = [&](const std::string& name, std::function<uint32_t(F, X)> row, int rows) {
        add("E: fourth + SSE by " + name, [&, row, rows](Options& o) { fourth_coded(o), o.extra_maps.push_back({row, rows}); });
    };
    e_map("quad H x size / 2", [](F f, X) { return f.quad_mean * 32u + f.size / 2u; }, 2048);
    e_map("group x quad K", [](F f, X) { return f.group * 64u + f.quad_gauss; }, 640);
    e_map("ref2 x unref2", [](F, X x) { return x.thr_ref2 * 32u + x.thr_unref2; }, 1024);
    e_map("level x size", [](F f, X) { return f.level * 64u + f.size; }, 512);
    auto e_mix = [&](const std::string& name, std::function<uint32_t(F, X)> set, int sets) {
        add("E: fourth + mixer E by " + name, [&, set, sets](Options& o) { fourth_coded(o), o.mixer_e = set, o.mixer_e_sets = sets; });
    };
    e_mix("ref2 / 4 x unref2 / 4", [](F, X x) { return x.thr_ref2 / 4u * 8 + x.thr_unref2 / 4u; }, 64);
    e_mix("quad H / 4 x level", [](F f, X) { return f.quad_mean / 4u * 8 + f.level; }, 128);
    e_mix("group x quad K / 4", [](F f, X) { return f.group * 16u + f.quad_gauss / 4u; }, 160);
    // Session of 2026-12-05 (docs/HIERARCHY_CODER.md, "Beyond the fifth model"): the fifth model
    // as coded plus a wider quadric, the refinement two levels up, final SSE stages, mixer A by
    // level band, young mixers' faster rates.
    auto fifth_y = [&](Options& o) { fifth_coded(o), o.drop |= drops({2, 9, 15, 16}); };
    add("S: fifth model as coded (leave one out)", fifth_y);
    auto s_plus = plus("S: fifth", fifth_y);
    s_plus("star H x size / 2 x level", {[](F f, X x) { return (x.star_h * 32u + f.size / 2u) * 8 + f.level; }});
    s_plus("star K x size / 2 x level", {[](F f, X x) { return (x.star_k * 32u + f.size / 2u) * 8 + f.level; }});
    s_plus("star H x size / 2 x level, star K x size / 2 x level", {[](F f, X x) { return (x.star_h * 32u + f.size / 2u) * 8 + f.level; },
        [](F f, X x) { return (x.star_k * 32u + f.size / 2u) * 8 + f.level; }});
    auto hk = [](auto hf, auto kf) {
        return std::vector<std::function<uint32_t(F, X)>>{[hf](F f, X x) { return (uint32_t(hf(x)) * 32u + f.size / 2u) * 8 + f.level; },
                                                          [kf](F f, X x) { return (uint32_t(kf(x)) * 32u + f.size / 2u) * 8 + f.level; }};
    };
    s_plus("star3 H, K x size / 2 x level", hk([](X x) { return x.star3_h; }, [](X x) { return x.star3_k; }));
    s_plus("cstar H, K x size / 2 x level", hk([](X x) { return x.cstar_h; }, [](X x) { return x.cstar_k; }));
    s_plus("cstar3 H, K x size / 2 x level", hk([](X x) { return x.cstar3_h; }, [](X x) { return x.cstar3_k; }));
    auto s_replace = [&](const std::string& name, std::vector<std::function<uint32_t(F, X)>> contexts, std::initializer_list<int> dropped) {
        const uint64_t d = drops(dropped);
        std::string label = "S: fifth without";
        for (int j : dropped) label += " " + std::to_string(j);
        add(label + " + " + name, [&, contexts, d](Options& o) {
            fifth_y(o), o.drop |= d;
            for (const auto& c : contexts) o.extra.push_back(c);
        });
    };
    s_replace("star H, K x size / 2 x level", hk([](X x) { return x.star_h; }, [](X x) { return x.star_k; }), {28, 29});
    s_replace("star H, K x size / 2 x level", hk([](X x) { return x.star_h; }, [](X x) { return x.star_k; }), {28, 29, 30});
    s_replace("cstar H, K x size / 2 x level", hk([](X x) { return x.cstar_h; }, [](X x) { return x.cstar_k; }), {28, 29, 30});
    s_replace("cstar3 H, K x size / 2 x level", hk([](X x) { return x.cstar3_h; }, [](X x) { return x.cstar3_k; }), {28, 29, 30});
    s_plus("star H, K x size / 2 x level, sthr ref2 x unref2 x level", {[](F f, X x) { return (x.star_h * 32u + f.size / 2u) * 8 + f.level; },
        [](F f, X x) { return (x.star_k * 32u + f.size / 2u) * 8 + f.level; },
        [](F f, X x) { return (f.level * 32u + x.sthr_ref2) * 32 + x.sthr_unref2; }});
    s_plus("star H, K x size / 2 x level, star H x group x star K / 4", {[](F f, X x) { return (x.star_h * 32u + f.size / 2u) * 8 + f.level; },
        [](F f, X x) { return (x.star_k * 32u + f.size / 2u) * 8 + f.level; },
        [](F f, X x) { return (f.group * 64u + x.star_h) * 16 + x.star_k / 4u; }});
    auto star_h_size = [](F f, X x) { return (x.star_h * 32u + f.size / 2u) * 8 + f.level; };
    auto star_k_size = [](F f, X x) { return (x.star_k * 32u + f.size / 2u) * 8 + f.level; };
    auto star_hk_group = [](F f, X x) { return (f.group * 64u + x.star_h) * 16 + x.star_k / 4u; };
    auto sthr_level = [](F f, X x) { return (f.level * 32u + x.sthr_ref2) * 32 + x.sthr_unref2; };
    s_replace("star H, K x size / 2 x level, star H x group x star K / 4", {star_h_size, star_k_size, star_hk_group}, {28, 29, 30});
    s_replace("star H, K x size / 2 x level, star H x group x star K / 4", {star_h_size, star_k_size, star_hk_group}, {28, 29});
    s_replace("star H, K x size / 2 x level, sthr ref2 x unref2 x level", {star_h_size, star_k_size, sthr_level}, {31});
    s_plus("B2: star H, K x size / 2 x level, sthr, star H x group x star K / 4", {star_h_size, star_k_size, sthr_level, star_hk_group});
    auto sixth_design = [&](Options& o) {
        fifth_y(o);
        o.extra.push_back(star_h_size), o.extra.push_back(star_k_size);
        o.extra.push_back(sthr_level), o.extra.push_back(star_hk_group);
    };
    s_plus("qr1 H, K x size / 2 x level", hk([](X x) { return x.qr1_h; }, [](X x) { return x.qr1_k; }));
    s_plus("qr2 H, K x size / 2 x level", hk([](X x) { return x.qr2_h; }, [](X x) { return x.qr2_k; }));
    s_plus("cq1 H, K x size / 2 x level", hk([](X x) { return x.cq1_h; }, [](X x) { return x.cq1_k; }));
    s_plus("cq2 H, K x size / 2 x level", hk([](X x) { return x.cq2_h; }, [](X x) { return x.cq2_k; }));
    add("G6: B2 without the bending's tables 19 20 26 27 31, mixer B by star H / 4", [&](Options& o) {
        sixth_design(o), o.drop |= drops({19, 20, 26, 27, 31}), o.extra_set_b = 3;
    });
    add("G6: B2 without the bending's tables 19 20 26 27 31 and the quadric's 28 29 30, mixer B by star H / 4", [&](Options& o) {
        sixth_design(o), o.drop |= drops({19, 20, 26, 27, 31, 28, 29, 30}), o.extra_set_b = 3;
    });
    add("G6: B2 without the quadric's 28 29 30", [&](Options& o) { sixth_design(o), o.drop |= drops({28, 29, 30}); });
    add("G6: B2, mixer B by star H / 4", [&](Options& o) { sixth_design(o), o.extra_set_b = 3; });
    auto cq1_h_size = [](F f, X x) { return (x.cq1_h * 32u + f.size / 2u) * 8 + f.level; };
    auto cq1_k_size = [](F f, X x) { return (x.cq1_k * 32u + f.size / 2u) * 8 + f.level; };
    auto cq1_hk_group = [](F f, X x) { return (f.group * 64u + x.cq1_h) * 16 + x.cq1_k / 4u; };
    auto cthr_level = [](F f, X x) { return (f.level * 32u + x.cthr_ref2) * 32 + x.cthr_unref2; };
    auto c6 = [&](Options& o, int variant) {
        fifth_y(o);
        o.extra.push_back(cq1_h_size), o.extra.push_back(cq1_k_size);
        if (variant >= 1) o.extra.push_back(cq1_hk_group);
        if (variant >= 2) o.extra.push_back(cthr_level);
    };
    add("C6a: fifth + cq1 H, K x size / 2 x level", [&](Options& o) { c6(o, 0); });
    add("C6b: fifth + cq1 H, K x size / 2 x level, cq1 H x group x K / 4", [&](Options& o) { c6(o, 1); });
    add("C6c: C6b + cthr ref2 x unref2 x level", [&](Options& o) { c6(o, 2); });
    add("C6d: C6c without the ring's 19 20 27, mixer B by cq1 H / 4", [&](Options& o) { c6(o, 2), o.drop |= drops({19, 20, 27}), o.extra_set_b = 4; });
    add("C6e: C6c, mixer B by cq1 H / 4", [&](Options& o) { c6(o, 2), o.extra_set_b = 4; });
    add("C6f: C6c without 19 20 27 (mixer B by ring mean)", [&](Options& o) { c6(o, 2), o.drop |= drops({19, 20, 27}); });
    add("C6g: C6d without 0 3 5", [&](Options& o) { c6(o, 2), o.drop |= drops({19, 20, 27, 0, 3, 5}), o.extra_set_b = 4; });
    for (auto dropped : {std::vector<int>{0}, std::vector<int>{3}, std::vector<int>{5}, std::vector<int>{0, 5}, std::vector<int>{0, 3}, std::vector<int>{7}, std::vector<int>{17}, std::vector<int>{24}}) {
        uint64_t d = drops({19, 20, 27});
        std::string name = "C6h: C6d without";
        for (int j : dropped) d |= uint64_t{1} << j, name += " " + std::to_string(j);
        add(name, [&, d](Options& o) { c6(o, 2), o.drop |= d, o.extra_set_b = 4; });
    }
    // Session of 2026-12-05 morning: the sixth model (C6h) plus the model's own errors as contexts.
    auto sixth_coded = [&](Options& o) { c6(o, 2), o.drop |= drops({19, 20, 27, 0, 5}), o.extra_set_b = 4; };
    add("R7: sixth model (C6h)", sixth_coded);
    auto r7_plus = plus("R7: sixth", sixth_coded);
    auto parent_p = [](F f, X x) { return (x.dyn_parent * 8u + f.level) * 2 + f.center; };
    auto resid_count = [](F f, X x) { return (x.dyn_resid * 8u + x.dyn_count) * 8 + f.level; };
    auto z_count = [](F f, X x) { return (x.dyn_z * 8u + x.dyn_count) * 8 + f.level; };
    r7_plus("parent p x level x center", {parent_p});
    r7_plus("resid x count x level", {resid_count});
    r7_plus("z x count x level", {z_count});
    r7_plus("resid x group x resid1", {[](F f, X x) { return (f.group * 16u + x.dyn_resid) * 16 + x.dyn_resid1; }});
    r7_plus("parent p x level x center, z x count x level", {parent_p, z_count});
    add("R7: sixth, learning-cost bound (symbols coded twice, second pass counted)", [&](Options& o) { sixth_coded(o), o.prime = true; });
    for (int c : {2, 4, 8}) add("R7: sixth, fresh slots start at count " + std::to_string(c), [&, c](Options& o) { sixth_coded(o), o.flat_count = c; });
    for (int k : {1, 2, 4}) add("R7: sixth, inputs by confidence n / (n + " + std::to_string(k) + ")", [&, k](Options& o) { sixth_coded(o), o.confidence = k; });
    for (int c : {2, 4}) add("R7: sixth + trained initial states, count " + std::to_string(c), [&, c](Options& o) { sixth_coded(o), o.prior_count = c; });
    add("R7: sixth + trained initial states of the geometric tables, count 4", [&](Options& o) { sixth_coded(o), o.prior_count = 4, o.prior_geometric_only = true; });
    // The sixth's last four extra tables: 0 cq1 H x size x level, 1 cq1 K x size x level, 2 cq1 H x
    // group x K, 3 the threshold on it (as FORMAT.md 2.6's tables 31-34).
    for (auto hist : {std::vector<int>{0}, std::vector<int>{0, 1}, std::vector<int>{0, 1, 2, 3}, std::vector<int>{-6, -5, 0, 1}}) {
        std::string name = "R7: sixth + bit histories of the ring-quadric tables";
        for (int k : hist) name += " " + std::to_string(31 + k);
        add(name, [&, hist](Options& o) {
            sixth_coded(o);
            for (int k : hist) o.extra_history.push_back(int(o.extra.size()) - 4 + k);
        });
    }
    add("R7: sixth + trained initial states of the ring-quadric tables 31-34, count 4", [&](Options& o) { sixth_coded(o), o.prior_count = 4, o.prior_last_extras = 4; });
    add("R7: sixth + trained initial states of the geometric tables, count 4, + parent p x level x center, z x count x level", [&](Options& o) {
        sixth_coded(o), o.extra.push_back(parent_p), o.extra.push_back(z_count);
        o.prior_count = 4, o.prior_geometric_only = true;
    });
    add("R7: sixth + trained initial states of the geometric tables, count 2", [&](Options& o) { sixth_coded(o), o.prior_count = 2, o.prior_geometric_only = true; });
    for (int c : {1, 2, 4}) add("R7: sixth, fresh slots start at the coded probability, count " + std::to_string(c), [&, c](Options& o) { sixth_coded(o), o.fresh_from_final = c; });
    add("R7: sixth, tables 31 32 coarser (ring quadric / 2 x size / 4 x level)", [&](Options& o) {
        sixth_coded(o);
        const size_t k = o.extra.size() - 4;
        o.extra[k] = [](F f, X x) { return (x.cq1_h / 2u * 16u + f.size / 4u) * 8 + f.level; };
        o.extra[k + 1] = [](F f, X x) { return (x.cq1_k / 2u * 16u + f.size / 4u) * 8 + f.level; };
    });
    add("R7: sixth + tables 31 32 coarser beside them", [&](Options& o) {
        sixth_coded(o);
        o.extra.push_back([](F f, X x) { return (x.cq1_h / 2u * 16u + f.size / 4u) * 8 + f.level; });
        o.extra.push_back([](F f, X x) { return (x.cq1_k / 2u * 16u + f.size / 4u) * 8 + f.level; });
    });
    add("R7: sixth + trained initial states of tables 31 32 only, count 4", [&](Options& o) { sixth_coded(o), o.prior_count = 4, o.prior_last_extras = 4, o.prior_skip_last = 2; });
    for (int step : {64, 128, 256})
        add("R7: sixth + trained initial states of the geometric tables, count 4, rounded to " + std::to_string(step) + "/256 of a logit", [&, step](Options& o) {
            sixth_coded(o), o.prior_count = 4, o.prior_geometric_only = true, o.prior_step = step;
        });
    // Session of 2026-12-05, the seventh model's form: every reached slot at count 4, half logits.
    add("R7: sixth + trained initial states of the geometric tables, count 4 for every reached slot, rounded to 128/256 of a logit", [&](Options& o) {
        sixth_coded(o), o.prior_count = 4, o.prior_geometric_only = true, o.prior_step = 128, o.prior_count_fixed = true;
    });
    add("R7: sixth + mixer E by z x count", [&](Options& o) {
        sixth_coded(o), o.mixer_e = [](F, X x) { return x.dyn_z * 8u + x.dyn_count; }, o.mixer_e_sets = 128;
    });
    add("R7: sixth + final SSE (share 1/4) by z x count", [&](Options& o) {
        sixth_coded(o), o.final_map = [](F, X x) { return x.dyn_z * 8u + x.dyn_count; }, o.final_rows = 128, o.final_share = 1;
    });
    add("K6: sixth (B2)", sixth_design);
    add("K6: sixth (B2) without 0 3 5", [&](Options& o) { sixth_design(o), o.drop |= drops({0, 3, 5}); });
    add("K6: sixth (B2) without 0 3 5 20", [&](Options& o) { sixth_design(o), o.drop |= drops({0, 3, 5, 20}); });
    for (int j : {0, 3, 5, 7, 17, 19, 20, 21, 22, 23, 24, 26, 27, 28, 29, 30, 31, 32, 33})
        s_replace("star H, K x size / 2 x level, sthr ref2 x unref2 x level (ablation)", {star_h_size, star_k_size, sthr_level}, {j});
    s_plus("star H x group x star K / 4", {[](F f, X x) { return (f.group * 64u + x.star_h) * 16 + x.star_k / 4u; }});
    s_plus("star H x quad H / 4 x level", {[](F f, X x) { return (x.star_h * 16u + f.quad_mean / 4u) * 8 + f.level; }});
    s_plus("sthr ref2 x unref2 x level", {[](F f, X x) { return (f.level * 32u + x.sthr_ref2) * 32 + x.sthr_unref2; }});
    s_plus("grandparent nbrs x parent ring x group", {[](F f, X x) { return (f.group * 5u + x.gp_nbrs) * 10 + x.p_ring; }});
    s_plus("parent ring x grandparent ring x level", {[](F f, X x) { return (x.p_ring * 10u + x.g_ring) * 8 + f.level; }});
    s_plus("parent ring x group x inner", {[](F f, X x) { return (f.group * 10u + x.p_ring) * 4 + f.inner; }});
    auto s_final = [&](const std::string& name, std::function<uint32_t(F, X)> row, int rows, int share) {
        add("S: fifth + final SSE (share " + std::to_string(share) + "/4) by " + name, [&, row, rows, share](Options& o) {
            fifth_y(o), o.final_map = row, o.final_rows = rows, o.final_share = share;
        });
    };
    s_final("group x quad H", [](F f, X) { return f.group * 64u + f.quad_mean; }, 640, 2);
    s_final("group x quad H", [](F f, X) { return f.group * 64u + f.quad_mean; }, 640, 1);
    s_final("level x thr ref x thr unref / 4", [](F f, X) { return (f.level * 32u + f.thr_refined) * 8 + f.thr_unrefined / 4u; }, 2048, 1);
    s_final("size x level", [](F f, X) { return f.size * 8u + f.level; }, 512, 1);
    s_final("group x coded counts", [](F f, X) { return (f.group * 8u + f.coded_refined) * 8 + f.coded_unrefined; }, 640, 1);
    for (int band : {1, 2}) add("S: fifth, mixer A by group x level band " + std::to_string(band), [&, band](Options& o) { fifth_y(o), o.a_band = band; });
    for (int b : {8, 24}) add("S: fifth, mixer boost " + std::to_string(b), [&, b](Options& o) { fifth_y(o), o.boost = b; });
    for (int r : {12, 20}) add("S: fifth, mixer rate " + std::to_string(r), [&, r](Options& o) { fifth_y(o), o.mixer_rate = r; });
    for (int j = 0; j < 28; ++j) add("D: quad2 without input " + std::to_string(j), [&, j](Options& o) { quad2(o), o.drop = uint64_t{1} << j; });
    // Session of 2026-12-05 midday (designs "A21:"): candidates for the seventh model's successor,
    // on the seventh model's form (sixth + trained states of the geometric tables, count 4, half
    // logits): its own errors as contexts, rates a header could choose per file, SSE, a fifth mixer.
    auto seventh = [&](Options& o) { sixth_coded(o), o.prior_count = 4, o.prior_geometric_only = true, o.prior_step = 128, o.prior_count_fixed = true; };
    add("A21: seventh model", seventh);
    add("A21: seventh + parent p x level x center, z x count x level", [&](Options& o) { seventh(o), o.extra.push_back(parent_p), o.extra.push_back(z_count); });
    add("A21: seventh + z x count x level", [&](Options& o) { seventh(o), o.extra.push_back(z_count); });
    add("A21: seventh + resid x count x level", [&](Options& o) { seventh(o), o.extra.push_back(resid_count); });
    for (int r : {12, 20, 24}) add("A21: seventh, mixer rate " + std::to_string(r), [&, r](Options& o) { seventh(o), o.mixer_rate = r; });
    for (int w : {7, 9}) add("A21: seventh, direct window 2^" + std::to_string(w), [&, w](Options& o) { seventh(o), o.window_log2 = w, o.extra_window_log2 = w; });
    for (int c : {2, 8}) add("A21: seventh, trained count " + std::to_string(c), [&, c](Options& o) { seventh(o), o.prior_count = c; });
    for (int share : {1, 2})
        add("A21: seventh + final SSE (share " + std::to_string(share) + "/4) by group x level", [&, share](Options& o) {
            seventh(o), o.final_map = [](F f, X) { return f.group * 8u + f.level; }, o.final_rows = 80, o.final_share = share;
        });
    add("A21: seventh + final SSE (share 1/4) by parent nbrs x inner x level", [&](Options& o) {
        seventh(o), o.final_map = [](F f, X) { return (f.parent_nbrs * 4u + f.inner) * 8 + f.level; }, o.final_rows = 128, o.final_share = 1;
    });
    add("A21: seventh, every mixer weight set starts at its own trained weights", [&](Options& o) { seventh(o), o.per_set_start = true; });
    add("A21: seventh + mixer E by level x center x inner", [&](Options& o) {
        seventh(o), o.mixer_e = [](F f, X) { return (f.level * 2u + f.center) * 4 + f.inner; }, o.mixer_e_sets = 64;
    });
    const char* only = std::getenv("ONLY");

    const double paper_total = mixed_study::print_design_table_head(data);
    auto row = [&](const std::string& name, const std::vector<double>& bits) {
        double total = 0, mean = 0;
        std::printf("| %s |", name.c_str());
        for (size_t m = 0; m < data.size(); ++m) total += bits[m], mean += (bits[m] - data[m].paper_bits) / data[m].paper_bits;
        std::printf(" %+.2f%% | %+.2f%% |", 100.0 * (total - paper_total) / paper_total, 100.0 * mean / double(data.size()));
        for (size_t m = 0; m < data.size(); ++m) std::printf(" %+.2f%% |", 100.0 * (bits[m] - data[m].paper_bits) / data[m].paper_bits);
        std::printf("\n");
        std::fflush(stdout);
    };
    std::vector<double> library;
    for (const ModelData& d : data) library.push_back(d.library_bits);
    row("the coder's mixing mode (as encoders write it when the cache was made: since 2026-12-05 the seventh model, version 20)", library);
    for (const Design& design : designs) {
        if (only && &design != &designs[0]) {  // ONLY=a|b|c: any of them
            bool wanted = false;
            for (size_t from = 0, bar = 0; bar != std::string::npos; from = bar + 1) {
                bar = std::string(only).find('|', from);
                wanted |= design.name.find(std::string(only).substr(from, bar - from)) != std::string::npos;
            }
            if (!wanted) continue;
        }
        std::vector<double> bits;
        std::vector<std::array<std::vector<double>, 4>> ended;
        std::vector<std::array<std::pair<std::vector<int32_t>, std::vector<uint32_t>>, 4>> ended_sets;
        if (design.o.trained_start)
            for (size_t m = 0; m < data.size(); ++m) {
                Options plain = design.o;
                plain.trained_start = false, plain.per_set_start = false;
                Study study(plain);
                study.code(data[m].symbols, extras[m], &links[m]);
                ended.push_back(study.mean_weights());
                if (design.o.per_set_start) {
                    ended_sets.emplace_back();
                    for (int k = 0; k < 4; ++k) ended_sets.back()[size_t(k)] = {study.mixer(k).all_weights(), study.mixer(k).uses()};
                }
            }
        const char* weights_in = std::getenv("WEIGHTS_IN");
        const char* weights_out = std::getenv("WEIGHTS_OUT");
        const std::string weights_file = "-" + std::to_string(&design - &designs[0]) + ".w";
        std::array<std::vector<int32_t>, 4> given;
        const size_t mixers = design.o.mixer_d ? 4 : 3;
        if (design.o.trained_start && weights_in) {
            std::ifstream in(std::string(weights_in) + weights_file);
            for (size_t k = 0; k < mixers; ++k) {
                std::vector<int32_t>& w = given[k];
                w.resize(size_t(MixedHierarchyModel::kSecondInputs + 1 + design.o.extra.size()));
                for (int32_t& x : w) in >> x;
            }
        }
        if (design.o.trained_start && weights_out) {
            std::ofstream out(std::string(weights_out) + weights_file);
            for (size_t k = 0; k < mixers; ++k) {
                for (size_t i = 0; i < ended[0][k].size(); ++i) {
                    double sum = 0;
                    for (const auto& e : ended) sum += e[k][i] / double(ended.size());
                    out << std::lround(sum) << (i + 1 < ended[0][k].size() ? ' ' : '\n');
                }
            }
        }
        // Trained initial states: TRAIN=stem,stem,... names the training models (each model is
        // coded with the others' counts if it is one of them); without TRAIN, each model is coded
        // with the counts of the models of other meshes (leave one mesh out).
        std::vector<Counts> counted;
        if (design.o.prior_count > 0)
            for (size_t m = 0; m < data.size(); ++m) {
                Options plain = design.o;
                plain.prior_count = 0;
                Study study(plain);
                study.code(data[m].symbols, extras[m], &links[m]);
                counted.push_back(study.counts_);
            }
        auto mesh_of = [](const std::string& name) { return name.substr(0, name.rfind('_')); };
        auto trains = [&](size_t m, size_t other) {
            if (other == m) return false;
            const char* train = std::getenv("TRAIN");
            if (!train) return mesh_of(data[other].name) != mesh_of(data[m].name);
            const std::string list = std::string(",") + train + ",";
            return list.find("," + data[other].name + ",") != std::string::npos;
        };
        for (size_t m = 0; m < data.size(); ++m) {
            Options o = design.o;
            if (o.trained_start && weights_in) o.start = given;
            else if (o.trained_start && data.size() > 1)
                for (size_t k = 0; k < mixers; ++k) {
                    std::vector<double> sum(ended[0][size_t(k)].size(), 0);
                    for (size_t other = 0; other < data.size(); ++other)
                        if (other != m)
                            for (size_t i = 0; i < sum.size(); ++i) sum[i] += ended[other][size_t(k)][i] / double(data.size() - 1);
                    o.start[size_t(k)].assign(sum.begin(), sum.end());
                }
            // A single model leaves no other to start from: its mixers start at 1/n each (the
            // mean over no model gave all-zero weights, every input ignored at first).
            else if (o.trained_start && m == 0)
                std::fprintf(stderr, "%s: one model: the mixers start at 1/n (no other model to take start weights from)\n", design.name.c_str());
            if (o.per_set_start && !o.start[0].empty())
                for (size_t k = 0; k < 4; ++k) {
                    const size_t n = size_t(MixedHierarchyModel::kSecondInputs + 1 + o.extra.size());
                    const size_t sets = ended_sets[0][k].second.size();
                    const std::vector<int32_t>& row = o.start[k < 3 || !o.start[3].empty() ? k : 1];
                    std::vector<int32_t>& out = o.set_start[k];
                    out.assign(sets * n, 0);
                    for (size_t set = 0; set < sets; ++set) {
                        std::vector<double> sum(n, 0);
                        double uses = 0;
                        for (size_t other = 0; other < data.size(); ++other) {
                            if (other == m || mesh_of(data[other].name) == mesh_of(data[m].name)) continue;
                            const double u = ended_sets[other][k].second[set];
                            uses += u;
                            for (size_t i = 0; i < n; ++i) sum[i] += u * ended_sets[other][k].first[set * n + i];
                        }
                        for (size_t i = 0; i < n; ++i) out[set * n + i] = uses > 0 ? int32_t(std::lround(sum[i] / uses)) : row[i];
                    }
                }
            Counts prior;
            if (o.prior_count > 0) {
                for (size_t other = 0; other < data.size(); ++other)
                    if (trains(m, other)) prior.add(counted[other]);
                if (prior.tables.empty()) o.prior_count = 0;
                o.priors = &prior;
            }
            Study study(o);
            bits.push_back(study.code(data[m].symbols, extras[m], &links[m]));
            if (std::getenv("PRIOR_SLOTS") && o.prior_count > 0)
                std::fprintf(stderr, "%s: %s: %zu slots with trained initial states, %zu reached by the training\n", design.name.c_str(),
                             data[m].name.c_str(), study.prior_slots_[0], study.prior_slots_[1]);
            if (std::getenv("PER_LEVEL") && (&design == &designs[0] || design.name == std::getenv("PER_LEVEL"))) {
                std::fprintf(stderr, "%s:", data[m].name.c_str());
                for (int l = 0; l < 8; ++l)
                    std::fprintf(stderr, " L%d %.0f sym %.0f%% ones %.0f bits", l, study.level_symbols[size_t(l)],
                                 100 * study.level_ones[size_t(l)] / std::max(1.0, study.level_symbols[size_t(l)]), study.level_bits[size_t(l)]);
                std::fprintf(stderr, "\n");
            }
        }
        if (&design == &designs[0])
            for (size_t m = 0; m < data.size(); ++m)
                if (std::abs(bits[m] - data[m].second_bits) > 1e-6 * data[m].second_bits)
                    std::fprintf(stderr, "%s: re-implementation %.1f bits, coder's second model %.1f\n", data[m].name.c_str(), bits[m],
                                 data[m].second_bits);
        row(design.name, bits);
    }
    return 0;
}
