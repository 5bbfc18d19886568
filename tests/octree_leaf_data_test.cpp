// .amq version 2: per-leaf data (leaf fields, bit-exact) and coarse meshes with moved vertices
// (bit-exact, or on a grid), with the golden files of tests/data/golden/amq-v2/.
#include "coding/container.h"
#include "octree/octree_file.h"
#include "octree_test_util.h"

#include <amc/mesh_io.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <unistd.h>

namespace amc {
namespace {

OctreeForest decode(const std::vector<uint8_t>& bytes, const OctreeDecodeOptions& options = {}) {
    return decode_octree_forest(bytes.data(), bytes.size(), options);
}

ErrorCode error_of(const std::vector<uint8_t>& bytes, const OctreeDecodeOptions& options = {}) {
    try {
        decode(bytes, options);
    } catch (const Error& e) {
        return e.code();
    }
    return ErrorCode(0);
}

Field cell_field(const std::string& name, FieldType type, uint32_t components) {
    Field f;
    f.name = name;
    f.association = FieldAssociation::cell;
    f.type = type;
    f.components = components;
    return f;
}

// Fields of every kind, from the leaves' positions in exact arithmetic (the golden files depend
// on no library function): a smooth scalar, a float32 vector, labels, extreme integers.
std::vector<Field> fields_of(const OctreeForest& forest) {
    const int root = octree_root_log2(forest.dim());
    Field u = cell_field("u", FieldType::float64, 1), grad = cell_field("grad", FieldType::float32, 3),
          region = cell_field("region", FieldType::int32, 1), flags = cell_field("flags", FieldType::uint8, 2),
          big = cell_field("big", FieldType::uint64, 1);
    for (uint32_t t = 0; t < forest.tree_count(); ++t)
        for (uint64_t i = forest.tree_offsets[t]; i < forest.tree_offsets[t + 1]; ++i) {
            const Octant& o = forest.leaves[i];
            const double x = std::ldexp(double(o.x), -root) + t, y = std::ldexp(double(o.y), -root), z = std::ldexp(double(o.z), -root);
            u.values.push_back(x * x - 0.5 * y + 0.25 * z + 1e-3 * o.level);
            grad.values.insert(grad.values.end(), {double(float(2 * x)), -0.5, double(float(0.25 + z / 3))});
            region.integers.push_back(x * x + y * y < 0.3 ? -7 : 1000000 + int64_t(t));
            flags.integers.insert(flags.integers.end(), {int64_t(o.level), int64_t(i % 256)});
            big.integers.push_back(i % 3 == 0 ? -1 : int64_t(i));  // UInt64 2^64 - 1 as its bit pattern
        }
    return {u, grad, region, flags, big};
}

OctreeForest circle_forest() {
    return balance_octree_forest(sphere_octree_forest(brick_connectivity(2, 2, 1), {1.0, 0.5, 0}, 0.35, 6), OctreeBalance::face);
}

// A brick whose vertices are moved (a non-affine coarse mesh): offsets in multiples of 1/64.
TreeConnectivity moved_brick(int dim, int nx, int ny, int nz, bool periodic = false) {
    TreeConnectivity conn = brick_connectivity(dim, nx, ny, nz, periodic);
    for (size_t v = 0; v < conn.vertices.size(); ++v) {
        conn.vertices[v].x += double(int(v * 37 % 11) - 5) / 64;
        conn.vertices[v].y += double(int(v * 53 % 7) - 3) / 64;
        if (dim == 3) conn.vertices[v].z += double(int(v * 29 % 5) - 2) / 64;
        else conn.vertices[v].z = double(int(v % 3)) / 8;  // a 2D mesh embedded in 3D
    }
    return conn;
}

TEST(OctreeLeafData, FieldsOfEveryTypeRoundTripBitExactInVersion2) {
    OctreeForest forest = circle_forest();
    const std::vector<uint8_t> plain = encode_octree_forest(forest);
    EXPECT_EQ(plain[4], kOctreeBaseVersion);  // no leaf data: still version 1
    forest.leaf_data = fields_of(forest);
    // Values a float coder must keep: signed zeros, denormals, infinities, NaN payloads, extremes.
    std::vector<double>& u = forest.leaf_data[0].values;
    u[0] = -0.0, u[1] = std::numeric_limits<double>::denorm_min(), u[2] = std::numeric_limits<double>::infinity();
    u[3] = -std::numeric_limits<double>::max();
    uint64_t nan_bits = 0x7FF4000000ABCDEFull;
    std::memcpy(&u[4], &nan_bits, 8);
    OctreeEncodeStats stats;
    const std::vector<uint8_t> bytes = encode_octree_forest(forest, {}, &stats);
    EXPECT_EQ(bytes[4], kOctreeLeafDataVersion);
    EXPECT_EQ(stats.file_bytes, bytes.size());
    EXPECT_GT(stats.leaf_data_bytes, 0u);
    EXPECT_EQ(bytes.size() - plain.size(), stats.leaf_data_bytes + 5 * kBlockOverhead);
    const OctreeForest decoded = decode(bytes);
    ASSERT_TRUE(decoded == forest);  // identical(): bit for bit
    uint64_t decoded_nan_bits;
    std::memcpy(&decoded_nan_bits, &decoded.leaf_data[0].values[4], 8);
    EXPECT_EQ(decoded_nan_bits, nan_bits);
    // Progressive decoding gives the coarse forest without the data.
    OctreeDecodeOptions coarse;
    coarse.max_level = 2;
    EXPECT_TRUE(decode(bytes, coarse).leaf_data.empty());
    // A constant label costs next to nothing: a few bytes for thousands of leaves.
    OctreeForest labelled = circle_forest();
    Field label = cell_field("label", FieldType::int16, 1);
    label.integers.assign(labelled.leaves.size(), 42);
    labelled.leaf_data = {label};
    EXPECT_LT(encode_octree_forest(labelled).size() - plain.size(), 40u) << labelled.leaves.size() << " leaves";
}

TEST(OctreeLeafData, RandomForestsAndFieldsRoundTrip) {
    std::mt19937_64 rng(28);
    for (int round = 0; round < 12; ++round) {
        OctreeForest forest = octree_test::random_balanced_forest(2 + round % 2, rng);
        const FieldType type = FieldType(rng() % 10);
        Field f = cell_field("f" + std::to_string(round), type, 1 + uint32_t(rng() % 4));
        for (size_t k = 0; k < forest.leaves.size() * f.components; ++k) {
            const uint64_t r = rng();
            if (type == FieldType::float64) {
                double v;
                std::memcpy(&v, &r, 8);
                f.values.push_back(std::isnan(v) ? 1.5 : v);
            } else if (type == FieldType::float32) {
                f.values.push_back(double(float(int32_t(r)) / 4096.0f));
            } else {
                const int bits = int(8 * (type <= FieldType::uint8 ? 1 : type <= FieldType::uint16 ? 2 : type <= FieldType::uint32 ? 4 : 8));
                const bool is_signed = type == FieldType::int8 || type == FieldType::int16 || type == FieldType::int32 || type == FieldType::int64;
                int64_t v = bits == 64 ? int64_t(r) : int64_t(r & ((uint64_t{1} << bits) - 1));
                if (is_signed && bits < 64) v -= int64_t(1) << (bits - 1);
                f.integers.push_back(v);
            }
        }
        forest.leaf_data = {f};
        const std::vector<uint8_t> bytes = encode_octree_forest(forest);
        ASSERT_TRUE(decode(bytes) == forest) << "round " << round << " type " << field_type_name(type);
    }
}

TEST(OctreeLeafData, BadFieldsAreRefusedByTheEncoder) {
    const OctreeForest base = circle_forest();
    const auto refused = [&](const Field& f) {
        OctreeForest forest = base;
        forest.leaf_data = {f};
        EXPECT_THROW(encode_octree_forest(forest), Error) << f.name;
    };
    Field f = cell_field("short", FieldType::float64, 1);
    f.values.assign(base.leaves.size() - 1, 0.0);
    refused(f);
    f = cell_field("range", FieldType::uint8, 1);
    f.integers.assign(base.leaves.size(), 256);
    refused(f);
    f = cell_field("notfloat", FieldType::float32, 1);
    f.values.assign(base.leaves.size(), 0.1);
    refused(f);
    f.values.assign(base.leaves.size(), 1e300);  // beyond the float range
    refused(f);
    f = cell_field("point", FieldType::float64, 1);
    f.association = FieldAssociation::point;
    f.values.assign(base.leaves.size(), 0.0);
    refused(f);
    f = cell_field("", FieldType::float64, 1);
    f.values.assign(base.leaves.size(), 0.0);
    refused(f);
    OctreeForest twice = base;
    f.name = "twice";
    twice.leaf_data = {f, f};
    EXPECT_THROW(encode_octree_forest(twice), Error);
}

TEST(OctreeLeafData, EveryTruncationAndChangedByteIsAnErrorAndLimitsHold) {
    OctreeForest forest = balance_octree_forest(sphere_octree_forest(brick_connectivity(2, 1, 1), {0.5, 0.5, 0}, 0.3, 4), OctreeBalance::face);
    forest.leaf_data = fields_of(forest);
    const std::vector<uint8_t> bytes = encode_octree_forest(forest);
    std::mt19937_64 rng(3);
    for (size_t n = 0; n < bytes.size(); ++n) EXPECT_THROW(decode(std::vector<uint8_t>(bytes.begin(), bytes.begin() + n)), Error) << n;
    for (size_t i = 0; i < bytes.size(); ++i) {
        std::vector<uint8_t> changed = bytes;
        changed[i] ^= uint8_t(1 + rng() % 255);
        EXPECT_THROW(decode(changed), Error) << i;
    }
    OctreeDecodeOptions small;
    small.max_leaf_values = forest.leaves.size() * 7 - 1;  // the fields hold 8 values per leaf
    EXPECT_EQ(error_of(bytes, small), ErrorCode::limit_exceeded);
    small.max_leaf_values = forest.leaves.size() * 8;
    EXPECT_TRUE(decode(bytes, small) == forest);
    // A leaf field block in a version 1 file is an unknown block type.
    std::vector<uint8_t> v1 = bytes;
    v1[4] = kOctreeBaseVersion;
    EXPECT_THROW(decode(v1), Error);
}

TEST(OctreeGeometry, MovedVerticesBitExactOrOnAGrid) {
    for (int dim : {2, 3}) {
        for (bool periodic : {false, true}) {  // periodic: the gluing is stored (mode 1 / 5), else derived (0 / 4)
            const TreeConnectivity conn = moved_brick(dim, 3, 2, 2, periodic);
            const OctreeForest forest =
                balance_octree_forest(front_octree_forest(conn, 1.2, dim == 2 ? 6 : 4), OctreeBalance::face);
            const std::vector<uint8_t> exact = encode_octree_forest(forest);
            EXPECT_EQ(exact[4], kOctreeBaseVersion);
            ASSERT_TRUE(decode(exact) == forest);  // bit-exact positions
            for (double step : {1.0 / 1024, 1e-6, 0.3}) {
                OctreeEncodeOptions options;
                options.vertex_step = step;
                OctreeEncodeStats stats, exact_stats;
                encode_octree_forest(forest, {}, &exact_stats);
                const std::vector<uint8_t> bytes = encode_octree_forest(forest, options, &stats);
                EXPECT_EQ(bytes[4], kOctreeLeafDataVersion);
                EXPECT_LT(stats.connectivity_bytes, exact_stats.connectivity_bytes) << step;
                const OctreeForest decoded = decode(bytes);
                OctreeForest expected = forest;
                for (Vec3& p : expected.connectivity.vertices) {
                    const Vec3 q = p;
                    p = {std::nearbyint(q.x / step) * step, std::nearbyint(q.y / step) * step, std::nearbyint(q.z / step) * step};
                    ASSERT_LE(std::fabs(p.x - q.x), step / 2 * (1 + 1e-12));
                    ASSERT_LE(std::fabs(p.y - q.y), step / 2 * (1 + 1e-12));
                    ASSERT_LE(std::fabs(p.z - q.z), step / 2 * (1 + 1e-12));
                }
                ASSERT_TRUE(decoded == expected) << "dim " << dim << " periodic " << periodic << " step " << step;
            }
        }
    }
    // A brick keeps its exact mode 3 whatever the step.
    OctreeEncodeOptions options;
    options.vertex_step = 0.1;
    const OctreeForest brick = uniform_octree_forest(brick_connectivity(2, 2, 2), 2);
    EXPECT_EQ(encode_octree_forest(brick, options)[4], kOctreeBaseVersion);
    // Steps that are no steps, or too small for the positions.
    const OctreeForest moved = uniform_octree_forest(moved_brick(2, 2, 1, 1), 1);
    for (double bad : {-1.0, std::nan(""), std::numeric_limits<double>::infinity(), 1e-300}) {
        options.vertex_step = bad;
        EXPECT_THROW(encode_octree_forest(moved, options), Error) << bad;
    }
}

// Golden .amq version 2 files (tests/data/golden/amq-v2/), kept forever: each decodes to the
// forest it was made from, and the encoder still writes exactly its bytes. AMC_UPDATE_GOLDEN=1
// writes the missing files (never overwrites one).
TEST(OctreeGolden, Version2FilesDecodeAndEncoderBytesArePinned) {
    struct Case {
        std::string name;
        OctreeForest forest, expected;
        OctreeEncodeOptions options;
    };
    std::vector<Case> cases;
    OctreeForest circle = circle_forest();
    circle.leaf_data = fields_of(circle);
    cases.push_back({"circle_2d_fields", circle, circle, {}});
    OctreeEncodeOptions grid;
    grid.vertex_step = 1.0 / 256;  // the moved vertices are multiples of 1/64: the grid keeps them
    OctreeForest moved =
        balance_octree_forest(sphere_octree_forest(moved_brick(3, 2, 1, 1), {1.0, 0.5, 0.5}, 0.4, 3), OctreeBalance::corner);
    Field rank = cell_field("rank", FieldType::uint16, 1);
    for (size_t i = 0; i < moved.leaves.size(); ++i) rank.integers.push_back(int64_t(i * 4 / moved.leaves.size()));
    moved.leaf_data = {rank};
    cases.push_back({"moved_3d_quantized_rank", moved, moved, grid});
    OctreeForest periodic = uniform_octree_forest(moved_brick(2, 3, 1, 1, true), 2);
    grid.vertex_step = 0.1;
    OctreeForest periodic_snapped = periodic;
    for (Vec3& p : periodic_snapped.connectivity.vertices)
        p = {std::nearbyint(p.x / 0.1) * 0.1, std::nearbyint(p.y / 0.1) * 0.1, std::nearbyint(p.z / 0.1) * 0.1};
    cases.push_back({"periodic_2d_quantized_explicit", periodic, periodic_snapped, grid});

    const std::string dir = std::string(AMC_TEST_DATA_DIR) + "/golden/amq-v2/";
    const bool update = std::getenv("AMC_UPDATE_GOLDEN") != nullptr;
    for (const Case& c : cases) {
        const std::string path = dir + c.name + ".amq";
        const std::vector<uint8_t> bytes = encode_octree_forest(c.forest, c.options);
        EXPECT_EQ(bytes[4], kOctreeLeafDataVersion) << c.name;
        std::ifstream in(path, std::ios::binary);
        if (!in) {
            ASSERT_TRUE(update) << path << " is missing (AMC_UPDATE_GOLDEN=1 writes it)";
            std::filesystem::create_directories(dir);
            std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
            continue;
        }
        const std::vector<uint8_t> golden((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        EXPECT_TRUE(decode(golden) == c.expected) << path;
        EXPECT_EQ(bytes, golden) << path << ": the encoder's bytes changed (a new .amq version?)";
    }
}

TEST(OctreeLeafData, VtuCellDataHoldsTheFields) {
    OctreeForest forest = uniform_octree_forest(brick_connectivity(2, 1, 1), 1);
    Field u = cell_field("pressure", FieldType::float64, 1);
    u.values = {0.5, -1.25, 3, 4};
    Field level = cell_field("level", FieldType::int32, 1);  // replaces the writer's own "level"
    level.integers = {7, 7, 7, 7};
    forest.leaf_data = {u, level};
    const std::string path = (std::filesystem::temp_directory_path() / ("amc_leaf_vtu_" + std::to_string(::getpid()) + ".vtu")).string();
    write_octree_vtu(path, forest, VtuEncoding::ascii);
    std::ifstream in(path);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::filesystem::remove(path);
    EXPECT_NE(text.find("Name=\"pressure\""), std::string::npos) << text;
    EXPECT_NE(text.find("0.5 -1.25 3 4"), std::string::npos) << text;
    EXPECT_NE(text.find("7 7 7 7"), std::string::npos) << text;
    EXPECT_EQ(text.find("Name=\"level\""), text.rfind("Name=\"level\"")) << text;  // once
    EXPECT_NE(text.find("Name=\"tree\""), std::string::npos) << text;
}

}  // namespace
}  // namespace amc
