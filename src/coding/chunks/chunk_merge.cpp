// The chunks of a chunked file decoded into the whole (chunk_merge.h).
#include "coding/chunks/chunk_merge.h"

#include "coding/file_metadata.h"
#include "common/check.h"
#include "common/parallel.h"
#include "hierarchy/hierarchy_builder.h"

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <memory>
#include <mutex>
#include <string>
#include <utility>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace amc {

namespace {

// Returns the free pages of the heap to the system: glibc keeps blocks below its mapping
// threshold (which grows as large blocks are freed) in the process after they are freed.
void give_back_free_memory() {
#if defined(__GLIBC__)
    malloc_trim(0);
#endif
}

// What both ways of merging know before the first chunk is decoded. The whole's vertices are
// the base's, then every seam vertex (seam order), then each chunk's own in chunk order, until
// finish_vertices drops the seam vertices no chunk holds.
struct MergePlan {
    TriangleMesh base;                // of the chunks' roots
    std::vector<VertexId> base_keys;  // base vertex -> the file's base vertex (its seam key)
    std::vector<VertexId> base_id;    // the file's base vertex -> base vertex (kNoVertex: not a chunk's)
    uint32_t file_base_vertices = 0;
    std::vector<NodeId> first_root;   // of each chunk in the whole
    uint64_t nodes = 0;               // of the whole, by the chunk table
    bool trusted = false;             // the table's node counts may be reserved up front
    bool full = false;                // every level of every chunk of the file: the metadata's counts hold
    VertexId seam_start = 0;
    uint32_t seam_count = 0;
    std::vector<std::pair<NodeId, int>> seam_edges;  // root edges between two chunks, both sides

    ChunkVertexKeys keys_in_whole() const { return {&base_keys, seam_start, seam_count, file_base_vertices}; }
    VertexId own_start() const { return seam_start + seam_count; }
};

MergePlan plan_merge(const std::vector<ChunkJob>& jobs, const ChunkMergeInput& input) {
    MergePlan plan;
    std::vector<RootRange> ranges;
    for (const ChunkJob& job : jobs) ranges.push_back(job.roots);
    if (input.whole_file) {
        plan.base = *input.base;
        plan.base_keys.resize(plan.base.positions.size());
        for (VertexId v = 0; v < plan.base_keys.size(); ++v) plan.base_keys[v] = v;
    } else {
        plan.base = base_of_roots(*input.base, ranges, plan.base_keys);
    }
    plan.nodes = plan.base.triangles.size();
    std::vector<uint32_t> part_of_root;
    for (size_t i = 0; i < jobs.size(); ++i) {
        plan.first_root.push_back(NodeId(part_of_root.size()));
        part_of_root.resize(part_of_root.size() + jobs[i].roots.count, uint32_t(i));
        plan.nodes += jobs[i].nodes - jobs[i].roots.count;
    }
    // The table's counts are trusted as far as a whole file's decoder reserves up front for the
    // file's size. Beyond that (a file of uniform levels, or a crafted one) the whole grows as
    // the chunks are decoded.
    plan.trusted = input.options.max_level < 0 &&
                   plan.nodes <= plan.base.triangles.size() + kReservedNodesPerFileByte * uint64_t(input.file_size);
    plan.full = input.whole_file && input.options.max_level < 0;
    plan.seam_start = VertexId(plan.base.positions.size());
    plan.seam_count = input.seam->vertex_count();
    AMC_REQUIRE(uint64_t(plan.seam_start) + plan.seam_count < kNoVertex, limit_exceeded, "too many vertices");
    AMC_REQUIRE(!plan.full || (input.vertices >= plan.own_start() && input.vertices < kNoVertex), corrupt,
                "the metadata's vertex count does not fit the base and the seam");
    plan.file_base_vertices = input.seam->base_vertex_count();
    plan.base_id.assign(input.base->positions.size(), kNoVertex);
    for (VertexId v = 0; v < plan.base_keys.size(); ++v) plan.base_id[plan.base_keys[v]] = v;
    return plan;
}

// The root edges between two chunks of `h` (over plan.base): both sides.
void find_seam_edges(MergePlan& plan, const Hierarchy& h, size_t chunks) {
    std::vector<uint32_t> part_of_root(h.root_count());
    for (size_t i = 0; i < chunks; ++i) {
        const NodeId end = i + 1 < chunks ? plan.first_root[i + 1] : h.root_count();
        std::fill(part_of_root.begin() + plan.first_root[i], part_of_root.begin() + end, uint32_t(i));
    }
    for (NodeId r = 0; r < part_of_root.size(); ++r)
        for (int e = 0; e < 3; ++e)
            if (!h.is_boundary_edge(r, e) && part_of_root[h.neighbor(r, e)] != part_of_root[r]) plan.seam_edges.emplace_back(r, e);
}

ChunkDecodeLimits limits_of(const ChunkJob& job, const ChunkMergeInput& input) {
    ChunkDecodeLimits limits;
    limits.max_nodes = std::min(job.nodes, input.options.max_nodes);
    limits.max_level = input.options.max_level;
    limits.file_version = input.file_version;
    limits.stream_version = hierarchy_stream_version_of_file(input.file_version);
    return limits;
}

std::string chunk_name(const ChunkJob& job) { return "chunk " + std::to_string(job.chunk); }

// Once every chunk is in: checks the whole file's vertices against the metadata, or drops the
// seam vertices that no decoded chunk holds.
void finish_vertices(Hierarchy& whole, const MergePlan& plan, const std::vector<uint8_t>& seam_used,
                     const ChunkMergeInput& input) {
    const auto unused = std::find(seam_used.begin(), seam_used.end(), uint8_t(0));
    if (plan.full) {
        AMC_REQUIRE(unused == seam_used.end(), corrupt,
                    "seam block: vertex " + std::to_string(unused - seam_used.begin()) + " is in no chunk");
        AMC_REQUIRE(whole.positions().size() == input.vertices, corrupt, "the chunks hold fewer vertices than the metadata says");
        return;
    }
    if (unused == seam_used.end()) return;
    std::vector<VertexId> seam_id(plan.seam_count, kNoVertex);
    std::vector<Vec3> positions(whole.positions().begin(), whole.positions().begin() + plan.seam_start);
    for (uint32_t s = 0; s < plan.seam_count; ++s) {
        if (!seam_used[s]) continue;
        seam_id[s] = VertexId(positions.size());
        positions.push_back(whole.position(plan.seam_start + s));
    }
    const VertexId own_start = plan.own_start(), removed = VertexId(own_start - positions.size());
    positions.insert(positions.end(), whole.positions().begin() + own_start, whole.positions().end());
    HierarchyBuilder::stitch_rename_vertices(whole, whole.root_count(), whole.node_capacity(), [&](VertexId v) {
        return v < plan.seam_start ? v : v < own_start ? seam_id[v - plan.seam_start] : v - removed;
    });
    HierarchyBuilder::stitch_positions(whole, std::move(positions));
}

// One thread: each chunk decoded straight into the whole, in chunk order, so that its nodes and
// its own vertices come out where the whole keeps them. No chunk hierarchy, no copy.
Hierarchy merge_in_order(const std::vector<ChunkJob>& jobs, const ChunkMergeInput& input, MergePlan& plan,
                         std::vector<ChunkCounts>& counts) {
    Hierarchy whole(plan.base);
    if (plan.trusted) whole.reserve(size_t(plan.nodes), plan.full ? size_t(input.vertices) : 0);
    HierarchyBuilder::append_vertices(whole, input.seam->positions());
    find_seam_edges(plan, whole, jobs.size());
    const std::vector<HierarchyBuilder::RootLink> cut = HierarchyBuilder::cut_root_links(whole, plan.seam_edges);
    std::vector<uint8_t> seam_used(plan.seam_count, 0);
    HierarchyLevelDecoder decoder;
    for (size_t i = 0; i < jobs.size(); ++i) {
        const ChunkJob& job = jobs[i];
        const ChunkPlace place{&whole, plan.first_root[i], job.roots.count, plan.keys_in_whole(), seam_used.data()};
        decode_chunk(decoder, job.data, job.size, place, *input.seam, input.space, limits_of(job, input), chunk_name(job),
                     counts[i]);
        AMC_REQUIRE(input.options.max_level >= 0 || decoder.node_count() == job.nodes, corrupt,
                    chunk_name(job) + " does not hold the nodes the chunk table says");
        AMC_REQUIRE(!plan.full || whole.positions().size() <= input.vertices, corrupt,
                    "the chunks hold more vertices than the metadata says");
    }
    HierarchyBuilder::relink_roots(whole, cut);
    finish_vertices(whole, plan, seam_used, input);
    HierarchyBuilder::stitch_seams(whole, plan.seam_edges);
    return whole;
}

// Several threads: each chunk decoded alone (over its own roots, the seam vertices placed after
// its base vertices) and copied into its slice of the whole.
Hierarchy merge_copies(const std::vector<ChunkJob>& jobs, const ChunkMergeInput& input, MergePlan& plan,
                       std::vector<ChunkCounts>& counts, unsigned threads) {
    const size_t n = jobs.size();
    std::vector<HierarchyBuilder::StitchPart> parts(n);
    std::vector<NodeId> slice_end(n);
    uint64_t whole_nodes = plan.base.triangles.size();
    for (size_t i = 0; i < n; ++i) {
        parts[i].first_root = plan.first_root[i];
        parts[i].first_node = NodeId(whole_nodes);
        whole_nodes += jobs[i].nodes - jobs[i].roots.count;
        slice_end[i] = NodeId(std::min<uint64_t>(whole_nodes, kNoNode));
    }
    // The whole is made first when its size is trusted, so that each chunk is copied into it as
    // soon as it is decoded and the chunk's memory serves the next one. Otherwise (and when a
    // progressive decode stops early) every chunk is decoded first and the whole is made from
    // what they hold.
    const bool whole_first = plan.trusted;
    Hierarchy whole;
    if (whole_first) whole = HierarchyBuilder::stitch_frame(plan.base, size_t(whole_nodes));

    std::vector<std::unique_ptr<HierarchyLevelDecoder>> decoder_of(n), idle;
    std::mutex idle_mutex;
    // Each decoder builds its chunks in room for the largest one, reserved once.
    uint64_t largest_chunk = 0;
    for (const ChunkJob& job : jobs) largest_chunk = std::max(largest_chunk, job.nodes);
    std::atomic<size_t> started{0};  // chunks whose decoding has begun
    std::vector<std::vector<VertexId>> base_keys(n);  // each chunk's base vertex -> the file's
    std::vector<std::vector<uint8_t>> seam_used(n, std::vector<uint8_t>(plan.seam_count, 0));
    std::vector<uint32_t> own(n);                     // vertices that are neither base nor seam vertices
    std::vector<std::vector<Vec3>> own_positions(n);  // their positions, when their place is not known yet
    std::vector<uint32_t> live(n);                    // nodes past the roots
    // The whole's positions: the base's, the seam's, then each chunk's own vertices in chunk order.
    // A whole file has the metadata's vertex count, so each chunk's own positions have their place
    // once the chunks before it are counted: written there directly, or set aside until then.
    // Otherwise all are set aside and placed once every chunk is in.
    const bool positions_first = whole_first && plan.full;
    std::vector<Vec3> positions;
    std::vector<uint64_t> first_own(n);
    std::vector<uint8_t> counted(n, 0), aside(n, 0);
    size_t placed = 0;  // chunks whose place in `positions` is known
    uint64_t next_own = plan.own_start();
    std::mutex placed_mutex;
    auto place_counted = [&] {  // under placed_mutex: the places of the chunks counted in order
        for (; placed < n && counted[placed]; ++placed) {
            first_own[placed] = next_own;
            next_own += own[placed];
            AMC_REQUIRE(next_own <= positions.size(), corrupt, "the chunks hold more vertices than the metadata says");
            if (aside[placed]) {
                std::vector<Vec3>& own_of = own_positions[placed];
                std::copy(own_of.begin(), own_of.end(), positions.begin() + ptrdiff_t(first_own[placed]));
                std::vector<Vec3>().swap(own_of);
            }
        }
    };
    positions = plan.base.positions;
    positions.insert(positions.end(), input.seam->positions().begin(), input.seam->positions().end());
    if (positions_first) positions.resize(size_t(input.vertices));
    std::vector<uint8_t> named(n, 0);  // chunks whose own vertices have their final ids
    // Chunk i, decoded into h, into the whole (its nodes and own positions); its own vertices
    // named own_start() + k until every chunk is counted, unless their place is known already.
    auto copy_into_whole = [&](size_t i, const Hierarchy& h) {
        const VertexId local_base = VertexId(base_keys[i].size()), local_own = local_base + plan.seam_count;
        own[i] = uint32_t(h.positions().size() - local_own);
        AMC_REQUIRE(plan.own_start() + uint64_t(own[i]) < kNoVertex, limit_exceeded, "too many vertices");
        bool direct = false;
        if (positions_first) {
            std::lock_guard<std::mutex> lock(placed_mutex);
            counted[i] = 1;
            place_counted();
            direct = placed > i;
        }
        const Vec3* own_of = h.positions().data() + local_own;
        if (direct)
            std::copy(own_of, own_of + own[i], positions.begin() + ptrdiff_t(first_own[i]));
        else
            own_positions[i].assign(own_of, own_of + own[i]);
        std::vector<VertexId> id(h.positions().size());
        for (VertexId v = 0; v < local_base; ++v) id[v] = plan.base_id[base_keys[i][v]];
        for (uint32_t s = 0; s < plan.seam_count; ++s) id[local_base + s] = plan.seam_start + s;
        const VertexId own_id = VertexId(direct ? first_own[i] : plan.own_start());
        for (uint32_t k = 0; k < own[i]; ++k) id[local_own + k] = own_id + k;
        named[i] = direct;
        parts[i].part = &h;
        parts[i].vertex_id = id.data();
        live[i] = h.node_capacity() - h.root_count();
        AMC_REQUIRE(parts[i].first_node + live[i] == slice_end[i], corrupt,
                    chunk_name(jobs[i]) + " does not hold the nodes the chunk table says");
        HierarchyBuilder::stitch_part(whole, parts[i]);
        parts[i].part = nullptr;
        parts[i].vertex_id = nullptr;
        if (!direct) {
            std::lock_guard<std::mutex> lock(placed_mutex);
            aside[i] = 1;
            if (placed > i) {  // placed meanwhile, before its positions were aside
                std::copy(own_positions[i].begin(), own_positions[i].end(), positions.begin() + ptrdiff_t(first_own[i]));
                std::vector<Vec3>().swap(own_positions[i]);
            }
        }
    };
    parallel_for(n, threads, [&](size_t i) {
        ++started;
        const ChunkJob& job = jobs[i];
        {
            std::lock_guard<std::mutex> lock(idle_mutex);
            if (!idle.empty()) {
                decoder_of[i] = std::move(idle.back());
                idle.pop_back();
            }
        }
        if (decoder_of[i] == nullptr) {
            decoder_of[i] = std::make_unique<HierarchyLevelDecoder>();
            if (whole_first) decoder_of[i]->hierarchy().reserve(size_t(largest_chunk), 0);
        }
        Hierarchy& h = decoder_of[i]->hierarchy();
        h.reset(base_of_roots(*input.base, {job.roots}, base_keys[i]));
        HierarchyBuilder::append_vertices(h, input.seam->positions());
        const ChunkPlace place{&h, 0, job.roots.count,
                               {&base_keys[i], VertexId(base_keys[i].size()), plan.seam_count, plan.file_base_vertices},
                               seam_used[i].data()};
        decode_chunk(*decoder_of[i], job.data, job.size, place, *input.seam, input.space, limits_of(job, input),
                     chunk_name(job), counts[i]);
        AMC_REQUIRE(input.options.max_level >= 0 || h.node_count() == job.nodes, corrupt,
                    chunk_name(job) + " does not hold the nodes the chunk table says");
        if (!whole_first) return;
        if (started.load() < n) {  // a chunk still to begin takes this decoder, memory and all
            copy_into_whole(i, h);
            std::lock_guard<std::mutex> lock(idle_mutex);
            idle.push_back(std::move(decoder_of[i]));
            return;
        }
        // None will: its working memory goes before the copy, which is where the decode peaks.
        const Hierarchy last = std::move(h);
        decoder_of[i].reset();
        give_back_free_memory();
        copy_into_whole(i, last);
    });
    if (!whole_first) {  // slices as long as the chunks are
        whole_nodes = plan.base.triangles.size();
        for (size_t i = 0; i < n; ++i) {
            const Hierarchy& h = decoder_of[i]->hierarchy();
            parts[i].first_node = NodeId(whole_nodes);
            whole_nodes += h.node_capacity() - h.root_count();
            AMC_REQUIRE(whole_nodes < kNoNode, limit_exceeded, "too many nodes");
            slice_end[i] = NodeId(whole_nodes);
        }
        whole = HierarchyBuilder::stitch_frame(plan.base, size_t(whole_nodes));
        parallel_for(n, threads, [&](size_t i) {
            copy_into_whole(i, decoder_of[i]->hierarchy());
            decoder_of[i].reset();
        });
    }
    idle.clear();
    if (!positions_first) {
        uint64_t vertices = positions.size();
        for (size_t i = 0; i < n; ++i) vertices += own[i];
        AMC_REQUIRE(vertices < kNoVertex, limit_exceeded, "too many vertices");
        positions.resize(size_t(vertices));
        std::fill(counted.begin(), counted.end(), uint8_t(1));
        place_counted();
    }
    AMC_REQUIRE(placed == n && next_own == positions.size(), corrupt, "the chunks hold fewer vertices than the metadata says");
    parallel_for(n, threads, [&](size_t i) {
        if (named[i]) return;
        const VertexId own_start = plan.own_start();
        HierarchyBuilder::stitch_rename_vertices(whole, parts[i].first_node, parts[i].first_node + live[i], [&](VertexId v) {
            return v < own_start ? v : VertexId(first_own[i] + (v - own_start));
        });
    });
    HierarchyBuilder::stitch_positions(whole, std::move(positions));
    std::vector<uint8_t> used(plan.seam_count, 0);
    for (const std::vector<uint8_t>& chunk_used : seam_used)
        for (uint32_t s = 0; s < plan.seam_count; ++s) used[s] |= chunk_used[s];
    finish_vertices(whole, plan, used, input);
    find_seam_edges(plan, whole, n);
    HierarchyBuilder::stitch_seams(whole, plan.seam_edges);
    return whole;
}

}  // namespace

Hierarchy decode_and_merge_chunks(const std::vector<ChunkJob>& jobs, const ChunkMergeInput& input, MergedCounts& counts) {
    MergePlan plan = plan_merge(jobs, input);
    std::vector<ChunkCounts> chunk_counts(jobs.size());
    const unsigned threads = std::min<unsigned>(resolve_thread_count(input.options.threads), unsigned(jobs.size()));
    Hierarchy whole = threads <= 1 ? merge_in_order(jobs, input, plan, chunk_counts)
                                   : merge_copies(jobs, input, plan, chunk_counts, threads);
    counts = MergedCounts();
    for (const ChunkCounts& c : chunk_counts) {
        counts.faces += c.faces;
        counts.depth = std::max(counts.depth, c.depth);
    }
    return whole;
}

}  // namespace amc
