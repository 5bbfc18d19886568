// Leaf field blocks of the .amq file (docs/FORMAT.md section 8.6).
#include "octree/octree_leaf_data.h"

#include "coding/container.h"
#include "coding/field_words.h"
#include "coding/geometry/float_coder.h"
#include "common/check.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <set>

namespace amc {

namespace {

// Contexts: component (0, 1, 2, 3 and more) x the leaf's level against the leaf before it
// (same, finer, coarser).
constexpr int kLeafFieldContexts = 12;

int value_context(uint32_t component, const Octant* before, const Octant& leaf) {
    const int step = before == nullptr || before->level == leaf.level ? 0 : leaf.level > before->level ? 1 : 2;
    return step * 4 + int(std::min<uint32_t>(component, 3));
}

}  // namespace

std::string field_what(const std::string& name) { return "leaf field \"" + name + "\""; }

size_t field_type_bytes(FieldType type) {
    switch (type) {
        case FieldType::int8: case FieldType::uint8: return 1;
        case FieldType::int16: case FieldType::uint16: return 2;
        case FieldType::int32: case FieldType::uint32: case FieldType::float32: return 4;
        default: return 8;
    }
}

size_t octree_leaf_data_bytes(const std::vector<Field>& leaf_data) {
    size_t bytes = 0;
    for (const Field& f : leaf_data) bytes += field_type_bytes(f.type) * f.components;
    return bytes;
}

void validate_leaf_fields(const std::vector<Field>& fields, uint64_t leaves, const std::string& what) {
    std::set<std::string> names;
    for (const Field& f : fields) {
        const std::string where = what + ": " + field_what(f.name);
        AMC_REQUIRE(!f.name.empty() && f.name.size() <= kMaxFieldNameBytes, invalid_input, where + ": a name of 1 to 1024 bytes is required");
        AMC_REQUIRE(names.insert(f.name).second, invalid_input, where + ": the name is used twice");
        AMC_REQUIRE(f.association == FieldAssociation::cell, invalid_input, where + ": leaf data are cell fields (one tuple per leaf)");
        AMC_REQUIRE(uint8_t(f.type) <= uint8_t(FieldType::float64), invalid_input, where + ": unknown type");
        AMC_REQUIRE(f.components >= 1 && f.components <= kMaxFieldComponents, invalid_input, where + ": components must be 1 to 1024");
        const bool is_float = is_float_type(f.type);
        AMC_REQUIRE(f.value_count() == leaves * f.components && (is_float ? f.integers.empty() : f.values.empty()), invalid_input,
                    where + ": " + std::to_string(f.value_count()) + " values for " + std::to_string(leaves) + " leaves of " +
                        std::to_string(f.components) + " components");
        for (int64_t v : f.integers) AMC_REQUIRE(integer_in_range(v, f.type), invalid_input, where + ": a value out of the type's range");
        if (f.type == FieldType::float32)
            for (double v : f.values)  // beyond the float range the conversion is undefined: checked first
                AMC_REQUIRE(!std::isfinite(v) || (std::fabs(v) <= FLT_MAX && double(float(v)) == v), invalid_input,
                            where + ": a Float32 value that is not a float");
    }
}

void write_leaf_field_head(const Field& field, std::vector<uint8_t>& out) {
    put_varint(out, field.name.size());
    out.insert(out.end(), field.name.begin(), field.name.end());
    out.push_back(uint8_t(field.type));
    put_varint(out, field.components);
}

Field read_leaf_field_head(PayloadReader& in, const std::string& block) {
    Field f;
    f.association = FieldAssociation::cell;
    const uint64_t name_size = in.varint();
    AMC_REQUIRE(name_size >= 1 && name_size <= kMaxFieldNameBytes && name_size <= in.remaining(), corrupt,
                block + ": a name of " + std::to_string(name_size) + " bytes");
    f.name.assign(reinterpret_cast<const char*>(in.bytes(name_size)), size_t(name_size));
    const std::string what = field_what(f.name);
    const uint8_t type = in.u8();
    AMC_REQUIRE(type <= uint8_t(FieldType::float64), corrupt, what + ": unknown type " + std::to_string(type));
    f.type = FieldType(type);
    const uint64_t comps = in.varint();
    AMC_REQUIRE(comps >= 1 && comps <= kMaxFieldComponents, corrupt, what + ": " + std::to_string(comps) + " components");
    f.components = uint32_t(comps);
    return f;
}

void size_leaf_field(Field& f, uint64_t tuples, uint64_t max_values, uint64_t bytes_left) {
    const std::string what = field_what(f.name);
    const uint64_t values = tuples * f.components;
    AMC_REQUIRE(values <= max_values, limit_exceeded,
                what + ": " + std::to_string(values) + " values, more than the limit " + std::to_string(max_values));
    AMC_REQUIRE(values <= max_decodable_symbols(bytes_left) / kMinSymbolsPerSignedResidual, corrupt,
                what + ": " + std::to_string(values) + " values do not fit in " + std::to_string(bytes_left) + " bytes");
    if (is_float_type(f.type)) f.values.resize(values);
    else f.integers.resize(values);
}

std::vector<uint8_t> write_leaf_field(const Field& field, const std::vector<Octant>& leaves) {
    std::vector<uint8_t> out;
    write_leaf_field_head(field, out);
    const uint32_t comps = field.components;
    FloatResidualModels models(kLeafFieldContexts);
    ArithmeticEncoder encoder;
    for (size_t i = 0; i < leaves.size(); ++i)
        for (uint32_t c = 0; c < comps; ++c)
            encode_word(encoder, models.context(value_context(c, i > 0 ? &leaves[i - 1] : nullptr, leaves[i])), field.type,
                        word_of(field, i * comps + c), i > 0 ? word_of(field, (i - 1) * comps + c) : 0);
    const std::vector<uint8_t> stream = encoder.finish();
    out.insert(out.end(), stream.begin(), stream.end());
    return out;
}

Field read_leaf_field(const uint8_t* data, size_t size, const std::vector<Octant>& leaves, uint64_t max_values) {
    PayloadReader in(data, size, "leaf field block");
    Field f = read_leaf_field_head(in, "leaf field block");
    size_leaf_field(f, leaves.size(), max_values, in.remaining());
    const std::string what = field_what(f.name);
    const uint32_t comps = f.components;
    FloatResidualModels models(kLeafFieldContexts);
    ArithmeticDecoder decoder(in.rest(), in.remaining());
    uint64_t bad_range = 0;
    std::vector<uint64_t> previous(comps, 0);
    for (size_t i = 0; i < leaves.size(); ++i)
        for (uint32_t c = 0; c < comps; ++c) {
            previous[c] = decode_word(decoder, models, models.context(value_context(c, i > 0 ? &leaves[i - 1] : nullptr, leaves[i])),
                                      f.type, previous[c]);
            bad_range += !set_word(f, i * comps + c, previous[c]);
        }
    AMC_REQUIRE(!decoder.overran(), truncated, what + ": the values run past the end of the block");
    AMC_REQUIRE(!models.saw_invalid_symbol(), corrupt, what + ": an invalid residual");
    AMC_REQUIRE(bad_range == 0, corrupt, what + ": " + std::to_string(bad_range) + " values out of the type's range");
    return f;
}

}  // namespace amc
