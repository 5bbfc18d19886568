// Golden .amc files: the bytes of version 2 are pinned. A change that alters the bitstream fails
// here; if it is deliberate, bump the format version, update docs/FORMAT.md, and regenerate with
// AMC_UPDATE_GOLDEN=1 ./amc_tests --gtest_filter='Golden*' (in the same commit).
#include "hierarchy_checks.h"

#include <amc/codec.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iterator>

namespace amc {
namespace {

struct GoldenCase {
    std::string name;
    Hierarchy hierarchy;
    EncodeOptions options;
};

std::vector<GoldenCase> golden_cases() {
    std::vector<GoldenCase> cases;
    {
        Hierarchy h(make_icosahedron());
        refine_uniformly(h, 2);
        cases.push_back({"icosahedron_uniform2", h, {}});
    }
    {
        Hierarchy h(make_l_shape(2));
        refine_to_size(h, [](Vec3 x) { return 0.2 * std::sqrt(x.x * x.x + x.y * x.y) + 0.01; }, 6);
        cases.push_back({"lshape_graded", h, {}});
    }
    {
        Hierarchy h(make_bumpy_sphere(0));  // float32 coordinates
        refine_randomly(h, 400, 4, 11);
        int k = 0;
        for (NodeId n : h.leaves()) {
            if (h.hanging_node_count(n) == 2 && (k++ % 3) == 0) h.set_diagonal_flipped(n, true);
        }
        cases.push_back({"bumpy_random_float32", h, {}});
        EncodeOptions quantized;
        quantized.quantize_bits = 12;
        cases.push_back({"bumpy_random_q12", h, quantized});
    }
    {
        Hierarchy h(make_torus(6, 5, 2.0, 0.7));
        refine_randomly(h, 300, 3, 5);
        EncodeOptions naive;
        naive.hierarchy.traversal = Traversal::naive;
        naive.hierarchy.use_contexts = false;
        naive.predictor = GeometryPredictor::butterfly;
        cases.push_back({"torus_naive_butterfly", h, naive});
    }
    return cases;
}

std::string golden_path(const std::string& name) { return std::string(AMC_TEST_DATA_DIR) + "/golden/" + name + ".amc"; }

TEST(Golden, EncodingsMatchTheGoldenFiles) {
    const bool update = std::getenv("AMC_UPDATE_GOLDEN") != nullptr;
    for (const GoldenCase& c : golden_cases()) {
        const std::vector<uint8_t> bytes = encode(c.hierarchy, c.options);
        if (update) {
            std::ofstream(golden_path(c.name), std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
        }
        std::ifstream file(golden_path(c.name), std::ios::binary);
        ASSERT_TRUE(file) << golden_path(c.name) << " is missing";
        const std::vector<uint8_t> golden((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
        EXPECT_EQ(bytes, golden) << c.name << ": the bitstream changed";
        // The golden file decodes, and inspect() sees the blocks FORMAT.md describes.
        const Hierarchy back = decode(golden.data(), golden.size());
        EXPECT_EQ(back.node_count(), c.hierarchy.node_count()) << c.name;
        const FileInfo info = inspect(golden.data(), golden.size());
        EXPECT_EQ(info.version, 2);
        EXPECT_EQ(info.quantize_bits, c.options.quantize_bits);
        EXPECT_EQ(info.single_precision, c.hierarchy.single_precision() && c.options.quantize_bits == 0);
        ASSERT_EQ(info.blocks.size(), size_t(4 + info.levels)) << "metadata, base connectivity, base geometry, levels, end";
        EXPECT_EQ(info.blocks[0].name, "metadata");
        EXPECT_EQ(info.blocks[1].name, "base connectivity");
        EXPECT_EQ(info.blocks[2].name, "base geometry");
        for (int l = 0; l < info.levels; ++l) EXPECT_EQ(info.blocks[size_t(3 + l)].level, l);
        EXPECT_EQ(info.blocks.back().name, "end");
        if (c.options.quantize_bits == 0) {
            EXPECT_TRUE(identical(back, in_decoder_order(c.hierarchy))) << c.name;
        }
    }
}

}  // namespace
}  // namespace amc
