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
constexpr int kMinSymbolsPerValue = 7;  // as in the .amq leaf field
constexpr uint64_t kMaxName = 1024, kMaxComponents = 1024;

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

std::vector<uint8_t> temporal_payload(const Field& field, const Field& before, const ForestFieldFrame& frame) {
    std::vector<uint8_t> out;
    put_varint(out, field.name.size());
    out.insert(out.end(), field.name.begin(), field.name.end());
    out.push_back(uint8_t(field.type));
    put_varint(out, field.components);
    const uint32_t comps = field.components;
    const uint64_t mask = word_mask(field.type);
    const int top = word_bits(field.type) - 1;
    FloatResidualModels models(kTemporalContexts);
    ArithmeticEncoder encoder;
    for (size_t i = 0; i < frame.prev_leaf.size(); ++i)
        for (uint32_t c = 0; c < comps; ++c) {
            const uint64_t d = (word_of(field, i * comps + c) - word_of(before, frame.prev_leaf[i] * comps + c)) & mask;
            const bool negative = (d >> top) & 1;
            encode_signed_residual(encoder, models.context(frame.relation[i] * 4 + int(std::min<uint32_t>(c, 3))), negative,
                                   negative ? (~d + 1) & mask : d);
        }
    const std::vector<uint8_t> stream = encoder.finish();
    out.insert(out.end(), stream.begin(), stream.end());
    return out;
}

Field read_temporal(const uint8_t* data, size_t size, const ForestFieldFrame& frame, uint64_t max_values) {
    PayloadReader in(data, size, "leaf field");
    Field f;
    f.association = FieldAssociation::cell;
    const uint64_t name_size = in.varint();
    AMC_REQUIRE(name_size >= 1 && name_size <= kMaxName && name_size <= in.remaining(), corrupt,
                "leaf field: a name of " + std::to_string(name_size) + " bytes");
    f.name.assign(reinterpret_cast<const char*>(in.bytes(name_size)), size_t(name_size));
    const std::string what = "leaf field \"" + f.name + "\"";
    const uint8_t type = in.u8();
    AMC_REQUIRE(type <= uint8_t(FieldType::float64), corrupt, what + ": unknown type " + std::to_string(type));
    f.type = FieldType(type);
    const uint64_t comps = in.varint();
    AMC_REQUIRE(comps >= 1 && comps <= kMaxComponents, corrupt, what + ": " + std::to_string(comps) + " components");
    f.components = uint32_t(comps);
    const Field* before = previous_field(frame, f.name);
    AMC_REQUIRE(before && before->type == f.type && before->components == f.components, corrupt,
                what + ": coded against the frame before, which has no field of that name, type and components");
    const uint64_t values = uint64_t(frame.prev_leaf.size()) * comps;
    AMC_REQUIRE(values <= max_values, limit_exceeded,
                what + ": " + std::to_string(values) + " values, more than the limit " + std::to_string(max_values));
    AMC_REQUIRE(values <= max_decodable_symbols(in.remaining()) / kMinSymbolsPerValue, corrupt,
                what + ": " + std::to_string(values) + " values do not fit in " + std::to_string(in.remaining()) + " bytes");
    const bool is_float = is_float_type(f.type);
    if (is_float) f.values.resize(values);
    else f.integers.resize(values);
    const uint64_t mask = word_mask(f.type);
    FloatResidualModels models(kTemporalContexts);
    ArithmeticDecoder decoder(in.rest(), in.remaining());
    uint64_t bad_range = 0;
    for (size_t i = 0; i < frame.prev_leaf.size(); ++i)
        for (uint32_t c = 0; c < comps; ++c) {
            bool negative;
            uint64_t magnitude;
            decode_signed_residual(decoder, models, models.context(frame.relation[i] * 4 + int(std::min<uint32_t>(c, 3))), negative,
                                   magnitude);
            const uint64_t p = word_of(*before, frame.prev_leaf[i] * comps + c);
            const uint64_t w = (negative ? p - magnitude : p + magnitude) & mask;
            const size_t k = i * comps + c;
            if (is_float) {
                f.values[k] = from_ordered_bits(w, precision_of(f.type));
            } else {
                f.integers[k] = int64_t(w);
                bad_range += !integer_in_range(f.integers[k], f.type);
            }
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
