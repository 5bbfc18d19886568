// Procedural base meshes: no input files needed for the embedded default and the tests.
#include <amc/refinement.h>

#include "common/check.h"

#include <cmath>
#include <map>
#include <random>
#include <utility>

namespace amc {

namespace {

constexpr double kPi = 3.14159265358979323846;

Vec3 normalized(Vec3 p) {
    double length = std::sqrt(dot(p, p));
    return (1.0 / length) * p;
}

// Rounds every coordinate to float so meshes behave like ones read from float32 files.
void make_single_precision(TriangleMesh& mesh) {
    for (Vec3& p : mesh.positions) p = {double(float(p.x)), double(float(p.y)), double(float(p.z))};
    mesh.single_precision = true;
}

TriangleMesh icosphere(int subdivisions) {
    TriangleMesh mesh = make_icosahedron();
    for (int s = 0; s < subdivisions; ++s) {
        std::map<std::pair<uint32_t, uint32_t>, uint32_t> midpoints;
        auto midpoint = [&](uint32_t a, uint32_t b) {
            auto key = std::minmax(a, b);
            auto it = midpoints.find(key);
            if (it != midpoints.end()) return it->second;
            uint32_t id = uint32_t(mesh.positions.size());
            mesh.positions.push_back(normalized(0.5 * (mesh.positions[a] + mesh.positions[b])));
            midpoints.emplace(key, id);
            return id;
        };
        std::vector<Triangle> finer;
        finer.reserve(mesh.triangles.size() * 4);
        for (const Triangle& t : mesh.triangles) {
            // The six points of a red split (red_split.h): corners, then edge midpoints.
            const uint32_t points[6] = {t[0], t[1], t[2], midpoint(t[0], t[1]), midpoint(t[1], t[2]), midpoint(t[2], t[0])};
            for (const auto& child : red_split::kChildPoints) finer.push_back({points[child[0]], points[child[1]], points[child[2]]});
        }
        mesh.triangles = std::move(finer);
    }
    return mesh;
}

}  // namespace

TriangleMesh make_icosahedron() {
    const double t = (1.0 + std::sqrt(5.0)) / 2.0;
    TriangleMesh mesh;
    const Vec3 corners[12] = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                              {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
    for (const Vec3& c : corners) mesh.positions.push_back(normalized(c));
    mesh.triangles = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                      {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                      {3, 8, 9},  {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
    return mesh;
}

TriangleMesh make_torus(int rings, int segments, double major_radius, double minor_radius) {
    TriangleMesh mesh;
    for (int i = 0; i < rings; ++i) {
        const double u = 2 * kPi * i / rings;
        for (int j = 0; j < segments; ++j) {
            const double v = 2 * kPi * j / segments;
            const double r = major_radius + minor_radius * std::cos(v);
            mesh.positions.push_back({r * std::cos(u), r * std::sin(u), minor_radius * std::sin(v)});
        }
    }
    auto id = [&](int i, int j) { return uint32_t((i % rings) * segments + (j % segments)); };
    for (int i = 0; i < rings; ++i) {
        for (int j = 0; j < segments; ++j) {
            mesh.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
            mesh.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
        }
    }
    return mesh;
}

namespace {

// A vertex's offset from its grid point along one axis: up to 0.3 of a cell either way.
double cell_jitter(std::mt19937& rng) { return (double(rng() >> 8) * 0x1p-24 - 0.5) * 0.6; }

// Cuts each cell (i, j) of a rows x columns grid, corners id(i, j) .. id(i + 1, j + 1), along the
// diagonal one draw of `rng` picks, cell after cell in row order.
template <class Id>
void cut_cells_at_random(TriangleMesh& mesh, int rows, int columns, std::mt19937& rng, Id id) {
    mesh.triangles.reserve(mesh.triangles.size() + 2 * size_t(rows) * size_t(columns));
    for (int i = 0; i < rows; ++i) {
        for (int j = 0; j < columns; ++j) {
            const uint32_t a = id(i, j), b = id(i + 1, j), c = id(i + 1, j + 1), d = id(i, j + 1);
            if (rng() & 1) {
                mesh.triangles.push_back({a, b, c});
                mesh.triangles.push_back({a, c, d});
            } else {
                mesh.triangles.push_back({a, b, d});
                mesh.triangles.push_back({b, c, d});
            }
        }
    }
}

}  // namespace

TriangleMesh make_irregular_torus(int rings, int segments, uint32_t seed) {
    AMC_REQUIRE(rings >= 3 && segments >= 3, invalid_input, "irregular torus: at least 3 rings and 3 segments");
    std::mt19937 rng(seed);  // its raw bits only: the same mesh from every standard library
    TriangleMesh mesh;
    mesh.positions.reserve(size_t(rings) * segments);
    for (int i = 0; i < rings; ++i) {
        for (int j = 0; j < segments; ++j) {
            const double u = (i + cell_jitter(rng)) * 2 * kPi / rings, v = (j + cell_jitter(rng)) * 2 * kPi / segments;
            const double r = 3.0 + std::cos(v);
            mesh.positions.push_back({r * std::cos(u), r * std::sin(u), std::sin(v)});
        }
    }
    cut_cells_at_random(mesh, rings, segments, rng,
                        [&](int i, int j) { return uint32_t((i % rings) * segments + (j % segments)); });
    make_single_precision(mesh);
    return mesh;
}

TriangleMesh make_irregular_strip(int length, int width, uint32_t seed) {
    AMC_REQUIRE(length >= 1 && width >= 1, invalid_input, "irregular strip: at least one cell each way");
    std::mt19937 rng(seed);
    TriangleMesh mesh;
    for (int i = 0; i <= length; ++i) {
        for (int j = 0; j <= width; ++j) {
            const double x = i + cell_jitter(rng), y = j + cell_jitter(rng);
            mesh.positions.push_back({x, y, 0.1 * std::sin(0.7 * x) * std::cos(1.3 * y)});
        }
    }
    cut_cells_at_random(mesh, length, width, rng, [&](int i, int j) { return uint32_t(i * (width + 1) + j); });
    make_single_precision(mesh);
    return mesh;
}

namespace {

// A grid of cells over [x0, x0+w] x [y0, y0+h]; cells flagged by `keep` are triangulated with
// alternating diagonals (a "criss-cross"-free, FE-style pattern).
TriangleMesh planar_grid(int nx, int ny, double x0, double y0, double cell,
                         bool (*keep)(double cx, double cy)) {
    TriangleMesh mesh;
    std::vector<int64_t> index((nx + 1) * (ny + 1), -1);
    auto vertex = [&](int i, int j) {
        int64_t& slot = index[j * (nx + 1) + i];
        if (slot < 0) {
            slot = int64_t(mesh.positions.size());
            mesh.positions.push_back({x0 + i * cell, y0 + j * cell, 0.0});
        }
        return uint32_t(slot);
    };
    for (int j = 0; j < ny; ++j) {
        for (int i = 0; i < nx; ++i) {
            if (keep != nullptr && !keep(x0 + (i + 0.5) * cell, y0 + (j + 0.5) * cell)) continue;
            uint32_t a = vertex(i, j), b = vertex(i + 1, j), c = vertex(i + 1, j + 1), d = vertex(i, j + 1);
            if ((i + j) % 2 == 0) {
                mesh.triangles.push_back({a, b, c});
                mesh.triangles.push_back({a, c, d});
            } else {
                mesh.triangles.push_back({a, b, d});
                mesh.triangles.push_back({b, c, d});
            }
        }
    }
    return mesh;
}

}  // namespace

TriangleMesh make_square(int cells) {
    return planar_grid(cells, cells, 0.0, 0.0, 1.0 / cells, nullptr);
}

TriangleMesh make_l_shape(int cells_per_unit) {
    return planar_grid(2 * cells_per_unit, 2 * cells_per_unit, -1.0, -1.0, 1.0 / cells_per_unit,
                       [](double cx, double cy) { return !(cx > 0 && cy < 0); });
}

TriangleMesh make_bumpy_sphere(int subdivisions) {
    TriangleMesh mesh = icosphere(subdivisions);
    for (Vec3& p : mesh.positions) {
        // Smooth bumps of several frequencies, and one sharp ridge, so curvature varies a lot.
        const double theta = std::acos(std::max(-1.0, std::min(1.0, p.z)));
        const double phi = std::atan2(p.y, p.x);
        double r = 1.0 + 0.12 * std::sin(5 * theta) * std::cos(4 * phi) + 0.05 * std::cos(9 * theta) +
                   0.03 * std::sin(13 * phi) * std::sin(theta);
        r += 0.08 * std::exp(-40.0 * (p.x - 0.5) * (p.x - 0.5) - 40.0 * p.y * p.y);
        p = r * p;
    }
    make_single_precision(mesh);
    return mesh;
}

}  // namespace amc
