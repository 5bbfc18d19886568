// Leaves of octree forests as VTU quads and hexahedra.
#include <amc/mesh_io.h>
#include <amc/octree.h>

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>

namespace amc {
namespace {

std::string written(const OctreeForest& forest, VtuEncoding encoding) {
    const std::string path =
        (std::filesystem::temp_directory_path() / ("amc_octree_vtu_" + std::to_string(::getpid()) + ".vtu")).string();
    write_octree_vtu(path, forest, encoding);
    std::ifstream in(path, std::ios::binary);
    std::stringstream text;
    text << in.rdbuf();
    std::filesystem::remove(path);
    return text.str();
}

TEST(OctreeVtu, KnownAnswerOfOneRefinedQuad) {
    const std::string text = written(uniform_octree_forest(brick_connectivity(2, 1, 1), 1), VtuEncoding::ascii);
    EXPECT_NE(text.find("NumberOfPoints=\"9\" NumberOfCells=\"4\""), std::string::npos) << text;
    // Leaves in Morton order, corners counter-clockwise, points numbered as first met.
    EXPECT_NE(text.find("0 1 2 3 1 4 5 2 3 2 6 7 2 5 8 6"), std::string::npos) << text;
    EXPECT_NE(text.find("9 9 9 9"), std::string::npos) << text;  // VTK_QUAD
    EXPECT_NE(text.find("Name=\"level\""), std::string::npos);
    EXPECT_NE(text.find("0.5 0.5 0"), std::string::npos);
}

TEST(OctreeVtu, HexahedraWithHangingNodes) {
    const OctreeForest forest =
        balance_octree_forest(sphere_octree_forest(brick_connectivity(3, 2, 1, 1), {1, 0.5, 0.5}, 0.4, 3), OctreeBalance::face);
    const std::string text = written(forest, VtuEncoding::ascii);
    EXPECT_NE(text.find("NumberOfCells=\"" + std::to_string(forest.leaves.size()) + "\""), std::string::npos);
    EXPECT_NE(text.find("12 12 12 12"), std::string::npos);  // VTK_HEXAHEDRON
    const std::string binary = written(forest, VtuEncoding::binary_zlib);
    EXPECT_NE(binary.find("AppendedData"), std::string::npos);
    EXPECT_LT(binary.size(), text.size());
}

}  // namespace
}  // namespace amc
