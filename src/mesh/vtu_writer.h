// VTK XML UnstructuredGrid (.vtu) writer: binary as VTK writes it by default (appended raw data,
// zlib blocks, UInt64 headers), or ASCII; points, triangles, point data and cell data.
#pragma once

#include <string>
#include <vector>

#include "amc/mesh_io.h"

namespace amc {

// The file's bytes. Points as Float32 when mesh.single_precision, else Float64; connectivity
// and offsets as Int32 when they fit, else Int64; types as UInt8 (5, VTK_TRIANGLE). Arrays must
// hold one tuple per vertex (point_data) or per triangle (cell_data). The zlib blocks are
// compressed on up to `threads` threads (0: every core; the bytes do not depend on it). Throws Error.
std::string format_vtu(const TriangleMesh& mesh, const std::vector<DataArray>& point_data,
                       const std::vector<DataArray>& cell_data, VtuEncoding encoding, unsigned threads = 0);

// Cells of one VTK type with `corners` points each: `count` cells, their point indices one cell
// after the other in `connectivity` (the octree forests' quads and hexahedra, say).
struct VtuCells {
    const uint32_t* connectivity;
    std::size_t count;
    int corners;
    uint8_t vtk_type;
};

// format_vtu for any such cells; points as Float32 when single_precision.
std::string format_vtu_cells(const std::vector<Vec3>& positions, bool single_precision, const VtuCells& cells,
                             const std::vector<DataArray>& point_data, const std::vector<DataArray>& cell_data,
                             VtuEncoding encoding, unsigned threads = 0);

}  // namespace amc
