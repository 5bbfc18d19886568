// The cut border of mode 0 (FORMAT.md 4.5), shared by its encoder and decoder: a stack of loops
// of border nodes, and the triangles decoded around each vertex (the ops' contexts and the gate
// rule). Each loop is held twice: as a doubly linked ring for the steps next to the gate, and as
// a splay tree in ring order whose nodes carry their vertex's triangle count, so that choosing
// the gate, walking to a split's tip and cutting or splicing loops cost amortized logarithmic
// time, not a loop's length (a strip's loop is as long as the strip).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace amc {

struct CutBorder {
    struct Loop {
        uint32_t gate;
        uint32_t length;
    };
    // Per node: the ring, the node's vertex and the third vertex of the decoded triangle on the
    // border edge leaving it (the parallelogram stencil of a new vertex there).
    std::vector<uint32_t> next, prev, vert, opp;
    std::vector<Loop> stack;      // the top is the current loop; its gate is the edge leaving `gate`
    std::vector<uint32_t> degree;  // per vertex: triangles created around it

    // `update_budget` bounds the node updates of count_triangle (FORMAT.md 4.5).
    CutBorder(uint32_t vertices, uint64_t update_budget);

    uint32_t add_vertex();
    // Counts a new triangle around its three vertices and updates their border nodes; false
    // once the updates pass the budget.
    bool count_triangle(uint32_t a, uint32_t b, uint32_t c);

    Loop& top() { return stack.back(); }
    // Starts a component with triangle (a, b, c): loop a -> c -> b, gate at a.
    void start(uint32_t a, uint32_t b, uint32_t c);
    // C: new vertex w on the gate; returns its node.
    uint32_t op_new(uint32_t w);
    // R: the tip is the vertex before u; u leaves the border, the gate moves back.
    void op_right();
    // L: the tip is the vertex after v; v leaves the border.
    void op_left();
    // E: the 3-loop is closed.
    void op_end();
    // S: the tip is node n = k steps after v (2 <= k <= length - 3). The part v .. n becomes a
    // loop of its own, pushed below the current one; returns the new node of w in that part.
    uint32_t op_split(uint32_t n, uint32_t k);
    // M: the tip is node n of the stack loop `index` (stack position); the loops are merged.
    uint32_t op_merge(uint32_t n, size_t index);
    // After R and E: the gate moves to the first node, from the gate on around the loop, whose
    // vertex has the most triangles (the vertex closest to completion: fewer splits, as in
    // Alliez–Desbrun's conquest).
    void choose_gate();
    // The node `steps` nodes after n around its loop.
    uint32_t walk(uint32_t n, uint32_t steps);
    // Steps from node `from` forward to node `to` of the same loop.
    uint32_t steps_between(uint32_t from, uint32_t to);
    bool same_loop(uint32_t a, uint32_t b);
    // The border nodes holding vertex v: first_node_of(v), then next_node_of(x) until kNoBorderNode.
    uint32_t first_node_of(uint32_t v) const { return first_of_vertex_[v]; }
    uint32_t next_node_of(uint32_t node) const { return next_of_vertex_[node]; }
    static constexpr uint32_t kNoBorderNode = UINT32_MAX;

private:
    uint32_t new_node(uint32_t v, uint32_t o);
    void link(uint32_t a, uint32_t b) {
        next[a] = b;
        prev[b] = a;
    }
    // S and M alike: the gate's triangle has its tip at node n elsewhere on the loops. The gate
    // now leads to n, and a second node of the tip's vertex joins n's predecessor to the gate's
    // far end; returns it.
    uint32_t close_gate_at(uint32_t n);
    void retire(uint32_t node);  // leaves the border: off its vertex's list and out of its tree

    // Splay trees over the loops, in ring order, keyed by position (subtree sizes), each node
    // carrying its vertex's degree and its subtree's largest degree.
    void pull(uint32_t x);
    void rotate(uint32_t x);
    void splay(uint32_t x);
    uint32_t join(uint32_t a, uint32_t b);         // roots; returns the root of a then b
    uint32_t cut_after(uint32_t x);                // x's tree keeps .. x; returns the rest's root
    uint32_t cut_before(uint32_t x);               // x's tree keeps x ..; returns the rest's root
    uint32_t cut_off(uint32_t x, std::vector<uint32_t>& side);  // x splayed; its `side` subtree cut
    uint32_t ending_at(uint32_t x);                // x's loop rotated to end at x; returns its root
    uint32_t index_of(uint32_t x);                 // x's position in its tree (x becomes the root)
    uint32_t size_of(uint32_t x) const { return x == kNoBorderNode ? 0 : size_[x]; }
    std::vector<uint32_t> left_, right_, parent_, size_, max_degree_;

    std::vector<uint32_t> first_of_vertex_, next_of_vertex_, prev_of_vertex_;
    uint64_t updates_ = 0, update_budget_;
};

}  // namespace amc
