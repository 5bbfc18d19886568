// p4est interoperability (optional: AMC_WITH_P4EST, Debian's libp4est-dev): the functions of
// each dimension, which p4est_forest_2d.cpp and p4est_forest_3d.cpp build from one source.
#pragma once

#include <amc/octree.h>

#include <cstdint>
#include <string>
#include <vector>

namespace amc {

// MPI_Init (once, if nobody did; MPI_Finalize at exit) and p4est_init with errors-only logging.
void ensure_p4est_initialized();

void write_p4est_file_2d(const std::string& path, const OctreeForest& forest);
void write_p4est_file_3d(const std::string& path, const OctreeForest& forest);
OctreeForest read_p4est_file_2d(const std::string& path, uint32_t* checksum, const std::vector<Field>& data_layout);
OctreeForest read_p4est_file_3d(const std::string& path, uint32_t* checksum, const std::vector<Field>& data_layout);

// Leaf fields as p4est user data: per leaf, each field's tuple in field order, each value in its
// type's bytes, little-endian (the machine's order: p4est writes user data as it is in memory).
std::vector<uint8_t> pack_leaf_data(const std::vector<Field>& fields, size_t leaves);
// The inverse, for `layout` (names, types, components; without a layout one UInt8 field
// "p4est_data" of data_size components). Throws Error when the layout's bytes are not data_size.
std::vector<Field> unpack_leaf_data(const uint8_t* bytes, size_t leaves, size_t data_size, const std::vector<Field>& layout,
                                    const std::string& what);
void write_p4est_sphere_forest_2d(const std::string& path, const TreeConnectivity& conn, Vec3 center, double radius,
                                  int max_level, OctreeBalance balance);
void write_p4est_sphere_forest_3d(const std::string& path, const TreeConnectivity& conn, Vec3 center, double radius,
                                  int max_level, OctreeBalance balance);
void write_p4est_front_forest_2d(const std::string& path, const TreeConnectivity& conn, double t, int max_level, OctreeBalance balance);
void write_p4est_front_forest_3d(const std::string& path, const TreeConnectivity& conn, double t, int max_level, OctreeBalance balance);
// For benchmarks: the seconds p4est_save_ext and p4est_load_ext take on the forest (through `path`).
void time_p4est_save_load_2d(const OctreeForest& forest, const std::string& path, double* save_seconds, double* load_seconds);
void time_p4est_save_load_3d(const OctreeForest& forest, const std::string& path, double* save_seconds, double* load_seconds);
OctreeForest balanced_by_p4est_2d(const OctreeForest& forest, OctreeBalance balance);
OctreeForest balanced_by_p4est_3d(const OctreeForest& forest, OctreeBalance balance);
bool is_balanced_in_p4est_2d(const OctreeForest& forest, OctreeBalance balance);
bool is_balanced_in_p4est_3d(const OctreeForest& forest, OctreeBalance balance);
TreeConnectivity p4est_builtin_connectivity_2d(const std::string& name);
TreeConnectivity p4est_builtin_connectivity_3d(const std::string& name);
uint32_t p4est_checksum_of_2d(const OctreeForest& forest);
uint32_t p4est_checksum_of_3d(const OctreeForest& forest);

}  // namespace amc
