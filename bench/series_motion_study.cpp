// Motion-compensated prediction of a frame's refinement (docs/SERIES.md, "Predicting where the
// front goes"): for every "refined?" symbol the inter-frame coder codes (FORMAT.md 7.6 walk),
// what the previous frames say at the node's place, under several predictions of the frame:
//   - the previous frame at the same place (no motion);
//   - the previous frame displaced by a motion the encoder estimates per block of the domain and
//     would send (block matching of frame k against frame k-1);
//   - the previous frame displaced by the motion estimated between the two frames before it
//     (frame k-1 against k-2: the decoder can do that itself, nothing sent);
//   - the depth extrapolated linearly from the two previous frames (2 d(k-1) - d(k-2));
//   - either block motion replaced by one affine map a frame fitted to its moving blocks' vectors
//     (six numbers to send, or none for the extrapolated one), plainly or robustly (outliers dropped);
//   - for reference, the previous frame displaced by the front's own motion, exactly (an oracle:
//     the best any motion model could do).
// The previous frames are seen as depth images: the level of the leaf covering each pixel (a
// pixel is a finest-level leg over --subpixels; planar meshes only). A node of level l at centroid c asks the
// predicted image at c and at the midpoints of c and its corners: depth - l (> 0: refined there).
// Per design: the static conditional entropy H(X|ctx) and the adaptive code length with the
// coder's BitModel carried from frame to frame, against the same frames coded alone
// (encode_hierarchy) and against the cost of the motion vectors (Elias-gamma estimate).
//
//   series_motion_study [--scenario front|front-cfl] [--frames N] [--max-level L] [--cfl C]
//                       [--block PX] [--search PX] [--subpixels S (pixels a finest leg, default 1)]
#include <amc/hierarchy_coder.h>
#include <amc/refinement.h>

#include "coding/entropy/arithmetic_coder.h"
#include "series/frame_connectivity.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <map>
#include <string>
#include <vector>

using namespace amc;

namespace {

// series_bench's front-cfl scenario (the same code): make_moving_front_sequence's circle advancing
// `cfl` finest elements a step; cfl 0 is make_moving_front_sequence itself.
Vec3 centroid(const Hierarchy& h, NodeId n) {
    return (1.0 / 3.0) * (h.position(h.vertex(n, 0)) + h.position(h.vertex(n, 1)) + h.position(h.vertex(n, 2)));
}
double diameter(const Hierarchy& h, NodeId n) {
    double longest = 0;
    for (int e = 0; e < 3; ++e) {
        const Vec3 d = h.position(h.vertex(n, e)) - h.position(h.vertex(n, (e + 1) % 3));
        longest = std::max(longest, dot(d, d));
    }
    return std::sqrt(longest);
}
std::vector<Hierarchy> front_sequence(int steps, int max_level, double cfl) {
    if (cfl <= 0) return make_moving_front_sequence(steps, max_level);
    const double advance = cfl * std::sqrt(2.0) / 8 / double(1 << max_level);
    std::vector<Hierarchy> sequence;
    Hierarchy h(make_square(8));
    for (int step = 0; step < steps; ++step) {
        const double radius = 0.5 + advance * step;
        auto size_at = [radius](Vec3 x) { return 1.2 * std::fabs(std::hypot(x.x + 0.3, x.y + 0.2) - radius); };
        for (bool changed = true; changed;) {
            changed = false;
            const std::vector<NodeId> order = h.breadth_first_order();
            for (auto it = order.rbegin(); it != order.rend(); ++it)
                if (h.is_alive(*it) && !h.is_leaf(*it) && diameter(h, *it) <= size_at(centroid(h, *it)) && h.coarsen(*it))
                    changed = true;
        }
        refine_to_size(h, size_at, max_level);
        sequence.push_back(h);
    }
    return sequence;
}

struct Image {
    double x0 = 0, y0 = 0, h = 1;
    int w = 0, ht = 0;
    std::vector<int8_t> d;  // leaf level, -1 outside
    int at(int x, int y) const { return x < 0 || y < 0 || x >= w || y >= ht ? -1 : d[size_t(y) * size_t(w) + size_t(x)]; }
};

Image rasterize(const Hierarchy& h, double x0, double y0, double px, int w, int ht) {
    Image im;
    im.x0 = x0, im.y0 = y0, im.h = px, im.w = w, im.ht = ht;
    im.d.assign(size_t(w) * size_t(ht), -1);
    for (NodeId n : h.leaves()) {
        Vec3 p[3];
        for (int i = 0; i < 3; ++i) p[i] = h.position(h.vertex(n, i));
        const double area = (p[1].x - p[0].x) * (p[2].y - p[0].y) - (p[1].y - p[0].y) * (p[2].x - p[0].x);
        const double s = area < 0 ? -1 : 1;
        const int xa = std::max(0, int(std::floor((std::min({p[0].x, p[1].x, p[2].x}) - x0) / px)));
        const int xb = std::min(w - 1, int(std::ceil((std::max({p[0].x, p[1].x, p[2].x}) - x0) / px)));
        const int ya = std::max(0, int(std::floor((std::min({p[0].y, p[1].y, p[2].y}) - y0) / px)));
        const int yb = std::min(ht - 1, int(std::ceil((std::max({p[0].y, p[1].y, p[2].y}) - y0) / px)));
        for (int y = ya; y <= yb; ++y)
            for (int x = xa; x <= xb; ++x) {
                const double cx = x0 + (x + 0.5) * px, cy = y0 + (y + 0.5) * px;
                bool inside = true;
                for (int i = 0; i < 3 && inside; ++i) {
                    const Vec3 a = p[i], b = p[(i + 1) % 3];
                    inside = s * ((b.x - a.x) * (cy - a.y) - (b.y - a.y) * (cx - a.x)) >= 0;
                }
                if (inside) im.d[size_t(y) * size_t(w) + size_t(x)] = int8_t(h.level(n));
            }
    }
    return im;
}

struct Motion {
    int block = 64;
    int bw = 0, bh = 0;
    std::vector<int> vx, vy;  // per block, in pixels: frame(x) ~ reference(x - v)
    int get_x(int x, int y, int block_px) const { return vx[size_t(y / block_px) * size_t(bw) + size_t(x / block_px)]; }
};

// Sum of |a(x) - b(x - v)| over the block's pixels at the stride; outside on either side costs 2.
long block_sad(const Image& a, const Image& b, int bx, int by, int block, int vx, int vy, int stride) {
    long sad = 0;
    for (int y = by * block; y < std::min(a.ht, (by + 1) * block); y += stride)
        for (int x = bx * block; x < std::min(a.w, (bx + 1) * block); x += stride) {
            const int p = a.at(x, y);
            if (p < 0) continue;
            const int q = b.at(x - vx, y - vy);
            sad += q < 0 ? 2 : std::abs(p - q);
        }
    return sad;
}

Motion estimate(const Image& a, const Image& b, int block, int search) {
    Motion m;
    m.block = block;
    m.bw = (a.w + block - 1) / block;
    m.bh = (a.ht + block - 1) / block;
    m.vx.assign(size_t(m.bw) * size_t(m.bh), 0);
    m.vy = m.vx;
    for (int by = 0; by < m.bh; ++by)
        for (int bx = 0; bx < m.bw; ++bx) {
            long best = block_sad(a, b, bx, by, block, 0, 0, 1);
            if (best == 0) continue;
            int cx = 0, cy = 0;
            // Coarse to fine: candidate steps 8, 2, 1 (sampling strides 4, 2, 1).
            const int steps[3] = {8, 2, 1}, ranges[3] = {(search + 7) / 8, 4, 1}, strides[3] = {4, 2, 1};
            for (int s = 0; s < 3; ++s) {
                int bxv = cx, byv = cy;
                long bs = block_sad(a, b, bx, by, block, cx, cy, strides[s]);
                for (int dy = -ranges[s]; dy <= ranges[s]; ++dy)
                    for (int dx = -ranges[s]; dx <= ranges[s]; ++dx) {
                        const int vx = cx + dx * steps[s], vy = cy + dy * steps[s];
                        if (std::abs(vx) > search || std::abs(vy) > search) continue;
                        const long sad = block_sad(a, b, bx, by, block, vx, vy, strides[s]);
                        if (sad < bs || (sad == bs && std::abs(vx) + std::abs(vy) < std::abs(bxv) + std::abs(byv)))
                            bs = sad, bxv = vx, byv = vy;
                    }
                cx = bxv, cy = byv;
            }
            if (block_sad(a, b, bx, by, block, cx, cy, 1) < best) {
                m.vx[size_t(by) * size_t(m.bw) + size_t(bx)] = cx;
                m.vy[size_t(by) * size_t(m.bw) + size_t(bx)] = cy;
            }
        }
    return m;
}

// Elias gamma of the zigzagged value, in bits.
double gamma_bits(int v) {
    const unsigned z = v >= 0 ? 2u * unsigned(v) : 2u * unsigned(-v) - 1;
    return 2 * std::floor(std::log2(double(z) + 1)) + 1;
}

// An affine motion field v(p) = A p + t (pixels) fitted by least squares to the moving blocks'
// vectors (at the blocks' centres): one map a frame, six numbers to send.
struct Affine {
    double a[3] = {0, 0, 0}, b[3] = {0, 0, 0};  // vx = a0 x + a1 y + a2, vy = b0 x + b1 y + b2
};
Affine fit_affine(const Motion& m, const std::vector<uint8_t>* use = nullptr) {
    double n[3][3] = {}, rx[3] = {}, ry[3] = {};
    int count = 0;
    for (int by = 0; by < m.bh; ++by)
        for (int bx = 0; bx < m.bw; ++bx) {
            const size_t i = size_t(by) * size_t(m.bw) + size_t(bx);
            if (m.vx.empty() || (m.vx[i] == 0 && m.vy[i] == 0)) continue;
            if (use && !(*use)[i]) continue;
            const double f[3] = {(bx + 0.5) * m.block, (by + 0.5) * m.block, 1.0};
            for (int r = 0; r < 3; ++r) {
                for (int c = 0; c < 3; ++c) n[r][c] += f[r] * f[c];
                rx[r] += f[r] * m.vx[i];
                ry[r] += f[r] * m.vy[i];
            }
            ++count;
        }
    Affine out;
    if (count < 3) return out;
    // Cramer's rule on the 3 x 3 normal equations.
    auto det = [](const double q[3][3]) {
        return q[0][0] * (q[1][1] * q[2][2] - q[1][2] * q[2][1]) - q[0][1] * (q[1][0] * q[2][2] - q[1][2] * q[2][0]) +
               q[0][2] * (q[1][0] * q[2][1] - q[1][1] * q[2][0]);
    };
    const double d = det(n);
    if (std::fabs(d) < 1e-9) return out;
    for (int c = 0; c < 3; ++c) {
        double qx[3][3], qy[3][3];
        for (int r = 0; r < 3; ++r)
            for (int k = 0; k < 3; ++k) qx[r][k] = qy[r][k] = n[r][k];
        for (int r = 0; r < 3; ++r) qx[r][c] = rx[r], qy[r][c] = ry[r];
        out.a[c] = det(qx) / d;
        out.b[c] = det(qy) / d;
    }
    return out;
}

// The same fit, robust: three rounds, each dropping the blocks whose vector is more than twice
// the median distance from the previous round's map.
Affine fit_affine_robust(const Motion& m) {
    Affine f = fit_affine(m);
    std::vector<uint8_t> use(m.vx.size(), 1);
    for (int round = 0; round < 3; ++round) {
        std::vector<double> r(m.vx.size(), -1);
        std::vector<double> sorted;
        for (int by = 0; by < m.bh; ++by)
            for (int bx = 0; bx < m.bw; ++bx) {
                const size_t i = size_t(by) * size_t(m.bw) + size_t(bx);
                if (m.vx[i] == 0 && m.vy[i] == 0) continue;
                const double x = (bx + 0.5) * m.block, y = (by + 0.5) * m.block;
                r[i] = std::hypot(m.vx[i] - (f.a[0] * x + f.a[1] * y + f.a[2]), m.vy[i] - (f.b[0] * x + f.b[1] * y + f.b[2]));
                sorted.push_back(r[i]);
            }
        if (sorted.size() < 6) return f;
        std::nth_element(sorted.begin(), sorted.begin() + long(sorted.size() / 2), sorted.end());
        const double limit = std::max(0.5, 2 * sorted[sorted.size() / 2]);
        for (size_t i = 0; i < r.size(); ++i) use[i] = r[i] >= 0 && r[i] <= limit;
        f = fit_affine(m, &use);
    }
    return f;
}

struct Prediction {
    // relative depth codes at the centroid and min / max over the centroid and the three
    // corner midpoints: 0 outside, 1: depth - level <= -1, 2: 0, 3: 1, 4: >= 2.
    uint8_t c = 0, lo = 0, hi = 0;
};

struct Symbol {
    uint16_t frame;
    uint8_t level, cls, border, dec_changed, dec_refined, parent_area, bit;
    Prediction none, sent, extra, linear, oracle, fitted, fitted_extra, robust, robust_extra;
};

uint8_t rel_code(int depth, int level) {
    if (depth < 0) return 0;
    return uint8_t(std::max(-1, std::min(depth - level, 2)) + 2);
}

int previous_class(const Hierarchy& prev, NodeId p) {
    if (p == kNoNode) return 0;
    if (prev.is_leaf(p)) return 1;
    for (int k = 0; k < 4; ++k)
        if (!prev.is_leaf(prev.child(p, k))) return 3;
    return 2;
}

using Lookup = std::function<int(double, double)>;

Prediction predict(const Lookup& depth_at, const Vec3 p[3], int level) {
    const double cx = (p[0].x + p[1].x + p[2].x) / 3, cy = (p[0].y + p[1].y + p[2].y) / 3;
    Prediction out;
    out.c = rel_code(depth_at(cx, cy), level);
    out.lo = out.hi = out.c;
    for (int i = 0; i < 3; ++i) {
        const uint8_t r = rel_code(depth_at((cx + p[i].x) / 2, (cy + p[i].y) / 2), level);
        out.lo = std::min(out.lo, r);
        out.hi = std::max(out.hi, r);
    }
    return out;
}

void collect(int frame, const Hierarchy& prev, const Hierarchy& h, const Lookup lookups[5], std::vector<Symbol>& out) {
    const Counterparts cp = match_nodes(prev, h);
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
            if (complete && h.level(n) < kMaxLevel && refined_neighbors < 3) {
                Symbol s{};
                s.frame = uint16_t(frame);
                s.level = uint8_t(h.level(n));
                s.cls = uint8_t(cls);
                for (int e = 0; e < 3; ++e) {
                    const NodeId q = h.neighbor(n, e);
                    if (q == kNoNode || !(state[q] & kDecided)) continue;
                    s.dec_changed += bool(state[q] & kChanged);
                    s.dec_refined += bool(state[q] & kRefined);
                }
                const NodeId parent = h.parent(n);
                if (parent != kNoNode) {
                    s.parent_area = changed(parent);
                    for (int e = 0; e < 3; ++e) s.parent_area |= changed(h.neighbor(parent, e));
                }
                int reference_refined = 0;
                if (p != kNoNode)
                    for (int e = 0; e < 3; ++e) {
                        const NodeId q = prev.neighbor(p, e);
                        reference_refined += q != kNoNode && !prev.is_leaf(q);
                    }
                s.border = uint8_t(cls == 0 ? std::min<int>(s.dec_refined, 2)
                                   : cls == 1 ? std::min(reference_refined, 2)
                                   : reference_refined == 3 ? 0 : reference_refined == 2 ? 1 : 2);
                Vec3 pos[3];
                for (int i = 0; i < 3; ++i) pos[i] = h.position(h.vertex(n, i));
                s.none = predict(lookups[0], pos, s.level);
                s.sent = predict(lookups[1], pos, s.level);
                s.extra = predict(lookups[2], pos, s.level);
                s.linear = predict(lookups[3], pos, s.level);
                s.oracle = predict(lookups[4], pos, s.level);
                s.fitted = predict(lookups[5], pos, s.level);
                s.fitted_extra = predict(lookups[6], pos, s.level);
                s.robust = predict(lookups[7], pos, s.level);
                s.robust_extra = predict(lookups[8], pos, s.level);
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

int pcode(const Prediction& p) { return (p.c * 5 + p.lo) * 5 + p.hi; }

}  // namespace

int main(int argc, char** argv) {
    std::string scenario = "front";
    int frames = 100, max_level = 8, block = 64, search = 48;
    double cfl = 0;
    int subpixels = 1;
    for (int i = 1; i + 1 < argc; i += 2) {
        const std::string a = argv[i];
        if (a == "--scenario") scenario = argv[i + 1];
        else if (a == "--frames") frames = std::atoi(argv[i + 1]);
        else if (a == "--max-level") max_level = std::atoi(argv[i + 1]);
        else if (a == "--cfl") cfl = std::atof(argv[i + 1]);
        else if (a == "--block") block = std::atoi(argv[i + 1]);
        else if (a == "--search") search = std::atoi(argv[i + 1]);
        else if (a == "--subpixels") subpixels = std::max(1, std::atoi(argv[i + 1]));
        else {
            std::fprintf(stderr, "unknown option %s\n", a.c_str());
            return 2;
        }
    }
    if (scenario != "front" && scenario != "front-cfl") {
        std::fprintf(stderr, "unknown scenario %s\n", scenario.c_str());
        return 2;
    }
    const std::vector<Hierarchy> seq = front_sequence(frames, max_level, scenario == "front" ? 0 : cfl);
    const double step = scenario == "front" ? 1.0 / std::max(1, frames - 1) : cfl * std::sqrt(2.0) / 8 / double(1 << max_level);
    // Pixels: a finest-level leg of the base's (unit square's) 1/8 cells, over `subpixels`.
    const double px = (1.0 / 8) / double(1 << max_level) / subpixels;
    const int w = int(std::lround(1.0 / px));
    // The depth images of the last three frames (images[k % 3] is frame k's).
    std::vector<Image> images(3);
    images[0] = rasterize(seq[0], 0, 0, px, w, w);

    std::vector<Symbol> symbols;
    uint64_t alone_total = 0, alone_first = 0;
    double sent_bits_zero = 0, sent_bits_temporal = 0, sent_bits_vs_extrapolated = 0;
    uint64_t moving_blocks = 0;
    double moving_length = 0;
    std::vector<int> prev_vx, prev_vy;
    for (size_t k = 1; k < seq.size(); ++k) {
        images[k % 3] = rasterize(seq[k], 0, 0, px, w, w);
        const Image& a = images[k % 3];
        const Image& b = images[(k - 1) % 3];
        const Motion sent = estimate(a, b, block, search);
        Motion extra;
        if (k >= 2) extra = estimate(b, images[(k - 2) % 3], block, search);
        for (size_t i = 0; i < sent.vx.size(); ++i) {
            const bool moving = sent.vx[i] != 0 || sent.vy[i] != 0;
            moving_blocks += moving;
            if (moving) moving_length += std::hypot(double(sent.vx[i]), double(sent.vy[i]));
            sent_bits_zero += 1 + (moving ? gamma_bits(sent.vx[i]) + gamma_bits(sent.vy[i]) : 0);
            const int px0 = prev_vx.empty() ? 0 : prev_vx[i], py0 = prev_vy.empty() ? 0 : prev_vy[i];
            sent_bits_temporal += gamma_bits(sent.vx[i] - px0) + gamma_bits(sent.vy[i] - py0);
            const int ex = k >= 2 ? extra.vx[i] : 0, ey = k >= 2 ? extra.vy[i] : 0;
            sent_bits_vs_extrapolated += gamma_bits(sent.vx[i] - ex) + gamma_bits(sent.vy[i] - ey);
        }
        prev_vx = sent.vx, prev_vy = sent.vy;
        auto pix = [&](double x, double y, int& ix, int& iy) {
            ix = int(std::floor((x - b.x0) / b.h));
            iy = int(std::floor((y - b.y0) / b.h));
        };
        const Affine fitted = fit_affine(sent), fitted_extra = k >= 2 ? fit_affine(extra) : Affine{};
        const Affine robust = fit_affine_robust(sent), robust_extra = k >= 2 ? fit_affine_robust(extra) : Affine{};
        auto affine_lookup = [&](const Affine& f, double x, double y) {
            const double fx = (x - b.x0) / b.h, fy = (y - b.y0) / b.h;
            const double vx = f.a[0] * fx + f.a[1] * fy + f.a[2], vy = f.b[0] * fx + f.b[1] * fy + f.b[2];
            return b.at(int(std::floor(fx - vx)), int(std::floor(fy - vy)));
        };
        const Lookup lookups[9] = {
            [&](double x, double y) { int ix, iy; pix(x, y, ix, iy); return b.at(ix, iy); },
            [&](double x, double y) {
                int ix, iy;
                pix(x, y, ix, iy);
                const int cx = std::max(0, std::min(ix, w - 1)), cy = std::max(0, std::min(iy, w - 1));
                const size_t bi = size_t(cy / block) * size_t(sent.bw) + size_t(cx / block);
                return b.at(ix - sent.vx[bi], iy - sent.vy[bi]);
            },
            [&](double x, double y) {
                int ix, iy;
                pix(x, y, ix, iy);
                if (k < 2) return b.at(ix, iy);
                const int cx = std::max(0, std::min(ix, w - 1)), cy = std::max(0, std::min(iy, w - 1));
                const size_t bi = size_t(cy / block) * size_t(extra.bw) + size_t(cx / block);
                return b.at(ix - extra.vx[bi], iy - extra.vy[bi]);
            },
            [&](double x, double y) {
                int ix, iy;
                pix(x, y, ix, iy);
                const int d1 = b.at(ix, iy);
                if (k < 2 || d1 < 0) return d1;
                const int d2 = images[(k - 2) % 3].at(ix, iy);
                return d2 < 0 ? d1 : std::max(0, 2 * d1 - d2);
            },
            // The front's own motion, exactly: a point at distance d from the centre was at d - step.
            [&](double x, double y) {
                const double dx = x + 0.3, dy = y + 0.2, d = std::hypot(dx, dy);
                const double f = d > step ? (d - step) / d : 0.0;
                int ix, iy;
                pix(-0.3 + dx * f, -0.2 + dy * f, ix, iy);
                return b.at(ix, iy);
            },
            [&](double x, double y) { return affine_lookup(fitted, x, y); },
            [&](double x, double y) { return affine_lookup(fitted_extra, x, y); },
            [&](double x, double y) { return affine_lookup(robust, x, y); },
            [&](double x, double y) { return affine_lookup(robust_extra, x, y); },
        };
        collect(int(k), seq[k - 1], seq[k], lookups, symbols);
        const uint64_t alone = encode_hierarchy(seq[k]).size();
        alone_total += alone;
        if (k == 1) alone_first = encode_hierarchy(seq[0]).size();
        std::fprintf(stderr, "frame %zu: %zu symbols so far\n", k, symbols.size());
    }
    uint64_t faces = 0;
    for (const Hierarchy& h : seq) faces += h.leaf_count();
    std::printf("# series_motion_study --scenario %s --frames %d --max-level %d --cfl %g --block %d --search %d "
                "--subpixels %d (the front advances %.3g pixels a step)\n",
                scenario.c_str(), frames, max_level, cfl, block, search, subpixels, step / px);
    std::printf("# %zu frames, %.0f leaves a frame on average; %zu coded symbols in frames 1..; frames 1.. coded alone "
                "(encode_hierarchy): %llu bytes (frame 0: %llu); every frame alone / 5 = %.0f bytes\n",
                seq.size(), double(faces) / double(seq.size()), symbols.size(), (unsigned long long)alone_total,
                (unsigned long long)alone_first, double(alone_total + alone_first) / 5);
    std::printf("# motion vectors (blocks of %d px, %d blocks a frame, %.1f moving on average): Elias-gamma "
                "estimate %.0f bytes coded against zero, %.0f against the previous frame's, %.0f against the "
                "decoder's extrapolation; the moving blocks' vectors are %.2f pixels long on average\n",
                block, int(prev_vx.size()), double(moving_blocks) / double(seq.size() - 1), sent_bits_zero / 8,
                sent_bits_temporal / 8, sent_bits_vs_extrapolated / 8, moving_length / double(std::max<uint64_t>(moving_blocks, 1)));
    auto cap = [](int v, int m) { return std::min(v, m); };
    auto v3 = [&](const Symbol& s) { return ((s.cls * 3 + s.border) * 3 + cap(s.dec_changed, 2)) * 2 + s.parent_area; };
    const std::vector<Design> designs = {
        {"v3 contexts (no indicator): cls, border, changed nbrs, parent area", v3},
        {"spatial: decided nbrs refined, level", [&](const Symbol& s) { return s.dec_refined * 16 + s.level; }},
        {"no motion: depth at centroid", [&](const Symbol& s) { return s.none.c; }},
        {"no motion: depth c/min/max", [&](const Symbol& s) { return pcode(s.none); }},
        {"no motion: depth c/min/max + v3", [&](const Symbol& s) { return pcode(s.none) * 100 + v3(s); }},
        {"sent motion: depth at centroid", [&](const Symbol& s) { return s.sent.c; }},
        {"sent motion: depth c/min/max", [&](const Symbol& s) { return pcode(s.sent); }},
        {"sent motion: c/min/max + decided nbrs refined", [&](const Symbol& s) { return pcode(s.sent) * 4 + s.dec_refined; }},
        {"sent motion: c/min/max + v3", [&](const Symbol& s) { return pcode(s.sent) * 100 + v3(s); }},
        {"sent motion: c/min/max + dec refined + dec changed(vs motion)", [&](const Symbol& s) {
             return (pcode(s.sent) * 4 + s.dec_refined) * 3 + cap(s.dec_changed, 2); }},
        {"extrapolated motion: depth at centroid", [&](const Symbol& s) { return s.extra.c; }},
        {"extrapolated motion: depth c/min/max", [&](const Symbol& s) { return pcode(s.extra); }},
        {"extrapolated motion: c/min/max + decided nbrs refined", [&](const Symbol& s) { return pcode(s.extra) * 4 + s.dec_refined; }},
        {"extrapolated motion: c/min/max + v3", [&](const Symbol& s) { return pcode(s.extra) * 100 + v3(s); }},
        {"affine fit of the sent vectors: c/min/max + v3", [&](const Symbol& s) { return pcode(s.fitted) * 100 + v3(s); }},
        {"affine fit of the extrapolated vectors: c/min/max + v3", [&](const Symbol& s) { return pcode(s.fitted_extra) * 100 + v3(s); }},
        {"robust affine fit of the sent vectors: c/min/max + v3", [&](const Symbol& s) { return pcode(s.robust) * 100 + v3(s); }},
        {"robust affine fit of the extrapolated vectors: c/min/max + v3", [&](const Symbol& s) { return pcode(s.robust_extra) * 100 + v3(s); }},
        {"the front's exact motion: depth at centroid", [&](const Symbol& s) { return s.oracle.c; }},
        {"the front's exact motion: c/min/max", [&](const Symbol& s) { return pcode(s.oracle); }},
        {"the front's exact motion: c/min/max + decided nbrs refined", [&](const Symbol& s) { return pcode(s.oracle) * 4 + s.dec_refined; }},
        {"the front's exact motion: c/min/max + v3", [&](const Symbol& s) { return pcode(s.oracle) * 100 + v3(s); }},
        {"the front's exact motion: c/min/max + dec refined, changed + level", [&](const Symbol& s) {
             return ((pcode(s.oracle) * 4 + s.dec_refined) * 3 + cap(s.dec_changed, 2)) * 16 + s.level; }},
        {"linear depth extrapolation: c/min/max", [&](const Symbol& s) { return pcode(s.linear); }},
        {"linear depth extrapolation: c/min/max + dec refined", [&](const Symbol& s) { return pcode(s.linear) * 4 + s.dec_refined; }},
    };
    for (const Design& d : designs) {
        std::map<int, std::pair<uint64_t, uint64_t>> counts;
        std::map<int, BitModel> carried;
        double carried_bits = 0;
        for (const Symbol& s : symbols) {
            const int c = d.ctx(s);
            auto& cnt = counts[c];
            cnt.first += s.bit;
            ++cnt.second;
            carried_bits += carried[c].cost_bits(s.bit);
            carried[c].update(s.bit);
        }
        double h = 0;
        for (const auto& kv : counts) h += binary_entropy_bits(kv.second.first, kv.second.second);
        std::printf("%-66s ctx %5zu  H(X|ctx) %8.0f B  adaptive, carried %8.0f B (%5.1f%% of alone)\n", d.name,
                    counts.size(), h / 8, carried_bits / 8, 100 * carried_bits / 8 / double(alone_total));
    }
    return 0;
}
