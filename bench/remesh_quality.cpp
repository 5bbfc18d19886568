// The measures of docs/REMESHER.md for a remeshed surface against the mesh it approximates:
// fold-overs (of both), smallest triangle quality, coincident vertices, degenerate triangles, the
// certified two-sided distance (Hausdorff and RMS, relative to the reference's bounding-box
// diagonal), face count and precision. One tab-separated line per mesh.
//
//   remesh_quality [--header] [--tolerance T] REFERENCE APPROXIMATION...
//       measures approximations made elsewhere (e.g. the leaf meshes `amc refine` writes);
//   remesh_quality [--header] [--tolerance T] --remesh mean|gauss|error [--faces N] [--base-faces B]
//                  [--max-level L] REFERENCE...
//       remeshes each reference with remesh_adaptively and measures the leaf mesh; `cpu_s` is the
//       process CPU time of the remeshing alone (wall time is meaningless on a shared machine).
// scripts/remesher_table.sh runs the second form on every mesh of ../shared/data.
#include "geometry/surface_quality.h"

#include <amc/mesh.h>
#include <amc/mesh_io.h>
#include <amc/refinement.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <string>
#include <vector>

namespace {

double cpu_seconds() { return double(std::clock()) / CLOCKS_PER_SEC; }

// The measures of `mesh` against `reference`, tab-separated, after the caller's first columns.
void print_measures(const amc::TriangleMesh& reference, const amc::MeshShape& input, const amc::TriangleMesh& mesh,
                    double tolerance) {
    const amc::MeshShape shape = amc::measure_shape(mesh);
    const amc::SurfaceDistance d = amc::surface_distance(reference, mesh, tolerance);
    if (!d.complete()) std::fprintf(stderr, "remesh_quality: the distance was not measured (its queries cost too much)\n");
    std::printf("%zu\t%d\t%u\t%u\t%u\t%u\t%.3g\t%.3f\t%.3e\t%.3e\t%.3e\t%u\t%.3g", mesh.triangles.size(),
                int(mesh.single_precision), input.fold_overs, shape.fold_overs, shape.degenerate_triangles,
                shape.coincident_vertices, shape.min_quality, shape.mean_quality, d.max, d.max_upper, d.rms,
                input.coincident_vertices, input.min_quality);
    for (const amc::OneSidedDistance* side : {&d.to_reference, &d.from_reference})
        std::fprintf(stderr, "  %s: max %.4g at (%.6g, %.6g, %.6g), %llu evaluations\n",
                     side == &d.to_reference ? "to reference" : "from reference", side->max, side->max_point.x,
                     side->max_point.y, side->max_point.z, (unsigned long long)side->evaluations);
}

const char* kMeasureColumns =
    "faces\tfloat32\tinput_folds\tfolds\tdegenerate\tcoincident\tmin_quality\tmean_quality\tmax\tmax_upper\trms\tinput_coincident\tinput_min_quality";

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
    try {
        if (!criterion.empty()) {
            if (header)
                std::printf("file\tinput_faces\tbase\tbase_attempts\tbase_folds\tbase_distance\tasked\t%s\tinherited\tcpu_s\n",
                            kMeasureColumns);
            for (const std::string& file : files) {
                const amc::TriangleMesh reference = amc::read_mesh(file);
                const amc::MeshShape input = amc::measure_shape(reference);
                const double start = cpu_seconds();
                amc::SurfaceRemeshStats stats;
                const amc::Hierarchy h = amc::remesh_adaptively(reference, options, &stats);
                const double seconds = cpu_seconds() - start;
                std::fprintf(stderr,
                             "%s: base %u triangles after %u attempts (quality %.3f, %u fold-overs), %u vertices "
                             "corrected; wall seconds: simplify %.2f refine %.2f correct %.2f\n",
                             file.c_str(), stats.base_triangles, stats.base_attempts, stats.base_min_quality,
                             stats.base_fold_overs, stats.corrected_vertices, stats.simplify_seconds,
                             stats.refine_seconds, stats.correct_seconds);
                const std::string name = file.substr(file.find_last_of('/') + 1);
                std::printf("%s\t%zu\t%u\t%u\t%u\t%.3e\t%u\t", name.c_str(), reference.triangles.size(),
                            stats.base_triangles, stats.base_attempts, stats.base_fold_overs, stats.base_distance,
                            options.target_faces);
                print_measures(reference, input, amc::extract_leaf_mesh(h).mesh, tolerance);
                std::printf("\t%u\t%.2f\n", stats.inherited_fold_overs, seconds);
                std::fflush(stdout);
            }
            return 0;
        }
        if (files.size() < 2) {
            if (header) {
                std::printf("file\t%s\n", kMeasureColumns);
                return 0;
            }
            std::fprintf(stderr, "usage: remesh_quality [--header] [--tolerance T] REFERENCE APPROXIMATION...\n");
            return 2;
        }
        if (header) std::printf("file\t%s\n", kMeasureColumns);
        const amc::TriangleMesh reference = amc::read_mesh(files[0]);
        const amc::MeshShape input = amc::measure_shape(reference);
        for (size_t i = 1; i < files.size(); ++i) {
            std::printf("%s\t", files[i].c_str());
            print_measures(reference, input, amc::read_mesh(files[i]), tolerance);
            std::printf("\n");
            std::fflush(stdout);
        }
    } catch (const amc::Error& e) {
        std::fprintf(stderr, "remesh_quality: %s\n", e.what());
        return 1;
    }
    return 0;
}
