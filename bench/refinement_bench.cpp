// Throughput of the hierarchy stages in nodes per second at about 10^4, 10^5 and 10^6 nodes:
// uniform and random refinement, leaf-mesh extraction, the .amh file round trip, and
// curvature-adaptive surface remeshing. Each stage should be linear in the number of nodes, so
// nodes/s (the items_per_second column) should stay roughly flat across sizes.
//
// The benchmark argument is the target node count; the "nodes" counter reports the count
// actually reached, and items processed are those nodes, so Google Benchmark prints nodes/s.
#include <amc/hierarchy.h>
#include <amc/refinement.h>

#include <benchmark/benchmark.h>

#include <cstdint>
#include <map>
#include <string>

namespace {

constexpr uint64_t kSeed = 12345;
constexpr int kRandomMaxLevel = 12;

// ---- sizes ---------------------------------------------------------------------------------

// Uniform refinement multiplies the node count by about four per level, so sizes are matched by
// the base torus instead: nodes = triangles * (4^(levels+1) - 1) / 3 with 2 * rings * segments
// triangles; four levels give the factor 341.
struct UniformSetup {
    int rings, segments, levels;
};

UniformSetup uniform_setup(int64_t target_nodes) {
    if (target_nodes <= 10000) return {3, 5, 4};    //    30 triangles ->  10,230 nodes
    if (target_nodes <= 100000) return {12, 12, 4};  //   288 triangles ->  98,208 nodes
    return {36, 40, 4};                              // 2,880 triangles -> 982,080 nodes
}

amc::TriangleMesh uniform_base(const UniformSetup& s) {
    return amc::make_torus(s.rings, s.segments, 1.0, 0.35);
}

// Random refinement works on one base (a 768-triangle torus) at every size. A hierarchy with
// L leaves over R roots has (4L - R) / 3 nodes, so the leaf target for N nodes is (3N + R) / 4.
amc::TriangleMesh random_base() { return amc::make_torus(16, 24, 1.0, 0.35); }

uint32_t leaves_for_nodes(int64_t target_nodes, uint32_t roots) {
    return static_cast<uint32_t>((3 * target_nodes + roots) / 4);
}

amc::Hierarchy make_random_hierarchy(int64_t target_nodes) {
    amc::Hierarchy h(random_base());
    amc::refine_randomly(h, leaves_for_nodes(target_nodes, h.root_count()), kRandomMaxLevel, kSeed);
    return h;
}

// Hierarchies for the extraction and file benchmarks, built once per size outside the timing.
const amc::Hierarchy& prebuilt_hierarchy(int64_t target_nodes) {
    static std::map<int64_t, amc::Hierarchy> cache;
    auto it = cache.find(target_nodes);
    if (it == cache.end()) {
        it = cache.emplace(target_nodes, make_random_hierarchy(target_nodes)).first;
    }
    return it->second;
}

void report_nodes(benchmark::State& state, uint32_t nodes) {
    state.SetItemsProcessed(state.iterations() * int64_t(nodes));
    state.counters["nodes"] = nodes;
}

// ---- benchmarks ----------------------------------------------------------------------------

// Builds the forest over the base and refines every leaf `levels` times.
void BM_UniformRefinement(benchmark::State& state) {
    const UniformSetup setup = uniform_setup(state.range(0));
    const amc::TriangleMesh base = uniform_base(setup);
    uint32_t nodes = 0;
    for (auto _ : state) {
        amc::Hierarchy h(base);
        amc::refine_uniformly(h, setup.levels);
        nodes = h.node_count();
        benchmark::DoNotOptimize(nodes);
    }
    report_nodes(state, nodes);
    state.counters["levels"] = setup.levels;
}

// Builds the forest and refines random leaves (with balancing and closure) to the leaf target.
void BM_RandomRefinement(benchmark::State& state) {
    const amc::TriangleMesh base = random_base();
    uint32_t nodes = 0, leaves = 0;
    for (auto _ : state) {
        amc::Hierarchy h(base);
        const uint32_t target_leaves = leaves_for_nodes(state.range(0), h.root_count());
        amc::refine_randomly(h, target_leaves, kRandomMaxLevel, kSeed);
        nodes = h.node_count();
        leaves = h.leaf_count();
        benchmark::DoNotOptimize(nodes);
    }
    report_nodes(state, nodes);
    state.counters["leaves"] = leaves;
}

// The conforming leaf mesh with green closure, of a randomly refined hierarchy.
void BM_LeafMeshExtraction(benchmark::State& state) {
    const amc::Hierarchy& h = prebuilt_hierarchy(state.range(0));
    size_t faces = 0;
    for (auto _ : state) {
        amc::LeafMesh leaf = amc::extract_leaf_mesh(h);
        faces = leaf.mesh.triangles.size();
        benchmark::DoNotOptimize(leaf);
    }
    report_nodes(state, h.node_count());
    state.counters["faces"] = double(faces);
}

// Writes the hierarchy to .amh bytes and reads them back (with full validation).
void BM_HierarchyFileRoundTrip(benchmark::State& state) {
    const amc::Hierarchy& h = prebuilt_hierarchy(state.range(0));
    size_t bytes = 0;
    for (auto _ : state) {
        const std::string file = amc::serialize_hierarchy(h);
        amc::Hierarchy back = amc::deserialize_hierarchy(file, "benchmark");
        bytes = file.size();
        benchmark::DoNotOptimize(back);
    }
    report_nodes(state, h.node_count());
    state.counters["bytes"] = double(bytes);
    state.SetBytesProcessed(state.iterations() * int64_t(bytes));
}

// Curvature-adaptive remeshing of the bumpy sphere (81,920 triangles): simplification to the
// base, greedy refinement, projection of new vertices onto the reference. Argument: target faces.
void BM_SurfaceRemeshing(benchmark::State& state) {
    static const amc::TriangleMesh reference = amc::make_bumpy_sphere(6);
    amc::SurfaceRemeshOptions options;
    options.target_faces = static_cast<uint32_t>(state.range(0));
    uint32_t nodes = 0;
    amc::SurfaceRemeshStats stats;
    for (auto _ : state) {
        amc::Hierarchy h = amc::remesh_adaptively(reference, options, &stats);
        nodes = h.node_count();
        benchmark::DoNotOptimize(nodes);
    }
    report_nodes(state, nodes);
    state.counters["simplify_ms"] = stats.simplify_seconds * 1e3;
    state.counters["refine_ms"] = stats.refine_seconds * 1e3;
}

// Node-count sizes; MinTime keeps the whole program at about half a minute on two cores.
void node_sizes(benchmark::internal::Benchmark* b) {
    b->Arg(10000)->Arg(100000)->Arg(1000000)->Unit(benchmark::kMillisecond)->MinTime(0.5);
}

}  // namespace

BENCHMARK(BM_UniformRefinement)->Apply(node_sizes);
BENCHMARK(BM_RandomRefinement)->Apply(node_sizes);
BENCHMARK(BM_LeafMeshExtraction)->Apply(node_sizes);
BENCHMARK(BM_HierarchyFileRoundTrip)->Apply(node_sizes);
BENCHMARK(BM_SurfaceRemeshing)
    ->Arg(10000)->Arg(100000)->Unit(benchmark::kMillisecond)->Iterations(3);

BENCHMARK_MAIN();
