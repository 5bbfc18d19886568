// A small pull tokenizer for the XML of VTK files: tags with attributes, and the text between
// them, over a whole file held in memory. Declarations, processing instructions, comments and
// DOCTYPE are skipped; attribute values have the five predefined entities and character
// references decoded. Not a validating parser: nesting is the caller's business. The writers'
// side is escape_xml_attribute.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace amc {

struct XmlAttribute {
    std::string_view name;
    std::string value;
};

struct XmlToken {
    enum class Kind { start_tag, end_tag, text, end_of_input };
    Kind kind = Kind::end_of_input;
    std::string_view name;                // start_tag, end_tag
    std::vector<XmlAttribute> attributes;  // start_tag
    bool self_closing = false;            // start_tag written as <name ... />
    std::string_view text;                // text, entities not decoded
    std::size_t begin = 0, end = 0;       // byte range of the token in the input

    // The value of an attribute, or null when the tag has none of that name.
    const std::string* attribute(std::string_view attribute_name) const;
};

// `value` escaped to stand between double quotes as an attribute value (what the tokenizer decodes
// back; line breaks and tabs as character references, so they survive attribute normalisation).
std::string escape_xml_attribute(std::string_view value);

class XmlTokenizer {
public:
    // `what` names the source in messages.
    XmlTokenizer(std::string_view input, const std::string& what) : input_(input), what_(what) {}

    // The next token; end_of_input at the end. Throws Error on malformed markup.
    XmlToken next();

    std::size_t position() const { return pos_; }
    // 1-based line number of a byte offset, for messages.
    std::size_t line_of(std::size_t offset) const;

private:
    [[noreturn]] void fail(std::size_t offset, const std::string& message) const;
    void skip_until(std::string_view terminator, std::size_t start, const char* what);
    std::string_view read_name();
    void skip_space();
    std::string decode_attribute(std::string_view raw, std::size_t offset) const;

    std::string_view input_;
    const std::string& what_;
    std::size_t pos_ = 0;
};

}  // namespace amc
