#include "import/hierarchy_from_levels.h"

#include "common/keyed_hash.h"
#include "common/no_index.h"

#include <algorithm>
#include <utility>
#include <vector>

namespace amc {
namespace {


// Three vertex ids as a key: a triangle's vertex set (triple_key, the ids sorted) or an oriented
// triangle (the final check). 21 bits each would not do for large meshes, so two words; no
// triangle has three equal ids, so the empty key cannot occur.
struct TripleKey {
    uint64_t low, high;
    bool operator==(const TripleKey& o) const { return low == o.low && high == o.high; }
};
constexpr TripleKey kEmptyTriple{~0ull, ~0ull};
TripleKey triple_key(uint32_t a, uint32_t b, uint32_t c) {
    if (a > b) std::swap(a, b);
    if (b > c) std::swap(b, c);
    if (a > b) std::swap(a, b);
    return {(uint64_t(a) << 32) | b, c};
}
// Keyed (common/keyed_hash.h): the ids are the input's numbering, which a file chooses, and an
// unkeyed multiply-xorshift let one direction of a matching's edges fill one probe run.
size_t hash_of(TripleKey k, const KeyedWordHash& hash) { return size_t(splitmix64_mix(hash(k.low) ^ k.high)); }
size_t hash_of(uint64_t k, const KeyedWordHash& hash) { return hash(k); }

// Open addressing with linear probing, sized once for at most `count` keys: the node and edge
// tables here hold a few entries per leaf face, and a node-based map spent most of this file's
// time allocating.
template <typename Key, typename Value>
class FlatMap {
public:
    FlatMap(size_t count, Key empty) : empty_(empty) {
        size_t capacity = 16;
        while (capacity < 2 * count) capacity *= 2;
        slots_.assign(capacity, {empty, Value{}});
    }
    Value& operator[](Key key) {
        std::pair<Key, Value>& slot = slots_[probe(key)];
        slot.first = key;
        return slot.second;
    }
    const Value* find(Key key) const {
        const std::pair<Key, Value>& slot = slots_[probe(key)];
        return slot.first == empty_ ? nullptr : &slot.second;
    }
    Value* find(Key key) { return const_cast<Value*>(static_cast<const FlatMap&>(*this).find(key)); }

private:
    size_t probe(Key key) const {
        size_t s = hash_of(key, hash_) & (slots_.size() - 1);
        while (!(slots_[s].first == empty_) && !(slots_[s].first == key)) s = (s + 1) & (slots_.size() - 1);
        return s;
    }
    Key empty_;
    const KeyedWordHash hash_;
    std::vector<std::pair<Key, Value>> slots_;
};

uint64_t directed(uint32_t a, uint32_t b) { return (uint64_t(a) << 32) | b; }

// A triangle rotated so that its smallest id comes first (orientation kept).
Triangle normalized(Triangle t) {
    const int r = t[0] < t[1] ? (t[0] < t[2] ? 0 : 2) : (t[1] < t[2] ? 1 : 2);
    return {t[size_t(r)], t[size_t(r + 1) % 3], t[size_t(r + 2) % 3]};
}

}  // namespace

ImportedHierarchy hierarchy_from_levels(const TriangleMesh& mesh, const DetectedBase& detected,
                                        const std::string& what) {
    auto fail = [&](const std::string& message) -> void { throw Error(what + ": base detection: " + message); };
    validate_triangle_mesh(detected.base, what + " (detected base)");
    ImportedHierarchy out;
    Hierarchy& h = out.hierarchy;
    h = Hierarchy(detected.base);
    std::vector<uint32_t> input_of = detected.leaf_vertex_of_base;  // hierarchy vertex -> input vertex
    // The build's tables are freed before the check makes its own (a large mesh's peak memory).
    // They hold the splits' parents and children, not every root: a plain mesh's base is nearly
    // the mesh, and a table of its roots cost a large mesh most of this function's time.
    {
        size_t split_count = 0;
        for (const DetectedLevel& level : detected.levels) split_count += level.splits.size();
        auto key_of = [&](NodeId n) { return triple_key(input_of[h.vertex(n, 0)], input_of[h.vertex(n, 1)], input_of[h.vertex(n, 2)]); };
        // The root of each split's triangle, found in one pass over the roots (the last root of a
        // vertex set, as a table of every root filled in order would hold).
        FlatMap<TripleKey, NodeId> root_of(split_count, kEmptyTriple);
        for (const DetectedLevel& level : detected.levels)
            for (const auto& s : level.splits) root_of[triple_key(s[0], s[1], s[2])] = kNoNode;
        if (split_count > 0) {
            for (NodeId root = 0; root < h.root_count(); ++root)
                if (NodeId* r = root_of.find(key_of(root))) *r = root;
        }
        FlatMap<TripleKey, NodeId> child_of(4 * split_count, kEmptyTriple);
        auto node_of = [&](TripleKey key) -> const NodeId* {
            if (const NodeId* child = child_of.find(key)) return child;  // written after the roots: it wins
            const NodeId* root = root_of.find(key);
            return root != nullptr && *root != kNoNode ? root : nullptr;
        };

        for (size_t level = detected.levels.size(); level-- > 0;) {
            for (const auto& s : detected.levels[level].splits) {
                const NodeId* found = node_of(triple_key(s[0], s[1], s[2]));
                if (found == nullptr || !h.is_leaf(*found)) {
                    fail("level " + std::to_string(level) + " splits a triangle that is not a leaf");
                }
                const NodeId n = *found;
                int r = 0;
                while (r < 3 && input_of[h.vertex(n, r)] != s[0]) ++r;
                if (r == 3 || input_of[h.vertex(n, (r + 1) % 3)] != s[1] || input_of[h.vertex(n, (r + 2) % 3)] != s[2]) {
                    fail("a split parent has the wrong orientation");
                }
                if (!h.can_split(n)) fail("a split breaks balance");
                h.split(n);
                for (int e = 0; e < 3; ++e) {
                    const VertexId v = h.midpoint(n, e);
                    const uint32_t m = s[size_t(3 + (e - r + 3) % 3)];  // node edge e is split edge e - r
                    if (v >= input_of.size()) input_of.resize(size_t(v) + 1, kNoIndex);
                    if (input_of[v] == kNoIndex) {
                        input_of[v] = m;
                        h.set_position(v, mesh.positions[m]);
                    } else if (input_of[v] != m) {
                        fail("two midpoints for one edge");
                    }
                }
                for (int k = 0; k < 4; ++k) child_of[key_of(h.child(n, k))] = h.child(n, k);
            }
        }
    }

    // Diagonals of two-hanging-node leaves: the default one joins m_{u+1} and v_u (a triangle
    // (v_u, m_{u+1}, m_{u+2}) exists), the other m_{u+2} and v_{u+1}. The input's directed edges are
    // looked up only from those leaves' v_u (a table of every edge was most of a large plain
    // mesh's peak memory).
    {
        struct Green {
            NodeId node;
            uint32_t from, to;  // input ids of v_u and m_{u+1}
        };
        std::vector<Green> greens;
        std::vector<uint8_t> asked(mesh.positions.size(), 0);
        for (NodeId n : h.leaves()) {
            if (h.hanging_node_count(n) != 2) continue;
            const int u = !h.has_hanging_node(n, 0) ? 0 : !h.has_hanging_node(n, 1) ? 1 : 2;
            const int e1 = (u + 1) % 3;
            const VertexId m1 = h.midpoint(h.neighbor(n, e1), h.neighbor_edge(n, e1));
            greens.push_back({n, input_of[h.vertex(n, u)], input_of[m1]});
            if (greens.back().from < asked.size()) asked[greens.back().from] = 1;
        }
        size_t asked_edges = 0;
        for (const Triangle& t : mesh.triangles)
            for (uint32_t v : t) asked_edges += asked[v];
        FlatMap<uint64_t, uint8_t> edges(asked_edges, ~0ull);  // the input's directed edges from those v_u
        for (const Triangle& t : mesh.triangles) {
            for (int e = 0; e < 3; ++e)
                if (asked[t[size_t(e)]]) edges[directed(t[size_t(e)], t[size_t(e + 1) % 3])] = 1;
        }
        for (const Green& g : greens) h.set_diagonal_flipped(g.node, edges.find(directed(g.from, g.to)) == nullptr);
    }

    // The check: every input vertex used once, the same triangles, a valid hierarchy.
    out.vertex_of_input.assign(mesh.positions.size(), kNoIndex);
    for (VertexId v = 0; v < input_of.size(); ++v) {
        if (input_of[v] == kNoIndex) continue;
        if (out.vertex_of_input[input_of[v]] != kNoIndex) fail("an input vertex is used twice");
        out.vertex_of_input[input_of[v]] = v;
    }
    if (std::count(out.vertex_of_input.begin(), out.vertex_of_input.end(), kNoIndex) != 0) {
        fail("an input vertex is missing from the hierarchy");
    }
    const std::string problem = check_invariants(h);
    if (!problem.empty()) fail(problem);
    const LeafMesh leaf = extract_leaf_mesh(h);
    const std::vector<uint32_t> canonical = canonical_vertex_order(h);
    std::vector<uint32_t> input_of_canonical(leaf.mesh.positions.size(), kNoIndex);
    for (VertexId v = 0; v < canonical.size(); ++v) {
        if (canonical[v] < input_of_canonical.size()) input_of_canonical[canonical[v]] = input_of[v];
    }
    // The same triangles as a multiset: both lists, each triangle rotated to start at its smallest
    // id, bucketed by that id and sorted within buckets, are equal (a bucket sort keeps the ids'
    // locality in the file, where a hash table scatters them).
    const uint32_t vertex_count = static_cast<uint32_t>(mesh.positions.size());
    auto bucketed = [&](const std::vector<Triangle>& triangles, auto input_id, std::vector<uint32_t>& start,
                        std::vector<uint64_t>& rest) {
        start.assign(size_t(vertex_count) + 1, 0);
        for (const Triangle& t : triangles) {
            const Triangle n = normalized({input_id(t[0]), input_id(t[1]), input_id(t[2])});
            if (n[0] >= vertex_count || n[1] >= vertex_count || n[2] >= vertex_count) return false;
            ++start[n[0] + 1];
        }
        for (size_t v = 0; v < vertex_count; ++v) start[v + 1] += start[v];
        std::vector<uint32_t> cursor(start.begin(), start.end() - 1);
        rest.resize(triangles.size());
        for (const Triangle& t : triangles) {
            const Triangle n = normalized({input_id(t[0]), input_id(t[1]), input_id(t[2])});
            rest[cursor[n[0]]++] = (uint64_t(n[1]) << 32) | n[2];
        }
        for (size_t v = 0; v < vertex_count; ++v)
            if (start[v + 1] - start[v] > 1) std::sort(rest.begin() + start[v], rest.begin() + start[v + 1]);
        return true;
    };
    bool same = leaf.mesh.triangles.size() == mesh.triangles.size();
    if (same) {
        std::vector<uint32_t> given_start, built_start;
        std::vector<uint64_t> given, built;
        same = bucketed(mesh.triangles, [](uint32_t v) { return v; }, given_start, given) &&
               bucketed(leaf.mesh.triangles, [&](uint32_t v) { return v < input_of_canonical.size() ? input_of_canonical[v] : kNoIndex; },
                        built_start, built) &&
               given_start == built_start && given == built;
    }
    if (!same) fail("the hierarchy's leaf mesh differs from the input");
    return out;
}

}  // namespace amc
