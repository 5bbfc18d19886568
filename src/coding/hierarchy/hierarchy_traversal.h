// The level-wise traversal shared by the hierarchy encoder and decoder (paper, II-B, II-C, II-E).
//
// Within a level every node is decided exactly once: either a rule implies its state (culled:
// 1-regularity, hanging nodes, uniform levels) or one symbol is coded in the node's context group.
// The encoder answers `code` from the hierarchy it holds; the decoder from the stream. Both see
// the same decisions in the same order, so they agree on every context.
//
// The traversal runs on the level forest (level_forest.h); the improved traversal's buckets are
// bucket_queue.h's.
#pragma once

#include "coding/format_version.h"
#include "coding/hierarchy/bucket_queue.h"
#include "coding/hierarchy/level_forest.h"
#include "coding/hierarchy/level_tables.h"
#include "common/compiler.h"

#include <amc/hierarchy_coder.h>

#include <cstdint>

namespace amc {

class LevelTraversal {
public:
    // `stream_version`: the hierarchy stream's version (format_version.h), which says when the
    // nodes 1-regularity culls are decided.
    LevelTraversal(const HierarchyCoderOptions& options, uint8_t stream_version) { configure(options, stream_version); }

    // Switches to other options, keeping the working memory.
    void configure(const HierarchyCoderOptions& options, uint8_t stream_version) {
        options_ = options;
        culls_in_turn_ = culls_decided_in_turn(stream_version);
        // What a decided neighbour does to a node's state in the improved traversal: an
        // undecided node outside bucket 0 moves one bucket down (not below 1), or to bucket 0
        // once its three refined neighbours make it culled (a node culled by 1-regularity is in
        // bucket 0 from the outset).
        const CullRules rules{options.cull_one_regularity, options.cull_hanging_nodes};
        for (int s = 0; s < 256; ++s) {
            const int p = s >> kPriorityShift;
            int next = p;
            if (!(s & kDecided) && p != 0 && p <= 4)
                next = rules.fate(uint8_t(s)) != Fate::coded ? 0 : (p > 1 ? p - 1 : 1);
            after_neighbor_decided_[s] = uint8_t((s & ~kPriorityMask) | (next << kPriorityShift));
        }
    }

    // Gives the working memory's pages back to the system until the next level (release_pages).
    void release_working_memory() { buckets_.release(); }
    // Gives the working memory's storage back to the allocator: all of it, or when it is far
    // larger than a level of n nodes needs.
    void free_working_memory() { buckets_.deallocate(); }
    void shrink_working_memory(uint32_t n) { buckets_.shrink_for(n); }

    // Decides every node of `level` (undecided, canonical order) and records the decisions in
    // the nodes' state; afterwards each state's refined-neighbour count is exact.
    //   code(uint32_t i, int context_group) -> bool   the node's symbol (coded by the caller)
    //   force(uint32_t i, Fate fate, bool refined) -> bool   a decision implied by a rule; returns
    //       the node's actual state (the decoder: `refined`; the encoder: the hierarchy's, so even
    //       an invalid hierarchy keeps the level forest in step with it)
    template <class Code, class Force>
    void run(Level& level, bool uniform_level, Code&& code, Force&& force) {
        with_links(level, [&](auto links) {
            if (culls_in_turn_) {
                run_on<true>(links, level.state(), static_cast<uint32_t>(level.size()), level.incomplete_count,
                             uniform_level, code, force);
            } else {
                run_on<false>(links, level.state(), static_cast<uint32_t>(level.size()), level.incomplete_count,
                              uniform_level, code, force);
            }
        });
    }
    // run for the newest stream version only (culls_in_turn() is false): for hot paths, which
    // then hold no code of older versions (see HierarchyLevelDecoder::decide_level).
    template <class Code, class Force>
    void run_newest(Level& level, bool uniform_level, Code&& code, Force&& force) {
        with_links(level, [&](auto links) {
            run_on<false>(links, level.state(), static_cast<uint32_t>(level.size()), level.incomplete_count,
                          uniform_level, code, force);
        });
    }
    // run for version 1 only (culls_in_turn() is true).
    template <class Code, class Force>
    void run_version1(Level& level, bool uniform_level, Code&& code, Force&& force) {
        with_links(level, [&](auto links) {
            run_on<true>(links, level.state(), static_cast<uint32_t>(level.size()), level.incomplete_count,
                         uniform_level, code, force);
        });
    }
    // Hierarchy stream version 1 (see configure).
    bool culls_in_turn() const { return culls_in_turn_; }

private:
    template <bool kCullsInTurn, class Links, class Code, class Force>
    void run_on(Links links, uint8_t* state, uint32_t n, uint32_t incomplete_count, bool uniform_level, Code& code,
                Force& force) {
        // A copy in a local: the state bytes written below could alias options_.
        const CullRules rules{options_.cull_one_regularity, options_.cull_hanging_nodes};
        if (uniform_level) {
            for (uint32_t i = 0; i < n; ++i) {
                if (force(i, Fate::uniform, true)) {
                    state[i] = uint8_t(state[i] | kDecided | kRefined);
                    add_refined_neighbor(links.neighbors(i), state);
                } else {
                    state[i] = uint8_t(state[i] | kDecided);
                }
            }
            return;
        }
        if (options_.traversal == Traversal::naive) {
            if constexpr (kCullsInTurn) {
                if (rules.one_regularity && incomplete_count != 0) {
                    run_naive_culls_in_turn(links, state, n, code, force);
                    return;
                }
            }
            // (The nodes 1-regularity culls are decided already.)
            for (uint32_t i = 0; i < n; ++i) {
                if (!(state[i] & kDecided)) decide(rules.fate(state[i]), links.neighbors(i), state, i, code, force);
            }
            return;
        }
        // Improved traversal: a bucket queue over priorities 0 (culled: nothing to code) to 4 (no
        // neighbour decided yet); each decided neighbour lowers a node's priority by one. The
        // lowest non-empty bucket goes first, each bucket last in, first out; an entry is stale
        // once its node is decided or has moved to a lower bucket, and is skipped. Every node
        // enters at most five buckets: linear time.
        // The nodes 1-regularity culls (the incomplete ones) are decided first, and a new level's
        // states hold their decisions and the priorities they leave (derive_next_level). The
        // nodes of buckets 1-3 go onto their stacks in reverse canonical order, so that each
        // stack pops in canonical order. Bucket 4 holds every other node in canonical order and
        // never receives another, so it is a cursor. Without the 1-regularity rule every node
        // starts in bucket 4.
        if (!rules.one_regularity) {
            for (uint32_t i = 0; i < n; ++i) state[i] = uint8_t(state[i] | kFreshPriority);
        }
        const BucketTops bottoms = buckets_.reset(n);
        uint32_t* const bottom[4] = {bottoms.at[0], bottoms.at[1], bottoms.at[2], bottoms.at[3]};
        uint32_t* top[4] = {bottom[0], bottom[1], bottom[2], bottom[3]};
        uint8_t transition[256];  // a local copy: the state bytes written below could alias the member
        for (int k = 0; k < 256; ++k) transition[k] = after_neighbor_decided_[k];
        // The pushes of node i's decision into the buckets; returns the lowest bucket pushed to
        // (5 if none) and in `next` the node pushed last into it.
        auto push_neighbors = [&](const Neighbors& node, uint32_t& next) {
            int next_bucket = 5;
            for (int e = 0; e < 3; ++e) {
                const uint32_t q = node.nbr[e];
                const uint8_t s = neighbor_state(state, q);
                const uint8_t t = transition[s];
                if (t == s) continue;  // decided (or no neighbour), or already in bucket 1
                state[q] = t;
                // Last in, first out: q is likely to be decided soon, and its links are usually
                // not in cache yet.
                links.prefetch(q);
                const int bucket = t >> kPriorityShift;
                *top[bucket]++ = q;
                if (bucket <= next_bucket) {
                    next = q;
                    next_bucket = bucket;
                }
            }
            return next_bucket;
        };
        if (rules.one_regularity && incomplete_count != 0) {
            BucketTops tops{{top[0], top[1], top[2], top[3]}};
            if constexpr (kCullsInTurn) {
                tops = push_culled_in_turn(links, state, n, tops);
            } else {
                tops = BucketQueue::push_lowered(state, n, tops);
            }
            for (int b = 0; b < 4; ++b) top[b] = tops.at[b];
        }
        uint32_t fresh_cursor = 0;
        constexpr uint8_t kDecidedOrPriority = kDecided | kPriorityMask;
        int current = 0;  // every bucket below this one is empty
        uint32_t i = 0;
        bool culled = false;
        bool popped = false;  // i was taken off its bucket by the previous step
        for (;;) {
            // A node from bucket 0 is culled; from any other bucket it carries a symbol (its
            // priority was set when its fate last changed).
            if (popped) {
                popped = false;
            } else if (current == 0) {
                if (top[0] == bottom[0]) {
                    current = 1;
                    continue;
                }
                i = *--top[0];  // entries of bucket 0 are never stale
                culled = true;
            } else if (current < 4) {
                // Most entries below a bucket's top are stale (every move from bucket 3 to 2
                // leaves one in 3); they are skipped here rather than by the outer loop.
                const uint8_t live = uint8_t(current << kPriorityShift);
                uint32_t* t = top[current];
                uint32_t* const b = bottom[current];
                bool found = false;
                while (t != b) {
                    i = *--t;
                    if ((state[i] & kDecidedOrPriority) == live) {
                        found = true;
                        break;
                    }
                }
                top[current] = t;
                if (!found) {
                    ++current;
                    continue;
                }
                culled = false;
            } else {
                i = BucketQueue::next_fresh(state, n, fresh_cursor);
                if (i == n) break;
                fresh_cursor = i + 1;
                culled = false;
            }
            const Neighbors node = links.neighbors(i);
            decide(culled ? rules.fate(state[i]) : Fate::coded, node, state, i, code, force);
            // The last push into the lowest bucket is the next node whenever that bucket is now
            // the lowest non-empty one. Knowing it here, rather than reading it back from the
            // bucket, keeps the stack and the state byte out of the chain of loads from one node
            // to the next.
            uint32_t next = 0;
            const int next_bucket = push_neighbors(node, next);
            if (next_bucket <= current) {
                current = next_bucket;
                --top[current];
                i = next;
                culled = current == 0;
                popped = true;
            }
        }
    }

    // Hierarchy stream version 1, improved traversal: the nodes 1-regularity culls went first, one
    // by one in canonical order, each pushing its undecided neighbours one bucket lower as
    // run_on's steps do; a node lowered twice or three times left stale entries behind, and each
    // stack holds its nodes in the order they were lowered. The level's states hold version 2's
    // priorities (derive_next_level): they are put back in bucket 4 and lowered again in that order.
    template <class Links>
    AMC_NOIPA BucketTops push_culled_in_turn(Links links, uint8_t* state, uint32_t n, BucketTops tops) const {
        for (uint32_t i = 0; i < n; ++i) {
            if (!(state[i] & kDecided)) state[i] = uint8_t((state[i] & ~kPriorityMask) | kFreshPriority);
        }
        for (uint32_t i = 0; i < n; ++i) {
            if (!(state[i] & kDecided)) continue;  // decided at the outset: culled by 1-regularity
            const Neighbors node = links.neighbors(i);
            for (int e = 0; e < 3; ++e) {
                const uint32_t q = node.nbr[e];
                const uint8_t s = neighbor_state(state, q);
                const uint8_t t = after_neighbor_decided_[s];
                if (t == s) continue;
                state[q] = t;
                *tops.at[t >> kPriorityShift]++ = q;
            }
        }
        return tops;
    }

    // Hierarchy stream version 1, naive traversal: a node 1-regularity culls is decided in its
    // turn, so the nodes before it see it undecided (context group). The level's states hold it
    // decided (derive_next_level): it is made undecided again first.
    template <class Links, class Code, class Force>
    AMC_NOIPA void run_naive_culls_in_turn(Links links, uint8_t* state, uint32_t n, Code& code, Force& force) const {
        const CullRules rules{options_.cull_one_regularity, options_.cull_hanging_nodes};
        for (uint32_t i = 0; i < n; ++i) {
            if (!(state[i] & kComplete)) state[i] = 0;
        }
        for (uint32_t i = 0; i < n; ++i) {
            if (!(state[i] & kComplete)) {
                state[i] = uint8_t(state[i] | kDecided);  // culled: not refined
                continue;
            }
            decide(rules.fate(state[i]), links.neighbors(i), state, i, code, force);
        }
    }

    // A node has at most three neighbour edges, so its count of refined neighbours never
    // overflows; the shared kNoNeighborState byte may, harmlessly: adding multiples of 4 keeps its
    // decided, not refined bits.
    static void add_refined_neighbor(const Neighbors& node, uint8_t* state) {
        for (int e = 0; e < 3; ++e) {
            uint8_t& s = neighbor_state(state, node.nbr[e]);
            s = uint8_t(s + kRefinedNeighbor);
        }
    }

    // The context group of a node: its neighbours refined, not refined, not yet decided.
    static int context_group(const Neighbors& node, const uint8_t* state) {
        unsigned code = 0;
        for (int e = 0; e < 3; ++e) {
            const uint32_t q = node.nbr[e];
            // No neighbour (boundary, or a coarser region: see context_groups.h) counts as not
            // refined; a neighbour's kind is its decided and refined bits.
            const unsigned kind = neighbor_state(state, q) & (kDecided | kRefined);
            code |= kind << (2 * e);
        }
        return kContextTable.group[code];
    }

    // Decides node i (links `node`) whose fate is known: codes its symbol or applies the rule,
    // records the decision and counts it at the neighbours.
    template <class Code, class Force>
    static void decide(Fate fate, const Neighbors& node, uint8_t* state, uint32_t i, Code& code, Force& force) {
        const bool refined = fate == Fate::coded ? code(i, context_group(node, state))
                                                 : force(i, fate, fate == Fate::hanging_nodes);
        state[i] = uint8_t(state[i] | kDecided | (refined ? kRefined : 0));
        if (refined) add_refined_neighbor(node, state);
    }

    HierarchyCoderOptions options_;
    bool culls_in_turn_ = false;  // hierarchy stream version 1 (see configure)
    uint8_t after_neighbor_decided_[256];  // state -> state, see the constructor
    BucketQueue buckets_;
};

}  // namespace amc
