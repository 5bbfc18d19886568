// Static-table entropy coding built for decode throughput: interleaved rANS over symbols of
// alphabets up to kRansMaxSymbols with frequency tables the stream carries, and a raw bit stream
// for bits not worth modelling (the noise bits of bit-exact coordinates). Used by the geometry
// coder's static mode (docs/FORMAT.md 5.6).
//
// rANS (J. Duda, "Asymmetric numeral systems", 2013) in the byte-wise form of F. Giesen's ryg_rans:
// 32-bit state x in [L, 256 L), L = 2^23, probabilities as frequencies f summing to
// M = 2^kRansScaleBits. Decoding a symbol: slot = x mod M, s = the symbol whose range
// [start_s, start_s + f_s) holds slot, x = f_s * (x / M) + slot - start_s, then while x < L:
// x = 256 x + next byte. Two states take the symbols in turn (symbol i with state i mod 2), so a
// decoder's consecutive steps do not wait on each other. The encoder works backwards.
//
// Stream (frozen; docs/FORMAT.md 5.6): the decoder's initial state 0, then state 1, each 4 bytes
// little endian, then the renormalisation bytes in the order the decoder reads them. An empty
// symbol sequence is the 8 bytes of two states equal to L. After the last symbol both states are
// L again (the encoder's initial states): a decoder checks it.
//
// Raw bits: packed least significant bit first into bytes, a value of c bits (c <= 57) at a time,
// its low bit first.
#pragma once

#include "common/huge_pages.h"
#include "common/simd.h"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <vector>

namespace amc {

constexpr int kRansScaleBits = 12;
constexpr uint32_t kRansScale = uint32_t{1} << kRansScaleBits;
constexpr uint32_t kRansLow = uint32_t{1} << 23;  // L: the lower bound of the normalised state
constexpr int kRansMaxSymbols = 512;
constexpr size_t kRansStateBytes = 8;  // two states of 4 bytes
// No symbol may have the whole scale (at most M - 1): every coded symbol costs at least
// -log2((M - 1) / M) bits of the encoder's output.
constexpr uint32_t kRansMaxFrequency = kRansScale - 1;

// A static frequency table: symbols 0 .. size()-1, frequencies summing to kRansScale, none above
// kRansMaxFrequency (zero for symbols that never occur).
class RansTable {
public:
    RansTable() = default;
    // Scales counts (any, at least one nonzero; at most kRansMaxSymbols of them, at most
    // kRansScale - 1 nonzero) to frequencies: every symbol with a nonzero count gets at least 1,
    // the rest in proportion. Throws Error otherwise.
    static RansTable from_counts(const std::vector<uint64_t>& counts);
    // from_counts' frequencies for a RansEncoder only: without the decoder's slot index
    // (entry_of_slot; 4096 slots filled per table), which an encoder weighing modes never reads.
    static RansTable for_encoding(const std::vector<uint64_t>& counts);
    // Takes frequencies as they are; returns false (table unchanged) unless they sum to
    // kRansScale, none exceeds kRansMaxFrequency, and there are at most kRansMaxSymbols.
    bool assign(const std::vector<uint32_t>& frequencies);

    int size() const { return int(frequency_.size()); }
    uint32_t frequency(int symbol) const { return frequency_[size_t(symbol)]; }
    uint32_t start(int symbol) const { return start_[size_t(symbol)]; }
    const std::vector<uint32_t>& frequencies() const { return frequency_; }
    // The encoder's step for one symbol without a division (F. Giesen's ryg_rans after Alverson,
    // "Integer division using reciprocals"): x -> (x / f) M + x mod f + start as x + bias + q (M - f),
    // q = x / f from a 32-bit reciprocal, exact for every x below 2^31 (the encoder's x < x_max).
    struct Coding {
        uint32_t x_max = 0, reciprocal = 0, bias = 0, complement = 0, shift = 0;
        uint32_t code(uint32_t x) const {
            const uint32_t q = uint32_t((uint64_t(x) * reciprocal) >> shift);
            return x + bias + q * complement;
        }
    };
    static Coding coding_of(uint32_t start, uint32_t frequency);
    const Coding& coding(int symbol) const { return coding_[size_t(symbol)]; }
    // Every symbol's Coding, by symbol.
    const Coding* codings() const { return coding_.data(); }
    // -log2 of the symbol's probability (its code length in bits); the symbol must have a frequency.
    double cost_bits(int symbol) const;

    // The decoder's view: the symbols of nonzero frequency in increasing order, and per slot of
    // [0, M) the index of the one whose range holds it, in a byte where a table has at most 256 such
    // symbols (every quantized residual's table), else in two: a level's six tables of bytes (24 KB)
    // stay in the processor's first-level cache, where six-byte slots (144 KB) did not.
    struct Entry {
        uint16_t symbol, frequency, start;
    };
    const Entry& entry_of_slot(uint32_t slot) const {
        return entries_[narrow_ ? size_t(narrow_index_[slot]) : size_t(wide_index_[slot])];
    }
    // The decoder's view of a table made by assign() whose slots index in a byte: a decoder whose
    // tables are all narrow (every quantized and float32 residual's) reads each symbol's entry
    // without the width's test and the table's two vectors. Null pointers for a wide table.
    struct NarrowView {
        const uint8_t* index = nullptr;
        const Entry* entries = nullptr;
    };
    NarrowView narrow_view() const {
        return narrow_ && !narrow_index_.empty() ? NarrowView{narrow_index_.data(), entries_.data()} : NarrowView{};
    }

private:
    void set_starts();
    void build_slots();
    std::vector<uint32_t> frequency_, start_;
    std::vector<Coding> coding_;
    std::vector<Entry> entries_;
    bool narrow_ = true;
    std::vector<uint8_t> narrow_index_;
    std::vector<uint16_t> wide_index_;
};

class RansEncoder {
public:
    // Queues one symbol (it must have a nonzero frequency in `table`, which must outlive finish()).
    void put(const RansTable& table, int symbol) { queue_.push_back(&table.coding(symbol)); }
    size_t symbols() const { return queue_.size(); }
    void reserve(size_t symbols) { queue_.reserve(symbols); }
    // Codes the queued symbols; the encoder is empty again afterwards.
    std::vector<uint8_t> finish();

private:
    std::vector<const RansTable::Coding*> queue_;
};

// RansEncoder's stream for a caller that can give its `count` symbols last to first (rANS codes
// backwards): each is coded as it comes, with no queue (8 bytes a symbol, written and read again).
class RansBackwardEncoder {
public:
    explicit RansBackwardEncoder(size_t count);
    // The same in `memory`, kept by the caller from one encoder to the next.
    RansBackwardEncoder(size_t count, ScratchArray<uint8_t>& memory);
    // The symbol before the one put last (the first call: the last symbol), of nonzero frequency.
    void put(const RansTable& table, int symbol) { put_coding(table.coding(symbol)); }
    void put_coding(const RansTable::Coding& c) {
        if (left_ == 0) throw_too_many();  // the buffer holds `count` symbols' bytes
        uint32_t& x = state_[--left_ & 1];  // symbol i of the stream takes state i mod 2
        while (x >= c.x_max) {
            *--begin_ = uint8_t(x);
            x >>= 8;
        }
        x = c.code(x);
    }
    // put_coding for `count` symbols at once, the last first: coding_of(j) for j = count - 1 down
    // to 0. Both states and the output stay in registers (put_coding's live in the object, where
    // each byte written may alias them).
    template <class CodingOf>
    void put_all(size_t count, CodingOf&& coding_of) {
        if (count > left_) throw_too_many();
        const size_t first = left_ - count;  // the stream index of coding_of(0)
        uint32_t x0 = state_[0], x1 = state_[1];
        uint8_t* out = begin_;
        // Without a branch on the bytes a symbol renormalises (0, 1 or 2, by turns on
        // bit-exact residuals): both written below `out`, where the buffer has room for two a
        // symbol, and `out` moved over those that count; the others are written over later.
        auto step = [&out](uint32_t& x, const RansTable::Coding& c) {
            const uint32_t bytes = uint32_t(x >= c.x_max) + uint32_t((x >> 8) >= c.x_max);
            out[-1] = uint8_t(x);
            out[-2] = uint8_t(x >> 8);
            out -= bytes;
            x >>= 8 * bytes;
            x = c.code(x);
        };
        size_t j = count;  // symbol j takes state (first + j) mod 2
        if (j > 0 && (first + j - 1) % 2 == 0) step(x0, coding_of(--j));
        for (; j >= 2; j -= 2) {
            step(x1, coding_of(j - 1));
            step(x0, coding_of(j - 2));
        }
        if (j == 1) step(x1, coding_of(0));
        state_[0] = x0;
        state_[1] = x1;
        begin_ = out;
        left_ = first;
    }
    // The stream (once); throws Error unless exactly `count` symbols were put.
    std::vector<uint8_t> finish();
    // The same into `out` (its capacity kept).
    void finish(std::vector<uint8_t>& out);

private:
    [[noreturn]] static void throw_too_many();
    // The buffer's size for `count` symbols.
    static size_t buffer_bytes(size_t count) { return 2 * count + kRansStateBytes; }
    // At most two bytes a symbol (x < 2^31 before, x_max >= 2^19) and the states, written from the
    // end down; not zeroed, so the pages the code never reaches are never touched. Owned, or the
    // caller's memory.
    std::unique_ptr<uint8_t[]> buffer_;
    uint8_t* end_;
    uint8_t* begin_;  // the first byte written so far
    size_t left_;     // symbols still to be put
    uint32_t state_[2] = {kRansLow, kRansLow};
};

class RansDecoder {
public:
    // Reads at most `size` bytes; fewer than kRansStateBytes is an overrun at once.
    RansDecoder(const uint8_t* data, size_t size) : data_(data), size_(size) {
        for (uint32_t& x : state_) {
            x = 0;
            for (int shift = 0; shift < 32; shift += 8) x |= next_byte() << shift;
            if (x < kRansLow) {  // no encoder ends below L; from there a run of zero bytes would never renormalise
                overran_ = true;
                x = kRansLow;
            }
        }
    }

    // The next symbol (symbol i of the stream with state i mod 2).
    int get(const RansTable& table) {
        which_ ^= 1;
        return which_ == 1 ? get_with<0>(table) : get_with<1>(table);
    }
    // The next symbol when the caller knows it is coded with state `State` (symbol i: i mod 2). A
    // loop that names the state keeps both in registers; a decoder uses get() or get_with only.
    template <int State>
    int get_with(const RansTable& table) {
        uint32_t& x = state_[State];
        const uint32_t slot = x & (kRansScale - 1);
        const RansTable::Entry& e = table.entry_of_slot(slot);
        x = uint32_t(e.frequency) * (x >> kRansScaleBits) + slot - e.start;
        while (x < kRansLow) x = (x << 8) | next_byte();
        return e.symbol;
    }

    // get_with for a narrow table's view (RansTable::narrow_view).
    template <int State>
    int get_with(const RansTable::NarrowView& table) {
        uint32_t& x = state_[State];
        const uint32_t slot = x & (kRansScale - 1);
        const RansTable::Entry& e = table.entries[table.index[slot]];
        x = uint32_t(e.frequency) * (x >> kRansScaleBits) + slot - e.start;
        while (x < kRansLow) x = (x << 8) | next_byte();
        return e.symbol;
    }

    // True once the decoder needed bytes past the end: the stream is truncated or corrupt.
    bool overran() const { return overran_; }
    // After the last symbol: both states are back at L and every byte was read.
    bool ended_cleanly() const { return !overran_ && state_[0] == kRansLow && state_[1] == kRansLow && pos_ == size_; }

private:
    uint32_t next_byte() {
        if (pos_ < size_) return data_[pos_++];
        overran_ = true;
        return 0;
    }
    const uint8_t* data_;
    size_t size_, pos_ = 0;
    uint32_t state_[2] = {kRansLow, kRansLow};
    int which_ = 0;
    bool overran_ = false;
};

class RawBitWriter {
public:
    // The low `count` bits of value, count in [0, 57].
    void put(uint64_t value, int count) {
        buffer_ |= (count == 0 ? 0 : value & (~uint64_t{0} >> (64 - count))) << filled_;
        filled_ += count;
        if (filled_ >= 8) flush_whole_bytes();
    }
    // Room for `bits` more bits without growing on the way.
    void reserve_bits(uint64_t bits) { bytes_.reserve(used_ + size_t(bits / 8) + 8); }
    size_t bits() const { return used_ * 8 + size_t(filled_); }
    // Pads the last byte with zero bits and returns the bytes; the writer is empty again.
    std::vector<uint8_t> finish();
    // Writes into `memory` from now on (emptied, its capacity kept): a buffer kept from an earlier
    // writer's finish(). Only while the writer is empty.
    void adopt(std::vector<uint8_t>&& memory) {
        bytes_ = std::move(memory);
        bytes_.clear();
    }

private:
    // The buffer's whole bytes (1..8) out at once: a byte at a time was a push_back each.
    void flush_whole_bytes() {
        const int whole = filled_ >> 3;
        if (bytes_.size() < used_ + 8) bytes_.resize(std::max(bytes_.capacity(), used_ + 8));
#if AMC_LITTLE_ENDIAN
        std::memcpy(bytes_.data() + used_, &buffer_, 8);  // the bytes past `whole` are written again later
#else
        for (int i = 0; i < whole; ++i) bytes_[used_ + size_t(i)] = uint8_t(buffer_ >> (8 * i));
#endif
        used_ += size_t(whole);
        buffer_ = whole == 8 ? 0 : buffer_ >> (8 * whole);
        filled_ -= 8 * whole;
    }

    std::vector<uint8_t> bytes_;  // the first used_ are written
    size_t used_ = 0;
    uint64_t buffer_ = 0;
    int filled_ = 0;
};

class RawBitReader {
public:
    RawBitReader(const uint8_t* data, size_t size) : data_(data), size_(size) {}
    // count in [0, 57]; bits past the end read as 0 and set overran().
    uint64_t get(int count) {
        if (filled_ < count) refill();
        const uint64_t value = count == 0 ? 0 : buffer_ & (~uint64_t{0} >> (64 - count));
        buffer_ >>= count;
        filled_ -= count;
        consumed_ += uint64_t(count);
        return value;
    }
    bool overran() const { return consumed_ > uint64_t(size_) * 8; }
    // Every bit read but the zero padding of the last byte (fewer than 8 bits).
    bool ended_cleanly() const { return !overran() && uint64_t(size_) * 8 - consumed_ < 8; }

private:
    void refill() {
#if AMC_LITTLE_ENDIAN
        // The loop's bytes (up to 57..64 bits) from one 8-byte load: it took up to 8 rounds.
        if (filled_ <= 56 && size_ - pos_ >= 8) {
            uint64_t word;
            std::memcpy(&word, data_ + pos_, 8);
            const int bytes = (64 - filled_) >> 3;  // 1..8
            buffer_ |= (word & (~uint64_t{0} >> (64 - 8 * bytes))) << filled_;
            pos_ += size_t(bytes);
            filled_ += 8 * bytes;
            return;
        }
#endif
        while (filled_ <= 56) {
            buffer_ |= uint64_t(pos_ < size_ ? data_[pos_++] : 0) << filled_;
            filled_ += 8;
        }
    }
    const uint8_t* data_;
    size_t size_, pos_ = 0;
    uint64_t buffer_ = 0, consumed_ = 0;
    int filled_ = 0;
};

}  // namespace amc
