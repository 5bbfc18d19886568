// The fields every mode of the base connectivity stream is built from (FORMAT.md 4.1, 4.6): counts,
// bounded indices and split offsets in one arithmetic-coded payload, and the decoder's error.
#pragma once

#include "coding/entropy/arithmetic_coder.h"

#include <amc/mesh.h>

#include <cstdint>
#include <string>

namespace amc {

// Counts are Elias-gamma codes of x + 1 in at most 32 bits.
constexpr uint32_t kMaxBaseCount = 0x7FFFFFFFu;

// Thrown by an encoder of one mode when the mesh does not fit it; the caller falls back to the
// next mode (base_mesh_coder.cpp). Never reaches a user.
struct EncoderGaveUp {};

// Throws amc::Error(code, "base mesh stream: <what>").
[[noreturn]] void fail_base_stream(const std::string& what, ErrorCode code = ErrorCode::corrupt);
// The message for a stream announcing `isolated` isolated vertices where the caller allows `max`.
std::string isolated_refused(uint64_t isolated, uint32_t max, const char* qualifier = "");

// count: Elias gamma of x + 1, raw bits (x <= kMaxBaseCount, else EncoderGaveUp).
void put_count(ArithmeticEncoder& enc, uint32_t x);
uint32_t get_count(ArithmeticDecoder& dec);

// index(range): a value in [0, range) as bit_length(range - 1) raw bits.
void put_index(ArithmeticEncoder& enc, uint32_t value, uint32_t range);
uint32_t get_index(ArithmeticDecoder& dec, uint32_t range, const char* what);

// split(range): an offset d in [0, range), near end first (FORMAT.md 4.6).
struct SplitOffsetModels {
    BitModel side;        // counted from the start (1) or from the end (0)
    BitModel length[33];  // unary bit length of the distance + 1
};
void put_split_offset(ArithmeticEncoder& enc, SplitOffsetModels& m, uint32_t d, uint32_t range);
uint32_t get_split_offset(ArithmeticDecoder& dec, SplitOffsetModels& m, uint32_t range);

}  // namespace amc
