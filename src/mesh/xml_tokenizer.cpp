// XmlTokenizer: one pass over the bytes, no allocation beyond the attribute list of a tag.
#include "mesh/xml_tokenizer.h"

#include <algorithm>
#include <cstdint>

#include "amc/mesh.h"

namespace amc {

std::string escape_xml_attribute(std::string_view value) {
    std::string out;
    for (char c : value) {
        switch (c) {
            case '&': out += "&amp;"; break;
            case '<': out += "&lt;"; break;
            case '>': out += "&gt;"; break;
            case '"': out += "&quot;"; break;
            case '\n': out += "&#10;"; break;
            case '\t': out += "&#9;"; break;
            case '\r': out += "&#13;"; break;
            default: out += c;
        }
    }
    return out;
}

namespace {

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }

bool is_name_char(char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
           c == ':' || c == '-' || c == '.' || static_cast<unsigned char>(c) >= 0x80;
}

void append_utf8(std::string& out, uint32_t code) {
    if (code < 0x80) {
        out += static_cast<char>(code);
    } else if (code < 0x800) {
        out += static_cast<char>(0xc0 | (code >> 6));
        out += static_cast<char>(0x80 | (code & 0x3f));
    } else if (code < 0x10000) {
        out += static_cast<char>(0xe0 | (code >> 12));
        out += static_cast<char>(0x80 | ((code >> 6) & 0x3f));
        out += static_cast<char>(0x80 | (code & 0x3f));
    } else {
        out += static_cast<char>(0xf0 | (code >> 18));
        out += static_cast<char>(0x80 | ((code >> 12) & 0x3f));
        out += static_cast<char>(0x80 | ((code >> 6) & 0x3f));
        out += static_cast<char>(0x80 | (code & 0x3f));
    }
}

}  // namespace

const std::string* XmlToken::attribute(std::string_view attribute_name) const {
    for (const XmlAttribute& a : attributes) {
        if (a.name == attribute_name) return &a.value;
    }
    return nullptr;
}

std::size_t XmlTokenizer::line_of(std::size_t offset) const {
    offset = std::min(offset, input_.size());
    return 1 + static_cast<std::size_t>(std::count(input_.begin(), input_.begin() + offset, '\n'));
}

void XmlTokenizer::fail(std::size_t offset, const std::string& message) const {
    throw Error(ErrorCode::corrupt, what_ + ": bad XML at line " + std::to_string(line_of(offset)) + ": " + message);
}

void XmlTokenizer::skip_until(std::string_view terminator, std::size_t start, const char* what) {
    const std::size_t found = input_.find(terminator, pos_);
    if (found == std::string_view::npos) fail(start, std::string("unterminated ") + what);
    pos_ = found + terminator.size();
}

void XmlTokenizer::skip_space() {
    while (pos_ < input_.size() && is_space(input_[pos_])) ++pos_;
}

std::string_view XmlTokenizer::read_name() {
    const std::size_t begin = pos_;
    while (pos_ < input_.size() && is_name_char(input_[pos_])) ++pos_;
    return input_.substr(begin, pos_ - begin);
}

std::string XmlTokenizer::decode_attribute(std::string_view raw, std::size_t offset) const {
    std::string out;
    out.reserve(raw.size());
    for (std::size_t i = 0; i < raw.size(); ++i) {
        if (raw[i] != '&') {
            out += raw[i];
            continue;
        }
        const std::size_t semicolon = raw.find(';', i);
        if (semicolon == std::string_view::npos || semicolon - i > 10) {
            fail(offset, "unterminated entity in an attribute value");
        }
        const std::string_view entity = raw.substr(i + 1, semicolon - i - 1);
        if (entity == "lt") {
            out += '<';
        } else if (entity == "gt") {
            out += '>';
        } else if (entity == "amp") {
            out += '&';
        } else if (entity == "quot") {
            out += '"';
        } else if (entity == "apos") {
            out += '\'';
        } else if (entity.size() >= 2 && entity[0] == '#') {
            const bool hex = entity[1] == 'x';
            uint32_t code = 0;
            const std::string_view digits = entity.substr(hex ? 2 : 1);
            if (digits.empty()) fail(offset, "bad character reference");
            for (char c : digits) {
                int d = c >= '0' && c <= '9'            ? c - '0'
                        : hex && c >= 'a' && c <= 'f'   ? c - 'a' + 10
                        : hex && c >= 'A' && c <= 'F'   ? c - 'A' + 10
                                                        : -1;
                if (d < 0 || code > 0x10ffff) fail(offset, "bad character reference");
                code = code * (hex ? 16 : 10) + static_cast<uint32_t>(d);
            }
            if (code == 0 || code > 0x10ffff) fail(offset, "bad character reference");
            append_utf8(out, code);
        } else {
            fail(offset, "unknown entity '&" + std::string(entity.substr(0, 16)) + ";'");
        }
        i = semicolon;
    }
    return out;
}

XmlToken XmlTokenizer::next() {
    XmlToken token;
    for (;;) {
        token.begin = pos_;
        if (pos_ >= input_.size()) {
            token.kind = XmlToken::Kind::end_of_input;
            token.end = pos_;
            return token;
        }
        if (input_[pos_] != '<') {
            const std::size_t lt = input_.find('<', pos_);
            pos_ = lt == std::string_view::npos ? input_.size() : lt;
            token.kind = XmlToken::Kind::text;
            token.text = input_.substr(token.begin, pos_ - token.begin);
            token.end = pos_;
            return token;
        }
        const std::string_view rest = input_.substr(pos_);
        if (rest.substr(0, 4) == "<!--") {
            skip_until("-->", token.begin, "comment");
        } else if (rest.substr(0, 2) == "<?") {
            skip_until("?>", token.begin, "processing instruction");
        } else if (rest.substr(0, 9) == "<!DOCTYPE") {
            skip_until(">", token.begin, "DOCTYPE");
        } else if (rest.substr(0, 2) == "</") {
            pos_ += 2;
            token.kind = XmlToken::Kind::end_tag;
            token.name = read_name();
            if (token.name.empty()) fail(token.begin, "end tag without a name");
            skip_space();
            if (pos_ >= input_.size() || input_[pos_] != '>') {
                fail(token.begin, "unterminated end tag </" + std::string(token.name) + ">");
            }
            ++pos_;
            token.end = pos_;
            return token;
        } else {
            ++pos_;
            token.kind = XmlToken::Kind::start_tag;
            token.name = read_name();
            if (token.name.empty()) fail(token.begin, "'<' not followed by a tag name");
            for (;;) {
                const std::size_t before_space = pos_;
                skip_space();
                if (pos_ >= input_.size()) {
                    fail(token.begin, "unterminated tag <" + std::string(token.name) + ">");
                }
                if (input_[pos_] == '>') {
                    ++pos_;
                    break;
                }
                if (input_.substr(pos_, 2) == "/>") {
                    pos_ += 2;
                    token.self_closing = true;
                    break;
                }
                if (pos_ == before_space) {
                    fail(pos_, "malformed tag <" + std::string(token.name) + ">");
                }
                const std::string_view name = read_name();
                skip_space();
                if (name.empty() || pos_ >= input_.size() || input_[pos_] != '=') {
                    fail(pos_, "malformed attribute in tag <" + std::string(token.name) + ">");
                }
                ++pos_;
                skip_space();
                if (pos_ >= input_.size() || (input_[pos_] != '"' && input_[pos_] != '\'')) {
                    fail(pos_, "unquoted attribute value in tag <" + std::string(token.name) + ">");
                }
                const char quote = input_[pos_++];
                const std::size_t close = input_.find(quote, pos_);
                if (close == std::string_view::npos) {
                    fail(token.begin, "unterminated attribute value in tag <" +
                                          std::string(token.name) + ">");
                }
                token.attributes.push_back(
                    {name, decode_attribute(input_.substr(pos_, close - pos_), pos_)});
                pos_ = close + 1;
            }
            token.end = pos_;
            return token;
        }
    }
}

}  // namespace amc
