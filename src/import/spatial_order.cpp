#include "import/spatial_order.h"

#include <algorithm>

namespace amc::detail {

namespace {

constexpr uint32_t kCellsPerAxis = MortonFrame::kCellsPerAxis;  // two 15-bit counting-sort passes

// The 10 bits of x spread to every third bit.
constexpr uint32_t spread_bits(uint32_t x) {
    x &= 0x3ff;
    x = (x | (x << 16)) & 0x030000ffu;
    x = (x | (x << 8)) & 0x0300f00fu;
    x = (x | (x << 4)) & 0x030c30c3u;
    x = (x | (x << 2)) & 0x09249249u;
    return x;
}

// spread_bits of every cell, looked up (three per vertex: the shifts were a third of the codes'
// instructions).
struct SpreadCells {
    uint32_t of[kCellsPerAxis];
    constexpr SpreadCells() : of() {
        for (uint32_t c = 0; c < kCellsPerAxis; ++c) of[c] = spread_bits(c);
    }
};
constexpr SpreadCells kSpreadCells{};

}  // namespace

MortonFrame::MortonFrame(const std::vector<Vec3>& positions) {
    if (positions.empty()) return;
    double high[3] = {positions[0].x, positions[0].y, positions[0].z};
    for (int a = 0; a < 3; ++a) low[a] = high[a];
    for (const Vec3& p : positions) {
        const double c[3] = {p.x, p.y, p.z};
        for (int a = 0; a < 3; ++a) {
            low[a] = std::min(low[a], c[a]);
            high[a] = std::max(high[a], c[a]);
        }
    }
    *this = MortonFrame(low, high);
}

MortonFrame::MortonFrame(const double least[3], const double greatest[3]) {
    for (int a = 0; a < 3; ++a) low[a] = least[a];
    const double largest = std::max({greatest[0] - low[0], greatest[1] - low[1], greatest[2] - low[2]});
    scale = largest > 0 ? double(kCellsPerAxis) / largest : 0;  // may overflow to infinity: scale 0, one cell
}

std::vector<uint32_t> morton_codes(const std::vector<Vec3>& positions) {
    const uint32_t n = uint32_t(positions.size());
    std::vector<uint32_t> code(n);
    if (n == 0) return code;
    const MortonFrame frame(positions);
    for (uint32_t v = 0; v < n; ++v) {
        const double c[3] = {positions[v].x, positions[v].y, positions[v].z};
        uint32_t key = 0;
        for (int a = 0; a < 3; ++a) key |= kSpreadCells.of[MortonFrame::cell_of(frame.t(c[a], a))] << a;
        code[v] = key;
    }
    return code;
}

std::vector<uint32_t> spatial_vertex_order(const std::vector<Vec3>& positions, std::vector<uint32_t>* sorted_codes) {
    const std::vector<uint32_t> codes = morton_codes(positions);
    std::vector<uint32_t> order = order_by_codes(codes);
    if (sorted_codes != nullptr) {
        sorted_codes->resize(order.size());
        for (size_t i = 0; i < order.size(); ++i) (*sorted_codes)[i] = codes[order[i]];
    }
    return order;
}

std::vector<uint32_t> order_by_codes(const std::vector<uint32_t>& code) {
    const uint32_t n = uint32_t(code.size());
    std::vector<uint32_t> order(n);
    if (n == 0) return order;
    // Least significant half first; each pass is stable.
    constexpr uint32_t kBuckets = 1u << 15;
    std::vector<uint32_t> count(kBuckets + 1), scratch(n);
    auto pass = [&](const uint32_t* from, uint32_t* to, int shift, bool identity) {
        std::fill(count.begin(), count.end(), 0);
        for (uint32_t i = 0; i < n; ++i) ++count[((code[identity ? i : from[i]] >> shift) & (kBuckets - 1)) + 1];
        for (uint32_t b = 1; b <= kBuckets; ++b) count[b] += count[b - 1];
        for (uint32_t i = 0; i < n; ++i) {
            const uint32_t v = identity ? i : from[i];
            to[count[(code[v] >> shift) & (kBuckets - 1)]++] = v;
        }
    };
    pass(nullptr, scratch.data(), 0, true);
    pass(scratch.data(), order.data(), 15, false);
    return order;
}

}  // namespace amc::detail
