// VTU writer. Binary files follow vtkXMLUnstructuredGridWriter's defaults, so that VTK,
// ParaView and meshio read them as they read VTK's own: the XML names each array and its offset
// into one appended raw section, where every array is a zlib block header and its blocks.
#include "mesh/vtu_writer.h"

#include <charconv>
#include <cstring>
#include <limits>
#include <type_traits>
#include <variant>

#include "mesh/text_number.h"
#include "mesh/vtk_types.h"
#include "mesh/xml_tokenizer.h"
#include "mesh/zlib_blocks.h"

namespace amc {
namespace {

// The arrays of the Points and Cells sections, made from the mesh.
struct GeometryArrays {
    DataArray points, connectivity, offsets, types;
};

template <typename Index>
void fill_cells(const VtuCells& cells, GeometryArrays& g) {
    const std::size_t n = cells.count * std::size_t(cells.corners);
    std::vector<Index> connectivity(n), offsets(cells.count);
    for (std::size_t i = 0; i < n; ++i) connectivity[i] = static_cast<Index>(cells.connectivity[i]);
    for (std::size_t c = 0; c < cells.count; ++c) offsets[c] = static_cast<Index>((c + 1) * std::size_t(cells.corners));
    g.connectivity.values = std::move(connectivity);
    g.offsets.values = std::move(offsets);
}

GeometryArrays geometry_arrays(const std::vector<Vec3>& positions, bool single_precision, const VtuCells& cells) {
    GeometryArrays g;
    g.points.name = "Points";
    g.points.components = 3;
    if (single_precision) {
        std::vector<float> xyz;
        xyz.reserve(3 * positions.size());
        for (const Vec3& p : positions) {
            xyz.insert(xyz.end(), {static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z)});
        }
        g.points.values = std::move(xyz);
    } else {
        std::vector<double> xyz;
        xyz.reserve(3 * positions.size());
        for (const Vec3& p : positions) xyz.insert(xyz.end(), {p.x, p.y, p.z});
        g.points.values = std::move(xyz);
    }
    g.connectivity.name = "connectivity";
    g.offsets.name = "offsets";
    g.types.name = "types";
    const uint64_t int32_max = std::numeric_limits<int32_t>::max();
    if (uint64_t(cells.corners) * cells.count <= int32_max && positions.size() <= int32_max) {
        fill_cells<int32_t>(cells, g);
    } else {
        fill_cells<int64_t>(cells, g);
    }
    g.types.values = std::vector<uint8_t>(cells.count, cells.vtk_type);
    return g;
}

void check_sizes(const std::vector<DataArray>& arrays, std::size_t tuples, const char* kind) {
    for (const DataArray& a : arrays) {
        if (a.components == 0 || a.size() != uint64_t(tuples) * a.components) {
            throw Error("VTU writer: " + std::string(kind) + " " + text::quote_token(a.name) + " has " +
                        std::to_string(a.size()) + " values, expected " + std::to_string(tuples) + " x " +
                        std::to_string(a.components));
        }
    }
}

std::string array_tag(const DataArray& a, const std::string& format_attributes) {
    std::string tag = "        <DataArray type=\"" + std::string(vtk_type_name(a.type())) + "\" Name=\"" +
                      escape_xml_attribute(a.name) + "\"";
    if (a.components != 1) tag += " NumberOfComponents=\"" + std::to_string(a.components) + "\"";
    return tag + " " + format_attributes;
}

std::pair<const uint8_t*, std::size_t> raw_bytes(const DataArray& a) {
    return std::visit(
        [](const auto& v) {
            return std::make_pair(reinterpret_cast<const uint8_t*>(v.data()),
                                  v.size() * sizeof(typename std::decay_t<decltype(v)>::value_type));
        },
        a.values);
}

template <typename T>
void append_number(std::string& out, T value) {
    if constexpr (std::is_floating_point_v<T>) {
        text::append_real(out, value);  // shortest decimals that read back as the same bits
    } else {
        char buf[24];
        // int8 and uint8 print as numbers, not characters.
        const auto [ptr, ec] = std::to_chars(buf, buf + sizeof buf, +value);
        out.append(buf, ec == std::errc() ? ptr : buf);
    }
}

void append_ascii_values(std::string& out, const DataArray& a) {
    std::visit(
        [&](const auto& v) {
            // One tuple a line for vectors, 16 values a line for scalars.
            const std::size_t per_line = a.components > 1 ? a.components : 16;
            for (std::size_t i = 0; i < v.size(); ++i) {
                out += i % per_line == 0 ? "          " : " ";
                append_number(out, v[i]);
                if (i % per_line == per_line - 1 || i + 1 == v.size()) out += '\n';
            }
        },
        a.values);
}

// Writes the XML of the arrays in order and collects their appended data (binary) or inlines
// their text (ascii).
class ArrayWriter {
public:
    ArrayWriter(std::string& xml, VtuEncoding encoding, unsigned threads) : xml_(xml), encoding_(encoding), threads_(threads) {}

    void write(const DataArray& a) {
        if (encoding_ == VtuEncoding::ascii) {
            xml_ += array_tag(a, "format=\"ascii\">\n");
            append_ascii_values(xml_, a);
            xml_ += "        </DataArray>\n";
            return;
        }
        xml_ += array_tag(a, "format=\"appended\" offset=\"" + std::to_string(appended_.size()) + "\"/>\n");
        const auto [data, size] = raw_bytes(a);
        const CompressedBlocks blocks = compress_zlib_blocks(data, size, kVtkBlockSize, kZlibLevel, threads_);
        const uint64_t count = blocks.compressed_sizes.size();
        const uint64_t last = size % kVtkBlockSize;
        append_word(count);
        append_word(kVtkBlockSize);
        append_word(last);  // 0: the last block is a full one
        for (uint64_t c : blocks.compressed_sizes) append_word(c);
        appended_ += blocks.bytes;
    }

    const std::string& appended() const { return appended_; }

private:
    // header_type="UInt64", in the host's byte order (which the file declares).
    void append_word(uint64_t word) {
        char bytes[8];
        std::memcpy(bytes, &word, 8);
        appended_.append(bytes, 8);
    }

    std::string& xml_;
    VtuEncoding encoding_;
    unsigned threads_;
    std::string appended_;
};

}  // namespace

std::string format_vtu(const TriangleMesh& mesh, const std::vector<DataArray>& point_data,
                       const std::vector<DataArray>& cell_data, VtuEncoding encoding, unsigned threads) {
    static_assert(sizeof(Triangle) == 3 * sizeof(uint32_t), "triangles are three packed indices");
    const VtuCells triangles{mesh.triangles.empty() ? nullptr : mesh.triangles[0].data(), mesh.triangles.size(), 3,
                             static_cast<uint8_t>(kVtkTriangle)};
    return format_vtu_cells(mesh.positions, mesh.single_precision, triangles, point_data, cell_data, encoding, threads);
}

std::string format_vtu_cells(const std::vector<Vec3>& positions, bool single_precision, const VtuCells& cells,
                             const std::vector<DataArray>& point_data, const std::vector<DataArray>& cell_data,
                             VtuEncoding encoding, unsigned threads) {
    check_sizes(point_data, positions.size(), "point data");
    check_sizes(cell_data, cells.count, "cell data");
    const GeometryArrays geometry = geometry_arrays(positions, single_precision, cells);
    const bool binary = encoding == VtuEncoding::binary_zlib;

    std::string xml;
    xml.reserve(binary ? 4096 : positions.size() * 60 + cells.count * (12 + 8 * std::size_t(cells.corners)) + 4096);
    xml += "<?xml version=\"1.0\"?>\n";
    xml += "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"";
    xml += kHostBigEndian ? "BigEndian" : "LittleEndian";
    xml += "\" header_type=\"UInt64\"";
    if (binary) xml += " compressor=\"vtkZLibDataCompressor\"";
    xml += ">\n  <UnstructuredGrid>\n";
    xml += "    <Piece NumberOfPoints=\"" + std::to_string(positions.size()) + "\" NumberOfCells=\"" +
           std::to_string(cells.count) + "\">\n";
    ArrayWriter arrays(xml, encoding, threads);
    if (!point_data.empty()) {
        xml += "      <PointData>\n";
        for (const DataArray& a : point_data) arrays.write(a);
        xml += "      </PointData>\n";
    }
    if (!cell_data.empty()) {
        // ParaView colours by the Scalars array when a file is opened.
        bool has_level = false;
        for (const DataArray& a : cell_data) has_level |= a.name == "level" && a.components == 1;
        xml += has_level ? "      <CellData Scalars=\"level\">\n" : "      <CellData>\n";
        for (const DataArray& a : cell_data) arrays.write(a);
        xml += "      </CellData>\n";
    }
    xml += "      <Points>\n";
    arrays.write(geometry.points);
    xml += "      </Points>\n      <Cells>\n";
    arrays.write(geometry.connectivity);
    arrays.write(geometry.offsets);
    arrays.write(geometry.types);
    xml += "      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n";
    if (binary) {
        xml += "  <AppendedData encoding=\"raw\">\n   _";
        xml += arrays.appended();
        xml += "\n  </AppendedData>\n";
    }
    xml += "</VTKFile>\n";
    return xml;
}

}  // namespace amc
