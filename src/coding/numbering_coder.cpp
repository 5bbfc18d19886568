// The numbering block: permutations coded as ranks among the values not used yet, each relative
// to the rank that continues the previous value (a caller's order that follows the canonical one
// costs almost nothing; a random one costs about log2(n!) bits).
#include "coding/numbering_coder.h"

#include "coding/arithmetic_coder.h"
#include "coding/container.h"

#include <algorithm>
#include <array>
#include <string>

namespace amc {

namespace {

// Frozen values (written to files).
enum class PermutationMethod : uint8_t { identity = 0, uniform = 1, adaptive = 2 };
enum class FaceReference : uint8_t { leaf_order = 0, lowest_vertex = 1, highest_vertex = 2 };
enum class RotationMode : uint8_t { none = 0, leaf_corners = 1, lowest_corner = 2 };

constexpr int kLengthTreeLevels = 5;  // bit lengths 1..32 of a rank difference's magnitude

int bit_length(uint32_t x) { return x == 0 ? 0 : 32 - __builtin_clz(x); }

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

// The leaf triangles in the order a face reference lists them, given the caller's vertex index of
// every leaf vertex: leaf order, or sorted by the caller's indices of their corners.
std::vector<uint32_t> reference_order(FaceReference reference, const std::vector<Triangle>& leaf,
                                      const std::vector<uint32_t>& caller_vertex) {
    std::vector<uint32_t> order(leaf.size());
    for (uint32_t t = 0; t < leaf.size(); ++t) order[t] = t;
    if (reference == FaceReference::leaf_order) return order;
    std::vector<std::array<uint32_t, 3>> keys(leaf.size());
    for (uint32_t t = 0; t < leaf.size(); ++t) {
        std::array<uint32_t, 3> key = {caller_vertex[leaf[t][0]], caller_vertex[leaf[t][1]], caller_vertex[leaf[t][2]]};
        std::sort(key.begin(), key.end());
        if (reference == FaceReference::highest_vertex) std::swap(key[0], key[2]);
        keys[t] = key;
    }
    std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return keys[a] != keys[b] ? keys[a] < keys[b] : a < b; });
    return order;
}

// The corner a rotation mode measures the caller's rotations from: 0, or the leaf triangle's
// corner with the caller's lowest vertex index.
int reference_corner(RotationMode mode, const Triangle& t, const std::vector<uint32_t>& caller_vertex) {
    if (mode != RotationMode::lowest_corner) return 0;
    int lowest = 0;
    for (int c = 1; c < 3; ++c)
        if (caller_vertex[t[c]] < caller_vertex[t[lowest]]) lowest = c;
    return lowest;
}

struct RotationModels {
    std::array<std::array<BitModel, 2>, 3> models{};  // per previous symbol: "is 0", "is 1"
};

void encode_rotations(ArithmeticEncoder& encoder, const std::vector<uint8_t>& symbols) {
    RotationModels m;
    uint8_t previous = 0;
    for (uint8_t s : symbols) {
        encoder.encode(s == 0, m.models[previous][0]);
        if (s != 0) encoder.encode(s == 1, m.models[previous][1]);
        previous = s;
    }
}

}  // namespace

std::vector<uint8_t> encode_numbering(const LeafNumbering& numbering, const std::vector<Triangle>& leaf) {
    const uint32_t vertices = uint32_t(numbering.vertex.size());
    const std::string problem = check_numbering(numbering, vertices, leaf.size());
    if (!problem.empty()) throw Error("encode: numbering does not fit the leaf mesh: " + problem);

    // Coded in the decoder's order: for leaf vertex k (triangle t), the caller's index.
    std::vector<uint32_t> caller_vertex(vertices), caller_face(leaf.size());
    std::vector<uint8_t> caller_rotation(leaf.size());
    for (uint32_t i = 0; i < vertices; ++i) caller_vertex[numbering.vertex[i]] = i;
    for (uint32_t j = 0; j < leaf.size(); ++j) {
        caller_face[numbering.face[j]] = j;
        caller_rotation[numbering.face[j]] = numbering.rotation[j];
    }
    const PermutationMethod vertex_method = best_method(caller_vertex);

    size_t best_size = SIZE_MAX;
    FaceReference face_reference = FaceReference::leaf_order;
    std::vector<uint32_t> face_sequence;
    PermutationMethod face_method = PermutationMethod::identity;
    for (FaceReference reference : {FaceReference::leaf_order, FaceReference::lowest_vertex, FaceReference::highest_vertex}) {
        const std::vector<uint32_t> order = reference_order(reference, leaf, caller_vertex);
        std::vector<uint32_t> sequence(order.size());
        for (uint32_t k = 0; k < order.size(); ++k) sequence[k] = caller_face[order[k]];
        const PermutationMethod method = best_method(sequence);
        ArithmeticEncoder trial;
        encode_permutation(trial, method, sequence);
        const size_t size = trial.finish().size();
        if (size < best_size) {
            best_size = size;
            face_reference = reference;
            face_sequence = std::move(sequence);
            face_method = method;
        }
    }

    RotationMode rotation_mode = RotationMode::none;
    std::vector<uint8_t> rotation_symbols;
    if (std::any_of(caller_rotation.begin(), caller_rotation.end(), [](uint8_t r) { return r != 0; })) {
        best_size = SIZE_MAX;
        for (RotationMode mode : {RotationMode::leaf_corners, RotationMode::lowest_corner}) {
            std::vector<uint8_t> symbols(leaf.size());
            for (uint32_t t = 0; t < leaf.size(); ++t)
                symbols[t] = uint8_t((caller_rotation[t] + 3 - reference_corner(mode, leaf[t], caller_vertex)) % 3);
            ArithmeticEncoder trial;
            encode_rotations(trial, symbols);
            const size_t size = trial.finish().size();
            if (size < best_size) {
                best_size = size;
                rotation_mode = mode;
                rotation_symbols = std::move(symbols);
            }
        }
    }

    std::vector<uint8_t> out;
    put_varint(out, vertices);
    put_varint(out, leaf.size());
    out.push_back(uint8_t(vertex_method));
    out.push_back(uint8_t(face_reference));
    out.push_back(uint8_t(face_method));
    out.push_back(uint8_t(rotation_mode));
    ArithmeticEncoder encoder;
    encode_permutation(encoder, vertex_method, caller_vertex);
    encode_permutation(encoder, face_method, face_sequence);
    if (rotation_mode != RotationMode::none) encode_rotations(encoder, rotation_symbols);
    const std::vector<uint8_t> coded = encoder.finish();
    out.insert(out.end(), coded.begin(), coded.end());
    return out;
}

LeafNumbering decode_numbering(const uint8_t* data, size_t size, const std::vector<Triangle>& leaf, uint32_t vertices) {
    PayloadReader in(data, size, "numbering block");
    if (in.varint() != vertices || in.varint() != leaf.size())
        throw Error(ErrorCode::corrupt, "numbering block: its counts do not match the leaf mesh");
    const uint8_t vertex_method = in.u8(), face_reference = in.u8(), face_method = in.u8(), rotation_mode = in.u8();
    if (vertex_method > uint8_t(PermutationMethod::adaptive) || face_method > uint8_t(PermutationMethod::adaptive) ||
        face_reference > uint8_t(FaceReference::highest_vertex) || rotation_mode > uint8_t(RotationMode::lowest_corner))
        throw Error(ErrorCode::corrupt, "numbering block: unknown method");
    ArithmeticDecoder decoder(in.rest(), in.remaining());

    const std::vector<uint32_t> caller_vertex = decode_permutation(decoder, PermutationMethod(vertex_method), vertices, "vertex");
    const std::vector<uint32_t> order = reference_order(FaceReference(face_reference), leaf, caller_vertex);
    const std::vector<uint32_t> face_sequence =
        decode_permutation(decoder, PermutationMethod(face_method), uint32_t(leaf.size()), "face");

    LeafNumbering numbering;
    numbering.vertex.resize(vertices);
    for (uint32_t k = 0; k < vertices; ++k) numbering.vertex[caller_vertex[k]] = k;
    numbering.face.resize(leaf.size());
    numbering.rotation.assign(leaf.size(), 0);
    std::vector<uint32_t> caller_face(leaf.size());
    for (uint32_t k = 0; k < order.size(); ++k) {
        numbering.face[face_sequence[k]] = order[k];
        caller_face[order[k]] = face_sequence[k];
    }
    if (rotation_mode != uint8_t(RotationMode::none)) {
        RotationModels m;
        uint8_t previous = 0;
        for (uint32_t t = 0; t < leaf.size(); ++t) {
            uint8_t s = 0;
            if (!decoder.decode(m.models[previous][0])) s = decoder.decode(m.models[previous][1]) ? 1 : 2;
            previous = s;
            numbering.rotation[caller_face[t]] =
                uint8_t((s + reference_corner(RotationMode(rotation_mode), leaf[t], caller_vertex)) % 3);
        }
    }
    if (decoder.overran()) throw Error(ErrorCode::corrupt, "numbering block is truncated or corrupt");
    return numbering;
}

}  // namespace amc
