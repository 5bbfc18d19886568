// What storing a caller's numbering costs: for each mesh file, its own vertex and face order (and
// the same mesh shuffled) coded against the decoder's canonical leaf mesh, part by part, next to
// log2 of the number of orders (the cost of a random one). The mesh is taken as its own base
// (no refinement), or as a leaf mesh of a detected hierarchy with --import.
//   numbering_bench [--import] mesh.obj ...
#include <amc/codec.h>
#include <amc/import.h>
#include <amc/mesh_io.h>
#include <amc/numbering.h>

#include "coding/numbering/numbering_coder.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <random>

namespace {

using namespace amc;

double log2_factorial(double n) { return std::lgamma(n + 1) / std::log(2.0); }

TriangleMesh shuffled(const TriangleMesh& mesh, uint32_t seed) {
    std::mt19937 random(seed);
    std::vector<uint32_t> order(mesh.positions.size()), position_of(order.size());
    for (uint32_t i = 0; i < order.size(); ++i) order[i] = i;
    std::shuffle(order.begin(), order.end(), random);
    TriangleMesh out;
    out.single_precision = mesh.single_precision;
    for (uint32_t i = 0; i < order.size(); ++i) {
        out.positions.push_back(mesh.positions[order[i]]);
        position_of[order[i]] = i;
    }
    for (const Triangle& t : mesh.triangles) {
        const int r = int(random() % 3);
        out.triangles.push_back({position_of[t[r]], position_of[t[(r + 1) % 3]], position_of[t[(r + 2) % 3]]});
    }
    std::shuffle(out.triangles.begin(), out.triangles.end(), random);
    return out;
}

const char* method_name(int method) {
    static const char* names[] = {"identity", "uniform", "adaptive", "walk"};
    return method >= 0 && method < 4 ? names[method] : "?";
}

void report(const std::string& name, const TriangleMesh& mesh, bool import) {
    ImportedHierarchy imported;
    if (import) {
        imported = import_mesh(mesh, name);
    } else {
        imported.hierarchy = Hierarchy(mesh);
        for (uint32_t i = 0; i < mesh.positions.size(); ++i) imported.vertex_of_input.push_back(i);
    }
    const LeafNumbering numbering = leaf_numbering(imported.hierarchy, mesh, imported.vertex_of_input);
    EncodeOptions options;
    options.numbering = &numbering;
    options.store_numbering = false;
    EncodeStats stats;
    const size_t file_bytes = encode(imported.hierarchy, options, &stats).size();  // lossless, without the numbering
    const Hierarchy decoded_order = in_decoder_order(imported.hierarchy);
    NumberingCodeStats code;
    const std::vector<uint8_t> payload = encode_numbering(stats.numbering, extract_leaf_mesh(decoded_order).mesh.triangles, &code);
    const double v = double(mesh.positions.size()), f = double(mesh.triangles.size());
    std::printf("%-28s %8.0f %8.0f %9zu %6.2f %-8s %9zu %6.2f %-8s %9zu %6.2f %9zu %7.2f %7.2f %9zu %6.1f%%\n", name.c_str(), v, f,
                code.vertex_bytes, 8.0 * code.vertex_bytes / v, method_name(code.vertex_method), code.face_bytes,
                8.0 * code.face_bytes / f, method_name(code.face_method), code.rotation_bytes, 8.0 * code.rotation_bytes / f,
                payload.size(), 8.0 * payload.size() / v, (log2_factorial(v) + log2_factorial(f) + f * std::log2(3.0)) / v,
                file_bytes, 100.0 * double(payload.size()) / double(file_bytes));
}

}  // namespace

int main(int argc, char** argv) {
    bool import = false;
    std::printf("%-28s %8s %8s %9s %6s %-8s %9s %6s %-8s %9s %6s %9s %7s %7s %9s %7s\n", "mesh", "V", "F", "vert B", "b/v", "method",
                "face B", "b/f", "method", "rot B", "b/f", "total B", "b/v", "rand b/v", "amc B", "of amc");
    for (int i = 1; i < argc; ++i) {
        if (std::strcmp(argv[i], "--import") == 0) {
            import = true;
            continue;
        }
        try {
            const TriangleMesh mesh = read_mesh(argv[i]);
            const std::string name = std::filesystem::path(argv[i]).filename().string();
            report(name, mesh, import);
            report(name + " shuffled", shuffled(mesh, 1), import);
        } catch (const std::exception& e) {
            std::fprintf(stderr, "numbering_bench: %s\n", e.what());
            return 1;
        }
    }
    return 0;
}
