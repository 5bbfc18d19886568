// Rate and distortion of an .amc file's level prefixes (issue 30; docs/CODEC.md, "What each level
// prefix costs"): each hierarchy is encoded with default options at every requested precision; for
// every level L the file is cut after L's block, which is what a reader that stops there (or a
// download still arriving) holds, decoded as a partial file, and its conforming mesh measured
// against the hierarchy's own full-resolution leaf mesh: the two-sided Hausdorff distance (found
// and certified bound) and the RMS distance, relative to the bounding-box diagonal.
//   rate_distortion [--bits 12,16,0] [--tolerance 1e-4] model.amh ...   (0: bit-exact)
// Prints one markdown table; a file with chunks (more than `chunk_faces` faces) has no level
// prefixes and is reported as such.
#include "coding/container.h"
#include "geometry/surface_quality.h"

#include <amc/codec.h>
#include <amc/hierarchy.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

std::vector<int> parse_bits(const std::string& list) {
    std::vector<int> out;
    std::stringstream in(list);
    for (std::string item; std::getline(in, item, ',');) out.push_back(std::stoi(item));
    return out;
}

void report(const std::string& path, const std::vector<int>& bits, double tolerance) {
    const amc::Hierarchy h = amc::read_hierarchy(path);
    const amc::TriangleMesh full = amc::extract_leaf_mesh(h).mesh;
    const std::string name = std::filesystem::path(path).stem().string();
    for (int b : bits) {
        amc::EncodeOptions options;
        options.quantize_bits = b;
        const std::vector<uint8_t> file = amc::encode(h, options);
        const amc::FileInfo info = amc::inspect(file.data(), file.size());
        const std::string precision = b ? std::to_string(b) + " bits" : "bit-exact";
        if (!info.chunks.empty()) {
            std::printf("| %s | %s | (chunked: no level prefixes) | | | | | | |\n", name.c_str(), precision.c_str());
            continue;
        }
        // The cuts: after the base mesh's blocks (its geometry comes last), then after each level block.
        std::vector<size_t> cuts;
        for (const amc::FileBlock& block : info.blocks) {
            if (block.type == uint8_t(amc::BlockType::base_geometry) || block.level >= 0) cuts.push_back(size_t(block.offset + block.size));
        }
        for (size_t c = 0; c < cuts.size(); ++c) {
            const size_t cut = cuts[c];
            const amc::PartialDecode partial = amc::decode_partial(file.data(), cut);
            // The finest level's block decides no split: its prefix is the level before's mesh.
            if (!partial.complete && c + 1 < cuts.size() &&
                amc::decode_partial(file.data(), cuts[c + 1]).level == partial.level)
                continue;
            const amc::TriangleMesh mesh = amc::extract_leaf_mesh(partial.hierarchy).mesh;
            const amc::SurfaceDistance d = amc::surface_distance(full, mesh, tolerance);
            if (!d.complete()) std::fprintf(stderr, "rate_distortion: the distance was not measured (its queries cost too much)\n");
            std::printf("| %s | %s | %d | %zu | %.1f%% | %.3f | %zu | %.3f (%.3f) | %.4f |\n", name.c_str(),
                        precision.c_str(), partial.level, cut, 100.0 * double(cut) / double(file.size()),
                        8.0 * double(cut) / double(full.triangles.size()), mesh.triangles.size(), 1e3 * d.max,
                        1e3 * d.max_upper, 1e3 * d.rms);
            std::fflush(stdout);
            if (partial.complete) break;
        }
    }
}

}  // namespace

int main(int argc, char** argv) {
    try {
        std::vector<int> bits = {12, 16, 0};
        double tolerance = 1e-4;
        std::vector<std::string> inputs;
        for (int i = 1; i < argc; ++i) {
            const std::string arg = argv[i];
            if (arg == "--bits" && i + 1 < argc) bits = parse_bits(argv[++i]);
            else if (arg == "--tolerance" && i + 1 < argc) tolerance = std::stod(argv[++i]);
            else if (arg.rfind("--", 0) == 0) throw std::runtime_error("unknown option " + arg);
            else inputs.push_back(arg);
        }
        if (inputs.empty()) {
            std::fprintf(stderr, "usage: rate_distortion [--bits 12,16,0] [--tolerance 1e-4] model.amh ...\n");
            return 2;
        }
        std::printf("| model | coordinates | level | bytes received | of the file | bits per final face | faces | "
                    "Hausdorff, 10^-3 of the diagonal (bound) | RMS, 10^-3 |\n");
        std::printf("|---|---|--:|--:|--:|--:|--:|--:|--:|\n");
        for (const std::string& path : inputs) report(path, bits, tolerance);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "rate_distortion: %s\n", e.what());
        return 1;
    }
    return 0;
}
