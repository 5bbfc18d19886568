// The import property (issue 23): the input drives a random red-green hierarchy over one of the
// stream bases, takes its leaf mesh as a user would hand it in (vertices and faces shuffled,
// corners rotated, refinement vertices moved off their midpoints or anywhere, the base's vertices
// given by an index map or not) and damages it (faces dropped, doubled, flipped or rewired, vertices
// added, doubled or swapped). The importer, with the base or from the leaf mesh alone, either
// refuses the mesh as invalid input or returns a valid hierarchy whose leaf mesh is exactly the
// input; that hierarchy encodes and decodes bit-exactly. An undamaged mesh on its midpoints is
// always imported, with its base or alone.
#include "fuzz_targets.h"

#include <amc/codec.h>
#include <amc/import.h>
#include <amc/refinement.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>
#include <utility>

namespace amc::fuzz {
namespace {

constexpr uint32_t kMaxNodes = 4000;  // the hierarchy a run builds at most
constexpr int kMaxRefinedLevel = 6;
constexpr int kMaxDamages = 4;

Triangle rotated_to_smallest(Triangle t) {
    const int r = t[0] < t[1] ? (t[0] < t[2] ? 0 : 2) : (t[1] < t[2] ? 1 : 2);
    return {t[size_t(r)], t[size_t(r + 1) % 3], t[size_t(r + 2) % 3]};
}

// The imported hierarchy is valid and its leaf mesh is the input: the same oriented triangles on
// the same positions, related by vertex_of_input.
bool reproduces(const ImportedHierarchy& imported, const TriangleMesh& input) {
    const Hierarchy& h = imported.hierarchy;
    if (!check_invariants(h).empty() || imported.vertex_of_input.size() != input.positions.size()) return false;
    const std::vector<uint32_t> canonical = canonical_vertex_order(h);
    const LeafMesh leaf = extract_leaf_mesh(h);
    if (leaf.mesh.positions.size() != input.positions.size()) return false;
    std::vector<uint32_t> input_of_canonical(leaf.mesh.positions.size(), 0xffffffffu);
    for (uint32_t i = 0; i < input.positions.size(); ++i) {
        const VertexId v = imported.vertex_of_input[i];
        if (v >= canonical.size() || canonical[v] >= input_of_canonical.size()) return false;
        if (!(h.position(v) == input.positions[i]) || input_of_canonical[canonical[v]] != 0xffffffffu) return false;
        input_of_canonical[canonical[v]] = i;
    }
    std::vector<Triangle> built, given;
    for (const Triangle& t : leaf.mesh.triangles)
        built.push_back(rotated_to_smallest({input_of_canonical[t[0]], input_of_canonical[t[1]], input_of_canonical[t[2]]}));
    for (const Triangle& t : input.triangles) given.push_back(rotated_to_smallest(t));
    std::sort(built.begin(), built.end());
    std::sort(given.begin(), given.end());
    return built == given;
}

Vec3 any_position(ByteReader& in) {
    double c[3];
    for (double& x : c) {
        const uint64_t bits = in.u64();
        std::memcpy(&x, &bits, 8);
        if (!std::isfinite(x)) x = 0.0;  // non-finite coordinates are refused by the readers already
    }
    return {c[0], c[1], c[2]};
}

// Moves a refinement vertex off its midpoint by up to an eighth of the base's size, or anywhere.
Vec3 moved(Vec3 p, ByteReader& in, bool anywhere) {
    if (anywhere) return any_position(in);
    const auto offset = [&in] { return (double(in.u8()) - 127.5) / 1024.0; };
    const double dx = offset(), dy = offset();
    return {p.x + dx, p.y + dy, p.z + offset()};
}

// Damage of a kind the importer must refuse or reproduce exactly.
void damage(TriangleMesh& mesh, ByteReader& in) {
    if (mesh.triangles.empty()) return;
    const uint8_t kind = in.u8() % 7;
    const size_t f = in.u32() % mesh.triangles.size();
    const uint32_t vertices = uint32_t(mesh.positions.size());
    switch (kind) {
        case 0: mesh.triangles.erase(mesh.triangles.begin() + long(f)); break;                   // a hole
        case 1: mesh.triangles.push_back(mesh.triangles[f]); break;                              // a face twice
        case 2: std::swap(mesh.triangles[f][1], mesh.triangles[f][2]); break;                    // flipped
        case 3: mesh.triangles[f][in.u8() % 3] = in.u32() % vertices; break;                     // rewired
        case 4: mesh.positions.push_back(any_position(in)); break;                               // unused vertex
        case 5: {                                                                                // a corner doubled
            const int corner = in.u8() % 3;
            mesh.positions.push_back(mesh.positions[mesh.triangles[f][size_t(corner)]]);
            mesh.triangles[f][size_t(corner)] = vertices;
            break;
        }
        default: std::swap(mesh.positions[in.u32() % vertices], mesh.positions[in.u32() % vertices]); break;
    }
}

}  // namespace

void leaf_import(const uint8_t* data, size_t size) {
    ByteReader in(data, size);
    const uint8_t flags = in.u8();
    const bool move = flags & 1, anywhere = flags & 2, with_map = flags & 4, leaf_only = flags & 8,
               damaged = flags & 16, shuffle = flags & 32;
    const std::vector<TriangleMesh>& bases = stream_bases();
    const TriangleMesh& base = bases[in.u8() % bases.size()];

    Hierarchy h(base);
    refine_at_random(h, in, kMaxNodes, kMaxRefinedLevel, true);

    // The leaf mesh lists the base's vertices first, in the base's order.
    TriangleMesh input = extract_leaf_mesh(h).mesh;
    const uint32_t base_vertices = uint32_t(base.positions.size());
    if (move) {
        for (uint32_t v = base_vertices; v < input.positions.size(); ++v)
            if (in.u8() & 1) input.positions[v] = moved(input.positions[v], in, anywhere);
    }
    const int damages = damaged ? 1 + in.u8() % kMaxDamages : 0;
    for (int i = 0; i < damages; ++i) damage(input, in);

    std::vector<uint32_t> new_index(input.positions.size());
    std::iota(new_index.begin(), new_index.end(), 0u);
    if (shuffle) {
        for (uint32_t i = uint32_t(new_index.size()); i > 1; --i) std::swap(new_index[i - 1], new_index[in.u32() % i]);
        TriangleMesh shuffled = input;
        for (uint32_t v = 0; v < input.positions.size(); ++v) shuffled.positions[new_index[v]] = input.positions[v];
        for (Triangle& t : shuffled.triangles) {
            const uint8_t r = in.u8() % 3;
            t = {new_index[t[r]], new_index[t[(r + 1) % 3]], new_index[t[(r + 2) % 3]]};
        }
        for (size_t i = shuffled.triangles.size(); i > 1; --i) std::swap(shuffled.triangles[i - 1], shuffled.triangles[in.u32() % i]);
        input = std::move(shuffled);
    }
    std::vector<uint32_t> leaf_vertex_of_base;
    if (with_map) leaf_vertex_of_base.assign(new_index.begin(), new_index.begin() + base_vertices);

    ImportedHierarchy imported;
    try {
        imported = leaf_only ? import_mesh(input, "fuzz mesh") : import_leaf_mesh(base, input, leaf_vertex_of_base, "fuzz mesh");
    } catch (const Error& e) {
        FUZZ_CHECK(e.code() == ErrorCode::invalid_input);
        // An undamaged leaf mesh on its midpoints is a red-green refinement of its base, and a
        // mesh of its own (moved vertices may meet, which is a fault of the mesh).
        FUZZ_CHECK(damaged || move);
        return;
    }
    FUZZ_CHECK(reproduces(imported, input));
    // What the importer returns, the codec takes (the base in the input's order: the base coder's
    // search over a mesh imported as its own base costs seconds under the fuzzer's instrumentation).
    EncodeOptions options;
    options.keep_base_order = true;
    options.threads = 1;
    const std::vector<uint8_t> file = encode(imported.hierarchy, options);
    DecodeOptions decode_options;
    decode_options.threads = 1;
    const Hierarchy decoded = decode(file.data(), file.size(), decode_options);
    FUZZ_CHECK(identical(decoded, in_decoder_order(imported.hierarchy, options)));
}

}  // namespace amc::fuzz
