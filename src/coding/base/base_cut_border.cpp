// The cut border of mode 0 with its loops as splay trees. See base_cut_border.h.
#include "coding/base/base_cut_border.h"

#include <algorithm>

namespace amc {

CutBorder::CutBorder(uint32_t vertices, uint64_t update_budget)
    : degree(vertices, 0), first_of_vertex_(vertices, kNoBorderNode), update_budget_(update_budget) {}

uint32_t CutBorder::add_vertex() {
    degree.push_back(0);
    first_of_vertex_.push_back(kNoBorderNode);
    return static_cast<uint32_t>(degree.size() - 1);
}

bool CutBorder::count_triangle(uint32_t a, uint32_t b, uint32_t c) {
    for (uint32_t v : {a, b, c}) {
        ++degree[v];
        for (uint32_t x = first_of_vertex_[v]; x != kNoBorderNode; x = next_of_vertex_[x]) {
            ++updates_;
            splay(x);  // x's subtree is then its whole tree: one pull updates every maximum
            pull(x);
        }
    }
    return updates_ <= update_budget_;
}

uint32_t CutBorder::new_node(uint32_t v, uint32_t o) {
    const uint32_t x = static_cast<uint32_t>(vert.size());
    next.push_back(kNoBorderNode);
    prev.push_back(kNoBorderNode);
    vert.push_back(v);
    opp.push_back(o);
    left_.push_back(kNoBorderNode);
    right_.push_back(kNoBorderNode);
    parent_.push_back(kNoBorderNode);
    size_.push_back(1);
    max_degree_.push_back(degree[v]);
    next_of_vertex_.push_back(first_of_vertex_[v]);
    prev_of_vertex_.push_back(kNoBorderNode);
    if (first_of_vertex_[v] != kNoBorderNode) prev_of_vertex_[first_of_vertex_[v]] = x;
    first_of_vertex_[v] = x;
    return x;
}

void CutBorder::retire(uint32_t x) {
    const uint32_t before = prev_of_vertex_[x], after = next_of_vertex_[x];
    if (before == kNoBorderNode) first_of_vertex_[vert[x]] = after;
    else next_of_vertex_[before] = after;
    if (after != kNoBorderNode) prev_of_vertex_[after] = before;
    splay(x);
    const uint32_t a = left_[x], b = right_[x];
    if (a != kNoBorderNode) parent_[a] = kNoBorderNode;
    if (b != kNoBorderNode) parent_[b] = kNoBorderNode;
    left_[x] = right_[x] = kNoBorderNode;
    join(a, b);
}

void CutBorder::start(uint32_t a, uint32_t b, uint32_t c) {
    const uint32_t na = new_node(a, b), nc = new_node(c, a), nb = new_node(b, c);
    link(na, nc);
    link(nc, nb);
    link(nb, na);
    join(join(na, nc), nb);
    stack.push_back({na, 3});
}

uint32_t CutBorder::op_new(uint32_t w) {
    Loop& l = top();
    const uint32_t g = l.gate, nv = next[g];
    const uint32_t nw = new_node(w, vert[g]);
    opp[g] = vert[nv];
    link(g, nw);
    link(nw, nv);
    ++l.length;
    splay(g);
    right_[nw] = right_[g];
    if (right_[nw] != kNoBorderNode) parent_[right_[nw]] = nw;
    pull(nw);
    right_[g] = nw;
    parent_[nw] = g;
    pull(g);
    return nw;
}

void CutBorder::op_right() {
    Loop& l = top();
    const uint32_t g = l.gate, p = prev[g], nv = next[g];
    opp[p] = vert[g];
    link(p, nv);
    l.gate = p;
    --l.length;
    retire(g);
}

void CutBorder::op_left() {
    Loop& l = top();
    const uint32_t g = l.gate, nv = next[g], nw = next[nv];
    opp[g] = vert[nv];
    link(g, nw);
    --l.length;
    retire(nv);
}

void CutBorder::op_end() {
    const uint32_t g = top().gate;
    for (uint32_t x : {g, next[g], next[next[g]]}) retire(x);
    stack.pop_back();
}

uint32_t CutBorder::op_split(uint32_t n, uint32_t k) {
    const uint32_t g = top().gate, pn = prev[n];
    ending_at(g);  // v .. pn, n .. g
    cut_after(pn);
    const uint32_t nw = close_gate_at(n);
    join(pn, nw);
    top().length -= k;
    stack.insert(stack.end() - 1, Loop{nw, k + 1});
    return nw;
}

uint32_t CutBorder::op_merge(uint32_t n, size_t index) {
    const uint32_t current = ending_at(top().gate);  // v .. g
    const uint32_t before_n = cut_before(n);
    const uint32_t other = join(n, before_n);  // n .. pn
    const uint32_t nw = close_gate_at(n);
    join(join(current, other), nw);
    const uint32_t other_length = stack[index].length;
    stack.erase(stack.begin() + static_cast<std::ptrdiff_t>(index));
    top().length += other_length + 1;
    return nw;
}

uint32_t CutBorder::close_gate_at(uint32_t n) {
    const uint32_t g = top().gate, nv = next[g], pn = prev[n];
    const uint32_t nw = new_node(vert[n], vert[g]);
    opp[g] = vert[nv];
    link(g, n);
    link(pn, nw);
    link(nw, nv);
    return nw;
}

void CutBorder::choose_gate() {
    if (stack.empty()) return;
    const uint32_t g = top().gate;
    splay(g);  // its right subtree follows it around the loop, then its left subtree
    const uint32_t most = max_degree_[g];
    uint32_t x = g;
    if (degree[vert[g]] != most) {
        x = right_[g] != kNoBorderNode && max_degree_[right_[g]] == most ? right_[g] : left_[g];
        for (;;) {
            if (left_[x] != kNoBorderNode && max_degree_[left_[x]] == most) x = left_[x];
            else if (degree[vert[x]] == most) break;
            else x = right_[x];
        }
    }
    splay(x);
    top().gate = x;
}

uint32_t CutBorder::walk(uint32_t n, uint32_t steps) {
    uint32_t x = ending_at(n);  // n last: the node wanted is at position steps - 1
    const uint32_t length = size_of(x);
    uint32_t rank = static_cast<uint32_t>((uint64_t{steps} + length - 1) % length);
    for (;;) {
        const uint32_t before = size_of(left_[x]);
        if (rank < before) {
            x = left_[x];
        } else if (rank == before) {
            break;
        } else {
            rank -= before + 1;
            x = right_[x];
        }
    }
    splay(x);
    return x;
}

uint32_t CutBorder::steps_between(uint32_t from, uint32_t to) {
    const uint32_t length = size_of(ending_at(from));
    return static_cast<uint32_t>((uint64_t{index_of(to)} + 1) % length);
}

bool CutBorder::same_loop(uint32_t a, uint32_t b) {
    splay(a);
    splay(b);  // in a's tree, a is then below b
    return a == b || parent_[a] != kNoBorderNode;
}

void CutBorder::pull(uint32_t x) {
    const uint32_t l = left_[x], r = right_[x];
    size_[x] = 1 + size_of(l) + size_of(r);
    uint32_t most = degree[vert[x]];
    if (l != kNoBorderNode) most = std::max(most, max_degree_[l]);
    if (r != kNoBorderNode) most = std::max(most, max_degree_[r]);
    max_degree_[x] = most;
}

void CutBorder::rotate(uint32_t x) {
    const uint32_t p = parent_[x], g = parent_[p];
    if (left_[p] == x) {
        left_[p] = right_[x];
        if (right_[x] != kNoBorderNode) parent_[right_[x]] = p;
        right_[x] = p;
    } else {
        right_[p] = left_[x];
        if (left_[x] != kNoBorderNode) parent_[left_[x]] = p;
        left_[x] = p;
    }
    parent_[p] = x;
    parent_[x] = g;
    if (g != kNoBorderNode) (left_[g] == p ? left_[g] : right_[g]) = x;
    pull(p);
    pull(x);
}

void CutBorder::splay(uint32_t x) {
    while (parent_[x] != kNoBorderNode) {
        const uint32_t p = parent_[x], g = parent_[p];
        if (g != kNoBorderNode) rotate((left_[g] == p) == (left_[p] == x) ? p : x);
        rotate(x);
    }
}

uint32_t CutBorder::join(uint32_t a, uint32_t b) {
    if (a == kNoBorderNode) return b;
    if (b == kNoBorderNode) return a;
    uint32_t last = a;
    while (right_[last] != kNoBorderNode) last = right_[last];
    splay(last);
    right_[last] = b;
    parent_[b] = last;
    pull(last);
    return last;
}

uint32_t CutBorder::cut_after(uint32_t x) { return cut_off(x, right_); }

uint32_t CutBorder::cut_before(uint32_t x) { return cut_off(x, left_); }

uint32_t CutBorder::cut_off(uint32_t x, std::vector<uint32_t>& side) {
    splay(x);
    const uint32_t rest = side[x];
    if (rest == kNoBorderNode) return kNoBorderNode;
    parent_[rest] = kNoBorderNode;
    side[x] = kNoBorderNode;
    pull(x);
    return rest;
}

uint32_t CutBorder::ending_at(uint32_t x) {
    const uint32_t rest = cut_after(x);
    return join(rest, x);
}

uint32_t CutBorder::index_of(uint32_t x) {
    splay(x);
    return size_of(left_[x]);
}

}  // namespace amc
