// The thread-safety promise of README.md ("Threads"): calls on different objects, and const calls on
// one shared object, run at once from any number of threads. Run under ThreadSanitizer by .ci/run
// (AMC_SANITIZE_THREAD), where a data race is fatal; without it these tests still check results.
#include "hierarchy_checks.h"

#include "common/parallel.h"

#include <amc/codec.h>
#include <amc/hierarchy_coder.h>
#include <amc/import.h>
#include <amc/mesh.h>
#include <amc/mesh_io.h>
#include <amc/octree.h>
#include <amc/series.h>
#include <amc/simulation.h>

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>
#include <vector>

#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

namespace amc {
namespace {

constexpr int kThreads = 4;

Hierarchy test_hierarchy(uint64_t seed) {
    Hierarchy h(seed % 2 ? make_icosahedron() : make_torus(6, 5, 2.0, 0.7));
    refine_randomly(h, 400, 4, seed);
    return h;
}

// One shared hierarchy and one shared file, encoded, decoded and inspected by every thread at once,
// each also building, encoding and decoding hierarchies of its own.
TEST(ThreadSafety, ConcurrentEncodesAndDecodesGiveTheSerialResults) {
    const Hierarchy shared = test_hierarchy(7);
    const std::vector<uint8_t> shared_bytes = encode(shared);
    const Hierarchy shared_back = decode(shared_bytes.data(), shared_bytes.size());
    std::atomic<int> mismatches{0};
    std::vector<std::thread> threads;
    for (int t = 0; t < kThreads; ++t) {
        threads.emplace_back([&, t] {
            for (int round = 0; round < 3; ++round) {
                EncodeOptions options;
                options.quantize_bits = round == 2 ? 14 : 0;
                options.predictor = round == 1 ? GeometryPredictor::butterfly : GeometryPredictor::automatic;
                if (options.quantize_bits == 0 && options.predictor == GeometryPredictor::automatic && encode(shared, options) != shared_bytes)
                    ++mismatches;
                if (!identical(decode(shared_bytes.data(), shared_bytes.size()), shared_back)) ++mismatches;
                if (inspect(shared_bytes.data(), shared_bytes.size()).levels == 0) ++mismatches;
                const Hierarchy own = test_hierarchy(uint64_t(100 + t * 10 + round));
                const std::vector<uint8_t> bytes = encode(own, options);
                const DecodeResult back = try_decode(bytes.data(), bytes.size());
                if (!back.ok || (options.quantize_bits == 0 && !identical(back.hierarchy, in_decoder_order(own)))) ++mismatches;
                const std::vector<uint8_t> stream = encode_hierarchy(own);
                if (decode_hierarchy(own.base(), stream.data(), stream.size()).leaf_count() != own.leaf_count()) ++mismatches;
            }
        });
    }
    for (std::thread& thread : threads) thread.join();
    EXPECT_EQ(mismatches.load(), 0);
}

// A chunked file decoded on several threads, each chunk into its slice of one hierarchy (with the
// seam vertices each thread's chunks split off in an array of the thread's), also through a
// DecodeContext kept by each of two threads decoding at once: the one-thread hierarchy.
TEST(ThreadSafety, ChunkedFileDecodesInSlicesOnManyThreads) {
    Hierarchy h(make_square(12));
    refine_randomly(h, 4000, 6, 11);
    for (int bits : {0, 12}) {
        EncodeOptions options;
        options.quantize_bits = bits;
        options.chunks = 16;
        options.min_chunk_bytes = 0;
        const std::vector<uint8_t> file = encode(h, options);
        ASSERT_EQ(inspect(file.data(), file.size()).chunks.size(), 16u);
        DecodeOptions one;
        one.threads = 1;
        const Hierarchy serial = decode(file.data(), file.size(), one);
        DecodeOptions four;
        four.threads = 4;
        EXPECT_TRUE(identical(decode(file.data(), file.size(), four), serial));
        std::atomic<int> mismatches{0};
        std::vector<std::thread> threads;
        for (int t = 0; t < 2; ++t) {
            threads.emplace_back([&] {
                DecodeContext context;
                DecodeOptions two;
                two.threads = 2;
                for (int round = 0; round < 2; ++round) {
                    Hierarchy back = decode(context, file.data(), file.size(), two);
                    mismatches += !identical(back, serial);
                    context.recycle(std::move(back));
                }
            });
        }
        for (std::thread& thread : threads) thread.join();
        EXPECT_EQ(mismatches.load(), 0);
    }
}

// Effort 3 codes its base orders' files several at once (encode_choosing_base): an encode on four
// threads, and two at once from two threads, each on two threads with an EncodeContext of its own
// (whose memory serves one file at a time), write the one-thread bytes and choose its order.
TEST(ThreadSafety, EffortThreeOnThreadsGivesTheOneThreadFile) {
    const Hierarchy h = testing::curved_sphere_remesh(3000);
    EncodeOptions options;
    options.hierarchy_contexts = HierarchyContexts::mixed;
    options.effort = 3;
    options.threads = 1;
    const std::vector<uint8_t> serial = encode(h, options);
    const Hierarchy serial_order = in_decoder_order(h, options);
    EncodeOptions two = options;
    two.effort = kMaxGeometryEffort;
    ASSERT_LT(serial.size(), encode(h, two).size()) << "the search keeps the base coder's order: nothing to choose between";
    options.threads = 4;
    EXPECT_EQ(encode(h, options), serial);
    EXPECT_TRUE(identical(in_decoder_order(h, options), serial_order));
    options.threads = 2;
    std::atomic<int> mismatches{0};
    std::vector<std::thread> threads;
    for (int t = 0; t < 2; ++t) {
        threads.emplace_back([&] {
            EncodeContext context;
            for (int round = 0; round < 2; ++round) mismatches += encode(context, h, options) != serial;
        });
    }
    for (std::thread& thread : threads) thread.join();
    EXPECT_EQ(mismatches.load(), 0);
}

// Base detection runs its second search (the triangles in reverse order) beside the first on two
// threads, and cancels it when the first finds it not needed: the hierarchy is the one-thread one
// either way. The random refinement's search stops far from its base (so the second one counts);
// the uniform one finds its base (so the second one is cancelled).
TEST(ThreadSafety, BaseSearchOnTwoThreadsGivesTheOneThreadHierarchy) {
    Hierarchy random(make_icosahedron());
    refine_randomly(random, 3000, 6, 11);
    Hierarchy uniform(make_icosahedron());
    refine_uniformly(uniform, 3);
    for (const Hierarchy* h : {&random, &uniform}) {
        const TriangleMesh leaf = extract_leaf_mesh(*h).mesh;
        const ImportedHierarchy one = import_mesh(leaf, "leaf", 1);
        const ImportedHierarchy two = import_mesh(leaf, "leaf", 2);
        EXPECT_TRUE(identical(one.hierarchy, two.hierarchy));
        EXPECT_EQ(one.vertex_of_input, two.vertex_of_input);
        const bool far_from_base = one.hierarchy.base().triangles.size() * 16 > leaf.triangles.size();
        EXPECT_EQ(far_from_base, h == &random) << "the case does not take the path it is there for";
    }
}

// The series file and the octree coder the same way: one shared file read by every thread (each with
// a reader of its own: SeriesReader keeps the frame it decoded last), one shared forest encoded by
// all, and each thread writing a series and a forest of its own.
TEST(ThreadSafety, ConcurrentSeriesAndOctreeCodingGivesTheSerialResults) {
    HeatRunOptions run;
    run.frames = 3;
    run.max_level = 4;
    run.target_elements = 150;
    run.initial_adaptations = 2;
    std::vector<SeriesFrame> frames;
    run_heat_simulation(run, [&](const SimulationFrame& f) { frames.push_back({*f.hierarchy, f.time, f.fields}); });
    auto write_series = [&](const SeriesOptions& options) {
        SeriesWriter writer(frames.front().hierarchy.base(), options);
        for (const SeriesFrame& f : frames) writer.add_frame(f.hierarchy, f.time, f.fields);
        writer.close();
        return writer.bytes();
    };
    const std::vector<uint8_t> series = write_series({});
    const OctreeForest forest = balance_octree_forest(
        random_octree_forest(brick_connectivity(3, 2, 1, 1, true), 5, 0.4, 1, 3), OctreeBalance::face);
    const std::vector<uint8_t> amq = encode_octree_forest(forest);
    std::atomic<int> mismatches{0};
    std::vector<std::thread> threads;
    for (int t = 0; t < kThreads; ++t) {
        threads.emplace_back([&, t] {
            SeriesReader reader(series);
            for (size_t k = frames.size(); k-- > 0;)  // backwards: every frame from its keyframe
                if (!identical(reader.frame(k).hierarchy, frames[k].hierarchy)) ++mismatches;
            SeriesOptions own;
            own.keyframe_interval = uint32_t(1 + t % 2);
            own.error_bound = t % 2 ? 1e-4 : 0;
            const std::vector<uint8_t> bytes = write_series(own);
            SeriesReader own_reader(bytes);
            if (own_reader.frame_count() != frames.size() || !identical(own_reader.frame(1).hierarchy, frames[1].hierarchy))
                ++mismatches;
            if (encode_octree_forest(forest) != amq || !(decode_octree_forest(amq.data(), amq.size()) == forest)) ++mismatches;
            const OctreeForest mine = balance_octree_forest(
                random_octree_forest(brick_connectivity(2, 1 + t, 2, 1), uint64_t(t), 0.5, 1, 5), OctreeBalance::face);
            const std::vector<uint8_t> mine_bytes = encode_octree_forest(mine);
            if (!(decode_octree_forest(mine_bytes.data(), mine_bytes.size()) == mine)) ++mismatches;
        });
    }
    for (std::thread& thread : threads) thread.join();
    EXPECT_EQ(mismatches.load(), 0);
}

// Threads writing the same path at once: every write is whole, the last rename wins, no temporary
// file is left (write_file_atomically's names are unique per call).
// The VTU writer compresses and the reader inflates runs of zlib blocks on several threads
// (docs/VTU.md): arrays of several MiB, so that the runs are shared out, give the bytes and the
// mesh of one thread.
TEST(ThreadSafety, VtuWriterAndReaderThreadsGiveTheSerialResults) {
    TriangleMesh mesh;
    constexpr uint32_t kSide = 300;
    for (uint32_t j = 0; j <= kSide; ++j)
        for (uint32_t i = 0; i <= kSide; ++i) mesh.positions.push_back({i * 0.1, j * 0.3, double(i * j % 17)});
    for (uint32_t j = 0; j < kSide; ++j) {
        for (uint32_t i = 0; i < kSide; ++i) {
            const uint32_t a = j * (kSide + 1) + i;
            mesh.triangles.push_back({a, a + 1, a + kSide + 2});
            mesh.triangles.push_back({a, a + kSide + 2, a + kSide + 1});
        }
    }
    const std::string one = format_mesh(mesh, nullptr, MeshFormat::vtu, MeshEncoding::binary, 1);
    EXPECT_EQ(format_mesh(mesh, nullptr, MeshFormat::vtu, MeshEncoding::binary, kThreads), one);

    // The reader inflates runs of the same blocks on several threads: threads reading the file
    // at once, each on several threads, read the mesh of one thread.
    const std::string path =
        (std::filesystem::temp_directory_path() / ("amc_threads_read_" + std::to_string(::getpid()) + ".vtu")).string();
    {
        std::ofstream(path, std::ios::binary) << one;
    }
    const VtuMesh serial = read_vtu(path, 1);
    EXPECT_EQ(serial.mesh.triangles, mesh.triangles);
    std::atomic<int> same{0};
    std::vector<std::thread> readers;
    for (int t = 0; t < kThreads; ++t) {
        readers.emplace_back([&] {
            const VtuMesh vtu = read_vtu(path, kThreads);
            if (vtu.mesh.positions == serial.mesh.positions && vtu.mesh.triangles == serial.mesh.triangles) ++same;
        });
    }
    for (std::thread& reader : readers) reader.join();
    std::filesystem::remove(path);
    EXPECT_EQ(same.load(), kThreads);
}

TEST(ThreadSafety, ConcurrentAtomicWritesOfOnePathLeaveOneWholeFile) {
    const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("amc_threads_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    const std::string path = (dir / "out.amc").string();
    std::vector<std::string> contents;
    for (int t = 0; t < kThreads; ++t) contents.push_back(std::string(size_t(200000 + 1000 * t), char('a' + t)));
    std::vector<std::thread> threads;
    for (int t = 0; t < kThreads; ++t) {
        threads.emplace_back([&, t] {
            for (int round = 0; round < 20; ++round) write_file_atomically(path, contents[size_t(t)]);
        });
    }
    for (std::thread& thread : threads) thread.join();
    std::ifstream file(path, std::ios::binary);
    const std::string written((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
    EXPECT_NE(std::find(contents.begin(), contents.end(), written), contents.end()) << "a mixed or partial file";
    int entries = 0;
    for (const auto& entry : std::filesystem::directory_iterator(dir)) {
        ++entries;
        EXPECT_EQ(entry.path().filename(), "out.amc");
    }
    EXPECT_EQ(entries, 1);
    std::filesystem::remove_all(dir);
}

// parallel_for (src/common/parallel.h) called by several threads at once and from inside its own
// tasks: every task runs once, and a task's exception comes back to its caller only.
TEST(ThreadSafety, ParallelForRunsEveryTaskOnceFromManyCallersAndNested) {
    constexpr size_t kTasks = 40, kInner = 7;
    std::atomic<int> wrong{0};
    std::vector<std::thread> threads;
    for (int t = 0; t < kThreads; ++t) {
        threads.emplace_back([&, t] {
            for (int round = 0; round < 20; ++round) {
                std::vector<std::atomic<int>> runs(kTasks * kInner);
                parallel_for(kTasks, unsigned(2 + t % 3), [&](size_t i) {
                    parallel_for(kInner, 2, [&](size_t k) { ++runs[i * kInner + k]; });
                });
                for (const std::atomic<int>& r : runs) wrong += r.load() != 1;
                bool caught = false;
                try {
                    parallel_for(kTasks, 3, [&](size_t i) {
                        if (i == kTasks / 2) throw Error("task " + std::to_string(i) + " of thread " + std::to_string(t));
                    });
                } catch (const Error& e) {
                    caught = std::string(e.what()) == "task " + std::to_string(kTasks / 2) + " of thread " + std::to_string(t);
                }
                wrong += !caught;
            }
        });
    }
    for (std::thread& thread : threads) thread.join();
    EXPECT_EQ(wrong.load(), 0);
}

// Task 1 of a 2-thread parallel_for runs on a helper (task 0, the caller's, waits until it has
// started): the same helper thread every call, not a new one (docs/BENCHMARKS.md, "Threads and
// memory": a new thread's memory is faulted in again).
TEST(ThreadSafety, ParallelForKeepsItsHelperThread) {
    std::vector<long> helper_ids;
    for (int call = 0; call < 20; ++call) {
        std::atomic<bool> started{false};
        long id = 0;
        parallel_for(2, 2, [&](size_t i) {
            if (i == 1) {
                id = long(syscall(SYS_gettid));
                started = true;
                return;
            }
            while (!started) std::this_thread::yield();
        });
        helper_ids.push_back(id);
    }
    EXPECT_NE(helper_ids[0], long(syscall(SYS_gettid)));
    EXPECT_EQ(std::count(helper_ids.begin(), helper_ids.end(), helper_ids[0]), 20);
}

// A child forked after parallel_for has used helpers has none of them: its own parallel_for starts
// new ones instead of waiting for threads that do not exist in it.
TEST(ThreadSafety, ParallelForWorksInAForkedChild) {
#if defined(__SANITIZE_THREAD__)
    GTEST_SKIP() << "ThreadSanitizer ends a multi-threaded process's child that starts threads";
#else
    auto both_threads = [] {
        std::atomic<bool> started{false};
        parallel_for(2, 2, [&](size_t i) {
            if (i == 1) started = true;
            while (!started) std::this_thread::yield();
        });
    };
    both_threads();
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
        alarm(20);  // a child waiting for a helper that does not exist ends here, failed
        both_threads();
        _exit(0);
    }
    int status = 0;
    ASSERT_EQ(waitpid(child, &status, 0), child);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "status " << status;
#endif
}

}  // namespace
}  // namespace amc
