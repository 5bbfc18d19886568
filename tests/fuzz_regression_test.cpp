// Every input a fuzzer found a problem with (tests/data/fuzz-regressions/<target>/, named after
// the finding) runs through its target again, as do the golden files through the .amc targets
// (all of them) and the series, octree and .amh targets (.amcs, .amq, .amh): a crash, sanitizer report,
// uncaught exception or violated property fails the test.
#include "fuzz_targets.h"

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace amc {
namespace {

namespace fs = std::filesystem;

std::vector<uint8_t> read_bytes(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    return std::vector<uint8_t>((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

class FuzzRegressions : public ::testing::TestWithParam<fuzz::Target> {};

TEST_P(FuzzRegressions, EveryFoundInputPasses) {
    const fuzz::Target target = GetParam();
    std::vector<fs::path> inputs;
    const fs::path data = AMC_TEST_DATA_DIR;
    const fs::path regressions = data / "fuzz-regressions" / target.name;
    if (fs::is_directory(regressions))
        for (const auto& entry : fs::directory_iterator(regressions)) inputs.push_back(entry.path());
    const std::string name = target.name;
    const std::string golden_extension = name == "series_read" || name == "forest_series_read" ? ".amcs"
                                         : name == "octree_decode"                              ? ".amq"
                                         : name == "amh_read"                                   ? ".amh"
                                                                                                : "";
    const size_t found_inputs = inputs.size();  // the golden files after them are timed by no one here
    if (name.rfind("amc_", 0) == 0 || !golden_extension.empty())
        for (const auto& entry : fs::recursive_directory_iterator(data / "golden"))
            if (entry.is_regular_file() && (golden_extension.empty() || entry.path().extension() == golden_extension))
                inputs.push_back(entry.path());
    target.run(nullptr, 0);
    for (size_t i = 0; i < inputs.size(); ++i) {
        const fs::path& input = inputs[i];
        SCOPED_TRACE(input.string());
        const std::vector<uint8_t> bytes = read_bytes(input);
        const auto start = std::chrono::steady_clock::now();
        target.run(bytes.data(), bytes.size());
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        if (i < found_inputs) {
            EXPECT_LT(seconds, 5.0) << "slow input (a found input runs in milliseconds)";
        }
    }
}

// Every seed of a target passes it (its properties and oracles), on every build.
void replay_seeds(const std::vector<std::vector<uint8_t>>& seeds, void (*target)(const uint8_t*, size_t)) {
    EXPECT_GE(seeds.size(), 3u);
    for (size_t i = 0; i < seeds.size(); ++i) {
        SCOPED_TRACE("seed " + std::to_string(i));
        target(seeds[i].data(), seeds[i].size());
    }
}

// The closest-point target's seeds (a fan, a far component, a translated lattice, fans at 2^-1000
// and 2^1000): every answer of ClosestPointQuery equals the brute-force loop's.
TEST(FuzzSeeds, ClosestPointSeedsMatchBruteForce) { replay_seeds(fuzz::closest_point_seeds(), fuzz::closest_point); }

// The nearest-vertex target's seeds (a lattice, copies of a point, a cluster beside an outlier,
// tiny and huge scales, a graded box): every answer of NearestVertex as the target's oracles want.
TEST(FuzzSeeds, NearestVertexSeedsPassTheOracles) { replay_seeds(fuzz::nearest_vertex_seeds(), fuzz::nearest_vertex); }

INSTANTIATE_TEST_SUITE_P(All, FuzzRegressions, ::testing::ValuesIn(fuzz::targets()),
                         [](const ::testing::TestParamInfo<fuzz::Target>& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace amc
