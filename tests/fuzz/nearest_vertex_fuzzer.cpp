// Fuzz target of NearestVertex (src/import/nearest_vertex.h), the importer's nearest-vertex search,
// against a brute-force scan and the k-d tree. The input builds a point set of up to 4096 points
// that holds what the trees' special cases need (a lattice of exact ties, many copies of a point, a
// cluster inside one Morton cell, far outliers up to DBL_MAX, random boxes, any coordinates, all of
// it scaled by 2^-1074 .. 2^1023), an insertion order or none, and asks up to 32 queries (at a
// point, between two, nudged off one by a few ulps, anywhere, far away; `count` 0 .. kMaxCount + 1;
// limits infinite, 0, exactly a point's squared distance and its neighbouring doubles; `usable`
// from a byte mask). The oracles, each from the header:
//   (a) "the up to count usable vertices nearest to p, nearest first", "only vertices nearer than
//       sqrt(max_squared_distance) count": the squared distances returned are the brute-force
//       smallest ones of usable vertices below the limit, in order, computed as the library does
//       (exact_dot of the point minus the query); each returned vertex is usable, distinct and at
//       its distance; `usable` is asked only about vertices below the limit ("tested only on
//       vertices as near as the best so far or nearer");
//   (b) "a Morton tree answers every query whose nearest usable vertices lie at distinct
//       distances; where two lie at the same distance ... the first in a k-d tree built from the
//       vertices in a given order": untied, the vertices are the brute-force ones (then unique);
//       tied (two usable vertices at one distance within the answer, or one as near as its last),
//       they are a KdTree's built here from the same points and order (which of equal vertices a
//       k-d tree meets first is its own, so no scan derives it);
//   (c) "the answer and whether it ties do not depend on the order in which points are met": the
//       same answers, mapped back, from three other NearestVertex over the same points: in Morton
//       order with their codes (spatial_vertex_order, as the importer builds it), that one renamed
//       under a permutation (NearestVertex(other, new_id), as the importer's renumbered leaf
//       mesh), and a build over the points so renumbered (another order within the Morton cells,
//       so other median splits); and find(p, usable) is find_nearest(p, usable, 1, ...).
// A mismatch prints the case and aborts.
#include "fuzz_targets.h"

#include "common/exact_float.h"
#include "import/nearest_vertex.h"
#include "import/spatial_order.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <numeric>
#include <string>

namespace amc::fuzz {
namespace {

constexpr uint32_t kMaxPoints = 4096;
constexpr int kMaxGroups = 16;
constexpr int kMaxQueries = 32;
constexpr uint32_t kMaxCount = NearestVertex::kMaxCount;
constexpr double kInfinity = std::numeric_limits<double>::infinity();

uint32_t u16(ByteReader& in) {
    const uint32_t low = in.u8();
    return low | uint32_t(in.u8()) << 8;
}

// A binary exponent in [-1074, 1023]: 2^e from the least subnormal to the greatest power of two.
int exponent(ByteReader& in) { return std::clamp(int(int16_t(u16(in))), -1074, 1023); }

// Coordinates must be finite (the importer refuses others before it searches): an infinity or
// NaN becomes DBL_MAX of its sign.
double finite(double x) { return std::isfinite(x) ? x : std::copysign(DBL_MAX, x); }
Vec3 finite(Vec3 p) { return {finite(p.x), finite(p.y), finite(p.z)}; }

double raw_double(ByteReader& in) {
    const uint64_t bits = in.u64();
    double x;
    std::memcpy(&x, &bits, sizeof x);
    return x;
}

// p + 2^e (dx, dy, dz) for small integers.
Vec3 nudged(Vec3 p, ByteReader& in, int e) {
    const double dx = int8_t(in.u8()), dy = int8_t(in.u8()), dz = int8_t(in.u8());
    return finite(Vec3{p.x + std::ldexp(dx, e), p.y + std::ldexp(dy, e), p.z + std::ldexp(dz, e)});
}

// The squared distance NearestVertex computes (nearest_vertex.h, squared_distance).
double squared_distance(Vec3 point, Vec3 query) {
    const Vec3 d = {point.x - query.x, point.y - query.y, point.z - query.z};
    return exact_dot(d, d);
}

// A permutation of 0 .. n-1 drawn from a seed.
std::vector<uint32_t> shuffled(uint32_t n, uint32_t seed) {
    std::vector<uint32_t> order(n);
    std::iota(order.begin(), order.end(), 0u);
    Random random{seed};
    for (uint32_t i = n; i > 1; --i) std::swap(order[i - 1], order[random.next() % i]);
    return order;
}

std::vector<uint32_t> inverse(const std::vector<uint32_t>& permutation) {
    std::vector<uint32_t> out(permutation.size());
    for (uint32_t i = 0; i < permutation.size(); ++i) out[permutation[i]] = i;
    return out;
}

// Groups of points, each from a kind byte, until kMaxPoints.
std::vector<Vec3> read_points(ByteReader& in) {
    std::vector<Vec3> points;
    const int groups = 1 + in.u8() % kMaxGroups;
    auto room = [&points] { return kMaxPoints - uint32_t(points.size()); };
    auto earlier = [&points](ByteReader& in) {  // an earlier point, or the origin
        const uint32_t i = u16(in);
        return points.empty() ? Vec3{0, 0, 0} : points[i % points.size()];
    };
    for (int g = 0; g < groups && room() > 0; ++g) {
        switch (in.u8() % 6) {
            case 0: {  // any finite coordinates
                const uint32_t m = std::min(1 + in.u8() % 8u, room());
                for (uint32_t i = 0; i < m; ++i) {
                    const double x = raw_double(in), y = raw_double(in);
                    points.push_back(finite(Vec3{x, y, raw_double(in)}));
                }
                break;
            }
            case 1: {  // a lattice of step 2^e, 2^(e+1) or 3 2^e (exact ties everywhere) at an earlier point
                const int e = exponent(in);
                const double step = std::ldexp(1 + in.u8() % 3, e);
                const Vec3 origin = earlier(in);
                const uint32_t nx = 1 + in.u8() % 16, ny = 1 + in.u8() % 16, nz = 1 + in.u8() % 16;
                for (uint32_t i = 0; i < nx && room() > 0; ++i)
                    for (uint32_t j = 0; j < ny && room() > 0; ++j)
                        for (uint32_t k = 0; k < nz && room() > 0; ++k)
                            points.push_back(finite(Vec3{origin.x + i * step, origin.y + j * step, origin.z + k * step}));
                break;
            }
            case 2: {  // up to 256 copies of an earlier point
                const Vec3 p = earlier(in);
                const uint32_t m = std::min(1 + uint32_t(in.u8()), room());
                points.insert(points.end(), m, p);
                break;
            }
            case 3: {  // a cluster within 128 * 2^e of an earlier point (one Morton cell when e is small)
                const Vec3 center = earlier(in);
                const int e = exponent(in);
                const uint32_t m = std::min(1 + in.u8() % 64u, room());
                Random random{in.u32()};
                for (uint32_t i = 0; i < m; ++i) {
                    const double dx = int8_t(random.next()), dy = int8_t(random.next()), dz = int8_t(random.next());
                    points.push_back(finite(Vec3{center.x + std::ldexp(dx, e), center.y + std::ldexp(dy, e),
                                                 center.z + std::ldexp(dz, e)}));
                }
                break;
            }
            case 4: {  // an outlier: an earlier point with some coordinates far away
                Vec3 p = earlier(in);
                const uint8_t axes = in.u8();
                const uint8_t kind = in.u8() % 4;
                const double far = kind == 0 ? 1e300 : kind == 1 ? DBL_MAX : kind == 2 ? std::ldexp(1.0, exponent(in))
                                                                                       : std::fabs(finite(raw_double(in)));
                double* c[3] = {&p.x, &p.y, &p.z};
                for (int a = 0; a < 3; ++a)
                    if (axes >> a & 1) *c[a] = axes >> (a + 3) & 1 ? -far : far;
                points.push_back(p);
                break;
            }
            default: {  // up to 2048 points on a random integer box of 2^e steps (ties), or graded off it
                const uint32_t m = std::min(1 + u16(in) % 2048, room());
                const uint32_t radius = 1 + in.u8();
                const int e = exponent(in);
                const bool graded = in.u8() & 1;
                Random random{in.u32()};
                for (uint32_t i = 0; i < m; ++i) {
                    double c[3];
                    for (double& x : c) x = std::ldexp(double(random.next() % (2 * radius + 1)) - radius, e);
                    const double grade = graded ? std::pow(double(random.next() % 1024) / 1024, 3.0) : 1.0;
                    points.push_back(finite(Vec3{grade * c[0], grade * c[1], grade * c[2]}));
                }
                break;
            }
        }
    }
    return points;
}

struct Query {
    Vec3 p;
    uint32_t count;
    double limit;
    uint64_t mask;      // usable(v): bit v % modulus of mask
    uint32_t modulus;
    bool usable(uint32_t v) const { return mask >> (v % modulus) & 1; }
};

Query read_query(ByteReader& in, const std::vector<Vec3>& points) {
    auto point = [&](ByteReader& in) {
        const uint32_t i = u16(in);
        return points.empty() ? Vec3{0, 0, 0} : points[i % points.size()];
    };
    Query q;
    switch (in.u8() % 6) {
        case 0: q.p = point(in); break;  // at a point
        case 1: {                        // halfway between two (as a midpoint is placed): ties
            const Vec3 a = point(in), b = point(in);
            q.p = finite(Vec3{0.5 * a.x + 0.5 * b.x, 0.5 * a.y + 0.5 * b.y, 0.5 * a.z + 0.5 * b.z});
            break;
        }
        case 2: {
            const Vec3 a = point(in);
            q.p = nudged(a, in, exponent(in));
            break;
        }
        case 3: {
            const double x = raw_double(in), y = raw_double(in);
            q.p = finite(Vec3{x, y, raw_double(in)});
            break;
        }
        case 4: {  // far away on some axes
            q.p = point(in);
            const uint8_t axes = in.u8();
            const double mantissa = 1 + in.u8() / 256.0;
            const double far = std::ldexp(mantissa, exponent(in));
            double* c[3] = {&q.p.x, &q.p.y, &q.p.z};
            for (int a = 0; a < 3; ++a)
                if (axes >> a & 1) *c[a] = finite(axes >> (a + 3) & 1 ? -far : far);
            break;
        }
        default: {  // a coordinate of a point moved by a few ulps
            q.p = point(in);
            double* c[3] = {&q.p.x, &q.p.y, &q.p.z};
            double& x = *c[in.u8() % 3];
            const int8_t ulps = int8_t(in.u8());
            for (int i = 0; i < std::abs(int(ulps)) % 8; ++i) x = finite(std::nextafter(x, ulps < 0 ? -kInfinity : kInfinity));
            break;
        }
    }
    q.count = in.u8() % (kMaxCount + 2);
    const uint8_t limit = in.u8() % 8;
    const double d = squared_distance(point(in), q.p);
    switch (limit) {
        case 2: q.limit = 0; break;
        case 3: q.limit = d; break;  // that point is left out (the limit is exclusive), equally near ones too
        case 4: q.limit = std::nextafter(d, kInfinity); break;
        case 5: q.limit = d > 0 ? std::nextafter(d, 0.0) : 0.0; break;
        case 6: {
            const double x = std::fabs(raw_double(in));
            q.limit = std::isnan(x) ? kInfinity : x;
            break;
        }
        case 7: {  // as pick_search_limit bounds a pick: twice an edge's length
            const Vec3 a = point(in);
            q.limit = 4 * squared_distance(a, point(in));
            break;
        }
        default: q.limit = kInfinity; break;
    }
    const uint8_t use = in.u8();
    q.mask = use == 0 ? ~uint64_t(0) : use == 1 ? 0 : in.u64();
    q.modulus = 1 + in.u8() % 64;
    return q;
}

// One search's answer, in the input's vertex ids.
struct Answer {
    uint32_t count = 0;
    uint32_t vertex[kMaxCount];
};

struct Case {
    const std::vector<Vec3>& points;
    const std::vector<uint32_t>* insertion_order;
    const Query& query;
    const std::vector<uint32_t>& ranked;  // usable vertices below the limit, nearest first (ties in id order)
    const std::vector<double>& distance;  // of every vertex to the query
};

void print_answer(const char* who, const Answer& a, const Case& c) {
    std::fprintf(stderr, "%s: %u:", who, a.count);
    for (uint32_t i = 0; i < a.count && i < kMaxCount; ++i) {
        const uint32_t v = a.vertex[i];
        if (v < c.points.size())
            std::fprintf(stderr, " %u (%a)", v, c.distance[v]);
        else
            std::fprintf(stderr, " %u (no such vertex)", v);
    }
    std::fprintf(stderr, "\n");
}

// A mismatch: the case, what each search answered, then abort (libFuzzer saves the input).
[[noreturn]] void mismatch(const char* what, const Case& c, const Answer& got, const Answer* kd_tree, int line) {
    const Query& q = c.query;
    std::fprintf(stderr, "points: %zu, insertion order %s\n", c.points.size(), c.insertion_order ? "given" : "none");
    std::fprintf(stderr, "query: p %a %a %a, count %u, limit %a, usable mask %016llx modulus %u\n", q.p.x, q.p.y, q.p.z,
                 q.count, q.limit, static_cast<unsigned long long>(q.mask), q.modulus);
    std::fprintf(stderr, "brute force, nearest usable below the limit (of %zu):\n", c.ranked.size());
    for (size_t i = 0; i < c.ranked.size() && i < kMaxCount + 2; ++i) {
        const uint32_t v = c.ranked[i];
        const Vec3 p = c.points[v];
        std::fprintf(stderr, "  %u at %a %a %a: %a\n", v, p.x, p.y, p.z, c.distance[v]);
    }
    print_answer("answer", got, c);
    if (kd_tree) print_answer("k-d tree", *kd_tree, c);
    violated(what, __FILE__, line);
}

#define NV_CHECK(condition, what, c, got, kd) \
    do {                                      \
        if (!(condition)) mismatch(what, c, got, kd, __LINE__); \
    } while (0)

bool same(const Answer& a, const Answer& b) {
    return a.count == b.count && std::equal(a.vertex, a.vertex + a.count, b.vertex);
}

// Oracle (a) on an answer, and (b) where the brute force decides it alone.
void check_against_brute_force(const Answer& got, const Case& c) {
    const uint32_t wanted = std::min(c.query.count, kMaxCount);
    const uint32_t k = std::min<uint32_t>(wanted, uint32_t(c.ranked.size()));
    NV_CHECK(got.count == k, "as many vertices as are usable below the limit, up to count", c, got, nullptr);
    for (uint32_t i = 0; i < k; ++i) {
        const uint32_t v = got.vertex[i];
        NV_CHECK(v < c.points.size(), "a vertex of the set", c, got, nullptr);
        NV_CHECK(c.query.usable(v), "a usable vertex", c, got, nullptr);
        NV_CHECK(std::find(got.vertex, got.vertex + i, v) == got.vertex + i, "distinct vertices", c, got, nullptr);
        NV_CHECK(c.distance[v] == c.distance[c.ranked[i]], "the brute-force distances, nearest first", c, got, nullptr);
    }
}

// Whether two usable vertices below the limit lie at one distance within the answer, or one as
// near as its last (nearest_vertex.h, Nearest::tied): then the k-d tree answers.
bool tied(const Case& c) {
    const size_t ranks = std::min<size_t>(std::min(c.query.count, kMaxCount) + 1, c.ranked.size());  // the answer and the next
    for (size_t i = 1; i < ranks; ++i)
        if (c.distance[c.ranked[i]] == c.distance[c.ranked[i - 1]]) return true;
    return false;
}

}  // namespace

void nearest_vertex(const uint8_t* data, size_t size) {
    ByteReader in(data, size);
    const uint8_t flags = in.u8();
    std::vector<Vec3> points = read_points(in);
    const uint32_t n = uint32_t(points.size());
    if (flags & 2) {  // the whole set scaled by 2^e: tiny (subnormal distances) or huge (overflowing ones)
        const int e = exponent(in);
        for (Vec3& p : points) p = finite(Vec3{std::ldexp(p.x, e), std::ldexp(p.y, e), std::ldexp(p.z, e)});
    }
    // The k-d tree's order: none (0, 1, ...), shuffled, or reversed.
    std::vector<uint32_t> order(n);
    std::iota(order.begin(), order.end(), 0u);
    if (flags & 1) order = shuffled(n, in.u32());
    if (flags & 4) std::reverse(order.begin(), order.end());
    const bool with_order = flags & 5;
    const std::vector<uint32_t>* insertion_order = with_order ? &order : nullptr;

    const NearestVertex nearest(points, insertion_order);
    const NearestVertex::KdTree kd_tree(points, insertion_order);
    // In Morton order with the codes, as the importer builds it: spatial id s is input id input_of[s].
    std::vector<uint32_t> codes;
    const std::vector<uint32_t> input_of = detail::spatial_vertex_order(points, &codes);
    const std::vector<uint32_t> spatial_of = inverse(input_of);
    std::vector<Vec3> spatial_points(n);
    std::vector<uint32_t> spatial_order(n);
    for (uint32_t s = 0; s < n; ++s) spatial_points[s] = points[input_of[s]];
    for (uint32_t i = 0; i < n; ++i) spatial_order[i] = spatial_of[order[i]];
    const NearestVertex spatial(spatial_points, &spatial_order, &codes);
    // That one renamed, and a build over the points so renumbered in the same k-d order: input id v
    // is renamed renamed_of[v].
    const std::vector<uint32_t> renamed_of = shuffled(n, in.u32());
    const std::vector<uint32_t> input_of_renamed = inverse(renamed_of);
    std::vector<uint32_t> renamed_of_spatial(n), renamed_order(n);
    std::vector<Vec3> renamed_points(n);
    for (uint32_t s = 0; s < n; ++s) renamed_of_spatial[s] = renamed_of[input_of[s]];
    for (uint32_t v = 0; v < n; ++v) renamed_points[renamed_of[v]] = points[v];
    for (uint32_t i = 0; i < n; ++i) renamed_order[i] = renamed_of[order[i]];
    const NearestVertex renamed(spatial, renamed_of_spatial);
    const NearestVertex renumbered(renamed_points, &renamed_order);

    const int queries = 1 + in.u8() % kMaxQueries;
    std::vector<double> distance(n);
    std::vector<uint32_t> ranked;
    for (int qi = 0; qi < queries && (qi == 0 || in.remaining() > 0); ++qi) {
        const Query q = read_query(in, points);
        ranked.clear();
        for (uint32_t v = 0; v < n; ++v) {
            distance[v] = squared_distance(points[v], q.p);
            if (distance[v] < q.limit && q.usable(v)) ranked.push_back(v);
        }
        std::stable_sort(ranked.begin(), ranked.end(), [&](uint32_t a, uint32_t b) { return distance[a] < distance[b]; });
        const Case c{points, insertion_order, q, ranked, distance};

        // Each search in its own ids, mapped back; `usable` asked only about vertices of the set below the limit.
        auto search = [&](const auto& tree, const std::vector<uint32_t>* input_id) {
            Answer a;
            auto usable = [&](uint32_t id) {
                FUZZ_CHECK(id < n);
                const uint32_t v = input_id ? (*input_id)[id] : id;
                FUZZ_CHECK(distance[v] < q.limit);
                return q.usable(v);
            };
            a.count = tree.find_nearest(q.p, usable, q.count, a.vertex, q.limit);
            FUZZ_CHECK(a.count <= kMaxCount);
            for (uint32_t i = 0; i < a.count; ++i) {
                FUZZ_CHECK(a.vertex[i] < n);
                if (input_id) a.vertex[i] = (*input_id)[a.vertex[i]];
            }
            return a;
        };
        const Answer expected = search(kd_tree, nullptr);
        check_against_brute_force(expected, c);
        if (!tied(c)) {  // the nearest are unique: the brute force's
            for (uint32_t i = 0; i < expected.count; ++i)
                NV_CHECK(expected.vertex[i] == ranked[i], "untied: the brute-force vertices", c, expected, nullptr);
        }
        const Answer got = search(nearest, nullptr);
        check_against_brute_force(got, c);
        NV_CHECK(same(got, expected), "the k-d tree's vertices", c, got, &expected);
        const Answer in_spatial = search(spatial, &input_of);
        NV_CHECK(same(in_spatial, expected), "in Morton order with its codes: the same vertices", c, in_spatial, &expected);
        const Answer in_renamed = search(renamed, &input_of_renamed);
        NV_CHECK(same(in_renamed, expected), "renamed: the same vertices", c, in_renamed, &expected);
        const Answer in_renumbered = search(renumbered, &input_of_renamed);
        NV_CHECK(same(in_renumbered, expected), "renumbered: the same vertices", c, in_renumbered, &expected);

        // find is find_nearest of one, unbounded.
        uint32_t first = kNoIndex;
        const uint32_t found = nearest.find_nearest(q.p, [&](uint32_t v) { return q.usable(v); }, 1, &first);
        FUZZ_CHECK(nearest.find(q.p, [&](uint32_t v) { return q.usable(v); }) == (found == 1 ? first : kNoIndex));
    }
}


namespace {

// A seed's bytes, in the order nearest_vertex reads them.
struct SeedWriter {
    std::vector<uint8_t> bytes;
    void u8(uint32_t x) { bytes.push_back(uint8_t(x)); }
    void u16(uint32_t x) { u8(x), u8(x >> 8); }
    void u32(uint32_t x) { u16(x), u16(x >> 16); }
    void u64(uint64_t x) { u32(uint32_t(x)), u32(uint32_t(x >> 32)); }
    void real(double x) {
        uint64_t bits;
        std::memcpy(&bits, &x, sizeof bits);
        u64(bits);
    }
    void lattice(int e, uint32_t step, uint32_t origin, uint32_t nx, uint32_t ny, uint32_t nz) {
        u8(1), u16(uint32_t(e)), u8(step), u16(origin), u8(nx - 1), u8(ny - 1), u8(nz - 1);
    }
    void copies(uint32_t of, uint32_t m) { u8(2), u16(of), u8(m - 1); }
    void cluster(uint32_t around, int e, uint32_t m, uint32_t seed) { u8(3), u16(around), u16(uint32_t(e)), u8(m - 1), u32(seed); }
    void outlier(uint32_t of, uint8_t axes, uint8_t kind) { u8(4), u16(of), u8(axes), u8(kind); }
    void box(uint32_t m, uint32_t radius, int e, bool graded, uint32_t seed) {
        u8(5), u16(m - 1), u8(radius - 1), u16(uint32_t(e)), u8(graded), u32(seed);
    }
    // `queries` of every kind in turn, counts 0 .. kMaxCount + 1, every kind of limit and of mask;
    // nudges off a point of up to 127 2^(nudge - k), k < 8. Single: midpoints and nudges only, of
    // count 1 (whose search starts in the query's cell).
    void queries(uint32_t queries, uint32_t points, uint32_t seed, int nudge = 0, bool single = false) {
        u8(queries - 1);
        Random random{seed};
        auto point = [&] { u16(uint32_t(random.next() % points)); };
        for (uint32_t i = 0; i < queries; ++i) {
            const uint32_t kind = single ? 1 + i % 2 : i % 6;
            u8(kind);
            switch (kind) {
                case 0: point(); break;
                case 1: point(), point(); break;
                case 2: point(), u16(uint32_t(nudge - int(random.next() % 8))), u8(random.next()), u8(random.next()), u8(random.next()); break;
                case 3: real(double(random.next() % 64) - 8), real(double(random.next() % 64) - 8), real(0.5); break;
                case 4: point(), u8(random.next()), u8(random.next()), u16(uint32_t(random.next() % 40)); break;
                default: point(), u8(random.next()), u8(random.next()); break;
            }
            u8(single ? 1 : i % (kMaxCount + 2));
            const uint32_t limit = i / 2 % 8;
            u8(limit);
            point();
            if (limit == 6) real(double(random.next() % 100));
            if (limit == 7) point(), point();
            const uint32_t use = i % 7 == 0 ? 0 : i % 11 == 5 ? 1 : 2;
            u8(use);
            if (use > 1) u64(uint64_t(random.next()) << 32 | random.next());
            u8(random.next());
        }
    }
};

}  // namespace

std::vector<std::vector<uint8_t>> nearest_vertex_seeds() {
    std::vector<std::vector<uint8_t>> seeds;
    {  // a 16 x 16 x 4 lattice in a shuffled order: ties at points, between them, around them
        SeedWriter s;
        s.u8(1), s.u8(0), s.lattice(0, 0, 0, 16, 16, 4), s.u32(17), s.u32(5), s.queries(32, 1024, 1);
        seeds.push_back(s.bytes);
    }
    {  // 256 copies of a lattice point and 256 of another: many vertices at one position
        SeedWriter s;
        s.u8(0), s.u8(2), s.lattice(-2, 1, 0, 8, 8, 8), s.copies(100, 256), s.copies(300, 256), s.u32(6);
        s.queries(32, 1024, 2);
        seeds.push_back(s.bytes);
    }
    {  // a cluster of 2^-30 beside an outlier at 1e300: every point of the cluster in one Morton cell
        SeedWriter s;
        s.u8(4), s.u8(1), s.box(400, 3, -30, false, 3), s.outlier(0, 0x09, 0), s.u32(7), s.queries(32, 400, 3);
        seeds.push_back(s.bytes);
    }
    {  // a lattice and a cluster scaled by 2^-1000: squared distances underflow to 0 (all tie) or are subnormal
        SeedWriter s;
        s.u8(3), s.u8(1), s.lattice(0, 2, 0, 10, 10, 10), s.cluster(5, -3, 64, 4), s.u16(uint32_t(-1000)), s.u32(9), s.u32(8);
        s.queries(32, 1064, 4);
        seeds.push_back(s.bytes);
    }
    {  // a box of steps of 2^-540: squared distances subnormal, many of them equal
        SeedWriter s;
        s.u8(2), s.u8(0), s.box(500, 4, 0, false, 8), s.u16(uint32_t(-540)), s.u32(13), s.queries(32, 500, 8);
        seeds.push_back(s.bytes);
    }
    {  // a box at 2^1000 and points at DBL_MAX: squared distances overflow to infinity
        SeedWriter s;
        s.u8(0), s.u8(1), s.box(300, 5, 1000, false, 5), s.outlier(7, 0x3f, 1), s.u32(10), s.queries(32, 301, 5);
        seeds.push_back(s.bytes);
    }
    {  // a graded random box of 2048 points, as an adaptive mesh crowds its vertices, reversed
        SeedWriter s;
        s.u8(4), s.u8(0), s.box(2048, 255, -8, true, 6), s.u32(11), s.queries(32, 2048, 6);
        seeds.push_back(s.bytes);
    }
    {  // cells of unit size (points at 0 and 1024), a lattice on the sides of the 32^3 cells that a
       // query searches first, clusters across them: nearest vertices just across a side
        SeedWriter s;
        s.u8(0), s.u8(12), s.u8(0), s.u8(1), s.real(0), s.real(0), s.real(0), s.real(1024), s.real(1024), s.real(1024);
        s.lattice(5, 0, 0, 8, 8, 8);
        for (uint32_t k = 0; k < 11; ++k) s.cluster(2 + k * 47, -20, 64, 20 + k);
        s.u32(14), s.queries(32, 1218, 9, -22, true);
        seeds.push_back(s.bytes);
    }
    {  // unit cells again, and pairs of vertices equally near a query of count 1, one in its 32^3
       // cell and one just across its side, both nearer than 1.1 times the gap to that side: the
       // cell's answer must not stand (a tie is the k-d tree's)
        SeedWriter s;
        s.u8(0), s.u8(3), s.u8(0), s.u8(1), s.real(0), s.real(0), s.real(0), s.real(1024), s.real(1024), s.real(1024);
        for (int group = 0; group < 3; ++group) {
            s.u8(0), s.u8(7);
            for (int pair = 0; pair < 4; ++pair) {
                const double side = 32.0 * (1 + 4 * group + pair), across = 16.0 + 32 * (group + pair);
                s.real(side - 0.125), s.real(across), s.real(across);  // 4.125 below the query, outside
                s.real(side + 8.125), s.real(across), s.real(across);  // 4.125 above it, inside
            }
        }
        s.u32(15), s.u8(11);
        for (int group = 0; group < 3; ++group) {
            for (int pair = 0; pair < 4; ++pair) {
                const double side = 32.0 * (1 + 4 * group + pair), across = 16.0 + 32 * (group + pair);
                s.u8(3), s.real(side + 4), s.real(across), s.real(across), s.u8(1), s.u8(0), s.u16(0), s.u8(0), s.u8(0);
            }
        }
        seeds.push_back(s.bytes);
    }
    {  // one point
        SeedWriter s;
        s.u8(0), s.u8(0), s.u8(0), s.u8(0), s.real(0.25), s.real(-1), s.real(3), s.u32(12), s.queries(12, 1, 7);
        seeds.push_back(s.bytes);
    }
    return seeds;
}

}  // namespace amc::fuzz
