// Series as ParaView collections: the .pvd file, fields as DataArrays, frames to and from VTU
// meshes (include/amc/series.h).
#include <amc/import.h>
#include <amc/numbering.h>
#include <amc/series.h>

#include "common/check.h"
#include "common/file_io.h"
#include "mesh/xml_tokenizer.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>

namespace amc {

namespace {

template <class T>
void copy_values(const std::vector<T>& in, Field& f) {
    if (is_float_type(f.type)) f.values.assign(in.begin(), in.end());
    else f.integers.assign(in.begin(), in.end());
}

template <class T>
std::vector<T> typed(const Field& f) {
    if (is_float_type(f.type)) return std::vector<T>(f.values.begin(), f.values.end());
    std::vector<T> out(f.integers.size());
    for (size_t i = 0; i < out.size(); ++i) out[i] = T(f.integers[i]);
    return out;
}

// Tuple `from` of `in` is tuple map[from] of the result.
Field permuted(const Field& in, const std::vector<uint32_t>& map) {
    Field out = in;
    const size_t c = in.components;
    for (size_t i = 0; i < map.size(); ++i)
        for (size_t k = 0; k < c; ++k) {
            if (is_float_type(in.type)) out.values[size_t(map[i]) * c + k] = in.values[i * c + k];
            else out.integers[size_t(map[i]) * c + k] = in.integers[i * c + k];
        }
    return out;
}

}  // namespace

std::vector<PvdEntry> read_pvd(const std::string& path) {
    const std::string text = read_whole_file(path);
    XmlTokenizer xml(text, path);
    bool collection = false;
    std::vector<PvdEntry> entries;
    for (XmlToken tag = xml.next(); tag.kind != XmlToken::Kind::end_of_input; tag = xml.next()) {
        if (tag.kind != XmlToken::Kind::start_tag) continue;
        if (tag.name == "VTKFile") {
            const std::string* type = tag.attribute("type");
            collection = type && *type == "Collection";
        }
        if (tag.name != "DataSet" || !collection) continue;
        // Its line counted only for a message: counting from the file's start at every DataSet was
        // quadratic in them (docs/FUZZING.md).
        const auto where = [&] { return path + ":" + std::to_string(xml.line_of(tag.begin)) + ": "; };
        const std::string* file = tag.attribute("file");
        AMC_REQUIRE(file && !file->empty(), invalid_input, where() + "a DataSet without a file");
        PvdEntry e;
        e.file = *file;
        e.time = double(entries.size());
        if (const std::string* time = tag.attribute("timestep")) {
            char* stop = nullptr;
            e.time = std::strtod(time->c_str(), &stop);
            AMC_REQUIRE(stop != time->c_str() && *stop == '\0' && std::isfinite(e.time), invalid_input,
                        where() + "timestep \"" + *time + "\" is not a number");
        }
        entries.push_back(e);
    }
    AMC_REQUIRE(collection, bad_magic, path + ": not a ParaView collection (.pvd): no <VTKFile type=\"Collection\">");
    AMC_REQUIRE(!entries.empty(), invalid_input, path + ": the collection lists no DataSet");
    return entries;
}

void write_pvd(const std::string& path, const std::vector<PvdEntry>& entries) {
    std::ostringstream out;
    out.precision(17);
    out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
           "  <Collection>\n";
    for (const PvdEntry& e : entries)
        out << "    <DataSet timestep=\"" << e.time << "\" group=\"\" part=\"0\" file=\"" << escape_xml_attribute(e.file) << "\"/>\n";
    out << "  </Collection>\n</VTKFile>\n";
    write_file_atomically(path, out.str());
}

Field field_from_array(const DataArray& array, FieldAssociation association) {
    Field f;
    f.name = array.name;
    f.association = association;
    f.type = FieldType(array.type());
    f.components = array.components;
    std::visit([&f](const auto& values) { copy_values(values, f); }, array.values);
    return f;
}

DataArray array_from_field(const Field& f) {
    DataArray a;
    a.name = f.name;
    a.components = f.components;
    switch (f.type) {
        case FieldType::int8: a.values = typed<int8_t>(f); break;
        case FieldType::uint8: a.values = typed<uint8_t>(f); break;
        case FieldType::int16: a.values = typed<int16_t>(f); break;
        case FieldType::uint16: a.values = typed<uint16_t>(f); break;
        case FieldType::int32: a.values = typed<int32_t>(f); break;
        case FieldType::uint32: a.values = typed<uint32_t>(f); break;
        case FieldType::int64: a.values = typed<int64_t>(f); break;
        case FieldType::uint64: a.values = typed<uint64_t>(f); break;
        case FieldType::float32: a.values = typed<float>(f); break;
        case FieldType::float64: a.values = typed<double>(f); break;
    }
    return a;
}

SeriesFrame frame_from_vtu(const TriangleMesh& base, const VtuMesh& vtu, double time, const std::string& what) {
    ImportedHierarchy imported = import_leaf_mesh(base, vtu.mesh, {}, what);
    const LeafNumbering numbering = leaf_numbering(imported.hierarchy, vtu.mesh, imported.vertex_of_input);
    SeriesFrame frame;
    frame.time = time;
    for (const DataArray& a : vtu.point_data) {
        AMC_REQUIRE(a.components >= 1 && a.size() == vtu.mesh.positions.size() * a.components, invalid_input,
                    what + ": point array \"" + a.name + "\" does not have one tuple per point");
        frame.fields.push_back(permuted(field_from_array(a, FieldAssociation::point), numbering.vertex));
    }
    for (const DataArray& a : vtu.cell_data) {
        AMC_REQUIRE(a.components >= 1 && a.size() == vtu.mesh.triangles.size() * a.components, invalid_input,
                    what + ": cell array \"" + a.name + "\" does not have one tuple per cell");
        frame.fields.push_back(permuted(field_from_array(a, FieldAssociation::cell), numbering.face));
    }
    frame.hierarchy = std::move(imported.hierarchy);
    return frame;
}

VtuMesh vtu_from_frame(const SeriesFrame& frame, int max_level) {
    const LeafMesh leaf = extract_leaf_mesh(frame.hierarchy, max_level);
    VtuMesh vtu;
    vtu.mesh = leaf.mesh;
    const bool cut = max_level >= 0 && max_level < frame.hierarchy.depth();
    bool has_level = false, has_green = false;
    for (const Field& f : frame.fields) {
        if (f.association == FieldAssociation::point) {
            DataArray a = array_from_field(f);
            if (cut) {  // the mesh of a level holds the first vertices of the canonical order
                Field first = f;
                const size_t n = leaf.mesh.positions.size() * f.components;
                if (is_float_type(f.type)) first.values.resize(n);
                else first.integers.resize(n);
                a = array_from_field(first);
            }
            vtu.point_data.push_back(std::move(a));
        } else if (!cut) {
            has_level |= f.name == "level";
            has_green |= f.name == "green";
            vtu.cell_data.push_back(array_from_field(f));
        }
    }
    for (DataArray& a : cell_data_arrays(leaf.cells))
        if ((a.name == "level" && !has_level) || (a.name == "green" && !has_green)) vtu.cell_data.push_back(std::move(a));
    return vtu;
}

}  // namespace amc
