// Interleaved static rANS and the raw bit stream; see rans_coder.h.
#include "coding/entropy/rans_coder.h"

#include <amc/mesh.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <string>
#include <utility>

namespace amc {

RansTable RansTable::from_counts(const std::vector<uint64_t>& counts) {
    RansTable table = for_encoding(counts);
    table.build_slots();
    return table;
}

RansTable RansTable::for_encoding(const std::vector<uint64_t>& counts) {
    if (counts.empty() || counts.size() > size_t(kRansMaxSymbols)) {
        throw Error("RansTable: " + std::to_string(counts.size()) + " symbols (1 to " + std::to_string(kRansMaxSymbols) + ")");
    }
    uint64_t total = 0;
    size_t used = 0;
    for (uint64_t c : counts) {
        total += c;
        used += c != 0;
    }
    if (total == 0 || used >= kRansScale) throw Error("RansTable: no counts, or more symbols than frequencies");
    std::vector<uint32_t> f(counts.size(), 0);
    if (used == 1) {
        // One symbol may not take the whole scale: a neighbour that never occurs gets 1.
        const size_t s = size_t(std::find_if(counts.begin(), counts.end(), [](uint64_t c) { return c != 0; }) - counts.begin());
        if (f.size() == 1) f.push_back(0);
        f[s] = kRansMaxFrequency;
        f[s == 0 ? 1 : s - 1] = 1;
    } else {
        int64_t sum = 0;
        for (size_t s = 0; s < counts.size(); ++s) {
            if (counts[s] == 0) continue;
            // counts[s] * M < 2^64 for any count below 2^52, more than a stream holds.
            f[s] = uint32_t(std::max<uint64_t>(1, (counts[s] << kRansScaleBits) / total));
            sum += f[s];
        }
        // Settle the rounding: add to the most frequent symbols (by count, the first on ties), take
        // from the largest frequencies (the first of the largest, one at a time).
        if (sum < int64_t(kRansScale)) {
            std::vector<size_t> by_count;  // the used symbols: the rest never get more
            by_count.reserve(used);
            for (size_t s = 0; s < counts.size(); ++s)
                if (counts[s] != 0) by_count.push_back(s);
            std::stable_sort(by_count.begin(), by_count.end(), [&](size_t a, size_t b) { return counts[a] > counts[b]; });
            for (size_t i = 0; sum < int64_t(kRansScale); i = (i + 1) % used) {
                if (f[by_count[i]] < kRansMaxFrequency) {
                    ++f[by_count[i]];
                    ++sum;
                }
            }
        }
        if (sum > int64_t(kRansScale)) {
            // A heap on (frequency, then the lower symbol) gives each step's largest as the scan for
            // the first maximum did (tables of rare tokens bump many to 1: a scan per excess unit).
            auto lower = [&](uint32_t a, uint32_t b) { return f[a] != f[b] ? f[a] < f[b] : a > b; };
            std::vector<uint32_t> heap;
            heap.reserve(used);
            for (size_t s = 0; s < f.size(); ++s)
                if (f[s] != 0) heap.push_back(uint32_t(s));
            std::make_heap(heap.begin(), heap.end(), lower);
            while (sum > int64_t(kRansScale)) {
                std::pop_heap(heap.begin(), heap.end(), lower);
                --f[heap.back()];  // the largest is above 1: sum > M >= 2 * used would be needed otherwise
                --sum;
                std::push_heap(heap.begin(), heap.end(), lower);
            }
        }
    }
    RansTable table;
    table.frequency_ = std::move(f);  // what assign() accepts: the sum is M, none above the largest frequency
    table.set_starts();
    return table;
}

bool RansTable::assign(const std::vector<uint32_t>& frequencies) {
    if (frequencies.empty() || frequencies.size() > size_t(kRansMaxSymbols)) return false;
    uint64_t sum = 0;
    for (uint32_t f : frequencies) {
        if (f > kRansMaxFrequency) return false;
        sum += f;
    }
    if (sum != kRansScale) return false;
    frequency_ = frequencies;
    set_starts();
    build_slots();
    return true;
}

void RansTable::set_starts() {
    start_.assign(frequency_.size(), 0);
    coding_.assign(frequency_.size(), Coding{});
    uint32_t start = 0;
    for (size_t s = 0; s < frequency_.size(); ++s) {
        start_[s] = start;
        if (frequency_[s] != 0) coding_[s] = coding_of(start, frequency_[s]);
        start += frequency_[s];
    }
}

RansTable::Coding RansTable::coding_of(uint32_t start, uint32_t frequency) {
    Coding c;
    // The largest state that stays below 256 L after coding: ((L / M) << 8) * f.
    c.x_max = ((kRansLow >> kRansScaleBits) << 8) * frequency;
    c.complement = kRansScale - frequency;
    if (frequency < 2) {
        // 1 has no reciprocal below 1: q = x - 1 (from 2^32 - 1, no shift), and the bias makes up
        // for it: x + bias + (x - 1)(M - 1) = x M + start.
        c.reciprocal = ~uint32_t{0};
        c.shift = 32;
        c.bias = start + kRansScale - 1;
        return c;
    }
    uint32_t bits = 0;  // ceil(log2 f)
    while (frequency > (uint32_t{1} << bits)) ++bits;
    c.reciprocal = uint32_t(((uint64_t{1} << (bits + 31)) + frequency - 1) / frequency);
    c.shift = 32 + bits - 1;
    c.bias = start;
    return c;
}

void RansTable::build_slots() {
    entries_.clear();
    for (size_t s = 0; s < frequency_.size(); ++s)
        if (frequency_[s] != 0) entries_.push_back({uint16_t(s), uint16_t(frequency_[s]), uint16_t(start_[s])});
    narrow_ = entries_.size() <= 256;
    narrow_index_.assign(narrow_ ? kRansScale : 0, 0);
    wide_index_.assign(narrow_ ? 0 : kRansScale, 0);
    // Each symbol's run of slots in one fill (a decoder builds a table per level and role).
    for (size_t i = 0; i < entries_.size(); ++i) {
        const size_t start = entries_[i].start, frequency = entries_[i].frequency;
        if (narrow_) std::fill_n(narrow_index_.begin() + std::ptrdiff_t(start), frequency, uint8_t(i));
        else std::fill_n(wide_index_.begin() + std::ptrdiff_t(start), frequency, uint16_t(i));
    }
}

double RansTable::cost_bits(int symbol) const {
    return double(kRansScaleBits) - std::log2(double(frequency_[size_t(symbol)]));
}

std::vector<uint8_t> RansEncoder::finish() {
    RansBackwardEncoder backward(queue_.size());
    for (size_t i = queue_.size(); i-- > 0;) backward.put_coding(*queue_[i]);
    queue_.clear();
    return backward.finish();
}

RansBackwardEncoder::RansBackwardEncoder(size_t count)
    : buffer_(new uint8_t[buffer_bytes(count)]), end_(buffer_.get() + buffer_bytes(count)), begin_(end_), left_(count) {}

RansBackwardEncoder::RansBackwardEncoder(size_t count, ScratchArray<uint8_t>& memory)
    : end_(memory.reserve(buffer_bytes(count)) + buffer_bytes(count)), begin_(end_), left_(count) {}

void RansBackwardEncoder::throw_too_many() { throw Error("RansBackwardEncoder::put: more symbols than it was made for"); }

std::vector<uint8_t> RansBackwardEncoder::finish() {
    std::vector<uint8_t> out;
    finish(out);
    return out;
}

void RansBackwardEncoder::finish(std::vector<uint8_t>& out) {
    if (left_ != 0) throw Error("RansBackwardEncoder::finish: " + std::to_string(left_) + " symbols were not put");
    for (int s = 1; s >= 0; --s)
        for (int shift = 24; shift >= 0; shift -= 8) *--begin_ = uint8_t(state_[s] >> shift);
    out.assign(begin_, end_);
}

std::vector<uint8_t> RawBitWriter::finish() {
    bytes_.resize(used_);
    if (filled_ > 0) bytes_.push_back(uint8_t(buffer_));
    buffer_ = 0;
    filled_ = 0;
    used_ = 0;
    std::vector<uint8_t> out;
    out.swap(bytes_);
    return out;
}

}  // namespace amc
