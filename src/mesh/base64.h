// Base64 (RFC 4648) decoding as VTK files need it: white space skipped, and '=' padding allowed
// at the end of any 4-character quantum, because VTK writes an array's header and its data as
// two separately padded runs while meshio and DUNE write one or the other.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>

namespace amc {

class Base64Reader {
public:
    explicit Base64Reader(std::string_view text) : text_(text) {}

    // Decodes the next n bytes into out. False when the text ends (or reaches a character that
    // is not base64, such as the '<' of a closing tag) first, or a quantum is malformed; then
    // failure() says which.
    bool read(uint8_t* out, std::size_t n);

    // An upper bound on the bytes still to come, to check a declared size before allocating.
    std::size_t max_remaining() const { return (pending_end_ - pending_pos_) + (text_.size() - pos_) / 4 * 3; }

    const char* failure() const { return failure_; }
    // True when read() failed on a malformed quantum rather than at the end of the text.
    bool malformed() const { return malformed_; }

private:
    bool decode_quantum();

    std::string_view text_;
    std::size_t pos_ = 0;
    uint8_t pending_[3] = {};
    int pending_pos_ = 0, pending_end_ = 0;
    const char* failure_ = "";
    bool malformed_ = false;
};

}  // namespace amc
