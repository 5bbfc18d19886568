// Fields of the base connectivity stream; see base_mesh_stream.h and FORMAT.md 4.1, 4.6.
#include "coding/base/base_mesh_stream.h"

#include "common/bits.h"
#include "common/check.h"

#include <amc/mesh.h>

namespace amc {

void fail_base_stream(const std::string& what, ErrorCode code) { throw_error(code, "base mesh stream: " + what); }

std::string isolated_refused(uint64_t isolated, uint32_t max, const char* qualifier) {
    return std::string(qualifier) + std::to_string(isolated) + (isolated == 1 ? " isolated vertex" : " isolated vertices") +
           " (used by no triangle), " +
           (max == 0 ? std::string("where the base mesh must use every vertex") : "more than " + std::to_string(max));
}

void put_count(ArithmeticEncoder& enc, uint32_t x) {
    if (x > kMaxBaseCount) throw EncoderGaveUp{};
    const uint32_t y = x + 1;
    const int n = bit_length(y);
    enc.encode_bits_raw(0, n - 1);
    enc.encode_bits_raw(y, n);
}

uint32_t get_count(ArithmeticDecoder& dec) {
    int zeros = 0;
    while (dec.decode_bits_raw(1) == 0) {
        if (++zeros > 31) fail_base_stream("bad count");
    }
    const uint32_t y = (uint32_t{1} << zeros) | dec.decode_bits_raw(zeros);
    return y - 1;
}

void put_index(ArithmeticEncoder& enc, uint32_t value, uint32_t range) {
    if (value >= range) throw EncoderGaveUp{};
    enc.encode_bits_raw(value, bit_length(range - 1));
}

uint32_t get_index(ArithmeticDecoder& dec, uint32_t range, const char* what) {
    if (range == 0) fail_base_stream(std::string("empty range for ") + what);
    const uint32_t value = dec.decode_bits_raw(bit_length(range - 1));
    if (value >= range) fail_base_stream(std::string(what) + " out of range");
    return value;
}

// The side it is nearer to (adaptive), then the distance from that side as an Elias-gamma code
// with an adaptive unary bit length and raw mantissa bits.
void put_split_offset(ArithmeticEncoder& enc, SplitOffsetModels& m, uint32_t d, uint32_t range) {
    if (d >= range) throw EncoderGaveUp{};
    const bool from_start = d <= range - 1 - d;
    enc.encode(from_start, m.side);
    const uint32_t y = (from_start ? d : range - 1 - d) + 1;
    const int n = bit_length(y) - 1;
    for (int i = 0; i < n; ++i) enc.encode(true, m.length[i]);
    if (n < bit_length(range)) enc.encode(false, m.length[n]);
    enc.encode_bits_raw(y, n);
}

uint32_t get_split_offset(ArithmeticDecoder& dec, SplitOffsetModels& m, uint32_t range) {
    const bool from_start = dec.decode(m.side);
    int n = 0;
    const int max_n = bit_length(range);
    while (n < max_n && dec.decode(m.length[n])) ++n;
    if (n >= max_n) fail_base_stream("split offset out of range");
    const uint64_t y = (uint64_t{1} << n) | dec.decode_bits_raw(n);
    if (y > range) fail_base_stream("split offset out of range");
    const uint32_t dist = static_cast<uint32_t>(y - 1);
    return from_start ? dist : range - 1 - dist;
}

}  // namespace amc
