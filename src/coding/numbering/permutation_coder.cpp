// Permutations coded as ranks among the values not used yet, each relative to the rank that
// continues the previous value, or as a walk over a graph of the elements: see permutation_coder.h.
#include "coding/numbering/permutation_coder.h"

#include "common/bits.h"

#include <algorithm>
#include <array>
#include <string>

namespace amc {

namespace {

constexpr int kLengthTreeLevels = 5;  // bit lengths 1..32 of a rank difference's magnitude

// The values 0..n-1 not used yet, with rank and select in O(log n) (a Fenwick tree of counts).
class UnusedValues {
public:
    explicit UnusedValues(uint32_t n) : tree_(size_t(n) + 1), remaining_(n) {
        for (uint32_t i = 1; i <= n; ++i) tree_[i] = i & (~i + 1);  // every value present: lowbit(i)
        top_ = 1;
        while (top_ * 2 <= n) top_ *= 2;
    }
    uint32_t remaining() const { return remaining_; }
    // Number of unused values below v.
    uint32_t count_below(uint32_t v) const {
        uint32_t sum = 0;
        for (uint32_t i = v; i > 0; i &= i - 1) sum += tree_[i];
        return sum;
    }
    // The unused value of rank r (r < remaining()).
    uint32_t select(uint32_t r) const {
        uint32_t position = 0;
        for (uint32_t step = top_; step > 0; step >>= 1) {
            const uint32_t next = position + step;
            if (next < tree_.size() && tree_[next] <= r) {
                position = next;
                r -= tree_[next];
            }
        }
        return position;  // the value is position (1-based tree index position + 1, minus 1)
    }
    void remove(uint32_t v) {
        for (size_t i = size_t(v) + 1; i < tree_.size(); i += i & (~i + 1)) --tree_[i];
        --remaining_;
    }

private:
    std::vector<uint32_t> tree_;
    uint32_t remaining_;
    uint32_t top_ = 0;
};

struct PermutationModels {
    std::array<BitModel, 2> zero{};  // context: the previous difference was zero
    BitModel sign{};
    std::array<BitModel, 1 << kLengthTreeLevels> length{};
    std::array<BitModel, 33> high{};  // the bit below the leading one, per bit length
};

// Walks a permutation as rank differences: for the k-th element, with m values left, the rank
// that continues the previous value is p (0 after the largest), and the element's rank is
// (p + d) mod m. `step(d, m)` maps d to the element's rank difference on both sides.
class RankWalk {
public:
    explicit RankWalk(uint32_t n) : unused_(n) {}
    uint32_t remaining() const { return unused_.remaining(); }
    uint32_t predicted_rank() const {
        if (!started_) return 0;
        const uint32_t p = unused_.count_below(previous_);
        return p == unused_.remaining() ? 0 : p;
    }
    uint32_t difference_of(uint32_t value) const {
        const uint32_t m = unused_.remaining();
        return uint32_t((uint64_t(unused_.count_below(value)) + m - predicted_rank()) % m);
    }
    uint32_t value_of(uint32_t difference) const {
        const uint32_t m = unused_.remaining();
        return unused_.select(uint32_t((uint64_t(predicted_rank()) + difference) % m));
    }
    void take(uint32_t value) {
        unused_.remove(value);
        previous_ = value;
        started_ = true;
    }

private:
    UnusedValues unused_;
    uint32_t previous_ = 0;
    bool started_ = false;
};

void encode_difference(ArithmeticEncoder& encoder, PermutationModels& models, PermutationMethod method, uint32_t d,
                       uint32_t m, bool& previous_zero) {
    if (method == PermutationMethod::uniform) {
        // Truncated binary: the first u values take k bits, the others k + 1.
        const int k = bit_length(m) - 1;
        const uint64_t u = (uint64_t{1} << (k + 1)) - m;
        if (d < u) {
            encoder.encode_bits_raw(d, k);
        } else {
            encoder.encode_bits_raw(uint32_t(d + u), k + 1);
        }
        return;
    }
    const bool zero = d == 0;
    encoder.encode(zero, models.zero[previous_zero]);
    previous_zero = zero;
    if (zero) return;
    const bool negative = d > m - d;
    const uint32_t magnitude = negative ? m - d : d;
    encoder.encode(negative, models.sign);
    const int length = bit_length(magnitude);
    int node = 1;
    for (int i = kLengthTreeLevels - 1; i >= 0; --i) {
        const int bit = ((length - 1) >> i) & 1;
        encoder.encode(bit, models.length[node]);
        node = 2 * node + bit;
    }
    if (length >= 2) {
        encoder.encode((magnitude >> (length - 2)) & 1, models.high[length]);
        encoder.encode_bits_raw(magnitude & ((uint32_t{1} << (length - 2)) - 1), length - 2);
    }
}

// Returns false on a difference no encoder writes.
bool decode_difference(ArithmeticDecoder& decoder, PermutationModels& models, PermutationMethod method, uint32_t m,
                       bool& previous_zero, uint32_t& d) {
    if (method == PermutationMethod::uniform) {
        const int k = bit_length(m) - 1;
        const uint64_t u = (uint64_t{1} << (k + 1)) - m;
        uint64_t value = decoder.decode_bits_raw(k);
        if (value >= u) value = ((value << 1) | decoder.decode_bits_raw(1)) - u;
        d = uint32_t(value);
        return value < m;
    }
    const bool zero = decoder.decode(models.zero[previous_zero]);
    previous_zero = zero;
    if (zero) {
        d = 0;
        return true;
    }
    const bool negative = decoder.decode(models.sign);
    int node = 1;
    for (int i = 0; i < kLengthTreeLevels; ++i) node = 2 * node + int(decoder.decode(models.length[node]));
    const int length = node - (1 << kLengthTreeLevels) + 1;
    uint32_t magnitude = 1;
    if (length >= 2) {
        magnitude = (magnitude << 1) | uint32_t(decoder.decode(models.high[length]));
        const uint32_t low = decoder.decode_bits_raw(length - 2);
        magnitude = uint32_t((uint64_t(magnitude) << (length - 2)) | low);
    }
    if (magnitude >= m) return false;
    d = negative ? m - magnitude : magnitude;
    return true;
}

constexpr int kCandidateModels = 8;

struct WalkModels {
    std::array<BitModel, 2> hit{};                        // context: the previous element was a hit
    std::array<BitModel, kCandidateModels> candidate{};  // unary over the candidates' positions
    PermutationModels miss;
};

// Method 3: the sequence in the caller's order, each element predicted to be one of the unused
// neighbours of the one before it (a caller's order that walks the mesh costs a few bits each);
// other elements as rank differences among all unused ones.
class SequenceWalk {
public:
    SequenceWalk(const Graph& graph, uint32_t n) : graph_(graph), used_(n, false), ranks_(n) {}
    // The unused neighbours of the previous element, in increasing order.
    const std::vector<uint32_t>& candidates() {
        candidates_.clear();
        if (started_) {
            for (uint32_t k = graph_.start[previous_]; k < graph_.start[previous_ + 1]; ++k)
                if (!used_[graph_.neighbors[k]]) candidates_.push_back(graph_.neighbors[k]);
        }
        return candidates_;
    }
    RankWalk& ranks() { return ranks_; }
    bool started() const { return started_; }
    void take(uint32_t value) {
        used_[value] = true;
        ranks_.take(value);
        previous_ = value;
        started_ = true;
    }

private:
    const Graph& graph_;
    std::vector<bool> used_;
    RankWalk ranks_;
    std::vector<uint32_t> candidates_;
    uint32_t previous_ = 0;
    bool started_ = false;
};

}  // namespace

void encode_permutation(ArithmeticEncoder& encoder, PermutationMethod method, const std::vector<uint32_t>& sequence) {
    if (method == PermutationMethod::identity) return;
    PermutationModels models;
    RankWalk walk(uint32_t(sequence.size()));
    bool previous_zero = false;
    for (uint32_t value : sequence) {
        encode_difference(encoder, models, method, walk.difference_of(value), walk.remaining(), previous_zero);
        walk.take(value);
    }
}

std::vector<uint32_t> decode_permutation(ArithmeticDecoder& decoder, PermutationMethod method, uint32_t n,
                                         const char* what) {
    std::vector<uint32_t> sequence(n);
    RankWalk walk(n);
    PermutationModels models;
    bool previous_zero = false;
    for (uint32_t k = 0; k < n; ++k) {
        uint32_t d = 0;
        if (method != PermutationMethod::identity &&
            !decode_difference(decoder, models, method, walk.remaining(), previous_zero, d))
            throw Error(ErrorCode::corrupt, std::string("numbering block: corrupt ") + what + " order");
        sequence[k] = walk.value_of(d);
        walk.take(sequence[k]);
    }
    return sequence;
}

Graph vertex_graph(const std::vector<Triangle>& leaf, uint32_t vertices) {
    std::vector<std::pair<uint32_t, uint32_t>> edges;
    edges.reserve(6 * leaf.size());
    for (const Triangle& t : leaf) {
        for (int c = 0; c < 3; ++c) {
            edges.push_back({t[c], t[(c + 1) % 3]});
            edges.push_back({t[(c + 1) % 3], t[c]});
        }
    }
    std::sort(edges.begin(), edges.end());
    edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
    Graph g;
    g.start.assign(size_t(vertices) + 1, 0);
    for (auto [a, b] : edges) ++g.start[a + 1];
    for (uint32_t v = 0; v < vertices; ++v) g.start[v + 1] += g.start[v];
    for (auto [a, b] : edges) g.neighbors.push_back(b);
    return g;
}

// Triangles are neighbours when they share an edge.
Graph triangle_graph(const std::vector<Triangle>& leaf) {
    // Half-edges (a, b, triangle), sorted; the triangle across (a, b) holds (b, a).
    std::vector<std::array<uint32_t, 3>> halfedges;
    halfedges.reserve(3 * leaf.size());
    for (uint32_t t = 0; t < leaf.size(); ++t)
        for (int c = 0; c < 3; ++c) halfedges.push_back({leaf[t][c], leaf[t][(c + 1) % 3], t});
    std::sort(halfedges.begin(), halfedges.end());
    std::vector<std::pair<uint32_t, uint32_t>> pairs;
    for (const auto& [a, b, t] : halfedges) {
        const auto it = std::lower_bound(halfedges.begin(), halfedges.end(), std::array<uint32_t, 3>{b, a, 0});
        if (it != halfedges.end() && (*it)[0] == b && (*it)[1] == a) pairs.push_back({t, (*it)[2]});
    }
    std::sort(pairs.begin(), pairs.end());
    Graph g;
    g.start.assign(leaf.size() + 1, 0);
    for (auto [a, b] : pairs) ++g.start[a + 1];
    for (size_t t = 0; t < leaf.size(); ++t) g.start[t + 1] += g.start[t];
    for (auto [a, b] : pairs) g.neighbors.push_back(b);
    return g;
}

void encode_walk(ArithmeticEncoder& encoder, const Graph& graph, const std::vector<uint32_t>& sequence) {
    SequenceWalk walk(graph, uint32_t(sequence.size()));
    WalkModels models;
    bool previous_hit = false, previous_zero = false;
    for (uint32_t value : sequence) {
        const std::vector<uint32_t>& candidates = walk.candidates();
        const auto found = std::find(candidates.begin(), candidates.end(), value);
        if (!candidates.empty()) {
            const bool hit = found != candidates.end();
            encoder.encode(hit, models.hit[previous_hit]);
            previous_hit = hit;
            if (hit) {
                const size_t position = size_t(found - candidates.begin());
                for (size_t j = 0; j + 1 < candidates.size() && j <= position; ++j)
                    encoder.encode(j == position, models.candidate[std::min<size_t>(j, kCandidateModels - 1)]);
                walk.take(value);
                continue;
            }
        }
        encode_difference(encoder, models.miss, walk.started() ? PermutationMethod::adaptive : PermutationMethod::uniform,
                          walk.ranks().difference_of(value), walk.ranks().remaining(), previous_zero);
        walk.take(value);
    }
}

std::vector<uint32_t> decode_walk(ArithmeticDecoder& decoder, const Graph& graph, uint32_t n, const char* what) {
    std::vector<uint32_t> sequence(n);
    SequenceWalk walk(graph, n);
    WalkModels models;
    bool previous_hit = false, previous_zero = false;
    for (uint32_t i = 0; i < n; ++i) {
        const std::vector<uint32_t>& candidates = walk.candidates();
        if (!candidates.empty()) {
            const bool hit = decoder.decode(models.hit[previous_hit]);
            previous_hit = hit;
            if (hit) {
                size_t position = 0;
                while (position + 1 < candidates.size() &&
                       !decoder.decode(models.candidate[std::min<size_t>(position, kCandidateModels - 1)]))
                    ++position;
                sequence[i] = candidates[position];
                walk.take(sequence[i]);
                continue;
            }
        }
        uint32_t d = 0;
        if (!decode_difference(decoder, models.miss, walk.started() ? PermutationMethod::adaptive : PermutationMethod::uniform,
                               walk.ranks().remaining(), previous_zero, d))
            throw Error(ErrorCode::corrupt, std::string("numbering block: corrupt ") + what + " order");
        sequence[i] = walk.ranks().value_of(d);
        walk.take(sequence[i]);
    }
    return sequence;
}

// Differences that are all zero need no code; otherwise the smaller of the two methods.
PermutationMethod best_method(const std::vector<uint32_t>& sequence) {
    bool identity = true;
    for (uint32_t k = 0; k < sequence.size() && identity; ++k) identity = sequence[k] == k;
    if (identity) return PermutationMethod::identity;
    size_t best_size = SIZE_MAX;
    PermutationMethod best = PermutationMethod::uniform;
    for (PermutationMethod method : {PermutationMethod::uniform, PermutationMethod::adaptive}) {
        ArithmeticEncoder trial;
        encode_permutation(trial, method, sequence);
        const size_t size = trial.finish().size();
        if (size < best_size) {
            best_size = size;
            best = method;
        }
    }
    return best;
}

}  // namespace amc
