// compare_bench: the measurements and how they are written out: a CSV file with one row per model,
// coder and payload, and the markdown tables of docs/BENCHMARKS.md.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace amc_bench {

// Coder ids (stable: the CSV and the chart script use them), in table order.
// Connectivity coders:
//   raw                 the 32-bit index buffer, 12 bytes per face (not a coder)
//   zstd-19, xz-9       that buffer through zstd -19 and xz -9
//   meshopt             meshoptimizer's index codec after its vertex cache optimizer
//   meshopt+zstd        the same followed by zstd -19
//   draco-default       Draco at speed 5 (the C++ API default): standard Edgebreaker
//   draco-best          Draco at speed 0: valence Edgebreaker
//   one-bit-per-node    base connectivity + one raw bit per node (computed, not a coder)
//   naive-hierarchy     base connectivity + the hierarchy coder with every switch off: one
//                       adaptively coded symbol per node, no culling, no contexts, naive order
//   amc-paper-naive     the paper's method with its naive traversal
//   amc-paper-improved  the paper's method with its improved traversal
//   amc-best            amcodec's default options
//   amc-imported        amcodec from the leaf mesh alone, as users have it: import_mesh (the
//                       coarsest base found in the connectivity), then the default options
// Complete meshes (payload mesh-lossless, mesh-16, mesh-12): draco-default, draco-best, amc-best.
struct Result {
    std::string model;
    uint64_t faces = 0, vertices = 0, nodes = 0;
    uint64_t base_triangles = 0;   // of the hierarchy coded (amc-imported: of the base found)
    std::string coder;
    std::string payload;           // connectivity, mesh-lossless, mesh-16 or mesh-12
    uint64_t bytes = 0;
    double max_error = 0;          // mesh payloads: largest coordinate error
    uint64_t connectivity_bytes = 0;  // mesh payloads: the part of the file that codes connectivity
    double encode_seconds = 0;     // median of the runs; 0: not timed
    double decode_seconds = 0;
    std::string check;             // "ok", "computed" (nothing to decode) or what went wrong
    std::string note;              // what a passing check tolerated (Draco's split vertices)
};

// A decoded result that matched its input, or a figure with nothing to decode ("computed").
bool passed(const Result& r);

void write_csv(const std::string& path, const std::vector<Result>& results);
// The tables of docs/BENCHMARKS.md (sizes, bits per face, ratios, complete meshes, speeds, checks);
// `runs`: how many times each figure was measured.
void write_markdown(const std::string& path, const std::vector<Result>& results, int runs);

}  // namespace amc_bench
