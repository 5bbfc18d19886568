// Golden series files (docs/FORMAT.md, section 7), one directory per series version
// (tests/data/golden/series/vN/), kept forever and never regenerated: each decodes to the frames it
// was made from, and the current writer's bytes are pinned to the current version's file. The
// frames use only correctly rounded arithmetic (no libm transcendental), so the bytes are the same
// on every IEEE platform. AMC_UPDATE_GOLDEN=1 writes a missing file (never overwrites one).
#include <amc/import.h>
#include <amc/octree.h>
#include <amc/refinement.h>
#include <amc/series.h>

#include "padded_series.h"
#include "series/series_format.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>

namespace amc {
namespace {

struct GoldenFrame {
    Hierarchy h;
    double time;
    std::vector<Field> fields;
};

// The front model with coarsening, a moving last frame and fields of several kinds.
std::vector<GoldenFrame> golden_frames() {
    std::vector<GoldenFrame> frames;
    std::vector<Hierarchy> meshes = make_moving_front_sequence(5, 5);
    for (size_t k = 0; k < meshes.size(); ++k) {
        Hierarchy& h = meshes[k];
        if (k == 4)  // a moving mesh: every vertex shifted
            for (NodeId n : h.breadth_first_order())
                for (int i = 0; i < 3; ++i) {
                    const VertexId v = h.vertex(n, i);
                    const Vec3 p = h.position(v);
                    h.set_position(v, {p.x + 0.125 * p.y * p.y, p.y, 0.0});
                }
        const LeafMesh leaf = extract_leaf_mesh(h);
        Field u{"u", FieldAssociation::point, FieldType::float64, 1, {}, {}};
        Field w{"w", FieldAssociation::point, FieldType::float32, 2, {}, {}};
        for (const Vec3& p : leaf.mesh.positions) {
            u.values.push_back(p.x * p.x - 0.5 * p.y + 0.1 * double(k));
            w.values.push_back(double(float(p.x * p.y)));
            w.values.push_back(double(float(1.0 / (1.0 + p.x))));
        }
        Field level{"level", FieldAssociation::cell, FieldType::uint8, 1, {}, {}};
        Field area{"area", FieldAssociation::cell, FieldType::float64, 1, {}, {}};
        for (size_t t = 0; t < leaf.mesh.triangles.size(); ++t) {
            level.integers.push_back(leaf.cells.level[t]);
            const Triangle& tri = leaf.mesh.triangles[t];
            const Vec3 e1 = leaf.mesh.positions[tri[1]] - leaf.mesh.positions[tri[0]];
            const Vec3 e2 = leaf.mesh.positions[tri[2]] - leaf.mesh.positions[tri[0]];
            area.values.push_back(0.5 * cross(e1, e2).z);
        }
        frames.push_back({h, 0.25 * double(k), {u, w, level, area}});
    }
    return frames;
}

// Version 2 on: an adaptive run in miniature, whose refinement follows its own cell field "eta"
// (a peak moving across the square; refine where eta is large, coarsen where it is small), so
// that the inter-frame forests take eta as their indicator (FORMAT.md 7.6). Only + - * /.
std::vector<GoldenFrame> indicator_frames() {
    std::vector<GoldenFrame> frames;
    Hierarchy h(make_square(4));
    for (int k = 0; k < 8; ++k) {
        const LeafMesh leaf = extract_leaf_mesh(h);
        Field eta{"eta", FieldAssociation::cell, FieldType::float64, 1, {}, {}};
        const double px = 0.15 + 0.1 * double(k), py = 0.5;
        for (const Triangle& t : leaf.mesh.triangles) {
            const Vec3 s = leaf.mesh.positions[t[0]] + leaf.mesh.positions[t[1]] + leaf.mesh.positions[t[2]];
            const Vec3 c{s.x / 3, s.y / 3, s.z / 3};
            const Vec3 e1 = leaf.mesh.positions[t[1]] - leaf.mesh.positions[t[0]];
            const Vec3 e2 = leaf.mesh.positions[t[2]] - leaf.mesh.positions[t[0]];
            const double area = 0.5 * cross(e1, e2).z;
            eta.values.push_back(area / (0.01 + (c.x - px) * (c.x - px) + (c.y - py) * (c.y - py)));
        }
        frames.push_back({h, double(k), {eta}});
        std::vector<uint32_t> refine, coarsen;
        for (uint32_t e = 0; e < eta.values.size(); ++e) {
            if (eta.values[e] > 0.02 && leaf.cells.level[e] < 6) refine.push_back(e);
            else if (eta.values[e] < 0.002) coarsen.push_back(e);
        }
        apply_adaptation_step(h, refine, coarsen);
    }
    return frames;
}

SeriesOptions golden_options() {
    SeriesOptions options;
    options.keyframe_interval = 3;
    options.field_bounds = {{"area", 1e-4}};
    return options;
}

std::string golden_path(int version, const std::string& name = "front_fields") {
    return std::string(AMC_TEST_DATA_DIR) + "/golden/series/v" + std::to_string(version) + "/" + name + ".amcs";
}

std::vector<uint8_t> read_file(const std::string& path) {
    std::ifstream file(path, std::ios::binary);
    return std::vector<uint8_t>((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
}

TEST(SeriesGolden, EncodingMatchesTheCurrentVersionsFile) {
    const std::vector<GoldenFrame> frames = golden_frames();
    SeriesWriter writer(frames[0].h.base(), golden_options());
    for (const GoldenFrame& f : frames) writer.add_frame(f.h, f.time, f.fields);
    writer.close();
    const std::string path = golden_path(kSeriesVersion);
    if (std::getenv("AMC_UPDATE_GOLDEN") && !std::filesystem::exists(path)) {
        std::filesystem::create_directories(std::filesystem::path(path).parent_path());
        std::ofstream(path, std::ios::binary)
            .write(reinterpret_cast<const char*>(writer.bytes().data()), std::streamsize(writer.bytes().size()));
    }
    const std::vector<uint8_t> golden = read_file(path);
    ASSERT_FALSE(golden.empty()) << path << " is missing";
    EXPECT_EQ(writer.bytes(), golden) << "the series bitstream changed (a new series version: FORMAT.md, section 7)";
}

TEST(SeriesGolden, FilesOfEveryVersionDecodeToTheirFrames) {
    for (int version = 1; version <= kNewestSeriesVersion; ++version) {
        SCOPED_TRACE(golden_path(version));
        const std::vector<GoldenFrame> frames = golden_frames();
        SeriesReader reader(read_file(golden_path(version)), golden_path(version));
        ASSERT_EQ(reader.frame_count(), frames.size());
        for (size_t k = 0; k < frames.size(); ++k) {
            const SeriesFrame f = reader.frame(k);
            if (k % 3 == 0) {
                EXPECT_TRUE(reader.info(k).keyframe) << k;  // version 2: and the encoder's choices
            }
            EXPECT_TRUE(identical(f.hierarchy, frames[k].h)) << "frame " << k;
            EXPECT_EQ(f.time, frames[k].time);
            ASSERT_EQ(f.fields.size(), frames[k].fields.size());
            for (size_t i = 0; i < f.fields.size(); ++i) {
                if (f.fields[i].name == "area") {
                    EXPECT_LE(max_abs_difference(f.fields[i], frames[k].fields[i]), 1e-4);
                } else {
                    EXPECT_TRUE(identical(f.fields[i], frames[k].fields[i])) << "frame " << k << " " << f.fields[i].name;
                }
            }
        }
    }
}

void write_missing_golden(const std::string& path, const std::vector<uint8_t>& bytes) {
    if (!std::getenv("AMC_UPDATE_GOLDEN") || std::filesystem::exists(path)) return;
    std::filesystem::create_directories(std::filesystem::path(path).parent_path());
    std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
}

TEST(SeriesGolden, TheIndicatorFileOfVersion2DecodesAndIsWhatTheWriterWrites) {
    const std::vector<GoldenFrame> frames = indicator_frames();
    SeriesWriter writer(frames[0].h.base());
    std::vector<SeriesFrameStats> stats;
    for (const GoldenFrame& f : frames) stats.push_back(writer.add_frame(f.h, f.time, f.fields));
    writer.close();
    const std::string current = golden_path(kSeriesVersion, "indicator");
    write_missing_golden(current, writer.bytes());
    EXPECT_EQ(writer.bytes(), read_file(current)) << "the series bitstream changed (a new series version: FORMAT.md, section 7)";
    for (int version = 2; version <= kNewestSeriesVersion; ++version) {
        const std::string path = golden_path(version, "indicator");
        SeriesReader reader(read_file(path), path);
        ASSERT_EQ(reader.frame_count(), frames.size());
        for (size_t k = 0; k < frames.size(); ++k) {
            const SeriesFrame f = reader.frame(k);
            EXPECT_TRUE(identical(f.hierarchy, frames[k].h)) << path << " frame " << k;
            ASSERT_EQ(f.fields.size(), 1u);
            EXPECT_TRUE(identical(f.fields[0], frames[k].fields[0])) << path << " frame " << k;
        }
    }
}

// The padded series (padded_series.h): frames that cost next to nothing, padded by the writers to
// at most kSeriesNodesPerByte nodes (octants) per byte (FORMAT.md 7.2, Bounds).
TEST(SeriesGolden, PaddedFramesDecodeAndAreWhatTheWritersWrite) {
    const test::PaddedSeries series = test::padded_series();
    const std::string path = golden_path(kSeriesVersion, "padded");
    write_missing_golden(path, series.bytes);
    const std::vector<uint8_t> golden = read_file(path);
    EXPECT_EQ(series.bytes, golden) << "the series bitstream changed (a new series version: FORMAT.md, section 7)";
    SeriesReader reader(golden, path);
    ASSERT_EQ(reader.frame_count(), 2u);
    for (size_t k = 0; k < 2; ++k) {
        EXPECT_TRUE(identical(reader.frame(k).hierarchy, series.hierarchy)) << path << " frame " << k;
        EXPECT_LT((reader.info(k).size - 1) * kSeriesNodesPerByte, series.hierarchy.node_count()) << "frame " << k << " not padded";
    }

    const test::PaddedForestSeries forests = test::padded_forest_series();
    const std::string forest_path = golden_path(kForestSeriesVersion, "padded_forest");
    write_missing_golden(forest_path, forests.bytes);
    const std::vector<uint8_t> forest_golden = read_file(forest_path);
    EXPECT_EQ(forests.bytes, forest_golden) << "the series bitstream changed (a new series version: FORMAT.md, section 7)";
    ForestSeriesReader forest_reader(forest_golden, forest_path);
    ASSERT_EQ(forest_reader.frame_count(), 2u);
    for (size_t k = 0; k < 2; ++k) {
        EXPECT_EQ(forest_reader.frame(k).forest, forests.forest) << forest_path << " frame " << k;
        EXPECT_LT((forest_reader.info(k).size - 1) * kSeriesNodesPerByte, forest_reader.info(k).octants) << "frame " << k;
    }
}

}  // namespace
}  // namespace amc
