// Chunked .amc files (docs/FORMAT.md 3.11-3.14): chunked files decode to exactly what unchunked
// ones do, any subset of chunks decodes to exactly its roots' trees, and the thread count changes
// neither bytes nor results.
#include "coding/chunks/chunk_layout.h"
#include "coding/container.h"
#include "coding/format_version.h"
#include "hierarchy/hierarchy_builder.h"
#include "hierarchy_checks.h"

#include <amc/codec.h>
#include <amc/refinement.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <thread>

namespace amc {
namespace {

using testing::Random;

// A random adaptive hierarchy over one of the fixture meshes (boundaries, handles, several
// components), some diagonals flipped, positions moved off the midpoints on every other seed.
Hierarchy random_hierarchy(uint64_t seed, bool single) {
    Random random{seed};
    const auto meshes = testing::fixture_meshes();
    TriangleMesh base = meshes[random.next() % meshes.size()].mesh;
    base.single_precision = single;
    if (single)
        for (Vec3& p : base.positions) p = Vec3{double(float(p.x)), double(float(p.y)), double(float(p.z))};
    Hierarchy h(base);
    refine_randomly(h, h.root_count() + 50 + uint32_t(random.next() % 600), 1 + int(random.next() % 5), seed);
    for (NodeId n : h.leaves())
        if (h.hanging_node_count(n) == 2 && random.next() % 3 == 0) h.set_diagonal_flipped(n, true);
    if (seed % 2 == 0) {
        for (VertexId v = 0; v < h.positions().size(); ++v) {
            const Vec3 p = h.position(v);
            const double wobble = 1.0 + double(random.next() % 1000) / 1e4;
            const Vec3 q{p.x * wobble, p.y - 0.01 * wobble, p.z + wobble * 0.001};
            h.set_position(v, single ? Vec3{double(float(q.x)), double(float(q.y)), double(float(q.z))} : q);
        }
    }
    return h;
}

EncodeOptions with_chunks(uint32_t chunks, unsigned threads = 0, int bits = 0) {
    EncodeOptions options;
    options.chunks = chunks;
    options.threads = threads;
    options.quantize_bits = bits;
    options.grid_contexts = false;  // geometry mode 3 inside chunks: files of one chunk stay below version 7
    return options;
}

// The encoder's split (and MPI's of a file's chunks among ranks): runs of consecutive roots, chunk k
// closing at the first root where the nodes so far reach (k + 1) / chunks of all, at least one root
// for each chunk still to come. Nodes are the weight: docs/BENCHMARKS.md, "Threads and memory", "What
// a chunk's work follows" measured chunk work against roots, nodes, vertices, leaf faces and symbols.
TEST(Chunks, BalancedChunksCloseEachChunkAtItsShareOfTheNodes) {
    auto ranges = [](const std::vector<uint64_t>& nodes, uint32_t chunks) {
        std::vector<std::pair<uint32_t, uint32_t>> out;
        for (const RootRange& r : balanced_chunks(nodes, chunks)) out.emplace_back(r.first, r.count);
        return out;
    };
    using Ranges = std::vector<std::pair<uint32_t, uint32_t>>;
    // One heavy root: the first chunk closes right after it, at 22 of 30 nodes.
    EXPECT_EQ(ranges({1, 21, 1, 1, 5, 1}, 2), (Ranges{{0, 2}, {2, 4}}));
    EXPECT_EQ(ranges({1, 21, 1, 1, 5, 1}, 3), (Ranges{{0, 2}, {2, 1}, {3, 3}}));
    // A share reached exactly closes the chunk.
    EXPECT_EQ(ranges({2, 2, 2, 2}, 2), (Ranges{{0, 2}, {2, 2}}));
    // A heavy last root still gets a chunk of its own.
    EXPECT_EQ(ranges({1, 1, 1, 1, 100}, 2), (Ranges{{0, 4}, {4, 1}}));
    // No more chunks than roots, and at least one.
    EXPECT_EQ(ranges({5, 5}, 4), (Ranges{{0, 1}, {1, 1}}));
    EXPECT_EQ(ranges({7}, 0), (Ranges{{0, 1}}));

    // A forest with known uneven roots: root 0 refined uniformly four levels deep, root 11 two,
    // the others by balance and closure only. nodes_per_root counts each root's tree as a walk does.
    Hierarchy h(make_icosahedron());
    auto leaves_of = [&h](NodeId root) {
        std::vector<NodeId> leaves, stack{root};
        while (!stack.empty()) {
            const NodeId n = stack.back();
            stack.pop_back();
            if (h.is_leaf(n)) {
                leaves.push_back(n);
                continue;
            }
            for (int k = 0; k < 4; ++k) stack.push_back(h.child(n, k));
        }
        return leaves;
    };
    auto refine_below = [&](NodeId root, int depth) {
        for (int level = 0; level < depth; ++level)
            for (NodeId leaf : leaves_of(root))
                if (h.level(leaf) == level) h.refine(leaf);
    };
    refine_below(0, 4);
    refine_below(11, 2);
    std::vector<uint64_t> walked(h.root_count(), 0);
    for (NodeId r = 0; r < h.root_count(); ++r) {
        std::vector<NodeId> stack{r};
        while (!stack.empty()) {
            const NodeId n = stack.back();
            stack.pop_back();
            ++walked[r];
            if (h.is_leaf(n)) continue;
            for (int k = 0; k < 4; ++k) stack.push_back(h.child(n, k));
        }
    }
    const std::vector<uint64_t> per_root = nodes_per_root(h, root_of_nodes(h));
    ASSERT_EQ(per_root, walked);
    uint64_t total = 0;
    for (uint64_t n : per_root) total += n;
    ASSERT_EQ(total, h.node_count());
    ASSERT_GT(per_root[0], total / 2);  // uneven indeed: root 0 holds more than half of the forest
    for (uint32_t chunks : {2u, 3u, 5u}) {
        SCOPED_TRACE("chunks " + std::to_string(chunks));
        const std::vector<RootRange> split = balanced_chunks(per_root, chunks);
        ASSERT_EQ(split.size(), chunks);
        // Consecutive runs covering every root, none empty, and none holding more than its share
        // of the nodes plus one root's tree (the greedy split's bound on its imbalance).
        uint32_t next_root = 0;
        for (uint32_t k = 0; k < chunks; ++k) {
            ASSERT_EQ(split[k].first, next_root);
            ASSERT_GE(split[k].count, 1u);
            uint64_t nodes = 0, largest_root = 0;
            for (uint32_t r = split[k].first; r < split[k].first + split[k].count; ++r) {
                nodes += per_root[r];
                largest_root = std::max(largest_root, per_root[r]);
            }
            EXPECT_LE(nodes, (total + chunks - 1) / chunks + largest_root) << "chunk " << k;
            next_root = split[k].first + split[k].count;
        }
        EXPECT_EQ(next_root, h.root_count());
        // Root 0's tree alone reaches the first share of any of these counts: chunk 0 is that root.
        EXPECT_EQ(split[0].count, 1u);
    }
}

TEST(Chunks, ChunkedFilesDecodeToWhatUnchunkedFilesDo) {
    int chunked_files = 0;
    for (uint64_t seed = 0; seed < 60; ++seed) {
        SCOPED_TRACE("seed " + std::to_string(seed));
        const Hierarchy h = random_hierarchy(seed, seed % 3 == 0);
        const int bits = seed % 5 == 1 ? 12 : 0;
        const std::vector<uint8_t> one = encode(h, with_chunks(1, 0, bits));
        ASSERT_TRUE(inspect(one.data(), one.size()).chunks.empty());
        const Hierarchy expected = decode(one.data(), one.size());
        for (uint32_t chunks : {2u, 3u, 7u, 1000u}) {
            EncodeOptions options = with_chunks(chunks, 0, bits);
            options.predictor = GeometryPredictor(seed % 4);
            const std::vector<uint8_t> bytes = encode(h, options);
            const FileInfo info = inspect(bytes.data(), bytes.size());
            if (h.root_count() >= 2) {
                ASSERT_GE(info.version, kChunkVerticesVersion);  // 14 with raw side streams
                ASSERT_EQ(info.chunks.size(), std::min<size_t>(chunks, h.root_count()));
                ++chunked_files;
            }
            const Hierarchy back = decode(bytes.data(), bytes.size());
            ASSERT_TRUE(testing::hierarchy_is_valid(back));
            ASSERT_TRUE(identical(back, expected)) << chunks << " chunks";
            if (bits == 0) {
                ASSERT_TRUE(identical(back, in_decoder_order(h, options)));
            }
        }
    }
    EXPECT_GT(chunked_files, 150);
}

// The same hierarchy with the same ids: every node's vertices, links, children, level and flags,
// and every vertex's position, bit for bit (identical() compares in canonical order only).
bool same_ids(const Hierarchy& a, const Hierarchy& b) {
    if (a.node_capacity() != b.node_capacity() || a.node_count() != b.node_count() || a.positions().size() != b.positions().size())
        return false;
    for (NodeId n = 0; n < a.node_capacity(); ++n) {
        if (a.is_alive(n) != b.is_alive(n)) return false;
        if (!a.is_alive(n)) continue;
        if (a.level(n) != b.level(n) || a.is_leaf(n) != b.is_leaf(n) || a.parent(n) != b.parent(n) ||
            a.diagonal_flipped(n) != b.diagonal_flipped(n) || (!a.is_leaf(n) && a.child(n, 0) != b.child(n, 0)))
            return false;
        for (int e = 0; e < 3; ++e) {
            if (a.vertex(n, e) != b.vertex(n, e) || a.neighbor(n, e) != b.neighbor(n, e) ||
                a.is_boundary_edge(n, e) != b.is_boundary_edge(n, e) ||
                (a.neighbor(n, e) != kNoNode && a.neighbor_edge(n, e) != b.neighbor_edge(n, e)))
                return false;
        }
    }
    return std::memcmp(a.positions().data(), b.positions().data(), a.positions().size() * sizeof(Vec3)) == 0;
}

// The chunk hierarchy as split() replays it: the trees of `roots`, breadth first.
Hierarchy replayed_roots(const Hierarchy& h, const std::vector<RootRange>& roots, std::vector<VertexId>& vertex_of) {
    Hierarchy out(base_of_roots(h.base(), roots, vertex_of));
    std::vector<std::pair<NodeId, NodeId>> level, next;  // (node of out, node of h)
    for (const RootRange& range : roots)
        for (uint32_t r = range.first; r < range.first + range.count; ++r) level.emplace_back(NodeId(level.size()), r);
    while (!level.empty()) {
        next.clear();
        for (const auto& p : level) {
            if (h.is_leaf(p.second)) {
                out.set_diagonal_flipped(p.first, h.diagonal_flipped(p.second));
                continue;
            }
            out.split(p.first);
            vertex_of.resize(out.positions().size(), kNoVertex);
            for (int e = 0; e < 3; ++e) {
                out.set_position(out.midpoint(p.first, e), h.position(h.midpoint(p.second, e)));
                vertex_of[out.midpoint(p.first, e)] = h.midpoint(p.second, e);
            }
            for (int k = 0; k < 4; ++k) next.emplace_back(out.child(p.first, k), h.child(p.second, k));
        }
        std::swap(level, next);
    }
    return out;
}

// extract_roots builds the chunk directly; the ids must be the replay's, which the chunk coder and
// the seam rely on. Also over forests whose ids were reused by coarsening (children before parents).
TEST(Chunks, ExtractedRootsHaveTheIdsOfASplitReplay) {
    for (uint64_t seed = 0; seed < 24; ++seed) {
        SCOPED_TRACE("seed " + std::to_string(seed));
        Hierarchy h = random_hierarchy(seed, false);
        if (seed % 3 == 2) refine_randomly(h, h.leaf_count() + 300, 6, seed, 0.3);
        const uint32_t roots = h.root_count();
        const uint32_t cut = 1 + uint32_t(seed % (roots - 1));
        const std::vector<std::vector<RootRange>> parts = {
            {RootRange{0, roots}}, {RootRange{0, cut}}, {RootRange{cut, roots - cut}},
            {RootRange{0, cut / 2 + 1}, RootRange{cut + 1 < roots ? cut + 1 : cut, 1}}};
        for (const auto& part : parts) {
            std::vector<VertexId> expected_vertex_of, vertex_of;
            const Hierarchy expected = replayed_roots(h, part, expected_vertex_of);
            const Hierarchy chunk = extract_roots(h, part, &vertex_of);
            EXPECT_TRUE(same_ids(chunk, expected));
            EXPECT_EQ(chunk.base().triangles, expected.base().triangles);
            EXPECT_EQ(vertex_of, expected_vertex_of);
            EXPECT_TRUE(testing::hierarchy_is_valid(chunk));
        }
    }
}

// The chunked encoder copies each chunk into a room made beforehand (in the calling thread's
// arena for the workers, made resident by the thread that fills it): a room too small or large
// enough must give the same chunk.
TEST(Chunks, ExtractionIntoARoomIsTheSameChunk) {
    for (uint64_t seed = 0; seed < 12; ++seed) {
        SCOPED_TRACE("seed " + std::to_string(seed));
        Hierarchy h = random_hierarchy(seed, false);
        if (seed % 3 == 2) refine_randomly(h, h.leaf_count() + 300, 6, seed, 0.3);
        const uint32_t roots = h.root_count();
        const uint32_t cut = 1 + uint32_t(seed % (roots - 1));
        const std::vector<uint32_t> root_of = root_of_nodes(h);
        std::vector<NodeId> local(h.node_capacity());
        for (const std::vector<RootRange>& part : {std::vector<RootRange>{RootRange{0, cut}}, {RootRange{cut, roots - cut}}}) {
            std::vector<VertexId> expected_vertex_of;
            const Hierarchy expected = extract_roots(h, part, &expected_vertex_of);
            for (const size_t room_nodes : {size_t(1), size_t(expected.node_count()), size_t(h.node_count())}) {
                SCOPED_TRACE("room for " + std::to_string(room_nodes) + " nodes");
                SubforestRoom room = HierarchyBuilder::subforest_room(h, room_nodes, room_nodes / 2);
                if (room_nodes > 1) std::thread([&room] { HierarchyBuilder::make_resident(room); }).join();  // as a chunk task does
                std::vector<VertexId> vertex_of;
                const Hierarchy chunk = extract_roots(h, part, root_of, local.data(), &vertex_of, &room);
                EXPECT_TRUE(identical(chunk, expected));
                EXPECT_TRUE(same_ids(chunk, expected));
                EXPECT_EQ(vertex_of, expected_vertex_of);
            }
        }
    }
}

TEST(Chunks, ThreadCountChangesNeitherBytesNorResults) {
    for (uint64_t seed = 100; seed < 110; ++seed) {
        const Hierarchy h = random_hierarchy(seed, false);
        const std::vector<uint8_t> bytes = encode(h, with_chunks(5, 1));
        for (unsigned threads : {2u, 3u, 8u}) EXPECT_EQ(encode(h, with_chunks(5, threads)), bytes) << threads << " threads";
        const Hierarchy one = decode(bytes.data(), bytes.size(), DecodeOptions{-1, 1ull << 26, 1});
        for (unsigned threads : {2u, 5u}) {
            const Hierarchy back = decode(bytes.data(), bytes.size(), DecodeOptions{-1, 1ull << 26, threads});
            EXPECT_TRUE(same_ids(back, one)) << threads << " threads";
            const size_t count = inspect(bytes.data(), bytes.size()).chunks.size();
            const std::vector<uint32_t> some = count <= 1 ? std::vector<uint32_t>{0} : std::vector<uint32_t>{1, uint32_t(count - 1)};
            EXPECT_TRUE(same_ids(decode_chunks(bytes.data(), bytes.size(), some, DecodeOptions{-1, 1ull << 26, threads}).hierarchy,
                                 decode_chunks(bytes.data(), bytes.size(), some, DecodeOptions{-1, 1ull << 26, 1}).hierarchy))
                << threads << " threads, some chunks";
            // One thread decodes each chunk straight into the whole, several copy them in: a
            // progressive decode leaves seam vertices unused, which both drop alike.
            for (int level : {1, 2})
                EXPECT_TRUE(same_ids(decode(bytes.data(), bytes.size(), DecodeOptions{level, 1ull << 26, threads}),
                                     decode(bytes.data(), bytes.size(), DecodeOptions{level, 1ull << 26, 1})))
                    << threads << " threads, up to level " << level;
        }
    }
}

TEST(Chunks, ChunkSubsetsDecodeToExactlyTheirRootsTrees) {
    for (uint64_t seed = 200; seed < 230; ++seed) {
        SCOPED_TRACE("seed " + std::to_string(seed));
        const Hierarchy h = random_hierarchy(seed, seed % 2 == 0);
        const std::vector<uint8_t> bytes = encode(h, with_chunks(4));
        const FileInfo info = inspect(bytes.data(), bytes.size());
        const Hierarchy whole = decode(bytes.data(), bytes.size());
        const uint32_t count = uint32_t(std::max<size_t>(1, info.chunks.size()));
        for (uint32_t mask = 1; mask < (1u << count); ++mask) {
            std::vector<uint32_t> chunks;
            std::vector<RootRange> ranges;
            for (uint32_t c = 0; c < count; ++c) {
                if (!(mask >> c & 1)) continue;
                chunks.push_back(c);
                ranges.push_back(info.chunks.empty() ? RootRange{0, whole.root_count()}
                                                     : RootRange{info.chunks[c].first_root, info.chunks[c].roots});
            }
            const ChunkDecode part = decode_chunks(bytes.data(), bytes.size(), chunks);
            ASSERT_TRUE(testing::hierarchy_is_valid(part.hierarchy));
            std::vector<VertexId> base_vertices;
            base_of_roots(whole.base(), ranges, base_vertices);
            EXPECT_EQ(part.base_vertices, base_vertices);
            std::vector<uint32_t> roots;
            for (const RootRange& r : ranges)
                for (uint32_t t = r.first; t < r.first + r.count; ++t) roots.push_back(t);
            EXPECT_EQ(part.roots, roots);
            EXPECT_TRUE(identical(part.hierarchy, extract_roots(whole, ranges))) << "chunk mask " << mask;
            // The selected trees, node for node (levels and leaves), and their positions.
            EXPECT_EQ(chunks_covering(info, roots), chunks);
        }
    }
}

TEST(Chunks, DefaultsKeepSmallFilesUnchangedAndChunkLargeOnes) {
    const Hierarchy h = random_hierarchy(7, false);
    EncodeOptions unchunked;
    unchunked.chunks = 1;
    EXPECT_EQ(encode(h, EncodeOptions{}), encode(h, unchunked)) << "fewer faces than chunk_faces: one chunk";
    EncodeOptions small_chunks;
    small_chunks.chunk_faces = 100;
    small_chunks.min_chunk_bytes = 0;  // keeps chunks this small (chunk_policy_test.cpp tests the fallback)
    EncodeStats stats;
    const std::vector<uint8_t> bytes = encode(h, small_chunks, &stats);
    const FileInfo info = inspect(bytes.data(), bytes.size());
    EXPECT_EQ(info.chunks.size(), std::min<uint64_t>(stats.faces / 100, h.root_count()));
    EXPECT_TRUE(identical(decode(bytes.data(), bytes.size()), in_decoder_order(h)));
    // The chunk blocks are where the table says, and cover every root once.
    uint32_t next_root = 0;
    for (const ChunkInfo& c : info.chunks) {
        EXPECT_EQ(c.first_root, next_root);
        next_root += c.roots;
        ASSERT_GT(c.size, kBlockOverhead);
        EXPECT_EQ(bytes[c.offset], uint8_t(BlockType::chunk));
    }
    EXPECT_EQ(next_root, info.base_triangles);
}

TEST(Chunks, ProgressiveAndPartialDecodingOfChunkedFiles) {
    const Hierarchy h = random_hierarchy(12, false);
    const std::vector<uint8_t> chunked = encode(h, with_chunks(3));
    const std::vector<uint8_t> plain = encode(h, with_chunks(1));
    for (int level = 0; level <= h.depth(); ++level) {
        DecodeOptions options;
        options.max_level = level;
        EXPECT_TRUE(identical(decode(chunked.data(), chunked.size(), options), decode(plain.data(), plain.size(), options)))
            << "level " << level;
    }
    // A file cut anywhere after its base mesh gives the base until every chunk has arrived.
    const FileInfo info = inspect(chunked.data(), chunked.size());
    const size_t base_end = info.blocks[2].offset + info.blocks[2].size;
    for (size_t size = base_end; size < chunked.size(); size += 1 + (chunked.size() - base_end) / 40) {
        const PartialDecode part = decode_partial(chunked.data(), size);
        EXPECT_FALSE(part.complete);
        EXPECT_EQ(part.level, 0);
        EXPECT_EQ(part.hierarchy.node_count(), h.root_count());
    }
    const PartialDecode whole = decode_partial(chunked.data(), chunked.size());
    EXPECT_TRUE(whole.complete);
    EXPECT_TRUE(identical(whole.hierarchy, decode(chunked.data(), chunked.size())));
}

TEST(Chunks, EveryTruncationAndCorruptionIsAnError) {
    const Hierarchy h = random_hierarchy(14, false);
    const std::vector<uint8_t> bytes = encode(h, with_chunks(4));
    const Hierarchy expected = decode(bytes.data(), bytes.size());
    for (size_t size = 0; size < bytes.size(); ++size) {
        const DecodeResult r = try_decode(bytes.data(), size);
        EXPECT_FALSE(r.ok) << "cut at " << size;
    }
    // A payload byte changed, the checksum made valid again: an error, or a valid hierarchy (the
    // sizes stay, so the chunk table's offsets stay right and the chunk parsers see the change).
    BlockReader reader(bytes.data(), bytes.size());
    std::vector<std::pair<BlockType, std::vector<uint8_t>>> blocks;
    Block block;
    while (reader.next(block))
        if (block.type != BlockType::end) blocks.push_back({block.type, {block.payload, block.payload + block.size}});
    Random random{5};
    int decoded = 0;
    for (int trial = 0; trial < 3000; ++trial) {
        auto mutated = blocks;
        auto& payload = mutated[3 + random.next() % (mutated.size() - 3)].second;  // table, seam, chunks
        if (payload.empty()) continue;
        payload[random.next() % payload.size()] ^= uint8_t(1 + random.next() % 255);
        BlockWriter writer(reader.version(), reader.flags());
        for (const auto& [type, bytes_of] : mutated) writer.add(type, bytes_of);
        const std::vector<uint8_t> file = writer.finish();
        const DecodeResult r = try_decode(file.data(), file.size());
        if (r.ok) {
            ++decoded;
            EXPECT_TRUE(testing::hierarchy_is_valid(r.hierarchy));
        } else {
            EXPECT_NE(r.code, ErrorCode::checksum) << r.error;
        }
    }
    EXPECT_LT(decoded, 3000);
}

// Chunk blocks are checked by the threads that decode them: a changed byte of one, anywhere
// but its length, is still a checksum error naming the block, on one thread and on several.
TEST(Chunks, ChangedChunkBlocksAreChecksumErrorsOnEveryThreadCount) {
    const Hierarchy h = random_hierarchy(18, false);
    const std::vector<uint8_t> bytes = encode(h, with_chunks(4));
    BlockReader reader(bytes.data(), bytes.size());
    Block block;
    std::vector<Block> chunks;
    while (reader.next(block))
        if (block.type == BlockType::chunk) chunks.push_back(block);
    ASSERT_EQ(chunks.size(), 4u);
    for (const Block& chunk : chunks) {
        const size_t end = chunk.offset + kBlockOverhead + chunk.size;
        // The type, the first, a middle and the last payload byte, the checksum's last byte.
        for (size_t at : {chunk.offset, chunk.offset + 5, chunk.offset + 5 + chunk.size / 2, end - 5, end - 1}) {
            std::vector<uint8_t> changed = bytes;
            changed[at] ^= 0x24;
            for (unsigned threads : {1u, 2u, 3u}) {
                DecodeOptions options;
                options.threads = threads;
                const DecodeResult r = try_decode(changed.data(), changed.size(), options);
                EXPECT_EQ(r.code, ErrorCode::checksum) << "byte " << at << ", " << threads << " threads: " << r.error;
                if (at != chunk.offset) {
                    EXPECT_EQ(r.error, "checksum mismatch in the chunk block at byte " + std::to_string(chunk.offset));
                }
            }
        }
    }
}

// `bytes` (a chunked file of version 13) with its chunk table's own vertex counts changed: chunk
// k's by delta[k].
std::vector<uint8_t> with_vertex_counts(const std::vector<uint8_t>& bytes, const std::vector<int64_t>& delta) {
    BlockReader reader(bytes.data(), bytes.size());
    BlockWriter writer(reader.version(), reader.flags());
    Block block;
    while (reader.next(block) && block.type != BlockType::end) {
        std::vector<uint8_t> payload(block.payload, block.payload + block.size);
        if (block.type == BlockType::chunk_table) {
            PayloadReader in(block.payload, block.size, "chunk table block");
            payload.clear();
            const uint64_t count = in.varint();
            put_varint(payload, count);
            for (uint64_t c = 0; c < count; ++c) {
                put_varint(payload, in.varint());  // roots
                put_varint(payload, in.varint());  // nodes
                put_varint(payload, uint64_t(int64_t(in.varint()) + (c < delta.size() ? delta[c] : 0)));
                put_varint(payload, in.varint());  // offset, from the table's end
            }
        }
        writer.add(block.type, payload);
    }
    return writer.finish();
}

// The chunk table's vertex counts (version 13) are checked on every thread count, before the
// whole is made: a file decodes on several threads exactly when it decodes on one.
TEST(Chunks, CraftedVertexCountsAreClearErrors) {
    const Hierarchy h = random_hierarchy(16, false);
    const std::vector<uint8_t> bytes = encode(h, with_chunks(3));
    ASSERT_GE(inspect(bytes.data(), bytes.size()).version, kChunkVerticesVersion);  // 14 with raw side streams
    EXPECT_EQ(with_vertex_counts(bytes, {}), bytes);
    struct Crafted {
        std::vector<int64_t> delta;
        std::string error;
    };
    const Crafted cases[] = {
        {{1, -1, 0}, "chunk 0 does not hold the vertices the chunk table says"},  // the sum still right
        {{0, 2, -2}, "chunk 1 does not hold the vertices the chunk table says"},
        {{0, 0, 1}, "the chunk table's vertex counts do not add up to the metadata's vertex count"},
        {{-1, 0, 0}, "the chunk table's vertex counts do not add up to the metadata's vertex count"},
        {{0, 1 << 30, 0}, "chunk table block: chunk 1 has inconsistent counts"},  // more than 3 per split
    };
    for (const Crafted& c : cases) {
        const std::vector<uint8_t> file = with_vertex_counts(bytes, c.delta);
        for (unsigned threads : {1u, 2u, 3u}) {
            DecodeOptions options;
            options.threads = threads;
            const DecodeResult r = try_decode(file.data(), file.size(), options);
            EXPECT_FALSE(r.ok) << threads << " threads";
            EXPECT_EQ(r.code, ErrorCode::corrupt) << r.error;
            EXPECT_NE(r.error.find(c.error), std::string::npos) << threads << " threads: " << r.error;
        }
    }
}

// `bytes` with the payload byte in the middle of its last chunk block changed and the checksums
// made right again: a chunk whose decoder stops in the middle of a level, or decodes garbage.
std::vector<uint8_t> with_last_chunk_changed(const std::vector<uint8_t>& bytes) {
    BlockReader reader(bytes.data(), bytes.size());
    BlockWriter writer(reader.version(), reader.flags());
    std::vector<std::pair<BlockType, std::vector<uint8_t>>> blocks;
    Block block;
    while (reader.next(block) && block.type != BlockType::end)
        blocks.emplace_back(block.type, std::vector<uint8_t>(block.payload, block.payload + block.size));
    for (size_t i = blocks.size(); i-- > 0;)
        if (blocks[i].first == BlockType::chunk) {
            blocks[i].second[blocks[i].second.size() / 2] ^= 0x5a;
            break;
        }
    for (const auto& b : blocks) writer.add(b.first, b.second);
    return writer.finish();
}

// A DecodeContext's decoders keep their working memory, and any state a restart forgot, from one
// decode to the next, and a recycled hierarchy's memory holds the next result: files of other
// sizes, chunk counts and geometry modes, with corrupt ones in between, must still decode exactly
// as without a context, on every thread count.
TEST(Chunks, DecodesThroughAContextAreThoseWithoutOne) {
    std::vector<std::vector<uint8_t>> files;
    for (uint64_t seed = 200; seed < 212; ++seed) {
        EncodeOptions options = with_chunks(2 + uint32_t(seed % 4), 1, seed % 3 == 1 ? 12 : 0);
        options.grid_contexts = seed % 2 == 0;
        options.unit_normals = seed % 4 == 2;
        files.push_back(encode(random_hierarchy(seed, seed % 5 == 0), options));
    }
    for (unsigned threads : {1u, 2u, 3u}) {
        const DecodeOptions options{-1, 1ull << 26, threads};
        DecodeContext context;
        int failed = 0;
        for (int pass = 0; pass < 2; ++pass) {
            for (size_t f = 0; f < files.size(); ++f) {
                const std::vector<uint8_t>& bytes = files[f];
                SCOPED_TRACE("file " + std::to_string(f) + ", " + std::to_string(threads) + " threads, pass " + std::to_string(pass));
                ASSERT_GT(inspect(bytes.data(), bytes.size()).chunks.size(), 1u);
                Hierarchy back = decode(context, bytes.data(), bytes.size(), options);
                EXPECT_TRUE(same_ids(back, decode(bytes.data(), bytes.size(), DecodeOptions{-1, 1ull << 26, 1})));
                // The next decode builds in this one's memory (its nodes and positions stale until written).
                if (pass == 1) context.recycle(f % 3 == 0 ? random_hierarchy(f, false) : std::move(back));
                const std::vector<uint8_t> corrupt = with_last_chunk_changed(bytes);
                const DecodeResult without = try_decode(corrupt.data(), corrupt.size(), options);
                try {
                    const Hierarchy h = decode(context, corrupt.data(), corrupt.size(), options);
                    EXPECT_TRUE(without.ok && same_ids(h, without.hierarchy));
                } catch (const Error& e) {
                    EXPECT_EQ(std::string(e.what()), without.error);
                    ++failed;
                }
            }
            if (pass == 0) context.release();
        }
        EXPECT_GT(failed, 0);
        DecodeContext moved = std::move(context);
        EXPECT_TRUE(same_ids(decode(moved, files[0].data(), files[0].size(), options), decode(files[0].data(), files[0].size())));
        EXPECT_TRUE(same_ids(decode(context, files[1].data(), files[1].size(), options), decode(files[1].data(), files[1].size())));
    }
}

}  // namespace
}  // namespace amc
