// Forest series leaf fields (docs/FORMAT.md 7.12).
#include "series/forest_fields.h"

#include "coding/field_words.h"
#include "coding/geometry/float_coder.h"
#include "common/check.h"
#include "octree/octree_leaf_data.h"

#include <algorithm>

namespace amc {

namespace {

constexpr int kTemporalContexts = 12;  // relation (3) x component (0, 1, 2, 3 and more)

uint64_t morton(const Octant& o, int dim) {
    uint64_t key = 0;
    for (int b = octree_root_log2(dim) - 1; b >= 0; --b) {
        if (dim == 3) key = (key << 1) | ((uint32_t(o.z) >> b) & 1);
        key = (key << 1) | ((uint32_t(o.y) >> b) & 1);
        key = (key << 1) | ((uint32_t(o.x) >> b) & 1);
    }
    return key;
}

const Field* previous_field(const ForestFieldFrame& frame, const std::string& name) {
    if (!frame.prev) return nullptr;
    for (const Field& f : frame.prev->leaf_data)
        if (f.name == name) return &f;
    return nullptr;
}

int temporal_context(const ForestFieldFrame& frame, size_t leaf, uint32_t component) {
    return frame.relation[leaf] * 4 + int(std::min<uint32_t>(component, 3));
}

std::vector<uint8_t> temporal_payload(const Field& field, const Field& before, const ForestFieldFrame& frame) {
    std::vector<uint8_t> out;
    write_leaf_field_head(field, out);
    const uint32_t comps = field.components;
    FloatResidualModels models(kTemporalContexts);
    ArithmeticEncoder encoder;
    for (size_t i = 0; i < frame.prev_leaf.size(); ++i)
        for (uint32_t c = 0; c < comps; ++c)
            encode_word(encoder, models.context(temporal_context(frame, i, c)), field.type, word_of(field, i * comps + c),
                        word_of(before, frame.prev_leaf[i] * comps + c));
    const std::vector<uint8_t> stream = encoder.finish();
    out.insert(out.end(), stream.begin(), stream.end());
    return out;
}

Field read_temporal(const uint8_t* data, size_t size, const ForestFieldFrame& frame, uint64_t max_values) {
    PayloadReader in(data, size, "leaf field");
    Field f = read_leaf_field_head(in, "leaf field");
    const std::string what = field_what(f.name);
    const Field* before = previous_field(frame, f.name);
    AMC_REQUIRE(before && before->type == f.type && before->components == f.components, corrupt,
                what + ": coded against the frame before, which has no field of that name, type and components");
    size_leaf_field(f, frame.prev_leaf.size(), max_values, in.remaining());
    const uint32_t comps = f.components;
    FloatResidualModels models(kTemporalContexts);
    ArithmeticDecoder decoder(in.rest(), in.remaining());
    uint64_t bad_range = 0;
    for (size_t i = 0; i < frame.prev_leaf.size(); ++i)
        for (uint32_t c = 0; c < comps; ++c) {
            const uint64_t w = decode_word(decoder, models, models.context(temporal_context(frame, i, c)), f.type,
                                           word_of(*before, frame.prev_leaf[i] * comps + c));
            bad_range += !set_word(f, i * comps + c, w);
        }
    AMC_REQUIRE(!decoder.overran(), truncated, what + ": the values run past the end of the field");
    AMC_REQUIRE(!models.saw_invalid_symbol(), corrupt, what + ": an invalid residual");
    AMC_REQUIRE(bad_range == 0, corrupt, what + ": " + std::to_string(bad_range) + " values out of the type's range");
    return f;
}

}  // namespace

ForestFieldFrame::ForestFieldFrame(const OctreeForest* p, const OctreeForest& n) : prev(p), next(&n) {
    if (!prev) return;
    const int dim = n.dim();
    prev_leaf.resize(n.leaves.size());
    relation.resize(n.leaves.size());
    std::vector<uint64_t> keys(prev->leaves.size());
    for (size_t i = 0; i < keys.size(); ++i) keys[i] = morton(prev->leaves[i], dim);
    for (uint32_t t = 0; t < n.tree_count(); ++t) {
        const auto begin = keys.begin() + std::ptrdiff_t(prev->tree_offsets[t]);
        const auto end = keys.begin() + std::ptrdiff_t(prev->tree_offsets[t + 1]);
        for (uint64_t i = n.tree_offsets[t]; i < n.tree_offsets[t + 1]; ++i) {
            // The last previous leaf starting at or before the leaf's first corner (every tree
            // starts with a leaf at key 0).
            const uint64_t j = uint64_t(std::upper_bound(begin, end, morton(n.leaves[i], dim)) - keys.begin()) - 1;
            prev_leaf[i] = j;
            const int a = prev->leaves[j].level, b = n.leaves[i].level;
            relation[i] = a == b ? 0 : b > a ? 1 : 2;
        }
    }
}

void encode_forest_field(const Field& field, const ForestFieldFrame& frame, std::vector<uint8_t>& out) {
    std::vector<uint8_t> payload = write_leaf_field(field, frame.next->leaves);
    ForestFieldMode mode = ForestFieldMode::spatial;
    const Field* before = previous_field(frame, field.name);
    if (before && before->type == field.type && before->components == field.components) {
        std::vector<uint8_t> temporal = temporal_payload(field, *before, frame);
        if (temporal.size() < payload.size()) {
            payload = std::move(temporal);
            mode = ForestFieldMode::temporal;
        }
    }
    out.push_back(uint8_t(mode));
    put_varint(out, payload.size());
    out.insert(out.end(), payload.begin(), payload.end());
}

Field decode_forest_field(PayloadReader& in, const ForestFieldFrame& frame, uint64_t max_values) {
    const uint8_t mode = in.u8();
    AMC_REQUIRE(mode <= uint8_t(ForestFieldMode::temporal), corrupt, "leaf field: unknown mode " + std::to_string(mode));
    const uint64_t length = in.varint();
    AMC_REQUIRE(length <= in.remaining(), truncated, "leaf field: longer than the frame");
    const uint8_t* data = in.bytes(length);
    if (mode == uint8_t(ForestFieldMode::spatial)) return read_leaf_field(data, size_t(length), frame.next->leaves, max_values);
    AMC_REQUIRE(frame.prev != nullptr, corrupt, "leaf field: coded against the frame before in a keyframe");
    return read_temporal(data, size_t(length), frame, max_values);
}

}  // namespace amc
