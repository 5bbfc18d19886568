// The coded symbols of a hierarchy with the features the mixing mode computes for them
// (HierarchyLevelEncoder::mixed_symbols), the paper's and the coder's own code lengths, kept in a
// cache directory after the first run: the input of bench/mixing_study and bench/model_study.
#pragma once

#include <amc/codec.h>
#include <amc/hierarchy.h>

#include "coding/entropy/arithmetic_coder.h"
#include "coding/hierarchy/context_groups.h"
#include "coding/hierarchy/hierarchy_level_coder.h"
#include "coding/hierarchy/mixed_contexts.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace mixed_study {

using namespace amc;

struct Symbol {
    MixedFeatures f;
    uint8_t bit;
    uint8_t ring_max = 0, ring_mean = 0, parent_curv = 0;  // study-only features (see extra_features)
};

// The raw mean-curvature feature of mixed_features: sum of chord * edge / (2 * twice area), times
// the longest edge (no exact rounding: a study).
inline double raw_curvature(const Hierarchy& h, NodeId n) {
    auto normal = [&](NodeId m) {
        const Vec3 a = h.position(h.vertex(m, 0)), b = h.position(h.vertex(m, 1)), c = h.position(h.vertex(m, 2));
        const Vec3 u = b - a, v = c - a;
        const Vec3 x{u.y * v.z - u.z * v.y, u.z * v.x - u.x * v.z, u.x * v.y - u.y * v.x};
        const double len = std::sqrt(dot(x, x));
        return std::pair<Vec3, double>{len > 0 ? (1.0 / len) * x : Vec3{0, 0, 0}, len};
    };
    const auto [nn, twice_area] = normal(n);
    if (!(twice_area > 0)) return 0;
    double weighted = 0, longest = 0;
    for (int e = 0; e < 3; ++e) {
        const Vec3 d = h.position(h.vertex(n, (e + 1) % 3)) - h.position(h.vertex(n, e));
        const double len = std::sqrt(dot(d, d));
        longest = std::max(longest, len);
        const NodeId q = h.neighbor(n, e);
        if (q == kNoNode) continue;
        const Vec3 c = nn - normal(q).first;
        weighted += std::sqrt(dot(c, c)) * len;
    }
    return weighted * longest / (2 * twice_area);
}

inline int quarter_bin(double x) {
    if (!(x > 0)) return 0;
    return std::clamp(int(std::floor(4 * std::log2(x))) + 40, 1, 63);
}

struct ModelData {
    std::string name;
    std::vector<Symbol> symbols;
    double paper_bits = 0;
    double library_bits = 0;  // the coder's own mixing mode, as encoders write it
    double second_bits = 0;   // the coder's second model (version 10) on the same symbols
};

// The adaptive code length of `symbols` under the coder's mixing model `model` (the seventh's
// trained initial states `trained`).
inline double model_bits(MixingModel model, const std::vector<Symbol>& symbols, const TrainedStateTables& trained = kTrainedStateTables) {
    MixedHierarchyModel coder(model, trained);
    double bits = 0;
    for (const Symbol& s : symbols) {
        const double p = coder.p16(s.f) / 65536.0;
        bits -= std::log2(s.bit ? p : 1 - p);
        coder.update(s.bit != 0);
    }
    return bits;
}

// A cache entry: the paper's and the coder's bits, the symbol count, the symbols. read_cache
// fills d (its second_bits too) and says whether `file` held one.
inline bool read_cache(const std::filesystem::path& file, ModelData& d) {
    std::ifstream in{file, std::ios::binary};
    if (!in) return false;
    uint64_t n = 0;
    in.read(reinterpret_cast<char*>(&d.paper_bits), sizeof d.paper_bits);
    in.read(reinterpret_cast<char*>(&d.library_bits), sizeof d.library_bits);
    in.read(reinterpret_cast<char*>(&n), sizeof n);
    d.symbols.resize(n);
    in.read(reinterpret_cast<char*>(d.symbols.data()), std::streamsize(n * sizeof(Symbol)));
    if (!in) {
        d.symbols.clear();
        return false;
    }
    d.second_bits = model_bits(MixingModel::second, d.symbols);
    return true;
}

inline void write_cache(const std::filesystem::path& file, const ModelData& d) {
    std::filesystem::create_directories(file.parent_path());
    std::ofstream out(file, std::ios::binary);
    const uint64_t n = d.symbols.size();
    out.write(reinterpret_cast<const char*>(&d.paper_bits), sizeof d.paper_bits);
    out.write(reinterpret_cast<const char*>(&d.library_bits), sizeof d.library_bits);
    out.write(reinterpret_cast<const char*>(&n), sizeof n);
    out.write(reinterpret_cast<const char*>(d.symbols.data()), std::streamsize(n * sizeof(Symbol)));
}

// The model's symbols with their features, and the paper's coded bits, from the cache or computed.
// `traversal`: the mixing mode's order of the symbols (the paper's bits are always the improved
// traversal's, the common reference). The naive traversal's symbols are those of the hierarchy in
// the decoder's base order (in_decoder_order), the order of a level's nodes in a file; the improved
// traversal's of the hierarchy as read, as the seventh model's table was trained.
inline ModelData load(const std::string& path, const std::filesystem::path& cache, Traversal traversal = Traversal::improved) {
    ModelData d;
    d.name = std::filesystem::path(path).stem().string();
    const std::filesystem::path file = cache / (d.name + (traversal == Traversal::naive ? "-naive" : "") + ".mf8");
    if (read_cache(file, d)) return d;
    const Hierarchy h = traversal == Traversal::naive ? in_decoder_order(read_hierarchy(path)) : read_hierarchy(path);
    {
        HierarchyLevelEncoder paper(h, HierarchyCoderOptions{});
        ArithmeticEncoder sink;
        for (int l = 0; l < paper.level_count(); ++l) paper.encode_level(l, sink);
        for (const ContextGroupStats& g : paper.stats().groups) d.paper_bits += g.coded_bits;
    }
    std::vector<CodedSymbol> trace;
    HierarchyCoderOptions mixed_options;
    mixed_options.traversal = traversal;
    const HierarchyLevelEncoder mixed(h, mixed_options, kHierarchyStreamVersion, &trace, true);
    for (const auto& [f, bit] : mixed.mixed_symbols()) d.symbols.push_back({f, uint8_t(bit)});
    {
        HierarchyLevelEncoder& coder = const_cast<HierarchyLevelEncoder&>(mixed);
        ArithmeticEncoder sink;
        for (int l = 0; l < coder.level_count(); ++l) coder.encode_level(l, sink);
        for (const ContextGroupStats& g : coder.stats().groups) d.library_bits += g.coded_bits;
    }
    for (size_t i = 0; i < d.symbols.size(); ++i) {
        const NodeId n = trace[i].node;
        const double own = raw_curvature(h, n);
        double mx = own, sum = own;
        int count = 1;
        for (int e = 0; e < 3; ++e) {
            const NodeId q = h.neighbor(n, e);
            if (q == kNoNode) continue;
            const double c = raw_curvature(h, q);
            mx = std::max(mx, c);
            sum += c;
            ++count;
        }
        d.symbols[i].ring_max = uint8_t(quarter_bin(mx));
        d.symbols[i].ring_mean = uint8_t(quarter_bin(sum / count));
        // Two rings: the mean over n, its neighbours and theirs (each once).
        std::vector<NodeId> seen = {n};
        for (int e = 0; e < 3; ++e) {
            const NodeId q = h.neighbor(n, e);
            if (q == kNoNode) continue;
            if (std::find(seen.begin(), seen.end(), q) == seen.end()) seen.push_back(q);
            for (int f = 0; f < 3; ++f) {
                const NodeId r = h.neighbor(q, f);
                if (r != kNoNode && std::find(seen.begin(), seen.end(), r) == seen.end()) seen.push_back(r);
            }
        }
        double sum2 = 0;
        for (NodeId r : seen) sum2 += raw_curvature(h, r);
        d.symbols[i].parent_curv = uint8_t(quarter_bin(sum2 / double(seen.size())));
    }
    d.second_bits = model_bits(MixingModel::second, d.symbols);
    write_cache(file, d);
    return d;
}

// The head of a study's markdown table (a design per row, a column per model); returns the
// paper's bits over all models, the rows' reference.
inline double print_design_table_head(const std::vector<ModelData>& data) {
    std::printf("| design | all | mean per model |");
    for (const ModelData& d : data) std::printf(" %s |", d.name.c_str());
    std::printf("\n|---|---:|---:|");
    for (size_t m = 0; m < data.size(); ++m) std::printf("---:|");
    std::printf("\n");
    double paper_total = 0;
    for (const ModelData& d : data) paper_total += d.paper_bits;
    return paper_total;
}

}  // namespace mixed_study
