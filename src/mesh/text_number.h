// Locale-independent number parsing and shortest round-trip formatting for the text mesh
// formats (OBJ, OFF, ASCII PLY, VTU), and a token cursor over a whole file held in memory.
#pragma once

#include <charconv>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <system_error>
#include <type_traits>

namespace amc::text {

// Parses the whole token as a real number with std::from_chars (correctly rounded, no locale).
// Accepts a leading '+' and "nan"/"inf", which validation rejects later with a better message.
template <typename Real>
bool parse_real(std::string_view token, Real& out) {
    if (!token.empty() && token[0] == '+') {
        token.remove_prefix(1);
        if (!token.empty() && (token[0] == '+' || token[0] == '-')) return false;
    }
    const char* last = token.data() + token.size();
    auto [ptr, ec] = std::from_chars(token.data(), last, out, std::chars_format::general);
    return ec == std::errc() && ptr == last;
}

// Parses the whole token as a decimal integer (optional sign).
inline bool parse_int(std::string_view token, int64_t& out) {
    if (!token.empty() && token[0] == '+') {
        token.remove_prefix(1);
        if (!token.empty() && (token[0] == '+' || token[0] == '-')) return false;
    }
    const char* last = token.data() + token.size();
    auto [ptr, ec] = std::from_chars(token.data(), last, out, 10);
    return ec == std::errc() && ptr == last;
}

// Appends the shortest decimal that reads back as exactly `value` (std::to_chars).
template <typename Real>
void append_real(std::string& out, Real value) {
    char buf[64];
    auto [ptr, ec] = std::to_chars(buf, buf + sizeof buf, value);
    if (ec != std::errc()) ptr = buf;  // cannot happen with 64 bytes
    out.append(buf, ptr);
}

inline void append_uint(std::string& out, uint64_t value) {
    char buf[24];
    auto [ptr, ec] = std::to_chars(buf, buf + sizeof buf, value);
    if (ec != std::errc()) ptr = buf;
    out.append(buf, ptr);
}

// Three numbers separated by spaces, then a newline: a vertex line (floating point) or a triangle
// line (unsigned).
template <typename T>
void append_line(std::string& out, T a, T b, T c) {
    const T values[3] = {a, b, c};
    for (int k = 0; k < 3; ++k) {
        if constexpr (std::is_floating_point_v<T>) {
            append_real(out, values[k]);
        } else {
            append_uint(out, values[k]);
        }
        out += k < 2 ? ' ' : '\n';
    }
}

// Shortens a token for an error message.
inline std::string quote_token(std::string_view token) {
    std::string s;
    for (char c : token.substr(0, 32)) s += (c >= 0x20 && c < 0x7f) ? c : '?';
    if (token.size() > 32) s += "...";
    return "'" + s + "'";
}

// Whitespace-separated tokens of an in-memory file; '#' starts a comment to the end of the line
// when `hash_comments` is set. Tracks the 1-based line number for messages.
class TokenCursor {
public:
    TokenCursor(std::string_view text, bool hash_comments, std::size_t start = 0)
        : text_(text), pos_(start), hash_comments_(hash_comments) {}

    // Skips white space and comments; false at the end of the text.
    bool skip_space() {
        while (pos_ < text_.size()) {
            char c = text_[pos_];
            if (c == '\n') {
                ++line_;
                ++pos_;
            } else if (c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v') {
                ++pos_;
            } else if (c == '#' && hash_comments_) {
                while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
            } else {
                return true;
            }
        }
        return false;
    }

    // The next token, or an empty view at the end of the text.
    std::string_view next() {
        if (!skip_space()) return {};
        std::size_t begin = pos_;
        while (pos_ < text_.size() && !is_separator(text_[pos_])) ++pos_;
        return text_.substr(begin, pos_ - begin);
    }

    // Moves past the end of the current line (used to drop optional trailing values).
    void skip_line() {
        while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
    }

    std::size_t line() const { return line_; }
    std::size_t remaining() const { return text_.size() - pos_; }

private:
    bool is_separator(char c) const {
        return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v' ||
               (c == '#' && hash_comments_);
    }

    std::string_view text_;
    std::size_t pos_;
    std::size_t line_ = 1;
    bool hash_comments_;
};

}  // namespace amc::text
