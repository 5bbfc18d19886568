// The structure of a VTU file: see vtu_layout.h.
#include "mesh/vtu_layout.h"

#include "mesh/text_number.h"
#include "mesh/xml_tokenizer.h"

#include <algorithm>
#include <optional>

namespace amc::vtu {

void fail(const std::string& what, const std::string& message, ErrorCode code) {
    throw Error(code, what + ": " + message);
}

namespace {

std::size_t line_of(std::string_view bytes, std::size_t offset) {
    offset = std::min(offset, bytes.size());
    return 1 + static_cast<std::size_t>(std::count(bytes.begin(), bytes.begin() + offset, '\n'));
}

// Line numbers of tags met in file order, counted once over the file (not from the start for
// each tag, which a file of many tags would make quadratic).
class LineCounter {
public:
    explicit LineCounter(std::string_view bytes) : bytes_(bytes) {}
    std::size_t at(std::size_t offset) {
        offset = std::min(offset, bytes_.size());
        if (offset < pos_) return line_of(bytes_, offset);
        line_ += static_cast<std::size_t>(std::count(bytes_.begin() + pos_, bytes_.begin() + offset, '\n'));
        pos_ = offset;
        return line_;
    }

private:
    std::string_view bytes_;
    std::size_t pos_ = 0, line_ = 1;
};


uint64_t count_attribute(const XmlToken& tag, const char* name, std::optional<uint64_t> fallback,
                         const std::string& what, std::size_t line) {
    const std::string* value = tag.attribute(name);
    const std::string at = " (line " + std::to_string(line) + ")";
    if (!value) {
        if (fallback) return *fallback;
        fail(what, "<" + std::string(tag.name) + "> has no " + name + " attribute" + at);
    }
    int64_t n = 0;
    if (!text::parse_int(*value, n) || n < 0) {
        fail(what, "<" + std::string(tag.name) + "> has a bad " + name + " " +
                       text::quote_token(*value) + at);
    }
    return static_cast<uint64_t>(n);
}

void read_root(const XmlToken& tag, Layout& layout, const std::string& what) {
    if (tag.name != "VTKFile") {
        fail(what, "not a VTK XML file (the root element is <" + std::string(tag.name.substr(0, 32)) + ">)", ErrorCode::bad_magic);
    }
    const std::string* type = tag.attribute("type");
    if (!type) fail(what, "<VTKFile> has no type attribute");
    if (*type != "UnstructuredGrid") {
        fail(what, "is a VTK " + text::quote_token(*type) +
                       " file; only UnstructuredGrid (.vtu) files are read", ErrorCode::invalid_input);
    }
    const std::string* order = tag.attribute("byte_order");
    if (order && *order == "BigEndian") {
        layout.big_endian = true;
    } else if (order && *order != "LittleEndian") {
        fail(what, "unknown byte_order " + text::quote_token(*order));
    }
    const std::string* header = tag.attribute("header_type");
    if (header && *header == "UInt64") {
        layout.header_bytes = 8;
    } else if (header && *header != "UInt32") {
        fail(what, "unknown header_type " + text::quote_token(*header) + " (UInt32 or UInt64)");
    }
    const std::string* compressor = tag.attribute("compressor");
    if (compressor && *compressor == "vtkZLibDataCompressor") {
        layout.zlib = true;
    } else if (compressor && !compressor->empty()) {
        fail(what, "compressor " + text::quote_token(*compressor) +
                       " is not supported (only vtkZLibDataCompressor, or none)", ErrorCode::invalid_input);
    }
}

ArrayElement read_array_tag(const XmlToken& tag, Section section, const std::string& what,
                            std::size_t line) {
    ArrayElement a;
    a.section = section;
    a.line = line;
    if (const std::string* name = tag.attribute("Name")) a.name = *name;
    const std::string array = "DataArray " + text::quote_token(a.name) + " (line " + std::to_string(line) + ")";
    const std::string* type = tag.attribute("type");
    if (!type) fail(what, array + " has no type");
    if (!parse_vtk_type_name(*type, a.type)) {
        fail(what, array + " has type " + text::quote_token(*type) +
                       ", which is not read (Int8 to Int64, UInt8 to UInt64, Float32, Float64)", ErrorCode::invalid_input);
    }
    a.components = count_attribute(tag, "NumberOfComponents", 1, what, line);
    if (a.components == 0 || a.components > kMaxElements) {
        fail(what, array + " has " + std::to_string(a.components) + " components");
    }
    const std::string* format = tag.attribute("format");
    if (!format || *format == "ascii") {
        a.format = DataFormat::ascii;
    } else if (*format == "binary") {
        a.format = DataFormat::binary;
    } else if (*format == "appended") {
        a.format = DataFormat::appended;
        a.offset = count_attribute(tag, "offset", std::nullopt, what, line);
    } else {
        fail(what, array + " has unknown format " + text::quote_token(*format));
    }
    return a;
}

// The byte after the '_' that starts appended data, and where that data ends.
void locate_appended(const XmlToken& tag, std::string_view bytes, Layout& layout,
                     const std::string& what) {
    const std::string* encoding = tag.attribute("encoding");
    if (!encoding || *encoding == "base64") {
        layout.appended_base64 = true;
    } else if (*encoding != "raw") {
        fail(what, "AppendedData has unknown encoding " + text::quote_token(*encoding));
    }
    std::size_t pos = tag.end;
    while (pos < bytes.size() && (bytes[pos] == ' ' || bytes[pos] == '\t' || bytes[pos] == '\n' ||
                                  bytes[pos] == '\r')) {
        ++pos;
    }
    if (tag.self_closing || pos >= bytes.size() || bytes[pos] != '_') {
        fail(what, "AppendedData does not start with '_' (line " +
                       std::to_string(line_of(bytes, tag.begin)) + ")");
    }
    const std::size_t begin = pos + 1;
    // Raw data may hold any byte, so the closing tag is looked for from the end of the file; a
    // truncated file has none and its data runs to the end.
    std::size_t end = bytes.rfind("</AppendedData>");
    if (end == std::string_view::npos || end < begin) end = bytes.size();
    layout.has_appended = true;
    layout.appended = bytes.substr(begin, end - begin);
}

}  // namespace

Layout read_layout(std::string_view bytes, const std::string& what) {
    Layout layout;
    XmlTokenizer xml(bytes, what);
    LineCounter lines(bytes);
    std::vector<std::string_view> stack;
    bool saw_root = false;
    // The DataArray whose text is being collected: (piece, array index), at this depth.
    std::optional<std::pair<std::size_t, std::size_t>> open_array;
    for (;;) {
        XmlToken token = xml.next();
        if (token.kind == XmlToken::Kind::end_of_input) {
            if (!saw_root) fail(what, "not a VTK XML file (no VTKFile element)", ErrorCode::bad_magic);
            if (!stack.empty()) {
                fail(what, "the file ends inside <" + std::string(stack.back()) + "> (truncated?)", ErrorCode::truncated);
            }
            break;
        }
        if (token.kind == XmlToken::Kind::text) {
            if (open_array && stack.size() == 5) {
                ArrayElement& a = layout.pieces[open_array->first].arrays[open_array->second];
                const bool blank = token.text.find_first_not_of(" \t\r\n") == std::string_view::npos;
                if (!blank) {
                    if (!a.text.empty()) {
                        fail(what, "DataArray " + text::quote_token(a.name) + " (line " +
                                       std::to_string(a.line) +
                                       ") has text in several places");
                    }
                    a.text = token.text;
                }
            }
            continue;
        }
        if (token.kind == XmlToken::Kind::end_tag) {
            if (stack.empty() || stack.back() != token.name) {
                fail(what, "bad XML at line " + std::to_string(lines.at(token.begin)) + ": </" +
                               std::string(token.name.substr(0, 32)) + "> closes " +
                               (stack.empty() ? std::string("nothing")
                                              : "<" + std::string(stack.back()) + ">"));
            }
            if (stack.size() == 5) open_array.reset();
            stack.pop_back();
            continue;
        }
        // A start tag. Only the elements on the paths VTKFile/UnstructuredGrid/Piece/<section>/
        // DataArray and VTKFile/AppendedData matter; others (FieldData, ...) are skipped.
        const std::size_t depth = stack.size();
        if (depth == 0) {
            if (saw_root) fail(what, "a second root element <" + std::string(token.name.substr(0, 32)) + ">");
            read_root(token, layout, what);
            saw_root = true;
        } else if (depth == 1 && token.name == "AppendedData") {
            locate_appended(token, bytes, layout, what);
            break;
        } else if (depth == 2 && token.name == "Piece" && stack[1] == "UnstructuredGrid") {
            PieceElement piece;
            const std::size_t line = lines.at(token.begin);
            piece.points = count_attribute(token, "NumberOfPoints", std::nullopt, what, line);
            piece.cells = count_attribute(token, "NumberOfCells", std::nullopt, what, line);
            layout.pieces.push_back(std::move(piece));
        } else if (depth == 4 && token.name == "DataArray" && stack[1] == "UnstructuredGrid" &&
                   stack[2] == "Piece") {
            const std::string_view parent = stack[3];
            std::optional<Section> section;
            if (parent == "Points") section = Section::points;
            if (parent == "Cells") section = Section::cells;
            if (parent == "PointData") section = Section::point_data;
            if (parent == "CellData") section = Section::cell_data;
            if (section) {
                PieceElement& piece = layout.pieces.back();
                piece.arrays.push_back(read_array_tag(token, *section, what, lines.at(token.begin)));
                if (!token.self_closing) {
                    open_array = std::make_pair(layout.pieces.size() - 1, piece.arrays.size() - 1);
                }
            }
        }
        if (!token.self_closing) stack.push_back(token.name);
    }
    if (layout.pieces.empty()) fail(what, "no UnstructuredGrid Piece in the file");
    return layout;
}

}  // namespace amc::vtu
