// Locale-independent number parsing and shortest round-trip formatting for the text mesh
// formats (OBJ, OFF, ASCII PLY, VTU), and a token cursor over a whole file held in memory.
#pragma once

#include <array>
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

// Parses the whole token as a decimal integer (optional sign), as std::from_chars would, which
// spent more than a hundred instructions on each short face index.
inline bool parse_int(std::string_view token, int64_t& out) {
    std::size_t i = 0;
    const bool negative = !token.empty() && token[0] == '-';
    if (!token.empty() && (token[0] == '+' || token[0] == '-')) i = 1;
    if (i == token.size()) return false;
    constexpr uint64_t kMaxMagnitude = uint64_t{1} << 63;  // -2^63 is the one magnitude past the maximum
    constexpr std::size_t kDigitsThatFit = 18;                // 10^18 - 1 < 2^63
    const bool may_overflow = token.size() - i > kDigitsThatFit;
    uint64_t magnitude = 0;
    for (; i < token.size(); ++i) {
        const unsigned digit = unsigned(static_cast<unsigned char>(token[i])) - unsigned('0');
        if (digit > 9) return false;
        if (may_overflow && magnitude > (kMaxMagnitude - digit) / 10) return false;
        magnitude = magnitude * 10 + digit;
    }
    if (magnitude == kMaxMagnitude && !negative) return false;
    out = negative ? int64_t(0 - magnitude) : int64_t(magnitude);
    return true;
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
        const unsigned separators = kSpace | (hash_comments_ ? kHash : 0u);
        while (pos_ < text_.size() && !(kind(text_[pos_]) & separators)) ++pos_;
        return text_.substr(begin, pos_ - begin);
    }

    // Moves past the end of the current line (used to drop optional trailing values).
    void skip_line() {
        while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
    }

    std::size_t line() const { return line_; }
    std::size_t remaining() const { return text_.size() - pos_; }

private:
    // One table look-up a character instead of seven comparisons: tokens are most of a text mesh.
    static constexpr unsigned kSpace = 1, kHash = 2;
    static unsigned kind(char c) {
        static constexpr auto table = [] {
            std::array<uint8_t, 256> t{};
            for (char s : {' ', '\t', '\n', '\r', '\f', '\v'}) t[static_cast<unsigned char>(s)] = kSpace;
            t[static_cast<unsigned char>('#')] = kHash;
            return t;
        }();
        return table[static_cast<unsigned char>(c)];
    }

    std::string_view text_;
    std::size_t pos_;
    std::size_t line_ = 1;
    bool hash_comments_;
};

}  // namespace amc::text
