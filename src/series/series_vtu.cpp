// Series as ParaView collections: the .pvd file, fields as DataArrays, frames to and from VTU
// meshes (include/amc/series.h).
#include <amc/import.h>
#include <amc/numbering.h>
#include <amc/series.h>

#include "common/check.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>

namespace amc {

namespace {

// The value of attribute `name` in one XML start tag (between its '<' and '>'), or "" if absent.
std::string attribute(const std::string& tag, const std::string& name, bool& found) {
    size_t pos = 0;
    found = false;
    while ((pos = tag.find(name, pos)) != std::string::npos) {
        const bool starts_word = pos > 0 && (tag[pos - 1] == ' ' || tag[pos - 1] == '\t' || tag[pos - 1] == '\n' || tag[pos - 1] == '\r');
        size_t p = pos + name.size();
        while (p < tag.size() && (tag[p] == ' ' || tag[p] == '\t')) ++p;
        if (starts_word && p < tag.size() && tag[p] == '=') {
            ++p;
            while (p < tag.size() && (tag[p] == ' ' || tag[p] == '\t')) ++p;
            if (p < tag.size() && (tag[p] == '"' || tag[p] == '\'')) {
                const size_t end = tag.find(tag[p], p + 1);
                if (end != std::string::npos) {
                    found = true;
                    return tag.substr(p + 1, end - p - 1);
                }
            }
        }
        pos += name.size();
    }
    return "";
}

std::string xml_escape(const std::string& s) {
    std::string out;
    for (char c : s) {
        switch (c) {
            case '&': out += "&amp;"; break;
            case '<': out += "&lt;"; break;
            case '>': out += "&gt;"; break;
            case '"': out += "&quot;"; break;
            default: out += c;
        }
    }
    return out;
}

std::string xml_unescape(const std::string& s) {
    std::string out;
    for (size_t i = 0; i < s.size(); ++i) {
        if (s[i] != '&') {
            out += s[i];
            continue;
        }
        static const std::pair<const char*, char> entities[] = {{"&amp;", '&'}, {"&lt;", '<'}, {"&gt;", '>'},
                                                                {"&quot;", '"'}, {"&apos;", '\''}};
        bool matched = false;
        for (const auto& [entity, c] : entities)
            if (s.compare(i, std::strlen(entity), entity) == 0) {
                out += c;
                i += std::strlen(entity) - 1;
                matched = true;
                break;
            }
        if (!matched) out += '&';
    }
    return out;
}

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
    std::ifstream in(path, std::ios::binary);
    AMC_REQUIRE(in.good(), io, path + ": can not open");
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    AMC_REQUIRE(text.find("<VTKFile") != std::string::npos && text.find("Collection") != std::string::npos, bad_magic,
                path + ": not a ParaView collection (.pvd): no <VTKFile type=\"Collection\">");
    std::vector<PvdEntry> entries;
    size_t pos = 0;
    while ((pos = text.find("<DataSet", pos)) != std::string::npos) {
        const size_t end = text.find('>', pos);
        const size_t line = 1 + size_t(std::count(text.begin(), text.begin() + long(pos), '\n'));
        const std::string where = path + ":" + std::to_string(line) + ": ";
        AMC_REQUIRE(end != std::string::npos, truncated, where + "unterminated <DataSet");
        const std::string tag = text.substr(pos, end - pos);
        bool has_file = false, has_time = false;
        PvdEntry e;
        e.file = xml_unescape(attribute(tag, "file", has_file));
        const std::string time = attribute(tag, "timestep", has_time);
        AMC_REQUIRE(has_file && !e.file.empty(), invalid_input, where + "a DataSet without a file");
        if (has_time) {
            char* stop = nullptr;
            e.time = std::strtod(time.c_str(), &stop);
            AMC_REQUIRE(stop != time.c_str() && *stop == '\0' && std::isfinite(e.time), invalid_input,
                        where + "timestep \"" + time + "\" is not a number");
        } else {
            e.time = double(entries.size());
        }
        entries.push_back(e);
        pos = end;
    }
    AMC_REQUIRE(!entries.empty(), invalid_input, path + ": the collection lists no DataSet");
    return entries;
}

void write_pvd(const std::string& path, const std::vector<PvdEntry>& entries) {
    std::ostringstream out;
    out.precision(17);
    out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
           "  <Collection>\n";
    for (const PvdEntry& e : entries)
        out << "    <DataSet timestep=\"" << e.time << "\" group=\"\" part=\"0\" file=\"" << xml_escape(e.file) << "\"/>\n";
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
