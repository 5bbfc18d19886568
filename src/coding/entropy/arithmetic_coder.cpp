// LZMA-style binary range coder; see arithmetic_coder.h for the bitstream and the model.
#include "coding/entropy/arithmetic_coder.h"

#include "common/bits.h"
#include "common/exact_float.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "amc/mesh.h"

namespace amc {

double BitModel::cost_bits(bool bit) const {
    const uint32_t q = p16();
    return -std::log2(static_cast<double>(bit ? q : kProbOne - q) / kProbOne);
}

double binary_entropy_bits(uint64_t ones, uint64_t n) {
    if (ones == 0 || ones >= n) return 0.0;
    const double dn = static_cast<double>(n);
    const double d1 = static_cast<double>(ones);
    const double d0 = dn - d1;
    return rounded(d1 * std::log2(dn / d1)) + rounded(d0 * std::log2(dn / d0));  // unfused: encoders decide by it
}

static void check_raw_count(int count, const char* where) {
    if (count < 0 || count > 32) {
        throw Error(std::string(where) + ": raw bit count " + std::to_string(count) +
                    " outside [0, 32]");
    }
}

void ArithmeticEncoder::flush_cache() {
    const uint8_t carry = static_cast<uint8_t>(low_ >> 32);
    uint8_t byte = cache_;
    do {
        if (first_byte_pending_) {
            first_byte_pending_ = false;  // always 0: the interval never leaves [0, 2^32)
        } else {
            out_.push_back(static_cast<uint8_t>(byte + carry));
        }
        byte = 0xFF;
    } while (--cache_size_ != 0);
    cache_ = static_cast<uint8_t>(low_ >> 24);
}

void ArithmeticEncoder::encode_bits_raw(uint32_t value, int count) {
    check_raw_count(count, "ArithmeticEncoder::encode_bits_raw");
    // The interval in locals between the byte shifts (about every 8 bits), so that it stays in
    // registers.
    uint64_t low = low_;
    uint32_t range = range_;
    for (int i = count - 1; i >= 0; --i) {
        range >>= 1;
        // Raw bits are noise (low mantissa bits): a branch on them would mispredict half the time.
        low += range & (0u - ((value >> i) & 1u));
        if (range < kTop) {
            low_ = low;
            range_ = range;
            do {
                range_ <<= 8;
                shift_low();
            } while (range_ < kTop);
            low = low_;
            range = range_;
        }
    }
    low_ = low;
    range_ = range;
}

std::vector<uint8_t> ArithmeticEncoder::finish() {
    // Any number in [low, low + range) decodes to the same symbols. Take the one with the most
    // trailing zero bytes: those need not be written, the decoder reads missing bytes as 0.
    const uint64_t end = low_ + range_;
    for (int zero_bytes = 4; zero_bytes >= 0; --zero_bytes) {
        const uint64_t mask = (uint64_t{1} << (8 * zero_bytes)) - 1;
        const uint64_t value = (low_ + mask) & ~mask;
        if (value < end) {
            low_ = value;  // may set the carry bit (value == 2^32); shift_low resolves it
            break;
        }
    }
    for (int i = 0; i < 5; ++i) shift_low();
    std::vector<uint8_t> out = std::move(out_);
    for (size_t dropped = 0; dropped < kMaxImplicitZeroBytes && !out.empty() && out.back() == 0;
         ++dropped) {
        out.pop_back();
    }
    *this = ArithmeticEncoder();
    return out;
}

ArithmeticDecoder::ArithmeticDecoder(const uint8_t* data, size_t size)
    : data_(data), size_(data == nullptr ? 0 : size) {
    for (int i = 0; i < 4; ++i) code_ = (code_ << 8) | next_byte();
}

uint32_t ArithmeticDecoder::decode_bits_raw(int count) {
    check_raw_count(count, "ArithmeticDecoder::decode_bits_raw");
    uint32_t value = 0;
    uint32_t range = range_, code = code_;  // in registers, as in the encoder
    for (int left = count; left > 0;) {
        // A range of bit_length B >= 25 halves B - 25 times and stays at kTop or above; the next
        // halving takes it below. So that many bits and one more go without the test, then the
        // byte shifts: the same steps as a test after every bit.
        const int run = std::min(left, bit_length(range) - 24);  // 1..8
        // One bit without a branch (raw bits are noise): a compare, a conditional move and an
        // add. The run's bits enter the unrolled steps at their count: no test per bit.
        auto bit = [&range, &code, &value] {
            range >>= 1;
            const uint32_t rest = code - range;
            const bool one = code >= range;
            code = one ? rest : code;
            value = value + value + uint32_t(one);
        };
        switch (run) {
            case 8: bit(); [[fallthrough]];
            case 7: bit(); [[fallthrough]];
            case 6: bit(); [[fallthrough]];
            case 5: bit(); [[fallthrough]];
            case 4: bit(); [[fallthrough]];
            case 3: bit(); [[fallthrough]];
            case 2: bit(); [[fallthrough]];
            default: bit();
        }
        left -= run;
        while (range < kTop) {
            range <<= 8;
            code = (code << 8) | next_byte();
        }
    }
    range_ = range;
    code_ = code;
    return value;
}

}  // namespace amc
