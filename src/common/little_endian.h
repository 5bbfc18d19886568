// Integers stored least significant byte first, as every amcodec format (and little-endian binary
// PLY) keeps them. Written byte by byte so that they hold on any machine; GCC and Clang make each
// one a single load or store on little-endian processors.
#pragma once

#include <cstdint>
#include <cstring>
#include <vector>

namespace amc {

inline uint32_t load_le32(const uint8_t* p) {
    return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}

inline uint64_t load_le64(const uint8_t* p) { return load_le32(p) | uint64_t(load_le32(p + 4)) << 32; }

inline uint8_t* store_le32(uint8_t* at, uint32_t v) {
    for (int i = 0; i < 4; ++i) at[i] = uint8_t(v >> (8 * i));
    return at + 4;
}

inline uint8_t* store_le64(uint8_t* at, uint64_t v) { return store_le32(store_le32(at, uint32_t(v)), uint32_t(v >> 32)); }

inline void append_le32(std::vector<uint8_t>& out, uint32_t v) {
    uint8_t bytes[4];
    store_le32(bytes, v);
    out.insert(out.end(), bytes, bytes + 4);
}

inline void append_le64(std::vector<uint8_t>& out, uint64_t v) {
    uint8_t bytes[8];
    store_le64(bytes, v);
    out.insert(out.end(), bytes, bytes + 8);
}

// The same bits as another type of the same size (C++20's std::bit_cast): IEEE floats to the
// integers above and back.
template <class To, class From>
inline To bit_cast(const From& from) {
    static_assert(sizeof(To) == sizeof(From), "bit_cast between types of one size");
    To to;
    std::memcpy(&to, &from, sizeof(To));
    return to;
}

}  // namespace amc
