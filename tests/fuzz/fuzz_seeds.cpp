// Writes the seed corpus of every fuzz target: files encoded here from small hierarchies of every
// kind (switches, precisions, quantization, predictors, a numbering), the golden files, the bad
// inputs and the regression inputs of tests/data.
//   fuzz_seeds <tests/data folder> <output folder>     -> <output folder>/<target>/...
//   fuzz_seeds --list                                   the targets' names, one a line
#include "fuzz_targets.h"

#include "coding/entropy/arithmetic_coder.h"
#include "coding/base/base_mesh_coder.h"
#include "coding/hierarchy/coder_switches.h"
#include "coding/geometry/float_coder.h"
#include "mesh/obj_io.h"
#include "mesh/off_io.h"
#include "mesh/ply_io.h"
#include "mesh/vtu_writer.h"
#include "../octree_test_util.h"

#include <amc/codec.h>
#include <amc/mesh_io.h>
#include <amc/octree.h>
#include <amc/refinement.h>
#include <amc/series.h>
#include <amc/simulation.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <numeric>
#include <string>

namespace fs = std::filesystem;
using namespace amc;

namespace {

std::map<std::string, int> seed_count;
fs::path out_dir;

void write_seed(const std::string& target, const std::vector<uint8_t>& bytes) {
    const fs::path dir = out_dir / target;
    fs::create_directories(dir);
    std::ofstream(dir / ("seed_" + std::to_string(seed_count[target]++)), std::ios::binary)
        .write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
}
void write_seed(const std::string& target, const std::string& bytes) {
    write_seed(target, std::vector<uint8_t>(bytes.begin(), bytes.end()));
}

// Every file under `dir` with the extension, named after its path below `dir` (golden files of
// different versions share their names: v1/lshape_graded.amc, v4/lshape_graded.amc).
void copy_files(const fs::path& dir, const std::string& target, const std::string& extension) {
    if (!fs::is_directory(dir)) return;
    for (const auto& entry : fs::recursive_directory_iterator(dir)) {
        if (!entry.is_regular_file()) continue;
        if (!extension.empty() && entry.path().extension() != extension) continue;
        std::string name = fs::relative(entry.path(), dir).string();
        std::replace(name.begin(), name.end(), '/', '_');
        fs::create_directories(out_dir / target);
        fs::copy_file(entry.path(), out_dir / target / ("data_" + name), fs::copy_options::overwrite_existing);
    }
}

std::vector<Hierarchy> sample_hierarchies() {
    std::vector<Hierarchy> out;
    uint64_t seed = 1;
    for (const TriangleMesh& base : fuzz::stream_bases()) {
        Hierarchy h(base);
        refine_randomly(h, h.root_count() + 60, 4, seed++);
        for (NodeId n : h.leaves())
            if (h.hanging_node_count(n) == 2 && n % 3 == 0) h.set_diagonal_flipped(n, true);
        out.push_back(h);
        Hierarchy u(base);
        refine_uniformly(u, 2);
        out.push_back(u);
    }
    return out;
}

void amc_seeds(const std::vector<Hierarchy>& hierarchies) {
    int k = 0;
    for (const Hierarchy& h : hierarchies) {
        EncodeOptions options;
        options.quantize_bits = k % 4 == 1 ? 12 : 0;
        options.predictor = GeometryPredictor(k % 3);
        options.grid_contexts = k % 8 == 1;  // quantized: geometry mode 4 where it codes smaller (version 9)
        options.hierarchy = coder_options_from_switches(k % 2 ? 63 : (k * 7) % kCoderSwitchCombinations);
        if (k % 3 == 2) options.chunks = 3;  // a chunked file (version 13): chunk table, seam, chunks
        // Bit-exact files in geometry modes 6 and 7 (version 15): static tables over the stencils.
        if (options.quantize_bits == 0 && k % 6 == 4) options.predictor = k % 12 == 4 ? GeometryPredictor::midpoint_static
                                                                                       : GeometryPredictor::butterfly_static;
        Hierarchy input = h;
        if (k % 4 == 2) {  // a forest over the base in single precision
            TriangleMesh base = h.base();
            base.single_precision = true;
            for (Vec3& p : base.positions) p = {float(p.x), float(p.y), float(p.z)};
            input = Hierarchy(base);
            refine_randomly(input, input.root_count() + 60, 4, uint64_t(k));
        }
        LeafNumbering numbering;
        if (k % 5 == 3) {
            const uint32_t faces = uint32_t(extract_leaf_mesh(input).mesh.triangles.size());
            numbering.vertex.resize(input.vertex_count());
            std::iota(numbering.vertex.rbegin(), numbering.vertex.rend(), 0u);
            numbering.face.resize(faces);
            std::iota(numbering.face.begin(), numbering.face.end(), 0u);
            numbering.rotation.assign(faces, 1);
            options.numbering = &numbering;
        }
        try {
            const std::vector<uint8_t> file = encode(input, options);
            write_seed("amc_decode", file);
            write_seed("amc_inspect", file);
        } catch (const Error& e) {
            std::fprintf(stderr, "fuzz_seeds: skipped a hierarchy: %s\n", e.what());
        }
        write_seed("amh_read", serialize_hierarchy(input));
        ++k;
    }
}

// A base_connectivity seed: the mesh with decoder vertex v at fuzz::base_position(v), as the
// target decodes it. The coder's vertex order depends on the positions (mode 2): positions are
// assigned in the order of a first encoding, then the mesh is encoded again; when that changes
// the order, the seed still decodes (to another mesh), which is all a seed needs. `windowed`: in
// mode 3, which the coder chooses only for long loops.
void write_base_seed(TriangleMesh mesh, bool windowed = false) {
    auto code = [&] {
        return windowed ? encode_base_connectivity(mesh, BaseConnectivityMode::angle_windowed) : encode_base_connectivity(mesh);
    };
    const BaseMeshCode first = code();
    for (uint32_t i = 0; i < first.vertex_order.size(); ++i) mesh.positions[first.vertex_order[i]] = fuzz::base_position(i);
    const std::vector<uint8_t> stream = code().bytes;
    const uint32_t n = uint32_t(mesh.positions.size());
    std::vector<uint8_t> seed = {uint8_t(n), uint8_t(n >> 8)};
    seed.insert(seed.end(), stream.begin(), stream.end());
    write_seed("base_connectivity", seed);
}

void stream_seeds(const std::vector<Hierarchy>& hierarchies) {
    const std::vector<TriangleMesh>& bases = fuzz::stream_bases();
    for (size_t b = 0; b < bases.size(); ++b) {
        for (int switches : {63, 0, 47, 31, 60}) {
            Hierarchy h(bases[b]);
            refine_randomly(h, h.root_count() + 80, 5, uint64_t(switches + 1));
            std::vector<uint8_t> seed = {uint8_t(b), 0};
            const std::vector<uint8_t> stream = encode_hierarchy(h, coder_options_from_switches(switches));
            seed.insert(seed.end(), stream.begin(), stream.end());
            write_seed("hierarchy_stream", seed);
        }
        write_base_seed(bases[b]);
    }
    write_base_seed(bases.back(), true);
    // Two tetrahedra sharing a vertex (a vertex copy) and a mesh with two components.
    TriangleMesh pinched;
    pinched.positions.resize(7);
    pinched.triangles = {{0, 1, 2}, {0, 2, 3}, {0, 3, 1}, {1, 3, 2}, {0, 4, 5}, {0, 5, 6}, {0, 6, 4}, {4, 6, 5}};
    write_base_seed(pinched);
    TriangleMesh two = hierarchies.front().base();
    const uint32_t offset = uint32_t(two.positions.size());
    for (Triangle t : hierarchies.front().base().triangles) two.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
    two.positions.resize(2 * offset);
    write_base_seed(two);
}

void geometry_seeds() {
    const double values[] = {0.0, -0.0, 1.5, -2.25, 1e-310, 3.4e38, 1e300, 0.1, 7.0, -1e-5};
    for (uint8_t mode : {0, 1, 2, 35, 89}) {
        const bool quantized = mode % 3 == 2;
        const Precision precision = mode % 3 == 0 ? Precision::float32 : Precision::float64;
        const int bits = 1 + mode / 3 % 30;
        std::vector<uint8_t> seed = {mode, 3};
        const double predictions[4] = {0.0, 1.0, -3.5, 100.0};
        for (double p : predictions) {
            uint64_t raw;
            std::memcpy(&raw, &p, 8);
            if (quantized) raw = uint64_t(p < 0 ? 0 : p);
            for (int i = 0; i < 8; ++i) seed.push_back(uint8_t(raw >> (8 * i)));
        }
        ArithmeticEncoder encoder;
        FloatResidualModels models(fuzz::kGeometryContexts);
        for (size_t i = 0; i < 60; ++i) {
            const int context = int(i * 7 % fuzz::kGeometryContexts);
            const double v = values[i % 10];
            if (quantized) {
                const uint32_t top = (uint32_t{1} << bits) - 1;
                encode_quantized(encoder, models, context, bits, uint32_t(i * 37) & top, std::min<uint32_t>(uint32_t(predictions[i % 4] < 0 ? 0 : predictions[i % 4]), top));
            } else {
                encode_coordinate(encoder, models, context, precision, precision == Precision::float32 ? double(float(v)) : v,
                                  predictions[i % 4]);
            }
        }
        const std::vector<uint8_t> payload = encoder.finish();
        seed.insert(seed.end(), payload.begin(), payload.end());
        write_seed("geometry", seed);
    }
}

void mesh_seeds(const std::vector<Hierarchy>& hierarchies) {
    for (size_t i = 0; i < hierarchies.size(); i += 2) {
        TriangleMesh mesh = extract_leaf_mesh(hierarchies[i]).mesh;
        write_seed("obj_read", format_obj(mesh));
        write_seed("off_read", format_off(mesh));
        write_seed("ply_read", format_ply(mesh));
        write_seed("vtu_read", format_vtu(mesh, {}, cell_data_arrays(extract_leaf_mesh(hierarchies[i]).cells), VtuEncoding::ascii));
        mesh.single_precision = true;
        for (Vec3& p : mesh.positions) p = {float(p.x), float(p.y), float(p.z)};
        write_seed("ply_read", format_ply(mesh));
    }
    write_seed("ply_read", std::string("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                                       "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
                                       "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"));
}

void round_trip_seeds() {
    fuzz::Random random{7};
    for (int k = 0; k < 24; ++k) {
        std::vector<uint8_t> seed(16 + random.next() % 500);
        for (uint8_t& b : seed) b = uint8_t(random.next());
        seed[0] = uint8_t(k);  // every combination of the flags
        write_seed("round_trip", seed);
    }
}

// Every combination of the flags (moved, anywhere, index map, leaf mesh alone, damaged, shuffled)
// over random refinements of every stream base.
void leaf_import_seeds() {
    fuzz::Random random{11};
    for (int k = 0; k < 64; ++k) {
        std::vector<uint8_t> seed(64 + random.next() % 1500);
        for (uint8_t& b : seed) b = uint8_t(random.next());
        seed[0] = uint8_t(k);
        seed[1] = uint8_t(k % fuzz::stream_bases().size());
        write_seed("leaf_import", seed);
    }
}

// Small series of the heat run: keyframes or not, lossless or bounded fields, a base in single
// precision, an unfinished file (no END block), one without fields.
void series_seeds() {
    HeatRunOptions run;
    run.frames = 4;
    run.max_level = 4;
    run.target_elements = 120;
    run.initial_adaptations = 2;
    std::vector<SeriesFrame> frames;
    run_heat_simulation(run, [&](const SimulationFrame& f) { frames.push_back({*f.hierarchy, f.time, f.fields}); });
    for (int k = 0; k < 5; ++k) {
        SeriesOptions options;
        options.keyframe_interval = k % 2 ? 2 : 0;
        options.error_bound = k == 2 ? 1e-3 : 0;
        if (k == 3) options.field_bounds = {{"heat_flux", 1e-2}};
        TriangleMesh base = frames.front().hierarchy.base();
        if (k == 4) {
            base.single_precision = true;
            for (Vec3& p : base.positions) p = {float(p.x), float(p.y), float(p.z)};
        }
        SeriesWriter writer(base, options);
        for (const SeriesFrame& f : frames) {
            if (k == 4) {
                Hierarchy h(base);
                refine_randomly(h, h.root_count() + 40, 3, uint64_t(f.time * 1000) + 1);
                writer.add_frame(h, f.time);
            } else {
                writer.add_frame(f.hierarchy, f.time, f.fields);
            }
        }
        if (k != 1) writer.close();
        write_seed("series_read", writer.bytes());
    }
}

// Small forest series over bricks of 2D and 3D trees: random forests (unbalanced: coded without
// culling), keyframes or not, an unfinished file.
void forest_series_seeds() {
    for (int k = 0; k < 4; ++k) {
        const int dim = 2 + k % 2;
        const TreeConnectivity conn = brick_connectivity(dim, 2, 1, 1);
        SeriesOptions options;
        options.keyframe_interval = k / 2 ? 2 : 0;
        ForestSeriesWriter writer(conn, options);
        for (int f = 0; f < 4; ++f)
            writer.add_frame(random_octree_forest(conn, uint64_t(10 * k + f), 0.35, 1, dim == 2 ? 5 : 3), 0.5 * f);
        if (k != 1) writer.close();
        write_seed("forest_series_read", writer.bytes());
    }
}

// Forests of every connectivity mode (brick, periodic brick, glued by vertices, explicit without
// vertices), 2D and 3D, balanced or not, with every switch somewhere.
void octree_seeds() {
    std::mt19937_64 rng(3);
    for (int k = 0; k < 16; ++k) {
        const int dim = 2 + k % 2;
        OctreeForest forest = octree_test::random_balanced_forest(dim, rng);
        OctreeEncodeOptions options;
        options.uniform_levels = k & 1;
        options.truncate = k & 2;
        options.context_groups = k & 4;
        options.improved_traversal = k & 8;
        if (k % 5 == 4) {  // unbalanced, coded without culling
            forest = random_octree_forest(forest.connectivity, uint64_t(k), 0.4, 1, dim == 2 ? 5 : 3);
            options.cull_by_balance = false;
        }
        if (k % 7 == 6) {  // explicit, without vertices
            forest.connectivity.vertices.clear();
            forest.connectivity.tree_to_vertex.clear();
        }
        write_seed("octree_decode", encode_octree_forest(forest, options));
    }
}

}  // namespace

int main(int argc, char** argv) {
    if (argc == 2 && std::string(argv[1]) == "--list") {
        for (const fuzz::Target& target : fuzz::targets()) std::printf("%s\n", target.name);
        return 0;
    }
    if (argc != 3) {
        std::fprintf(stderr, "usage: fuzz_seeds <tests/data folder> <output folder> | fuzz_seeds --list\n");
        return 2;
    }
    const fs::path data = argv[1];
    out_dir = argv[2];
    const std::vector<Hierarchy> hierarchies = sample_hierarchies();
    amc_seeds(hierarchies);
    stream_seeds(hierarchies);
    geometry_seeds();
    mesh_seeds(hierarchies);
    round_trip_seeds();
    leaf_import_seeds();
    series_seeds();
    forest_series_seeds();
    octree_seeds();
    for (const std::vector<uint8_t>& seed : fuzz::closest_point_seeds()) write_seed("closest_point", seed);
    for (const std::vector<uint8_t>& seed : fuzz::nearest_vertex_seeds()) write_seed("nearest_vertex", seed);
    for (const char* target : {"amc_decode", "amc_inspect"}) {
        copy_files(data / "golden", target, ".amc");
        copy_files(data / "bad", target, ".amc");
    }
    copy_files(data / "golden", "series_read", ".amcs");  // forest series too: refused by name
    copy_files(data / "golden", "forest_series_read", ".amcs");  // triangle series too: refused by name
    copy_files(data / "golden", "octree_decode", ".amq");
    copy_files(data / "golden", "amh_read", ".amh");
    copy_files(data / "bad", "amh_read", ".amh");
    copy_files(data / "bad", "obj_read", ".obj");
    copy_files(data / "bad", "off_read", ".off");
    copy_files(data / "bad", "ply_read", ".ply");
    copy_files(data / "bad", "vtu_read", ".vtu");
    copy_files(data / "vtu", "vtu_read", ".vtu");
    for (const fuzz::Target& target : fuzz::targets()) copy_files(data / "fuzz-regressions" / target.name, target.name, "");
    for (const fuzz::Target& target : fuzz::targets()) {
        const fs::path dir = out_dir / target.name;
        size_t n = 0;
        if (fs::is_directory(dir)) n = size_t(std::distance(fs::directory_iterator(dir), fs::directory_iterator()));
        std::printf("%-20s %zu seeds\n", target.name, n);
    }
    return 0;
}
