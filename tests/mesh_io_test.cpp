// Mesh readers, writers and validation: bit-exact round trips, hand-written inputs in every
// encoding, malformed files (tests/data/bad), truncations and byte flips, and the validation rules.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include "amc/mesh.h"
#include "amc/mesh_io.h"
#include "mesh/obj_io.h"
#include "mesh/off_io.h"
#include "mesh/ply_io.h"
#include "mesh/text_number.h"

namespace fs = std::filesystem;
using namespace amc;

namespace {

// A fresh directory per test, removed at the end.
class TempDir {
public:
    TempDir() {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        path_ = fs::temp_directory_path() /
                (std::string("amc_mesh_io_") + info->test_suite_name() + "_" + info->name() + "_" +
                 std::to_string(std::random_device{}()));
        fs::create_directories(path_);
    }
    ~TempDir() {
        std::error_code ec;
        fs::remove_all(path_, ec);
    }
    std::string file(const std::string& name) const { return (path_ / name).string(); }
    const fs::path& path() const { return path_; }

private:
    fs::path path_;
};

std::string read_bytes(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

// An n x m grid of quads split into triangles, consistently oriented; wrapped in both directions
// it is a torus (genus 1), otherwise a disc with one boundary loop.
TriangleMesh grid_mesh(uint32_t n, uint32_t m, bool torus) {
    TriangleMesh mesh;
    const uint32_t rows = torus ? n : n + 1, cols = torus ? m : m + 1;
    for (uint32_t i = 0; i < rows; ++i) {
        for (uint32_t j = 0; j < cols; ++j) {
            const double two_pi = 6.283185307179586;
            double u = two_pi * i / rows, v = two_pi * j / cols;
            mesh.positions.push_back(torus ? Vec3{(2 + std::cos(v)) * std::cos(u),
                                                  (2 + std::cos(v)) * std::sin(u), std::sin(v)}
                                           : Vec3{double(i), double(j), 0.25 * i * j});
        }
    }
    auto id = [&](uint32_t i, uint32_t j) { return (i % rows) * cols + (j % cols); };
    for (uint32_t i = 0; i < n; ++i) {
        for (uint32_t j = 0; j < m; ++j) {
            uint32_t a = id(i, j), b = id(i + 1, j), c = id(i + 1, j + 1), d = id(i, j + 1);
            mesh.triangles.push_back({a, b, c});
            mesh.triangles.push_back({a, c, d});
        }
    }
    return mesh;
}

TriangleMesh tetrahedron() {
    TriangleMesh mesh;
    mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    mesh.triangles = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {2, 0, 3}};
    return mesh;
}

uint64_t bits(double d) {
    uint64_t u;
    std::memcpy(&u, &d, 8);
    return u;
}

void expect_bit_exact(const TriangleMesh& a, const TriangleMesh& b) {
    ASSERT_EQ(a.positions.size(), b.positions.size());
    ASSERT_EQ(a.triangles, b.triangles);
    EXPECT_EQ(a.single_precision, b.single_precision);
    for (std::size_t i = 0; i < a.positions.size(); ++i) {
        const Vec3 &p = a.positions[i], &q = b.positions[i];
        ASSERT_EQ(bits(p.x), bits(q.x)) << "vertex " << i << " x " << p.x << " vs " << q.x;
        ASSERT_EQ(bits(p.y), bits(q.y)) << "vertex " << i << " y " << p.y << " vs " << q.y;
        ASSERT_EQ(bits(p.z), bits(q.z)) << "vertex " << i << " z " << p.z << " vs " << q.z;
    }
}

// A torus with coordinates that stress decimal round trips: random bit patterns of every
// magnitude, negative zero, denormals and the extremes of the type.
TriangleMesh stress_mesh(bool single, uint32_t seed) {
    TriangleMesh mesh = grid_mesh(12, 9, true);
    std::mt19937_64 rng(seed);
    std::vector<double> values;
    if (single) {
        using L = std::numeric_limits<float>;
        for (float f : {-0.0f, 0.0f, L::denorm_min(), -L::denorm_min(), L::min(), L::max(),
                        -L::max(), 0.1f, 1.0f / 3.0f, 16777217.0f, 1e-40f}) {
            values.push_back(f);
        }
        while (values.size() < mesh.positions.size() * 3) {
            uint32_t u = static_cast<uint32_t>(rng());
            float f;
            std::memcpy(&f, &u, 4);
            if (std::isfinite(f)) values.push_back(f);
        }
    } else {
        using L = std::numeric_limits<double>;
        for (double d : {-0.0, 0.0, L::denorm_min(), -L::denorm_min(), L::min(), L::max(),
                         -L::max(), 0.1, 1.0 / 3.0, 1e-310, 9007199254740993.0, 5e-324, 1e308,
                         -2.2250738585072009e-308}) {
            values.push_back(d);
        }
        while (values.size() < mesh.positions.size() * 3) {
            uint64_t u = rng();
            double d;
            std::memcpy(&d, &u, 8);
            if (std::isfinite(d)) values.push_back(rng() % 3 == 0 ? std::ldexp(d, -900) : d);
        }
    }
    std::shuffle(values.begin() + 4, values.end(), rng);
    for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
        mesh.positions[i] = {values[3 * i], values[3 * i + 1], values[3 * i + 2]};
    }
    mesh.single_precision = single;
    return mesh;
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

void expect_invalid(const TriangleMesh& mesh, const std::string& needle) {
    expect_error_containing([&] { validate_triangle_mesh(mesh, "m.obj"); }, "m.obj: " + needle);
}

// Little- and big-endian byte builders for hand-written binary PLY.
struct Bytes {
    std::string data;
    bool big_endian = false;
    template <typename T>
    Bytes& put(T value) {
        char b[sizeof(T)];
        std::memcpy(b, &value, sizeof(T));
        if (big_endian) std::reverse(b, b + sizeof(T));
        data.append(b, sizeof(T));
        return *this;
    }
};

}  // namespace

// ---------------------------------------------------------------------------------------------
// Round trips

class RoundTrip : public ::testing::TestWithParam<std::tuple<std::string, bool>> {};

TEST_P(RoundTrip, BitExactOnStressCoordinates) {
    const auto& [extension, single] = GetParam();
    TempDir dir;
    for (uint32_t seed = 1; seed <= 3; ++seed) {
        const TriangleMesh mesh = stress_mesh(single, seed);
        const std::string path = dir.file("mesh" + extension);
        write_mesh(path, mesh);
        expect_bit_exact(mesh, read_mesh(path));
    }
    // Nothing but the output is left in the directory.
    EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator()), 1);
}

INSTANTIATE_TEST_SUITE_P(Formats, RoundTrip,
                         ::testing::Combine(::testing::Values(".obj", ".off", ".ply", ".OBJ"),
                                            ::testing::Bool()));

TEST(RoundTrip, PlyWritesFloatOrDoubleByPrecision) {
    TriangleMesh mesh = tetrahedron();
    mesh.single_precision = true;
    EXPECT_NE(format_ply(mesh).find("property float x\n"), std::string::npos);
    mesh.single_precision = false;
    EXPECT_NE(format_ply(mesh).find("property double x\n"), std::string::npos);
    EXPECT_EQ(parse_ply(format_ply(mesh), "t.ply").triangles, mesh.triangles);
}

TEST(RoundTrip, PlyCellDataIsWrittenInAsciiAndSkippedOnRead) {
    TriangleMesh mesh = grid_mesh(3, 3, false);
    mesh.single_precision = true;  // small integers and quarters: read back as floats
    CellData cells;
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
        cells.level.push_back(static_cast<uint8_t>(t % 5));
        cells.is_green.push_back(static_cast<uint8_t>(t % 2));
    }
    const std::string ascii = format_ply(mesh, &cells, MeshEncoding::ascii);
    EXPECT_NE(ascii.find("format ascii 1.0\n"), std::string::npos);
    EXPECT_NE(ascii.find("property uchar level\nproperty uchar green\nend_header\n"), std::string::npos);
    EXPECT_NE(ascii.find("\n3 " + std::to_string(mesh.triangles[4][0]) + " " +
                         std::to_string(mesh.triangles[4][1]) + " " + std::to_string(mesh.triangles[4][2]) +
                         " 4 0\n"),
              std::string::npos);
    expect_bit_exact(mesh, parse_ply(ascii, "t.ply"));

    // Binary PLY holds vertices and faces only: meshio 5 reads no other face property there.
    const std::string binary = format_ply(mesh, &cells);
    EXPECT_EQ(binary.find("level"), std::string::npos);
    EXPECT_EQ(binary, format_ply(mesh));
    expect_bit_exact(mesh, parse_ply(binary, "t.ply"));

    cells.level.pop_back();
    TempDir dir;
    EXPECT_THROW(write_mesh(dir.file("x.ply"), mesh, &cells, MeshEncoding::ascii), Error);
    EXPECT_FALSE(fs::exists(dir.file("x.ply")));
}

TEST(RoundTrip, AsciiPlyIsBitExactInDoublePrecision) {
    TriangleMesh mesh = grid_mesh(4, 3, false);
    mesh.single_precision = false;
    for (Vec3& p : mesh.positions) p = {p.x + 0.1, p.y * 1e-300, -p.z - 1.0 / 3.0};
    const TriangleMesh back = parse_ply(format_ply(mesh, nullptr, MeshEncoding::ascii), "t.ply");
    expect_bit_exact(mesh, back);
    EXPECT_FALSE(back.single_precision);
}

TEST(RoundTrip, SinglePrecisionIsDetectedFromValues) {
    EXPECT_TRUE(parse_off("OFF 3 1 0  0.5 1 2  3 4 5  -0 0.25 8  3 0 1 2", "t.off").single_precision);
    EXPECT_FALSE(parse_off("OFF 3 1 0  0.1 1 2  3 4 5  6 7 8  3 0 1 2", "t.off").single_precision);
    EXPECT_FALSE(parse_obj("v 0.1 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "t.obj").single_precision);
    EXPECT_TRUE(parse_obj("v 0.5 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "t.obj").single_precision);
}

// Float data printed as the shortest decimal of each float (8 or 9 digits on some coordinate)
// is read as floats, and written back as the same text.
TEST(RoundTrip, FloatDecimalsAreReadAsFloats) {
    const std::string obj = "v 0.00040300004 -0.0401785 0.1\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    const TriangleMesh mesh = parse_obj(obj, "t.obj");
    EXPECT_TRUE(mesh.single_precision);
    EXPECT_EQ(mesh.positions[0].x, static_cast<double>(0.00040300004f));
    EXPECT_EQ(mesh.positions[0].z, static_cast<double>(0.1f));
    EXPECT_EQ(format_obj(mesh), obj);
    const TriangleMesh off = parse_off("OFF 3 1 0  0.00040300004 -0.0401785 0.1  1 0 0  0 1 0  3 0 1 2", "t.off");
    EXPECT_TRUE(off.single_precision);
    expect_bit_exact(mesh, off);
    EXPECT_EQ(format_off(off), "OFF\n3 1 0\n0.00040300004 -0.0401785 0.1\n1 0 0\n0 1 0\n3 0 1 2\n");

    // One coordinate no float prints (9 digits, not a float's shortest): all stay doubles.
    const TriangleMesh doubles = parse_obj("v 0.00040300004 0.123456789 0.1\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "t.obj");
    EXPECT_FALSE(doubles.single_precision);
    EXPECT_EQ(doubles.positions[0].x, 0.00040300004);
    EXPECT_EQ(doubles.positions[0].z, 0.1);
}

// Floats whose decimals are all short (0.1f) would read back as doubles: they are printed as
// doubles, which read back as exact floats.
TEST(RoundTrip, ShortFloatDecimalsReadBackAsFloats) {
    TriangleMesh mesh = tetrahedron();
    mesh.single_precision = true;
    for (Vec3& p : mesh.positions) p = {static_cast<float>(p.x + 0.1), static_cast<float>(p.y + 0.2), 0.3f};
    for (const TriangleMesh& back : {parse_obj(format_obj(mesh), "t.obj"), parse_off(format_off(mesh), "t.off")}) {
        EXPECT_TRUE(back.single_precision);
        expect_bit_exact(mesh, back);
    }
}

// Any single-precision mesh written as OBJ or OFF reads back single precision, bit for bit:
// floats drawn from their whole range by bit pattern (subnormals, FLT_MAX, signed zeros, short
// and 8-9 digit decimals), meshes of one to three vertices so that the writer's choice (float
// decimals or doubles) varies from mesh to mesh.
TEST(RoundTrip, AnySinglePrecisionMeshReadsBackBitExact) {
    std::mt19937 random(24);
    const auto any_float = [&] {
        for (;;) {
            uint32_t bits = random();
            if (random() % 4 == 0) bits &= 0x807fffffu | (uint32_t(random() % 3) << 23);  // zero, subnormal, tiny exponents
            if (random() % 8 == 0) bits = (bits & 0x80000000u) | (0x7f7fffffu - uint32_t(random() % 4));  // near FLT_MAX
            if (random() % 4 == 0) bits &= 0xffff0000u;  // short decimals
            float f;
            std::memcpy(&f, &bits, 4);
            if (std::isfinite(f)) return f;
        }
    };
    for (int trial = 0; trial < 20000; ++trial) {
        TriangleMesh mesh = tetrahedron();
        mesh.single_precision = true;
        const size_t varied = 1 + size_t(trial % 3);
        for (size_t v = 0; v < mesh.positions.size(); ++v) {
            Vec3& p = mesh.positions[v];
            if (v < varied) p = {any_float(), any_float(), any_float()};
            else p = {static_cast<float>(p.x + 0.1), static_cast<float>(p.y), static_cast<float>(p.z)};
        }
        const TriangleMesh obj = parse_obj(format_obj(mesh), "t.obj");
        const TriangleMesh off = parse_off(format_off(mesh), "t.off");
        ASSERT_TRUE(obj.single_precision && off.single_precision) << "trial " << trial << "\n" << format_obj(mesh);
        ASSERT_EQ(std::memcmp(obj.positions.data(), mesh.positions.data(), mesh.positions.size() * sizeof(Vec3)), 0)
            << "trial " << trial << "\n" << format_obj(mesh);
        ASSERT_EQ(std::memcmp(off.positions.data(), mesh.positions.data(), mesh.positions.size() * sizeof(Vec3)), 0)
            << "trial " << trial << "\n" << format_off(mesh);
    }
}

// ---------------------------------------------------------------------------------------------
// Readers on hand-written input

TEST(ObjReader, AcceptsCommentsGroupsTriplesRelativeIndicesAndCrlf) {
    const std::string text =
        "# comment\r\nmtllib none.mtl\r\no thing\r\n  v 0 0 0\r\nv\t1 0 0 1.0\r\nv 0 1 0\r\n"
        "v +0 0 .5e1\r\nvt 0 0\r\nvn 0 0 1\r\ng a\r\nusemtl none\r\nf 1/1/1 3/1/1 2/1/1\r\n"
        "f 1//1 2//1 4//1\r\ng b\r\nf -3 -2 -1\r\nf 3 1 4 \r\n";
    const TriangleMesh mesh = parse_obj(text, "t.obj");
    ASSERT_EQ(mesh.positions.size(), 4u);
    EXPECT_EQ(mesh.positions[1], (Vec3{1, 0, 0}));
    EXPECT_EQ(mesh.positions[3], (Vec3{0, 0, 5}));
    const std::vector<Triangle> expected = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {2, 0, 3}};
    EXPECT_EQ(mesh.triangles, expected);
    validate_triangle_mesh(mesh, "t.obj");
}

TEST(ObjReader, RejectsPolygonsOutOfRangeAndMalformedCoordinates) {
    const std::string v = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n";
    expect_error_containing([&] { parse_obj(v + "f 1 2 3\nf 1 2 3 4\n", "q.obj"); },
                            "q.obj: face 1 (line 6) has 4 vertices; only triangle meshes");
    expect_error_containing([&] { parse_obj(v + "f 1 2 7\n", "r.obj"); },
                            "r.obj: face 0 has vertex index 7 out of range (4 vertices, counted from 1)");
    expect_error_containing([&] { parse_obj(v + "f 1 2 -5\n", "r.obj"); },
                            "r.obj: face 0 has a relative vertex index before the first vertex");
    expect_error_containing([&] { parse_obj("v 0 0\n", "c.obj"); },
                            "c.obj: vertex 0 (line 1) has fewer than 3 coordinates");
    expect_error_containing([&] { parse_obj("v 0 0 1x\n", "c.obj"); }, "malformed coordinate '1x'");
    expect_error_containing([&] { parse_obj(v + "f 0 1 2\n", "z.obj"); }, "z.obj: OBJ parse error");
}

// parse_int is hand-written for speed: it must accept and give what std::from_chars does (plus
// a leading '+'), at the ends of the range and on random tokens.
TEST(TextNumber, ParseIntAgreesWithFromChars) {
    auto reference = [](std::string_view token, int64_t& out) {
        std::string_view digits = token;
        if (!digits.empty() && digits[0] == '+') {
            digits.remove_prefix(1);
            if (!digits.empty() && (digits[0] == '+' || digits[0] == '-')) return false;
        }
        const char* last = digits.data() + digits.size();
        auto [ptr, ec] = std::from_chars(digits.data(), last, out, 10);
        return ec == std::errc() && ptr == last;
    };
    std::vector<std::string> tokens = {"", "+", "-", "+-1", "-+1", "0", "-0", "+0", "007", "12a", "1 ",
                                       "9223372036854775807", "9223372036854775808", "-9223372036854775808",
                                       "-9223372036854775809", "+9223372036854775807", "18446744073709551616",
                                       "99999999999999999999", "1e3", "0x1f", "--1"};
    std::mt19937_64 random(7);
    const std::string alphabet = "0123456789+- x";
    for (int trial = 0; trial < 20000; ++trial) {
        std::string token;
        const int length = int(random() % 22);
        for (int k = 0; k < length; ++k) token += alphabet[random() % (trial % 2 ? 10 : alphabet.size())];
        tokens.push_back(token);
    }
    for (const std::string& token : tokens) {
        int64_t expected = -1, got = -1;
        const bool ok = reference(token, expected);
        ASSERT_EQ(text::parse_int(token, got), ok) << "'" << token << "'";
        if (ok) {
            ASSERT_EQ(got, expected) << "'" << token << "'";
        }
    }
}

TEST(ObjReader, ChecksEveryPartOfAFaceCorner) {
    const std::string v = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
    EXPECT_EQ(parse_obj(v + "f 1/2 2//3 3/-1/-2\n", "t.obj").triangles, (std::vector<Triangle>{{0, 1, 2}}));
    // A face may name a vertex that a later line defines; a relative index counts lines read so far.
    EXPECT_EQ(parse_obj("v 0 0 0\nv 1 0 0\nf -2 -1 3\nv 0 1 0\n", "t.obj").triangles,
              (std::vector<Triangle>{{0, 1, 2}}));
    for (const char* face : {"f 1/0 2 3\n", "f 1// 2 3\n", "f 1/ 2 3\n", "f 1/2/3/4 2 3\n", "f x 2 3\n",
                             "f 1 2 3.0\n", "f 1//0 2 3\n", "f 99999999999999999999 2 3\n"}) {
        expect_error_containing([&] { parse_obj(v + face, "m.obj"); }, "m.obj: OBJ parse error: face 0 (line 4)");
    }
}

TEST(OffReader, AcceptsCommentsTabsColoursAndTrailingWhitespace) {
    const std::string text =
        "OFF # header comment\n# a comment line\n\t4  4\t0 \r\n0 0 0\n\t1 0 0  # x axis\n"
        "0\t1\t0\n0 0 1\n3 0 2 1 255 0 0\n3  0 1 3\n\t3 1 2 3\n3 2 0 3\n   \t\n  \n";
    const TriangleMesh mesh = parse_off(text, "t.off");
    ASSERT_EQ(mesh.positions.size(), 4u);
    EXPECT_EQ(mesh.positions[2], (Vec3{0, 1, 0}));
    EXPECT_EQ(mesh.triangles, tetrahedron().triangles);
    EXPECT_EQ(parse_off("OFF 4 4 0 0 0 0 1 0 0 0 1 0 0 0 1\n3 0 2 1\n3 0 1 3\n3 1 2 3\n3 2 0 3",
                        "t.off")
                  .triangles,
              tetrahedron().triangles);
}

TEST(OffReader, RejectsBadCountsBeforeAllocating) {
    expect_error_containing([] { parse_off("OFF\n4000000000 1 0\n0 0 0\n", "h.off"); },
                            "h.off: header declares 4000000000 vertices");
    expect_error_containing([] { parse_off("OFF\n3 1000000 0\n0 0 0\n0 0 0\n0 0 0\n3 0 1 2\n", "h.off"); },
                            "h.off: header declares");
    expect_error_containing([] { parse_off("OFF\n-3 1 0\n", "n.off"); }, "n.off: bad vertex count");
    expect_error_containing([] { parse_off("OFF\n3 1\n", "t.off"); }, "t.off: truncated header");
    expect_error_containing([] { parse_off("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1\n        ", "t.off"); },
                            "t.off: truncated");
}

// The same mesh (a tetrahedron with an extra vertex property, a list property on the vertices,
// an "edge" element before the faces and a face property after the list) in all three encodings.
class PlyEncodings : public ::testing::TestWithParam<std::string> {};

TEST_P(PlyEncodings, ReadsTetrahedronSkippingExtraData) {
    const std::string encoding = GetParam();
    const std::vector<Vec3> positions = {{0, 0, 0}, {1.5, 0, 0}, {0, -2.25, 0}, {0, 0, 1e-3}};
    const std::vector<Triangle> triangles = tetrahedron().triangles;
    std::string bytes = "ply\r\nformat " + encoding +
                        " 1.0\r\ncomment hand written\nobj_info test\n"
                        "element vertex 4\nproperty uchar red\nproperty double x\n"
                        "property list int16 uint32 neighbours\nproperty float32 nx\n"
                        "property double y\nproperty double z\n"
                        "element edge 2\nproperty int vertex1\nproperty list uint8 float64 w\n"
                        "element face 4\nproperty list uchar uint vertex_index\n"
                        "property int16 flags\nend_header\n";
    if (encoding == "ascii") {
        bytes += "7 0 2 1 2 0.5 0 0\n8 1.5 0 0 0 0\n9 0 1 3 -1 -2.25 0\n10 0 3 1 2 3 0 0 1e-3\n";
        bytes += "0 2 1.5 2.5\n1 0\n";
        for (const Triangle& t : triangles) {
            bytes += "3 " + std::to_string(t[0]) + " " + std::to_string(t[1]) + " " +
                     std::to_string(t[2]) + " -7\n";
        }
    } else {
        Bytes b;
        b.big_endian = encoding == "binary_big_endian";
        for (std::size_t v = 0; v < 4; ++v) {
            b.put<uint8_t>(static_cast<uint8_t>(v)).put(positions[v].x);
            b.put<int16_t>(static_cast<int16_t>(v)); 
            for (std::size_t k = 0; k < v; ++k) b.put<uint32_t>(static_cast<uint32_t>(k));
            b.put(0.5f).put(positions[v].y).put(positions[v].z);
        }
        b.put<int32_t>(0).put<uint8_t>(2).put(1.5).put(2.5);
        b.put<int32_t>(1).put<uint8_t>(0);
        for (const Triangle& t : triangles) {
            b.put<uint8_t>(3).put(t[0]).put(t[1]).put(t[2]).put<int16_t>(-7);
        }
        bytes += b.data;
    }
    const TriangleMesh mesh = parse_ply(bytes, "t.ply");
    ASSERT_EQ(mesh.positions.size(), 4u);
    for (std::size_t v = 0; v < 4; ++v) EXPECT_EQ(mesh.positions[v], positions[v]) << v;
    EXPECT_EQ(mesh.triangles, triangles);
    EXPECT_FALSE(mesh.single_precision);  // 1e-3 is not a float
    validate_triangle_mesh(mesh, "t.ply");

    // Every truncation of the data fails cleanly (ASCII may lose only trailing white space).
    const std::size_t data_start = bytes.find("end_header\n") + 11;
    for (std::size_t n = 0; n + 1 < bytes.size(); ++n) {
        if (encoding == "ascii" && n >= data_start) continue;  // checked below
        EXPECT_THROW(parse_ply(bytes.substr(0, n), "t.ply"), Error) << n;
    }
    if (encoding == "ascii") {
        EXPECT_THROW(parse_ply(bytes.substr(0, bytes.size() - 5), "t.ply"), Error);
    }
}

INSTANTIATE_TEST_SUITE_P(All, PlyEncodings,
                         ::testing::Values("ascii", "binary_little_endian", "binary_big_endian"));

TEST(PlyReader, FloatAndIntegerCoordinateTypes) {
    // ASCII float properties are read as float, so "0.1" is the float 0.1f.
    const std::string header_f =
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
    const TriangleMesh f = parse_ply(header_f + "0.1 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", "f.ply");
    EXPECT_TRUE(f.single_precision);
    EXPECT_EQ(f.positions[0].x, static_cast<double>(0.1f));
    const std::string header_i =
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty int8 x\nproperty short y\n"
        "property uint z\nelement face 1\nproperty list uint16 int8 vertex_indices\nend_header\n";
    const TriangleMesh i = parse_ply(header_i + "-128 -32768 4294967295\n1 0 0\n0 1 0\n3 0 1 2\n", "i.ply");
    EXPECT_EQ(i.positions[0], (Vec3{-128, -32768, 4294967295.0}));
    EXPECT_FALSE(i.single_precision);  // 2^32 - 1 needs 32 bits of mantissa
    expect_error_containing(
        [&] { parse_ply(header_i + "-129 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", "o.ply"); },
        "o.ply: vertex 0 has value -129 out of the range of its type (line 10)");
}

TEST(PlyReader, RejectsHugeCountsBeforeAllocating) {
    std::string header =
        "ply\nformat binary_big_endian 1.0\nelement vertex 18446744073709551615\n"
        "property double x\nproperty double y\nproperty double z\nelement face 1\n"
        "property list uchar int vertex_indices\nend_header\n";
    expect_error_containing([&] { parse_ply(header + std::string(64, '\0'), "h.ply"); },
                            "h.ply: bad PLY header: malformed element line");
    header = "ply\nformat binary_little_endian 1.0\nelement junk 4000000000\nproperty float a\n"
             "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
             "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
    expect_error_containing([&] { parse_ply(header + std::string(64, '\0'), "h.ply"); },
                            "h.ply: element 'junk' declares 4000000000 items");
}

// ---------------------------------------------------------------------------------------------
// Files and formats

TEST(MeshIo, FormatFromExtensionIsCaseInsensitive) {
    EXPECT_EQ(mesh_format_from_path("a/b.obj"), MeshFormat::obj);
    EXPECT_EQ(mesh_format_from_path("B.OFF"), MeshFormat::off);
    EXPECT_EQ(mesh_format_from_path("x.y.Ply"), MeshFormat::ply);
    EXPECT_EQ(mesh_format_from_path("leaf.vtu"), MeshFormat::vtu);
    expect_error_containing([] { mesh_format_from_path("m.stl"); }, "m.stl: unknown mesh format '.stl'");
    expect_error_containing([] { mesh_format_from_path("dir.obj/m"); }, "dir.obj/m: unknown mesh format");
}

TEST(MeshIo, MissingFileAndDirectoryNameThePath) {
    TempDir dir;
    expect_error_containing([&] { read_mesh(dir.file("missing.obj")); }, "missing.obj: cannot open");
    fs::create_directory(dir.file("folder.off"));
    expect_error_containing([&] { read_mesh(dir.file("folder.off")); }, "folder.off: not a regular file");
}

TEST(MeshIo, WriteFileAtomicallyReplacesAndCleansUp) {
    TempDir dir;
    const std::string path = dir.file("out.bin");
    write_file_atomically(path, "first");
    write_file_atomically(path, std::string("sec\0ond", 7));
    EXPECT_EQ(read_bytes(path), std::string("sec\0ond", 7));
    EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator()), 1);
    expect_error_containing([&] { write_file_atomically(dir.file("no/such/dir/x.obj"), "x"); },
                            "no/such/dir/x.obj");
    // Renaming onto a directory fails: the temporary file is removed.
    fs::create_directory(dir.file("taken.obj"));
    fs::create_directory(dir.file("taken.obj/inside"));
    expect_error_containing([&] { write_mesh(dir.file("taken.obj"), tetrahedron()); }, "taken.obj");
    EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator()), 2);
}

TEST(MeshIo, EveryBadFileThrowsErrorNamingIt) {
    const fs::path bad_dir = fs::path(AMC_TEST_DATA_DIR) / "bad";
    ASSERT_TRUE(fs::is_directory(bad_dir));
    std::size_t count = 0;
    for (const fs::directory_entry& entry : fs::directory_iterator(bad_dir)) {
        const std::string name = entry.path().filename().string();
        ++count;
        try {
            read_mesh(entry.path().string());
            ADD_FAILURE() << name << " was accepted";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(name), std::string::npos)
                << name << ": " << e.what();
        } catch (const std::exception& e) {
            ADD_FAILURE() << name << " threw a non-amc exception: " << e.what();
        }
    }
    EXPECT_GE(count, 15u);
}

// Random byte flips of valid files: readers throw amc::Error or return a mesh, never anything
// else (and the sanitizer build checks that they never read out of bounds).
TEST(MeshIo, ByteFlipsNeverCrash) {
    TriangleMesh mesh = grid_mesh(4, 3, true);
    mesh.single_precision = true;
    struct Case {
        std::string name, bytes;
    };
    const std::vector<Case> cases = {{"f.obj", format_obj(mesh)},
                                     {"f.off", format_off(mesh)},
                                     {"f.ply", format_ply(mesh)}};
    std::mt19937 rng(12345);
    for (const Case& c : cases) {
        for (int trial = 0; trial < 1500; ++trial) {
            std::string bytes = c.bytes;
            const int flips = 1 + static_cast<int>(rng() % 4);
            for (int k = 0; k < flips; ++k) {
                const char pool[] = "0123456789 \n-+.e#/\xff\x80";
                bytes[rng() % bytes.size()] = rng() % 2 ? static_cast<char>(rng())
                                                        : pool[rng() % (sizeof pool - 1)];
            }
            if (rng() % 4 == 0) bytes.resize(rng() % bytes.size());
            try {
                TriangleMesh m = c.name == "f.obj"   ? parse_obj(bytes, c.name)
                                 : c.name == "f.off" ? parse_off(bytes, c.name)
                                                     : parse_ply(bytes, c.name);
                validate_triangle_mesh(m, c.name);
            } catch (const Error& e) {
                ASSERT_NE(std::string(e.what()).find(c.name), std::string::npos) << e.what();
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Validation

TEST(Validation, AcceptsClosedOpenAndHigherGenus) {
    EXPECT_NO_THROW(validate_triangle_mesh(tetrahedron(), "tet"));
    EXPECT_NO_THROW(validate_triangle_mesh(grid_mesh(5, 4, false), "disc"));
    EXPECT_NO_THROW(validate_triangle_mesh(grid_mesh(6, 5, true), "torus"));
    TriangleMesh single;  // one triangle: all boundary
    single.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    single.triangles = {{0, 1, 2}};
    EXPECT_NO_THROW(validate_triangle_mesh(single, "single"));
}

TEST(Validation, RejectsEachDefectNamingTheFirstOffender) {
    TriangleMesh mesh = tetrahedron();
    expect_invalid(TriangleMesh{}, "the mesh has no triangles");

    mesh = tetrahedron();
    mesh.triangles[2] = {1, 2, 9};
    expect_invalid(mesh, "triangle 2 has index 9 out of range (4 vertices)");

    mesh = tetrahedron();
    mesh.positions[3].y = std::numeric_limits<double>::quiet_NaN();
    expect_invalid(mesh, "vertex 3 has a non-finite coordinate");
    mesh.positions[3].y = -std::numeric_limits<double>::infinity();
    expect_invalid(mesh, "vertex 3 has a non-finite coordinate");

    mesh = tetrahedron();
    mesh.triangles[1] = {0, 3, 3};
    expect_invalid(mesh, "triangle 1 is degenerate (repeats vertex 3)");

    mesh = tetrahedron();
    mesh.triangles.push_back({3, 1, 2});  // triangle 2 again, rotated
    mesh.triangles.push_back({0, 1, 2});  // triangle 0 reversed
    expect_invalid(mesh, "triangle 4 repeats triangle 2");

    TriangleMesh pillow;  // two triangles, opposite orientations: every edge used once each way
    pillow.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    pillow.triangles = {{0, 1, 2}, {0, 2, 1}};
    expect_invalid(pillow, "triangle 1 repeats triangle 0");

    mesh = tetrahedron();
    mesh.positions.push_back({5, 5, 5});
    mesh.triangles.push_back({0, 1, 4});
    expect_invalid(mesh, "edge (0,1) is shared by 3 triangles (non-manifold): triangles 0, 1, 4");

    mesh = tetrahedron();
    mesh.triangles[3] = {0, 2, 3};  // flipped
    expect_invalid(mesh, "edge (0,2) is used twice in the same direction by triangles 0 and 3 "
                         "(inconsistent orientation)");

    mesh = tetrahedron();
    mesh.positions.insert(mesh.positions.begin() + 2, Vec3{7, 7, 7});
    for (Triangle& t : mesh.triangles) {
        for (uint32_t& v : t) v += v >= 2;
    }
    expect_invalid(mesh, "vertex 2 is not used by any triangle");
}

// The linear check's verdict against the definition, pair by pair, on random small triangle sets
// (pillows, repeated half-edges, edges of three triangles, fans, valid patches).
TEST(Validation, AgreesWithTheDefinitionOnRandomTriangleSets) {
    std::mt19937 rng(29);
    int invalid = 0;
    for (int trial = 0; trial < 3000; ++trial) {
        TriangleMesh mesh;
        const uint32_t n = 3 + rng() % 5;
        mesh.positions.assign(n, Vec3{0, 0, 0});
        for (uint32_t t = 0, count = 1 + rng() % 6; t < count; ++t) {
            const uint32_t a = rng() % n, b = (a + 1 + rng() % (n - 1)) % n;
            uint32_t c = rng() % n;
            while (c == a || c == b) c = rng() % n;
            mesh.triangles.push_back({a, b, c});
        }
        std::vector<bool> used(n, false);
        for (const Triangle& t : mesh.triangles)
            for (uint32_t v : t) used[v] = true;
        if (std::find(used.begin(), used.end(), false) != used.end()) continue;  // another check's fault
        bool expect_fault = false;
        for (size_t i = 0; i < mesh.triangles.size(); ++i)
            for (size_t j = i + 1; j < mesh.triangles.size(); ++j) {
                Triangle x = mesh.triangles[i], y = mesh.triangles[j];
                for (int k = 0; k < 3; ++k)
                    for (int m = 0; m < 3; ++m)  // the same directed edge twice
                        expect_fault |= x[k] == y[m] && x[(k + 1) % 3] == y[(m + 1) % 3];
                std::sort(x.begin(), x.end());
                std::sort(y.begin(), y.end());
                expect_fault |= x == y;  // a repeated triangle
            }
        invalid += expect_fault;
        bool threw = false;
        try {
            validate_triangle_mesh(mesh, "random");
        } catch (const Error& e) {
            threw = true;
            const std::string message = e.what();
            EXPECT_TRUE(message.find("repeats triangle") != std::string::npos ||
                        message.find("non-manifold") != std::string::npos ||
                        message.find("inconsistent orientation") != std::string::npos)
                << message;
        }
        EXPECT_EQ(threw, expect_fault) << "trial " << trial;
    }
    EXPECT_GT(invalid, 100);
}

TEST(Validation, MillionTrianglesIsFast) {
    const TriangleMesh mesh = grid_mesh(1000, 500, true);
    ASSERT_EQ(mesh.triangles.size(), 1000000u);
    const auto start = std::chrono::steady_clock::now();
    EXPECT_NO_THROW(validate_triangle_mesh(mesh, "big"));
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_LT(seconds, 20.0);  // ~0.2 s in a release build; generous for sanitizers
    TriangleMesh flipped = mesh;
    std::swap(flipped.triangles[777777][0], flipped.triangles[777777][1]);
    EXPECT_THROW(validate_triangle_mesh(flipped, "big"), Error);
}

// ---------------------------------------------------------------------------------------------
// Real meshes (optional: skipped when ../shared/data is absent)

TEST(SharedData, ReadsRealMeshes) {
    const fs::path dir = AMC_SHARED_DATA_DIR;
    if (!fs::is_directory(dir)) GTEST_SKIP() << "no " << dir;
    struct Expected {
        const char* file;
        std::size_t vertices, triangles;
    };
    for (const Expected& e : {Expected{"bunny.obj", 1839, 3674}, Expected{"rabbit-coarse.off", 453, 902},
                              Expected{"camelhead.off", 11381, 22704}, Expected{"femur.obj", 3897, 7798}}) {
        const fs::path path = dir / e.file;
        if (!fs::exists(path)) continue;
        const TriangleMesh mesh = read_mesh(path.string());
        EXPECT_EQ(mesh.positions.size(), e.vertices) << e.file;
        EXPECT_EQ(mesh.triangles.size(), e.triangles) << e.file;
        TempDir tmp;
        for (const char* ext : {".obj", ".off", ".ply"}) {
            write_mesh(tmp.file(std::string("copy") + ext), mesh);
            expect_bit_exact(mesh, read_mesh(tmp.file(std::string("copy") + ext)));
        }
    }
}
