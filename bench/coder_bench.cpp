// Hierarchy coder throughput, single thread, in nodes per second (items_per_second): encode and
// decode of curvature-adaptive hierarchies of the procedural surface and of random hierarchies,
// at about 10^5 and 10^6 nodes. The hierarchies are built once, outside the timing.
#include <amc/hierarchy_coder.h>
#include <amc/refinement.h>

#include <benchmark/benchmark.h>

#include <map>
#include <utility>

namespace {

enum Model { surface = 0, random_forest = 1 };

const amc::Hierarchy& hierarchy(Model model, int64_t target_nodes) {
    static std::map<std::pair<int, int64_t>, amc::Hierarchy> cache;
    auto key = std::make_pair(int(model), target_nodes);
    auto it = cache.find(key);
    if (it != cache.end()) return it->second;
    amc::Hierarchy h;
    if (model == surface) {
        amc::SurfaceRemeshOptions options;
        options.base_triangles = 500;
        options.max_level = 8;
        options.target_faces = uint32_t(target_nodes * 3 / 4);
        h = amc::remesh_adaptively(amc::make_bumpy_sphere(6), options);
    } else {
        h = amc::Hierarchy(amc::make_torus(16, 24, 1.0, 0.35));
        amc::refine_randomly(h, uint32_t(target_nodes * 3 / 4), 12, 7);
    }
    return cache.emplace(key, std::move(h)).first->second;
}

void BM_Encode(benchmark::State& state) {
    const amc::Hierarchy& h = hierarchy(Model(state.range(0)), state.range(1));
    size_t bytes = 0;
    for (auto _ : state) {
        std::vector<uint8_t> out = amc::encode_hierarchy(h);
        bytes = out.size();
        benchmark::DoNotOptimize(out.data());
    }
    state.SetItemsProcessed(int64_t(state.iterations()) * h.node_count());
    state.counters["nodes"] = h.node_count();
    state.counters["bytes"] = double(bytes);
    state.counters["bits_per_node"] = 8.0 * double(bytes) / h.node_count();
}

void BM_Decode(benchmark::State& state) {
    const amc::Hierarchy& h = hierarchy(Model(state.range(0)), state.range(1));
    const std::vector<uint8_t> bytes = amc::encode_hierarchy(h);
    for (auto _ : state) {
        amc::Hierarchy decoded = amc::decode_hierarchy(h.base(), bytes.data(), bytes.size());
        benchmark::DoNotOptimize(decoded.node_count());
    }
    state.SetItemsProcessed(int64_t(state.iterations()) * h.node_count());
    state.counters["nodes"] = h.node_count();
}

void sizes(benchmark::internal::Benchmark* b) {
    for (int model : {surface, random_forest}) {
        for (int64_t nodes : {100000, 1000000}) b->Args({model, nodes});
    }
    b->ArgNames({"model(0=surface,1=random)", "nodes"})->Unit(benchmark::kMillisecond)->MinTime(0.5);
}

BENCHMARK(BM_Encode)->Apply(sizes);
BENCHMARK(BM_Decode)->Apply(sizes);

}  // namespace

BENCHMARK_MAIN();
