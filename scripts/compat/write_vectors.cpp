// Writes test vectors with the amcodec it is built against (an older commit, see
// scripts/check_old_versions.sh): random hierarchies over five base meshes as .amh files, their
// hierarchy streams under all 64 coder switch combinations, and .amc files (lossless with the
// default, naive-with-contexts and butterfly settings, and quantized to 12 bits). Uses only API
// that amcodec has had since its first specified format.
// Usage: write_vectors OUT_DIR SEEDS
#include <amc/codec.h>
#include <amc/hierarchy.h>
#include <amc/hierarchy_coder.h>
#include <amc/refinement.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

namespace {

void write_bytes(const std::string& path, const std::vector<uint8_t>& bytes) {
    std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
}

amc::HierarchyCoderOptions options_of_switches(int s) {
    amc::HierarchyCoderOptions o;
    o.cull_one_regularity = s & 1;
    o.cull_hanging_nodes = s & 2;
    o.uniform_levels = s & 4;
    o.truncate_stream = s & 8;
    o.use_contexts = s & 16;
    o.traversal = (s & 32) ? amc::Traversal::improved : amc::Traversal::naive;
    return o;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 3) {
        std::fprintf(stderr, "usage: write_vectors OUT_DIR SEEDS\n");
        return 2;
    }
    const std::string out = argv[1];
    const int seeds = std::atoi(argv[2]);
    const std::vector<std::pair<std::string, amc::TriangleMesh>> bases = {
        {"icosahedron", amc::make_icosahedron()}, {"torus", amc::make_torus(6, 5, 2.0, 0.7)},
        {"square", amc::make_square(3)},          {"lshape", amc::make_l_shape(1)},
        {"bumpy", amc::make_bumpy_sphere(0)}};
    int files = 0;
    for (int seed = 1; seed <= seeds; ++seed) {
        for (const auto& [base_name, base] : bases) {
            amc::Hierarchy h(base);
            if (seed % 4 == 0) amc::refine_uniformly(h, 1);
            const uint32_t leaves = uint32_t(60 + (seed * 7919u) % 3000);
            amc::refine_randomly(h, leaves, 2 + seed % 5, uint64_t(seed));
            // Diagonals: the default, every third flipped, or each by the leaf's node id.
            int k = 0;
            for (amc::NodeId n : h.leaves()) {
                if (h.hanging_node_count(n) != 2) continue;
                if ((seed % 3 == 1 && (k++ % 3) == 0) || (seed % 3 == 2 && (n * 2654435761u) % 5 < 2))
                    h.set_diagonal_flipped(n, true);
            }
            const std::string name = out + "/" + base_name + "_" + std::to_string(seed);
            amc::write_hierarchy(name + ".amh", h);
            for (int s = 0; s < 64; ++s) write_bytes(name + ".sw" + std::to_string(s) + ".hs", amc::encode_hierarchy(h, options_of_switches(s)));
            amc::EncodeOptions lossless, naive, butterfly, quantized;
            naive.hierarchy.traversal = amc::Traversal::naive;
            butterfly.predictor = amc::GeometryPredictor::butterfly;
            quantized.quantize_bits = 12;
            // Each file with what this build decodes it to: the base order is the writing build's
            // (it changed with the base coder's mode 2, format version 4).
            const std::pair<const char*, const amc::EncodeOptions*> kinds[] = {
                {"lossless", &lossless}, {"naive", &naive}, {"butterfly", &butterfly}, {"q12", &quantized}};
            for (const auto& [kind, options] : kinds) {
                const std::vector<uint8_t> bytes = amc::encode(h, *options);
                write_bytes(name + "." + kind + ".amc", bytes);
                amc::write_hierarchy(name + "." + kind + ".decoded.amh", amc::decode(bytes.data(), bytes.size()));
            }
            files += 72;
        }
    }
    std::printf("write_vectors: %d hierarchies, %d files in %s\n", seeds * int(bases.size()), files, out.c_str());
    return 0;
}
