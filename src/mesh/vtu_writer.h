// VTK XML UnstructuredGrid (.vtu) writer: binary as VTK writes it by default (appended raw data,
// zlib blocks, UInt64 headers), or ASCII; points, triangles, point data and cell data.
#pragma once

#include <string>
#include <vector>

#include "amc/mesh.h"

namespace amc {

// The file's bytes. Points as Float32 when mesh.single_precision, else Float64; connectivity
// and offsets as Int32 when they fit, else Int64; types as UInt8 (5, VTK_TRIANGLE). Arrays must
// hold one tuple per vertex (point_data) or per triangle (cell_data). Throws Error.
std::string format_vtu(const TriangleMesh& mesh, const std::vector<DataArray>& point_data,
                       const std::vector<DataArray>& cell_data, VtuEncoding encoding);

}  // namespace amc
