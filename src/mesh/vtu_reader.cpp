// VTU reader. Two passes: the XML tokenizer collects the structure (pieces, their arrays and
// where each array's data is) up to the appended data, then each array is decoded with its
// declared sizes checked against the bytes that are really there before anything is allocated.
#include "mesh/vtu_reader.h"

#include <algorithm>
#include <cstring>
#include <limits>
#include <optional>
#include <utility>
#include <variant>
#include <vector>

#include "mesh/base64.h"
#include "mesh/text_number.h"
#include "mesh/vtk_types.h"
#include "mesh/xml_tokenizer.h"
#include "mesh/zlib_blocks.h"

namespace amc {
namespace {

// Structure no writer produces is `corrupt` unless a call says otherwise: `truncated` for data
// that ends early, `invalid_input` for valid VTK that is not a triangle mesh we read,
// `bad_magic` for files that are not VTK XML, `limit_exceeded` past 32-bit counts.
[[noreturn]] void fail(const std::string& what, const std::string& message,
                       ErrorCode code = ErrorCode::corrupt) {
    throw Error(code, what + ": " + message);
}

// Point indices and triangle numbers are 32-bit.
constexpr uint64_t kMaxElements = std::numeric_limits<uint32_t>::max();

enum class DataFormat { ascii, binary, appended };
enum class Section { points, cells, point_data, cell_data };

struct ArrayElement {
    std::string name;
    Section section = Section::points;
    ValueType type = ValueType::float64;
    uint64_t components = 1;
    DataFormat format = DataFormat::ascii;
    uint64_t offset = 0;    // appended: where the data starts after the '_'
    std::string_view text;  // ascii and binary: the element's text
    std::size_t line = 0;  // of the DataArray tag, for messages
};

struct PieceElement {
    uint64_t points = 0, cells = 0;
    std::vector<ArrayElement> arrays;
};

struct Layout {
    bool big_endian = false;
    unsigned header_bytes = 4;  // header_type UInt32 (VTK's default) or UInt64
    bool zlib = false;
    std::vector<PieceElement> pieces;
    bool has_appended = false;
    bool appended_base64 = false;
    std::string_view appended;  // from the byte after the '_'
};

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

// ---------------------------------------------------------------------------------------------
// Structure

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

// ---------------------------------------------------------------------------------------------
// Array data

// The bytes of appended raw data, or the decoded bytes of base64 text.
class ByteSource {
public:
    static ByteSource raw(std::string_view data) {
        ByteSource s;
        s.raw_ = data;
        return s;
    }
    static ByteSource base64(std::string_view text) {
        ByteSource s;
        s.base64_.emplace(text);
        return s;
    }

    // The next n bytes (in `scratch` or in the input), or null when the data ends first.
    const uint8_t* take(std::size_t n, std::vector<uint8_t>& scratch) {
        if (base64_) {
            if (n > base64_->max_remaining()) return nullptr;
            scratch.resize(n);
            return base64_->read(scratch.data(), n) ? scratch.data() : nullptr;
        }
        if (n > raw_.size() - pos_) return nullptr;
        const uint8_t* p = reinterpret_cast<const uint8_t*>(raw_.data()) + pos_;
        pos_ += n;
        return p;
    }

    uint64_t max_remaining() const {
        return base64_ ? base64_->max_remaining() : raw_.size() - pos_;
    }

    // Why take() failed: the data ended, or its base64 is malformed.
    bool truncated() const { return !base64_ || !base64_->malformed(); }
    std::string failure() const { return truncated() ? "ends early (truncated?)" : base64_->failure(); }

private:
    std::string_view raw_;
    std::size_t pos_ = 0;
    std::optional<Base64Reader> base64_;
};

// Names one array in messages: "Points", "Cells array 'types'", "point data 'u'".
std::string describe(const ArrayElement& a, const std::string& piece) {
    std::string s;
    switch (a.section) {
        case Section::points: s = "Points array"; break;
        case Section::cells: s = "Cells array"; break;
        case Section::point_data: s = "point data"; break;
        case Section::cell_data: s = "cell data"; break;
    }
    if (!a.name.empty()) s += " " + text::quote_token(a.name);
    return piece + s + " (line " + std::to_string(a.line) + ")";
}

template <typename T>
std::vector<T> typed_values(const uint8_t* data, std::size_t count, bool swap) {
    std::vector<T> v(count);
    if (count) std::memcpy(v.data(), data, count * sizeof(T));
    if (swap && sizeof(T) > 1) {
        for (T& x : v) {
            uint8_t b[sizeof(T)];
            std::memcpy(b, &x, sizeof(T));
            std::reverse(b, b + sizeof(T));
            std::memcpy(&x, b, sizeof(T));
        }
    }
    return v;
}

DataArray::Values make_values(ValueType type, const uint8_t* data, std::size_t count, bool swap) {
    switch (type) {
        case ValueType::int8: return typed_values<int8_t>(data, count, swap);
        case ValueType::uint8: return typed_values<uint8_t>(data, count, swap);
        case ValueType::int16: return typed_values<int16_t>(data, count, swap);
        case ValueType::uint16: return typed_values<uint16_t>(data, count, swap);
        case ValueType::int32: return typed_values<int32_t>(data, count, swap);
        case ValueType::uint32: return typed_values<uint32_t>(data, count, swap);
        case ValueType::int64: return typed_values<int64_t>(data, count, swap);
        case ValueType::uint64: return typed_values<uint64_t>(data, count, swap);
        case ValueType::float32: return typed_values<float>(data, count, swap);
        case ValueType::float64: return typed_values<double>(data, count, swap);
    }
    return {};
}

template <typename T>
bool parse_value(std::string_view token, T& out) {
    if constexpr (std::is_floating_point_v<T>) {
        return text::parse_real(token, out);
    } else if constexpr (std::is_same_v<T, uint64_t>) {
        if (!token.empty() && token[0] == '+') token.remove_prefix(1);
        const char* last = token.data() + token.size();
        auto [ptr, ec] = std::from_chars(token.data(), last, out, 10);
        return ec == std::errc() && ptr == last;
    } else {
        int64_t v = 0;
        if (!text::parse_int(token, v) || v < int64_t(std::numeric_limits<T>::min()) ||
            v > int64_t(std::numeric_limits<T>::max())) {
            return false;
        }
        out = static_cast<T>(v);
        return true;
    }
}

class ArrayDecoder {
public:
    ArrayDecoder(const Layout& layout, const std::string& what) : layout_(layout), what_(what) {}

    // The array's values, which must be `tuples` tuples of its components. `piece` prefixes
    // messages ("piece 2: " or "").
    DataArray decode(const ArrayElement& a, uint64_t tuples, const std::string& piece) const {
        DataArray out;
        out.name = a.name;
        out.components = static_cast<uint32_t>(a.components);
        const std::string where = describe(a, piece);
        // tuples and components are both below 2^32, so count and its bytes fit in 64 bits.
        const uint64_t count = tuples * a.components;
        const std::size_t size = value_size(a.type);
        if (count > std::numeric_limits<std::size_t>::max() / 8) fail(what_, where + ": too large");
        if (a.format == DataFormat::ascii) {
            out.values = parse_ascii(a, count, where);
            return out;
        }
        ByteSource source = ByteSource::base64(a.text);
        if (a.format == DataFormat::appended) {
            if (!layout_.has_appended) fail(what_, where + ": format=\"appended\" but the file has no AppendedData");
            if (a.offset > layout_.appended.size()) {
                fail(what_, where + ": offset " + std::to_string(a.offset) + " is past the end of the " +
                                std::to_string(layout_.appended.size()) + " bytes of appended data");
            }
            const std::string_view data = layout_.appended.substr(a.offset);
            source = layout_.appended_base64 ? ByteSource::base64(data) : ByteSource::raw(data);
        }
        const std::vector<uint8_t> raw = read_block(source, count * size, a, where);
        out.values = make_values(a.type, raw.data(), count, layout_.big_endian != kHostBigEndian);
        return out;
    }

private:
    DataArray::Values parse_ascii(const ArrayElement& a, uint64_t count, const std::string& where) const {
        // n values need at least 2n - 1 characters: checked before allocating.
        if (count > (a.text.size() + 1) / 2) {
            fail(what_, where + ": needs " + std::to_string(count) + " values, more than its " +
                            std::to_string(a.text.size()) + " characters of text can hold");
        }
        DataArray::Values values = make_values(a.type, nullptr, 0, false);
        std::visit(
            [&](auto& v) {
                using T = typename std::decay_t<decltype(v)>::value_type;
                v.resize(count);
                text::TokenCursor cursor(a.text, /*hash_comments=*/false);
                for (uint64_t i = 0; i < count; ++i) {
                    const std::string_view token = cursor.next();
                    if (token.empty()) {
                        fail(what_, where + ": holds " + std::to_string(i) + " values, expected " +
                                        std::to_string(count));
                    }
                    if (!parse_value<T>(token, v[i])) {
                        fail(what_, where + ": value " + std::to_string(i) + " " + text::quote_token(token) +
                                        " is not a valid " + std::string(vtk_type_name(a.type)));
                    }
                }
                if (!cursor.next().empty()) {
                    fail(what_, where + ": holds more than the " + std::to_string(count) + " values expected");
                }
            },
            values);
        return values;
    }

    [[noreturn]] void fail_source(const ByteSource& source, const std::string& where,
                                  const std::string& suffix) const {
        fail(what_, where + ": the data " + source.failure() + suffix,
             source.truncated() ? ErrorCode::truncated : ErrorCode::corrupt);
    }

    uint64_t read_word(ByteSource& source, const std::string& where, const char* what_word) const {
        std::vector<uint8_t> scratch;
        const uint8_t* p = source.take(layout_.header_bytes, scratch);
        if (!p) fail_source(source, where, std::string(" (in the ") + what_word + ")");
        uint64_t word = 0;
        for (unsigned i = 0; i < layout_.header_bytes; ++i) {
            const unsigned byte = layout_.big_endian ? i : layout_.header_bytes - 1 - i;
            word = (word << 8) | p[byte];
        }
        return word;
    }

    std::string expected_text(uint64_t bytes, const ArrayElement& a) const {
        return std::to_string(bytes) + " bytes (" + std::to_string(bytes / value_size(a.type)) + " " +
               std::string(vtk_type_name(a.type)) + " values)";
    }

    // The array's bytes, in the file's byte order, after its header.
    std::vector<uint8_t> read_block(ByteSource& source, uint64_t expected, const ArrayElement& a,
                                    const std::string& where) const {
        std::vector<uint8_t> scratch;
        if (!layout_.zlib) {
            const uint64_t declared = read_word(source, where, "header");
            if (declared != expected) {
                fail(what_, where + ": its header says " + std::to_string(declared) +
                                " bytes, expected " + expected_text(expected, a));
            }
            if (declared > source.max_remaining()) {
                fail(what_, where + ": declares " + std::to_string(declared) + " bytes, but only " +
                                std::to_string(source.max_remaining()) + " remain (truncated?)", ErrorCode::truncated);
            }
            const uint8_t* p = source.take(declared, scratch);
            if (!p) fail_source(source, where, "");
            return std::vector<uint8_t>(p, p + declared);
        }
        // vtkZLibDataCompressor: block count, block size, size of the last block (0: full), the
        // compressed size of each block, then the blocks.
        const uint64_t blocks = read_word(source, where, "compression header");
        const uint64_t block_size = read_word(source, where, "compression header");
        const uint64_t last_size = read_word(source, where, "compression header");
        if (blocks > source.max_remaining() / layout_.header_bytes) {
            fail(what_, where + ": declares " + std::to_string(blocks) +
                            " compressed blocks, more than the data can hold");
        }
        if (blocks > 0 && (block_size == 0 || last_size > block_size)) {
            fail(what_, where + ": bad compression header (block size " + std::to_string(block_size) +
                            ", last block " + std::to_string(last_size) + ")");
        }
        uint64_t total = 0;
        if (blocks > 0) {
            const uint64_t last = last_size ? last_size : block_size;
            if (blocks - 1 > (std::numeric_limits<uint64_t>::max() - last) / block_size) {
                fail(what_, where + ": bad compression header (size overflows)");
            }
            total = (blocks - 1) * block_size + last;
        }
        if (total != expected) {
            fail(what_, where + ": its compression header says " + std::to_string(total) +
                            " bytes, expected " + expected_text(expected, a));
        }
        std::vector<uint64_t> compressed(blocks);
        uint64_t compressed_total = 0;
        for (uint64_t& c : compressed) {
            c = read_word(source, where, "compression header");
            if (c > source.max_remaining()) {
                fail(what_, where + ": a compressed block of " + std::to_string(c) +
                                " bytes is longer than the data left (truncated?)", ErrorCode::truncated);
            }
            compressed_total += c;  // each term is bounded by the input size: no overflow
        }
        if (compressed_total > source.max_remaining()) {
            fail(what_, where + ": the compressed blocks need " + std::to_string(compressed_total) +
                            " bytes, but only " + std::to_string(source.max_remaining()) + " remain (truncated?)", ErrorCode::truncated);
        }
        // The output grows block by block, each block first checked against what zlib can
        // expand its bytes to: no allocation is larger than the input can back.
        std::vector<uint8_t> out;
        for (uint64_t b = 0; b < blocks; ++b) {
            const uint64_t size = (b + 1 == blocks && last_size) ? last_size : block_size;
            if (size > compressed[b] * kZlibMaxExpansion + 64) {
                fail(what_, where + ": compressed block " + std::to_string(b) + " declares " +
                                std::to_string(size) + " bytes, more than its " + std::to_string(compressed[b]) +
                                " compressed bytes can hold");
            }
            const uint8_t* p = source.take(compressed[b], scratch);
            if (!p) fail_source(source, where, "");
            const std::size_t at = out.size();
            out.resize(at + size);
            if (!inflate_zlib_block(p, compressed[b], out.data() + at, size)) {
                fail(what_, where + ": compressed block " + std::to_string(b) + " of " +
                                std::to_string(blocks) + " is not valid zlib data of " +
                                std::to_string(size) + " bytes");
            }
        }
        return out;
    }

    const Layout& layout_;
    const std::string& what_;
};

// Calls f(i, value) for each value of an integer array (64-bit unsigned values past INT64_MAX
// come as INT64_MAX, out of every range the callers accept).
template <typename F>
void for_each_integer(const DataArray& array, F f) {
    std::visit(
        [&](const auto& v) {
            using T = typename std::decay_t<decltype(v)>::value_type;
            if constexpr (std::is_integral_v<T>) {
                for (std::size_t i = 0; i < v.size(); ++i) {
                    if constexpr (std::is_same_v<T, uint64_t>) {
                        f(i, static_cast<int64_t>(std::min<uint64_t>(v[i], std::numeric_limits<int64_t>::max())));
                    } else {
                        f(i, static_cast<int64_t>(v[i]));
                    }
                }
            }
        },
        array.values);
}

template <typename T>
void append_values(DataArray::Values& to, const DataArray::Values& from) {
    std::get<std::vector<T>>(to).insert(std::get<std::vector<T>>(to).end(),
                                        std::get<std::vector<T>>(from).begin(),
                                        std::get<std::vector<T>>(from).end());
}

// Adds one piece's arrays to those of the earlier pieces (the first piece sets the list).
void append_data(std::vector<DataArray>& all, std::vector<DataArray>&& piece, bool first,
                 const char* kind, std::size_t piece_index, const std::string& what) {
    if (first) {
        all = std::move(piece);
        return;
    }
    if (piece.size() != all.size()) {
        fail(what, "piece " + std::to_string(piece_index) + " has " + std::to_string(piece.size()) + " " +
                       kind + " arrays, piece 0 has " + std::to_string(all.size()), ErrorCode::invalid_input);
    }
    for (std::size_t i = 0; i < all.size(); ++i) {
        if (piece[i].name != all[i].name || piece[i].type() != all[i].type() ||
            piece[i].components != all[i].components) {
            fail(what, "piece " + std::to_string(piece_index) + "'s " + kind + " array " +
                           text::quote_token(piece[i].name) + " does not match piece 0's " +
                           text::quote_token(all[i].name) + " (name, type and components)", ErrorCode::invalid_input);
        }
        std::visit(
            [&](auto& v) {
                using T = typename std::decay_t<decltype(v)>::value_type;
                append_values<T>(all[i].values, piece[i].values);
            },
            all[i].values);
    }
}

const ArrayElement* find_cells_array(const PieceElement& piece, const char* name) {
    for (const ArrayElement& a : piece.arrays) {
        if (a.section == Section::cells && a.name == name) return &a;
    }
    return nullptr;
}

}  // namespace

VtuMesh parse_vtu(std::string_view bytes, const std::string& what) {
    const Layout layout = read_layout(bytes, what);
    const ArrayDecoder decoder(layout, what);
    VtuMesh out;
    out.mesh.single_precision = true;
    uint64_t first_point = 0, first_cell = 0;
    for (std::size_t k = 0; k < layout.pieces.size(); ++k) {
        const PieceElement& piece = layout.pieces[k];
        const std::string prefix = layout.pieces.size() > 1 ? "piece " + std::to_string(k) + ": " : "";
        if (piece.points > kMaxElements - first_point || piece.cells > kMaxElements - first_cell) {
            fail(what, prefix + "declares " + std::to_string(piece.points) + " points and " +
                           std::to_string(piece.cells) + " cells, more than 2^32 - 1 in all", ErrorCode::limit_exceeded);
        }
        const auto need = [&](const char* name) -> const ArrayElement& {
            const ArrayElement* a = find_cells_array(piece, name);
            if (!a) fail(what, prefix + "Cells has no '" + name + "' DataArray");
            return *a;
        };
        const auto integers = [&](const ArrayElement& a, uint64_t tuples) {
            if (!is_integer(a.type) || a.components != 1) {
                fail(what, describe(a, prefix) + ": has type " + std::string(vtk_type_name(a.type)) +
                               " with " + std::to_string(a.components) +
                               " components; one integer per cell is needed", ErrorCode::invalid_input);
            }
            return decoder.decode(a, tuples, prefix);
        };

        // Types first, so that a mesh of quads is refused as such, whatever its offsets say.
        const DataArray types = integers(need("types"), piece.cells);
        for_each_integer(types, [&](std::size_t i, int64_t type) {
            if (type != kVtkTriangle && type != kVtkPolygon) {
                fail(what, "cell " + std::to_string(first_cell + i) + " is " + describe_vtk_cell_type(type) +
                               "; only triangles (VTK type 5) and polygons of 3 points are read", ErrorCode::invalid_input);
            }
        });
        const DataArray offsets = integers(need("offsets"), piece.cells);
        for_each_integer(offsets, [&](std::size_t i, int64_t end) {
            // Every earlier cell had 3 points, so this one starts at 3i.
            const int64_t begin = 3 * static_cast<int64_t>(i);
            if (end != begin + 3) {
                const int64_t type = static_cast<int64_t>(types.value(i));
                fail(what, "cell " + std::to_string(first_cell + i) + " is " + describe_vtk_cell_type(type) +
                               " of " + (end >= begin ? std::to_string(end - begin) : std::string("fewer than 0")) +
                               " points (offset " + std::to_string(end) +
                               "); only cells of 3 points are read", ErrorCode::invalid_input);
            }
        });
        const DataArray connectivity = integers(need("connectivity"), 3 * piece.cells);

        const ArrayElement* points = nullptr;
        for (const ArrayElement& a : piece.arrays) {
            if (a.section == Section::points) {
                points = &a;
                break;
            }
        }
        if (!points && piece.points > 0) fail(what, prefix + "no Points DataArray");
        if (points) {
            if (points->components != 3) {
                fail(what, describe(*points, prefix) + ": has " + std::to_string(points->components) +
                               " components; points need 3", ErrorCode::invalid_input);
            }
            const DataArray coordinates = decoder.decode(*points, piece.points, prefix);
            if (points->type != ValueType::float32) out.mesh.single_precision = false;
            out.mesh.positions.reserve(first_point + piece.points);
            std::visit(
                [&](const auto& v) {
                    for (std::size_t i = 0; i + 2 < v.size(); i += 3) {
                        out.mesh.positions.push_back({static_cast<double>(v[i]), static_cast<double>(v[i + 1]),
                                                      static_cast<double>(v[i + 2])});
                    }
                },
                coordinates.values);
        }

        out.mesh.triangles.resize(first_cell + piece.cells);
        for_each_integer(connectivity, [&](std::size_t i, int64_t index) {
            if (index < 0 || static_cast<uint64_t>(index) >= piece.points) {
                fail(what, "cell " + std::to_string(first_cell + i / 3) + " refers to point " +
                               std::to_string(index) + ", out of range (" + prefix +
                               std::to_string(piece.points) + " points)");
            }
            out.mesh.triangles[first_cell + i / 3][i % 3] = static_cast<uint32_t>(first_point + index);
        });

        std::vector<DataArray> point_data, cell_data;
        for (const ArrayElement& a : piece.arrays) {
            if (a.section == Section::point_data) point_data.push_back(decoder.decode(a, piece.points, prefix));
            if (a.section == Section::cell_data) cell_data.push_back(decoder.decode(a, piece.cells, prefix));
        }
        append_data(out.point_data, std::move(point_data), k == 0, "point data", k, what);
        append_data(out.cell_data, std::move(cell_data), k == 0, "cell data", k, what);
        first_point += piece.points;
        first_cell += piece.cells;
    }
    if (out.mesh.positions.empty()) out.mesh.single_precision = false;
    return out;
}

}  // namespace amc
