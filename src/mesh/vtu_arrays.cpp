// One DataArray of a VTU file: see vtu_arrays.h.
#include "mesh/vtu_arrays.h"

#include "common/parallel.h"
#include "mesh/base64.h"
#include "mesh/text_number.h"
#include "mesh/zlib_blocks.h"

#include <algorithm>
#include <charconv>
#include <cstring>
#include <limits>
#include <optional>
#include <type_traits>
#include <variant>
#include <vector>

namespace amc::vtu {

std::string describe(const ArrayElement& a, const std::string& piece) {
    std::string s;
    switch (a.section) {
        case Section::points: s = "Points array"; break;
        case Section::cells: s = "Cells array"; break;
        case Section::point_data: s = "point data"; break;
        case Section::cell_data: s = "cell data"; break;
    }
    if (!a.name.empty()) s += " " + text::quote_token(a.name);
    return piece + s + " (line " + std::to_string(a.line) + ")";
}

namespace {

// The bytes of appended raw data, or the decoded bytes of base64 text.
class ByteSource {
public:
    static ByteSource raw(std::string_view data) {
        ByteSource s;
        s.raw_ = data;
        return s;
    }
    static ByteSource base64(std::string_view text) {
        ByteSource s;
        s.base64_.emplace(text);
        return s;
    }

    // The next n bytes (in `scratch` or in the input), or null when the data ends first.
    const uint8_t* take(std::size_t n, std::vector<uint8_t>& scratch) {
        if (base64_) {
            if (n > base64_->max_remaining()) return nullptr;
            scratch.resize(n);
            return base64_->read(scratch.data(), n) ? scratch.data() : nullptr;
        }
        if (n > raw_.size() - pos_) return nullptr;
        const uint8_t* p = reinterpret_cast<const uint8_t*>(raw_.data()) + pos_;
        pos_ += n;
        return p;
    }

    uint64_t max_remaining() const {
        return base64_ ? base64_->max_remaining() : raw_.size() - pos_;
    }

    // Why take() failed: the data ended, or its base64 is malformed.
    bool truncated() const { return !base64_ || !base64_->malformed(); }
    std::string failure() const { return truncated() ? "ends early (truncated?)" : base64_->failure(); }

private:
    std::string_view raw_;
    std::size_t pos_ = 0;
    std::optional<Base64Reader> base64_;
};

template <typename T>
std::vector<T> typed_values(const uint8_t* data, std::size_t count, bool swap) {
    std::vector<T> v(count);
    if (count) std::memcpy(v.data(), data, count * sizeof(T));
    if (swap && sizeof(T) > 1) {
        for (T& x : v) {
            uint8_t b[sizeof(T)];
            std::memcpy(b, &x, sizeof(T));
            std::reverse(b, b + sizeof(T));
            std::memcpy(&x, b, sizeof(T));
        }
    }
    return v;
}

DataArray::Values make_values(ValueType type, const uint8_t* data, std::size_t count, bool swap) {
    switch (type) {
        case ValueType::int8: return typed_values<int8_t>(data, count, swap);
        case ValueType::uint8: return typed_values<uint8_t>(data, count, swap);
        case ValueType::int16: return typed_values<int16_t>(data, count, swap);
        case ValueType::uint16: return typed_values<uint16_t>(data, count, swap);
        case ValueType::int32: return typed_values<int32_t>(data, count, swap);
        case ValueType::uint32: return typed_values<uint32_t>(data, count, swap);
        case ValueType::int64: return typed_values<int64_t>(data, count, swap);
        case ValueType::uint64: return typed_values<uint64_t>(data, count, swap);
        case ValueType::float32: return typed_values<float>(data, count, swap);
        case ValueType::float64: return typed_values<double>(data, count, swap);
    }
    return {};
}

template <typename T>
bool parse_value(std::string_view token, T& out) {
    if constexpr (std::is_floating_point_v<T>) {
        return text::parse_real(token, out);
    } else if constexpr (std::is_same_v<T, uint64_t>) {
        if (!token.empty() && token[0] == '+') token.remove_prefix(1);
        const char* last = token.data() + token.size();
        auto [ptr, ec] = std::from_chars(token.data(), last, out, 10);
        return ec == std::errc() && ptr == last;
    } else {
        int64_t v = 0;
        if (!text::parse_int(token, v) || v < int64_t(std::numeric_limits<T>::min()) ||
            v > int64_t(std::numeric_limits<T>::max())) {
            return false;
        }
        out = static_cast<T>(v);
        return true;
    }
}

class ArrayDecoder {
public:
    ArrayDecoder(const Layout& layout, const std::string& what, unsigned threads)
        : layout_(layout), what_(what), threads_(threads) {}

    // The array's values, which must be `tuples` tuples of its components. `piece` prefixes
    // messages ("piece 2: " or "").
    DataArray decode(const ArrayElement& a, uint64_t tuples, const std::string& piece) const {
        DataArray out;
        out.name = a.name;
        out.components = static_cast<uint32_t>(a.components);
        const std::string where = describe(a, piece);
        // tuples and components are both below 2^32, so count and its bytes fit in 64 bits.
        const uint64_t count = tuples * a.components;
        const std::size_t size = value_size(a.type);
        if (count > std::numeric_limits<std::size_t>::max() / 8) fail(what_, where + ": too large");
        if (a.format == DataFormat::ascii) {
            out.values = parse_ascii(a, count, where);
            return out;
        }
        ByteSource source = ByteSource::base64(a.text);
        if (a.format == DataFormat::appended) {
            if (!layout_.has_appended) fail(what_, where + ": format=\"appended\" but the file has no AppendedData");
            if (a.offset > layout_.appended.size()) {
                fail(what_, where + ": offset " + std::to_string(a.offset) + " is past the end of the " +
                                std::to_string(layout_.appended.size()) + " bytes of appended data");
            }
            const std::string_view data = layout_.appended.substr(a.offset);
            source = layout_.appended_base64 ? ByteSource::base64(data) : ByteSource::raw(data);
        }
        const std::vector<uint8_t> raw = read_block(source, count * size, a, where);
        out.values = make_values(a.type, raw.data(), count, layout_.big_endian != kHostBigEndian);
        return out;
    }

private:
    DataArray::Values parse_ascii(const ArrayElement& a, uint64_t count, const std::string& where) const {
        // n values need at least 2n - 1 characters: checked before allocating.
        if (count > (a.text.size() + 1) / 2) {
            fail(what_, where + ": needs " + std::to_string(count) + " values, more than its " +
                            std::to_string(a.text.size()) + " characters of text can hold");
        }
        DataArray::Values values = make_values(a.type, nullptr, 0, false);
        std::visit(
            [&](auto& v) {
                using T = typename std::decay_t<decltype(v)>::value_type;
                v.resize(count);
                text::TokenCursor cursor(a.text, /*hash_comments=*/false);
                for (uint64_t i = 0; i < count; ++i) {
                    const std::string_view token = cursor.next();
                    if (token.empty()) {
                        fail(what_, where + ": holds " + std::to_string(i) + " values, expected " +
                                        std::to_string(count));
                    }
                    if (!parse_value<T>(token, v[i])) {
                        fail(what_, where + ": value " + std::to_string(i) + " " + text::quote_token(token) +
                                        " is not a valid " + std::string(vtk_type_name(a.type)));
                    }
                }
                if (!cursor.next().empty()) {
                    fail(what_, where + ": holds more than the " + std::to_string(count) + " values expected");
                }
            },
            values);
        return values;
    }

    [[noreturn]] void fail_source(const ByteSource& source, const std::string& where,
                                  const std::string& suffix) const {
        fail(what_, where + ": the data " + source.failure() + suffix,
             source.truncated() ? ErrorCode::truncated : ErrorCode::corrupt);
    }

    uint64_t read_word(ByteSource& source, const std::string& where, const char* what_word) const {
        std::vector<uint8_t> scratch;
        const uint8_t* p = source.take(layout_.header_bytes, scratch);
        if (!p) fail_source(source, where, std::string(" (in the ") + what_word + ")");
        uint64_t word = 0;
        for (unsigned i = 0; i < layout_.header_bytes; ++i) {
            const unsigned byte = layout_.big_endian ? i : layout_.header_bytes - 1 - i;
            word = (word << 8) | p[byte];
        }
        return word;
    }

    std::string expected_text(uint64_t bytes, const ArrayElement& a) const {
        return std::to_string(bytes) + " bytes (" + std::to_string(bytes / value_size(a.type)) + " " +
               std::string(vtk_type_name(a.type)) + " values)";
    }

    // The array's bytes, in the file's byte order, after its header.
    std::vector<uint8_t> read_block(ByteSource& source, uint64_t expected, const ArrayElement& a,
                                    const std::string& where) const {
        std::vector<uint8_t> scratch;
        if (!layout_.zlib) {
            const uint64_t declared = read_word(source, where, "header");
            if (declared != expected) {
                fail(what_, where + ": its header says " + std::to_string(declared) +
                                " bytes, expected " + expected_text(expected, a));
            }
            if (declared > source.max_remaining()) {
                fail(what_, where + ": declares " + std::to_string(declared) + " bytes, but only " +
                                std::to_string(source.max_remaining()) + " remain (truncated?)", ErrorCode::truncated);
            }
            const uint8_t* p = source.take(declared, scratch);
            if (!p) fail_source(source, where, "");
            return std::vector<uint8_t>(p, p + declared);
        }
        // vtkZLibDataCompressor: block count, block size, size of the last block (0: full), the
        // compressed size of each block, then the blocks.
        const uint64_t blocks = read_word(source, where, "compression header");
        const uint64_t block_size = read_word(source, where, "compression header");
        const uint64_t last_size = read_word(source, where, "compression header");
        if (blocks > source.max_remaining() / layout_.header_bytes) {
            fail(what_, where + ": declares " + std::to_string(blocks) +
                            " compressed blocks, more than the data can hold");
        }
        if (blocks > 0 && (block_size == 0 || last_size > block_size)) {
            fail(what_, where + ": bad compression header (block size " + std::to_string(block_size) +
                            ", last block " + std::to_string(last_size) + ")");
        }
        uint64_t total = 0;
        if (blocks > 0) {
            const uint64_t last = last_size ? last_size : block_size;
            if (blocks - 1 > (std::numeric_limits<uint64_t>::max() - last) / block_size) {
                fail(what_, where + ": bad compression header (size overflows)");
            }
            total = (blocks - 1) * block_size + last;
        }
        if (total != expected) {
            fail(what_, where + ": its compression header says " + std::to_string(total) +
                            " bytes, expected " + expected_text(expected, a));
        }
        std::vector<uint64_t> compressed(blocks);
        uint64_t compressed_total = 0;
        for (uint64_t& c : compressed) {
            c = read_word(source, where, "compression header");
            if (c > source.max_remaining()) {
                fail(what_, where + ": a compressed block of " + std::to_string(c) +
                                " bytes is longer than the data left (truncated?)", ErrorCode::truncated);
            }
            compressed_total += c;  // each term is bounded by the input size: no overflow
        }
        if (compressed_total > source.max_remaining()) {
            fail(what_, where + ": the compressed blocks need " + std::to_string(compressed_total) +
                            " bytes, but only " + std::to_string(source.max_remaining()) + " remain (truncated?)", ErrorCode::truncated);
        }
        return inflate_blocks(source, compressed, block_size, last_size, where);
    }

    // The blocks inflated one after another into one buffer, each first checked against what
    // zlib can expand its bytes to, so no allocation is larger than the input can back. Runs of
    // blocks (about 1 MiB of output each) inflate on several threads; the error is the one the
    // block-by-block loop (inflate_serially) reports first.
    std::vector<uint8_t> inflate_blocks(ByteSource& source, const std::vector<uint64_t>& compressed,
                                        uint64_t block_size, uint64_t last_size, const std::string& where) const {
        const uint64_t blocks = compressed.size();
        // The blocks before the first one that fails the size check are all inflated: an inflate
        // failure among them comes first in the serial loop.
        uint64_t checked = 0, in_size = 0, out_size = 0;
        bool empty_block = false;
        while (checked < blocks && block_fits(compressed, checked, block_size, last_size)) {
            in_size += compressed[checked];
            out_size += block_bytes(blocks, checked, block_size, last_size);
            empty_block |= compressed[checked] == 0;
            ++checked;
        }
        // Their bytes are consecutive: one take, as base64 decodes into the reused scratch.
        const ByteSource start = source;
        std::vector<uint8_t> scratch;
        const uint8_t* in = empty_block ? nullptr : source.take(in_size, scratch);
        if (!in) {
            // Base64 that breaks inside the blocks (is an earlier block's inflate failure or the
            // base64 error first?) or a block of no bytes (never valid; base64's take(0) into an
            // empty scratch reports the data ending): the serial loop says which error comes first.
            ByteSource again = start;
            return inflate_serially(again, compressed, block_size, last_size, where);
        }
        std::vector<uint8_t> out(out_size);
        std::vector<uint64_t> in_at(checked + 1, 0), out_at(checked + 1, 0);
        for (uint64_t b = 0; b < checked; ++b) {
            in_at[b + 1] = in_at[b] + compressed[b];
            out_at[b + 1] = out_at[b] + block_bytes(blocks, b, block_size, last_size);
        }
        const uint64_t per_task = std::max<uint64_t>(1, (uint64_t{1} << 20) / block_size);
        const std::size_t tasks = static_cast<std::size_t>((checked + per_task - 1) / per_task);
        std::vector<uint64_t> first_bad(tasks, checked);  // per task: its first block that fails
        parallel_for(tasks, resolve_thread_count(threads_), [&](std::size_t t) {
            for (uint64_t b = t * per_task; b < std::min(checked, (t + 1) * per_task); ++b) {
                if (!inflate_zlib_block(in + in_at[b], compressed[b], out.data() + out_at[b], out_at[b + 1] - out_at[b])) {
                    first_bad[t] = b;
                    return;
                }
            }
        });
        for (const uint64_t b : first_bad) {
            if (b < checked) fail_inflate(blocks, b, block_bytes(blocks, b, block_size, last_size), where);
        }
        if (checked < blocks) fail_size(compressed, checked, block_size, last_size, where);
        return out;
    }

    // The reference order of checks: size, bytes, inflate, block by block.
    std::vector<uint8_t> inflate_serially(ByteSource& source, const std::vector<uint64_t>& compressed,
                                          uint64_t block_size, uint64_t last_size, const std::string& where) const {
        const uint64_t blocks = compressed.size();
        std::vector<uint8_t> scratch, out;
        for (uint64_t b = 0; b < blocks; ++b) {
            const uint64_t size = block_bytes(blocks, b, block_size, last_size);
            if (!block_fits(compressed, b, block_size, last_size)) fail_size(compressed, b, block_size, last_size, where);
            const uint8_t* p = source.take(compressed[b], scratch);
            if (!p) fail_source(source, where, "");
            const std::size_t at = out.size();
            out.resize(at + size);
            if (!inflate_zlib_block(p, compressed[b], out.data() + at, size)) fail_inflate(blocks, b, size, where);
        }
        return out;
    }

    static uint64_t block_bytes(uint64_t blocks, uint64_t b, uint64_t block_size, uint64_t last_size) {
        return (b + 1 == blocks && last_size) ? last_size : block_size;
    }

    static bool block_fits(const std::vector<uint64_t>& compressed, uint64_t b, uint64_t block_size,
                           uint64_t last_size) {
        return block_bytes(compressed.size(), b, block_size, last_size) <= compressed[b] * kZlibMaxExpansion + 64;
    }

    [[noreturn]] void fail_size(const std::vector<uint64_t>& compressed, uint64_t b, uint64_t block_size,
                                uint64_t last_size, const std::string& where) const {
        fail(what_, where + ": compressed block " + std::to_string(b) + " declares " +
                        std::to_string(block_bytes(compressed.size(), b, block_size, last_size)) + " bytes, more than its " +
                        std::to_string(compressed[b]) + " compressed bytes can hold");
    }

    [[noreturn]] void fail_inflate(uint64_t blocks, uint64_t b, uint64_t size, const std::string& where) const {
        fail(what_, where + ": compressed block " + std::to_string(b) + " of " + std::to_string(blocks) +
                        " is not valid zlib data of " + std::to_string(size) + " bytes");
    }

    const Layout& layout_;
    const std::string& what_;
    unsigned threads_;
};

}  // namespace

DataArray decode_array(const Layout& layout, const ArrayElement& a, uint64_t tuples, const std::string& piece,
                       const std::string& what, unsigned threads) {
    return ArrayDecoder(layout, what, threads).decode(a, tuples, piece);
}

}  // namespace amc::vtu
