// Encoder of mode 2, the angle-guided cut-border coder (FORMAT.md 4.10-4.16; base_angle_coder.h).
// It runs the decoder's border and models (base_angle_border.h) on the closed mesh, reads each op
// off the mesh and codes it at once, in every context set (the conquest does not depend on the
// set), keeping the shortest stream.
#include "coding/base/base_angle_border.h"
#include "coding/base/base_angle_coder.h"
#include "coding/base/base_mesh_closing.h"
#include "common/check.h"
#include "common/parallel.h"

#include <algorithm>
#include <cstdint>
#include <iterator>
#include <mutex>
#include <utility>

namespace amc {

using angle_mode::Border;
using angle_mode::Models;

namespace {

class Encoder {
public:
    Encoder(const TriangleMesh& mesh, const ClosedMesh& cm, BaseConnectivityMode mode, uint32_t gate_radius, uint32_t first,
            uint32_t rotation)
        : mesh_(mesh), cm_(cm), mode_(mode), first_(first), rotation_(rotation) {
        border_.gate_radius = gate_radius;
        border_.tip_window = tip_window_of(mode);
        for (int set = 0; set < angle_mode::kContextSets; ++set) streams_.emplace_back(set);
    }

    // The stream of each context set, in set order.
    std::vector<std::vector<uint8_t>> run(BaseMeshCode& code) {
        count_vertices();
        count_components_and_merges();
        const uint32_t isolated = static_cast<uint32_t>(mesh_.positions.size()) - used_;
        const bool plain = isolated == 0 && cm_.dummies == 0 && copies_ == 0 && components_ == 1 && merges_ == 0;
        for (SetStream& s : streams_) {
            s.enc.encode_bits_raw(uint32_t(mode_), 2);
            s.enc.encode_bits_raw(static_cast<uint32_t>(s.set), 2);
            s.enc.encode_bits_raw(border_.gate_radius, 3);
            s.enc.encode_bits_raw(plain ? 1 : 0, 1);
            if (!plain) {
                put_count(s.enc, isolated);
                put_count(s.enc, cm_.dummies);
                put_count(s.enc, copies_);
                put_count(s.enc, components_);
                put_count(s.enc, merges_);
            }
        }
        traverse();
        if (triangles_.size() != cm_.triangles.size() || cm_of_.size() != cm_.original.size() ||
            merges_seen_ != merges_)
            throw EncoderGaveUp{};
        fill_orders(code);
        std::vector<std::vector<uint8_t>> out;
        for (SetStream& s : streams_) out.push_back(s.enc.finish());
        return out;
    }

private:
    // The coder of one context set.
    struct SetStream {
        explicit SetStream(int s) : set(s), models(s) {}
        int set;
        Models models;
        ArithmeticEncoder enc;
    };

    const TriangleMesh& mesh_;
    const ClosedMesh& cm_;
    const BaseConnectivityMode mode_;  // 2, or 3 with the tip window
    const uint32_t first_, rotation_;  // the first component's start triangle and its first corner
    uint32_t used_ = 0, copies_ = 0, components_ = 0, merges_ = 0, merges_seen_ = 0;
    std::vector<SetStream> streams_;
    Border border_;
    // Closed vertices: decoder numbering (creation order) and the closed mesh's.
    std::vector<uint32_t> decoder_id_, cm_of_;
    std::vector<uint32_t> final_of_original_;  // final index of an input vertex's first closed vertex
    uint32_t finals_ = 0;
    std::vector<BaseStencil> stencils_;  // per final vertex, as the decoder derives them (FORMAT.md 4.10)
    // Nodes: the unprocessed halfedge across the node's border edge, and whether it is on the
    // border still; per decoder vertex, a list of its nodes (first node, then node to node).
    std::vector<uint32_t> out_he_, node_link_, first_node_;
    std::vector<uint8_t> alive_, processed_;
    // The loops below the top (note_loop_below): each gate's serial + 1 (0: none), the Fenwick tree.
    std::vector<uint32_t> gate_serial_, below_;
    uint32_t serials_ = 0;
    std::vector<uint32_t> triangles_;  // closed triangles in decoder order
    std::vector<uint8_t> rotations_;
    uint64_t walked_ = 0;

    void count_vertices() {
        std::vector<uint8_t> seen(mesh_.positions.size(), 0);
        for (uint32_t o : cm_.original) {
            if (o == kNoVertex) continue;
            if (seen[o]) ++copies_;
            else ++used_;
            seen[o] = 1;
        }
        if (uint64_t{copies_} > 2 * uint64_t{used_} || uint64_t{cm_.dummies} > (uint64_t{used_} + copies_) / 3 + 1)
            throw EncoderGaveUp{};
    }

    // Components of the closed mesh, and the merges Euler's formula asks for (FORMAT.md 4.3).
    void count_components_and_merges() {
        const size_t fc = cm_.triangles.size();
        std::vector<uint8_t> reached(fc, 0);
        std::vector<uint32_t> queue;
        for (uint32_t s = 0; s < cm_.real_triangles; ++s) {
            if (reached[s]) continue;
            ++components_;
            reached[s] = 1;
            queue.assign(1, s);
            while (!queue.empty()) {
                const uint32_t t = queue.back();
                queue.pop_back();
                for (int k = 0; k < 3; ++k) {
                    const uint32_t n = cm_.twin[3 * t + k] / 3;
                    if (!reached[n]) {
                        reached[n] = 1;
                        queue.push_back(n);
                    }
                }
            }
        }
        const int64_t four_m = int64_t(fc) - 2 * int64_t(cm_.original.size()) + 4 * int64_t(components_);
        if (four_m < 0 || four_m % 4 != 0 || four_m / 4 > kMaxBaseCount) throw EncoderGaveUp{};
        merges_ = static_cast<uint32_t>(four_m / 4);
    }

    // A bit in every set's stream, with the model `model_of` picks from that set's models.
    template <class ModelOf>
    void put_bit(bool bit, ModelOf model_of) {
        for (SetStream& s : streams_) s.enc.encode(bit, model_of(s.set, s.models));
    }
    void put_index_all(uint32_t value, uint32_t range) {
        for (SetStream& s : streams_) put_index(s.enc, value, range);
    }
    void charge_walk(uint64_t nodes) {
        walked_ += nodes;
        if (walked_ > angle_mode::walk_budget(cm_.triangles.size())) throw EncoderGaveUp{};
    }

    // The final index of decoder vertex id, or -1 (none, or a dummy).
    int32_t final_of(int32_t id) const {
        if (id < 0) return -1;
        const uint32_t original = cm_.original[cm_of_[size_t(id)]];
        return original == kNoVertex ? -1 : int32_t(final_of_original_[original]);
    }

    // The decoder's stencil of a new final vertex from the raw one of the border (decoder ids):
    // the parallelogram where all three are final vertices, else the first that is, else the
    // previous final vertex.
    BaseStencil stencil_of(const BaseStencil& raw) const {
        const int32_t m0 = final_of(raw[0]), m1 = final_of(raw[1]), m2 = final_of(raw[2]);
        if (m0 >= 0 && m1 >= 0 && m2 >= 0) return {m0, m1, m2};
        if (m0 >= 0) return {m0, -1, -1};
        if (m1 >= 0) return {m1, -1, -1};
        return {int32_t(finals_) - 1, -1, -1};
    }

    // Creates the decoder vertex of closed vertex x, with its dummy and copy symbols; `raw` is
    // the stencil the decoder has for it in decoder ids.
    uint32_t create_vertex(uint32_t x, bool may_be_dummy, const BaseStencil& raw) {
        if (x >= decoder_id_.size() || decoder_id_[x] != kNoVertex) throw EncoderGaveUp{};
        const uint32_t original = cm_.original[x];
        const bool dummy = original == kNoVertex;
        if (dummy && !may_be_dummy) throw EncoderGaveUp{};
        if (may_be_dummy && cm_.dummies > 0) put_bit(dummy, [](int, Models& m) -> BitModel& { return m.dummy; });
        if (!dummy) {
            const uint32_t target = final_of_original_[original];
            if (copies_ > 0 && finals_ > 0) {
                put_bit(target != kNoVertex, [](int, Models& m) -> BitModel& { return m.copy; });
                if (target != kNoVertex) put_index_all(target, finals_);
            } else if (target != kNoVertex) {
                throw EncoderGaveUp{};
            }
            if (target == kNoVertex) {
                stencils_.push_back(stencil_of(raw));
                final_of_original_[original] = finals_++;
            }
        }
        const uint32_t id = border_.add_vertex(dummy ? Vec3{} : mesh_.positions[original], !dummy);
        decoder_id_[x] = id;
        cm_of_.push_back(x);
        first_node_.push_back(kNoVertex);
        return id;
    }

    void visit_triangle(uint32_t he) {
        const uint32_t t = he / 3;
        if (processed_[t]) throw EncoderGaveUp{};
        processed_[t] = 1;
        triangles_.push_back(t);
        rotations_.push_back(static_cast<uint8_t>(he % 3));
        const Triangle& tri = cm_.triangles[t];
        border_.count_triangle(decoder_id_[tri[0]], decoder_id_[tri[1]], decoder_id_[tri[2]]);
    }

    void track(uint32_t node, uint32_t he) {
        if (out_he_.size() <= node) {
            out_he_.resize(node + 1, kNoVertex);
            alive_.resize(node + 1, 0);
            node_link_.resize(node + 1, kNoVertex);
        }
        out_he_[node] = he;
        alive_[node] = 1;
        const uint32_t v = border_.vert(node);
        node_link_[node] = first_node_[v];
        first_node_[v] = node;
    }

    // Is closed triangle t in the unprocessed sector of node n (between its out and in edges)?
    bool sector_holds(uint32_t n, uint32_t t) const {
        uint32_t he = out_he_[n];
        const uint32_t stop = out_he_[border_.prev(n)] / 3;
        for (size_t steps = 0; steps <= cm_.triangles.size(); ++steps) {
            if (he / 3 == t) return true;
            if (he / 3 == stop) return false;
            he = cm_.twin[ClosedMesh::prev_halfedge(he)];
        }
        throw EncoderGaveUp{};
    }
    // The border node of decoder vertex w whose sector holds triangle t.
    uint32_t tip_node(uint32_t w, uint32_t t) const {
        uint32_t only = kNoVertex, alive = 0;
        for (uint32_t n = first_node_[w]; n != kNoVertex; n = node_link_[n]) {
            if (!alive_[n]) continue;
            ++alive;
            only = n;
        }
        if (alive == 1) return only;
        for (uint32_t n = first_node_[w]; n != kNoVertex; n = node_link_[n])
            if (alive_[n] && sector_holds(n, t)) return n;
        throw EncoderGaveUp{};
    }

    void traverse() {
        decoder_id_.assign(cm_.original.size(), kNoVertex);
        final_of_original_.assign(mesh_.positions.size(), kNoVertex);
        processed_.assign(cm_.triangles.size(), 0);
        border_.reserve(cm_.original.size(), cm_.original.size() + cm_.original.size() / 8 + 16);
        for (uint32_t i = 0; i < cm_.real_triangles; ++i) {
            // The first component starts at the chosen triangle, the others at their first in input order.
            const uint32_t s = i == 0 ? first_ : i <= first_ ? i - 1 : i;
            if (processed_[s]) continue;
            const uint32_t r = i == 0 ? rotation_ : 0;
            ++components_;
            const Triangle& st = cm_.triangles[s];
            // A component's first vertices: the stencil is the vertex created before.
            const uint32_t a = create_vertex(st[r], false, {int32_t(cm_of_.size()) - 1, -1, -1});
            const uint32_t b = create_vertex(st[(r + 1) % 3], false, {int32_t(a), -1, -1});
            const uint32_t c = create_vertex(st[(r + 2) % 3], false, {int32_t(b), -1, -1});
            visit_triangle(3 * s + r);
            border_.start(a, b, c);
            const uint32_t na = border_.top().gate, nc = border_.next(na), nb = border_.next(nc);
            track(na, cm_.twin[3 * s + (r + 2) % 3]);
            track(nc, cm_.twin[3 * s + (r + 1) % 3]);
            track(nb, cm_.twin[3 * s + r]);
            while (!border_.stack.empty()) {
                if (triangles_.size() >= cm_.triangles.size()) throw EncoderGaveUp{};
                encode_op();
            }
        }
    }

    void encode_op() {
        Border& b = border_;
        const Border::Loop loop = b.top();
        const uint32_t g = loop.gate, nv = b.next(g), p = b.prev(g);
        const uint32_t u = b.vert(g), v = b.vert(nv);
        const uint32_t he = out_he_[g];
        const uint32_t t = he / 3;
        if (processed_[t] || cm_.corner_vertex(he) != cm_of_[u] ||
            cm_.corner_vertex(ClosedMesh::next_halfedge(he)) != cm_of_[v])
            throw EncoderGaveUp{};
        const uint32_t w_closed = cm_.corner_vertex(ClosedMesh::prev_halfedge(he));
        const uint32_t to_v = cm_.twin[ClosedMesh::next_halfedge(he)];  // beyond the new edge w -> v
        const uint32_t to_w = cm_.twin[ClosedMesh::prev_halfedge(he)];  // beyond the new edge u -> w
        const bool is_new = decoder_id_[w_closed] == kNoVertex;
        const uint32_t n = is_new ? kNoVertex : tip_node(decoder_id_[w_closed], t);

        const bool right = n == p;
        // A closed vertex has at least three triangles (else the decoder's rule fails: give up).
        if (b.degree(u) >= 2) {
            const angle_mode::CornerClass corner = b.corner(g);
            const uint32_t degree = b.degree(u);
            put_bit(right, [&](int set, Models& m) -> BitModel& { return m.close_u[Models::closing_context(set, corner, degree)]; });
        }
        else if (right) throw EncoderGaveUp{};
        if (right) {
            visit_triangle(he);
            if (loop.length == 3) {
                alive_[g] = alive_[nv] = alive_[p] = 0;
                b.op_end();
                if (!b.stack.empty()) forget_loop_below(b.top().gate);  // the last loop below is the top now
            } else {
                alive_[g] = 0;
                out_he_[p] = to_v;
                b.op_right();
            }
            return;
        }
        if (loop.length > 3) {
            const bool left = n == b.next(nv);
            if (b.degree(v) >= 2) {
                const angle_mode::CornerClass corner = b.corner(nv);
                const uint32_t degree = b.degree(v);
                put_bit(left, [&](int set, Models& m) -> BitModel& { return m.close_v[Models::closing_context(set, corner, degree)]; });
            }
            else if (left) throw EncoderGaveUp{};
            if (left) {
                visit_triangle(he);
                alive_[nv] = 0;
                out_he_[g] = to_w;
                b.op_left();
                return;
            }
        }
        const bool can_split = loop.length >= 5, can_merge = b.stack.size() >= 2;
        if (can_split || can_merge) {
            const int context0 = Models::new_vertex_context(b.corner(g));
            put_bit(is_new, [&](int set, Models& m) -> BitModel& { return m.new_vertex[set == 0 ? context0 : 0]; });
        }
        else if (!is_new) throw EncoderGaveUp{};
        if (is_new) {
            const uint32_t w = create_vertex(w_closed, true, {int32_t(u), int32_t(v), int32_t(b.opp(g))});
            visit_triangle(he);
            const uint32_t nw = b.op_new(w);
            out_he_[g] = to_w;
            track(nw, to_v);
            return;
        }
        // S if the tip is on the current loop, M otherwise.
        const TipPlace place = locate_tip(n, g, loop.length);
        const bool split = place.split;
        const uint32_t k = place.k;
        if (split && (k < 2 || k + 3 > loop.length)) throw EncoderGaveUp{};
        if ((split && !can_split) || (!split && !can_merge)) throw EncoderGaveUp{};
        if (can_split && can_merge) put_bit(split, [](int, Models& m) -> BitModel& { return m.split; });
        uint32_t nw;
        if (split) {
            encode_split_tip(g, nv, n, k, loop.length);
            visit_triangle(he);
            nw = b.op_split(n, k);
            note_loop_below(b.stack[b.stack.size() - 2].gate);
        } else {
            const size_t index = place.index;
            const uint32_t offset = place.offset;
            ++merges_seen_;
            const uint32_t length = b.stack[index].length;
            put_index_all(static_cast<uint32_t>(b.stack.size() - 2 - index), static_cast<uint32_t>(b.stack.size() - 1));
            put_index_all(offset, length);
            charge_walk(std::min(offset, length - offset));
            visit_triangle(he);
            forget_loop_below(b.stack[index].gate);
            nw = b.op_merge(n, index);
        }
        out_he_[g] = to_w;
        track(nw, to_v);
    }

    // The loops below the top of the stack, for M's tip: splits append them (just below the top),
    // M removes any of them and E makes the last the top, so their stack order is the order of
    // their serial numbers. Each one's gate node (gates change only at the top) is marked with its
    // serial + 1, and a Fenwick tree over the serials counts those still below the top.
    void note_loop_below(uint32_t gate) {
        if (below_.empty()) below_.assign(cm_.triangles.size() + 2, 0);  // a split takes a triangle: fewer serials
        const uint32_t serial = serials_++;
        if (size_t(serial) + 1 >= below_.size()) throw EncoderGaveUp{};
        if (gate_serial_.size() <= gate) gate_serial_.resize(std::max<size_t>(size_t(gate) + 1, 2 * gate_serial_.size()), 0);
        gate_serial_[gate] = serial + 1;
        for (size_t i = size_t(serial) + 1; i < below_.size(); i += i & (~i + 1)) ++below_[i];
    }
    void forget_loop_below(uint32_t gate) {
        const uint32_t serial = gate_serial_[gate] - 1;
        gate_serial_[gate] = 0;
        for (size_t i = size_t(serial) + 1; i < below_.size(); i += i & (~i + 1)) --below_[i];
    }
    // Loops below the top with serials up to `serial`.
    uint32_t loops_below_through(uint32_t serial) const {
        uint32_t count = 0;
        for (size_t i = size_t(serial) + 1; i > 0; i &= i - 1) count += below_[i];
        return count;
    }
    bool marks_gate(uint32_t node) const { return node < gate_serial_.size() && gate_serial_[node] != 0; }

    // Where tip n lies: on the top loop, k steps after the gate's next node (S), or on the loop
    // below the top at stack index `index`, `offset` steps after that loop's gate (M). Found by
    // going round n both ways to the first gate, the top's or a marked one: no further than the
    // decoder walks for the same operation (FORMAT.md 4.14) plus two nodes, so its budget bounds
    // this search too and is charged only what the decoder charges.
    struct TipPlace {
        bool split = false;
        uint32_t k = 0;
        size_t index = 0;
        uint32_t offset = 0;
    };
    TipPlace locate_tip(uint32_t n, uint32_t top_gate, uint32_t top_length) const {
        const Border& b = border_;
        uint32_t back = n, ahead = n, gate = kNoVertex;
        size_t steps = 0;
        bool behind = true;  // the gate found going back from n (n is `steps` after it)
        for (; steps < out_he_.size(); ++steps, back = b.prev(back), ahead = b.next(ahead)) {
            if (back == top_gate || marks_gate(back)) {
                gate = back;
                break;
            }
            if (ahead == top_gate || marks_gate(ahead)) {
                gate = ahead;
                behind = false;
                break;
            }
        }
        if (gate == kNoVertex) throw EncoderGaveUp{};
        TipPlace place;
        if (gate == top_gate) {
            if (steps == 0 || steps >= top_length) throw EncoderGaveUp{};
            place.split = true;
            place.k = static_cast<uint32_t>(behind ? steps - 1 : top_length - steps - 1);
            return place;
        }
        // Stack order is serial order: the loops below the top up to this one's serial end at its index.
        const size_t index = loops_below_through(gate_serial_[gate] - 1) - 1;
        if (index + 1 >= b.stack.size() || b.stack[index].gate != gate || steps >= b.stack[index].length) throw EncoderGaveUp{};
        const uint32_t length = b.stack[index].length;
        place.index = index;
        place.offset = behind ? uint32_t(steps) : uint32_t((length - steps) % length);
        return place;
    }

    // The decoder's rule (base_angle_decoder.cpp, split_tip): the nearest-tip bit when there is a
    // prediction, else the offset.
    void encode_split_tip(uint32_t g, uint32_t nv, uint32_t n, uint32_t k, uint32_t length) {
        const Border::NearestTip tip = border_.nearest_tip(g, nv, length);
        charge_walk(tip.charge);
        if (tip.node != angle_mode::kNoBorderNode) {
            put_bit(tip.node == n, [](int, Models& m) -> BitModel& { return m.nearest; });
            if (tip.node == n) return;
        }
        for (SetStream& s : streams_) put_split_offset(s.enc, s.models.split_offset, k - 2, length - 4);
        charge_walk(std::min(k + 1, length - k - 1));
    }

    void fill_orders(BaseMeshCode& code) const {
        code.vertex_order.assign(finals_, kNoVertex);
        for (uint32_t o = 0; o < mesh_.positions.size(); ++o)
            if (final_of_original_[o] != kNoVertex) code.vertex_order[final_of_original_[o]] = o;
        code.stencils = stencils_;
        // Isolated vertices follow the used ones (FORMAT.md 4.15), each predicted by the one before.
        for (uint32_t o = 0; o < mesh_.positions.size(); ++o) {
            if (final_of_original_[o] != kNoVertex) continue;
            code.stencils.push_back({int32_t(code.vertex_order.size()) - 1, -1, -1});
            code.vertex_order.push_back(o);
        }
        code.triangle_order.clear();
        code.triangle_rotation.clear();
        for (size_t i = 0; i < triangles_.size(); ++i) {
            if (triangles_[i] >= cm_.real_triangles) continue;
            code.triangle_order.push_back(triangles_[i]);
            code.triangle_rotation.push_back(rotations_[i]);
        }
    }
};

// The encoder's search (FORMAT.md 4.16): the stream is written from several start triangles
// with several gate radii, each with every context set, and the shortest is kept. The decoder
// reads whichever was chosen. Measured (docs/BASE_CODER.md): 3-12 % on the coarse bases.
// The first candidate is what version 4's encoder wrote.
constexpr uint32_t kSearchStarts = 16;                // start triangles spread over the input order
constexpr uint32_t kSearchRadii[] = {5, 3, 4, 6, 7};  // 5 first: the best single radius

using Start = BaseStart;

// The candidates in the order they are tried, as many as the budget allows (at least one: the
// first triangle in input order, radius 5).
std::vector<Start> search_candidates(uint32_t real_triangles, size_t closed_triangles, uint64_t budget) {
    const uint64_t per_candidate = uint64_t(angle_mode::kContextSets) * std::max<size_t>(closed_triangles, 1);
    // A mesh too large to try every radius from one start is written as from the first start
    // alone: on the large meshes the search gained nothing (docs/BASE_CODER.md).
    uint64_t allowed = budget / per_candidate;
    if (allowed < std::size(kSearchRadii)) allowed = 1;
    std::vector<Start> out;
    for (uint32_t k = 0; k < kSearchStarts; ++k) {
        const uint32_t first = static_cast<uint32_t>(uint64_t{k} * real_triangles / kSearchStarts);
        if (k > 0 && first == out.back().first) break;  // fewer triangles than starts
        for (uint32_t rotation = 0; rotation < 3; ++rotation)
            for (uint32_t radius : kSearchRadii) {
                if (out.size() == allowed) return out;
                out.push_back({first, rotation, radius});
            }
    }
    return out;
}

}  // namespace

uint64_t one_start_search_budget(uint64_t triangles) {
    return uint64_t(angle_mode::kContextSets) * 3 * std::size(kSearchRadii) * triangles;
}

namespace {

// The shortest stream of the candidates (the earliest among equals) into `code`.
std::vector<uint8_t> encode_angle_candidates(const TriangleMesh& mesh, const ClosedMesh& cm, BaseMeshCode& code,
                                             BaseConnectivityMode mode, const std::vector<Start>& candidates,
                                             unsigned threads) {
    // Every start is coded on its own, in every context set at once, on up to `threads` threads;
    // the shortest (start, set) wins, the earliest among equals, so the choice does not depend on
    // the threads. Only the best so far is kept: holding every candidate's code cost 10 MiB on a
    // base of 768 triangles.
    struct Best {
        std::vector<uint8_t> bytes;
        BaseMeshCode code;
        size_t index = SIZE_MAX;
    } best;
    std::mutex best_mutex;
    parallel_for(candidates.size(), threads, [&](size_t c) {
        const Start& start = candidates[c];
        BaseMeshCode tried;
        std::vector<std::vector<uint8_t>> streams;
        try {
            Encoder e(mesh, cm, mode, start.radius, start.first, start.rotation);
            streams = e.run(tried);
        } catch (const EncoderGaveUp&) {
            return;  // this start does not fit (a walk over the budget, say): the others may
        }
        const std::lock_guard<std::mutex> lock(best_mutex);
        bool won = false;
        for (size_t set = 0; set < streams.size(); ++set) {
            const size_t i = c * angle_mode::kContextSets + set;
            const bool shorter = best.index == SIZE_MAX || streams[set].size() < best.bytes.size() ||
                                 (streams[set].size() == best.bytes.size() && i < best.index);
            if (!shorter) continue;
            best.bytes = std::move(streams[set]);
            best.index = i;
            won = true;
        }
        if (won) best.code = std::move(tried);  // the same orders in every set
    });
    if (best.index == SIZE_MAX) throw EncoderGaveUp{};
    code.vertex_order = std::move(best.code.vertex_order);
    code.triangle_order = std::move(best.code.triangle_order);
    code.triangle_rotation = std::move(best.code.triangle_rotation);
    code.stencils = std::move(best.code.stencils);
    return best.bytes;
}

}  // namespace

std::vector<uint8_t> encode_angle_mode(const TriangleMesh& mesh, BaseMeshCode& code, BaseConnectivityMode mode,
                                       bool search, unsigned threads, uint64_t search_budget) {
    const ClosedMesh cm = make_closed(mesh);
    std::vector<Start> candidates = search_candidates(cm.real_triangles, cm.triangles.size(), search_budget);
    if (!search) candidates.resize(1);
    return encode_angle_candidates(mesh, cm, code, mode, candidates, threads);
}

std::vector<uint8_t> encode_angle_mode(const TriangleMesh& mesh, BaseMeshCode& code, BaseConnectivityMode mode,
                                       const BaseStart& start) {
    AMC_REQUIRE(start.radius < 8 && start.rotation < 3 && start.first < mesh.triangles.size(), invalid_input,
                "base mesh coder: no such start");
    return encode_angle_candidates(mesh, make_closed(mesh), code, mode, {start}, 1);
}

}  // namespace amc
