// Writes the VTU files that tests/vtu_interop_test.py opens with meshio and VTK: a grid with point
// and cell arrays of every value type, binary (zlib) and ASCII, single and double precision.
// The values follow formulas that the Python test computes again.
//   vtu_write_sample OUT_DIR
#include <cstdio>
#include <string>
#include <vector>

#include "amc/mesh.h"
#include "amc/mesh_io.h"

using namespace amc;

namespace {

VtuMesh sample(bool single_precision) {
    const uint32_t w = 40, h = 30;  // 1271 points, 2400 triangles: several zlib blocks per array
    VtuMesh vtu;
    TriangleMesh& mesh = vtu.mesh;
    mesh.single_precision = single_precision;
    for (uint32_t j = 0; j <= h; ++j) {
        for (uint32_t i = 0; i <= w; ++i) {
            Vec3 p{i / 3.0, j * 0.1, (i * j % 7) / 7.0};
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
    const std::size_t n = mesh.positions.size(), m = mesh.triangles.size();
    std::vector<double> temperature(n);
    std::vector<float> velocity(3 * n);
    std::vector<int64_t> id(n);
    std::vector<uint16_t> u16(n);
    for (std::size_t i = 0; i < n; ++i) {
        temperature[i] = i / 3.0 + 0.1;
        for (int k = 0; k < 3; ++k) velocity[3 * i + k] = static_cast<float>(i + k / 10.0);
        id[i] = (int64_t(1) << 60) + int64_t(i);
        u16[i] = static_cast<uint16_t>(i * 7919 % 65536);
    }
    vtu.point_data = {{"temperature", 1, temperature}, {"velocity", 3, velocity}, {"id", 1, id}, {"u16", 1, u16}};
    CellData cells;
    std::vector<int32_t> material(m);
    std::vector<uint64_t> big(m);
    std::vector<int8_t> i8(m);
    std::vector<int16_t> i16(m);
    std::vector<uint32_t> u32(m);
    for (std::size_t t = 0; t < m; ++t) {
        cells.level.push_back(static_cast<uint8_t>(t % 5));
        cells.is_green.push_back(static_cast<uint8_t>(t % 2));
        material[t] = -1000 * int32_t(t);
        big[t] = (uint64_t(1) << 63) + t;
        i8[t] = static_cast<int8_t>(int(t % 256) - 128);
        i16[t] = static_cast<int16_t>(-int(t));
        u32[t] = static_cast<uint32_t>(4000000000u - t);
    }
    vtu.cell_data = cell_data_arrays(cells);
    vtu.cell_data.insert(vtu.cell_data.end(), {{"material", 1, material}, {"big", 1, big}, {"i8", 1, i8},
                                               {"i16", 1, i16}, {"u32", 1, u32}});
    return vtu;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: vtu_write_sample OUT_DIR\n");
        return 2;
    }
    const std::string dir = argv[1];
    try {
        write_vtu(dir + "/binary_double.vtu", sample(false));
        write_vtu(dir + "/binary_single.vtu", sample(true));
        write_vtu(dir + "/ascii_double.vtu", sample(false), VtuEncoding::ascii);
        write_vtu(dir + "/ascii_single.vtu", sample(true), VtuEncoding::ascii);
    } catch (const Error& e) {
        std::fprintf(stderr, "vtu_write_sample: %s\n", e.what());
        return 1;
    }
    return 0;
}
