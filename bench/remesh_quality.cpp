// The measures of docs/REMESHER.md for a remeshed surface against the mesh it approximates:
// fold-overs (of both), smallest triangle quality, coincident vertices, degenerate triangles, the
// certified two-sided distance (Hausdorff and RMS, relative to the reference's bounding-box
// diagonal), face count and precision. One tab-separated line per approximation; the table
// script (scripts/remesher_table.sh) runs it on the leaf meshes `amc refine` writes.
//
//   remesh_quality [--header] [--tolerance T] REFERENCE APPROXIMATION...
//   remesh_quality [--header] [--tolerance T] --remesh mean|gauss|error [--faces N] [--base-faces B]
//                  [--max-level L] REFERENCE...
// The second form remeshes each reference with remesh_adaptively itself and measures the leaf
// mesh (seconds: the remeshing alone).
#include "geometry/surface_quality.h"

#include <amc/mesh.h>
#include <amc/refinement.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace {

// seconds < 0: the measuring time is printed instead.
void print_row(const std::string& name, const amc::TriangleMesh& reference, const amc::MeshShape& input,
               const amc::TriangleMesh& mesh, double seconds, double tolerance) {
    const auto start = std::chrono::steady_clock::now();
    const amc::MeshShape shape = amc::measure_shape(mesh);
    const amc::SurfaceDistance d = amc::surface_distance(reference, mesh, tolerance);
    if (seconds < 0) seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf("%s\t%zu\t%d\t%u\t%u\t%u\t%u\t%.3g\t%.3f\t%.3e\t%.3e\t%.3e\t%llu\t%.2f\n", name.c_str(),
                mesh.triangles.size(), int(mesh.single_precision), input.fold_overs, shape.fold_overs,
                shape.degenerate_triangles, shape.coincident_vertices, shape.min_quality, shape.mean_quality, d.max,
                d.max_upper, d.rms, (unsigned long long)(d.to_reference.evaluations + d.from_reference.evaluations),
                seconds);
    std::fflush(stdout);
    for (const amc::OneSidedDistance* side : {&d.to_reference, &d.from_reference})
        std::fprintf(stderr, "  %s: max %.4g at (%.6g, %.6g, %.6g)\n", side == &d.to_reference ? "to reference" : "from reference",
                     side->max, side->max_point.x, side->max_point.y, side->max_point.z);
}

}  // namespace

int main(int argc, char** argv) {
    double tolerance = 1e-5;
    bool header = false;
    std::string criterion;
    amc::SurfaceRemeshOptions options;
    std::vector<std::string> files;
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        if (arg == "--header") {
            header = true;
        } else if (arg == "--tolerance" && i + 1 < argc) {
            tolerance = std::atof(argv[++i]);
        } else if (arg == "--remesh" && i + 1 < argc) {
            criterion = argv[++i];
            options.criterion = criterion == "gauss"   ? amc::RefinementCriterion::gauss_curvature
                                : criterion == "error" ? amc::RefinementCriterion::approximation_error
                                                       : amc::RefinementCriterion::mean_curvature;
        } else if (arg == "--faces" && i + 1 < argc) {
            options.target_faces = uint32_t(std::atol(argv[++i]));
        } else if (arg == "--base-faces" && i + 1 < argc) {
            options.base_triangles = uint32_t(std::atol(argv[++i]));
        } else if (arg == "--max-level" && i + 1 < argc) {
            options.max_level = std::atoi(argv[++i]);
        } else {
            files.push_back(arg);
        }
    }
    if (header)
        std::printf("file\tfaces\tfloat32\tinput_folds\tfolds\tdegenerate\tcoincident\tmin_quality\tmean_quality\t"
                    "max\tmax_upper\trms\tevaluations\tseconds\n");
    if (!criterion.empty()) {
        try {
            for (const std::string& file : files) {
                const amc::TriangleMesh reference = amc::read_mesh(file);
                const amc::MeshShape input = amc::measure_shape(reference);
                const auto start = std::chrono::steady_clock::now();
                amc::SurfaceRemeshStats stats;
                const amc::Hierarchy h = amc::remesh_adaptively(reference, options, &stats);
                const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
                std::fprintf(stderr,
                             "%s: base %u triangles (quality %.3f, %u fold-overs), %u vertices corrected, %u inherited "
                             "fold-overs; seconds: simplify %.2f refine %.2f correct %.2f\n",
                             file.c_str(), stats.base_triangles, stats.base_min_quality, stats.base_fold_overs,
                             stats.corrected_vertices, stats.inherited_fold_overs, stats.simplify_seconds,
                             stats.refine_seconds, stats.correct_seconds);
                const amc::TriangleMesh mesh = amc::extract_leaf_mesh(h).mesh;
                print_row(file, reference, input, mesh, seconds, tolerance);
            }
        } catch (const amc::Error& e) {
            std::fprintf(stderr, "remesh_quality: %s\n", e.what());
            return 1;
        }
        return 0;
    }
    if (files.size() < 2) {
        if (header) return 0;
        std::fprintf(stderr, "usage: remesh_quality [--header] [--tolerance T] REFERENCE APPROXIMATION...\n");
        return 2;
    }
    try {
        const amc::TriangleMesh reference = amc::read_mesh(files[0]);
        const amc::MeshShape input = amc::measure_shape(reference);
        for (size_t i = 1; i < files.size(); ++i) {
            const auto start = std::chrono::steady_clock::now();
            const amc::TriangleMesh mesh = amc::read_mesh(files[i]);
            print_row(files[i], reference, input, mesh, -1, tolerance);
            (void)start;
        }
    } catch (const amc::Error& e) {
        std::fprintf(stderr, "remesh_quality: %s\n", e.what());
        return 1;
    }
    return 0;
}
