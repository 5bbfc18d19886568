// Decoder of mode 2, the angle-guided cut-border coder (FORMAT.md 4.10-4.16; base_angle_coder.h).
#include "coding/base/base_angle_border.h"
#include "coding/base/base_angle_coder.h"

#include <algorithm>
#include <string>

namespace amc {

using angle_mode::Border;
using angle_mode::Models;

namespace {

struct Header {
    uint32_t used = 0;  // U: vertices of triangles; the isolated ones follow
    uint32_t dummies = 0, copies = 0, components = 0, merges = 0;
    int context_set = 0;
    uint32_t gate_radius = 0;
    uint32_t closed_vertices = 0, closed_triangles = 0;
};

// FORMAT.md 4.10: every count is checked before anything is sized by it.
Header read_header(ArithmeticDecoder& dec, size_t size, uint32_t vertex_count, uint32_t max_isolated) {
    Header h;
    h.context_set = static_cast<int>(dec.decode_bits_raw(2));
    if (h.context_set >= angle_mode::kContextSets) fail_base_stream("unknown context set");
    h.gate_radius = dec.decode_bits_raw(3);
    uint32_t isolated = 0;
    // A plain mesh: one closed, manifold component of genus 0, every vertex used.
    const bool plain = dec.decode_bits_raw(1) == 1;
    h.components = 1;
    if (!plain) {
        isolated = get_count(dec);
        h.dummies = get_count(dec);
        h.copies = get_count(dec);
        h.components = get_count(dec);
        h.merges = get_count(dec);
    }
    if (isolated > vertex_count) fail_base_stream("bad isolated vertex count");
    if (isolated > max_isolated) fail_base_stream(isolated_refused(isolated, max_isolated));
    h.used = vertex_count - isolated;
    if (uint64_t{h.copies} > 2 * uint64_t{h.used}) fail_base_stream("bad copy count");
    if (uint64_t{h.dummies} > (uint64_t{h.used} + h.copies) / 3 + 1) fail_base_stream("bad dummy count");
    // Every merge costs at least two raw bits.
    if (2 * uint64_t{h.merges} > 8 * (uint64_t{size} + 8)) fail_base_stream("merge count exceeds the stream");
    const uint64_t vc = uint64_t{h.used} + h.dummies + h.copies;
    const int64_t fc = 2 * int64_t(vc) - 4 * int64_t{h.components} + 4 * int64_t{h.merges};
    if (vc > kMaxBaseCount || 3 * uint64_t{h.components} > vc || fc < 0 || fc > int64_t{kMaxBaseCount} ||
        (h.components == 0) != (fc == 0))
        fail_base_stream("inconsistent counts");
    // An operation codes at least one modelled symbol unless it is a C at a gate vertex of one
    // triangle, which the next operation at that gate (now of two triangles) codes one after:
    // every two triangles past a component's first cost a symbol.
    if (uint64_t(fc) - h.components > 2 * max_decodable_symbols(size) + h.components)
        fail_base_stream("triangle count exceeds the stream");
    h.closed_vertices = static_cast<uint32_t>(vc);
    h.closed_triangles = static_cast<uint32_t>(fc);
    return h;
}

class Decoder {
public:
    Decoder(ArithmeticDecoder& dec, size_t size, const Header& header, uint32_t vertex_count, const BasePositionSource& source,
            uint32_t tip_window)
        : dec_(dec), h_(header), source_(source), models_(header.context_set) {
        out_.vertex_count = vertex_count;
        border_.gate_radius = h_.gate_radius;
        border_.tip_window = tip_window;
        // The counts are consistent but the stream may still stop early: memory is reserved for
        // what a stream of this size typically holds and grows with what is decoded. Nodes: one
        // per vertex, plus one per split or merge (few).
        const size_t vertices = std::min<size_t>(h_.closed_vertices, 64 * size + 64);
        border_.reserve(vertices, vertices + vertices / 8 + 16);
        final_of_.reserve(vertices);
        out_.triangles.reserve(std::min<size_t>(h_.closed_triangles, 2 * vertices));
        out_.stencils.reserve(std::min<size_t>(vertex_count, vertices));
        out_.positions.reserve(std::min<size_t>(vertex_count, vertices));
    }

    DecodedBaseMesh run() {
        for (uint32_t c = 0; c < h_.components; ++c) decode_component();
        if (triangles_ != h_.closed_triangles || final_of_.size() != h_.closed_vertices ||
            dummies_seen_ != h_.dummies || copies_seen_ != h_.copies || out_.positions.size() != h_.used)
            fail_base_stream("counts do not match the operations");
        // Isolated vertices follow the used ones (FORMAT.md 4.15).
        for (uint32_t f = h_.used; f < out_.vertex_count; ++f) new_position({int32_t(f) - 1, -1, -1});
        return std::move(out_);
    }

private:
    ArithmeticDecoder& dec_;
    const Header& h_;
    const BasePositionSource& source_;
    DecodedBaseMesh out_;
    Border border_;
    Models models_;
    std::vector<int32_t> final_of_;  // per closed vertex: its final index, -1 for dummies
    uint32_t triangles_ = 0, dummies_seen_ = 0, copies_seen_ = 0;
    uint64_t walked_ = 0;

    void decode_component() {
        const int32_t last = static_cast<int32_t>(final_of_.size()) - 1;
        const uint32_t a = start_vertex(last);
        const uint32_t b = start_vertex(int32_t(a));
        const uint32_t c = start_vertex(int32_t(b));
        add_triangle(a, b, c);
        border_.start(a, b, c);
        while (!border_.stack.empty()) decode_op();
    }

    // One operation (FORMAT.md 4.13); add_triangle refuses one triangle too many.
    void decode_op() {
        if (dec_.overran()) fail_base_stream("truncated", ErrorCode::truncated);
        Border& b = border_;
        const Border::Loop loop = b.top();
        const uint32_t g = loop.gate, nv = b.next(g);
        const uint32_t u = b.vert(g), v = b.vert(nv);
        const int set = h_.context_set;
        // A closed vertex has at least three triangles: one with fewer than two can not close.
        if (b.degree(u) >= 2 && dec_.decode(models_.close_u[Models::closing_context(set, b.corner(g), b.degree(u))])) {
            add_triangle(u, v, b.vert(b.prev(g)));
            if (loop.length == 3) b.op_end();
            else b.op_right();
            return;
        }
        if (loop.length > 3 && b.degree(v) >= 2 &&
            dec_.decode(models_.close_v[Models::closing_context(set, b.corner(nv), b.degree(v))])) {
            add_triangle(u, v, b.vert(b.next(nv)));
            b.op_left();
            return;
        }
        const bool can_split = loop.length >= 5, can_merge = b.stack.size() >= 2;
        if (!(can_split || can_merge) ||
            dec_.decode(models_.new_vertex[set == 0 ? Models::new_vertex_context(b.corner(g)) : 0])) {
            const bool dummy = h_.dummies > 0 && dec_.decode(models_.dummy);
            const uint32_t w = dummy ? new_dummy() : new_vertex({int32_t(u), int32_t(v), int32_t(b.opp(g))});
            add_triangle(u, v, w);
            b.op_new(w);
            return;
        }
        if (can_split && (!can_merge || dec_.decode(models_.split))) {
            uint32_t k = 0;
            const uint32_t n = split_tip(g, nv, loop.length, k);
            add_triangle(u, v, b.vert(n));
            b.op_split(n, k);
            return;
        }
        const uint32_t depth = get_index(dec_, static_cast<uint32_t>(b.stack.size() - 1), "merge loop");
        const size_t index = b.stack.size() - 2 - depth;
        const Border::Loop other = b.stack[index];
        const uint32_t offset = get_index(dec_, other.length, "merge offset");
        const uint32_t n = walk_to(other.gate, offset, other.length);
        add_triangle(u, v, b.vert(n));
        b.op_merge(n, index);
    }

    // FORMAT.md 4.14: the nearest-tip bit, else the offset k - 2 from the gate's next node.
    uint32_t split_tip(uint32_t g, uint32_t nv, uint32_t length, uint32_t& k) {
        const Border::NearestTip tip = border_.nearest_tip(g, nv, length);
        charge_walk(tip.charge);
        if (tip.node != angle_mode::kNoBorderNode && dec_.decode(models_.nearest)) {
            k = tip.k;
            return tip.node;
        }
        k = 2 + get_split_offset(dec_, models_.split_offset, length - 4);
        return walk_to(g, k + 1, length);
    }

    // The node `steps` links after `from` on a loop of `length` nodes, walked the shorter way.
    uint32_t walk_to(uint32_t from, uint32_t steps, uint32_t length) {
        const uint32_t back = length - steps;
        charge_walk(std::min(steps, back));
        return steps <= back ? border_.walk(from, steps) : border_.walk(from, -int64_t(back));
    }
    void charge_walk(uint64_t nodes) {
        walked_ += nodes;
        if (walked_ > angle_mode::walk_budget(h_.closed_triangles)) fail_base_stream("split and merge walks exceed the budget");
    }

    uint32_t start_vertex(int32_t previous) { return new_vertex({previous, -1, -1}); }

    uint32_t new_dummy() {
        if (final_of_.size() >= h_.closed_vertices) fail_base_stream("more vertices than announced");
        if (++dummies_seen_ > h_.dummies) fail_base_stream("more dummy vertices than announced");
        final_of_.push_back(-1);
        return border_.add_vertex(Vec3{}, false);
    }

    // A real vertex: a copy of a decoded one (non-manifold vertices), or the next final vertex,
    // whose position the source gives (FORMAT.md 4.10; 4.7 maps the raw stencil).
    uint32_t new_vertex(const BaseStencil& raw) {
        if (final_of_.size() >= h_.closed_vertices) fail_base_stream("more vertices than announced");
        const uint32_t finals = static_cast<uint32_t>(out_.positions.size());
        if (h_.copies > 0 && finals > 0 && dec_.decode(models_.copy)) {
            if (++copies_seen_ > h_.copies) fail_base_stream("more copies than announced");
            const uint32_t target = get_index(dec_, finals, "copy target");
            final_of_.push_back(int32_t(target));
            return border_.add_vertex(out_.positions[target], true);
        }
        if (finals >= h_.used) fail_base_stream("more vertices than announced");
        auto map = [&](int32_t x) { return x < 0 ? -1 : final_of_[size_t(x)]; };
        const int32_t m0 = map(raw[0]), m1 = map(raw[1]), m2 = map(raw[2]);
        const int32_t f = int32_t(finals);
        BaseStencil stencil = {f - 1, -1, -1};
        if (m0 >= 0 && m1 >= 0 && m2 >= 0) stencil = {m0, m1, m2};
        else if (m0 >= 0) stencil = {m0, -1, -1};
        else if (m1 >= 0) stencil = {m1, -1, -1};
        final_of_.push_back(f);
        return border_.add_vertex(new_position(stencil), true);
    }

    Vec3 new_position(const BaseStencil& stencil) {
        out_.stencils.push_back(stencil);
        const Vec3 p = source_(static_cast<uint32_t>(out_.positions.size()), stencil, out_.positions);
        out_.positions.push_back(p);
        return p;
    }

    void add_triangle(uint32_t a, uint32_t b, uint32_t c) {
        if (triangles_ >= h_.closed_triangles) fail_base_stream("more triangles than announced");
        if (a == b || b == c || a == c) fail_base_stream("degenerate triangle");
        ++triangles_;
        border_.count_triangle(a, b, c);
        const int32_t fa = final_of_[a], fb = final_of_[b], fc = final_of_[c];
        if (fa < 0 || fb < 0 || fc < 0) return;  // closes a boundary loop: not a base triangle
        // Distinct closed vertices have distinct final indices unless one is a copy.
        if (h_.copies > 0 && (fa == fb || fb == fc || fa == fc)) fail_base_stream("degenerate triangle");
        out_.triangles.push_back({uint32_t(fa), uint32_t(fb), uint32_t(fc)});
    }
};

}  // namespace

DecodedBaseMesh decode_angle_mode(ArithmeticDecoder& dec, size_t size, uint32_t vertex_count,
                                  const BasePositionSource& source, uint32_t max_isolated, BaseConnectivityMode mode) {
    const Header header = read_header(dec, size, vertex_count, max_isolated);
    return Decoder(dec, size, header, vertex_count, source, tip_window_of(mode)).run();
}

}  // namespace amc
