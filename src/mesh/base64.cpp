// Base64Reader: one 4-character quantum at a time through a 256-entry table.
#include "mesh/base64.h"

#include <array>

namespace amc {
namespace {

constexpr uint8_t kInvalid = 0xff, kSpace = 0xfe, kPad = 0xfd;

constexpr std::array<uint8_t, 256> make_table() {
    std::array<uint8_t, 256> table{};
    for (auto& t : table) t = kInvalid;
    const char* alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    for (uint8_t i = 0; i < 64; ++i) table[static_cast<uint8_t>(alphabet[i])] = i;
    table[' '] = table['\t'] = table['\n'] = table['\r'] = kSpace;
    table['='] = kPad;
    return table;
}

constexpr std::array<uint8_t, 256> kTable = make_table();

}  // namespace

bool Base64Reader::decode_quantum() {
    uint8_t digits[4];
    int count = 0;
    while (count < 4) {
        if (pos_ >= text_.size()) {
            failure_ = "ends early (truncated?)";
            return false;
        }
        const uint8_t d = kTable[static_cast<uint8_t>(text_[pos_])];
        if (d == kSpace) {
            ++pos_;
            continue;
        }
        if (d == kInvalid) {
            // At a quantum's start, '<' is the closing tag: the text ended.
            malformed_ = count > 0 || text_[pos_] != '<';
            failure_ = malformed_ ? "holds a character that is not base64" : "ends early (truncated?)";
            return false;
        }
        digits[count++] = d;
        ++pos_;
    }
    // "xx==" gives one byte, "xxx=" two; padding anywhere else is malformed.
    int bytes = 3;
    if (digits[3] == kPad) bytes = digits[2] == kPad ? 1 : 2;
    if (digits[0] == kPad || digits[1] == kPad || (digits[2] == kPad && digits[3] != kPad)) {
        failure_ = "holds misplaced base64 padding";
        malformed_ = true;
        return false;
    }
    const uint32_t word = (uint32_t(digits[0]) << 18) | (uint32_t(digits[1]) << 12) |
                          (uint32_t(bytes > 1 ? digits[2] : 0) << 6) | uint32_t(bytes > 2 ? digits[3] : 0);
    pending_[0] = static_cast<uint8_t>(word >> 16);
    pending_[1] = static_cast<uint8_t>(word >> 8);
    pending_[2] = static_cast<uint8_t>(word);
    pending_pos_ = 0;
    pending_end_ = bytes;
    return true;
}

bool Base64Reader::read(uint8_t* out, std::size_t n) {
    while (n > 0) {
        if (pending_pos_ == pending_end_ && !decode_quantum()) return false;
        while (n > 0 && pending_pos_ < pending_end_) {
            *out++ = pending_[pending_pos_++];
            --n;
        }
    }
    return true;
}

}  // namespace amc
