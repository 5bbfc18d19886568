// p4est interoperability (built with -DAMC_WITH_P4EST=ON; skipped otherwise): forests that p4est
// itself refines and balances, over bricks and turned bricks, go p4est_save -> amc -> p4est_save
// with p4est's checksum unchanged.
#include "octree_test_util.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <unistd.h>

namespace amc {
namespace {

std::string temp_path(const std::string& name) {
    return (std::filesystem::temp_directory_path() / ("amc_octree_p4est_" + std::to_string(::getpid()) + "_" + name)).string();
}

TEST(OctreeP4est, ForestsMadeByP4estRoundTripWithItsChecksum) {
    if (!octree_p4est_available()) GTEST_SKIP() << "built without p4est (cmake -DAMC_WITH_P4EST=ON, libp4est-dev)";
    std::mt19937_64 rng(8);
    int round = 0;
    for (int dim : {2, 3}) {
        for (OctreeBalance balance : {OctreeBalance::face, OctreeBalance::corner}) {
            for (bool turned : {false, true}) {
                const TreeConnectivity conn = turned ? octree_test::turned_brick(dim, 2, 2, 2, rng) : brick_connectivity(dim, 3, 2, 2);
                const std::string made = temp_path(std::to_string(round) + "_p4est.p4est");
                const std::string again = temp_path(std::to_string(round++) + "_amc.p4est");
                write_p4est_sphere_forest(made, conn, {1.1, 0.9, dim == 3 ? 0.8 : 0.0}, 0.7, dim == 2 ? 8 : 5, balance);
                uint32_t checksum = 0;
                const OctreeForest forest = read_p4est_file(made, &checksum);
                EXPECT_GT(forest.leaves.size(), dim == 2 ? 500u : 2000u);
                EXPECT_EQ(octree_balance_violation(forest, OctreeBalance::face), "");
                const std::vector<uint8_t> bytes = encode_octree_forest(forest);
                const OctreeForest decoded = decode_octree_forest(bytes.data(), bytes.size());
                ASSERT_TRUE(decoded == forest);
                EXPECT_EQ(octree_p4est_checksum(decoded), checksum);
                write_p4est_file(again, decoded);
                uint32_t checksum_again = 0;
                EXPECT_TRUE(read_p4est_file(again, &checksum_again) == forest);
                EXPECT_EQ(checksum_again, checksum);
                EXPECT_EQ(std::filesystem::file_size(again), std::filesystem::file_size(made));
                std::filesystem::remove(made);
                std::filesystem::remove(again);
            }
        }
    }
}

// p4est's face balance and ours agree: both are the smallest balanced refinement. (Both refine by
// the same sphere test, each with its own arithmetic: centre and radius keep clear of exact ties.)
TEST(OctreeP4est, FaceBalanceAgreesWithP4est) {
    if (!octree_p4est_available()) GTEST_SKIP() << "built without p4est (cmake -DAMC_WITH_P4EST=ON, libp4est-dev)";
    std::mt19937_64 rng(9);
    for (int dim : {2, 3}) {
        const TreeConnectivity conn = octree_test::turned_brick(dim, 2, 2, 2, rng);
        const std::string path = temp_path("balance.p4est");
        write_p4est_sphere_forest(path, conn, {0.9137, 1.2291, dim == 3 ? 1.1071 : 0.0}, 0.5173, dim == 2 ? 9 : 5, OctreeBalance::face);
        const OctreeForest p4est_balanced = read_p4est_file(path);
        std::filesystem::remove(path);
        const OctreeForest ours = balance_octree_forest(sphere_octree_forest(conn, {0.9137, 1.2291, dim == 3 ? 1.1071 : 0.0}, 0.5173, dim == 2 ? 9 : 5),
                                                        OctreeBalance::face);
        EXPECT_EQ(ours.leaves.size(), p4est_balanced.leaves.size());
        EXPECT_TRUE(ours == p4est_balanced) << "dim " << dim;
    }
}

TEST(OctreeP4est, WithoutP4estEveryCallSaysSo) {
    if (octree_p4est_available()) GTEST_SKIP() << "built with p4est";
    EXPECT_THROW(read_p4est_file("x.p4est"), Error);
    EXPECT_THROW(write_p4est_file("x.p4est", uniform_octree_forest(brick_connectivity(2, 1, 1), 1)), Error);
}

}  // namespace
}  // namespace amc
