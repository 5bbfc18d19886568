// PLY reader (ASCII, binary little- and big-endian) and binary little-endian writer.
#include "mesh/ply_io.h"

#include <cstdint>
#include <cstring>
#include <limits>
#include <utility>
#include <vector>

#include "common/check.h"
#include "mesh/text_number.h"

namespace amc {
namespace {

[[noreturn]] void fail(const std::string& what, const std::string& message, ErrorCode code = ErrorCode::corrupt) {
    throw_error(code, what + ": " + message);
}

enum class Encoding { ascii, binary_little_endian, binary_big_endian };
enum class Type { int8, uint8, int16, uint16, int32, uint32, float32, float64 };

struct Property {
    std::string name;
    Type type = Type::float32;  // the item type for a list
    bool is_list = false;
    Type count_type = Type::uint8;
};

struct Element {
    std::string name;
    uint64_t count = 0;
    std::vector<Property> properties;
};

struct Header {
    Encoding encoding = Encoding::ascii;
    std::vector<Element> elements;
    std::size_t data_offset = 0;
};

bool parse_type(std::string_view name, Type& type) {
    static const struct {
        const char* name;
        Type type;
    } names[] = {{"char", Type::int8},       {"int8", Type::int8},       {"uchar", Type::uint8},
                 {"uint8", Type::uint8},     {"short", Type::int16},     {"int16", Type::int16},
                 {"ushort", Type::uint16},   {"uint16", Type::uint16},   {"int", Type::int32},
                 {"int32", Type::int32},     {"uint", Type::uint32},     {"uint32", Type::uint32},
                 {"float", Type::float32},   {"float32", Type::float32}, {"double", Type::float64},
                 {"float64", Type::float64}};
    for (const auto& n : names) {
        if (name == n.name) {
            type = n.type;
            return true;
        }
    }
    return false;
}

std::size_t type_size(Type type) {
    switch (type) {
        case Type::int8:
        case Type::uint8: return 1;
        case Type::int16:
        case Type::uint16: return 2;
        case Type::int32:
        case Type::uint32:
        case Type::float32: return 4;
        case Type::float64: return 8;
    }
    return 8;
}

bool is_integer(Type type) { return type != Type::float32 && type != Type::float64; }

std::vector<std::string_view> split_words(std::string_view line) {
    std::vector<std::string_view> words;
    text::TokenCursor cursor(line, /*hash_comments=*/false);
    for (std::string_view w = cursor.next(); !w.empty(); w = cursor.next()) words.push_back(w);
    return words;
}

Header parse_header(std::string_view bytes, const std::string& what) {
    Header header;
    std::size_t pos = 0;
    std::size_t line_number = 0;
    bool have_format = false;
    for (;;) {
        const std::size_t end = bytes.find('\n', pos);
        if (end == std::string_view::npos) fail(what, "bad PLY header: no end_header line");
        std::string_view line = bytes.substr(pos, end - pos);
        pos = end + 1;
        ++line_number;
        if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
        const std::string at = " (header line " + std::to_string(line_number) + ")";
        if (line_number == 1) {
            if (line != "ply") fail(what, "not a PLY file (the first line is not \"ply\")", ErrorCode::bad_magic);
            continue;
        }
        std::vector<std::string_view> words = split_words(line);
        if (words.empty()) continue;
        const std::string_view keyword = words[0];
        if (keyword == "comment" || keyword == "obj_info") continue;
        if (keyword == "end_header") break;
        if (keyword == "format") {
            if (words.size() != 3) fail(what, "bad PLY header: malformed format line" + at);
            if (words[1] == "ascii") {
                header.encoding = Encoding::ascii;
            } else if (words[1] == "binary_little_endian") {
                header.encoding = Encoding::binary_little_endian;
            } else if (words[1] == "binary_big_endian") {
                header.encoding = Encoding::binary_big_endian;
            } else {
                fail(what, "bad PLY header: unknown format " + text::quote_token(words[1]) + at);
            }
            have_format = true;
        } else if (keyword == "element") {
            int64_t count = 0;
            if (words.size() != 3 || !text::parse_int(words[2], count) || count < 0) {
                fail(what, "bad PLY header: malformed element line" + at);
            }
            header.elements.push_back({std::string(words[1]), static_cast<uint64_t>(count), {}});
        } else if (keyword == "property") {
            if (header.elements.empty()) fail(what, "bad PLY header: property before element" + at);
            Property p;
            if (words.size() == 5 && words[1] == "list") {
                p.is_list = true;
                if (!parse_type(words[2], p.count_type) || !is_integer(p.count_type) ||
                    !parse_type(words[3], p.type)) {
                    fail(what, "bad PLY header: bad list property types" + at);
                }
                p.name = std::string(words[4]);
            } else if (words.size() == 3 && parse_type(words[1], p.type)) {
                p.name = std::string(words[2]);
            } else {
                fail(what, "bad PLY header: malformed property line" + at);
            }
            header.elements.back().properties.push_back(p);
        } else {
            fail(what, "bad PLY header: unknown keyword " + text::quote_token(keyword) + at);
        }
    }
    if (!have_format) fail(what, "bad PLY header: no format line");
    header.data_offset = pos;
    return header;
}

// Fewest bytes one item of the element can take: every fixed property and every list count in
// binary; one character and one separator per property in ASCII.
uint64_t min_item_bytes(const Element& e, Encoding encoding) {
    uint64_t bytes = 0;
    for (const Property& p : e.properties) {
        if (encoding == Encoding::ascii) {
            bytes += 2;
        } else {
            bytes += type_size(p.is_list ? p.count_type : p.type);
        }
    }
    return bytes;
}

void check_counts(const Header& header, std::size_t data_bytes, const std::string& what) {
    uint64_t total = 0;
    for (const Element& e : header.elements) {
        if (e.count == 0) continue;
        if (e.properties.empty()) {
            fail(what, "bad PLY header: element '" + e.name + "' has no properties");
        }
        const uint64_t item = min_item_bytes(e, header.encoding);
        // ASCII: n tokens need 2n - 1 bytes; allow for the missing last separator.
        const uint64_t available = data_bytes + (header.encoding == Encoding::ascii ? 1 : 0);
        if (e.count > available / item || total + e.count * item > available) {
            fail(what, "element '" + e.name + "' declares " + std::to_string(e.count) +
                           " items, more than the " + std::to_string(data_bytes) +
                           " bytes of data can hold");
        }
        total += e.count * item;
    }
}

// Where a value is read, for messages ("vertex 12"): composed only when one is written.
struct ItemPlace {
    const std::string& element;
    uint64_t item;
    std::string text() const { return element + " " + std::to_string(item); }
};

// Reads the values of one encoding as doubles (exact for every PLY type).
class ValueReader {
public:
    ValueReader(std::string_view bytes, std::size_t offset, Encoding encoding,
                const std::string& what)
        : bytes_(bytes), pos_(offset), encoding_(encoding), what_(what),
          tokens_(bytes, /*hash_comments=*/false, offset) {
        for (std::size_t i = 0; i < offset; ++i) header_lines_ += bytes[i] == '\n';
    }

    double read(Type type, const ItemPlace& place) {
        if (encoding_ == Encoding::ascii) return read_ascii(type, place);
        switch (type) {
            case Type::int8: return static_cast<int8_t>(take<uint8_t>(place));
            case Type::uint8: return take<uint8_t>(place);
            case Type::int16: return static_cast<int16_t>(take<uint16_t>(place));
            case Type::uint16: return take<uint16_t>(place);
            case Type::int32: return static_cast<int32_t>(take<uint32_t>(place));
            case Type::uint32: return take<uint32_t>(place);
            case Type::float32: {
                const uint32_t u = take<uint32_t>(place);
                float f;
                std::memcpy(&f, &u, 4);
                return f;
            }
            case Type::float64: {
                const uint64_t u = take<uint64_t>(place);
                double d;
                std::memcpy(&d, &u, 8);
                return d;
            }
        }
        return 0;
    }

    // Skips `count` values of one type.
    void skip(Type type, uint64_t count, const ItemPlace& place) {
        if (encoding_ == Encoding::ascii) {
            for (uint64_t i = 0; i < count; ++i) read_ascii(type, place);
            return;
        }
        const uint64_t size = type_size(type);
        if (count > (bytes_.size() - pos_) / size) fail(what_, "truncated data in " + place.text(), ErrorCode::truncated);
        pos_ += count * size;
    }

    // A list count or an index: an integer value in [0, limit].
    uint64_t read_index(Type type, uint64_t limit, const ItemPlace& place, const char* name) {
        const double v = read(type, place);
        if (!(v >= 0 && v <= static_cast<double>(limit)) ||
            v != static_cast<double>(static_cast<uint64_t>(v))) {
            fail(what_, place.text() + " has a bad " + name + " " + format(v));
        }
        return static_cast<uint64_t>(v);
    }

private:
    // The next binary value's bits, in the file's byte order.
    template <typename U>
    U take(const ItemPlace& place) {
        if (bytes_.size() - pos_ < sizeof(U)) fail(what_, "truncated data in " + place.text(), ErrorCode::truncated);
        const auto* b = reinterpret_cast<const unsigned char*>(bytes_.data() + pos_);
        pos_ += sizeof(U);
        U u = 0;
        if (encoding_ == Encoding::binary_big_endian) {
            for (std::size_t i = 0; i < sizeof(U); ++i) u = U(uint64_t(u) << 8 | b[i]);
        } else {
            for (std::size_t i = 0; i < sizeof(U); ++i) u = U(u | uint64_t(b[i]) << (8 * i));
        }
        return u;
    }

    static std::string format(double v) {
        std::string s;
        text::append_real(s, v);
        return s;
    }

    double read_ascii(Type type, const ItemPlace& place) {
        std::string_view token = tokens_.next();
        if (token.empty()) fail(what_, "truncated data in " + place.text(), ErrorCode::truncated);
        auto at = [&] { return " (line " + std::to_string(tokens_.line() + header_lines_) + ")"; };
        if (type == Type::float32) {
            float f;
            if (!text::parse_real(token, f)) {
                fail(what_, place.text() + " has a malformed value " + text::quote_token(token) + at());
            }
            return f;
        }
        if (type == Type::float64) {
            double d;
            if (!text::parse_real(token, d)) {
                fail(what_, place.text() + " has a malformed value " + text::quote_token(token) + at());
            }
            return d;
        }
        int64_t i = 0;
        if (!text::parse_int(token, i)) {
            fail(what_, place.text() + " has a malformed integer " + text::quote_token(token) + at());
        }
        int64_t lo = 0, hi = 0;
        switch (type) {
            case Type::int8: lo = INT8_MIN, hi = INT8_MAX; break;
            case Type::uint8: lo = 0, hi = UINT8_MAX; break;
            case Type::int16: lo = INT16_MIN, hi = INT16_MAX; break;
            case Type::uint16: lo = 0, hi = UINT16_MAX; break;
            case Type::int32: lo = INT32_MIN, hi = INT32_MAX; break;
            default: lo = 0, hi = UINT32_MAX; break;
        }
        if (i < lo || i > hi) {
            fail(what_, place.text() + " has value " + std::to_string(i) +
                            " out of the range of its type" + at());
        }
        return static_cast<double>(i);
    }

    std::string_view bytes_;
    std::size_t pos_;
    Encoding encoding_;
    const std::string& what_;
    text::TokenCursor tokens_;
    std::size_t header_lines_ = 0;  // so that ASCII messages give file line numbers
};

int find_property(const Element& e, std::string_view name) {
    for (std::size_t i = 0; i < e.properties.size(); ++i) {
        if (e.properties[i].name == name) return static_cast<int>(i);
    }
    return -1;
}

}  // namespace

TriangleMesh parse_ply(std::string_view bytes, const std::string& what) {
    const Header header = parse_header(bytes, what);
    check_counts(header, bytes.size() - header.data_offset, what);

    const Element* vertex_element = nullptr;
    const Element* face_element = nullptr;
    for (const Element& e : header.elements) {
        if (e.name == "vertex" || e.name == "face") {
            const Element*& slot = e.name == "vertex" ? vertex_element : face_element;
            if (slot) fail(what, "bad PLY header: two '" + e.name + "' elements");
            slot = &e;
        }
    }
    if (!vertex_element) fail(what, "bad PLY header: no vertex element");
    if (!face_element) fail(what, "bad PLY header: no face element");
    int xyz[3];
    for (int k = 0; k < 3; ++k) {
        const char* name = k == 0 ? "x" : k == 1 ? "y" : "z";
        xyz[k] = find_property(*vertex_element, name);
        if (xyz[k] < 0 || vertex_element->properties[xyz[k]].is_list) {
            fail(what, std::string("bad PLY header: the vertex element has no scalar property ") +
                           name);
        }
    }
    int corner_property = find_property(*face_element, "vertex_indices");
    if (corner_property < 0) corner_property = find_property(*face_element, "vertex_index");
    if (corner_property < 0 || !face_element->properties[corner_property].is_list) {
        fail(what, "bad PLY header: the face element has no vertex_indices list");
    }
    if (vertex_element->count > UINT32_MAX) fail(what, "too many vertices", ErrorCode::limit_exceeded);

    TriangleMesh mesh;
    // check_counts bounded both counts by the data size, so these allocations are safe.
    mesh.positions.resize(vertex_element->count);
    mesh.triangles.resize(face_element->count);
    ValueReader in(bytes, header.data_offset, header.encoding, what);
    for (const Element& e : header.elements) {
        const bool is_vertex = &e == vertex_element, is_face = &e == face_element;
        for (uint64_t item = 0; item < e.count; ++item) {
            const ItemPlace place{e.name, item};
            for (std::size_t pi = 0; pi < e.properties.size(); ++pi) {
                const Property& p = e.properties[pi];
                if (p.is_list) {
                    const uint64_t n = in.read_index(p.count_type, UINT32_MAX, place, "list size");
                    if (is_face && static_cast<int>(pi) == corner_property) {
                        if (n != 3) {
                            fail(what, "face " + std::to_string(item) + " has " +
                                           std::to_string(n) +
                                           " vertices; only triangle meshes are supported", ErrorCode::invalid_input);
                        }
                        for (uint32_t& index : mesh.triangles[item]) {
                            index = static_cast<uint32_t>(
                                in.read_index(p.type, UINT32_MAX, place, "vertex index"));
                        }
                    } else {
                        in.skip(p.type, n, place);
                    }
                } else if (is_vertex && (static_cast<int>(pi) == xyz[0] ||
                                         static_cast<int>(pi) == xyz[1] ||
                                         static_cast<int>(pi) == xyz[2])) {
                    Vec3& pos = mesh.positions[item];
                    double* coordinate = static_cast<int>(pi) == xyz[0]   ? &pos.x
                                         : static_cast<int>(pi) == xyz[1] ? &pos.y
                                                                          : &pos.z;
                    *coordinate = in.read(p.type, place);
                } else {
                    in.skip(p.type, 1, place);
                }
            }
        }
    }

    // Float properties give floats; integer or double ones may happen to be floats too.
    mesh.single_precision = true;
    for (const Vec3& p : mesh.positions) {
        for (double c : {p.x, p.y, p.z}) {
            if (static_cast<double>(static_cast<float>(c)) != c) mesh.single_precision = false;
        }
    }
    return mesh;
}

namespace {

// Stores value's bytes least significant first at `at` (the compiler makes it one store on
// little-endian machines); returns the end.
template <typename T>
char* put_le(char* at, T value) {
    static_assert(sizeof(T) == 1 || sizeof(T) == 4 || sizeof(T) == 8, "scalar");
    uint64_t u = 0;
    if constexpr (sizeof(T) == 8) {
        std::memcpy(&u, &value, 8);
    } else if constexpr (sizeof(T) == 4) {
        uint32_t u32;
        std::memcpy(&u32, &value, 4);
        u = u32;
    } else {
        uint8_t u8;
        std::memcpy(&u8, &value, 1);
        u = u8;
    }
    for (std::size_t i = 0; i < sizeof(T); ++i) at[i] = static_cast<char>((u >> (8 * i)) & 0xff);
    return at + sizeof(T);
}

}  // namespace

std::string format_ply(const TriangleMesh& mesh, const CellData* cells, MeshEncoding encoding) {
    const bool ascii = encoding == MeshEncoding::ascii;
    const bool write_level = ascii && cells && !cells->level.empty();
    const bool write_green = ascii && cells && !cells->is_green.empty();
    if ((write_level && cells->level.size() != mesh.triangles.size()) ||
        (write_green && cells->is_green.size() != mesh.triangles.size())) {
        throw Error("PLY writer: cell data size does not match the triangle count");
    }
    const bool wide_indices = mesh.positions.size() > static_cast<std::size_t>(INT32_MAX);
    const char* real = mesh.single_precision ? "float" : "double";
    std::string out = ascii ? "ply\nformat ascii 1.0\n" : "ply\nformat binary_little_endian 1.0\n";
    out += "comment written by amcodec\n";
    out += "element vertex " + std::to_string(mesh.positions.size()) + "\n";
    out += std::string("property ") + real + " x\nproperty " + real + " y\nproperty " + real +
           " z\n";
    out += "element face " + std::to_string(mesh.triangles.size()) + "\n";
    out += wide_indices ? "property list uchar uint vertex_indices\n"
                        : "property list uchar int vertex_indices\n";
    if (write_level) out += "property uchar level\n";
    if (write_green) out += "property uchar green\n";
    out += "end_header\n";

    if (ascii) {
        for (const Vec3& p : mesh.positions) {
            if (mesh.single_precision) {
                text::append_line(out, static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z));
            } else {
                text::append_line(out, p.x, p.y, p.z);
            }
        }
        for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
            out += "3 ";
            const auto& tri = mesh.triangles[t];
            text::append_line(out, uint64_t{tri[0]}, uint64_t{tri[1]}, uint64_t{tri[2]});
            if (!write_level && !write_green) continue;
            out.pop_back();  // the face's properties go on its line
            if (write_level) {
                out += ' ';
                text::append_uint(out, cells->level[t]);
            }
            if (write_green) {
                out += ' ';
                text::append_uint(out, cells->is_green[t]);
            }
            out += '\n';
        }
        return out;
    }

    const std::size_t real_size = mesh.single_precision ? 4 : 8;
    out.reserve(out.size() + mesh.positions.size() * 3 * real_size + mesh.triangles.size() * 13);
    // Values go through a small block: no per-byte appends, no zero fill of the whole.
    char block[1 << 12];
    char* at = block;
    auto make_room = [&](std::size_t bytes) {
        if (at + bytes <= block + sizeof block) return;
        out.append(block, std::size_t(at - block));
        at = block;
    };
    for (const Vec3& p : mesh.positions) {
        make_room(3 * 8);
        if (mesh.single_precision) {
            at = put_le(put_le(put_le(at, static_cast<float>(p.x)), static_cast<float>(p.y)), static_cast<float>(p.z));
        } else {
            at = put_le(put_le(put_le(at, p.x), p.y), p.z);
        }
    }
    for (const auto& tri : mesh.triangles) {
        make_room(13);
        at = put_le(at, uint8_t{3});
        for (uint32_t v : tri) at = put_le(at, v);
    }
    out.append(block, std::size_t(at - block));
    return out;
}

}  // namespace amc
