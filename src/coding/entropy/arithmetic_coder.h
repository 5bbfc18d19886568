// Adaptive binary arithmetic coding: the entropy back end of the hierarchy coder (paper II-D,
// "context groups": every context group owns one BitModel, all groups share one coder).
//
// The coder is an LZMA-style range coder: 32-bit range, 64-bit `low` holding one carry bit,
// carry propagation through a cached byte and a run of pending 0xFF bytes. Symbols are coded
// with a 16-bit probability; the split point is computed with a 64-bit product so the only
// approximation is the 16-bit quantisation of the model's probability.
//
// Bitstream (frozen; any change must also change the golden test):
//  * Bytes are the big-endian digits of a number in [low, low + range) of the final interval,
//    with LZMA's always-zero leading byte omitted.
//  * The decoder treats bytes past the end of the buffer as 0, so finish() picks the number in
//    the final interval with the most trailing zero bytes and drops up to
//    kMaxImplicitZeroBytes trailing zero bytes. A stream of zero symbols is zero bytes long.
//  * A modelled bit: bound = (range * p16) >> 16 where p16 = BitModel::p16() is the probability
//    of a one; a one takes [low, low + bound), a zero takes [low + bound, low + range).
//  * A raw bit (equiprobable): range >>= 1; a one takes the upper half. Raw values are coded
//    most significant bit first.
//  * Normalisation: while range < 2^24, shift one byte out (range <<= 8).
//
// Terms used by the tests and by the callers' statistics:
//  * Ideal adaptive code length (the "empirical adaptive code length") of a symbol sequence:
//        sum over coded symbols s_i of -log2 P_i(s_i),
//    where P_i is the probability the model assigned to s_i just before coding it — exactly the
//    16-bit probability the coder used (BitModel::cost_bits), plus 1 bit per raw bit. It is the
//    code length an ideal arithmetic coder would reach with the model's own predictions. The
//    coder's output exceeds it only by the rounding of the split point (< 2^-20 bits per symbol)
//    and the final flush (at most 4 bytes, usually 1-2); measured: < 0.01% + 2 bytes.
//  * Static empirical entropy of one context: n * H(n1 / n) for n symbols of which n1 are ones
//    (binary_entropy_bits). It is what a two-pass coder with a per-context probability, stored
//    for free, would reach; the adaptive KT model stays within O(log n) bits of it during the
//    first `limit` symbols and within ~1/(4 ln2 * limit) bits per symbol afterwards.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace amc {

// Probability precision of the coder: probabilities are multiples of 2^-16 in [2^-16, 1-2^-16].
constexpr int kProbBits = 16;
constexpr uint32_t kProbOne = uint32_t{1} << kProbBits;

// Bytes past the end of the buffer that a valid stream may make the decoder read (the trailing
// zero bytes dropped by finish()).
constexpr size_t kMaxImplicitZeroBytes = 4;

// Adaptive probability of a one for one context.
//
// Estimator: Krichevsky–Trofimov, p1 = (n1 + 1/2) / (n + 1), kept in the recursive form
// p <- p + (bit - p) / (n + 2), where n counts the symbols seen before this one. Once n + 2
// reaches the limit 2^limit_log2 the rate stays at 2^-limit_log2: an exponential window of
// about `limit` symbols, which plays the role of count halving (old statistics fade, so slowly
// varying sources are tracked) without a division. The probability is kept with 32 bits so that
// slow rates still move it; the coder sees its top 16 bits, clamped away from 0 and 1.
struct BitModel {
    static constexpr int kDefaultLimitLog2 = 12;  // window of 4096 symbols
    static constexpr int kMinLimitLog2 = 1;
    static constexpr int kMaxLimitLog2 = 16;

    uint32_t p = uint32_t{1} << 31;  // probability of a one, in units of 2^-32; never 0
    uint16_t n = 0;                  // symbols seen, saturates at limit - 2
    uint8_t limit_log2 = kDefaultLimitLog2;

    BitModel() = default;
    // limit_log2 is clamped to [kMinLimitLog2, kMaxLimitLog2].
    explicit BitModel(int limit_log2_)
        : limit_log2(static_cast<uint8_t>(limit_log2_ < kMinLimitLog2   ? kMinLimitLog2
                                          : limit_log2_ > kMaxLimitLog2 ? kMaxLimitLog2
                                                                        : limit_log2_)) {}

    // The coder's probability of a one, in units of 2^-16, in [1, 2^16 - 1].
    uint32_t p16() const {
        const uint32_t q = p >> (32 - kProbBits);
        return q == 0 ? 1 : q;  // p < 2^32 so q <= 2^16 - 1 already
    }

    void update(bool bit) { update_with_limit(bit, limit_log2); }

    // update() for a model whose limit_log2 is `limit`: with a constant limit (the hierarchy
    // coder's models all have the default) the window is folded into the code.
    void update_with_limit(bool bit, int limit) {
        if (static_cast<uint32_t>(n) + 2 < (uint32_t{1} << limit)) {
            const uint32_t d = static_cast<uint32_t>(n) + 2;  // KT ramp-up: rate 1/(n+2)
            if (bit) p += ~p / d;
            else p -= p / d;
            ++n;
        } else {
            if (bit) p += ~p >> limit;
            else p -= p >> limit;
        }
    }

    // -log2 of the probability the coder would use for `bit` now (its ideal code length).
    double cost_bits(bool bit) const;
};

// n * H(ones / n) in bits, with H the binary entropy; 0 for n == 0.
double binary_entropy_bits(uint64_t ones, uint64_t n);

// At most how many symbols, modelled or raw, an ArithmeticDecoder can read from a payload of
// `payload_bytes` bytes without overrunning it: decoders check every count a stream announces
// against this before they allocate for it. Each symbol narrows the range by more than 2^-16
// bits (a modelled bit keeps at most 1 - 2^-16 + 2^-24 of it, p16 being at most 2^16 - 1 and the
// range at least 2^24; a raw bit halves it), while the decoder can take in at most
// 8 * (payload_bytes + 1) bits of range before overran() turns true (docs/FORMAT.md, 3.7).
constexpr uint64_t max_decodable_symbols(uint64_t payload_bytes) { return (payload_bytes + 1) << 19; }

class ArithmeticEncoder {
public:
    ArithmeticEncoder() = default;

    void encode(bool bit, BitModel& model) { encode_with_limit(bit, model, model.limit_log2); }

    // encode() for a model whose limit_log2 is kLimitLog2 (see BitModel::update_with_limit).
    template <int kLimitLog2>
    void encode_with_limit(bool bit, BitModel& model) {
        encode_with_limit(bit, model, kLimitLog2);
    }

    // A bit with probability p16 (in [1, 2^16 - 1], units of 2^-16) of a one, from a model of the
    // caller's own (the hierarchy coder's mixing mode).
    void encode_with_probability(bool bit, uint32_t p16) {
        const uint32_t bound = static_cast<uint32_t>((uint64_t{range_} * p16) >> kProbBits);
        if (bit) {
            range_ = bound;
        } else {
            low_ += bound;
            range_ -= bound;
        }
        while (range_ < kTop) {
            range_ <<= 8;
            shift_low();
        }
    }

    // The low `count` bits of `value`, most significant first, each with probability 1/2.
    // count in [0, 32]; throws amc::Error otherwise.
    void encode_bits_raw(uint32_t value, int count);

    // Flushes the final interval with as few bytes as possible and returns the stream. The
    // encoder is reset to its initial state and can be reused.
    std::vector<uint8_t> finish();

    // Bytes committed so far (written or held back for carry propagation); the finished stream
    // has between bytes_so_far() and bytes_so_far() + 4 bytes.
    size_t bytes_so_far() const {
        return out_.size() + cache_size_ - (first_byte_pending_ ? 1 : 0);
    }

private:
    static constexpr uint32_t kTop = uint32_t{1} << 24;

    void encode_with_limit(bool bit, BitModel& model, int limit_log2) {
        const uint32_t bound =
            static_cast<uint32_t>((uint64_t{range_} * model.p16()) >> kProbBits);
        if (bit) {
            range_ = bound;
        } else {
            low_ += bound;
            range_ -= bound;
        }
        model.update_with_limit(bit, limit_log2);
        while (range_ < kTop) {
            range_ <<= 8;
            shift_low();
        }
    }

    // Moves the top byte of the 32-bit low out; resolves carries into the held-back bytes.
    void shift_low() {
        if (static_cast<uint32_t>(low_) < 0xFF000000u || (low_ >> 32) != 0) {
            flush_cache();
        }
        ++cache_size_;
        low_ = (low_ & 0x00FFFFFFu) << 8;
    }
    void flush_cache();

    uint64_t low_ = 0;  // bits 0..31 the interval start, bit 32 a pending carry
    uint32_t range_ = 0xFFFFFFFFu;
    uint8_t cache_ = 0;      // last byte not yet written (may still receive a carry)
    size_t cache_size_ = 1;  // cache_ plus this many - 1 bytes of 0xFF are held back
    bool first_byte_pending_ = true;  // LZMA's leading byte is always 0 and is not written
    std::vector<uint8_t> out_;
};

// Two arithmetic codes of the same symbols, each from its own state, the models read and updated
// once: an adaptive geometry trial sized from a fresh code while it also codes the level's own
// (which holds its hierarchy part), so that a winning trial need not be coded again.
class ArithmeticEncoderPair {
public:
    ArithmeticEncoderPair(ArithmeticEncoder& first, ArithmeticEncoder& second) : first_(first), second_(second) {}

    template <int kLimitLog2>
    void encode_with_limit(bool bit, BitModel& model) {
        const uint32_t p16 = model.p16();
        first_.encode_with_probability(bit, p16);
        second_.encode_with_probability(bit, p16);
        model.update_with_limit(bit, kLimitLog2);
    }
    void encode_bits_raw(uint32_t value, int count) {
        first_.encode_bits_raw(value, count);
        second_.encode_bits_raw(value, count);
    }

private:
    ArithmeticEncoder& first_;
    ArithmeticEncoder& second_;
};

class ArithmeticDecoder {
public:
    // Reads at most `size` bytes from `data`; never past it. `data` must outlive the decoder.
    ArithmeticDecoder(const uint8_t* data, size_t size);

    bool decode(BitModel& model) { return decode_with_limit(model, model.limit_log2); }

    // decode() for a model whose limit_log2 is kLimitLog2 (see BitModel::update_with_limit).
    template <int kLimitLog2>
    bool decode_with_limit(BitModel& model) {
        return decode_with_limit(model, kLimitLog2);
    }

    // The mirror of ArithmeticEncoder::encode_with_probability.
    bool decode_with_probability(uint32_t p16) {
        const uint32_t bound = static_cast<uint32_t>((uint64_t{range_} * p16) >> kProbBits);
        const bool bit = code_ < bound;
        if (bit) {
            range_ = bound;
        } else {
            code_ -= bound;
            range_ -= bound;
        }
        while (range_ < kTop) {
            range_ <<= 8;
            code_ = (code_ << 8) | next_byte();
        }
        return bit;
    }

    // count in [0, 32]; throws amc::Error otherwise.
    uint32_t decode_bits_raw(int count);

    // True once the decoder needed more than kMaxImplicitZeroBytes bytes past the end of the
    // buffer: the stream was truncated (or the caller decoded more symbols than were coded).
    // Check it after decoding; a corrupted stream may still decode to wrong symbols without it.
    bool overran() const { return past_end_ > kMaxImplicitZeroBytes; }

private:
    static constexpr uint32_t kTop = uint32_t{1} << 24;

    bool decode_with_limit(BitModel& model, int limit_log2) {
        const uint32_t bound =
            static_cast<uint32_t>((uint64_t{range_} * model.p16()) >> kProbBits);
        const bool bit = code_ < bound;
        if (bit) {
            range_ = bound;
        } else {
            code_ -= bound;
            range_ -= bound;
        }
        model.update_with_limit(bit, limit_log2);
        while (range_ < kTop) {
            range_ <<= 8;
            code_ = (code_ << 8) | next_byte();
        }
        return bit;
    }

    uint32_t next_byte() {
        if (pos_ < size_) return data_[pos_++];
        ++past_end_;
        return 0;
    }

    const uint8_t* data_;
    size_t size_;
    size_t pos_ = 0;
    size_t past_end_ = 0;
    uint32_t range_ = 0xFFFFFFFFu;
    uint32_t code_ = 0;
};

}  // namespace amc
