// Mode 0 of the base connectivity stream (FORMAT.md 4.3-4.7): the cut-border coder of format
// versions 1 and 2, and the writer's fallback after modes 2 and 3. See base_cut_border_coder.h.
#include "coding/base/base_cut_border_coder.h"

#include "coding/base/base_cut_border.h"
#include "coding/base/base_mesh_closing.h"
#include "common/bits.h"

#include <algorithm>
#include <string>

namespace amc {
namespace {

constexpr int kDegreeContexts = 8;

// The adaptive models of mode 0 (shared layout of encoder and decoder).
struct OpModels {
    BitModel is_new[kDegreeContexts];      // C or not, by triangles around u
    BitModel is_right[kDegreeContexts];    // R (E on a 3-loop) or not, by triangles around u
    BitModel is_left[kDegreeContexts];     // L or not, by triangles around v
    BitModel is_split;                     // S or M when both are possible
    BitModel is_dummy;                     // a new vertex is a boundary loop's dummy vertex
    SplitOffsetModels split;               // split offsets (tip counted from v or from u)

    static int degree_class(uint32_t d) { return static_cast<int>(std::min<uint32_t>(d, 7)); }
    BitModel& new_model(uint32_t du) { return is_new[degree_class(du)]; }
};

// Mode 0 keeps its decode linear up to logarithms: a stream whose border nodes need more degree
// updates than this (FORMAT.md 4.5; a vertex holding many border nodes at once) is refused.
uint64_t update_budget(uint32_t closed_faces) { return 64 * uint64_t{closed_faces} + (uint64_t{1} << 24); }

}  // namespace

DecodedBaseMesh decode_cut_border(ArithmeticDecoder& dec, size_t size, uint32_t expected_vertices, uint32_t max_isolated) {
    const uint32_t vertex_count = get_count(dec);
    const uint32_t isolated = get_count(dec);
    const uint32_t dummies = get_count(dec);
    const uint32_t copies = get_count(dec);
    const uint32_t components = get_count(dec);
    const uint32_t merges = get_count(dec);
    if (vertex_count != expected_vertices) fail_base_stream("vertex count differs from the caller's");
    if (isolated > vertex_count) fail_base_stream("bad isolated vertex count");
    if (isolated > max_isolated) fail_base_stream(isolated_refused(isolated, max_isolated));
    const uint64_t stream_bits = 8 * (uint64_t{size} + 8);
    // Every copy and merge costs at least two raw bits.
    if (2 * uint64_t{copies} > stream_bits || 2 * uint64_t{merges} > stream_bits)
        fail_base_stream("copy or merge count exceeds the stream");
    const uint64_t used = vertex_count - isolated;
    const uint64_t closed_vertices = used + dummies + copies;
    if (dummies > (used + copies) / 3 + 1 || closed_vertices > kMaxBaseCount)
        fail_base_stream("bad dummy vertex count");
    if (3 * uint64_t{components} > closed_vertices) fail_base_stream("bad component count");
    const int64_t closed_faces = 2 * int64_t(closed_vertices) - 4 * int64_t(components) +
                                 4 * int64_t(merges);
    if (closed_faces < 0 || closed_faces > kMaxBaseCount || (components == 0) != (closed_faces == 0))
        fail_base_stream("bad triangle count");
    // Every triangle but a component's first costs an operation, at least one modelled symbol.
    if (uint64_t(closed_faces) - components > max_decodable_symbols(size))
        fail_base_stream("triangle count exceeds the stream");

    OpModels models;
    const uint32_t vc = static_cast<uint32_t>(closed_vertices);
    const uint32_t fc = static_cast<uint32_t>(closed_faces);
    CutBorder border(0, update_budget(fc));
    const std::vector<uint32_t>& degree = border.degree;
    std::vector<uint8_t> is_dummy;
    std::vector<BaseStencil> raw_stencils;
    std::vector<Triangle> tris;
    // Room for what a stream of this size typically holds (a few triangles a byte); more grows.
    const uint64_t typical = 64 * uint64_t{size} + 64;
    border.degree.reserve(std::min<uint64_t>(vc, typical));
    tris.reserve(std::min<uint64_t>(fc, typical));
    uint32_t dummy_seen = 0;

    auto add_vertex = [&](BaseStencil s, bool dummy) {
        if (degree.size() >= vc) fail_base_stream("more vertices than announced");
        border.add_vertex();
        is_dummy.push_back(dummy ? 1 : 0);
        raw_stencils.push_back(s);
        return static_cast<uint32_t>(degree.size() - 1);
    };
    auto add_triangle = [&](uint32_t a, uint32_t b, uint32_t c) {
        if (tris.size() >= fc) fail_base_stream("more triangles than announced");
        if (a == b || b == c || a == c) fail_base_stream("degenerate triangle");
        tris.push_back({a, b, c});
        if (!border.count_triangle(a, b, c)) fail_base_stream("too many border nodes of the same vertices");
    };

    for (uint32_t comp = 0; comp < components; ++comp) {
        const int32_t last = static_cast<int32_t>(degree.size()) - 1;
        const uint32_t a = add_vertex({last, -1, -1}, false);
        const uint32_t b = add_vertex({int32_t(a), -1, -1}, false);
        const uint32_t c = add_vertex({int32_t(b), -1, -1}, false);
        add_triangle(a, b, c);
        border.start(a, b, c);
        while (!border.stack.empty()) {
            if (tris.size() >= fc) fail_base_stream("more triangles than announced");
            if (dec.overran()) fail_base_stream("truncated", ErrorCode::truncated);
            CutBorder::Loop& loop = border.top();
            const uint32_t g = loop.gate, nv = border.next[g];
            const uint32_t u = border.vert[g], v = border.vert[nv];
            if (dec.decode(models.new_model(degree[u]))) {
                const bool dummy = dummies > 0 && dec.decode(models.is_dummy);
                dummy_seen += dummy ? 1 : 0;
                const uint32_t w =
                    add_vertex({int32_t(u), int32_t(v), int32_t(border.opp[g])}, dummy);
                add_triangle(u, v, w);
                border.op_new(w);
                continue;
            }
            const uint32_t length = loop.length;
            const bool right = dec.decode(models.is_right[OpModels::degree_class(degree[u])]);
            if (right) {
                add_triangle(u, v, border.vert[border.prev[g]]);
                if (length == 3) border.op_end();
                else border.op_right();
                border.choose_gate();
                continue;
            }
            if (length > 3 && dec.decode(models.is_left[OpModels::degree_class(degree[v])])) {
                add_triangle(u, v, border.vert[border.next[nv]]);
                border.op_left();
                continue;
            }
            const bool can_split = length >= 5, can_merge = border.stack.size() >= 2;
            if (!can_split && !can_merge) fail_base_stream("impossible operation");
            const bool split = can_split && (!can_merge || dec.decode(models.is_split));
            if (split) {
                const uint32_t k = 2 + get_split_offset(dec, models.split, length - 4);
                const uint32_t n = border.walk(nv, k);
                add_triangle(u, v, border.vert[n]);
                border.op_split(n, k);
            } else {
                const size_t depth = get_index(
                    dec, static_cast<uint32_t>(border.stack.size() - 1), "merge loop");
                const size_t index = border.stack.size() - 2 - depth;
                const CutBorder::Loop other = border.stack[index];
                const uint32_t n = border.walk(other.gate, get_index(dec, other.length, "merge offset"));
                add_triangle(u, v, border.vert[n]);
                border.op_merge(n, index);
            }
        }
    }
    if (tris.size() != fc || degree.size() != vc) fail_base_stream("counts do not match the operations");
    if (dummy_seen != dummies) fail_base_stream("dummy vertex count does not match");

    // Copies of non-manifold vertices: merged into earlier vertices.
    std::vector<uint32_t> target(vc, kNoVertex);
    uint32_t previous_copy = 0;
    for (uint32_t i = 0; i < copies; ++i) {
        const uint32_t copy = get_index(dec, vc, "copy index");
        const uint32_t to = get_index(dec, vc, "copy target");
        if ((i > 0 && copy <= previous_copy) || to >= copy || is_dummy[copy] || is_dummy[to] ||
            target[to] != kNoVertex)
            fail_base_stream("bad vertex copy");
        target[copy] = to;
        previous_copy = copy;
    }
    if (dec.overran()) fail_base_stream("truncated", ErrorCode::truncated);

    DecodedBaseMesh out;
    out.vertex_count = vertex_count;
    std::vector<int32_t> final_index(vc, -1);
    int32_t next_final = 0;
    for (uint32_t i = 0; i < vc; ++i) {
        if (is_dummy[i]) continue;
        if (target[i] != kNoVertex) {
            final_index[i] = final_index[target[i]];
            continue;
        }
        final_index[i] = next_final++;
        const BaseStencil& s = raw_stencils[i];
        auto map = [&](int32_t x) { return x < 0 ? -1 : final_index[x]; };
        const int32_t m0 = map(s[0]), m1 = map(s[1]), m2 = map(s[2]);
        if (m0 >= 0 && m1 >= 0 && m2 >= 0) out.stencils.push_back({m0, m1, m2});
        else if (m0 >= 0) out.stencils.push_back({m0, -1, -1});
        else if (m1 >= 0) out.stencils.push_back({m1, -1, -1});
        else out.stencils.push_back({next_final - 2, -1, -1});
    }
    if (uint64_t(next_final) != used) fail_base_stream("vertex count does not match");
    for (uint32_t i = 0; i < isolated; ++i) {
        out.stencils.push_back({next_final - 1, -1, -1});
        ++next_final;
    }
    for (const Triangle& t : tris) {
        if (is_dummy[t[0]] || is_dummy[t[1]] || is_dummy[t[2]]) continue;
        const Triangle m = {uint32_t(final_index[t[0]]), uint32_t(final_index[t[1]]),
                            uint32_t(final_index[t[2]])};
        if (m[0] == m[1] || m[1] == m[2] || m[0] == m[2]) fail_base_stream("degenerate triangle");
        out.triangles.push_back(m);
    }
    return out;
}

namespace {

struct ClosedTraversal {
    std::vector<uint32_t> vertex_sequence;    // closed vertices in decoder order
    std::vector<uint32_t> triangle_sequence;  // closed triangles in decoder order
    std::vector<uint8_t> rotation;            // per decoded triangle
    uint32_t components = 0, merges = 0;
};

}  // namespace

std::vector<uint8_t> encode_cut_border(const TriangleMesh& mesh, BaseMeshCode& code) {
    const ClosedMesh cm = make_closed(mesh);
    const uint32_t fc = static_cast<uint32_t>(cm.triangles.size());
    const uint32_t vc = static_cast<uint32_t>(cm.original.size());
    auto corner_vertex = [&](uint32_t he) { return cm.triangles[he / 3][he % 3]; };
    auto next_he = [](uint32_t he) { return he / 3 * 3 + (he % 3 + 1) % 3; };
    auto prev_he = [](uint32_t he) { return he / 3 * 3 + (he % 3 + 2) % 3; };

    // Pass 1: the traversal, recording the ops; pass 2 writes them once the counts are known.
    struct Op {
        uint8_t kind;  // 0 start, 1 C, 2 R/E, 3 L, 4 S, 5 M
        uint32_t a = 0, b = 0;
    };
    std::vector<Op> ops;
    ClosedTraversal ec;
    std::vector<uint32_t> decoder_index(vc, kNoVertex);
    std::vector<uint8_t> processed(fc, 0);
    CutBorder border(vc, update_budget(fc));
    std::vector<uint32_t> out_he;  // per node: the unprocessed halfedge of its border edge

    auto visit_vertex = [&](uint32_t v) {
        decoder_index[v] = static_cast<uint32_t>(ec.vertex_sequence.size());
        ec.vertex_sequence.push_back(v);
    };
    auto visit_triangle = [&](uint32_t he) {
        const uint32_t t = he / 3;
        if (processed[t]) throw EncoderGaveUp{};
        processed[t] = 1;
        const Triangle& tri = cm.triangles[t];
        if (!border.count_triangle(tri[0], tri[1], tri[2])) throw EncoderGaveUp{};
        ec.triangle_sequence.push_back(t);
        ec.rotation.push_back(static_cast<uint8_t>(he % 3));
    };
    auto track = [&](uint32_t node, uint32_t he) {
        if (out_he.size() <= node) out_he.resize(node + 1, kNoVertex);
        out_he[node] = he;
    };
    // Is triangle t in the unprocessed sector of node n (between its out edge and in edge)?
    auto sector_holds = [&](uint32_t n, uint32_t t) {
        uint32_t he = out_he[n];
        const uint32_t stop = out_he[border.prev[n]] / 3;
        for (uint32_t steps = 0; steps <= fc; ++steps) {
            if (he / 3 == t) return true;
            if (he / 3 == stop) return false;
            he = cm.twin[prev_he(he)];
        }
        throw EncoderGaveUp{};
    };

    for (uint32_t start = 0; start < cm.real_triangles; ++start) {
        if (processed[start]) continue;
        const Triangle& st = cm.triangles[start];
        for (uint32_t v : st)
            if (decoder_index[v] != kNoVertex) throw EncoderGaveUp{};
        ++ec.components;
        ops.push_back({0});
        for (uint32_t v : st) visit_vertex(v);
        visit_triangle(3 * start);
        border.start(st[0], st[1], st[2]);
        const uint32_t na = border.top().gate, nc = border.next[na], nb = border.next[nc];
        track(na, cm.twin[3 * start + 2]);
        track(nc, cm.twin[3 * start + 1]);
        track(nb, cm.twin[3 * start + 0]);
        for (uint64_t guard = 0; !border.stack.empty(); ++guard) {
            if (guard > fc) throw EncoderGaveUp{};
            CutBorder::Loop& loop = border.top();
            const uint32_t g = loop.gate, nv = border.next[g];
            const uint32_t he = out_he[g];
            const uint32_t t = he / 3;
            if (processed[t] || corner_vertex(he) != border.vert[g] ||
                corner_vertex(next_he(he)) != border.vert[nv])
                throw EncoderGaveUp{};
            const uint32_t w = corner_vertex(prev_he(he));
            const uint32_t to_v = cm.twin[next_he(he)];  // w -> v, beyond the edge v -> w
            const uint32_t to_w = cm.twin[prev_he(he)];  // u -> w, beyond the edge w -> u
            visit_triangle(he);
            if (decoder_index[w] == kNoVertex) {
                visit_vertex(w);
                ops.push_back({1, cm.original[w] == kNoVertex ? 1u : 0u});
                const uint32_t nw = border.op_new(w);
                out_he[g] = to_w;
                track(nw, to_v);
                continue;
            }
            const uint32_t p = border.prev[g];
            if (border.vert[p] == w) {
                ops.push_back({2});
                if (loop.length == 3) {
                    border.op_end();
                } else {
                    border.op_right();
                    out_he[p] = to_v;
                }
                border.choose_gate();
                continue;
            }
            if (loop.length > 3 && border.vert[border.next[nv]] == w) {
                ops.push_back({3});
                border.op_left();
                out_he[g] = to_w;
                continue;
            }
            uint32_t n = kNoVertex;
            for (uint32_t x = border.first_node_of(w); x != CutBorder::kNoBorderNode && n == kNoVertex;
                 x = border.next_node_of(x))
                if (sector_holds(x, t)) n = x;
            if (n == kNoVertex) throw EncoderGaveUp{};
            if (border.same_loop(n, g)) {
                const uint32_t k = border.steps_between(nv, n);
                if (k < 2 || k + 3 > loop.length) throw EncoderGaveUp{};
                ops.push_back({4, k - 2, loop.length - 4});
                const uint32_t nw = border.op_split(n, k);
                out_he[g] = to_w;
                track(nw, to_v);
                continue;
            }
            size_t index = border.stack.size();
            for (size_t j = 0; j + 1 < border.stack.size() && index == border.stack.size(); ++j)
                if (border.same_loop(n, border.stack[j].gate)) index = j;
            if (index == border.stack.size()) throw EncoderGaveUp{};
            const uint32_t offset = border.steps_between(border.stack[index].gate, n);
            ++ec.merges;
            const uint32_t depth = static_cast<uint32_t>(border.stack.size() - 2 - index);
            ops.push_back({5, depth, offset});
            ops.back().kind = 5;
            // Stack size and loop length are needed to write the op: stored beside it.
            ops.push_back({6, static_cast<uint32_t>(border.stack.size() - 1),
                           border.stack[index].length});
            const uint32_t nw = border.op_merge(n, index);
            out_he[g] = to_w;
            track(nw, to_v);
        }
    }
    if (ec.triangle_sequence.size() != fc || ec.vertex_sequence.size() != vc) throw EncoderGaveUp{};

    // Vertex order, copies and triangle order.
    const uint32_t v_total = static_cast<uint32_t>(mesh.positions.size());
    std::vector<uint32_t> representative(v_total, kNoVertex);
    std::vector<std::pair<uint32_t, uint32_t>> copies;
    code.vertex_order.clear();
    for (uint32_t i = 0; i < vc; ++i) {
        const uint32_t orig = cm.original[ec.vertex_sequence[i]];
        if (orig == kNoVertex) continue;
        if (representative[orig] != kNoVertex) {
            copies.emplace_back(i, representative[orig]);
            continue;
        }
        representative[orig] = i;
        code.vertex_order.push_back(orig);
    }
    const uint32_t used = static_cast<uint32_t>(code.vertex_order.size());
    for (uint32_t v = 0; v < v_total; ++v)
        if (representative[v] == kNoVertex) code.vertex_order.push_back(v);
    code.triangle_order.clear();
    code.triangle_rotation.clear();
    for (size_t i = 0; i < ec.triangle_sequence.size(); ++i) {
        if (ec.triangle_sequence[i] >= cm.real_triangles) continue;
        code.triangle_order.push_back(ec.triangle_sequence[i]);
        code.triangle_rotation.push_back(ec.rotation[i]);
    }

    // Pass 2: replay the ops with the decoder's contexts.
    ArithmeticEncoder enc;
    enc.encode_bits_raw(uint32_t(BaseConnectivityMode::cut_border), 2);
    put_count(enc, v_total);
    put_count(enc, v_total - used);
    put_count(enc, cm.dummies);
    put_count(enc, static_cast<uint32_t>(copies.size()));
    put_count(enc, ec.components);
    put_count(enc, ec.merges);
    OpModels models;
    CutBorder replay(vc, UINT64_MAX);  // only for the contexts (degrees) and loop lengths: mirrors the decoder
    const std::vector<uint32_t>& degree = replay.degree;
    size_t next_vertex = 0, next_triangle = 0;
    auto count_triangle = [&]() {
        const Triangle& tri = cm.triangles[ec.triangle_sequence[next_triangle++]];
        replay.count_triangle(decoder_index[tri[0]], decoder_index[tri[1]], decoder_index[tri[2]]);
    };
    for (size_t i = 0; i < ops.size(); ++i) {
        const Op& op = ops[i];
        if (op.kind == 0) {
            next_vertex += 3;
            count_triangle();
            replay.start(uint32_t(next_vertex - 3), uint32_t(next_vertex - 2), uint32_t(next_vertex - 1));
            continue;
        }
        const CutBorder::Loop loop = replay.top();
        const uint32_t g = loop.gate, nv = replay.next[g];
        const uint32_t u = replay.vert[g], v = replay.vert[nv];
        enc.encode(op.kind == 1, models.new_model(degree[u]));
        if (op.kind == 1) {
            if (cm.dummies > 0) enc.encode(op.a != 0, models.is_dummy);
            count_triangle();
            replay.op_new(uint32_t(next_vertex++));
            continue;
        }
        count_triangle();
        enc.encode(op.kind == 2, models.is_right[OpModels::degree_class(degree[u] - 1)]);
        if (op.kind == 2) {
            if (loop.length == 3) replay.op_end();
            else replay.op_right();
            replay.choose_gate();
            continue;
        }
        if (loop.length > 3) enc.encode(op.kind == 3, models.is_left[OpModels::degree_class(degree[v] - 1)]);
        if (op.kind == 3) {
            replay.op_left();
            continue;
        }
        const bool can_split = loop.length >= 5, can_merge = replay.stack.size() >= 2;
        if (can_split && can_merge) enc.encode(op.kind == 4, models.is_split);
        if (op.kind == 4) {
            if (!can_split) throw EncoderGaveUp{};
            put_split_offset(enc, models.split, op.a, op.b);
            replay.op_split(replay.walk(nv, op.a + 2), op.a + 2);
        } else {
            const Op& extra = ops[++i];
            if (!can_merge) throw EncoderGaveUp{};
            put_index(enc, op.a, extra.a);
            put_index(enc, op.b, extra.b);
            const size_t index = replay.stack.size() - 2 - op.a;
            replay.op_merge(replay.walk(replay.stack[index].gate, op.b), index);
        }
    }
    for (const auto& [copy, to] : copies) {
        put_index(enc, copy, vc);
        put_index(enc, to, vc);
    }
    return enc.finish();
}


}  // namespace amc
