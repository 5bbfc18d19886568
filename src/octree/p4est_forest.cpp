// p4est files and checksums for octree forests: dispatch by dimension, MPI and p4est set up once;
// without AMC_WITH_P4EST every call says so.
#include "common/check.h"
#include "octree/octree_leaf_data.h"
#include "octree/p4est_forest.h"

#include <cstdio>
#include <cstdlib>
#include <cstring>

#ifdef AMC_HAVE_P4EST
#include <p4est_base.h>
#endif

namespace amc {

std::vector<uint8_t> pack_leaf_data(const std::vector<Field>& fields, size_t leaves) {
    const size_t size = octree_leaf_data_bytes(fields);
    std::vector<uint8_t> out(size * leaves);
    size_t offset = 0;  // of the field within a leaf's bytes
    for (const Field& f : fields) {
        const size_t bytes = field_type_bytes(f.type);
        for (size_t i = 0; i < leaves; ++i)
            for (uint32_t c = 0; c < f.components; ++c) {
                uint8_t* to = out.data() + i * size + offset + c * bytes;
                const size_t k = i * f.components + c;
                if (f.type == FieldType::float32) {
                    const float v = float(f.values[k]);
                    std::memcpy(to, &v, 4);
                } else if (f.type == FieldType::float64) {
                    std::memcpy(to, &f.values[k], 8);
                } else {
                    const uint64_t v = uint64_t(f.integers[k]);
                    for (size_t b = 0; b < bytes; ++b) to[b] = uint8_t(v >> (8 * b));
                }
            }
        offset += bytes * f.components;
    }
    return out;
}

std::vector<Field> unpack_leaf_data(const uint8_t* bytes, size_t leaves, size_t data_size, const std::vector<Field>& layout,
                                    const std::string& what) {
    std::vector<Field> fields;
    if (layout.empty()) {
        Field f;
        f.name = "p4est_data";
        f.association = FieldAssociation::cell;
        f.type = FieldType::uint8;
        f.components = uint32_t(data_size);
        fields.push_back(f);
    } else {
        for (const Field& l : layout) {
            Field f;
            f.name = l.name;
            f.association = FieldAssociation::cell;
            f.type = l.type;
            f.components = l.components;
            AMC_REQUIRE(uint8_t(f.type) <= uint8_t(FieldType::float64) && f.components >= 1, invalid_input,
                        what + ": the data layout's field \"" + f.name + "\" has no valid type or components");
            fields.push_back(f);
        }
    }
    AMC_REQUIRE(octree_leaf_data_bytes(fields) == data_size, invalid_input,
                what + ": the file holds " + std::to_string(data_size) + " bytes of data per quadrant, the data layout " +
                    std::to_string(octree_leaf_data_bytes(fields)));
    size_t offset = 0;
    for (Field& f : fields) {
        const size_t width = field_type_bytes(f.type);
        const bool is_signed = f.type == FieldType::int8 || f.type == FieldType::int16 || f.type == FieldType::int32;
        for (size_t i = 0; i < leaves; ++i)
            for (uint32_t c = 0; c < f.components; ++c) {
                const uint8_t* from = bytes + i * data_size + offset + c * width;
                if (f.type == FieldType::float32) {
                    float v;
                    std::memcpy(&v, from, 4);
                    f.values.push_back(double(v));
                } else if (f.type == FieldType::float64) {
                    double v;
                    std::memcpy(&v, from, 8);
                    f.values.push_back(v);
                } else {
                    uint64_t v = 0;
                    for (size_t b = 0; b < width; ++b) v |= uint64_t(from[b]) << (8 * b);
                    if (is_signed && width < 8 && (v >> (8 * width - 1)) & 1) v |= ~uint64_t{0} << (8 * width);  // sign-extend
                    f.integers.push_back(int64_t(v));
                }
            }
        offset += width * f.components;
    }
    validate_leaf_fields(fields, leaves, what);
    return fields;
}

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

OctreeForest read_p4est_file(const std::string& path, uint32_t* checksum, const std::vector<Field>& data_layout) {
    const int dim = p4est_file_dim(path);
    OctreeForest forest = dim == 2 ? read_p4est_file_2d(path, checksum, data_layout) : read_p4est_file_3d(path, checksum, data_layout);
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

void write_p4est_front_forest(const std::string& path, const TreeConnectivity& conn, double t, int max_level, OctreeBalance balance) {
    validate_connectivity(conn, path);
    if (conn.dim == 2) write_p4est_front_forest_2d(path, conn, t, max_level, balance);
    else write_p4est_front_forest_3d(path, conn, t, max_level, balance);
}

OctreeForest balanced_by_p4est(const OctreeForest& forest, OctreeBalance balance) {
    validate_octree_forest(forest, "balanced_by_p4est");
    return forest.dim() == 2 ? balanced_by_p4est_2d(forest, balance) : balanced_by_p4est_3d(forest, balance);
}

bool is_balanced_in_p4est(const OctreeForest& forest, OctreeBalance balance) {
    validate_octree_forest(forest, "is_balanced_in_p4est");
    return forest.dim() == 2 ? is_balanced_in_p4est_2d(forest, balance) : is_balanced_in_p4est_3d(forest, balance);
}

TreeConnectivity p4est_builtin_connectivity(int dim, const std::string& name) {
    AMC_REQUIRE(dim == 2 || dim == 3, invalid_input, "p4est_builtin_connectivity: dimension " + std::to_string(dim));
    TreeConnectivity conn = dim == 2 ? p4est_builtin_connectivity_2d(name) : p4est_builtin_connectivity_3d(name);
    validate_connectivity(conn, "p4est connectivity " + name);
    return conn;
}

#else

namespace {
[[noreturn]] void unavailable() {
    throw_error(ErrorCode::invalid_input, "amcodec was built without p4est (cmake -DAMC_WITH_P4EST=ON, Debian's libp4est-dev)");
}
}  // namespace

bool octree_p4est_available() { return false; }
OctreeForest read_p4est_file(const std::string&, uint32_t*, const std::vector<Field>&) { unavailable(); }
void write_p4est_file(const std::string&, const OctreeForest&) { unavailable(); }
uint32_t octree_p4est_checksum(const OctreeForest&) { unavailable(); }
void write_p4est_sphere_forest(const std::string&, const TreeConnectivity&, Vec3, double, int, OctreeBalance) { unavailable(); }
void write_p4est_front_forest(const std::string&, const TreeConnectivity&, double, int, OctreeBalance) { unavailable(); }
OctreeForest balanced_by_p4est(const OctreeForest&, OctreeBalance) { unavailable(); }
bool is_balanced_in_p4est(const OctreeForest&, OctreeBalance) { unavailable(); }
TreeConnectivity p4est_builtin_connectivity(int, const std::string&) { unavailable(); }

#endif

}  // namespace amc
