// A small adaptive finite-element run of our own, to make the kind of data a series file holds
// (docs/SERIES.md): the heat equation u_t - Δu = f, P1 elements on the leaf mesh of a hierarchy,
// implicit Euler in time, u = 0 on the boundary, a heat source moving through the domain. Each
// step solves, estimates the error element by element (residual estimator) and then refines
// where it is large and coarsens where it is small (apply_adaptation_step), carrying the solution
// over to the new mesh by P1 interpolation.
#pragma once

#include <amc/field.h>
#include <amc/hierarchy.h>

#include <cstdint>
#include <functional>
#include <vector>

namespace amc {

enum class HeatScenario : uint8_t {
    lshape = 0,    // L-shaped domain, the source circling the re-entrant corner (3/4 of a turn)
    rotating = 1,  // unit square, the source on a full circle around the centre
};

struct HeatRunOptions {
    HeatScenario scenario = HeatScenario::lshape;
    int frames = 100;              // frames delivered (time steps after the initial adaptation)
    double end_time = 1.0;         // the source's path takes [0, end_time]; dt = end_time / frames
    int max_level = 10;            // no element finer than this
    uint32_t target_elements = 20000;  // the estimator's tolerance aims at about this many
    int initial_adaptations = 8;   // solve-estimate-refine rounds at t = 0 before the first frame
};

// One output step: the mesh the solution was computed on, its time, and the solver's fields:
//   point "temperature" (Float64, 1): u at the vertices (canonical order);
//   cell "error_indicator" (Float64, 1): the residual estimator η_T;
//   cell "heat_flux" (Float64, 3): -∇u on the element (z = 0);
//   cell "level" (UInt8, 1): the element's refinement level.
struct SimulationFrame {
    int index = 0;
    double time = 0;
    const Hierarchy* hierarchy = nullptr;
    std::vector<Field> fields;
    uint32_t cg_iterations = 0;
    double estimated_error = 0;  // sqrt(Σ η_T²)
};

struct HeatRunStats {
    uint64_t total_cg_iterations = 0;
    double seconds = 0;
    uint32_t min_elements = 0, max_elements = 0;
};

// Runs the simulation and calls on_frame for every frame in order (the frame's pointers are valid
// during the call only). Deterministic.
HeatRunStats run_heat_simulation(const HeatRunOptions& options,
                                 const std::function<void(const SimulationFrame&)>& on_frame);

}  // namespace amc
