// Hierarchy coder throughput, single thread, in nodes per second (items_per_second): encode,
// decode into a new Hierarchy, and decode reusing one decoder and its target hierarchy, of
// curvature-adaptive hierarchies of the procedural surface, of random hierarchies and of graded
// planar finite-element hierarchies, at about 10^5 and 10^6 nodes. The hierarchies are built
// once, outside the timing.
#include "bench_common.h"

#include <amc/hierarchy_coder.h>

#include <benchmark/benchmark.h>

#include <map>
#include <utility>

namespace {

const amc::Hierarchy& hierarchy(BenchModel model, int64_t target_nodes) {
    static std::map<std::pair<int, int64_t>, amc::Hierarchy> cache;
    auto key = std::make_pair(int(model), target_nodes);
    auto it = cache.find(key);
    if (it != cache.end()) return it->second;
    return cache.emplace(key, make_bench_hierarchy(model, target_nodes)).first->second;
}

void BM_Encode(benchmark::State& state) {
    const amc::Hierarchy& h = hierarchy(BenchModel(state.range(0)), state.range(1));
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
    const amc::Hierarchy& h = hierarchy(BenchModel(state.range(0)), state.range(1));
    const std::vector<uint8_t> bytes = amc::encode_hierarchy(h);
    for (auto _ : state) {
        amc::Hierarchy decoded = amc::decode_hierarchy(h.base(), bytes.data(), bytes.size());
        benchmark::DoNotOptimize(decoded.node_count());
    }
    state.SetItemsProcessed(int64_t(state.iterations()) * h.node_count());
    state.counters["nodes"] = h.node_count();
}

// Stream after stream into the same hierarchy with one decoder (HierarchyDecoder): no fresh memory.
void BM_DecodeReusing(benchmark::State& state) {
    const amc::Hierarchy& h = hierarchy(BenchModel(state.range(0)), state.range(1));
    const std::vector<uint8_t> bytes = amc::encode_hierarchy(h);
    amc::HierarchyDecoder decoder;
    amc::Hierarchy decoded;
    for (auto _ : state) {
        decoder.decode(h.base(), bytes.data(), bytes.size(), decoded);
        benchmark::DoNotOptimize(decoded.node_count());
    }
    state.SetItemsProcessed(int64_t(state.iterations()) * h.node_count());
    state.counters["nodes"] = h.node_count();
}

void sizes(benchmark::internal::Benchmark* b) {
    for (BenchModel model : {BenchModel::surface, BenchModel::random, BenchModel::fe}) {
        for (int64_t nodes : {100000, 1000000}) b->Args({int64_t(model), nodes});
    }
    b->ArgNames({"model(0=surface,1=random,2=fe)", "nodes"})->Unit(benchmark::kMillisecond)->MinTime(0.5);
}

BENCHMARK(BM_Encode)->Apply(sizes);
BENCHMARK(BM_Decode)->Apply(sizes);
BENCHMARK(BM_DecodeReusing)->Apply(sizes);

}  // namespace

BENCHMARK_MAIN();
