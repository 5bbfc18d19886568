// p4est interoperability (optional: AMC_WITH_P4EST, Debian's libp4est-dev): the functions of
// each dimension, which p4est_forest_2d.cpp and p4est_forest_3d.cpp build from one source.
#pragma once

#include <amc/octree.h>

#include <cstdint>
#include <string>

namespace amc {

// MPI_Init (once, if nobody did; MPI_Finalize at exit) and p4est_init with errors-only logging.
void ensure_p4est_initialized();

void write_p4est_file_2d(const std::string& path, const OctreeForest& forest);
void write_p4est_file_3d(const std::string& path, const OctreeForest& forest);
OctreeForest read_p4est_file_2d(const std::string& path, uint32_t* checksum);
OctreeForest read_p4est_file_3d(const std::string& path, uint32_t* checksum);
void write_p4est_sphere_forest_2d(const std::string& path, const TreeConnectivity& conn, Vec3 center, double radius,
                                  int max_level, OctreeBalance balance);
void write_p4est_sphere_forest_3d(const std::string& path, const TreeConnectivity& conn, Vec3 center, double radius,
                                  int max_level, OctreeBalance balance);
// For benchmarks: the seconds p4est_save_ext and p4est_load_ext take on the forest (through `path`).
void time_p4est_save_load_2d(const OctreeForest& forest, const std::string& path, double* save_seconds, double* load_seconds);
void time_p4est_save_load_3d(const OctreeForest& forest, const std::string& path, double* save_seconds, double* load_seconds);
uint32_t p4est_checksum_of_2d(const OctreeForest& forest);
uint32_t p4est_checksum_of_3d(const OctreeForest& forest);

}  // namespace amc
