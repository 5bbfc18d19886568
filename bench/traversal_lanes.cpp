// Issue 29 item 3's prototype: can one core decide two independent hierarchy streams (two chunks,
// say) faster in lockstep, one node of each in turn, than one after the other? The improved
// traversal is bound by a chain of dependent loads from each node to the next (node -> its
// neighbours' states -> context -> model -> bit -> pushes -> next node; docs/HIERARCHY_CODER.md,
// "Speed"); two streams' chains do not depend on each other, so the processor could overlap them.
//
//   traversal_lanes [--nodes N] [--runs R] [--model surface|random|fe] [--mode all|ref|seq|lock|lib]
//
// Each lane decides one stream of the model (lane B a second copy of the same stream, or with
// --model random a random model of another seed): every level's traversal, arithmetic decoding,
// scan and derivation of the next level, as HierarchyLevelDecoder::decide_level does, without the
// build. Modes, alternated run by run:
//   ref   the library's traversal (LevelTraversal::run_newest), lane A's level, then lane B's
//   seq   this program's stepper: lane A's level, then lane B's
//   lock  the same stepper: one node of A, one node of B, until both levels are decided
//   lib   the library's decoder (HierarchyLevelDecoder::decide_level): stream A, then stream B
// seq and lock run the same code, so their difference is the overlap alone. Each lane's result is
// checked against the library's decode (node count, symbols read). --mode X runs X alone (for
// valgrind --tool=callgrind, whose instruction counts are exact).
#include "bench_common.h"
#include "coding/hierarchy/hierarchy_level_coder.h"

#include <amc/hierarchy_coder.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <string>
#include <vector>

namespace {

using namespace amc;

// The improved traversal of one level as a stepper: run_on's loop (hierarchy_traversal.h, the
// newest stream version) with its locals in a struct, so that two can take turns.
template <class Links>
struct Stepper {
    Links links;
    uint8_t* state;
    uint32_t n;
    const uint8_t* transition;
    CullRules rules;
    uint32_t* bottom[4];
    uint32_t* top[4];
    uint32_t fresh_cursor = 0;
    int current = 0;
    uint32_t i = 0;
    bool culled = false;
    bool popped = false;
    ArithmeticDecoder d;
    HierarchyModels models;
    uint64_t symbols_read, symbol_limit;
    int group_mask;

    static int context_group(const Neighbors& node, const uint8_t* state) {
        unsigned code = 0;
        for (int e = 0; e < 3; ++e) code |= unsigned(neighbor_state(state, node.nbr[e]) & (kDecided | kRefined)) << (2 * e);
        return kContextTable.group[code];
    }

    // Decides one node; false once the level is decided.
    AMC_ALWAYS_INLINE bool step() {
        constexpr uint8_t kDecidedOrPriority = kDecided | kPriorityMask;
        for (;;) {
            if (popped) {
                popped = false;
                break;
            }
            if (current == 0) {
                if (top[0] == bottom[0]) {
                    current = 1;
                    continue;
                }
                i = *--top[0];
                culled = true;
                break;
            }
            if (current < 4) {
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
                break;
            }
            i = BucketQueue::next_fresh(state, n, fresh_cursor);
            if (i == n) return false;
            fresh_cursor = i + 1;
            culled = false;
            break;
        }
        const Neighbors node = links.neighbors(i);
        const Fate fate = culled ? rules.fate(state[i]) : Fate::coded;
        bool refined;
        if (fate == Fate::coded) {
            const int group = context_group(node, state);
            if (symbols_read == symbol_limit) {
                refined = false;
            } else {
                ++symbols_read;
                refined = d.decode_with_limit<kHierarchyModelLimit>(models.groups[size_t(group & group_mask)]);
            }
        } else {
            refined = fate == Fate::hanging_nodes;
        }
        state[i] = uint8_t(state[i] | kDecided | (refined ? kRefined : 0));
        if (refined) {
            for (int e = 0; e < 3; ++e) {
                uint8_t& s = neighbor_state(state, node.nbr[e]);
                s = uint8_t(s + kRefinedNeighbor);
            }
        }
        int next_bucket = 5;
        uint32_t next = 0;
        for (int e = 0; e < 3; ++e) {
            const uint32_t q = node.nbr[e];
            const uint8_t s = neighbor_state(state, q);
            const uint8_t t = transition[s];
            if (t == s) continue;
            state[q] = t;
            links.prefetch(q);
            const int bucket = t >> kPriorityShift;
            *top[bucket]++ = q;
            if (bucket <= next_bucket) {
                next = q;
                next_bucket = bucket;
            }
        }
        if (next_bucket <= current) {
            current = next_bucket;
            --top[current];
            i = next;
            culled = current == 0;
            popped = true;
        }
        return true;
    }
};

enum class Mode { ref, seq, lock, lib };

// This thread's CPU time in milliseconds: on a shared machine, the time it was not running
// does not count (wall time there measures the other jobs).
double thread_cpu_ms() {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return double(t.tv_sec) * 1e3 + double(t.tv_nsec) * 1e-6;
}

// One stream decided level by level (HierarchyLevelDecoder::decide_level without the build).
class Lane {
public:
    Lane(const Hierarchy& h, const std::vector<uint8_t>& stream) : roots_(h.base()), stream_(stream) {
        for (int s = 0; s < 256; ++s) transition_[s] = 0;
        expected_nodes_ = h.node_count();
    }

    void start() {
        header_size_ = read_standalone_stream_header(stream_.data(), stream_.size(), header_);
        decoder_ = ArithmeticDecoder(stream_.data() + header_size_, stream_.size() - header_size_);
        models_ = HierarchyModels();
        traversal_.configure(header_.options, header_.version);
        const CullRules rules{header_.options.cull_one_regularity, header_.options.cull_hanging_nodes};
        for (int s = 0; s < 256; ++s) {  // LevelTraversal::configure's table
            const int p = s >> kPriorityShift;
            int next = p;
            if (!(s & kDecided) && p != 0 && p <= 4) next = rules.fate(uint8_t(s)) != Fate::coded ? 0 : (p > 1 ? p - 1 : 1);
            transition_[s] = uint8_t((s & ~kPriorityMask) | (next << kPriorityShift));
        }
        root_level(roots_, level_, header_.options.cull_one_regularity);
        l_ = 0;
        nodes_ = roots_.root_count();
        symbols_read_ = 0;
        symbol_limit_ = header_.options.truncate_stream ? header_.symbol_count : UINT64_MAX - 1;
    }
    bool done() const { return level_.empty(); }
    bool root_level_now() const { return level_.is_root_level(); }

    // A level no traversal decides (uniform, or after the last symbol): decided whole; true then.
    bool decide_without_traversal() {
        uint8_t* state = level_.state();
        const uint32_t n = uint32_t(level_.size());
        if (symbols_read_ == symbol_limit_ && l_ >= header_.uniform_levels) {
            for (uint32_t i = 0; i < n; ++i) state[i] = uint8_t(state[i] | kDecided);
            level_.refined_count = 0;
            finish_level();
            return true;
        }
        if (l_ < header_.uniform_levels) {
            decide_by_library();
            return true;
        }
        return false;
    }
    void decide_by_library() {
        ArithmeticDecoder d = decoder_;
        HierarchyModels models = models_;
        uint64_t symbols_read = symbols_read_;
        const uint64_t limit = symbol_limit_;
        const int mask = header_.options.use_contexts ? 0xff : 0;
        traversal_.run_newest(
            level_, l_ < header_.uniform_levels,
            [&](uint32_t, int group) {
                if (symbols_read == limit) return false;
                ++symbols_read;
                return d.decode_with_limit<kHierarchyModelLimit>(models.groups[size_t(group & mask)]);
            },
            [&](uint32_t, Fate, bool refined) { return refined; });
        decoder_ = d;
        models_ = models;
        symbols_read_ = symbols_read;
        end_level();
    }
    template <class Links>
    Stepper<Links> stepper(Links links) {
        uint8_t* state = level_.state();
        const uint32_t n = uint32_t(level_.size());
        const CullRules rules{header_.options.cull_one_regularity, header_.options.cull_hanging_nodes};
        if (!rules.one_regularity) {
            for (uint32_t i = 0; i < n; ++i) state[i] = uint8_t(state[i] | kFreshPriority);
        }
        BucketTops tops = buckets_.reset(n);
        Stepper<Links> s{links, state, n, transition_, rules, {}, {}, 0, 0, 0, false, false, decoder_, models_,
                         symbols_read_, symbol_limit_, header_.options.use_contexts ? 0xff : 0};
        for (int b = 0; b < 4; ++b) s.bottom[b] = tops.at[b];
        if (rules.one_regularity && level_.incomplete_count != 0) tops = BucketQueue::push_lowered(state, n, tops);
        for (int b = 0; b < 4; ++b) s.top[b] = tops.at[b];
        return s;
    }
    template <class Links>
    void take_back(const Stepper<Links>& s) {
        decoder_ = s.d;
        models_ = s.models;
        symbols_read_ = s.symbols_read;
        end_level();
    }
    const Level& level() const { return level_; }

    // The whole stream by the library's decoder (HierarchyLevelDecoder::decide_level, its fast
    // and general paths), without the build.
    void decide_all_by_decoder() {
        header_size_ = read_standalone_stream_header(stream_.data(), stream_.size(), header_);
        library_.restart(roots_.base(), header_, HierarchyDecodeOptions().max_nodes);
        ArithmeticDecoder d(stream_.data() + header_size_, stream_.size() - header_size_);
        while (!library_.done()) library_.decide_level(d);
        library_.finish();
        if (library_.node_count() != expected_nodes_) {
            std::fprintf(stderr, "traversal_lanes: the library decided %llu nodes\n", (unsigned long long)library_.node_count());
            std::exit(1);
        }
    }

    // decide_level's tail: the numbering, the closures' orientation bits, the next level.
    void end_level() {
        uint32_t* const closures = closures_.reserve(level_.size());
        const DecidedLevelScan scan = scan_decided_level(level_, numbering_, closures);
        for (uint32_t k = 0; k < scan.closures; ++k) {
            if (header_.orientation_coded) (void)decoder_.decode_with_limit<kHierarchyModelLimit>(models_.orientation);
        }
        finish_level();
    }
    void finish_level() {
        nodes_ += uint64_t(4) * level_.refined_count;
        derive_next_level(level_, numbering_, next_, header_.options.cull_one_regularity);
        std::swap(level_, next_);
        ++l_;
    }
    void check(const char* what) const {
        if (nodes_ != expected_nodes_ || (header_.options.truncate_stream && symbols_read_ != header_.symbol_count) ||
            decoder_.overran()) {
            std::fprintf(stderr, "traversal_lanes: %s decided %llu nodes (not %llu), %llu symbols (not %llu)\n", what,
                         (unsigned long long)nodes_, (unsigned long long)expected_nodes_,
                         (unsigned long long)symbols_read_, (unsigned long long)header_.symbol_count);
            std::exit(1);
        }
    }

private:
    Hierarchy roots_;
    const std::vector<uint8_t>& stream_;
    HierarchyStreamHeader header_;
    size_t header_size_ = 0;
    ArithmeticDecoder decoder_{nullptr, 0};
    HierarchyModels models_;
    LevelTraversal traversal_{HierarchyCoderOptions{}, kHierarchyStreamVersion};
    uint8_t transition_[256];
    Level level_, next_;
    RefinedNumbering numbering_;
    ScratchArray<uint32_t> closures_;
    BucketQueue buckets_;
    HierarchyLevelDecoder library_;
    int l_ = 0;
    uint64_t nodes_ = 0, expected_nodes_ = 0, symbols_read_ = 0, symbol_limit_ = 0;
};

template <class Links>
AMC_NOIPA void run_seq(Stepper<Links>& a, Stepper<Links>& b) {
    Stepper<Links> x = a, y = b;  // locals: the state bytes written could alias the callers'
    while (x.step()) {
    }
    while (y.step()) {
    }
    a = x;
    b = y;
}
template <class Links>
AMC_NOIPA void run_one(Stepper<Links>& a) {
    Stepper<Links> x = a;
    while (x.step()) {
    }
    a = x;
}
template <class Links>
AMC_NOIPA void run_lock(Stepper<Links>& a, Stepper<Links>& b) {
    Stepper<Links> x = a, y = b;
    bool more_x = true, more_y = true;
    while (more_x && more_y) {
        more_x = x.step();
        more_y = y.step();
    }
    while (more_x) more_x = x.step();
    while (more_y) more_y = y.step();
    a = x;
    b = y;
}

// One level of lane A and, if it is at a level too, lane B, decided the way `mode` says.
template <class Links>
void decide_pair(Lane& a, Lane* b, Mode mode, Links la, Links lb) {
    Stepper<Links> sa = a.stepper(la);
    if (b == nullptr) {
        run_one(sa);
        a.take_back(sa);
        return;
    }
    Stepper<Links> sb = b->stepper(lb);
    if (mode == Mode::lock) {
        run_lock(sa, sb);
    } else {
        run_seq(sa, sb);
    }
    a.take_back(sa);
    b->take_back(sb);
}

AMC_NOIPA void decide_all(Lane& a, Lane& b, Mode mode) {
    if (mode == Mode::lib) {
        a.decide_all_by_decoder();
        b.decide_all_by_decoder();
        return;
    }
    a.start();
    b.start();
    while (!a.done() || !b.done()) {
        Lane* ready[2] = {nullptr, nullptr};
        int count = 0;
        for (Lane* lane : {&a, &b}) {
            if (lane->done() || lane->decide_without_traversal()) continue;
            if (mode == Mode::ref) {
                lane->decide_by_library();
                continue;
            }
            ready[count++] = lane;
        }
        if (count == 0) continue;
        Lane& x = *ready[0];
        Lane* y = count == 2 ? ready[1] : nullptr;
        // Both lanes are at the same level index (they start together and every level costs one
        // round), so both have root links or both block links.
        if (x.root_level_now()) {
            decide_pair(x, y, mode, RootLinks{x.level().roots.data()},
                        RootLinks{y != nullptr ? y->level().roots.data() : nullptr});
        } else {
            decide_pair(x, y, mode, BlockLinks{x.level().nbr.data(), x.level().edges.data()},
                        BlockLinks{y != nullptr ? y->level().nbr.data() : nullptr,
                                   y != nullptr ? y->level().edges.data() : nullptr});
        }
    }
    a.check("lane A");
    b.check("lane B");
}

}  // namespace

int main(int argc, char** argv) {
    long nodes = 1000000;
    int runs = 11;
    std::string model_name = "surface", mode_name = "all";
    for (int k = 1; k < argc; ++k) {
        const std::string arg = argv[k];
        if (arg == "--nodes" && k + 1 < argc) {
            nodes = std::atol(argv[++k]);
        } else if (arg == "--runs" && k + 1 < argc) {
            runs = std::atoi(argv[++k]);
        } else if (arg == "--model" && k + 1 < argc) {
            model_name = argv[++k];
        } else if (arg == "--mode" && k + 1 < argc) {
            mode_name = argv[++k];
        } else {
            std::fprintf(stderr, "usage: traversal_lanes [--nodes N] [--runs R] [--model surface|random|fe] "
                                 "[--mode all|ref|seq|lock|lib]\n");
            return 2;
        }
    }
    const BenchModel model = model_name == "fe" ? BenchModel::fe : model_name == "random" ? BenchModel::random
                                                                                          : BenchModel::surface;
    const Hierarchy h = make_bench_hierarchy(model, nodes);
    // Lane B: another random refinement of the same torus (seed 8), else a second copy.
    Hierarchy other_random(make_torus(16, 24, 1.0, 0.35));
    if (model == BenchModel::random) refine_randomly(other_random, uint32_t(nodes * 3 / 4), 12, 8);
    const Hierarchy& hb = model == BenchModel::random ? other_random : h;
    const std::vector<uint8_t> sa = encode_hierarchy(h, HierarchyCoderOptions{});
    const std::vector<uint8_t> sb = encode_hierarchy(hb, HierarchyCoderOptions{});
    Lane a(h, sa), b(hb, sb);

    std::vector<Mode> modes;
    if (mode_name == "all" || mode_name == "ref") modes.push_back(Mode::ref);
    if (mode_name == "all" || mode_name == "seq") modes.push_back(Mode::seq);
    if (mode_name == "all" || mode_name == "lock") modes.push_back(Mode::lock);
    if (mode_name == "all" || mode_name == "lib") modes.push_back(Mode::lib);
    const char* const names[4] = {"ref", "seq", "lock", "lib"};
    std::vector<std::vector<double>> ms(4);
    for (int r = 0; r < runs; ++r) {
        for (const Mode m : modes) {
            const double t0 = thread_cpu_ms();
            decide_all(a, b, m);
            ms[size_t(m)].push_back(thread_cpu_ms() - t0);
        }
    }
    const double total_nodes = double(h.node_count()) + double(hb.node_count());
    std::printf("%s: lanes of %u and %u nodes (%zu and %zu bytes), %d runs, deciding both, thread CPU time (min / median)\n",
                model_name.c_str(), h.node_count(), hb.node_count(), sa.size(), sb.size(), runs);
    for (const Mode m : modes) {
        std::vector<double>& v = ms[size_t(m)];
        std::sort(v.begin(), v.end());
        const double best = v.front(), mid = v[v.size() / 2];
        std::printf("  %-4s %7.1f / %7.1f ms   %5.1f / %5.1f M nodes/s\n", names[size_t(m)], best, mid,
                    total_nodes / best / 1e3, total_nodes / mid / 1e3);
    }
    return 0;
}
