// VTU writer: ASCII XML that ParaView and VTK read directly.
#include "mesh/vtu_io.h"

#include <cstdint>

#include "mesh/text_number.h"

namespace amc {
namespace {

void append_uint8_array(std::string& out, const char* name, const std::vector<uint8_t>& values) {
    out += "        <DataArray type=\"UInt8\" Name=\"";
    out += name;
    out += "\" format=\"ascii\">\n";
    for (std::size_t i = 0; i < values.size(); ++i) {
        out += (i % 32 == 0) ? "          " : " ";
        text::append_uint(out, values[i]);
        if (i % 32 == 31 || i + 1 == values.size()) out += '\n';
    }
    out += "        </DataArray>\n";
}

}  // namespace

std::string format_vtu(const TriangleMesh& mesh, const CellData* cells) {
    const bool write_level = cells && !cells->level.empty();
    const bool write_green = cells && !cells->is_green.empty();
    if ((write_level && cells->level.size() != mesh.triangles.size()) ||
        (write_green && cells->is_green.size() != mesh.triangles.size())) {
        throw Error("VTU writer: cell data size does not match the triangle count");
    }
    std::string out;
    out.reserve(mesh.positions.size() * 60 + mesh.triangles.size() * 40 + 1024);
    out += "<?xml version=\"1.0\"?>\n";
    out += "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" "
           "header_type=\"UInt64\">\n";
    out += "  <UnstructuredGrid>\n";
    out += "    <Piece NumberOfPoints=\"" + std::to_string(mesh.positions.size()) +
           "\" NumberOfCells=\"" + std::to_string(mesh.triangles.size()) + "\">\n";

    out += "      <Points>\n";
    out += std::string("        <DataArray type=\"") +
           (mesh.single_precision ? "Float32" : "Float64") +
           "\" Name=\"Points\" NumberOfComponents=\"3\" format=\"ascii\">\n";
    for (const Vec3& p : mesh.positions) {
        out += "          ";
        for (int k = 0; k < 3; ++k) {
            const double c = k == 0 ? p.x : k == 1 ? p.y : p.z;
            if (k) out += ' ';
            // Shortest decimals of the stored type, so VTK reads back the same bits.
            if (mesh.single_precision) {
                text::append_real(out, static_cast<float>(c));
            } else {
                text::append_real(out, c);
            }
        }
        out += '\n';
    }
    out += "        </DataArray>\n";
    out += "      </Points>\n";

    out += "      <Cells>\n";
    out += "        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
    for (const Triangle& t : mesh.triangles) {
        out += "          ";
        text::append_line(out, t[0], t[1], t[2]);
    }
    out += "        </DataArray>\n";
    out += "        <DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
    for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
        out += (i % 16 == 0) ? "          " : " ";
        text::append_uint(out, 3 * (uint64_t(i) + 1));
        if (i % 16 == 15 || i + 1 == mesh.triangles.size()) out += '\n';
    }
    out += "        </DataArray>\n";
    const std::vector<uint8_t> types(mesh.triangles.size(), 5);  // VTK_TRIANGLE
    append_uint8_array(out, "types", types);
    out += "      </Cells>\n";

    if (write_level || write_green) {
        out += write_level ? "      <CellData Scalars=\"level\">\n" : "      <CellData>\n";
        if (write_level) append_uint8_array(out, "level", cells->level);
        if (write_green) append_uint8_array(out, "green", cells->is_green);
        out += "      </CellData>\n";
    }
    out += "    </Piece>\n";
    out += "  </UnstructuredGrid>\n";
    out += "</VTKFile>\n";
    return out;
}

}  // namespace amc
