// import_leaf_mesh throughput in leaf faces per second (docs/IMPORT.md, "Speed"): the leaf
// meshes of the bench models (surface, random, fe) at about 10^4, 10^5 and 10^6 nodes (10^4: the
// refusal's growth with size, docs/IMPORT.md "Complexity and speed"), vertices and
// faces shuffled, with new vertices at their midpoints (the exact path) or moved off them (the
// connectivity paths); and the semi-regular bunny of ../shared/data when it is there.
//
// Usage: import_bench [repetitions [filter]]   (default 5; prints the median and the range of the
// runs; with a filter, only the cases whose name holds it)
// Times are the thread's CPU time, which the other jobs on a shared machine disturb less.
#include "bench_common.h"
#include "user_leaf_mesh.h"

#include <amc/import.h>
#include <amc/mesh_io.h>

#include <cstdio>
#include <ctime>
#include <cstdlib>
#include <filesystem>
#include <numeric>
#include <string>
#include <vector>

namespace {

void run(const char* name, const amc::TriangleMesh& base, const amc::TriangleMesh& leaf, int repetitions) {
    std::vector<double> rates;
    for (int r = 0; r < repetitions; ++r) {
        const double start = thread_seconds();
        try {
            const amc::ImportedHierarchy imported = amc::import_leaf_mesh(base, leaf);
            if (imported.vertex_of_input.size() != leaf.positions.size()) std::abort();
        } catch (const amc::Error& e) {
            std::printf("%-34s %9zu faces  refused after %.2f s: %.60s...\n", name, leaf.triangles.size(),
                        thread_seconds() - start, e.what());
            return;
        }
        rates.push_back(double(leaf.triangles.size()) / (thread_seconds() - start));
    }
    std::sort(rates.begin(), rates.end());
    std::printf("%-34s %9zu faces  %6.2f M faces/s  (runs %.2f-%.2f)\n", name, leaf.triangles.size(),
                median(rates) * 1e-6, rates.front() * 1e-6, rates.back() * 1e-6);
    std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
    const int repetitions = argc > 1 ? std::max(1, std::atoi(argv[1])) : 5;
    const std::string filter = argc > 2 ? argv[2] : "";
    auto wanted = [&](const std::string& name) { return name.find(filter) != std::string::npos; };
    const char* names[] = {"surface", "random", "fe"};
    for (int64_t nodes : {int64_t(10000), int64_t(100000), int64_t(1000000)}) {
        for (int model = 0; model < 3; ++model) {
            const std::string model_name = std::string(names[model]) + " " + std::to_string(nodes / 1000) + "k nodes";
            if (!wanted(model_name + ", midpoints") && !wanted(model_name + ", moved")) continue;
            const amc::Hierarchy h = make_bench_hierarchy(BenchModel(model), nodes);
            const amc::LeafMesh leaf = amc::extract_leaf_mesh(h);
            const uint32_t v0 = uint32_t(h.base().positions.size());
            for (double move : {0.0, 0.3}) {
                const std::string name = std::string(names[model]) + " " + std::to_string(nodes / 1000) + "k nodes" +
                                         (move > 0 ? ", moved" : ", midpoints");
                if (!wanted(name)) continue;
                run(name.c_str(), h.base(), bench::user_leaf_mesh(leaf.mesh, v0, move, 17), repetitions);
            }
        }
    }
    const std::string data = std::string(AMC_SHARED_DATA_DIR);
    if (!wanted("bunny-sr-l3 (uniform, projected)")) return 0;
    if (std::filesystem::exists(data + "/bunny-sr-l3.obj")) {
        const amc::TriangleMesh base = amc::read_mesh(data + "/bunny-sr-l0.obj");
        const amc::TriangleMesh leaf = amc::read_mesh(data + "/bunny-sr-l3.obj");
        run("bunny-sr-l3 (uniform, projected)", base, bench::user_leaf_mesh(leaf, 0, 0.0, 17), repetitions);
    } else {
        std::printf("(%s/bunny-sr-l3.obj not found: semi-regular case skipped)\n", data.c_str());
    }
    return 0;
}
