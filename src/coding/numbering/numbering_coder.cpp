// The numbering block: the caller's vertex and face orders as permutations (permutation_coder.h)
// of the canonical leaf mesh's, each coded by the cheapest method and face reference, and the
// triangles' rotations.
#include "coding/numbering/numbering_coder.h"

#include "coding/container.h"
#include "coding/entropy/arithmetic_coder.h"
#include "coding/numbering/permutation_coder.h"

#include <algorithm>
#include <array>
#include <functional>
#include <string>

namespace amc {

namespace {

// Frozen values (written to files).
enum class FaceReference : uint8_t { leaf_order = 0, lowest_vertex = 1, highest_vertex = 2 };
enum class RotationMode : uint8_t { none = 0, leaf_corners = 1, lowest_corner = 2 };

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

namespace {

size_t coded_size(const std::function<void(ArithmeticEncoder&)>& code) {
    ArithmeticEncoder trial;
    code(trial);
    return trial.finish().size();
}

// One permutation's choice: its method, the face reference (faces only) and the sequence coded.
struct PermutationChoice {
    PermutationMethod method = PermutationMethod::identity;
    FaceReference reference = FaceReference::leaf_order;
    std::vector<uint32_t> sequence;
    size_t size = SIZE_MAX;
};

void encode_choice(ArithmeticEncoder& encoder, const PermutationChoice& choice, const Graph& graph) {
    if (choice.method == PermutationMethod::walk) {
        encode_walk(encoder, graph, choice.sequence);
    } else {
        encode_permutation(encoder, choice.method, choice.sequence);
    }
}

// The cheapest of the rank methods over `sequence` (leaf order -> caller index) and the walk over
// `caller_order` (caller order -> leaf element).
void consider(PermutationChoice& best, FaceReference reference, std::vector<uint32_t> sequence) {
    const PermutationMethod method = best_method(sequence);
    const size_t size = coded_size([&](ArithmeticEncoder& e) { encode_permutation(e, method, sequence); });
    if (size < best.size) best = {method, reference, std::move(sequence), size};
}

void consider_walk(PermutationChoice& best, const Graph& graph, const std::vector<uint32_t>& caller_order) {
    const size_t size = coded_size([&](ArithmeticEncoder& e) { encode_walk(e, graph, caller_order); });
    if (size < best.size) best = {PermutationMethod::walk, FaceReference::leaf_order, caller_order, size};
}

}  // namespace

std::vector<uint8_t> encode_numbering(const LeafNumbering& numbering, const std::vector<Triangle>& leaf,
                                      NumberingCodeStats* stats) {
    const uint32_t vertices = uint32_t(numbering.vertex.size());
    const std::string problem = check_numbering(numbering, vertices, leaf.size());
    if (!problem.empty()) throw Error("encode: numbering does not fit the leaf mesh: " + problem);

    // For leaf vertex k (triangle t), the caller's index.
    std::vector<uint32_t> caller_vertex(vertices), caller_face(leaf.size());
    std::vector<uint8_t> caller_rotation(leaf.size());
    for (uint32_t i = 0; i < vertices; ++i) caller_vertex[numbering.vertex[i]] = i;
    for (uint32_t j = 0; j < leaf.size(); ++j) {
        caller_face[numbering.face[j]] = j;
        caller_rotation[numbering.face[j]] = numbering.rotation[j];
    }
    const Graph vertex_neighbors = vertex_graph(leaf, vertices), triangle_neighbors = triangle_graph(leaf);

    PermutationChoice vertex_choice;
    consider(vertex_choice, FaceReference::leaf_order, caller_vertex);
    if (vertex_choice.method != PermutationMethod::identity) consider_walk(vertex_choice, vertex_neighbors, numbering.vertex);

    PermutationChoice face_choice;
    for (FaceReference reference : {FaceReference::leaf_order, FaceReference::lowest_vertex, FaceReference::highest_vertex}) {
        const std::vector<uint32_t> order = reference_order(reference, leaf, caller_vertex);
        std::vector<uint32_t> sequence(order.size());
        for (uint32_t k = 0; k < order.size(); ++k) sequence[k] = caller_face[order[k]];
        consider(face_choice, reference, std::move(sequence));
    }
    if (face_choice.method != PermutationMethod::identity) consider_walk(face_choice, triangle_neighbors, numbering.face);

    RotationMode rotation_mode = RotationMode::none;
    std::vector<uint8_t> rotation_symbols;
    size_t rotation_size = 0;
    if (std::any_of(caller_rotation.begin(), caller_rotation.end(), [](uint8_t r) { return r != 0; })) {
        rotation_size = SIZE_MAX;
        for (RotationMode mode : {RotationMode::leaf_corners, RotationMode::lowest_corner}) {
            std::vector<uint8_t> symbols(leaf.size());
            for (uint32_t t = 0; t < leaf.size(); ++t)
                symbols[t] = uint8_t((caller_rotation[t] + 3 - reference_corner(mode, leaf[t], caller_vertex)) % 3);
            const size_t size = coded_size([&](ArithmeticEncoder& e) { encode_rotations(e, symbols); });
            if (size < rotation_size) {
                rotation_size = size;
                rotation_mode = mode;
                rotation_symbols = std::move(symbols);
            }
        }
    }

    std::vector<uint8_t> out;
    put_varint(out, vertices);
    put_varint(out, leaf.size());
    out.push_back(uint8_t(vertex_choice.method));
    out.push_back(uint8_t(face_choice.reference));
    out.push_back(uint8_t(face_choice.method));
    out.push_back(uint8_t(rotation_mode));
    ArithmeticEncoder encoder;
    encode_choice(encoder, vertex_choice, vertex_neighbors);
    encode_choice(encoder, face_choice, triangle_neighbors);
    if (rotation_mode != RotationMode::none) encode_rotations(encoder, rotation_symbols);
    const std::vector<uint8_t> coded = encoder.finish();
    out.insert(out.end(), coded.begin(), coded.end());
    if (stats != nullptr) {
        stats->vertex_method = int(vertex_choice.method);
        stats->face_method = int(face_choice.method);
        stats->face_reference = int(face_choice.reference);
        stats->rotation_mode = int(rotation_mode);
        stats->vertex_bytes = vertex_choice.method == PermutationMethod::identity ? 0 : vertex_choice.size;
        stats->face_bytes = face_choice.method == PermutationMethod::identity ? 0 : face_choice.size;
        stats->rotation_bytes = rotation_size;
    }
    return out;
}

LeafNumbering decode_numbering(const uint8_t* data, size_t size, const std::vector<Triangle>& leaf, uint32_t vertices) {
    PayloadReader in(data, size, "numbering block");
    if (in.varint() != vertices || in.varint() != leaf.size())
        throw Error(ErrorCode::corrupt, "numbering block: its counts do not match the leaf mesh");
    const uint8_t vertex_method = in.u8(), face_reference = in.u8(), face_method = in.u8(), rotation_mode = in.u8();
    if (vertex_method > uint8_t(PermutationMethod::walk) || face_method > uint8_t(PermutationMethod::walk) ||
        face_reference > uint8_t(FaceReference::highest_vertex) || rotation_mode > uint8_t(RotationMode::lowest_corner) ||
        (face_method == uint8_t(PermutationMethod::walk) && face_reference != uint8_t(FaceReference::leaf_order)))
        throw Error(ErrorCode::corrupt, "numbering block: unknown method");
    ArithmeticDecoder decoder(in.rest(), in.remaining());

    LeafNumbering numbering;
    std::vector<uint32_t> caller_vertex(vertices);
    if (vertex_method == uint8_t(PermutationMethod::walk)) {
        numbering.vertex = decode_walk(decoder, vertex_graph(leaf, vertices), vertices, "vertex");
        for (uint32_t i = 0; i < vertices; ++i) caller_vertex[numbering.vertex[i]] = i;
    } else {
        caller_vertex = decode_permutation(decoder, PermutationMethod(vertex_method), vertices, "vertex");
        numbering.vertex.resize(vertices);
        for (uint32_t k = 0; k < vertices; ++k) numbering.vertex[caller_vertex[k]] = k;
    }

    std::vector<uint32_t> caller_face(leaf.size());
    if (face_method == uint8_t(PermutationMethod::walk)) {
        numbering.face = decode_walk(decoder, triangle_graph(leaf), uint32_t(leaf.size()), "face");
        for (uint32_t j = 0; j < leaf.size(); ++j) caller_face[numbering.face[j]] = j;
    } else {
        const std::vector<uint32_t> order = reference_order(FaceReference(face_reference), leaf, caller_vertex);
        const std::vector<uint32_t> sequence =
            decode_permutation(decoder, PermutationMethod(face_method), uint32_t(leaf.size()), "face");
        numbering.face.resize(leaf.size());
        for (uint32_t k = 0; k < order.size(); ++k) {
            numbering.face[sequence[k]] = order[k];
            caller_face[order[k]] = sequence[k];
        }
    }

    numbering.rotation.assign(leaf.size(), 0);
    if (rotation_mode != uint8_t(RotationMode::none)) {
        RotationModels m;
        uint8_t previous = 0;
        for (uint32_t t = 0; t < leaf.size(); ++t) {
            uint8_t symbol = 0;
            if (!decoder.decode(m.models[previous][0])) symbol = decoder.decode(m.models[previous][1]) ? 1 : 2;
            previous = symbol;
            numbering.rotation[caller_face[t]] =
                uint8_t((symbol + reference_corner(RotationMode(rotation_mode), leaf[t], caller_vertex)) % 3);
        }
    }
    if (decoder.overran()) throw Error(ErrorCode::corrupt, "numbering block is truncated or corrupt");
    return numbering;
}

LeafNumbering numbering_after_reorder(const Hierarchy& input, const LeafNumbering& numbering, const Hierarchy& h,
                                      const std::vector<VertexId>& vertex_map) {
    const TriangleMesh caller = renumber_leaf_mesh(extract_leaf_mesh(input), numbering);
    const std::vector<uint32_t> canonical = canonical_vertex_order(input);
    std::vector<VertexId> id_of_leaf_vertex(input.vertex_count());
    for (VertexId v = 0; v < canonical.size(); ++v) {
        if (canonical[v] != kNoVertex) id_of_leaf_vertex[canonical[v]] = v;
    }
    std::vector<VertexId> vertex_of_input(numbering.vertex.size());
    for (size_t i = 0; i < numbering.vertex.size(); ++i) vertex_of_input[i] = vertex_map[id_of_leaf_vertex[numbering.vertex[i]]];
    return leaf_numbering(h, caller, vertex_of_input);
}

}  // namespace amc
