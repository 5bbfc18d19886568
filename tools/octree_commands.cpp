// `amc octree make | encode | decode | info`: quadtree and octree forests (.amq, docs/OCTREE.md),
// from and to p4est files (when built with AMC_WITH_P4EST) and VTU.
#include "cli_files.h"
#include "commands.h"

#include <amc/mesh_io.h>
#include <amc/octree.h>

#include <array>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <sstream>

namespace amc::cli {

namespace {

std::string extension_of(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    return ext;
}

std::string read_bytes(const std::string& path) {
    try {
        return read_octree_input(path);
    } catch (const Error& e) {
        throw e.prefixed(path);  // as decode_bytes names it
    }
}

OctreeForest decode_bytes(const std::string& name, const std::string& bytes, const OctreeDecodeOptions& options) {
    try {
        return decode_octree_forest(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size(), options);
    } catch (const Error& e) {
        throw e.prefixed(name);
    }
}

// --data NAME:TYPE[:COMPONENTS],...: the layout of p4est user data.
std::vector<Field> data_layout(const std::string& spec) {
    std::vector<Field> layout;
    std::stringstream items(spec);
    for (std::string item; std::getline(items, item, ',');) {
        std::stringstream parts(item);
        std::string name, type, components = "1";
        std::getline(parts, name, ':');
        std::getline(parts, type, ':');
        std::getline(parts, components, ':');
        Field f;
        f.name = name;
        f.association = FieldAssociation::cell;
        bool known = false;
        for (int t = 0; t <= int(FieldType::float64); ++t)
            if (type == field_type_name(FieldType(t))) f.type = FieldType(t), known = true;
        char* end = nullptr;
        const unsigned long n = std::strtoul(components.c_str(), &end, 10);
        if (name.empty() || !known || *end != 0 || n < 1 || n > 1024)
            throw UsageError("--data: expected NAME:TYPE[:COMPONENTS] (TYPE Int8, UInt8, Int16, UInt16, Int32, UInt32, Int64, UInt64, "
                             "Float32 or Float64; 1 to 1024 components), got '" + item + "'");
        f.components = uint32_t(n);
        layout.push_back(f);
    }
    return layout;
}

// The forest in the format the output's extension names: .amq (default), .vtu or .p4est.
// `conforming`: VTU cells as conforming triangles / tetrahedra (conforming_leaf_mesh).
void write_forest(const std::string& path, const OctreeForest& forest, const GlobalOptions& global,
                  const OctreeEncodeOptions& options = {}, bool conforming = false) {
    const std::string ext = extension_of(path);
    if (conforming && ext != ".vtu") throw UsageError("--conforming: the output must be a .vtu file, got '" + path + "'");
    if (ext == ".vtu" || ext == ".p4est") {
        if (path == "-") throw UsageError("VTU and p4est output need a file name");
        if (!global.force) refuse_existing(path);
        if (ext == ".vtu")
            write_octree_vtu(path, forest, VtuEncoding::binary_zlib, conforming ? OctreeVtuCells::conforming : OctreeVtuCells::leaves);
        else write_p4est_file(path, forest);
    } else {
        const std::vector<uint8_t> bytes = encode_octree_forest(forest, options);
        write_output(path, std::string(bytes.begin(), bytes.end()), global.force);
    }
    if (global.verbosity > 0 && path != "-")
        std::fprintf(stderr, "%s: %zu leaves in %u trees\n", path.c_str(), forest.leaves.size(), forest.tree_count());
}

OctreeBalance balance_named(const std::string& name) {
    if (name == "face") return OctreeBalance::face;
    if (name == "edge") return OctreeBalance::edge;
    if (name == "corner") return OctreeBalance::corner;
    throw UsageError("--balance: expected face, edge, corner or none, got '" + name + "'");
}

// --trees NXxNY or NXxNYxNZ (a third size of 1 in 2D, as the default 1x1x1): whole numbers only,
// each parsed without overflow; brick_connectivity bounds their product.
std::array<int, 3> brick_sizes(const std::string& trees, int dim) {
    std::array<int, 3> n = {1, 1, 1};
    int sizes = 0;
    const char* p = trees.c_str();
    for (; sizes < 3 && std::isdigit(static_cast<unsigned char>(*p)); ++sizes) {
        char* end = nullptr;
        errno = 0;
        const long value = std::strtol(p, &end, 10);
        if (errno != 0 || value < 1 || value > std::numeric_limits<int>::max()) break;
        n[sizes] = int(value);
        p = end;
        if (*p != 'x') {
            ++sizes;
            break;
        }
        ++p;
    }
    if (*p != 0 || sizes < dim || (dim == 2 && n[2] != 1))
        throw UsageError("--trees: expected NXxNY (2D) or NXxNYxNZ (3D), sizes from 1, got '" + trees + "'");
    return n;
}

}  // namespace

void run_octree_make(const OctreeMakeCommand& c, const GlobalOptions& global) {
    const std::array<int, 3> n = brick_sizes(c.trees, c.dim);
    TreeConnectivity conn;
    try {
        conn = brick_connectivity(c.dim, n[0], n[1], n[2]);
    } catch (const Error& e) {
        throw UsageError("--trees " + c.trees + ": " + e.what());
    }
    const Vec3 center{0.5 * n[0], 0.5 * n[1], c.dim == 3 ? 0.5 * n[2] : 0.0};
    OctreeForest forest;
    const uint64_t most = c.max_leaves;
    try {
        if (c.model == "sphere") forest = sphere_octree_forest(conn, center, 0.35 * std::min(n[0], n[1]), c.level, most);
        else if (c.model == "front") forest = front_octree_forest(conn, 0.5 * n[0], c.level, most);
        else if (c.model == "random") forest = random_octree_forest(conn, c.seed, 0.4, std::min(2, c.level), c.level, most);
        else if (c.model == "uniform") forest = uniform_octree_forest(conn, c.level, most);
        else throw UsageError("--model: expected sphere, front, random or uniform, got '" + c.model + "'");
    } catch (const Error& e) {
        if (e.code() != ErrorCode::limit_exceeded) throw;
        throw UsageError("--level " + std::to_string(c.level) + ": the " + c.model + " " + e.what() + " (--max-leaves)");
    }
    if (c.balance != "none") forest = balance_octree_forest(forest, balance_named(c.balance));
    write_forest(c.output, forest, global, {}, c.conforming);
}

void run_octree_encode(const OctreeEncodeCommand& c, const GlobalOptions& global) {
    const std::string ext = extension_of(c.input);
    OctreeForest forest;
    if (ext == ".p4est") {
        forest = read_p4est_file(c.input, nullptr, data_layout(c.data));
    } else {
        if (!c.data.empty()) throw UsageError("--data describes p4est user data: the input is not a .p4est file");
        forest = decode_bytes(c.input, read_bytes(c.input), {});
    }
    const std::string output = c.output.empty() ? default_output(c.input, ".amq") : c.output;
    OctreeEncodeOptions options;
    options.vertex_step = c.vertex_step;
    write_forest(output, forest, global, options);
}

void run_octree_decode(const OctreeDecodeCommand& c, const GlobalOptions& global) {
    OctreeDecodeOptions options;
    options.max_level = c.level;
    if (c.max_nodes > 0) options.max_nodes = c.max_nodes;
    if (c.max_octants_per_byte >= 0) options.max_octants_per_byte = uint64_t(c.max_octants_per_byte);
    const OctreeForest forest = decode_bytes(c.input, read_bytes(c.input), options);
    const std::string output = c.output.empty() ? default_output(c.input, ".vtu") : c.output;
    if (extension_of(output) == ".amq") throw UsageError(output + ": decode writes .vtu or .p4est");
    write_forest(output, forest, global, {}, c.conforming);
}

void run_octree_info(const OctreeInfoCommand& c, const GlobalOptions&) {
    OctreeDecodeOptions options;
    if (c.max_nodes > 0) options.max_nodes = c.max_nodes;
    if (c.max_octants_per_byte >= 0) options.max_octants_per_byte = uint64_t(c.max_octants_per_byte);
    const std::string bytes = read_bytes(c.input);
    const OctreeForest forest = decode_bytes(c.input, bytes, options);
    const OctreeForestCounts counts = count_octree_forest(forest);
    std::printf("%s: %dD forest of %u trees, %llu leaves, %llu octants, %d levels\n", c.input.c_str(), forest.dim(),
                forest.tree_count(), (unsigned long long)counts.leaves, (unsigned long long)counts.nodes, counts.depth + 1);
    std::printf("  %zu bytes: %.4f bits/leaf, %.4f bits/octant; face balanced: %s\n", bytes.size(),
                8.0 * double(bytes.size()) / double(counts.leaves), 8.0 * double(bytes.size()) / double(counts.nodes),
                octree_balance_violation(forest, OctreeBalance::face).empty() ? "yes" : "no");
    std::vector<uint64_t> per_level(counts.depth + 1, 0);
    for (const Octant& o : forest.leaves) ++per_level[o.level];
    std::printf("  leaves per level:");
    for (uint64_t n : per_level) std::printf(" %llu", (unsigned long long)n);
    std::printf("\n");
    for (const Field& f : forest.leaf_data)
        std::printf("  leaf field \"%s\": %s x %u\n", f.name.c_str(), field_type_name(f.type), f.components);
}

}  // namespace amc::cli
