// `amc refine`: adaptive red-green hierarchies from the refinement drivers.
#include "cli_files.h"
#include "commands.h"
#include "hierarchy/refinement_counts.h"
#include "progress.h"

#include <amc/mesh_io.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>

namespace amc::cli {

namespace {

RefinementCriterion parse_criterion(const std::string& name) {
    if (name == "mean") return RefinementCriterion::mean_curvature;
    if (name == "gauss") return RefinementCriterion::gauss_curvature;
    if (name == "error") return RefinementCriterion::approximation_error;
    throw UsageError("--criterion: unknown criterion '" + name + "' (mean, gauss, error)");
}

// A hierarchy (.amh, also for stdout) or its leaf mesh, by the output's extension.
std::string hierarchy_or_leaf_bytes(const std::string& path, const Hierarchy& h, MeshEncoding encoding) {
    MeshFormat format = MeshFormat::ply;
    if (path == "-" || output_kind(path, &format) == OutputKind::hierarchy) return serialize_hierarchy(h);
    const LeafMesh leaf = extract_leaf_mesh(h);
    return format_mesh(leaf.mesh, &leaf.cells, format, encoding);
}

// "front.amh" -> "front_3.amh"; a name without extension is a prefix: "front" -> "front_3.amh".
std::string step_path(const std::string& path, size_t step, const std::string& default_extension) {
    std::filesystem::path p(path);
    const std::string extension = p.has_extension() ? p.extension().string() : default_extension;
    return p.replace_extension().string() + "_" + std::to_string(step) + extension;
}

// What the surface remesher did and how close and well-shaped its leaf mesh is (docs/REMESHER.md).
void print_remesh_report(std::FILE* out, const SurfaceRemeshStats& s, uint32_t asked, bool measured) {
    std::fprintf(out,
                 "remesh: base %u triangles (%u tried, %u fold-overs, within %.2e of the input), %u leaf-mesh "
                 "triangles (%u asked), %u vertices corrected\n",
                 s.base_triangles, s.base_attempts, s.base_fold_overs, s.base_distance, s.faces, asked,
                 s.corrected_vertices);
    if (!measured) return;
    std::fprintf(out, "remesh: fold-overs %u (input %u), coincident vertices %u, worst triangle quality %.3g; ",
                 s.fold_overs, s.reference_fold_overs, s.coincident_vertices, s.min_quality);
    if (!s.distance_measured) {
        std::fprintf(out, "distance to the input not measured (its closest-point queries cost too much: long thin "
                          "triangles around a vertex?)\n");
        return;
    }
    std::fprintf(out, "distance to the input: max %.3e (certified <= %.3e), RMS %.3e of the bounding-box diagonal\n",
                 s.max_distance, s.max_distance_bound, s.rms_distance);
}

}  // namespace

void run_refine(const RefineCommand& c, const GlobalOptions& global) {
    if (c.output.empty()) throw UsageError("refine needs -o (a .amh hierarchy or a leaf mesh file)");
    const bool series = c.model == "front";
    const OutputKind kind = c.output == "-" ? OutputKind::hierarchy : output_kind(c.output);
    const bool prefix = series && kind == OutputKind::other && !std::filesystem::path(c.output).has_extension();
    if (kind == OutputKind::compressed || (kind == OutputKind::other && !prefix))
        throw UsageError("refine writes a hierarchy (.amh) or a leaf mesh (.obj .off .ply .vtu), not " + c.output);
    if (!c.leaf_output.empty() && output_kind(c.leaf_output) != OutputKind::mesh)
        throw UsageError("--leaf-mesh writes a mesh (.obj .off .ply .vtu), not " + c.leaf_output);
    if (c.model != "surface" && c.model != "bumpy" && c.model != "lshape" && c.model != "front" && c.model != "uniform" &&
        c.model != "random")
        throw UsageError("--model: unknown model '" + c.model + "' (surface, bumpy, lshape, front, uniform, random)");
    if (c.model == "surface" && c.input.empty()) throw UsageError("--model surface needs --input MESH");
    if (series && c.output == "-") throw UsageError("--model front writes one file per step: -o needs a name");
    const RefinementCriterion criterion = parse_criterion(c.criterion);
    if (!global.force && !series) {
        refuse_existing(c.output);
        refuse_existing(c.leaf_output.empty() ? "-" : c.leaf_output);
    }

    Progress progress(global.verbosity > 0);
    progress.phase("refining (" + c.model + ")");
    const auto start = std::chrono::steady_clock::now();
    std::vector<std::pair<std::string, Hierarchy>> results;
    SurfaceRemeshStats remesh_stats;
    bool remeshed = false;
    if (c.model == "surface" || c.model == "bumpy") {
        TriangleMesh reference;
        std::string name = c.model;
        if (c.model == "surface") {
            const InputFile input = read_input(c.input);
            reference = mesh_of(input);
            name = std::filesystem::path(c.input).stem().string();
        } else {
            reference = make_bumpy_sphere(6);
        }
        SurfaceRemeshOptions options;
        options.criterion = criterion;
        options.base_triangles = c.base_faces;
        options.target_faces = c.faces;
        options.max_level = c.max_level;
        options.precision = c.precision == "float32"   ? SurfacePrecision::float32
                             : c.precision == "float64" ? SurfacePrecision::float64
                                                        : SurfacePrecision::as_reference;
        options.measure = !c.no_measure && global.verbosity > 0;
        options.max_nodes = c.max_nodes;
        try {
            results.emplace_back(name + "_" + c.criterion, remesh_adaptively(reference, options, &remesh_stats));
        } catch (const Error& e) {
            if (e.code() != ErrorCode::limit_exceeded) throw;
            throw UsageError("--faces " + std::to_string(c.faces) + " --max-level " + std::to_string(c.max_level) + ": " +
                             e.what() + " (--max-nodes)");
        }
        remeshed = true;
    } else if (c.model == "lshape") {
        results.emplace_back("lshape", make_l_shape_model(c.max_level));
    } else if (c.model == "front") {
        std::vector<Hierarchy> sequence;
        try {
            sequence = make_moving_front_sequence(c.steps, c.max_level, c.max_nodes);
        } catch (const Error& e) {
            if (e.code() != ErrorCode::limit_exceeded) throw;
            throw UsageError("--max-level " + std::to_string(c.max_level) + " --steps " + std::to_string(c.steps) +
                             ": the front makes " + e.what() + " (--max-nodes)");
        }
        for (size_t i = 0; i < sequence.size(); ++i) results.emplace_back("front_" + std::to_string(i), std::move(sequence[i]));
    } else {
        Hierarchy h(c.input.empty() ? make_icosahedron() : mesh_of(read_input(c.input)));
        if (c.model == "uniform") {
            if (uniform_node_count(h.root_count(), c.levels, c.max_nodes) > c.max_nodes)
                throw UsageError("--levels " + std::to_string(c.levels) + ": " + std::to_string(h.root_count()) +
                                 " base triangles refined so often make more than the " + std::to_string(c.max_nodes) +
                                 " nodes of --max-nodes");
            refine_uniformly(h, c.levels);
        } else {
            // It stops at --faces leaves, or where every leaf is at --max-level.
            if (std::min<uint64_t>(c.faces, uniform_leaf_count(h.root_count(), c.max_level, c.max_nodes)) > c.max_nodes)
                throw UsageError("--faces " + std::to_string(c.faces) + " --max-level " + std::to_string(c.max_level) +
                                 ": more leaves than the " + std::to_string(c.max_nodes) + " nodes of --max-nodes");
            refine_randomly(h, c.faces, c.max_level, c.seed);
        }
        results.emplace_back(c.model, std::move(h));
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

    progress.finish();
    std::FILE* report = c.output == "-" ? stderr : stdout;
    if (global.verbosity > 0)
        std::fprintf(report, "%-22s %7s %9s %9s %6s %9s %9s %9s %8s\n", "model", "base_f", "faces", "nodes", "levels", "red",
                     "green", "vertices", "seconds");
    for (size_t i = 0; i < results.size(); ++i) {
        const auto& [name, h] = results[i];
        if (global.verbosity > 0) {
            const HierarchyStats s = compute_stats(h);
            std::fprintf(report, "%-22s %7u %9u %9u %6u %9u %9u %9u %8.2f\n", name.c_str(), s.base_triangles, s.faces,
                         s.nodes, s.levels, s.red_faces, s.green_faces, s.vertices, seconds / double(results.size()));
        }
        const std::string target = series ? step_path(c.output, i, ".amh") : c.output;
        write_output(target, hierarchy_or_leaf_bytes(target, h, global.mesh_encoding), global.force);
        if (!c.leaf_output.empty()) {
            const std::string leaf_target = series ? step_path(c.leaf_output, i, ".vtu") : c.leaf_output;
            MeshFormat format = MeshFormat::vtu;
            output_kind(leaf_target, &format);
            const LeafMesh leaf = extract_leaf_mesh(h);
            write_output(leaf_target, format_mesh(leaf.mesh, &leaf.cells, format, global.mesh_encoding), global.force);
        }
    }
    if (remeshed && global.verbosity > 0) print_remesh_report(report, remesh_stats, c.faces, !c.no_measure);
}

}  // namespace amc::cli
