// The static geometry modes' decoder alone (docs/CODEC.md, "Geometry mode 4"): every level's new
// positions of a model, on a grid of BITS bits, coded once in mode 3 and once in mode 4, then
// decoded again and again into the same hierarchy, the two modes in turn, so that a change of the
// machine's load hits both alike. Prints the median [min - max] CPU nanoseconds per decoded vertex
// of each mode over ROUNDS rounds (each round decodes every level kRepeat times) and the median
// of the rounds' ratios to mode 3.
// Hot caches: what it times is the decoder's arithmetic and its chain of dependent values, not
// the memory of a first decode.
//   static_positions_speed ROUNDS BITS model.amh ...
#include <amc/hierarchy.h>

#include "bench_common.h"
#include "coding/entropy/arithmetic_coder.h"
#include "coding/geometry/float_coder.h"
#include "coding/geometry/geometry_prediction.h"
#include "coding/geometry/static_position_coder.h"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace {

using namespace amc;

constexpr int kRepeat = 10;

GeometryPredictor mode_of(bool grid_bins) { return grid_bins ? GeometryPredictor::normal_frame_grid : GeometryPredictor::normal_frame; }

struct CodedLevel {
    std::vector<std::pair<NodeId, int>> created;
    StaticTables tables;
    std::vector<uint8_t> rans, raw;
};

std::vector<CodedLevel> code_levels(const Hierarchy& h, CoordinateSpace space, bool grid_bins) {
    std::vector<CodedLevel> levels;
    for (const std::vector<NodeId>& nodes : nodes_by_level(h)) {
        CodedLevel level;
        level.created = new_vertices_of_level(h, nodes);
        if (level.created.empty()) continue;
        const StaticLevelEncoder code(h, level.created, space, mode_of(grid_bins));
        ArithmeticEncoder encoder;
        code.write_tables(encoder);
        const std::vector<uint8_t> tables = encoder.finish();
        ArithmeticDecoder decoder(tables.data(), tables.size());
        if (!read_static_tables(decoder, space, mode_of(grid_bins), level.tables)) throw Error("tables do not read back");
        level.rans = code.rans_bytes();
        level.raw = code.raw_bytes();
        levels.push_back(std::move(level));
    }
    return levels;
}

// CPU seconds of decoding every level once.
double decode_all(Hierarchy& h, const std::vector<CodedLevel>& levels, CoordinateSpace space, bool grid_bins) {
    const double start = cpu_seconds();
    for (const CodedLevel& l : levels) {
        if (!decode_static_positions(h, l.created, space, mode_of(grid_bins), l.tables, l.rans.data(), l.rans.size(), l.raw.data(),
                                     l.raw.size(), StaticOrder::grouped))
            throw Error("a level does not decode");
    }
    return cpu_seconds() - start;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 4) {
        std::fprintf(stderr, "usage: static_positions_speed ROUNDS BITS model.amh ...\n");
        return 2;
    }
    const int rounds = std::max(1, std::atoi(argv[1]));
    const int bits = std::atoi(argv[2]);
    const bool codings[] = {false, true};  // grid_bins
    const char* const names[] = {"mode 3", "mode 4"};
    std::printf("| model | vertices | coding | ns/vertex | / mode 3 (median of rounds) |\n|---|---:|---|---:|---:|\n");
    for (int a = 3; a < argc; ++a) {
        Hierarchy h = read_hierarchy(argv[a]);
        const Quantizer quantizer = make_quantizer(h.positions(), bits);
        for (VertexId v = 0; v < h.positions().size(); ++v)
            h.set_position(v, dequantize(quantizer, snap_to_grid(quantizer, h.position(v))));
        CoordinateSpace space;
        space.quantizer = &quantizer;
        std::vector<std::vector<CodedLevel>> coded;
        for (bool c : codings) coded.push_back(code_levels(h, space, c));
        size_t vertices = 0;
        for (const CodedLevel& l : coded[0]) vertices += l.created.size();
        std::vector<std::vector<double>> ns(coded.size()), ratio(coded.size());
        for (int r = 0; r < rounds; ++r) {
            std::vector<double> seconds(coded.size(), 0.0);
            for (int k = 0; k < kRepeat; ++k)
                for (size_t c = 0; c < coded.size(); ++c) seconds[c] += decode_all(h, coded[c], space, codings[c]);
            for (size_t c = 0; c < coded.size(); ++c) {
                ns[c].push_back(seconds[c] * 1e9 / double(kRepeat * vertices));
                ratio[c].push_back(seconds[0] > 0 ? seconds[c] / seconds[0] : 0.0);
            }
        }
        for (size_t c = 0; c < coded.size(); ++c) {
            const Range t = range_of(ns[c]), q = range_of(ratio[c]);
            std::printf("| %s | %zu | %s | %.1f [%.1f-%.1f] | %.3f [%.3f-%.3f] |\n",
                        std::filesystem::path(argv[a]).stem().string().c_str(), vertices, names[c], t.median, t.low, t.high,
                        q.median, q.low, q.high);
        }
        std::fflush(stdout);
    }
    return 0;
}
