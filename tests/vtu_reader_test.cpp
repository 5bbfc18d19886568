// VTU reader: the fixtures that meshio, VTK and DUNE wrote (tests/data/vtu, made by
// scripts/make_vtu_fixtures.py) read back to the known mesh and arrays; hand-made files cover
// the corners those tools do not write; bad files are refused with messages naming the problem.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "amc/mesh.h"
#include "amc/mesh_io.h"
#include "mesh/vtu_reader.h"
#include "mesh/zlib_blocks.h"

namespace fs = std::filesystem;
using namespace amc;

namespace {

std::string vtu_fixture(const std::string& name) { return std::string(AMC_TEST_DATA_DIR) + "/vtu/" + name; }
std::string bad_fixture(const std::string& name) { return std::string(AMC_TEST_DATA_DIR) + "/bad/" + name; }

std::string read_bytes(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

void expect_error_containing(const std::function<void()>& f, const std::string& needle) {
    try {
        f();
        ADD_FAILURE() << "no amc::Error thrown; expected one containing \"" << needle << "\"";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find(needle), std::string::npos)
            << "message: " << e.what() << "\nexpected to contain: " << needle;
    }
}

// The octahedron and arrays of scripts/make_vtu_fixtures.py, computed the same way.
const std::vector<Triangle> kOctahedron = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4},
                                           {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};

std::vector<Vec3> octahedron_points(bool single_precision) {
    std::vector<Vec3> p(6);
    for (int i = 0; i < 6; ++i) {
        double c = (i % 2 == 0 ? 1.0 : -1.0) * (1.0 + i / 7.0);
        if (single_precision) c = static_cast<float>(c);
        (i / 2 == 0 ? p[i].x : i / 2 == 1 ? p[i].y : p[i].z) = c;
    }
    return p;
}

std::vector<DataArray> octahedron_point_data() {
    std::vector<double> temperature;
    std::vector<float> velocity;
    std::vector<int64_t> ids;
    for (int i = 0; i < 6; ++i) {
        temperature.push_back(i / 3.0 + 0.1);
        for (int k = 0; k < 3; ++k) velocity.push_back(static_cast<float>(i + k / 10.0));
        ids.push_back((int64_t(1) << 60) + i);
    }
    return {{"temperature", 1, temperature}, {"velocity", 3, velocity}, {"id", 1, ids}};
}

std::vector<DataArray> octahedron_cell_data() {
    std::vector<uint8_t> level;
    std::vector<int32_t> material;
    std::vector<double> quality;
    for (int c = 0; c < 8; ++c) {
        level.push_back(static_cast<uint8_t>(c % 3));
        material.push_back(-1000 * c);
        quality.push_back(1.0 / (c + 1));
    }
    return {{"level", 1, level}, {"material", 1, material}, {"quality", 1, quality}};
}

// Float64 values compared within `tolerance` (relative) when it is not 0, everything else
// exactly: type, components and every value.
void expect_arrays(const std::vector<DataArray>& got, const std::vector<DataArray>& want,
                   double tolerance, const std::string& file) {
    ASSERT_EQ(got.size(), want.size()) << file;
    for (std::size_t i = 0; i < want.size(); ++i) {
        SCOPED_TRACE(file + ": array " + want[i].name);
        EXPECT_EQ(got[i].name, want[i].name);
        EXPECT_EQ(got[i].type(), want[i].type());
        EXPECT_EQ(got[i].components, want[i].components);
        if (tolerance > 0 && want[i].type() == ValueType::float64) {
            ASSERT_EQ(got[i].size(), want[i].size());
            for (std::size_t k = 0; k < want[i].size(); ++k) {
                EXPECT_NEAR(got[i].value(k), want[i].value(k), tolerance * std::abs(want[i].value(k)));
            }
        } else {
            EXPECT_TRUE(got[i].values == want[i].values);
        }
    }
}

struct Fixture {
    const char* file;
    bool single_precision;
    double tolerance;  // meshio writes ascii floats with 12 significant digits
};

const Fixture kOctahedronFixtures[] = {
    {"meshio_ascii.vtu", false, 1e-11},
    {"meshio_binary.vtu", false, 0},
    {"meshio_binary_zlib.vtu", false, 0},
    {"meshio_binary_zlib_uint64.vtu", false, 0},
    {"vtk_ascii.vtu", false, 0},
    {"vtk_binary_uint32.vtu", true, 0},
    {"vtk_binary_zlib.vtu", false, 0},
    {"vtk_appended_raw.vtu", false, 0},
    {"vtk_appended_raw_zlib_uint32.vtu", true, 0},
    {"vtk_appended_base64.vtu", false, 0},
    {"vtk_appended_base64_zlib.vtu", false, 0},
    {"vtk_big_endian_zlib.vtu", false, 0},
    {"vtk_big_endian_binary.vtu", true, 0},
    {"vtk_polygons.vtu", false, 0},
};

// ---------------------------------------------------------------------------------------------
// Hand-made files

std::string base64(const std::string& bytes) {
    static const char* alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    for (std::size_t i = 0; i < bytes.size(); i += 3) {
        uint32_t w = uint32_t(uint8_t(bytes[i])) << 16;
        if (i + 1 < bytes.size()) w |= uint32_t(uint8_t(bytes[i + 1])) << 8;
        if (i + 2 < bytes.size()) w |= uint8_t(bytes[i + 2]);
        out += alphabet[w >> 18];
        out += alphabet[(w >> 12) & 63];
        out += i + 1 < bytes.size() ? alphabet[(w >> 6) & 63] : '=';
        out += i + 2 < bytes.size() ? alphabet[w & 63] : '=';
    }
    return out;
}

template <typename T>
std::string le_bytes(const std::vector<T>& values) {
    std::string s;
    for (T v : values) {
        unsigned char b[sizeof(T)];
        std::memcpy(b, &v, sizeof(T));
        if (__BYTE_ORDER__ == __ORDER_BIG_ENDIAN__) std::reverse(b, b + sizeof(T));
        s.append(reinterpret_cast<const char*>(b), sizeof(T));
    }
    return s;
}

std::string u32(uint32_t v) { return le_bytes(std::vector<uint32_t>{v}); }
std::string u64(uint64_t v) { return le_bytes(std::vector<uint64_t>{v}); }

// One triangle in a file; `points`, `cells` and `cell_data` are the DataArray elements.
std::string one_piece(const std::string& root_attributes, const std::string& points,
                      const std::string& cells, const std::string& extra = "",
                      const std::string& tail = "</VTKFile>\n") {
    return "<?xml version=\"1.0\"?>\n<!-- a comment -->\n<VTKFile type=\"UnstructuredGrid\" " + root_attributes +
           ">\n<UnstructuredGrid>\n<Piece NumberOfPoints=\"3\" NumberOfCells=\"1\">\n<Points>" + points +
           "</Points>\n<Cells>" + cells + "</Cells>\n" + extra + "</Piece>\n</UnstructuredGrid>\n" + tail;
}

const std::string kAsciiPoints =
    "<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">0 0 0  1 0 0  0 1 0</DataArray>";
const std::string kAsciiCells =
    "<DataArray type=\"Int32\" Name=\"connectivity\" format=\"ascii\">0 1 2</DataArray>"
    "<DataArray type=\"Int32\" Name=\"offsets\" format=\"ascii\">3</DataArray>"
    "<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">5</DataArray>";

}  // namespace

TEST(VtuReader, EveryToolsFixtureReadsTheKnownMeshAndArrays) {
    for (const Fixture& f : kOctahedronFixtures) {
        SCOPED_TRACE(f.file);
        const VtuMesh vtu = read_vtu(vtu_fixture(f.file));
        EXPECT_EQ(vtu.mesh.single_precision, f.single_precision);
        EXPECT_EQ(vtu.mesh.triangles, kOctahedron);
        const std::vector<Vec3> want = octahedron_points(f.single_precision);
        ASSERT_EQ(vtu.mesh.positions.size(), want.size());
        for (std::size_t i = 0; i < want.size(); ++i) {
            if (f.tolerance == 0) {
                EXPECT_TRUE(vtu.mesh.positions[i] == want[i]) << "point " << i;
            } else {
                EXPECT_NEAR(vtu.mesh.positions[i].x, want[i].x, f.tolerance * 2);
                EXPECT_NEAR(vtu.mesh.positions[i].y, want[i].y, f.tolerance * 2);
                EXPECT_NEAR(vtu.mesh.positions[i].z, want[i].z, f.tolerance * 2);
            }
        }
        expect_arrays(vtu.point_data, octahedron_point_data(), f.tolerance, f.file);
        expect_arrays(vtu.cell_data, octahedron_cell_data(), f.tolerance, f.file);
        // read_mesh gives the same mesh.
        const TriangleMesh mesh = read_mesh(vtu_fixture(f.file));
        EXPECT_EQ(mesh.triangles, vtu.mesh.triangles);
    }
}

// VTK writes the whole grid into each of the two pieces it was asked for; the reader
// concatenates them, as VTK's reader does: two octahedra, the second numbered after the first.
TEST(VtuReader, PiecesAreConcatenated) {
    const VtuMesh vtu = read_vtu(vtu_fixture("vtk_two_pieces.vtu"));
    ASSERT_EQ(vtu.mesh.triangles.size(), 16u);
    ASSERT_EQ(vtu.mesh.positions.size(), 12u);
    for (std::size_t t = 0; t < 8; ++t) {
        EXPECT_EQ(vtu.mesh.triangles[t], kOctahedron[t]);
        for (int k = 0; k < 3; ++k) EXPECT_EQ(vtu.mesh.triangles[8 + t][k], kOctahedron[t][k] + 6);
    }
    std::vector<DataArray> point_data = octahedron_point_data(), cell_data = octahedron_cell_data();
    for (std::vector<DataArray>* arrays : {&point_data, &cell_data}) {
        for (DataArray& a : *arrays) {
            std::visit([](auto& v) { v.insert(v.end(), v.begin(), v.end()); }, a.values);
        }
    }
    expect_arrays(vtu.point_data, point_data, 0, "vtk_two_pieces.vtu");
    expect_arrays(vtu.cell_data, cell_data, 0, "vtk_two_pieces.vtu");
}

// DUNE's VTKWriter in its four output types: the same 2 x 2 grid of triangles (vertices as UG
// numbers them), Float32 points named "Coordinates", Float32 "height" and "index".
TEST(VtuReader, DuneFixturesReadTheKnownGrid) {
    const std::vector<Vec3> points = {{0, 0, 0},      {0.5, 0, 0},   {0.5, 0.25, 0},
                                      {0, 0.25, 0},   {1, 0, 0},     {1, 0.25, 0},
                                      {0.5, 0.5, 0},  {0, 0.5, 0},   {1, 0.5, 0}};
    const std::vector<Triangle> triangles = {{0, 1, 2}, {0, 2, 3}, {1, 4, 5}, {1, 5, 2},
                                             {3, 2, 6}, {3, 6, 7}, {2, 5, 8}, {2, 8, 6}};
    std::vector<float> height, index;
    for (const Vec3& p : points) height.push_back(static_cast<float>(10 * p.x + p.y));
    for (int e = 0; e < 8; ++e) index.push_back(e + 0.5f);
    for (const char* file : {"dune_ascii.vtu", "dune_base64.vtu", "dune_appended_raw.vtu",
                             "dune_appended_base64.vtu"}) {
        SCOPED_TRACE(file);
        const VtuMesh vtu = read_vtu(vtu_fixture(file));
        EXPECT_TRUE(vtu.mesh.single_precision);
        ASSERT_EQ(vtu.mesh.positions.size(), points.size());
        for (std::size_t i = 0; i < points.size(); ++i) EXPECT_TRUE(vtu.mesh.positions[i] == points[i]) << i;
        EXPECT_EQ(vtu.mesh.triangles, triangles);
        expect_arrays(vtu.point_data, {{"height", 1, height}}, 0, file);
        expect_arrays(vtu.cell_data, {{"index", 1, index}}, 0, file);
    }
}

TEST(VtuReader, HandMadeCornersOfTheFormat) {
    // Entities in names, comments, single quotes, polygons of 3 points, Int64 connectivity.
    VtuMesh vtu = parse_vtu(
        one_piece("byte_order='LittleEndian'", kAsciiPoints,
                  "<!-- cells --><DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">0 1 2</DataArray>"
                  "<DataArray type=\"UInt64\" Name=\"offsets\">3</DataArray>"
                  "<DataArray type=\"Int8\" Name=\"types\" format=\"ascii\">7</DataArray>",
                  "<CellData><DataArray type=\"Int8\" Name=\"a&lt;b&amp;&#x263A;\" format=\"ascii\"> -128 "
                  "</DataArray></CellData><FieldData><DataArray type=\"String\" Name=\"x\"/></FieldData>"),
        "h.vtu");
    EXPECT_EQ(vtu.mesh.triangles, (std::vector<Triangle>{{0, 1, 2}}));
    EXPECT_FALSE(vtu.mesh.single_precision);
    ASSERT_EQ(vtu.cell_data.size(), 1u);
    EXPECT_EQ(vtu.cell_data[0].name, "a<b&\xE2\x98\xBA");
    EXPECT_TRUE(vtu.cell_data[0].values == DataArray::Values(std::vector<int8_t>{-128}));

    // Inline binary with a UInt64 header, header and data as one base64 run (meshio's way),
    // and zlib blocks of which the last is full (its size word 0).
    const std::string xyz = le_bytes(std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0});
    const CompressedBlocks blocks = compress_zlib_blocks(
        reinterpret_cast<const uint8_t*>(xyz.data()), xyz.size(), 12, 9);
    ASSERT_EQ(blocks.compressed_sizes.size(), 3u);
    std::string header = u64(3) + u64(12) + u64(0);
    for (uint64_t c : blocks.compressed_sizes) header += u64(c);
    vtu = parse_vtu(one_piece("header_type=\"UInt64\" compressor=\"vtkZLibDataCompressor\"",
                              "<DataArray type=\"Float32\" NumberOfComponents=\"3\" format=\"binary\">\n  " +
                                  base64(header + blocks.bytes) + "\n</DataArray>",
                              kAsciiCells),
                    "h.vtu");
    EXPECT_TRUE(vtu.mesh.single_precision);
    EXPECT_TRUE(vtu.mesh.positions[2] == (Vec3{0, 1, 0}));

    // Appended raw data holding '<' and '>' bytes, with the header words split from the data.
    const std::string connectivity = le_bytes(std::vector<int32_t>{0, 1, 2});
    std::string appended = u32(uint32_t(connectivity.size())) + connectivity;
    const std::string cells = "<DataArray type=\"Int32\" Name=\"connectivity\" format=\"appended\" offset=\"0\"/>"
                              "<DataArray type=\"Int32\" Name=\"offsets\" format=\"appended\" offset=\"16\"/>"
                              "<DataArray type=\"UInt8\" Name=\"types\" format=\"appended\" offset=\"24\"/>";
    appended += u32(4) + le_bytes(std::vector<int32_t>{3}) + u32(1) + "\x05";
    const std::string cell_data = "<CellData><DataArray type=\"UInt8\" Name=\"lt\" format=\"appended\" offset=\"29\"/></CellData>";
    appended += u32(1) + "<";
    const std::string points = "<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"appended\" offset=\"34\"/>";
    appended += u32(72) + le_bytes(std::vector<double>{0, 0, 0, 1, 0, 0, 0, 1, 0});
    vtu = parse_vtu(one_piece("", points, cells, cell_data,
                              "<AppendedData encoding=\"raw\">\n _" + appended + "\n</AppendedData></VTKFile>"),
                    "h.vtu");
    ASSERT_EQ(vtu.cell_data.size(), 1u);
    EXPECT_TRUE(vtu.cell_data[0].values == DataArray::Values(std::vector<uint8_t>{'<'}));
    EXPECT_EQ(vtu.mesh.triangles, (std::vector<Triangle>{{0, 1, 2}}));
}

TEST(VtuReader, RefusesHandMadeDefectsNamingThem) {
    const auto refuse = [](const std::string& file, const std::string& needle) {
        expect_error_containing([&] { parse_vtu(file, "h.vtu"); }, "h.vtu: ");
        expect_error_containing([&] { parse_vtu(file, "h.vtu"); }, needle);
    };
    std::string unterminated = one_piece("", kAsciiPoints, kAsciiCells);
    refuse(unterminated.replace(unterminated.find("-->"), 3, "--"), "bad XML at line 2: unterminated comment");
    refuse(one_piece("header_type=\"UInt16\"", kAsciiPoints, kAsciiCells), "unknown header_type 'UInt16'");
    refuse(one_piece("byte_order=\"Middle\"", kAsciiPoints, kAsciiCells), "unknown byte_order 'Middle'");
    refuse(one_piece("", kAsciiPoints, kAsciiCells + "</Cells>"), "</Cells> closes <Piece>");
    std::string cells = kAsciiCells;
    refuse(one_piece("", kAsciiPoints, cells.replace(cells.find(">3<"), 3, ">4<")),
           "cell 0 is a triangle (VTK type 5) of 4 points (offset 4)");
    cells = kAsciiCells;
    refuse(one_piece("", kAsciiPoints, cells.replace(cells.find(">5<"), 3, ">77<")),
           "cell 0 is a cell of unknown type (VTK type 77)");
    cells = kAsciiCells;
    refuse(one_piece("", kAsciiPoints, cells.replace(cells.find("0 1 2"), 5, "0 1 -2")),
           "cell 0 refers to point -2, out of range (3 points)");
    cells = kAsciiCells;
    refuse(one_piece("", kAsciiPoints, cells.replace(cells.find("0 1 2"), 5, "0 1 2.5")),
           "Cells array 'connectivity' (line 7): value 2 '2.5' is not a valid Int32");
    cells = kAsciiCells;
    refuse(one_piece("", kAsciiPoints, cells.replace(cells.find("\"UInt8\""), 7, "\"Float32\"")),
           "Cells array 'types' (line 7): has type Float32 with 1 components; one integer per cell is needed");
    refuse(one_piece("", "<DataArray type=\"Float64\" NumberOfComponents=\"2\">0 0 1 0 0 1</DataArray>", kAsciiCells),
           "Points array (line 6): has 2 components; points need 3");
    refuse(one_piece("", kAsciiPoints, kAsciiCells,
                     "<PointData><DataArray type=\"UInt8\" Name=\"u\">1 2 300</DataArray></PointData>"),
           "point data 'u' (line 8): value 2 '300' is not a valid UInt8");
    refuse(one_piece("", kAsciiPoints, kAsciiCells,
                     "<CellData><DataArray type=\"UInt8\" Name=\"u\" format=\"appended\" offset=\"0\"/></CellData>"),
           "cell data 'u' (line 8): format=\"appended\" but the file has no AppendedData");
    refuse(one_piece("", kAsciiPoints, kAsciiCells, "", "<AppendedData encoding=\"raw\">x</AppendedData></VTKFile>"),
           "AppendedData does not start with '_'");
    // Zlib: a block count of zero for data that should be there; a block with trailing bytes.
    refuse(one_piece("compressor=\"vtkZLibDataCompressor\"",
                     "<DataArray type=\"Float32\" NumberOfComponents=\"3\" format=\"binary\">" +
                         base64(u32(0) + u32(32768) + u32(0)) + "</DataArray>",
                     kAsciiCells),
           "Points array (line 6): its compression header says 0 bytes, expected 36 bytes (9 Float32 values)");
    const std::string xyz = le_bytes(std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0});
    CompressedBlocks block = compress_zlib_blocks(reinterpret_cast<const uint8_t*>(xyz.data()), xyz.size(), 64, 5);
    refuse(one_piece("compressor=\"vtkZLibDataCompressor\"",
                     "<DataArray type=\"Float32\" NumberOfComponents=\"3\" format=\"binary\">" +
                         base64(u32(1) + u32(36) + u32(36) + u32(uint32_t(block.bytes.size() + 2)) + block.bytes + "xy") +
                         "</DataArray>",
                     kAsciiCells),
           "compressed block 0 of 1 is not valid zlib data of 36 bytes");
    // Pieces whose arrays differ.
    std::string two = one_piece("", kAsciiPoints, kAsciiCells,
                                "<CellData><DataArray type=\"UInt8\" Name=\"u\">1</DataArray></CellData>");
    const std::size_t piece = two.find("<Piece"), end = two.find("</UnstructuredGrid>");
    std::string second = two.substr(piece, end - piece);
    second.replace(second.find("Name=\"u\""), 8, "Name=\"v\"");
    two.insert(end, second);
    refuse(two, "piece 1's cell data array 'v' does not match piece 0's 'u'");
}

// A cell array of 4 MiB in 32 KiB zlib blocks: runs of blocks inflate on several threads
// (docs/VTU.md). Every thread count reads the same values, and a bad file gives the error that
// the block-by-block order of checks names first, appended raw or inline base64.
TEST(VtuReader, ZlibBlocksReadTheSameOnEveryThreadCount) {
    constexpr uint32_t kValues = 1 << 19;  // Float64: 4 MiB, 128 blocks
    std::vector<double> values(kValues);
    std::mt19937_64 random(7);
    for (uint32_t i = 0; i < kValues; ++i) values[i] = double(random() % 1000) * 0.25;
    const std::string data = le_bytes(values);
    const CompressedBlocks blocks =
        compress_zlib_blocks(reinterpret_cast<const uint8_t*>(data.data()), data.size(), kVtkBlockSize, 1);
    const std::size_t count = blocks.compressed_sizes.size();
    ASSERT_EQ(count, 128u);
    const auto start_of = [&](std::size_t b) {
        uint64_t at = 0;
        for (std::size_t k = 0; k < b; ++k) at += blocks.compressed_sizes[k];
        return at;
    };
    // The file with the given compressed-size words and block bytes.
    const auto file = [&](const std::vector<uint64_t>& sizes, const std::string& bytes, bool base64_inline) {
        std::string header = u64(count) + u64(kVtkBlockSize) + u64(0);
        for (uint64_t c : sizes) header += u64(c);
        const std::string array = "<CellData><DataArray type=\"Float64\" Name=\"big\" NumberOfComponents=\"" +
                                  std::to_string(kValues) + "\" format=\"";
        const std::string root = "header_type=\"UInt64\" compressor=\"vtkZLibDataCompressor\"";
        if (base64_inline) {
            return one_piece(root, kAsciiPoints, kAsciiCells,
                             array + "binary\">" + base64(header + bytes) + "</DataArray></CellData>");
        }
        return one_piece(root, kAsciiPoints, kAsciiCells, array + "appended\" offset=\"0\"/></CellData>",
                         "<AppendedData encoding=\"raw\">\n _" + header + bytes + "\n</AppendedData></VTKFile>");
    };
    const auto error_of = [](const std::string& bytes, unsigned threads) {
        try {
            parse_vtu(bytes, "h.vtu", threads);
        } catch (const Error& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    const std::string where = "h.vtu: cell data 'big' (line 8): ";
    const std::string late_bad = "compressed block 100 of 128 is not valid zlib data of 32768 bytes";
    const std::string size_bad = "compressed block 110 declares 32768 bytes, more than its 10 compressed bytes can hold";
    for (bool inline_base64 : {false, true}) {
        SCOPED_TRACE(inline_base64 ? "inline base64" : "appended raw");
        const std::string good = file(blocks.compressed_sizes, blocks.bytes, inline_base64);
        for (unsigned threads : {1u, 2u, 5u, 0u}) {
            const VtuMesh vtu = parse_vtu(good, "h.vtu", threads);
            ASSERT_EQ(vtu.cell_data.size(), 1u);
            EXPECT_TRUE(vtu.cell_data[0].values == DataArray::Values(values)) << threads << " threads";
        }
        // A late block's bytes corrupt: its error, on every thread count.
        std::string corrupt = blocks.bytes;
        corrupt[start_of(100) + 5] ^= 0x55;
        std::vector<uint64_t> sizes = blocks.compressed_sizes;
        // A later block whose declared size its 10 bytes cannot hold: checked before any
        // allocation, but the serial loop meets the corrupt block first.
        sizes[110] = 10;
        const std::string cases[][2] = {
            {file(blocks.compressed_sizes, corrupt, inline_base64), late_bad},
            {file(sizes, corrupt, inline_base64), late_bad},
            {file(sizes, blocks.bytes, inline_base64), size_bad},
        };
        for (const auto& c : cases) {
            for (unsigned threads : {1u, 3u, 0u}) EXPECT_EQ(error_of(c[0], threads), where + c[1]) << threads << " threads";
        }
        // A corrupt block after the one that fails the size check is never reached.
        corrupt = blocks.bytes;
        corrupt[start_of(120) + 5] ^= 0x55;
        for (unsigned threads : {1u, 4u}) EXPECT_EQ(error_of(file(sizes, corrupt, inline_base64), threads), where + size_bad);
    }
    // Base64 broken inside block 105: a corrupt earlier block is still the first error; alone,
    // the base64 error is.
    const std::size_t header_bytes = 8 * (3 + count);
    const std::size_t quantum = (header_bytes + start_of(105) + 100) / 3;  // a 4-character quantum inside block 105
    const auto broken = [&](const std::string& bytes) {
        std::string f = file(blocks.compressed_sizes, bytes, true);
        const std::size_t text = f.find("binary\">") + 8;
        f[text + 4 * quantum + 1] = '!';
        return f;
    };
    std::string corrupt = blocks.bytes;
    corrupt[start_of(100) + 5] ^= 0x55;
    for (unsigned threads : {1u, 4u}) {
        EXPECT_EQ(error_of(broken(corrupt), threads), where + late_bad);
        EXPECT_EQ(error_of(broken(blocks.bytes), threads), where + "the data holds a character that is not base64");
    }
    // A block of no bytes in base64 is reported as the data ending (take of nothing into an
    // empty buffer), as the block-by-block loop always did.
    const std::string empty_block = one_piece("compressor=\"vtkZLibDataCompressor\"",
                                              "<DataArray type=\"Float32\" NumberOfComponents=\"3\" format=\"binary\">" +
                                                  base64(u32(1) + u32(36) + u32(36) + u32(0)) + "</DataArray>",
                                              kAsciiCells);
    for (unsigned threads : {1u, 4u}) {
        EXPECT_EQ(error_of(empty_block, threads), "h.vtu: Points array (line 6): the data ends early (truncated?)");
    }
}

// Thousands of pieces (one triangle each, point data in each): concatenated in order. Messages
// name lines, and the line numbers are counted once over the file, not once per tag.
TEST(VtuReader, ManyPiecesConcatenateInOrder) {
    const uint32_t pieces = 5000;
    std::string file = "<VTKFile type=\"UnstructuredGrid\">\n<UnstructuredGrid>\n";
    for (uint32_t k = 0; k < pieces; ++k) {
        file += "<Piece NumberOfPoints=\"3\" NumberOfCells=\"1\">\n<PointData><DataArray type=\"UInt32\" Name=\"k\">" +
                std::to_string(k) + " " + std::to_string(k) + " " + std::to_string(k) +
                "</DataArray></PointData>\n<Points>" + kAsciiPoints + "</Points>\n<Cells>" + kAsciiCells +
                "</Cells>\n</Piece>\n";
    }
    file += "</UnstructuredGrid>\n</VTKFile>\n";
    const VtuMesh vtu = parse_vtu(file, "many.vtu");
    ASSERT_EQ(vtu.mesh.triangles.size(), pieces);
    EXPECT_EQ(vtu.mesh.triangles.back(), (Triangle{3 * pieces - 3, 3 * pieces - 2, 3 * pieces - 1}));
    ASSERT_EQ(vtu.point_data.size(), 1u);
    ASSERT_EQ(vtu.point_data[0].size(), 3u * pieces);
    EXPECT_EQ(vtu.point_data[0].value(3 * pieces - 1), pieces - 1);
    // An error in the last piece names its line.
    std::string quad = file;
    quad.replace(quad.rfind(">5</DataArray>"), 2, ">9");
    expect_error_containing([&] { parse_vtu(quad, "many.vtu"); }, "cell 4999 is a quad (VTK type 9)");
    std::string renamed = file;
    renamed.replace(renamed.rfind("Name=\"k\""), 8, "Name=\"j\"");
    expect_error_containing([&] { parse_vtu(renamed, "many.vtu"); },
                            "piece 4999's point data array 'j' does not match piece 0's 'k'");
    std::string bad_components = file;
    bad_components.replace(bad_components.rfind("NumberOfComponents=\"3\""), 22, "NumberOfComponents=\"x\"");
    expect_error_containing([&] { parse_vtu(bad_components, "many.vtu"); },
                            "<DataArray> has a bad NumberOfComponents 'x' (line 25000)");
}

TEST(VtuReader, EveryBadFixtureIsRefusedWithItsReason) {
    const struct {
        const char* file;
        ErrorCode code;
        const char* message;
    } cases[] = {
        {"mesh.vtu", ErrorCode::corrupt, "no UnstructuredGrid Piece in the file"},
        {"vtu_bad_base64_character.vtu", ErrorCode::corrupt, "Points array (line 6): the data holds a character that is not base64"},
        {"vtu_bad_zlib.vtu", ErrorCode::corrupt, "Points array (line 6): compressed block 0 of 1 is not valid zlib data of 144 bytes"},
        {"vtu_huge_block_count.vtu", ErrorCode::corrupt, "declares 1099511627776 compressed blocks, more than the data can hold"},
        {"vtu_huge_compressed_size.vtu", ErrorCode::corrupt, "compressed block 0 declares 2400000000 bytes, more than its 55 compressed bytes can hold"},
        {"vtu_huge_point_count.vtu", ErrorCode::corrupt, "needs 12000000000 values, more than its 149 characters of text can hold"},
        {"vtu_index_out_of_range.vtu", ErrorCode::corrupt, "cell 7 refers to point 6, out of range (6 points)"},
        {"vtu_lzma_compressor.vtu", ErrorCode::invalid_input, "compressor 'vtkLZMADataCompressor' is not supported"},
        {"vtu_missing_types.vtu", ErrorCode::corrupt, "Cells has no 'types' DataArray"},
        {"vtu_not_xml.vtu", ErrorCode::corrupt, "bad XML at line 2"},
        {"vtu_offset_past_end.vtu", ErrorCode::corrupt, "offset 99999 is past the end of the 74 bytes of appended data"},
        {"vtu_polydata.vtu", ErrorCode::invalid_input, "is a VTK 'PolyData' file; only UnstructuredGrid (.vtu) files are read"},
        {"vtu_polygon_of_4.vtu", ErrorCode::invalid_input, "cell 1 is a polygon (VTK type 7) of 4 points (offset 7)"},
        {"vtu_quad_cells.vtu", ErrorCode::invalid_input, "cell 5 is a quad (VTK type 9); only triangles (VTK type 5)"},
        {"vtu_truncated_appended.vtu", ErrorCode::truncated, "a compressed block of 55 bytes is longer than the data left (truncated?)"},
        {"vtu_truncated_base64.vtu", ErrorCode::truncated, "declares 144 bytes, but only 69 remain (truncated?)"},
        {"vtu_unclosed.vtu", ErrorCode::truncated, "the file ends inside <VTKFile> (truncated?)"},
        {"vtu_unknown_type.vtu", ErrorCode::invalid_input, "DataArray '' (line 6) has type 'Float16', which is not read"},
        {"vtu_wrong_header_size.vtu", ErrorCode::corrupt, "its header says 136 bytes, expected 144 bytes (18 Float64 values)"},
        {"vtu_wrong_point_count.vtu", ErrorCode::corrupt, "Points array (line 6): holds 18 values, expected 21"},
    };
    for (const auto& c : cases) {
        const std::string path = bad_fixture(c.file);
        ASSERT_TRUE(fs::exists(path)) << path;
        expect_error_containing([&] { read_vtu(path); }, c.message);
        expect_error_containing([&] { read_vtu(path); }, path + ": ");
        try {
            read_vtu(path);
        } catch (const Error& e) {
            EXPECT_EQ(e.code(), c.code) << c.file << ": " << error_code_name(e.code());
        }
    }
}

// Every prefix of a compressed appended file and of an inline base64 file, and random byte
// flips: an amc::Error naming the file or a mesh, nothing else (the ASan build checks the reads).
TEST(VtuReader, TruncationsAndByteFlipsNeverCrash) {
    std::mt19937 rng(2024);
    for (const char* file : {"vtk_appended_raw_zlib_uint32.vtu", "vtk_binary_zlib.vtu", "dune_appended_base64.vtu",
                             "meshio_ascii.vtu"}) {
        const std::string bytes = read_bytes(vtu_fixture(file));
        ASSERT_FALSE(bytes.empty());
        std::size_t refused = 0;
        for (std::size_t n = 0; n < bytes.size(); ++n) {
            try {
                VtuMesh vtu = parse_vtu(bytes.substr(0, n), "t.vtu");
                validate_triangle_mesh(vtu.mesh, "t.vtu");
            } catch (const Error& e) {
                ASSERT_NE(std::string(e.what()).find("t.vtu: "), std::string::npos) << e.what();
                ++refused;
            }
        }
        // Only prefixes that cut nothing but the closing tags after the data can be accepted.
        EXPECT_GE(refused, bytes.size() - 40) << file;
        for (int trial = 0; trial < 1500; ++trial) {
            std::string flipped = bytes;
            for (int k = 0, flips = 1 + int(rng() % 4); k < flips; ++k) {
                flipped[rng() % flipped.size()] = static_cast<char>(rng());
            }
            try {
                VtuMesh vtu = parse_vtu(flipped, "f.vtu");
                validate_triangle_mesh(vtu.mesh, "f.vtu");
            } catch (const Error& e) {
                ASSERT_NE(std::string(e.what()).find("f.vtu: "), std::string::npos) << e.what();
            }
        }
    }
}
