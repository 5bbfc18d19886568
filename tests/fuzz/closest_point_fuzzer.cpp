// Fuzz target of ClosestPointQuery (src/geometry/closest_point.h): the input builds a triangle mesh
// of at most a few hundred triangles that holds what the tree's special cases need (fans of 32 to
// 200 long thin triangles around one apex, zero-area and repeated triangles, shared and unshared
// vertices, a lattice scaled by 2^k for k in -1000..1000, a far component up to 2^997, the whole
// mesh translated by up to 2^40, about 10^12) and asks it a few queries (points on, near and far
// from triangles, vertices, edges and apexes; bounds of 0, infinity and exact ties; facing
// directions with min_cosine in [-1, 1]; lines with reach and tolerance 0 or 1e-9). Every answer
// must equal a brute-force loop over all triangles in index order, bit for bit: the header's
// promise ("the triangle of least distance, ties broken by the lowest triangle index").
//
// Non-finite input: the constructor keeps fans with a non-finite corner in the box tree on purpose,
// so meshes with infinite or NaN corners are held to the brute-force answer, as are non-finite
// directions, bounds and min_cosine. A query point (line origin) with an infinite or NaN coordinate
// is not: its distance to a box that reaches float infinity on that axis is NaN (infinity minus
// infinity), which prunes the box, and nothing asks for points at infinity; such a query must only
// return (closest(p) may throw Error instead, as it does for a NaN coordinate). A line's answer
// on a triangle it grazes (kGrazing) is not compared either: an open finding.
#include "fuzz_targets.h"

#include "geometry/closest_point.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <optional>
#include <string>

namespace amc::fuzz {
namespace {

constexpr uint32_t kNoTriangle = std::numeric_limits<uint32_t>::max();
constexpr double kInfinity = std::numeric_limits<double>::infinity();
constexpr int kMaxQueries = 16;
constexpr int kMaxFans = 2;
constexpr uint32_t kMinFan = ClosestPointQuery::kFanValence;  // 32..200 triangles a fan
constexpr uint32_t kMaxFanExtra = 169;

double squared_length(Vec3 v) { return dot(v, v); }

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }
bool same_bits(Vec3 a, Vec3 b) { return same_bits(a.x, b.x) && same_bits(a.y, b.y) && same_bits(a.z, b.z); }

double raw_double(ByteReader& in) {
    const uint64_t bits = in.u64();
    double x;
    std::memcpy(&x, &bits, sizeof x);
    return x;
}

int8_t small_integer(ByteReader& in) { return int8_t(in.u8()); }

uint32_t u16(ByteReader& in) {
    const uint32_t low = in.u8();
    return low | uint32_t(in.u8()) << 8;
}

Vec3 lattice_vector(ByteReader& in, double scale) {
    const double x = small_integer(in), y = small_integer(in), z = small_integer(in);
    return {x * scale, y * scale, z * scale};
}

// The oracle's unit normal: as ClosestPointQuery::add_record computes it (the cross product of the
// edges from corner 0, normalised; zero for a zero-area or overflowing triangle).
Vec3 unit_normal(Vec3 a, Vec3 b, Vec3 c) {
    const Vec3 normal = cross(b - a, c - a);
    const double length = std::sqrt(squared_length(normal));
    return length > 0 && std::isfinite(length) ? (1 / length) * normal : Vec3{};
}

struct Case {
    TriangleMesh mesh;
    std::vector<uint32_t> apexes;
    double scale = 1;
};

void print_mesh(const TriangleMesh& mesh) {
    std::fprintf(stderr, "mesh: %zu positions, %zu triangles\n", mesh.positions.size(), mesh.triangles.size());
    for (size_t i = 0; i < mesh.positions.size(); ++i) {
        const Vec3 p = mesh.positions[i];
        std::fprintf(stderr, "  v %zu %a %a %a\n", i, p.x, p.y, p.z);
    }
    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
        const Triangle& tr = mesh.triangles[t];
        std::fprintf(stderr, "  f %zu %u %u %u\n", t, tr[0], tr[1], tr[2]);
    }
}

void print_hit(const char* who, const std::optional<ClosestPointQuery::Hit>& hit) {
    if (!hit) {
        std::fprintf(stderr, "%s: none\n", who);
        return;
    }
    std::fprintf(stderr, "%s: triangle %u point %a %a %a distance_squared %a barycentric %a %a %a\n", who, hit->triangle,
                 hit->point.x, hit->point.y, hit->point.z, hit->distance_squared, hit->barycentric.x, hit->barycentric.y,
                 hit->barycentric.z);
}

// A mismatch: the whole case, then abort (libFuzzer saves the input).
[[noreturn]] void mismatch(const Case& c, const std::string& query, const std::optional<ClosestPointQuery::Hit>& expected,
                           const std::optional<ClosestPointQuery::Hit>& got) {
    print_mesh(c.mesh);
    std::fprintf(stderr, "query: %s\n", query.c_str());
    print_hit("brute force", expected);
    print_hit("ClosestPointQuery", got);
    violated("ClosestPointQuery's answer equals the brute-force loop's", __FILE__, __LINE__);
}

bool same_hit(const std::optional<ClosestPointQuery::Hit>& a, const std::optional<ClosestPointQuery::Hit>& b) {
    if (a.has_value() != b.has_value()) return false;
    if (!a) return true;
    return a->triangle == b->triangle && same_bits(a->point, b->point) && same_bits(a->distance_squared, b->distance_squared) &&
           same_bits(a->barycentric, b->barycentric);
}

std::string describe(const char* what, Vec3 p) {
    char text[160];
    std::snprintf(text, sizeof text, "%s %a %a %a", what, p.x, p.y, p.z);
    return text;
}
std::string describe(const char* what, double x) {
    char text[80];
    std::snprintf(text, sizeof text, " %s %a", what, x);
    return text;
}

// The oracles: loops over every triangle in index order.

// closest(p, max_distance) and closest_facing by the header: the triangle of least squared distance
// among those accepted within the bound (inclusive), ties to the lowest index; the search keeps
// the first of equal distances, the first at infinity too when unbounded (closest_point.cpp, search).
template <class Accept>
std::optional<ClosestPointQuery::Hit> brute_closest(const TriangleMesh& mesh, Vec3 p, double bound_squared, const Accept& accept) {
    double best = bound_squared;
    std::optional<ClosestPointQuery::Hit> hit;
    for (uint32_t t = 0; t < mesh.triangles.size(); ++t) {
        const Triangle& tr = mesh.triangles[t];
        const Vec3 a = mesh.positions[tr[0]], b = mesh.positions[tr[1]], c = mesh.positions[tr[2]];
        if (!accept(a, b, c)) continue;
        Vec3 barycentric;
        const Vec3 q = closest_point_on_triangle(p, a, b, c, barycentric);
        const double d = squared_length(p - q);
        if (d < best || (d == best && !hit)) {
            best = d;
            hit = ClosestPointQuery::Hit{q, t, d, barycentric};
        }
    }
    return hit;
}

std::optional<ClosestPointQuery::Hit> brute_closest(const TriangleMesh& mesh, Vec3 p, double max_distance) {
    if (!(max_distance >= 0)) return std::nullopt;
    return brute_closest(mesh, p, max_distance * max_distance, [](Vec3, Vec3, Vec3) { return true; });
}

// The header: facing means unit normal n with dot(n, direction) >= min_cosine * |direction|, and
// zero-area triangles face nowhere; the threshold as closest_facing computes it.
std::optional<ClosestPointQuery::Hit> brute_facing(const TriangleMesh& mesh, Vec3 p, Vec3 direction, double min_cosine,
                                                   double max_distance) {
    if (!(max_distance >= 0)) return std::nullopt;
    const double threshold = min_cosine * std::sqrt(squared_length(direction));
    return brute_closest(mesh, p, max_distance * max_distance, [&](Vec3 a, Vec3 b, Vec3 c) {
        const Vec3 n = unit_normal(a, b, c);
        return dot(n, n) > 0 && dot(n, direction) >= threshold;
    });
}

// The header's box a line's hit must lie in: the triangle's, widened by 16 ulps of its largest
// coordinate (closest_point.cpp's rounding margin) and by `widening` of its extent on each axis.
bool in_widened_box(Vec3 q, Vec3 a, Vec3 b, Vec3 c, double widening) {
    const double lo[3] = {std::min(std::min(a.x, b.x), c.x), std::min(std::min(a.y, b.y), c.y), std::min(std::min(a.z, b.z), c.z)};
    const double hi[3] = {std::max(std::max(a.x, b.x), c.x), std::max(std::max(a.y, b.y), c.y), std::max(std::max(a.z, b.z), c.z)};
    double max_abs = 0;
    for (int axis = 0; axis < 3; ++axis) max_abs = std::max({max_abs, std::fabs(lo[axis]), std::fabs(hi[axis])});
    const double margin = 16 * DBL_EPSILON * max_abs;
    const double x[3] = {q.x, q.y, q.z};
    for (int axis = 0; axis < 3; ++axis) {
        const double w = margin + (widening > 0 ? widening * (hi[axis] - lo[axis]) : 0.0);
        if (!(x[axis] >= lo[axis] - w && x[axis] <= hi[axis] + w)) return false;
    }
    return true;
}

// The header's intersect_line: among the triangles facing the direction (dot(n, d) > 0, d the unit
// direction), widened by `tolerance` of their barycentric range, the hit of least |t| (t in units of
// length along d, so |t| <= reach is the header's |t| * |direction| <= reach), ties to the lowest
// index, counted only inside the triangle's widened box. The hit and its t are computed as
// closest_point.cpp computes them (Moller-Trumbore, two-sided in t), and the point as the
// barycentric combination of the corners.
std::optional<ClosestPointQuery::Hit> brute_line(const TriangleMesh& mesh, Vec3 origin, Vec3 direction, double reach,
                                                 double tolerance, double* hit_t = nullptr) {
    const double direction_length = std::sqrt(squared_length(direction));
    if (!(direction_length > 0) || !(reach >= 0)) return std::nullopt;
    const Vec3 d = (1 / direction_length) * direction;
    double best = reach;
    uint32_t best_triangle = kNoTriangle;
    Vec3 best_barycentric;
    for (uint32_t t = 0; t < mesh.triangles.size(); ++t) {
        const Triangle& tr = mesh.triangles[t];
        const Vec3 a = mesh.positions[tr[0]], b = mesh.positions[tr[1]], c = mesh.positions[tr[2]];
        if (!(dot(unit_normal(a, b, c), d) > 0)) continue;
        const Vec3 e1 = b - a, e2 = c - a;
        const Vec3 pv = cross(d, e2);
        const double det = dot(e1, pv);
        if (!(std::fabs(det) > 0)) continue;
        const double inv = 1 / det;
        const Vec3 tv = origin - a;
        const double u = dot(tv, pv) * inv;
        if (u < -tolerance || u > 1 + tolerance) continue;
        const Vec3 qv = cross(tv, e1);
        const double v = dot(d, qv) * inv;
        if (v < -tolerance || u + v > 1 + tolerance) continue;
        const double line_t = dot(e2, qv) * inv;
        const double at = std::fabs(line_t);
        if ((at < best || (at == best && at < kInfinity && best_triangle == kNoTriangle)) &&
            in_widened_box(origin + line_t * d, a, b, c, 2 * tolerance)) {
            best = at;
            best_triangle = t;
            best_barycentric = {1 - u - v, u, v};
        }
    }
    if (best_triangle == kNoTriangle) return std::nullopt;
    if (hit_t) *hit_t = best;
    const Triangle& tr = mesh.triangles[best_triangle];
    const Vec3 point = best_barycentric.x * mesh.positions[tr[0]] + best_barycentric.y * mesh.positions[tr[1]] +
                       best_barycentric.z * mesh.positions[tr[2]];
    return ClosestPointQuery::Hit{point, best_triangle, squared_length(point - origin), best_barycentric};
}

// The mesh. Layout: u8 flags (bit 0 the fans' rims shared between neighbours, bit 1 a far
// component, bit 2 translated, bit 3 raw doubles among the vertices, bits 4-5 the fans), u16 the
// lattice's exponent, the translation (3 x i32 and u8 exponent), the shared vertices, triangles
// over them, triangles of their own vertices, the fans, the far component.
Case build_case(ByteReader& in) {
    Case c;
    const uint8_t flags = in.u8();
    const bool shared_rims = flags & 1, far = flags & 2, translated = flags & 4, raw = flags & 8;
    const int fans = std::min((flags >> 4) & 3, kMaxFans);
    const int exponent = int(u16(in) % 2001) - 1000;
    c.scale = std::ldexp(1.0, exponent);
    Vec3 translation{};
    if (translated) {
        const double x = int32_t(in.u32()), y = int32_t(in.u32()), z = int32_t(in.u32());
        const double unit = std::ldexp(1.0, int(in.u8() % 41) - 31);  // |x| <= 2^31: up to 2^40
        translation = {x * unit, y * unit, z * unit};
    }
    std::vector<Vec3>& positions = c.mesh.positions;
    std::vector<Triangle>& triangles = c.mesh.triangles;
    auto add_vertex = [&](Vec3 p) {
        positions.push_back(p);
        return uint32_t(positions.size() - 1);
    };
    auto lattice_vertex = [&]() {
        if (raw && in.u8() % 16 == 0) return add_vertex({raw_double(in), raw_double(in), raw_double(in)});
        return add_vertex(lattice_vector(in, c.scale) + translation);
    };

    const uint32_t shared = 3 + in.u8() % 62;
    for (uint32_t i = 0; i < shared; ++i) lattice_vertex();
    const uint32_t over_shared = in.u8() % 129;  // repeats and repeated corners make zero-area ones
    for (uint32_t i = 0; i < over_shared; ++i) triangles.push_back({in.u8() % shared, in.u8() % shared, in.u8() % shared});
    const uint32_t own = in.u8() % 17;
    for (uint32_t i = 0; i < own; ++i) {
        const uint32_t a = lattice_vertex(), b = lattice_vertex(), d = lattice_vertex();
        triangles.push_back({a, b, d});
    }
    // A fan: an apex and 32..200 triangles to rim points at lattice offsets times 2^length (long thin
    // triangles when the offsets are near each other), the apex at the corner `slot` turns to.
    for (int f = 0; f < fans; ++f) {
        const uint32_t count = kMinFan + in.u8() % kMaxFanExtra;
        const uint8_t shape = in.u8();
        const double length = c.scale * std::ldexp(1.0, shape % 16);
        const uint32_t apex = in.u8() % 4 == 0 ? in.u8() % shared : lattice_vertex();
        c.apexes.push_back(apex);
        const Vec3 centre = positions[apex];
        auto rim_vertex = [&]() { return add_vertex(centre + lattice_vector(in, length)); };
        const uint32_t first_rim = shared_rims ? rim_vertex() : 0;
        uint32_t previous = first_rim;
        for (uint32_t i = 0; i < count; ++i) {
            uint32_t b, d;
            if (shared_rims) {
                b = previous;
                d = i + 1 == count && shape & 0x80 ? first_rim : rim_vertex();  // closed or open
                previous = d;
            } else {
                b = rim_vertex();
                d = rim_vertex();
            }
            const uint32_t slot = (i * (shape >> 4 & 7)) % 3;
            Triangle t = slot == 0 ? Triangle{apex, b, d} : slot == 1 ? Triangle{d, apex, b} : Triangle{b, d, apex};
            triangles.push_back(t);
        }
    }
    if (far) {
        const double far_scale = std::ldexp(1.0, int(u16(in) % 998));  // up to 2^997, about 1.3e300
        const Vec3 offset = lattice_vector(in, far_scale);
        const uint32_t count = 1 + in.u8() % 8;
        const uint32_t first = uint32_t(positions.size());
        for (int i = 0; i < 4; ++i) add_vertex(offset + lattice_vector(in, far_scale / 128) + translation);
        for (uint32_t i = 0; i < count; ++i) triangles.push_back({first + in.u8() % 4, first + in.u8() % 4, first + in.u8() % 4});
    }
    if (triangles.empty()) triangles.push_back({0, 1, 2});
    return c;
}

Vec3 corner(const Case& c, uint32_t t, int k) { return c.mesh.positions[c.mesh.triangles[t][size_t(k)]]; }

// A query point: a vertex, a point on a triangle, an edge's midpoint, an apex moved a little, a
// lattice point, a point near a triangle, any double, or a point far away.
Vec3 query_point(const Case& c, ByteReader& in) {
    const uint32_t triangle_count = uint32_t(c.mesh.triangles.size());
    const uint8_t mode = in.u8();
    const uint32_t t = in.u8() % triangle_count;
    const Vec3 a = corner(c, t, 0), b = corner(c, t, 1), d = corner(c, t, 2);
    switch (mode % 8) {
        case 0: return c.mesh.positions[in.u8() % c.mesh.positions.size()];
        case 1:
        case 5: {
            const double s = small_integer(in) / 64.0, r = small_integer(in) / 64.0;
            const Vec3 on = a + s * (b - a) + r * (d - a);
            if (mode % 8 == 1) return on;
            return on + lattice_vector(in, c.scale * std::ldexp(1.0, -int(in.u8() % 64)));
        }
        case 2: return mode & 8 ? 0.5 * (a + b) : mode & 16 ? 0.5 * (b + d) : 0.5 * (d + a);
        case 3: {
            const Vec3 apex = c.apexes.empty() ? a : c.mesh.positions[c.apexes[in.u8() % c.apexes.size()]];
            return apex + lattice_vector(in, c.scale * std::ldexp(1.0, int(in.u8() % 32) - 16));
        }
        case 4: return a + lattice_vector(in, c.scale * 4);
        case 6: return {raw_double(in), raw_double(in), raw_double(in)};
        default: return lattice_vector(in, std::ldexp(1.0, int(u16(in) % 2100) - 1050));
    }
}

// A direction: lattice, a triangle's normal (as the query computes it) scaled, zero, or any.
Vec3 query_direction(const Case& c, ByteReader& in) {
    const uint8_t mode = in.u8();
    switch (mode % 4) {
        case 0: return lattice_vector(in, 1);
        case 1: {
            const uint32_t t = in.u8() % c.mesh.triangles.size();
            const Vec3 n = unit_normal(corner(c, t, 0), corner(c, t, 1), corner(c, t, 2));
            return std::ldexp(mode & 4 ? -1.0 : 1.0, int(in.u8() % 64) - 32) * n;
        }
        case 2: return mode & 4 ? Vec3{} : lattice_vector(in, c.scale);
        default: return {raw_double(in), raw_double(in), raw_double(in)};
    }
}

// A bound: 0, infinity, `exact` (the unbounded answer's, a tie) or a neighbour of it, a lattice
// length, negative, NaN or any double.
double query_bound(const Case& c, ByteReader& in, double exact) {
    const uint8_t mode = in.u8();
    switch (mode % 8) {
        case 0: return 0;
        case 1: return kInfinity;
        case 2:
        case 3: return exact;
        case 4: return std::nextafter(exact, mode & 8 ? kInfinity : 0.0);
        case 5: return in.u8() * c.scale;
        case 6: return mode & 8 ? -1.0 : std::numeric_limits<double>::quiet_NaN();
        default: return raw_double(in);
    }
}

double min_cosine(ByteReader& in) {
    const uint8_t x = in.u8();
    if (x == 255) return raw_double(in);
    return std::clamp((int(x) - 127) / 127.0, -1.0, 1.0);  // -1, 0 and 1 exactly among them
}

void check_closest(const Case& c, const ClosestPointQuery& query, Vec3 p) {
    const std::optional<ClosestPointQuery::Hit> expected = brute_closest(c.mesh, p, kInfinity);
    const std::string what = describe("closest", p);
    std::optional<ClosestPointQuery::Hit> got;
    try {
        got = query.closest(p);
    } catch (const Error&) {
        got.reset();  // no hit: the brute force must have none either
    }
    if (!same_hit(expected, got)) mismatch(c, what, expected, got);
    uint64_t tested = 0;
    try {
        got = query.closest(p, tested);
    } catch (const Error&) {
        got.reset();
    }
    if (!same_hit(expected, got)) mismatch(c, what + " (counting)", expected, got);
}

// Open (docs/FUZZING.md): a line within this cosine of a triangle's plane rounds Moller-Trumbore to
// an intersection anywhere near it, inside the triangle's box but maybe outside a fan's cone, which
// then prunes what the loop over all triangles accepts. Such an answer is not compared.
constexpr double kGrazing = 1e-6;

bool grazes(const Case& c, uint32_t t, Vec3 direction) {
    const double length = std::sqrt(squared_length(direction));
    const Vec3 n = unit_normal(corner(c, t, 0), corner(c, t, 1), corner(c, t, 2));
    return !(std::fabs(dot(n, (1 / length) * direction)) >= kGrazing);
}

bool finite(Vec3 p) { return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z); }

// A query from a point not finite: it returns, or closest(p) throws Error.
void run_unchecked(const ClosestPointQuery& query, Vec3 p, uint8_t kind, ByteReader& in) {
    try {
        query.closest(p);
    } catch (const Error&) {
    }
    const Vec3 direction{double(small_integer(in)), double(small_integer(in)), double(small_integer(in))};
    const double bound = raw_double(in);
    query.closest(p, bound);
    query.closest_facing(p, direction, min_cosine(in), bound);
    query.intersect_line(p, direction, bound, kind & 4 ? 1e-9 : 0.0);
}

void run_query(const Case& c, const ClosestPointQuery& query, ByteReader& in) {
    const uint8_t kind = in.u8();
    const Vec3 p = query_point(c, in);
    if (!finite(p)) {
        run_unchecked(query, p, kind, in);
        return;
    }
    switch (kind % 4) {
        case 0: check_closest(c, query, p); return;
        case 1: {
            const std::optional<ClosestPointQuery::Hit> unbounded = brute_closest(c.mesh, p, kInfinity);
            const double bound = query_bound(c, in, unbounded ? std::sqrt(unbounded->distance_squared) : 0.0);
            const std::optional<ClosestPointQuery::Hit> expected = brute_closest(c.mesh, p, bound);
            const std::optional<ClosestPointQuery::Hit> got = query.closest(p, bound);
            if (!same_hit(expected, got)) mismatch(c, describe("closest", p) + describe("max_distance", bound), expected, got);
            return;
        }
        case 2: {
            const Vec3 direction = query_direction(c, in);
            const double cosine = min_cosine(in);
            const std::optional<ClosestPointQuery::Hit> unbounded = brute_facing(c.mesh, p, direction, cosine, kInfinity);
            const double bound = query_bound(c, in, unbounded ? std::sqrt(unbounded->distance_squared) : 0.0);
            const std::optional<ClosestPointQuery::Hit> expected = brute_facing(c.mesh, p, direction, cosine, bound);
            const std::optional<ClosestPointQuery::Hit> got = query.closest_facing(p, direction, cosine, bound);
            if (!same_hit(expected, got))
                mismatch(c,
                         describe("closest_facing", p) + describe(" direction", direction) + describe("min_cosine", cosine) +
                             describe("max_distance", bound),
                         expected, got);
            return;
        }
        default: {
            const Vec3 direction = query_direction(c, in);
            const double tolerance = in.u8() & 1 ? 1e-9 : 0.0;
            double hit_t = 0;  // a reach of the unbounded hit's |t| ties it
            brute_line(c.mesh, p, direction, kInfinity, tolerance, &hit_t);
            const double reach = query_bound(c, in, hit_t);
            const std::optional<ClosestPointQuery::Hit> expected = brute_line(c.mesh, p, direction, reach, tolerance);
            const std::optional<ClosestPointQuery::Hit> got = query.intersect_line(p, direction, reach, tolerance);
            if (expected && grazes(c, expected->triangle, direction)) return;  // open: see kGrazing
            if (!same_hit(expected, got))
                mismatch(c,
                         describe("intersect_line", p) + describe(" direction", direction) + describe("reach", reach) +
                             describe("tolerance", tolerance),
                         expected, got);
            return;
        }
    }
}

}  // namespace

void closest_point(const uint8_t* data, size_t size) {
    ByteReader in(data, size);
    const Case c = build_case(in);
    const ClosestPointQuery query(c.mesh);  // every index is in range: it throws nothing here
    FUZZ_CHECK(query.triangle_count() == c.mesh.triangles.size());
    const int queries = 1 + in.u8() % kMaxQueries;
    for (int i = 0; i < queries; ++i) run_query(c, query, in);
}

namespace {

// A point of the square rim [-100, 100]^2 at `i` of `count` steps around it, at height z.
void rim_point(std::vector<uint8_t>& bytes, uint32_t i, uint32_t count, int z) {
    const int s = int(i * 800 / count), side = s / 200, along = s % 200 - 100;
    const int x = side == 0 ? along : side == 1 ? 100 : side == 2 ? -along : -100;
    const int y = side == 0 ? -100 : side == 1 ? along : side == 2 ? 100 : -along;
    for (int v : {x, y, z}) bytes.push_back(uint8_t(int8_t(v)));
}

// The seed's mesh: flags, the lattice exponent k, the translation's bytes, shared vertices on a
// small grid with triangles over them and two of their own, the fans (count, shape, a new apex at
// the origin, rim points around it), the far component's bytes; then random queries.
std::vector<uint8_t> seed(uint8_t flags, int exponent, const std::vector<uint8_t>& translation,
                          const std::vector<uint32_t>& fan_sizes, uint8_t fan_shape, const std::vector<uint8_t>& far,
                          uint64_t query_seed) {
    std::vector<uint8_t> bytes = {flags};
    const uint32_t k = uint32_t(exponent + 1000);
    bytes.push_back(uint8_t(k));
    bytes.push_back(uint8_t(k >> 8));
    bytes.insert(bytes.end(), translation.begin(), translation.end());
    bytes.push_back(16 - 3);  // 16 shared vertices: a 4 x 4 grid at height x y / 4
    for (int x = 0; x < 4; ++x)
        for (int y = 0; y < 4; ++y)
            for (int v : {4 * x, 4 * y, x * y}) {
                if (flags & 8) bytes.push_back(1);  // not raw
                bytes.push_back(uint8_t(int8_t(v)));
            }
    bytes.push_back(20);  // the grid's triangles, the last two repeated and degenerate
    for (uint8_t x = 0; x < 3; ++x)
        for (uint8_t y = 0; y < 3; ++y) {
            const uint8_t v = uint8_t(4 * x + y);
            for (uint8_t corner : {v, uint8_t(v + 4), uint8_t(v + 5), v, uint8_t(v + 5), uint8_t(v + 1)}) bytes.push_back(corner);
        }
    for (uint8_t corner : {0, 5, 10, 3, 3, 3}) bytes.push_back(corner);
    bytes.push_back(2);  // two triangles of their own vertices, one of them a segment
    for (int v : {1, 2, 3, 9, 7, 5, -3, 0, 8, 5, 5, 5, 7, 7, 7, 10, 10, 10}) {
        if (flags & 8) bytes.push_back(v == -3 ? 0 : 1);  // one raw vertex when raw
        if ((flags & 8) && v == -3) {
            for (int i = 0; i < 24; ++i) bytes.push_back(i < 16 ? 0 : i == 23 ? 0x7f : i == 22 ? 0xf0 : 0);  // 0, 0, +infinity
            continue;
        }
        bytes.push_back(uint8_t(int8_t(v)));
    }
    for (uint32_t count : fan_sizes) {
        bytes.push_back(uint8_t(count - ClosestPointQuery::kFanValence));
        bytes.push_back(fan_shape);
        bytes.push_back(1);  // a new apex
        if (flags & 8) bytes.push_back(1);
        for (int v : {0, 0, 2}) bytes.push_back(uint8_t(int8_t(v)));
        const uint32_t rims = flags & 1 ? count : 2 * count;
        for (uint32_t i = 0; i < rims; ++i) rim_point(bytes, i, rims, int(i % 3) - 1);
    }
    bytes.insert(bytes.end(), far.begin(), far.end());
    bytes.push_back(kMaxQueries - 1);
    Random random{query_seed};
    for (int i = 0; i < kMaxQueries * 40; ++i) bytes.push_back(uint8_t(random.next()));
    return bytes;
}

}  // namespace

std::vector<std::vector<uint8_t>> closest_point_seeds() {
    const std::vector<uint8_t> none;
    // 0x3ffffff0 x 2^9: about 5.5e11 a coordinate.
    const std::vector<uint8_t> translation = {0xf0, 0xff, 0xff, 0x3f, 0x10, 0x00, 0x00, 0xc0, 0x00, 0x00, 0x00, 0x20, 40};
    // The far component: 2^997 times (1, -1, 1), four corners 2^990 apart, four triangles.
    const std::vector<uint8_t> far = {0xe5, 0x03, 1, 0xff, 1, 3, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 2, 0, 2, 3, 1, 2, 3, 0, 0, 1};
    return {
        seed(0x91, 0, none, {100}, 0x96, none, 1),                // a closed fan of long thin triangles
        seed(0x10, 0, none, {200}, 0x06, none, 2),                // a fan of unshared rims
        seed(0x93, -3, none, {64}, 0x9a, far, 3),                 // a fan and a far component
        seed(0x95, -20, translation, {40}, 0x95, none, 4),        // a fan on a lattice translated by 10^12
        seed(0x07, -20, translation, {}, 0, far, 5),              // translated, far, no fan
        seed(0xa1, -1000, none, {50, 33}, 0x9c, none, 6),         // two fans at 2^-1000
        seed(0x29, 1000, none, {32, 32}, 0x8f, none, 7),          // two fans at 2^1000, an infinite vertex
        seed(0x00, 0, none, {}, 0, none, 8),                      // the grid alone
    };
}

}  // namespace amc::fuzz
