// VTU writer: what it writes reads back bit for bit (binary and ASCII, every value type, both
// coordinate precisions), its binary layout is VTK's (appended raw, zlib blocks, UInt64
// headers), and write_mesh writes the leaf mesh's level and green arrays.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "amc/mesh.h"
#include "amc/mesh_io.h"
#include "mesh/vtu_reader.h"
#include "mesh/vtu_writer.h"

namespace fs = std::filesystem;
using namespace amc;

namespace {

// A w x h grid of quads split into triangles, with awkward coordinates.
TriangleMesh grid(uint32_t w, uint32_t h, bool single_precision) {
    TriangleMesh mesh;
    mesh.single_precision = single_precision;
    for (uint32_t j = 0; j <= h; ++j) {
        for (uint32_t i = 0; i <= w; ++i) {
            Vec3 p{i / 3.0 + 1e-17 * j, j * 0.1, std::sin(i * 0.7 + j)};
            if (single_precision) p = {double(float(p.x)), double(float(p.y)), double(float(p.z))};
            mesh.positions.push_back(p);
        }
    }
    for (uint32_t j = 0; j < h; ++j) {
        for (uint32_t i = 0; i < w; ++i) {
            const uint32_t a = j * (w + 1) + i, b = a + 1, c = a + w + 1, d = c + 1;
            mesh.triangles.push_back({a, b, d});
            mesh.triangles.push_back({a, d, c});
        }
    }
    return mesh;
}

// One array of every value type, with the extremes of each type and, for floats, NaN payloads,
// signed zeros, infinities and subnormals.
std::vector<DataArray> every_type(std::size_t tuples, uint32_t seed) {
    std::mt19937_64 rng(seed);
    std::vector<DataArray> arrays;
    const auto add = [&](auto sample, const char* name, uint32_t components) {
        using T = decltype(sample);
        std::vector<T> v(tuples * components);
        for (std::size_t i = 0; i < v.size(); ++i) {
            const uint64_t bits = rng();
            if (i == 0) {
                v[i] = std::numeric_limits<T>::lowest();
            } else if (i == 1) {
                v[i] = std::numeric_limits<T>::max();
            } else if constexpr (std::is_floating_point_v<T>) {
                // Random bit patterns: every class of float, NaNs with payloads included.
                std::memcpy(&v[i], &bits, sizeof(T));
                if constexpr (sizeof(T) == 4) {
                    // A signalling NaN's payload survives memcpy, not a float conversion.
                    if (i == 2) v[i] = std::numeric_limits<T>::denorm_min();
                }
            } else {
                v[i] = static_cast<T>(bits);
            }
        }
        arrays.push_back({name, components, v});
    };
    add(int8_t{}, "int8", 1);
    add(uint8_t{}, "uint8", 2);
    add(int16_t{}, "int16", 1);
    add(uint16_t{}, "uint16", 1);
    add(int32_t{}, "int32 \"quoted\" & <tagged>", 3);
    add(uint32_t{}, "uint32", 1);
    add(int64_t{}, "int64", 1);
    add(uint64_t{}, "uint64", 1);
    add(float{}, "float32", 3);
    add(double{}, "float64", 1);
    return arrays;
}

bool same_bits(const DataArray& a, const DataArray& b) {
    if (a.name != b.name || a.components != b.components || a.type() != b.type() || a.size() != b.size()) {
        return false;
    }
    return std::visit(
        [&](const auto& va) {
            using V = std::decay_t<decltype(va)>;
            const V& vb = std::get<V>(b.values);
            return va.empty() || std::memcmp(va.data(), vb.data(), va.size() * sizeof(va[0])) == 0;
        },
        a.values);
}

void expect_same(const VtuMesh& got, const VtuMesh& want) {
    EXPECT_EQ(got.mesh.single_precision, want.mesh.single_precision);
    EXPECT_EQ(got.mesh.triangles, want.mesh.triangles);
    ASSERT_EQ(got.mesh.positions.size(), want.mesh.positions.size());
    EXPECT_EQ(std::memcmp(got.mesh.positions.data(), want.mesh.positions.data(),
                          want.mesh.positions.size() * sizeof(Vec3)),
              0);
    ASSERT_EQ(got.point_data.size(), want.point_data.size());
    ASSERT_EQ(got.cell_data.size(), want.cell_data.size());
    for (std::size_t i = 0; i < want.point_data.size(); ++i) {
        EXPECT_TRUE(same_bits(got.point_data[i], want.point_data[i])) << want.point_data[i].name;
    }
    for (std::size_t i = 0; i < want.cell_data.size(); ++i) {
        EXPECT_TRUE(same_bits(got.cell_data[i], want.cell_data[i])) << want.cell_data[i].name;
    }
}

std::string temp_path(const std::string& name) {
    return (fs::temp_directory_path() / ("amc_vtu_writer_" + std::to_string(std::random_device{}()) + "_" + name))
        .string();
}

}  // namespace

TEST(VtuWriter, BinaryRoundTripIsBitExact) {
    for (bool single : {false, true}) {
        for (uint32_t size : {1u, 7u, 120u}) {  // 120 x 120: arrays of several zlib blocks
            SCOPED_TRACE("single " + std::to_string(single) + " size " + std::to_string(size));
            VtuMesh vtu;
            vtu.mesh = grid(size, size, single);
            vtu.point_data = every_type(vtu.mesh.positions.size(), size);
            vtu.cell_data = every_type(vtu.mesh.triangles.size(), size + 1);
            const std::string bytes = format_vtu(vtu.mesh, vtu.point_data, vtu.cell_data, VtuEncoding::binary_zlib);
            expect_same(parse_vtu(bytes, "w.vtu"), vtu);
        }
    }
}

// ASCII keeps every finite value exactly (shortest round-trip decimals); NaN payloads are not
// kept by text, so float arrays are compared without them.
TEST(VtuWriter, AsciiRoundTripKeepsEveryFiniteValue) {
    for (bool single : {false, true}) {
        VtuMesh vtu;
        vtu.mesh = grid(9, 4, single);
        vtu.point_data = every_type(vtu.mesh.positions.size(), 5);
        vtu.cell_data = every_type(vtu.mesh.triangles.size(), 6);
        for (std::vector<DataArray>* arrays : {&vtu.point_data, &vtu.cell_data}) {
            for (DataArray& a : *arrays) {
                std::visit(
                    [](auto& v) {
                        for (auto& x : v) {
                            if constexpr (std::is_floating_point_v<std::decay_t<decltype(x)>>) {
                                if (!std::isfinite(x)) x = 0.25;
                            }
                        }
                    },
                    a.values);
            }
        }
        const std::string text = format_vtu(vtu.mesh, vtu.point_data, vtu.cell_data, VtuEncoding::ascii);
        EXPECT_EQ(text.find("AppendedData"), std::string::npos);
        EXPECT_EQ(text.find("compressor"), std::string::npos);
        expect_same(parse_vtu(text, "a.vtu"), vtu);
    }
}

TEST(VtuWriter, BinaryLayoutIsVtks) {
    VtuMesh vtu;
    vtu.mesh = grid(2, 2, true);
    vtu.cell_data = cell_data_arrays({std::vector<uint8_t>(8, 3), std::vector<uint8_t>(8, 1)});
    const std::string bytes = format_vtu(vtu.mesh, {}, vtu.cell_data, VtuEncoding::binary_zlib);
    for (const char* needle :
         {"<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\" "
          "compressor=\"vtkZLibDataCompressor\">",
          "<Piece NumberOfPoints=\"9\" NumberOfCells=\"8\">", "<CellData Scalars=\"level\">",
          "<DataArray type=\"UInt8\" Name=\"level\" format=\"appended\" offset=\"0\"/>",
          "<DataArray type=\"Float32\" Name=\"Points\" NumberOfComponents=\"3\" format=\"appended\"",
          "<DataArray type=\"Int32\" Name=\"connectivity\" format=\"appended\"",
          "<DataArray type=\"UInt8\" Name=\"types\" format=\"appended\"", "<AppendedData encoding=\"raw\">\n   _"}) {
        EXPECT_NE(bytes.find(needle), std::string::npos) << needle;
    }
    // The level array's block: one block of 8 bytes (count, block size, last size, compressed size).
    const std::size_t data = bytes.find("   _") + 4;
    uint64_t header[4];
    std::memcpy(header, bytes.data() + data, sizeof header);
    EXPECT_EQ(header[0], 1u);
    EXPECT_EQ(header[1], 32768u);
    EXPECT_EQ(header[2], 8u);
    EXPECT_GT(header[3], 8u);  // 8 bytes do not shrink under zlib
}

TEST(VtuWriter, ThreadsChangeNoByte) {
    // 400 x 400 quads: 3.9 MB of Float64 points and 3.8 MB of connectivity, several runs of zlib
    // blocks (1 MiB each) for the threads to share.
    VtuMesh vtu;
    vtu.mesh = grid(400, 400, false);
    const std::string one = format_vtu(vtu.mesh, {}, {}, VtuEncoding::binary_zlib, 1);
    EXPECT_EQ(format_vtu(vtu.mesh, {}, {}, VtuEncoding::binary_zlib, 3), one);
    EXPECT_EQ(format_vtu(vtu.mesh, {}, {}, VtuEncoding::binary_zlib, 0), one);
    expect_same(parse_vtu(one, "threads.vtu"), vtu);
}

TEST(VtuWriter, WriteMeshWritesLevelAndGreenAndReadsBack) {
    const std::string path = temp_path("leaf.VTU");
    const TriangleMesh mesh = grid(3, 2, false);
    CellData cells;
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
        cells.level.push_back(uint8_t(t % 5));
        cells.is_green.push_back(uint8_t(t % 2));
    }
    write_mesh(path, mesh, &cells);
    const VtuMesh back = read_vtu(path);
    EXPECT_EQ(back.mesh.triangles, mesh.triangles);
    ASSERT_EQ(back.cell_data.size(), 2u);
    EXPECT_EQ(back.cell_data[0].name, "level");
    EXPECT_TRUE(back.cell_data[0].values == DataArray::Values(cells.level));
    EXPECT_EQ(back.cell_data[1].name, "green");
    EXPECT_TRUE(back.cell_data[1].values == DataArray::Values(cells.is_green));
    EXPECT_EQ(read_mesh(path).positions.size(), mesh.positions.size());

    VtuMesh vtu{mesh, {}, cell_data_arrays(cells)};
    write_vtu(path, vtu, VtuEncoding::ascii);
    expect_same(read_vtu(path), vtu);
    fs::remove(path);
}

TEST(VtuWriter, RefusesArraysOfTheWrongSize) {
    VtuMesh vtu;
    vtu.mesh = grid(2, 1, false);
    vtu.point_data.push_back({"u", 2, std::vector<float>(11)});
    try {
        write_vtu("/nonexistent/x.vtu", vtu);
        ADD_FAILURE() << "accepted";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("/nonexistent/x.vtu: VTU writer: point data 'u' has 11 values, expected 6 x 2"),
                  std::string::npos)
            << e.what();
    }
    CellData cells;
    cells.level.assign(3, 0);
    EXPECT_THROW(format_vtu(vtu.mesh, {}, cell_data_arrays(cells), VtuEncoding::ascii), Error);
}
