// Series of quadtree/octree forests (include/amc/series.h, docs/FORMAT.md 7.10-7.12): round trips
// frame by frame in 2D and 3D with leaf fields, random access, keyframes, forests balanced by
// corners or not at all, the cost of unchanged frames, golden files of version 3, truncated,
// corrupted and mutated files refused.
#include <amc/octree.h>
#include <amc/series.h>

#include "series/series_format.h"

#include <gtest/gtest.h>
#include <xxhash.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <unistd.h>

namespace amc {
namespace {

// A straight front u + v / 2 = t crossing the coarse mesh (tree coordinates in the brick), refined
// in a band of about two octants at every level; balanced as asked. Exact dyadic arithmetic only
// (no libm), so that the golden files are the same everywhere. Leaf fields: "phi" (Float64, the
// front's distance at the leaf's centre), "level" (UInt8), "flux" (Float32 x 2).
OctreeForest straight_front(const TreeConnectivity& conn, double t, int max_level, OctreeBalance balance, bool with_fields = true) {
    const int root = octree_root_log2(conn.dim);
    auto phi_of = [&](uint32_t tree, const Octant& o, double* size) {
        const double len = double(int64_t(1) << (root - o.level));
        const Vec3 corner = tree_point(conn, tree, 0, 0, 0);
        const double u = corner.x + (o.x + len / 2) / double(int64_t(1) << root);
        const double v = corner.y + (o.y + len / 2) / double(int64_t(1) << root);
        *size = len / double(int64_t(1) << root);
        return u + v / 2 - t;
    };
    OctreeForest f = refine_octree_forest(uniform_octree_forest(conn, 0),
                                          [&](uint32_t tree, const Octant& o) {
                                              double size;
                                              const double phi = phi_of(tree, o, &size);
                                              return (phi < 0 ? -phi : phi) < 1.25 * size;
                                          },
                                          max_level);
    if (balance != OctreeBalance(0)) f = balance_octree_forest(f, balance);
    if (!with_fields) return f;
    Field phi{"phi", FieldAssociation::cell, FieldType::float64, 1, {}, {}};
    Field level{"level", FieldAssociation::cell, FieldType::uint8, 1, {}, {}};
    Field flux{"flux", FieldAssociation::cell, FieldType::float32, 2, {}, {}};
    for (uint32_t tree = 0; tree < f.tree_count(); ++tree)
        for (uint64_t i = f.tree_offsets[tree]; i < f.tree_offsets[tree + 1]; ++i) {
            double size;
            const double p = phi_of(tree, f.leaves[i], &size);
            phi.values.push_back(p);
            level.integers.push_back(f.leaves[i].level);
            flux.values.push_back(double(float(p > 0 ? 1 : -1)));
            flux.values.push_back(double(float(size * 0.5)));
        }
    f.leaf_data = {phi, level, flux};
    return f;
}

std::vector<OctreeForest> front_frames(int dim, int frames, int max_level, double step, OctreeBalance balance = OctreeBalance::face) {
    const TreeConnectivity conn = dim == 2 ? brick_connectivity(2, 2, 1) : brick_connectivity(3, 1, 1, 1);
    std::vector<OctreeForest> out;
    for (int k = 0; k < frames; ++k) out.push_back(straight_front(conn, 0.25 + step * k, max_level, balance));
    return out;
}

std::vector<uint8_t> write_forest_series(const std::vector<OctreeForest>& frames, const SeriesOptions& options = {},
                                         std::vector<ForestSeriesFrameStats>* stats = nullptr) {
    ForestSeriesWriter writer(frames.front().connectivity, options);
    for (size_t k = 0; k < frames.size(); ++k) {
        const ForestSeriesFrameStats s = writer.add_frame(frames[k], 0.5 * double(k));
        if (stats) stats->push_back(s);
    }
    writer.close();
    return writer.bytes();
}

void expect_frames(ForestSeriesReader& reader, const std::vector<OctreeForest>& frames) {
    ASSERT_EQ(reader.frame_count(), frames.size());
    for (size_t k = 0; k < frames.size(); ++k) {
        const ForestSeriesFrame f = reader.frame(k);
        EXPECT_TRUE(f.forest == frames[k]) << "frame " << k;
        EXPECT_EQ(f.time, 0.5 * double(k));
    }
}

TEST(ForestSeries, FrontRoundTripsFrameByFrameIn2DAnd3D) {
    for (int dim : {2, 3}) {
        SCOPED_TRACE(dim);
        // The front advances half a finest leaf a frame (a CFL-bounded solver's front).
        const int max_level = dim == 2 ? 7 : 4;
        const std::vector<OctreeForest> frames = front_frames(dim, 12, max_level, std::ldexp(0.5, -max_level));
        std::vector<ForestSeriesFrameStats> stats;
        const std::vector<uint8_t> bytes = write_forest_series(frames, {}, &stats);
        ForestSeriesReader reader(bytes);
        EXPECT_EQ(reader.version(), 3);
        EXPECT_TRUE(is_forest_series(bytes));
        expect_frames(reader, frames);
        uint64_t series = 0, independent = 0;
        for (size_t k = 0; k < frames.size(); ++k) {
            EXPECT_EQ(stats[k].leaves, frames[k].leaves.size());
            if (k == 0) continue;  // the keyframe
            series += stats[k].connectivity_bytes;
            OctreeForest bare = frames[k];
            bare.leaf_data.clear();
            OctreeEncodeStats s;
            encode_octree_forest(bare, {}, &s);
            independent += s.level_bytes;
        }
        // A front moving half a finest leaf a step: most of each forest persists (these small
        // forests: 0.55 and 0.52 of the frames coded alone; 0.51 at 12,000 leaves, SERIES.md).
        EXPECT_LT(10 * series, 7 * independent) << series << " against " << independent;
    }
}

TEST(ForestSeries, RandomAccessAndKeyframes) {
    const std::vector<OctreeForest> frames = front_frames(2, 15, 6, 1.0 / 32);
    SeriesOptions options;
    options.keyframe_interval = 4;
    const std::vector<uint8_t> bytes = write_forest_series(frames, options);
    ForestSeriesReader reader(bytes);
    EXPECT_EQ(reader.keyframe_interval(), 4u);
    for (size_t k : {9ul, 2ul, 14ul, 3ul, 4ul, 13ul}) EXPECT_TRUE(reader.frame(k).forest == frames[k]) << k;
    for (size_t k = 0; k < frames.size(); ++k) EXPECT_EQ(reader.info(k).keyframe, k % 4 == 0 || reader.info(k).keyframe) << k;
    for (size_t k = 0; k < frames.size(); k += 4) EXPECT_TRUE(reader.info(k).keyframe) << k;
    expect_frames(reader, frames);
}

TEST(ForestSeries, UnchangedFramesCostNextToNothing) {
    std::vector<OctreeForest> frames = front_frames(2, 1, 8, 0);
    frames.push_back(frames[0]);
    frames.push_back(frames[0]);
    std::vector<ForestSeriesFrameStats> stats;
    const std::vector<uint8_t> bytes = write_forest_series(frames, {}, &stats);
    EXPECT_FALSE(stats[2].keyframe);
    EXPECT_EQ(stats[2].changed_octants, 0u);
    EXPECT_LE(stats[2].connectivity_bytes, 4u);  // the switches byte and a stream of a few bytes
    EXPECT_LT(stats[2].field_bytes * 20, stats[0].field_bytes) << stats[2].field_bytes;  // temporal: residuals zero
    ForestSeriesReader reader(bytes);
    expect_frames(reader, frames);
}

TEST(ForestSeries, ForestsBalancedByCornersOrNotAtAllAndWithoutFields) {
    for (OctreeBalance balance : {OctreeBalance::corner, OctreeBalance(0)}) {
        std::vector<OctreeForest> frames = front_frames(2, 6, 6, 1.0 / 16, balance);
        frames[3].leaf_data.clear();  // fields come and go
        frames[4].leaf_data.pop_back();
        ForestSeriesReader reader(write_forest_series(frames));
        expect_frames(reader, frames);
    }
    // Turned trees (every face orientation) and random forests, changing completely.
    std::mt19937_64 rng(28);
    for (int dim : {2, 3}) {
        const TreeConnectivity conn = brick_connectivity(dim, 2, 2, dim == 3 ? 2 : 1, true, false, false);
        std::vector<OctreeForest> frames;
        for (int k = 0; k < 5; ++k)
            frames.push_back(balance_octree_forest(random_octree_forest(conn, rng(), 0.4, 1, dim == 2 ? 5 : 3), OctreeBalance::face));
        ForestSeriesReader reader(write_forest_series(frames));
        expect_frames(reader, frames);
    }
}

TEST(ForestSeries, RefusesOtherConnectivitiesBadForestsAndBounds) {
    const std::vector<OctreeForest> frames = front_frames(2, 2, 5, 1.0 / 16);
    ForestSeriesWriter writer(frames[0].connectivity);
    writer.add_frame(frames[0], 0);
    OctreeForest other = frames[1];
    other.connectivity = brick_connectivity(2, 1, 2);
    EXPECT_THROW(writer.add_frame(other, 1), Error);
    OctreeForest bad = frames[1];
    bad.leaves.pop_back();
    EXPECT_THROW(writer.add_frame(bad, 1), Error);
    bad = frames[1];
    bad.leaf_data[0].values.pop_back();
    EXPECT_THROW(writer.add_frame(bad, 1), Error);
    EXPECT_EQ(writer.frame_count(), 1u);
    writer.add_frame(frames[1], 1);
    writer.close();
    ForestSeriesReader reader(writer.bytes());
    EXPECT_TRUE(reader.frame(1).forest == frames[1]);
    SeriesOptions bounded;
    bounded.error_bound = 1e-3;
    EXPECT_THROW(ForestSeriesWriter(frames[0].connectivity, bounded), Error);
}

TEST(ForestSeries, TriangleAndForestReadersRefuseEachOthersFiles) {
    const std::vector<uint8_t> forests = write_forest_series(front_frames(2, 2, 4, 1.0 / 16));
    try {
        SeriesReader r(forests, "f.amcs");
        FAIL();
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("forests"), std::string::npos) << e.what();
    }
    SeriesWriter triangles(TriangleMesh{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{0, 1, 2}}});
    triangles.close();
    EXPECT_FALSE(is_forest_series(triangles.bytes()));
    try {
        ForestSeriesReader r(triangles.bytes(), "t.amcs");
        FAIL();
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("triangle"), std::string::npos) << e.what();
    }
}

std::vector<uint8_t> small_forest_series(size_t* frames_end = nullptr) {
    const std::vector<OctreeForest> frames = front_frames(2, 4, 5, 1.0 / 32);
    ForestSeriesWriter writer(frames[0].connectivity);
    for (size_t k = 0; k < frames.size(); ++k) writer.add_frame(frames[k], double(k));
    if (frames_end) *frames_end = writer.bytes().size();
    writer.close();
    return writer.bytes();
}

TEST(ForestSeries, EveryTruncationIsRefusedOrReadsTheCompleteFrames) {
    size_t frames_end = 0;
    const std::vector<uint8_t> bytes = small_forest_series(&frames_end);
    ForestSeriesReader whole(bytes);
    for (size_t cut = 0; cut < bytes.size(); ++cut) {
        const std::vector<uint8_t> part(bytes.begin(), bytes.begin() + long(cut));
        try {
            ForestSeriesReader r(part);
            ADD_FAILURE() << "a file cut at " << cut << " was accepted";
        } catch (const Error& e) {
            EXPECT_TRUE(e.code() == ErrorCode::truncated || e.code() == ErrorCode::bad_magic) << cut << ": " << e.what();
        }
        if (cut % 7 != 0 && cut != frames_end) continue;
        SeriesReadOptions partial;
        partial.allow_unfinished = true;
        try {
            ForestSeriesReader r(part, "series", partial);
            for (size_t k = 0; k < r.frame_count(); ++k) EXPECT_TRUE(r.frame(k).forest == whole.frame(k).forest) << cut;
            if (cut == frames_end) {
                EXPECT_EQ(r.frame_count(), whole.frame_count());
            }
        } catch (const Error& e) {
            EXPECT_TRUE(e.code() == ErrorCode::truncated || e.code() == ErrorCode::bad_magic) << e.what();
        }
    }
}

void fix_checksums(std::vector<uint8_t>& b) {
    auto get32 = [&](size_t at) { return uint32_t(b[at]) | uint32_t(b[at + 1]) << 8 | uint32_t(b[at + 2]) << 16 | uint32_t(b[at + 3]) << 24; };
    auto put32 = [&](size_t at, uint32_t v) {
        for (int i = 0; i < 4; ++i) b[at + size_t(i)] = uint8_t(v >> (8 * i));
    };
    put32(12, XXH32(b.data(), 12, 0));
    for (size_t pos = 16; b.size() - pos >= 9;) {
        const uint32_t length = get32(pos + 1);
        if (length > b.size() - pos - 9) return;
        put32(pos + 5 + length, XXH32(b.data() + pos, 5 + size_t(length), 0));
        pos += 9 + size_t(length);
    }
}

TEST(ForestSeries, CorruptedAndMutatedFilesAreRefusedWithClearErrors) {
    const std::vector<uint8_t> bytes = small_forest_series();
    std::mt19937 rng(28);
    for (int trial = 0; trial < 200; ++trial) {
        std::vector<uint8_t> bad = bytes;
        bad[rng() % bad.size()] ^= uint8_t(1u << (rng() % 8));
        EXPECT_THROW(
            {
                ForestSeriesReader r(bad);
                for (size_t k = 0; k < r.frame_count(); ++k) r.frame(k);
            },
            Error);  // every flip breaks a checksum
    }
    std::vector<uint8_t> newer = bytes;
    newer[4] = kNewestSeriesVersion + 1;
    try {
        ForestSeriesReader r(newer);
        FAIL();
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), ErrorCode::unsupported_version);
    }
    std::vector<uint8_t> older = bytes;  // forest blocks came with version 3
    older[4] = 2;
    fix_checksums(older);
    EXPECT_THROW(ForestSeriesReader r(older), Error);
    // Behind valid checksums: an amc::Error naming the series, never a crash (ASan in CI).
    SeriesReadOptions options;
    options.max_nodes = 1u << 20;
    int refused = 0, decoded = 0;
    for (int trial = 0; trial < 1500; ++trial) {
        std::vector<uint8_t> bad = bytes;
        const int edits = 1 + int(rng() % 4);
        for (int e = 0; e < edits; ++e) {
            const size_t at = 16 + rng() % (bad.size() - 16);
            switch (rng() % 3) {
                case 0: bad[at] ^= uint8_t(1u << (rng() % 8)); break;
                case 1: bad[at] = uint8_t(rng()); break;
                default: bad[at] = rng() % 2 ? 0xff : 0x00; break;
            }
        }
        fix_checksums(bad);
        try {
            ForestSeriesReader r(bad, "series", options);
            for (size_t k = 0; k < r.frame_count(); ++k) r.frame(k);
            ++decoded;
        } catch (const Error& e) {
            ++refused;
            EXPECT_NE(std::string(e.what()).find("series"), std::string::npos) << e.what();
        }
    }
    EXPECT_GT(refused, 1000);
    std::printf("mutated forest series: %d refused, %d decoded\n", refused, decoded);
}

TEST(ForestSeries, AFileOnDiskReadsEveryCompleteFrameBeforeClose) {
    const std::vector<OctreeForest> frames = front_frames(2, 3, 5, 1.0 / 32);
    const std::string path = (std::filesystem::temp_directory_path() / ("forest_series_" + std::to_string(::getpid()) + ".amcs")).string();
    {
        ForestSeriesWriter writer(path, frames[0].connectivity);
        for (size_t k = 0; k < frames.size(); ++k) writer.add_frame(frames[k], 0.5 * double(k));
        SeriesReadOptions partial;
        partial.allow_unfinished = true;
        ForestSeriesReader unfinished = ForestSeriesReader::open(path, partial);
        EXPECT_FALSE(unfinished.finished());
        expect_frames(unfinished, frames);
        EXPECT_THROW(ForestSeriesReader::open(path), Error);
        writer.close();
    }
    ForestSeriesReader reader = ForestSeriesReader::open(path);
    EXPECT_TRUE(reader.finished());
    expect_frames(reader, frames);
    std::filesystem::remove(path);
}

// ---- golden files (FORMAT.md 7.10-7.12) ------------------------------------------------------

std::string golden_path(const std::string& name) {
    return std::string(AMC_TEST_DATA_DIR) + "/golden/series/v3/" + name + ".amcs";
}

void check_golden(const std::string& name, const std::vector<OctreeForest>& frames, const SeriesOptions& options) {
    const std::vector<uint8_t> bytes = write_forest_series(frames, options);
    const std::string path = golden_path(name);
    if (std::getenv("AMC_UPDATE_GOLDEN") && !std::filesystem::exists(path)) {
        std::filesystem::create_directories(std::filesystem::path(path).parent_path());
        std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    }
    std::ifstream file(path, std::ios::binary);
    const std::vector<uint8_t> golden((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
    ASSERT_FALSE(golden.empty()) << path << " is missing";
    EXPECT_EQ(bytes, golden) << "the forest series bitstream changed (a new series version: FORMAT.md, section 7)";
    ForestSeriesReader reader(golden, path);
    expect_frames(reader, frames);
}

TEST(ForestSeriesGolden, Version3FilesDecodeAndAreWhatTheWriterWrites) {
    SeriesOptions options;
    options.keyframe_interval = 5;
    check_golden("front_2d", front_frames(2, 7, 5, 1.0 / 32), options);
    std::vector<OctreeForest> frames = front_frames(3, 4, 3, 1.0 / 8, OctreeBalance::corner);
    frames[2] = front_frames(3, 1, 3, 0.9, OctreeBalance(0))[0];  // a jump: a keyframe by choice, unbalanced
    check_golden("front_3d", frames, {});
}

}  // namespace
}  // namespace amc
