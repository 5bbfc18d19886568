// What the benchmark programs share: the hierarchies coder_bench and decode_phases time, the
// clock and the median of repeated timings, reading the hierarchy files the studies are given.
#pragma once

#include <amc/hierarchy.h>
#include <amc/refinement.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <ctime>
#include <exception>
#include <optional>
#include <string>
#include <vector>

// The true refinement bits of a level's n nodes (their ids, in the coder's level order) and the
// next level's ids, for studies that replay the coder's levels; whether every node split.
inline bool read_level(const amc::Hierarchy& h, const std::vector<amc::NodeId>& ids, uint32_t n, std::vector<uint8_t>& truth,
                std::vector<amc::NodeId>& next_ids) {
    truth.assign(n, 0);
    bool all_refined = true;
    next_ids.clear();
    for (uint32_t i = 0; i < n; ++i) {
        truth[i] = !h.is_leaf(ids[i]);
        all_refined &= truth[i] != 0;
        if (truth[i]) {
            const amc::NodeId c = h.child(ids[i], 0);
            next_ids.insert(next_ids.end(), {c, c + 1, c + 2, c + 3});
        }
    }
    return all_refined;
}

// CPU time of the calling thread, seconds: on the shared machine wall time also counts other jobs' turns.
inline double thread_seconds() {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

// A hierarchy file's model name: its file name without directory and extension.
inline std::string model_name(const std::string& path) {
    const std::string file = path.substr(path.find_last_of('/') + 1);
    return file.substr(0, file.find_last_of('.'));
}

// The hierarchy in path, or nothing after the reading error on stderr under the program's name.
inline std::optional<amc::Hierarchy> read_hierarchy_or_report(const char* program, const std::string& path) {
    try {
        return amc::read_hierarchy(path);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "%s: %s: %s\n", program, path.c_str(), e.what());
        return std::nullopt;
    }
}

enum class BenchModel { surface = 0, random = 1, fe = 2 };

// surface: a curvature-adaptive remesh of the procedural bumpy sphere; random: a random hierarchy
// over a torus; fe: a planar finite-element model, the L-shaped domain of amc::make_l_shape_model
// graded towards its re-entrant corner, with element sizes scaled to the target. All with about
// target_nodes nodes.
inline amc::Hierarchy make_bench_hierarchy(BenchModel model, int64_t target_nodes) {
    if (model == BenchModel::fe) {
        // The node count goes about as 1 / scale^2: two corrections from the default scale.
        double scale = 0.025;
        amc::Hierarchy h = amc::make_l_shape_model(14, scale);
        for (int step = 0; step < 2; ++step) {
            scale *= std::sqrt(double(h.node_count()) / double(target_nodes));
            h = amc::make_l_shape_model(14, scale);
        }
        return h;
    }
    if (model == BenchModel::surface) {
        amc::SurfaceRemeshOptions options;
        options.base_triangles = 500;
        options.max_level = 8;
        options.target_faces = uint32_t(target_nodes * 3 / 4);
        return amc::remesh_adaptively(amc::make_bumpy_sphere(6), options);
    }
    amc::Hierarchy h(amc::make_torus(16, 24, 1.0, 0.35));
    amc::refine_randomly(h, uint32_t(target_nodes * 3 / 4), 12, 7);
    return h;
}

using Clock = std::chrono::steady_clock;

// Seconds from `start` to now.
inline double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

// Seconds of CPU time this process has used, all its threads together.
inline double cpu_seconds() {
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

// The median of the samples (the mean of the middle two for an even count); 0 for none.
inline double median(std::vector<double> samples) {
    if (samples.empty()) return 0;
    std::sort(samples.begin(), samples.end());
    const size_t n = samples.size();
    return n % 2 ? samples[n / 2] : 0.5 * (samples[n / 2 - 1] + samples[n / 2]);
}

// The median of non-empty samples, and their extremes.
struct Range {
    double median, low, high;
};
inline Range range_of(std::vector<double> samples) {
    std::sort(samples.begin(), samples.end());
    return {median(samples), samples.front(), samples.back()};
}
