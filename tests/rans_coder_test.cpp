// Tests of the static rANS coder and the raw bit stream: round trips, code length against the
// table's entropy, golden bytes, and truncated or corrupt input.
#include "coding/entropy/rans_coder.h"

#include <amc/mesh.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

namespace amc {
namespace {

// Symbols drawn from a geometric-like distribution over `alphabet` symbols (std::mt19937's
// sequence is fixed by the standard).
std::vector<int> skewed_symbols(size_t n, int alphabet, uint32_t seed) {
    std::mt19937 rng(seed);
    std::vector<int> out;
    for (size_t i = 0; i < n; ++i) {
        int s = 0;
        while (s + 1 < alphabet && (rng() & 3) != 0) ++s;  // P(s) ~ (3/4)^s / 4
        out.push_back(s);
    }
    return out;
}

// The symbols' counts, and one more of symbol 0 (a table needs one symbol at least).
std::vector<uint64_t> counts_of(const std::vector<int>& symbols, int alphabet) {
    std::vector<uint64_t> counts(size_t(alphabet), 0);
    counts[0] = 1;
    for (int s : symbols) ++counts[size_t(s)];
    return counts;
}

TEST(RansTable, NormalisesCountsToTheScale) {
    const RansTable t = RansTable::from_counts({5, 0, 1000000, 1, 3});
    uint64_t sum = 0;
    for (uint32_t f : t.frequencies()) sum += f;
    EXPECT_EQ(sum, kRansScale);
    EXPECT_EQ(t.frequency(1), 0u);
    EXPECT_GE(t.frequency(0), 1u);
    EXPECT_GE(t.frequency(3), 1u);
    EXPECT_LE(t.frequency(2), kRansMaxFrequency);
    EXPECT_GT(t.frequency(2), 4000u);
    // One symbol alone may not take the whole scale.
    const RansTable single = RansTable::from_counts({0, 0, 7});
    EXPECT_EQ(single.frequency(2), kRansMaxFrequency);
    EXPECT_EQ(single.frequency(1), 1u);
    const RansTable only = RansTable::from_counts({9});
    EXPECT_EQ(only.size(), 2);
    EXPECT_EQ(only.frequency(0), kRansMaxFrequency);
    EXPECT_THROW(RansTable::from_counts({}), Error);
    EXPECT_THROW(RansTable::from_counts({0, 0}), Error);
    EXPECT_THROW(RansTable::from_counts(std::vector<uint64_t>(kRansMaxSymbols + 1, 1)), Error);
}

// The frequencies as the normalisation was first written (the format's tables, so the bytes, rest
// on them): floor(c M / total), at least 1; the deficit added one at a time to the symbols in order
// of count (the lower symbol first on ties), round and round; the excess taken one at a time from
// the first of the largest frequencies.
std::vector<uint32_t> reference_frequencies(const std::vector<uint64_t>& counts) {
    uint64_t total = 0;
    size_t used = 0;
    for (uint64_t c : counts) {
        total += c;
        used += c != 0;
    }
    std::vector<uint32_t> f(counts.size(), 0);
    int64_t sum = 0;
    for (size_t s = 0; s < counts.size(); ++s) {
        if (counts[s] == 0) continue;
        f[s] = uint32_t(std::max<uint64_t>(1, (counts[s] << kRansScaleBits) / total));
        sum += f[s];
    }
    std::vector<size_t> by_count(counts.size());
    for (size_t s = 0; s < by_count.size(); ++s) by_count[s] = s;
    std::stable_sort(by_count.begin(), by_count.end(), [&](size_t a, size_t b) { return counts[a] > counts[b]; });
    for (size_t i = 0; sum < int64_t(kRansScale); i = (i + 1) % used) {
        if (f[by_count[i]] < kRansMaxFrequency) {
            ++f[by_count[i]];
            ++sum;
        }
    }
    while (sum > int64_t(kRansScale)) {
        --f[size_t(std::max_element(f.begin(), f.end()) - f.begin())];
        --sum;
    }
    return f;
}

// Tables of a few common symbols and long tails of rare ones (many raised to 1: an excess to take
// back, with ties among the largest), of near-uniform counts (a deficit, ties everywhere), and of
// every size up to the largest alphabet: the reference's frequencies.
TEST(RansTable, FrequenciesAreTheReferenceNormalisations) {
    std::mt19937 rng(41);
    for (int trial = 0; trial < 400; ++trial) {
        const size_t size = 2 + rng() % (trial % 2 == 0 ? 300 : size_t(kRansMaxSymbols) - 1);
        std::vector<uint64_t> counts(size, 0);
        for (size_t s = 0; s < size; ++s) {
            switch (trial % 4) {
                case 0: counts[s] = rng() % 3 == 0 ? 0 : (s < 4 ? 100000 + rng() % 1000 : rng() % 3); break;
                case 1: counts[s] = 500 + rng() % 7; break;
                case 2: counts[s] = s % 5 == 0 ? 4096 : rng() % 2; break;
                default: counts[s] = rng() % 4 == 0 ? rng() % 100000 : 0; break;
            }
        }
        counts[rng() % size] += 1;  // one used symbol at least
        size_t used = 0;
        for (uint64_t c : counts) used += c != 0;
        if (used < 2 || used >= kRansScale) continue;
        ASSERT_EQ(RansTable::for_encoding(counts).frequencies(), reference_frequencies(counts)) << "trial " << trial;
    }
}

TEST(RansTable, EncodersTableHasTheSameFrequenciesAndStarts) {
    const std::vector<std::vector<uint64_t>> cases = {{5, 0, 1000000, 1, 3}, {0, 0, 7}, {9}, counts_of(skewed_symbols(5000, 60, 5), 60)};
    for (const std::vector<uint64_t>& counts : cases) {
        const RansTable both = RansTable::from_counts(counts), encoding = RansTable::for_encoding(counts);
        ASSERT_EQ(encoding.size(), both.size());
        for (int s = 0; s < both.size(); ++s) {
            EXPECT_EQ(encoding.frequency(s), both.frequency(s)) << s;
            EXPECT_EQ(encoding.start(s), both.start(s)) << s;
        }
    }
}

TEST(RansTable, AssignChecksTheFrequencies) {
    RansTable t;
    EXPECT_TRUE(t.assign({kRansScale - 1, 1}));
    EXPECT_FALSE(t.assign({kRansScale}));                 // one symbol with the whole scale
    EXPECT_FALSE(t.assign({kRansScale - 2, 1}));          // sum too small
    EXPECT_FALSE(t.assign({kRansScale - 1, 2}));          // sum too large
    EXPECT_FALSE(t.assign({}));
    EXPECT_EQ(t.size(), 2);  // unchanged by the refused ones
}

TEST(Rans, RoundTripsSeveralTablesInterleaved) {
    for (size_t n : {size_t(0), size_t(1), size_t(2), size_t(3), size_t(1000), size_t(100000)}) {
        const std::vector<int> a = skewed_symbols(n, 40, 1), b = skewed_symbols(n, 7, 2);
        const RansTable ta = RansTable::from_counts(counts_of(a, 40)), tb = RansTable::from_counts(counts_of(b, 7));
        RansEncoder encoder;
        for (size_t i = 0; i < n; ++i) {
            encoder.put(ta, a[i]);
            encoder.put(tb, b[i]);
        }
        const std::vector<uint8_t> bytes = encoder.finish();
        RansDecoder decoder(bytes.data(), bytes.size());
        for (size_t i = 0; i < n; ++i) {
            ASSERT_EQ(decoder.get(ta), a[i]) << n << " " << i;
            ASSERT_EQ(decoder.get(tb), b[i]) << n << " " << i;
        }
        EXPECT_TRUE(decoder.ended_cleanly()) << n;
    }
}

TEST(Rans, BackwardEncoderMakesTheQueuedEncodersStream) {
    for (size_t n : {size_t(0), size_t(1), size_t(2), size_t(3), size_t(1001), size_t(50000)}) {
        const std::vector<int> a = skewed_symbols(n, 40, 5), b = skewed_symbols(n, 7, 6);
        const RansTable ta = RansTable::from_counts(counts_of(a, 40)), tb = RansTable::from_counts(counts_of(b, 7));
        RansEncoder queued;
        for (size_t i = 0; i < n; ++i) {
            queued.put(ta, a[i]);
            if (i % 3 != 0) queued.put(tb, b[i]);  // an odd count of symbols too
        }
        const size_t count = queued.symbols();
        RansBackwardEncoder backward(count);
        for (size_t i = n; i-- > 0;) {
            if (i % 3 != 0) backward.put(tb, b[i]);
            backward.put(ta, a[i]);
        }
        EXPECT_EQ(backward.finish(), queued.finish()) << n;
    }
    const RansTable t = RansTable::from_counts({3, 1});
    RansBackwardEncoder short_of_one(2);
    short_of_one.put(t, 0);
    EXPECT_THROW(short_of_one.finish(), Error);
    RansBackwardEncoder one(1);
    one.put(t, 0);
    EXPECT_THROW(one.put(t, 1), Error);
}

TEST(Rans, BackwardEncodersPutAllMakesThePutStream) {
    // put_all in runs of every parity of length and stream position, mixed with single puts.
    for (size_t n : {size_t(0), size_t(1), size_t(2), size_t(5), size_t(1000), size_t(30001)}) {
        const std::vector<int> a = skewed_symbols(n, 40, 7);
        const RansTable t = RansTable::from_counts(counts_of(a, 40));
        RansBackwardEncoder one_by_one(n), in_runs(n);
        for (size_t i = n; i-- > 0;) one_by_one.put(t, a[i]);
        size_t left = n;
        for (size_t run = 0; left > 0; ++run) {
            const size_t count = std::min(left, run % 4 == 3 ? size_t(1) : run + 2);
            const size_t first = left - count;
            in_runs.put_all(count, [&](size_t j) -> const RansTable::Coding& { return t.coding(a[first + j]); });
            left = first;
        }
        EXPECT_EQ(in_runs.finish(), one_by_one.finish()) << n;
    }
    const RansTable t = RansTable::from_counts({3, 1});
    RansBackwardEncoder two(2);
    EXPECT_THROW(two.put_all(3, [&](size_t) -> const RansTable::Coding& { return t.coding(0); }), Error);
}

TEST(Rans, EncoderStepWithoutDivisionIsTheDivision) {
    // RansTable::Coding's reciprocal step against the definition, for every frequency, at the ends
    // of the states the encoder codes from ([x_max / 256, x_max) after renormalisation) and between.
    std::mt19937_64 rng(11);
    for (uint32_t f = 1; f < kRansScale; ++f) {
        const uint32_t start = kRansScale - f;
        const RansTable::Coding c = RansTable::coding_of(start, f);
        ASSERT_EQ(c.x_max, ((kRansLow >> kRansScaleBits) << 8) * f);
        std::vector<uint32_t> xs = {c.x_max - 1, c.x_max / 256, c.x_max / 256 + 1, c.x_max / 2};
        for (int i = 0; i < 64; ++i) xs.push_back(c.x_max / 256 + uint32_t(rng() % (c.x_max - c.x_max / 256)));
        for (uint32_t x : xs) ASSERT_EQ(c.code(x), (x / f) * kRansScale + x % f + start) << f << " " << x;
    }
}

TEST(Rans, CodeLengthIsTheTablesEntropy) {
    const std::vector<int> s = skewed_symbols(200000, 60, 3);
    const RansTable t = RansTable::from_counts(counts_of(s, 60));
    double ideal = 0;
    RansEncoder encoder;
    for (int x : s) {
        encoder.put(t, x);
        ideal += t.cost_bits(x);
    }
    const double bits = 8.0 * double(encoder.finish().size());
    EXPECT_LT(bits, ideal * 1.001 + 64);  // the two states' 8 bytes and a little rounding
    EXPECT_GT(bits, ideal * 0.999);
}

TEST(Rans, GoldenBytes) {
    // Pins the stream layout of FORMAT.md 5.6: states first, little endian, then the bytes.
    RansTable t;
    ASSERT_TRUE(t.assign({2048, 1024, 1023, 1}));
    RansEncoder encoder;
    for (int s : {0, 1, 2, 3, 0, 0, 3, 2, 1, 0}) encoder.put(t, s);
    const std::vector<uint8_t> bytes = encoder.finish();
    const std::vector<uint8_t> expected = {0x1b, 0x95, 0x00, 0x02, 0xff, 0xbb, 0x00, 0x02, 0xff, 0x14, 0x10, 0x00};
    EXPECT_EQ(bytes, expected);
    RansEncoder empty;
    EXPECT_EQ(empty.finish(), (std::vector<uint8_t>{0, 0, 0x80, 0, 0, 0, 0x80, 0}));
}

TEST(Rans, TruncatedOrCorruptInputNeverHangsAndIsNoticed) {
    const std::vector<int> s = skewed_symbols(5000, 20, 4);
    const RansTable t = RansTable::from_counts(counts_of(s, 20));
    RansEncoder encoder;
    for (int x : s) encoder.put(t, x);
    const std::vector<uint8_t> bytes = encoder.finish();
    for (size_t cut : {size_t(0), size_t(3), size_t(8), bytes.size() / 2, bytes.size() - 1}) {
        RansDecoder decoder(bytes.data(), cut);
        for (size_t i = 0; i < s.size(); ++i) decoder.get(t);
        EXPECT_FALSE(decoder.ended_cleanly()) << cut;
        EXPECT_TRUE(decoder.overran()) << cut;
    }
    std::vector<uint8_t> zeros(64, 0);  // a state below L
    RansDecoder decoder(zeros.data(), zeros.size());
    for (int i = 0; i < 1000; ++i) decoder.get(t);
    EXPECT_TRUE(decoder.overran());
    std::vector<uint8_t> flipped = bytes;
    flipped[bytes.size() / 2] ^= 0x10;
    RansDecoder damaged(flipped.data(), flipped.size());
    bool same = true;
    for (size_t i = 0; i < s.size(); ++i) same = damaged.get(t) == s[i] && same;
    EXPECT_FALSE(same && damaged.ended_cleanly());
}

TEST(RawBits, RoundTripAndOverrun) {
    std::mt19937_64 rng(5);
    std::vector<std::pair<uint64_t, int>> values;
    RawBitWriter writer;
    for (int i = 0; i < 10000; ++i) {
        const int count = int(rng() % 58);
        const uint64_t v = count == 0 ? 0 : rng() & (~uint64_t{0} >> (64 - count));
        values.emplace_back(v, count);
        writer.put(v | (count < 57 ? uint64_t{1} << count : 0), count);  // bits above count are ignored
    }
    const size_t bits = writer.bits();
    const std::vector<uint8_t> bytes = writer.finish();
    EXPECT_EQ(bytes.size(), (bits + 7) / 8);
    RawBitReader reader(bytes.data(), bytes.size());
    for (auto [v, count] : values) ASSERT_EQ(reader.get(count), v);
    EXPECT_TRUE(reader.ended_cleanly());
    reader.get(9);
    EXPECT_TRUE(reader.overran());
    RawBitWriter small;
    small.put(0x5, 3);
    small.put(0x1ff, 9);
    EXPECT_EQ(small.finish(), (std::vector<uint8_t>{0xfd, 0x0f}));
}

}  // namespace
}  // namespace amc
