// p4est files and checksums for octree forests: dispatch by dimension, MPI and p4est set up once;
// without AMC_WITH_P4EST every call says so.
#include "common/check.h"
#include "octree/p4est_forest.h"

#include <cstdio>
#include <cstdlib>
#include <cstring>

#ifdef AMC_HAVE_P4EST
#include <p4est_base.h>
#endif

namespace amc {

#ifdef AMC_HAVE_P4EST

void ensure_p4est_initialized() {
    static const bool done = [] {
        int initialized = 0;
        MPI_Initialized(&initialized);
        if (!initialized) {
            MPI_Init(nullptr, nullptr);
            std::atexit([] {
                int finalized = 0;
                MPI_Finalized(&finalized);
                if (!finalized) MPI_Finalize();
            });
        }
        p4est_init(nullptr, SC_LP_ERROR);
        return true;
    }();
    (void)done;
}

bool octree_p4est_available() { return true; }

namespace {

// p4est_save files start with the connectivity, whose first bytes name the dimension.
int p4est_file_dim(const std::string& path) {
    std::FILE* f = std::fopen(path.c_str(), "rb");
    AMC_REQUIRE(f, io, path + ": can not open");
    char magic[8] = {};
    const size_t got = std::fread(magic, 1, sizeof magic, f);
    std::fclose(f);
    AMC_REQUIRE(got == sizeof magic, truncated, path + ": too short for a p4est file");
    if (std::memcmp(magic, "p4est", 5) == 0) return 2;
    if (std::memcmp(magic, "p8est", 5) == 0) return 3;
    throw_error(ErrorCode::bad_magic, path + ": not a p4est file");
}

}  // namespace

OctreeForest read_p4est_file(const std::string& path, uint32_t* checksum) {
    const int dim = p4est_file_dim(path);
    OctreeForest forest = dim == 2 ? read_p4est_file_2d(path, checksum) : read_p4est_file_3d(path, checksum);
    validate_octree_forest(forest, path);
    return forest;
}

void write_p4est_file(const std::string& path, const OctreeForest& forest) {
    validate_octree_forest(forest, path);
    if (forest.dim() == 2) write_p4est_file_2d(path, forest);
    else write_p4est_file_3d(path, forest);
}

uint32_t octree_p4est_checksum(const OctreeForest& forest) {
    validate_octree_forest(forest, "octree_p4est_checksum");
    return forest.dim() == 2 ? p4est_checksum_of_2d(forest) : p4est_checksum_of_3d(forest);
}

void write_p4est_sphere_forest(const std::string& path, const TreeConnectivity& conn, Vec3 center, double radius, int max_level,
                               OctreeBalance balance) {
    validate_connectivity(conn, path);
    if (conn.dim == 2) write_p4est_sphere_forest_2d(path, conn, center, radius, max_level, balance);
    else write_p4est_sphere_forest_3d(path, conn, center, radius, max_level, balance);
}

#else

namespace {
[[noreturn]] void unavailable() {
    throw_error(ErrorCode::invalid_input, "amcodec was built without p4est (cmake -DAMC_WITH_P4EST=ON, Debian's libp4est-dev)");
}
}  // namespace

bool octree_p4est_available() { return false; }
OctreeForest read_p4est_file(const std::string&, uint32_t*) { unavailable(); }
void write_p4est_file(const std::string&, const OctreeForest&) { unavailable(); }
uint32_t octree_p4est_checksum(const OctreeForest&) { unavailable(); }
void write_p4est_sphere_forest(const std::string&, const TreeConnectivity&, Vec3, double, int, OctreeBalance) { unavailable(); }

#endif

}  // namespace amc
