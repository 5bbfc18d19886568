// Tests of the adaptive binary range coder: round trips, efficiency against the ideal adaptive
// code length and the static entropy, golden bytes, and robustness on truncated/garbage input.
#include "coding/entropy/arithmetic_coder.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <memory>
#include <random>
#include <vector>

#include "amc/mesh.h"

namespace amc {
namespace {

// Bernoulli(p) bits from std::mt19937, whose output sequence is fixed by the standard (unlike
// std::bernoulli_distribution's).
class BitSource {
public:
    BitSource(double p_one, uint32_t seed)
        : threshold_(static_cast<uint64_t>(p_one * 4294967296.0)), rng_(seed) {}
    void set_p(double p_one) { threshold_ = static_cast<uint64_t>(p_one * 4294967296.0); }
    bool next() { return uint64_t{rng_()} < threshold_; }
    uint32_t next_u32() { return static_cast<uint32_t>(rng_()); }

private:
    uint64_t threshold_;
    std::mt19937 rng_;
};

// One coded symbol: a modelled bit in context `ctx`, or `count` raw bits of `value` (ctx < 0).
struct Symbol {
    int ctx;
    uint32_t value;
    int count;
};

struct Coded {
    std::vector<uint8_t> bytes;
    double ideal_bits = 0;  // ideal adaptive code length (sum of model costs, raw bits at 1)
};

Coded encode_symbols(const std::vector<Symbol>& symbols, size_t contexts, int limit_log2) {
    std::vector<BitModel> models(contexts, BitModel(limit_log2));
    ArithmeticEncoder enc;
    Coded coded;
    for (const Symbol& s : symbols) {
        if (s.ctx >= 0) {
            coded.ideal_bits += models[s.ctx].cost_bits(s.value != 0);
            enc.encode(s.value != 0, models[s.ctx]);
        } else {
            coded.ideal_bits += s.count;
            enc.encode_bits_raw(s.value, s.count);
        }
    }
    coded.bytes = enc.finish();
    return coded;
}

// Decodes from an exactly sized heap copy, so AddressSanitizer sees any read past the end.
std::vector<Symbol> decode_symbols(const std::vector<uint8_t>& bytes,
                                   const std::vector<Symbol>& shape, size_t contexts,
                                   int limit_log2, bool* overran = nullptr) {
    std::unique_ptr<uint8_t[]> copy(new uint8_t[bytes.size() + (bytes.empty() ? 1 : 0)]);
    std::copy(bytes.begin(), bytes.end(), copy.get());
    std::vector<BitModel> models(contexts, BitModel(limit_log2));
    ArithmeticDecoder dec(copy.get(), bytes.size());
    std::vector<Symbol> out;
    out.reserve(shape.size());
    for (const Symbol& s : shape) {
        if (s.ctx >= 0) {
            out.push_back({s.ctx, dec.decode(models[s.ctx]) ? 1u : 0u, 1});
        } else {
            out.push_back({s.ctx, dec.decode_bits_raw(s.count), s.count});
        }
    }
    if (overran) *overran = dec.overran();
    return out;
}

void expect_round_trip(const std::vector<Symbol>& symbols, size_t contexts,
                       int limit_log2 = BitModel::kDefaultLimitLog2) {
    const Coded coded = encode_symbols(symbols, contexts, limit_log2);
    bool overran = true;
    const std::vector<Symbol> decoded =
        decode_symbols(coded.bytes, symbols, contexts, limit_log2, &overran);
    EXPECT_FALSE(overran);
    ASSERT_EQ(decoded.size(), symbols.size());
    for (size_t i = 0; i < symbols.size(); ++i) {
        ASSERT_EQ(decoded[i].value, symbols[i].value) << "symbol " << i << " of " << symbols.size();
    }
}

std::vector<Symbol> bernoulli(size_t n, double p, uint32_t seed) {
    BitSource src(p, seed);
    std::vector<Symbol> s(n);
    for (auto& x : s) x = {0, src.next() ? 1u : 0u, 1};
    return s;
}

double static_entropy_bits(const std::vector<Symbol>& symbols, size_t contexts) {
    std::vector<uint64_t> ones(contexts), n(contexts);
    double raw = 0;
    for (const Symbol& s : symbols) {
        if (s.ctx < 0) {
            raw += s.count;
        } else {
            ++n[s.ctx];
            ones[s.ctx] += s.value;
        }
    }
    double bits = raw;
    for (size_t c = 0; c < contexts; ++c) bits += binary_entropy_bits(ones[c], n[c]);
    return bits;
}

// ---------------------------------------------------------------------------------------------
// Helpers and the model

TEST(BinaryEntropy, KnownValues) {
    EXPECT_EQ(binary_entropy_bits(0, 0), 0.0);
    EXPECT_EQ(binary_entropy_bits(0, 100), 0.0);
    EXPECT_EQ(binary_entropy_bits(100, 100), 0.0);
    EXPECT_NEAR(binary_entropy_bits(50, 100), 100.0, 1e-9);
    EXPECT_NEAR(binary_entropy_bits(1, 4), 4 * 0.8112781244591328, 1e-9);
}

TEST(BitModel, StartsAtOneHalfAndFollowsKrichevskyTrofimov) {
    BitModel m;
    EXPECT_EQ(m.p16(), kProbOne / 2);
    EXPECT_NEAR(m.cost_bits(false), 1.0, 1e-12);
    EXPECT_NEAR(m.cost_bits(true), 1.0, 1e-12);
    // p1 = (n1 + 1/2) / (n + 1) while n + 2 < limit.
    BitSource src(0.3, 7);
    uint64_t ones = 0;
    for (uint64_t n = 1; n <= 4000; ++n) {
        const bool bit = src.next();
        ones += bit;
        m.update(bit);
        const double kt = (static_cast<double>(ones) + 0.5) / static_cast<double>(n + 1);
        ASSERT_NEAR(static_cast<double>(m.p) / 4294967296.0, kt, 1e-6) << "after " << n;
    }
}

TEST(BitModel, ProbabilityNeverReachesZeroOrOne) {
    for (int limit_log2 : {1, 4, 12, 16}) {
        BitModel zeros(limit_log2), ones(limit_log2);
        for (int i = 0; i < 300000; ++i) {
            zeros.update(false);
            ones.update(true);
        }
        EXPECT_GE(zeros.p16(), 1u);
        EXPECT_LE(ones.p16(), kProbOne - 1);
        EXPECT_TRUE(std::isfinite(zeros.cost_bits(true)));
        EXPECT_TRUE(std::isfinite(ones.cost_bits(false)));
        EXPECT_LE(zeros.cost_bits(true), 16.0 + 1e-9);
    }
}

TEST(BitModel, LimitIsClamped) {
    EXPECT_EQ(BitModel(0).limit_log2, BitModel::kMinLimitLog2);
    EXPECT_EQ(BitModel(40).limit_log2, BitModel::kMaxLimitLog2);
    EXPECT_EQ(BitModel(9).limit_log2, 9);
}

// ---------------------------------------------------------------------------------------------
// Round trips

TEST(ArithmeticCoder, EmptyStreamIsZeroBytes) {
    ArithmeticEncoder enc;
    EXPECT_EQ(enc.bytes_so_far(), 0u);
    EXPECT_TRUE(enc.finish().empty());
    ArithmeticDecoder dec(nullptr, 0);
    EXPECT_FALSE(dec.overran());
}

TEST(ArithmeticCoder, KnownSequences) {
    const size_t n = 100000;
    std::vector<Symbol> zeros(n, Symbol{0, 0, 1}), ones(n, Symbol{0, 1, 1}), alternating(n);
    for (size_t i = 0; i < n; ++i) alternating[i] = {0, static_cast<uint32_t>(i & 1), 1};
    for (const auto* seq : {&zeros, &ones, &alternating}) expect_round_trip(*seq, 1);
    // Constant streams cost O(log n) bits under KT plus the window: a handful of bytes.
    EXPECT_LE(encode_symbols(zeros, 1, BitModel::kDefaultLimitLog2).bytes.size(), 16u);
    EXPECT_LE(encode_symbols(ones, 1, BitModel::kDefaultLimitLog2).bytes.size(), 16u);
    // Alternating bits look like p = 1/2 to an order-0 model.
    EXPECT_LE(encode_symbols(alternating, 1, BitModel::kDefaultLimitLog2).bytes.size(),
              n / 8 + 16);
}

TEST(ArithmeticCoder, RandomSourcesRoundTrip) {
    for (double p : {0.01, 0.1, 0.5, 0.9}) {
        SCOPED_TRACE(p);
        expect_round_trip(bernoulli(100000, p, 12345), 1);
    }
}

TEST(ArithmeticCoder, EveryLengthUpTo1000) {
    BitSource pick(0.5, 99);
    for (size_t len = 0; len <= 1000; ++len) {
        const double p = (len % 4 == 0) ? 0.5 : (len % 4 == 1) ? 0.05 : (len % 4 == 2) ? 0.97 : 0.3;
        std::vector<Symbol> s = bernoulli(len, p, static_cast<uint32_t>(len));
        for (auto& x : s) x.ctx = static_cast<int>(pick.next_u32() % 3);
        SCOPED_TRACE(len);
        expect_round_trip(s, 3, 1 + static_cast<int>(len % 16));
    }
}

TEST(ArithmeticCoder, MillionSymbols) {
    std::vector<Symbol> s = bernoulli(1000000, 0.2, 2024);
    expect_round_trip(s, 1);
    expect_round_trip(s, 1, 16);
}

TEST(ArithmeticCoder, ManyContextsInterleaved) {
    // Nine context groups as in paper Table 2, with very different statistics.
    const double p[9] = {0.69, 0.96, 0.26, 0.56, 0.89, 0.10, 0.04, 0.14, 0.5};
    std::vector<BitSource> sources;
    for (int c = 0; c < 9; ++c) sources.emplace_back(p[c], 100 + c);
    BitSource pick(0.5, 5);
    std::vector<Symbol> s(200000);
    for (auto& x : s) {
        const int c = static_cast<int>(pick.next_u32() % 9);
        x = {c, sources[c].next() ? 1u : 0u, 1};
    }
    expect_round_trip(s, 9);
    const Coded coded = encode_symbols(s, 9, BitModel::kDefaultLimitLog2);
    EXPECT_LE(coded.bytes.size() * 8.0, coded.ideal_bits * 1.005 + 64);
    EXPECT_LE(coded.bytes.size() * 8.0, static_entropy_bits(s, 9) * 1.01 + 128);
}

// The bound decoders check counts against: no payload yields max_decodable_symbols of it
// without overrunning, whatever its bytes and however the models lean; and past a few bytes the
// bound is within a factor 2 of what a saturated model reaches.
TEST(ArithmeticCoder, NoPayloadHoldsMoreSymbolsThanTheBound) {
    std::mt19937 random(11);
    for (size_t size : {0, 1, 2, 3, 7, 20}) {
        for (int pattern = 0; pattern < 4; ++pattern) {
            std::vector<uint8_t> payload(size);
            for (uint8_t& b : payload) b = pattern == 0 ? 0x00 : pattern == 1 ? 0xFF : uint8_t(random());
            ArithmeticDecoder decoder(payload.data(), payload.size());
            BitModel model;
            uint64_t symbols = 0;
            const uint64_t bound = max_decodable_symbols(size);
            while (!decoder.overran() && symbols <= bound) {
                if (pattern == 3 && symbols % 97 == 0) decoder.decode_bits_raw(1);
                else decoder.decode(model);
                ++symbols;
            }
            EXPECT_LT(symbols, bound) << size << " bytes, pattern " << pattern;
            if (pattern == 0 && size >= 7) {
                EXPECT_GT(symbols, bound / 2) << size << " bytes: the bound is loose";
            }
        }
    }
}

TEST(ArithmeticCoder, RawBitsMixedWithModelledBits) {
    BitSource src(0.1, 77), pick(0.5, 78);
    std::vector<Symbol> s;
    for (int i = 0; i < 50000; ++i) {
        const uint32_t r = pick.next_u32();
        if (r % 5 == 0) {
            const int count = static_cast<int>((r >> 8) % 33);  // 0..32
            const uint32_t value = pick.next_u32();
            s.push_back({-1, count == 32 ? value : value & ((1u << count) - 1), count});
        } else {
            s.push_back({static_cast<int>(r % 2), src.next() ? 1u : 0u, 1});
        }
    }
    expect_round_trip(s, 2);
    // Raw bits cost one bit each.
    std::vector<Symbol> raw_only;
    for (int i = 0; i < 1000; ++i) raw_only.push_back({-1, pick.next_u32(), 32});
    expect_round_trip(raw_only, 1);
    EXPECT_LE(encode_symbols(raw_only, 1, 12).bytes.size(), 4000u + 5);
}

TEST(ArithmeticCoder, RawBitCountOutOfRangeThrows) {
    ArithmeticEncoder enc;
    EXPECT_THROW(enc.encode_bits_raw(0, 33), Error);
    EXPECT_THROW(enc.encode_bits_raw(0, -1), Error);
    const uint8_t byte = 0;
    ArithmeticDecoder dec(&byte, 1);
    EXPECT_THROW(dec.decode_bits_raw(33), Error);
}

TEST(ArithmeticCoder, CarryPropagationThroughLongRunsOfFF) {
    // Raw all-ones bits drive low towards 0xFF...F, which makes the encoder hold back long runs
    // of 0xFF bytes; a final modelled zero then carries into them.
    std::vector<Symbol> s;
    for (int i = 0; i < 2000; ++i) s.push_back({-1, 0xFFFFFFFFu, 32});
    s.push_back({0, 0, 1});
    for (int i = 0; i < 20; ++i) s.push_back({0, 1, 1});
    expect_round_trip(s, 1);
    BitSource src(0.5, 3);
    for (int rep = 0; rep < 200; ++rep) {
        std::vector<Symbol> t;
        for (int i = 0; i < 50; ++i) t.push_back({-1, 0xFFFFFFFFu, 32});
        for (int i = 0; i < 10; ++i) t.push_back({0, src.next() ? 1u : 0u, 1});
        expect_round_trip(t, 1);
    }
}

// ---------------------------------------------------------------------------------------------
// Efficiency

TEST(ArithmeticCoder, WithinHalfPercentOfIdealAdaptiveCodeLength) {
    for (double p : {0.001, 0.01, 0.02, 0.1, 0.3, 0.5, 0.9, 0.99}) {
        for (int limit_log2 : {5, 12, 16}) {
            const Coded coded = encode_symbols(bernoulli(100000, p, 4242), 1, limit_log2);
            const double ideal_bytes = coded.ideal_bits / 8;
            EXPECT_LE(coded.bytes.size(), ideal_bytes * 1.005 + 8)
                << "p=" << p << " limit_log2=" << limit_log2;
        }
    }
}

TEST(ArithmeticCoder, SlowlyVaryingSourceWithinHalfPercentOfIdeal) {
    const size_t n = 100000;
    BitSource src(0.05, 31);
    std::vector<Symbol> s(n);
    for (size_t i = 0; i < n; ++i) {
        src.set_p(0.175 + 0.125 * std::sin(static_cast<double>(i) * 6.283185307179586 / 30000));
        s[i] = {0, src.next() ? 1u : 0u, 1};
    }
    expect_round_trip(s, 1);
    for (int limit_log2 : {8, 12}) {
        const Coded coded = encode_symbols(s, 1, limit_log2);
        EXPECT_LE(coded.bytes.size(), coded.ideal_bits / 8 * 1.005 + 8);
    }
}

TEST(ArithmeticCoder, WithinOnePercentOfStaticEntropy) {
    for (double p : {0.02, 0.1, 0.3}) {
        for (size_t n : {size_t{100000}, size_t{1000000}}) {
            const std::vector<Symbol> s = bernoulli(n, p, 777);
            const double entropy_bytes = static_entropy_bits(s, 1) / 8;
            const Coded coded = encode_symbols(s, 1, BitModel::kDefaultLimitLog2);
            EXPECT_LE(coded.bytes.size(), entropy_bytes * 1.01 + 16) << "p=" << p << " n=" << n;
            // The KT model with a long window approaches the static entropy more closely.
            const Coded long_window = encode_symbols(s, 1, 16);
            EXPECT_LE(long_window.bytes.size(), entropy_bytes * 1.003 + 16)
                << "p=" << p << " n=" << n;
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Golden bytes: an accidental change of the coder or the model changes these.

TEST(ArithmeticCoder, GoldenBytes) {
    // 64 bits of p = 0.2 over two models (one with a window of 16), 20 raw bits, 16 more bits.
    std::vector<bool> bits;
    BitSource src(0.2, 1);
    for (int i = 0; i < 64; ++i) bits.push_back(src.next());
    const uint32_t raw = 0xABCDE;
    for (int i = 0; i < 16; ++i) bits.push_back(i % 5 == 0);

    BitModel a, b(4);
    ArithmeticEncoder enc;
    for (int i = 0; i < 64; ++i) enc.encode(bits[i], (i % 3 == 0) ? b : a);
    enc.encode_bits_raw(raw, 20);
    for (int i = 64; i < 80; ++i) enc.encode(bits[i], a);
    const std::vector<uint8_t> bytes = enc.finish();
    const std::vector<uint8_t> golden = {0xDD, 0x76, 0xFB, 0x9E, 0x6A, 0xB1,
                                         0xD7, 0xC0, 0xD5, 0xC2, 0x58};
    EXPECT_EQ(bytes, golden);

    BitModel da, db(4);
    ArithmeticDecoder dec(golden.data(), golden.size());
    for (int i = 0; i < 64; ++i) ASSERT_EQ(dec.decode((i % 3 == 0) ? db : da), bits[i]) << i;
    EXPECT_EQ(dec.decode_bits_raw(20), raw);
    for (int i = 64; i < 80; ++i) ASSERT_EQ(dec.decode(da), bits[i]) << i;
    EXPECT_FALSE(dec.overran());
}

// ---------------------------------------------------------------------------------------------
// Robustness

TEST(ArithmeticDecoder, TruncatedStreamsTerminateAndReportOverrun) {
    BitSource src(0.5, 11);
    std::vector<Symbol> s;
    for (int i = 0; i < 3000; ++i) {
        if (i % 7 == 0) s.push_back({-1, src.next_u32() & 0xFFF, 12});
        else s.push_back({i % 2, src.next() ? 1u : 0u, 1});
    }
    const Coded coded = encode_symbols(s, 2, 12);
    ASSERT_GT(coded.bytes.size(), 100u);
    for (size_t len = 0; len <= coded.bytes.size(); ++len) {
        std::vector<uint8_t> cut(coded.bytes.begin(), coded.bytes.begin() + len);
        bool overran = false;
        decode_symbols(cut, s, 2, 12, &overran);
        const size_t missing = coded.bytes.size() - len;
        if (missing > kMaxImplicitZeroBytes) {
            EXPECT_TRUE(overran) << "length " << len;
        }
        if (missing == 0) {
            EXPECT_FALSE(overran);
        }
    }
}

TEST(ArithmeticDecoder, GarbageInputTerminates) {
    BitSource src(0.5, 13);
    std::vector<Symbol> shape;
    for (int i = 0; i < 2000; ++i) {
        if (i % 11 == 0) shape.push_back({-1, 0, 32});
        else shape.push_back({static_cast<int>(i % 4), 0, 1});
    }
    for (int trial = 0; trial < 300; ++trial) {
        const size_t size = src.next_u32() % 600;
        std::vector<uint8_t> garbage(size);
        for (auto& g : garbage) g = static_cast<uint8_t>(src.next_u32());
        if (trial % 3 == 0) std::fill(garbage.begin(), garbage.end(), 0xFF);
        bool overran = false;
        const auto decoded = decode_symbols(garbage, shape, 4, 12, &overran);
        EXPECT_EQ(decoded.size(), shape.size());
        // 2000 symbols need far more than 600 bytes' worth of 1/2-probability decisions.
        if (size < 100) {
            EXPECT_TRUE(overran);
        }
    }
}

// The header's raw bit, read literally: range >>= 1, a one takes the upper half (code >= range,
// which then loses it), then the byte shifts while range < 2^24; bytes past the end read as 0.
struct LiteralRawReader {
    const std::vector<uint8_t>& bytes;
    size_t pos = 0;
    uint32_t range = 0xFFFFFFFFu, code = 0;
    explicit LiteralRawReader(const std::vector<uint8_t>& b) : bytes(b) {
        for (int i = 0; i < 4; ++i) code = (code << 8) | next();
    }
    uint32_t next() { return pos < bytes.size() ? bytes[pos++] : 0u; }
    uint32_t bits(int count) {
        uint32_t value = 0;
        for (int i = 0; i < count; ++i) {
            range >>= 1;
            const bool one = code >= range;
            if (one) code -= range;
            value = (value << 1) | uint32_t(one);
            while (range < (uint32_t{1} << 24)) {
                range <<= 8;
                code = (code << 8) | next();
            }
        }
        return value;
    }
};

// decode_bits_raw takes runs of bits between byte shifts at once (unrolled, without branches):
// every count from any state gives the bits of the literal reading, on random bytes (which is
// what coded raw bits are) and on runs of 0xFF (where code exceeds range); each read starts where
// the literal one left off.
TEST(ArithmeticDecoder, RawBitsEqualTheLiteralReading) {
    BitSource src(0.5, 29);
    for (int trial = 0; trial < 200; ++trial) {
        std::vector<uint8_t> bytes(src.next_u32() % 400);
        for (auto& b : bytes) b = static_cast<uint8_t>(trial % 5 == 0 ? 0xFF : src.next_u32());
        ArithmeticDecoder decoder(bytes.data(), bytes.size());
        LiteralRawReader literal(bytes);
        for (int read = 0; read < 300; ++read) {
            const int count = int(src.next_u32() % 33);
            ASSERT_EQ(decoder.decode_bits_raw(count), literal.bits(count)) << "trial " << trial << ", read " << read;
        }
    }
}

TEST(ArithmeticDecoder, DecodingPastTheEndOfAValidStreamIsReported) {
    const std::vector<Symbol> s = bernoulli(5000, 0.5, 21);
    const Coded coded = encode_symbols(s, 1, 12);
    std::vector<Symbol> longer = s;
    longer.resize(s.size() + 200, Symbol{0, 0, 1});
    bool overran = false;
    decode_symbols(coded.bytes, longer, 1, 12, &overran);
    EXPECT_TRUE(overran);
}

TEST(ArithmeticEncoder, BytesSoFarTracksOutputAndEncoderIsReusable) {
    ArithmeticEncoder enc;
    BitModel m;
    const std::vector<Symbol> s = bernoulli(20000, 0.5, 9);
    for (const Symbol& x : s) enc.encode(x.value != 0, m);
    const size_t so_far = enc.bytes_so_far();
    const std::vector<uint8_t> first = enc.finish();
    EXPECT_GE(first.size(), so_far);
    EXPECT_LE(first.size(), so_far + 4);
    EXPECT_EQ(enc.bytes_so_far(), 0u);
    BitModel m2;
    for (const Symbol& x : s) enc.encode(x.value != 0, m2);
    EXPECT_EQ(enc.finish(), first);
}

}  // namespace
}  // namespace amc
