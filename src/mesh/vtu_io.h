// VTK XML UnstructuredGrid (.vtu) output for viewing leaf meshes in ParaView; write only.
#pragma once

#include <string>

#include "amc/mesh.h"

namespace amc {

// ASCII DataArrays: Points (Float32 when mesh.single_precision, else Float64), Cells
// (connectivity, offsets, types = 5 VTK_TRIANGLE), and CellData "level" and "green" (UInt8) for
// the non-empty arrays of `cells` (their sizes must equal the triangle count).
std::string format_vtu(const TriangleMesh& mesh, const CellData* cells = nullptr);

}  // namespace amc
