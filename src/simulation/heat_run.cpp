// The adaptive heat run: solve, estimate, adapt, carry the solution over (include/amc/simulation.h).
#include <amc/import.h>
#include <amc/refinement.h>
#include <amc/simulation.h>

#include "simulation/p1_heat.h"

#include "common/check.h"

#include <chrono>
#include <cstring>
#include <cmath>
#include <unordered_map>

namespace amc {

namespace {

constexpr double kPi = 3.14159265358979323846;

struct Source {
    HeatScenario scenario;
    double end_time;
    Vec3 centre(double t) const {
        const double s = t / end_time;
        if (scenario == HeatScenario::lshape) {
            const double angle = 1.5 * kPi * s;  // the three quadrants of the L, around its corner
            return {0.5 * std::cos(angle) - 0.0, 0.5 * std::sin(angle), 0.0};
        }
        const double angle = 2 * kPi * s;
        return {0.5 + 0.25 * std::cos(angle), 0.5 + 0.25 * std::sin(angle), 0.0};
    }
    double width() const { return scenario == HeatScenario::lshape ? 0.07 : 0.04; }
    std::vector<double> at(const std::vector<Vec3>& points, double t) const {
        const Vec3 c = centre(t);
        const double w = width();
        std::vector<double> f(points.size());
        for (size_t i = 0; i < points.size(); ++i) {
            const Vec3 d = points[i] - c;
            f[i] = 200.0 * std::exp(-dot(d, d) / (2 * w * w));
        }
        return f;
    }
};

struct PositionKey {
    uint64_t x, y;
    bool operator==(const PositionKey& o) const { return x == o.x && y == o.y; }
};
struct PositionHash {
    size_t operator()(const PositionKey& k) const { return size_t(k.x * 0x9E3779B97F4A7C15ull ^ (k.y + (k.x >> 17))); }
};
PositionKey key_of(Vec3 p) {
    PositionKey k;
    std::memcpy(&k.x, &p.x, 8);
    std::memcpy(&k.y, &p.y, 8);
    return k;
}

// u on the vertices of h (by vertex id) from u on an earlier mesh (by position): vertices that
// persist keep their value, new ones take the mean of their edge's end points (P1 interpolation:
// new vertices are edge midpoints, created coarse to fine).
std::vector<double> transfer(const Hierarchy& h, const std::unordered_map<PositionKey, double, PositionHash>& old) {
    std::vector<double> u(h.positions().size(), 0.0);
    auto value_of = [&](VertexId v, double fallback) {
        auto it = old.find(key_of(h.position(v)));
        return it == old.end() ? fallback : it->second;
    };
    for (NodeId n : h.breadth_first_order()) {
        if (n < h.root_count())
            for (int i = 0; i < 3; ++i) u[h.vertex(n, i)] = value_of(h.vertex(n, i), 0.0);
        if (h.is_leaf(n)) continue;
        for (int e = 0; e < 3; ++e) {
            const VertexId m = h.midpoint(n, e);
            u[m] = value_of(m, 0.5 * (u[h.vertex(n, e)] + u[h.vertex(n, (e + 1) % 3)]));
        }
    }
    return u;
}

}  // namespace

HeatRunStats run_heat_simulation(const HeatRunOptions& options,
                                 const std::function<void(const SimulationFrame&)>& on_frame) {
    const auto start = std::chrono::steady_clock::now();
    AMC_REQUIRE(options.frames >= 1 && options.end_time > 0 && options.max_level >= 1 &&
                    options.max_level <= kMaxLevel && options.target_elements >= 1,
                invalid_input, "heat run: frames, end time, max level or target out of range");
    const Source source{options.scenario, options.end_time};
    Hierarchy h(options.scenario == HeatScenario::lshape ? make_l_shape(1) : make_square(2));
    const double dt = options.end_time / options.frames;
    std::vector<double> u_by_id(h.positions().size(), 0.0);
    HeatRunStats stats;
    stats.min_elements = UINT32_MAX;

    const int rounds = options.initial_adaptations + options.frames;
    for (int round = 0; round < rounds; ++round) {
        const bool output = round >= options.initial_adaptations;
        const int frame = round - options.initial_adaptations;
        const double t = output ? (frame + 1) * dt : 0.0;
        const LeafMesh leaf = extract_leaf_mesh(h);
        const std::vector<uint32_t> canonical = canonical_vertex_order(h);
        std::vector<double> u_old(leaf.mesh.positions.size(), 0.0);
        if (output)
            for (size_t v = 0; v < canonical.size(); ++v)
                if (canonical[v] != kNoVertex) u_old[canonical[v]] = u_by_id[v];
        const HeatStepResult step = heat_step(leaf.mesh, u_old, source.at(leaf.mesh.positions, t), dt);
        stats.total_cg_iterations += step.cg_iterations;
        double total = 0;
        for (double eta : step.indicator) total += eta * eta;

        if (output) {
            const uint32_t elements = uint32_t(leaf.mesh.triangles.size());
            stats.min_elements = std::min(stats.min_elements, elements);
            stats.max_elements = std::max(stats.max_elements, elements);
            SimulationFrame out;
            out.index = frame;
            out.time = t;
            out.hierarchy = &h;
            out.cg_iterations = step.cg_iterations;
            out.estimated_error = std::sqrt(total);
            Field temperature{"temperature", FieldAssociation::point, FieldType::float64, 1, step.u, {}};
            Field indicator{"error_indicator", FieldAssociation::cell, FieldType::float64, 1, step.indicator, {}};
            Field flux{"heat_flux", FieldAssociation::cell, FieldType::float64, 3, {}, {}};
            flux.values.reserve(3 * step.gradient.size());
            for (Vec3 g : step.gradient) flux.values.insert(flux.values.end(), {-g.x, -g.y, -g.z});
            Field level{"level", FieldAssociation::cell, FieldType::uint8, 1, {}, {}};
            level.integers.assign(leaf.cells.level.begin(), leaf.cells.level.end());
            out.fields = {std::move(temperature), std::move(indicator), std::move(flux), std::move(level)};
            on_frame(out);
        }

        // Mark: η_T² against the share of the total an element would have with target_elements
        // elements equidistributed; coarsen well below it (hysteresis: a coarsened parent's
        // indicator is up to ~16 times its children's).
        // With more elements than asked for, the threshold rises (and falls with fewer), so
        // the mesh stays near the target while the error moves.
        const double ratio = double(step.indicator.size()) / options.target_elements;
        const double target = total / options.target_elements * ratio * ratio;
        std::vector<uint32_t> refine, coarsen;
        for (uint32_t e = 0; e < step.indicator.size(); ++e) {
            const double eta2 = step.indicator[e] * step.indicator[e];
            if (eta2 > target && leaf.cells.level[e] < options.max_level) refine.push_back(e);
            else if (eta2 < 0.04 * target) coarsen.push_back(e);
        }
        std::unordered_map<PositionKey, double, PositionHash> old;
        old.reserve(leaf.mesh.positions.size() * 2);
        for (size_t i = 0; i < leaf.mesh.positions.size(); ++i) old[key_of(leaf.mesh.positions[i])] = step.u[i];
        apply_adaptation_step(h, refine, coarsen);
        u_by_id = transfer(h, old);
    }
    stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return stats;
}

}  // namespace amc
