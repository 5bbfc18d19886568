// The chunks of a chunked file decoded into the whole (chunk_merge.h).
#include "coding/chunks/chunk_merge.h"

#include "coding/file_metadata.h"
#include "common/check.h"
#include "common/huge_pages.h"
#include "common/parallel.h"
#include "hierarchy/hierarchy_builder.h"

#include <algorithm>
#include <cstddef>
#include <exception>
#include <memory>
#include <mutex>
#include <string>
#include <system_error>
#include <utility>

namespace amc {

namespace {

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
    // Each chunk's nodes and own vertices known and trusted, every level decoded (a progressive
    // decode would leave slices part empty): chunks may decode into their slices at once.
    bool slices = false;
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
                   plan.nodes <= reservable_nodes(plan.base.triangles.size(), input.file_size);
    plan.full = input.whole_file && input.options.max_level < 0;
    plan.seam_start = VertexId(plan.base.positions.size());
    plan.seam_count = input.seam->vertex_count();
    AMC_REQUIRE(uint64_t(plan.seam_start) + plan.seam_count < kNoVertex, limit_exceeded, "too many vertices");
    AMC_REQUIRE(!plan.full || (input.vertices >= plan.own_start() && input.vertices < kNoVertex), corrupt,
                "the metadata's vertex count does not fit the base and the seam");
    // The table's own vertex counts (version 13 on): with the base and the seam, the file's.
    uint64_t own_vertices = 0;
    bool counts_known = true;
    for (const ChunkJob& job : jobs) {
        counts_known &= job.own_vertices != kUnknownVertices;
        own_vertices += counts_known ? job.own_vertices : 0;  // each at most 3/4 of its nodes (read_chunk_table)
    }
    AMC_REQUIRE(!plan.full || !counts_known || plan.own_start() + own_vertices == input.vertices, corrupt,
                "the chunk table's vertex counts do not add up to the metadata's vertex count");
    plan.slices = counts_known && plan.trusted;
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

// Checks the job's block, then decodes it into `place`.
void decode_job(HierarchyLevelDecoder& decoder, const ChunkJob& job, const ChunkPlace& place, const ChunkMergeInput& input,
                ChunkCounts& counts) {
    input.reader->check_checksum(job.block);
    decode_chunk(decoder, job.block.payload, job.block.size, place, *input.seam, input.space, limits_of(job, input),
                 chunk_name(job), counts);
}

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

// One thread (or a chunk table without vertex counts, or a progressive decode): each chunk decoded
// straight into the whole, in chunk order, its nodes and own vertices appended where the whole
// keeps them.
Hierarchy merge_in_order(const std::vector<ChunkJob>& jobs, const ChunkMergeInput& input, MergePlan& plan,
                         std::vector<ChunkCounts>& counts) {
    Hierarchy whole(plan.base);
    if (input.spare != nullptr) HierarchyBuilder::adopt_storage(whole, std::move(*input.spare));
    if (plan.trusted) whole.reserve(size_t(plan.nodes), plan.full ? size_t(input.vertices) : 0);
    HierarchyBuilder::append_vertices(whole, input.seam->positions());
    find_seam_edges(plan, whole, jobs.size());
    const std::vector<HierarchyBuilder::RootLink> cut = HierarchyBuilder::cut_root_links(whole, plan.seam_edges);
    std::vector<uint8_t> seam_used(plan.seam_count, 0);
    ChunkDecoders own;
    ChunkDecoders& decoders = input.kept_decoders != nullptr ? *input.kept_decoders : own;
    std::unique_ptr<HierarchyLevelDecoder> decoder = decoders.take();
    for (size_t i = 0; i < jobs.size(); ++i) {
        const ChunkJob& job = jobs[i];
        const size_t vertices_before = whole.positions().size();
        const ChunkPlace place{&whole, plan.first_root[i], job.roots.count, plan.keys_in_whole(), seam_used.data(), nullptr,
                               input.kept_decoders == nullptr && i + 1 == jobs.size()};
        decode_job(*decoder, job, place, input, counts[i]);
        AMC_REQUIRE(input.options.max_level >= 0 || decoder->node_count() == job.nodes, corrupt,
                    chunk_name(job) + " does not hold the nodes the chunk table says");
        AMC_REQUIRE(input.options.max_level >= 0 || job.own_vertices == kUnknownVertices ||
                        whole.positions().size() - vertices_before == job.own_vertices,
                    corrupt, chunk_name(job) + " does not hold the vertices the chunk table says");
        AMC_REQUIRE(!plan.full || whole.positions().size() <= input.vertices, corrupt,
                    "the chunks hold more vertices than the metadata says");
    }
    decoders.give_back(std::move(decoder));
    HierarchyBuilder::relink_roots(whole, cut);
    finish_vertices(whole, plan, seam_used, input);
    HierarchyBuilder::stitch_seams(whole, plan.seam_edges);
    return whole;
}

// Several threads: every chunk straight into its slice of the whole, made first from the chunk
// table's counts, so that the whole comes out as merge_in_order makes it. Each thread reuses one
// decoder's working memory for the chunks it takes (the caller's, when it keeps them).
Hierarchy merge_in_slices(const std::vector<ChunkJob>& jobs, const ChunkMergeInput& input, MergePlan& plan,
                          std::vector<ChunkCounts>& counts, unsigned threads) {
    const size_t n = jobs.size();
    std::vector<Vec3> zeroed_positions;
    if (input.zeroed_positions != nullptr && input.zeroed_positions->valid()) zeroed_positions = input.zeroed_positions->get();
    Hierarchy whole(plan.base);
    if (input.spare != nullptr) HierarchyBuilder::adopt_storage(whole, std::move(*input.spare));
    HierarchyBuilder::append_vertices(whole, input.seam->positions());
    std::vector<HierarchySlice> slices(n);
    uint64_t node = plan.base.triangles.size(), vertex = plan.own_start();
    for (size_t i = 0; i < n; ++i) {
        slices[i].next_node = NodeId(node);
        slices[i].next_vertex = VertexId(std::min<uint64_t>(vertex, kNoVertex));
        node += jobs[i].nodes - jobs[i].roots.count;
        vertex += jobs[i].own_vertices;  // each at most 3/4 of its nodes (read_chunk_table)
        slices[i].node_end = NodeId(std::min<uint64_t>(node, kNoNode));
        slices[i].vertex_end = VertexId(std::min<uint64_t>(vertex, kNoVertex));
        slices[i].owner = chunk_name(jobs[i]);
    }
    AMC_REQUIRE(vertex < kNoVertex, limit_exceeded, "too many vertices");
    HierarchyBuilder::open_slices(whole, size_t(node), size_t(vertex), std::move(zeroed_positions));
    find_seam_edges(plan, whole, n);
    const std::vector<HierarchyBuilder::RootLink> cut = HierarchyBuilder::cut_root_links(whole, plan.seam_edges);
    // The seam vertices the chunks split off, in an array a thread (one a chunk grew as the file's square).
    std::vector<std::vector<uint8_t>> idle_used;
    std::mutex used_mutex;
    ChunkDecoders own;
    ChunkDecoders& decoders = input.kept_decoders != nullptr ? *input.kept_decoders : own;
    auto decode_into_slice = [&](size_t i) {
        std::unique_ptr<HierarchyLevelDecoder> decoder = decoders.take();
        std::vector<uint8_t> seam_used;
        {
            std::lock_guard<std::mutex> lock(used_mutex);
            if (!idle_used.empty()) {
                seam_used = std::move(idle_used.back());
                idle_used.pop_back();
            }
        }
        if (seam_used.empty()) seam_used.assign(plan.seam_count, 0);
        const ChunkJob& job = jobs[i];
        // Never lean (ChunkPlace::last): pages given back and faulted in again by two threads at
        // once cost more than they save.
        const ChunkPlace place{&whole, plan.first_root[i], job.roots.count, plan.keys_in_whole(), seam_used.data(),
                               &slices[i], false};
        decode_job(*decoder, job, place, input, counts[i]);
        AMC_REQUIRE(slices[i].next_node == slices[i].node_end, corrupt,
                    chunk_name(job) + " does not hold the nodes the chunk table says");
        AMC_REQUIRE(slices[i].next_vertex == slices[i].vertex_end, corrupt,
                    chunk_name(job) + " does not hold the vertices the chunk table says");
        decoders.give_back(std::move(decoder));
        std::lock_guard<std::mutex> lock(used_mutex);
        idle_used.push_back(std::move(seam_used));
    };
    // A corrupt file fails with its first bad chunk's error, as on one thread in chunk order.
    std::vector<std::exception_ptr> error(n);
    parallel_for(n, threads, [&](size_t i) {
        try {
            decode_into_slice(i);
        } catch (...) {
            error[i] = std::current_exception();
        }
    });
    for (const std::exception_ptr& e : error)
        if (e) std::rethrow_exception(e);
    HierarchyBuilder::relink_roots(whole, cut);
    std::vector<uint8_t> used(plan.seam_count, 0);
    for (const std::vector<uint8_t>& thread_used : idle_used)
        for (uint32_t s = 0; s < plan.seam_count; ++s) used[s] |= thread_used[s];
    finish_vertices(whole, plan, used, input);
    HierarchyBuilder::stitch_seams(whole, plan.seam_edges);
    return whole;
}

}  // namespace

std::unique_ptr<HierarchyLevelDecoder> ChunkDecoders::take() {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        if (!idle_.empty()) {
            std::unique_ptr<HierarchyLevelDecoder> decoder = std::move(idle_.back());
            idle_.pop_back();
            return decoder;
        }
    }
    return std::make_unique<HierarchyLevelDecoder>();
}

void ChunkDecoders::give_back(std::unique_ptr<HierarchyLevelDecoder> decoder) {
    std::lock_guard<std::mutex> lock(mutex_);
    idle_.push_back(std::move(decoder));
}

void ChunkDecoders::clear() {
    std::lock_guard<std::mutex> lock(mutex_);
    idle_.clear();
}

std::future<std::vector<Vec3>> start_zeroed_positions(size_t vertices) {
    try {
        return std::async(std::launch::async, [vertices] {
            std::vector<Vec3> positions;
            reserve_huge(positions, vertices);
            positions.resize(vertices);
            return positions;
        });
    } catch (const std::system_error&) {  // no thread to be had: open_slices zeroes them
        return {};
    }
}

Hierarchy decode_and_merge_chunks(const std::vector<ChunkJob>& jobs, const ChunkMergeInput& input, MergedCounts& counts) {
    MergePlan plan = plan_merge(jobs, input);
    std::vector<ChunkCounts> chunk_counts(jobs.size());
    const unsigned threads = std::min<unsigned>(resolve_thread_count(input.options.threads), unsigned(jobs.size()));
    Hierarchy whole = threads > 1 && plan.slices ? merge_in_slices(jobs, input, plan, chunk_counts, threads)
                                                 : merge_in_order(jobs, input, plan, chunk_counts);
    counts = MergedCounts();
    for (const ChunkCounts& c : chunk_counts) {
        counts.faces += c.faces;
        counts.depth = std::max(counts.depth, c.depth);
    }
    return whole;
}

}  // namespace amc
