// The series file (include/amc/series.h, docs/FORMAT.md section 7): round trips frame by frame on
// the adaptive heat run and the front model, random access, keyframes, moving meshes, fields of
// every kind, error bounds, cost of unchanged frames, encoder-chosen keyframes, the refinement
// indicator (version 2), truncation, corruption and a writer killed mid-frame.
#include <amc/refinement.h>
#include <amc/series.h>
#include <amc/simulation.h>

#include "series/frame_connectivity.h"
#include "coding/container.h"
#include "series/series_format.h"
#include "series/series_framing.h"

#include <gtest/gtest.h>
#include <xxhash.h>

#include <csignal>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>
#include <sys/wait.h>
#include <unistd.h>

namespace amc {
namespace {

struct Frame {
    Hierarchy h;
    double time;
    std::vector<Field> fields;
};

std::vector<Frame> heat_frames(int frames, HeatScenario scenario = HeatScenario::lshape, uint32_t target = 1500) {
    HeatRunOptions options;
    options.scenario = scenario;
    options.frames = frames;
    options.max_level = 8;
    options.target_elements = target;
    options.initial_adaptations = 4;
    std::vector<Frame> out;
    run_heat_simulation(options, [&](const SimulationFrame& f) { out.push_back({*f.hierarchy, f.time, f.fields}); });
    return out;
}

void expect_same_fields(const std::vector<Field>& a, const std::vector<Field>& b, size_t frame) {
    ASSERT_EQ(a.size(), b.size()) << "frame " << frame;
    for (size_t i = 0; i < a.size(); ++i) EXPECT_TRUE(identical(a[i], b[i])) << "frame " << frame << " field " << a[i].name;
}

std::vector<uint8_t> write_series(const std::vector<Frame>& frames, const SeriesOptions& options = {},
                                  std::vector<SeriesFrameStats>* stats = nullptr) {
    SeriesWriter writer(frames.front().h.base(), options);
    for (const Frame& f : frames) {
        SeriesFrameStats s = writer.add_frame(f.h, f.time, f.fields);
        if (stats) stats->push_back(s);
    }
    writer.close();
    return writer.bytes();
}

TEST(HeatSimulation, FramesAreValidAndCarryTheSolversFields) {
    const std::vector<Frame> frames = heat_frames(6);
    ASSERT_EQ(frames.size(), 6u);
    for (const Frame& f : frames) {
        EXPECT_EQ(check_invariants(f.h), "");
        const LeafMesh leaf = extract_leaf_mesh(f.h);
        ASSERT_EQ(f.fields.size(), 4u);
        EXPECT_EQ(f.fields[0].name, "temperature");
        EXPECT_EQ(f.fields[0].values.size(), leaf.mesh.positions.size());
        EXPECT_EQ(f.fields[1].values.size(), leaf.mesh.triangles.size());
        EXPECT_EQ(f.fields[2].values.size(), 3 * leaf.mesh.triangles.size());
        EXPECT_EQ(f.fields[3].integers.size(), leaf.mesh.triangles.size());
        double hottest = 0;
        for (double u : f.fields[0].values) hottest = std::max(hottest, u);
        EXPECT_GT(hottest, 0.01);  // the source heats the domain
        EXPECT_GT(leaf.mesh.triangles.size(), 200u);
    }
    // The mesh follows the source: refined and coarsened from frame to frame.
    EXPECT_FALSE(identical(frames[0].h, frames[5].h));
    // Deterministic.
    const std::vector<Frame> again = heat_frames(6);
    for (size_t k = 0; k < frames.size(); ++k) {
        EXPECT_TRUE(identical(frames[k].h, again[k].h));
        expect_same_fields(frames[k].fields, again[k].fields, k);
    }
}

TEST(SeriesFraming, RandomAccessStartsAtTheKeyframeOrAfterTheFrameHeld) {
    struct Info {
        bool keyframe;
    };
    const std::vector<Info> frames = {{true}, {false}, {false}, {true}, {false}, {false}};
    EXPECT_EQ(first_frame_to_decode(frames, 2, -1), 0u);
    EXPECT_EQ(first_frame_to_decode(frames, 5, -1), 3u);
    EXPECT_EQ(first_frame_to_decode(frames, 3, 2), 3u);  // a keyframe needs nothing before it
    EXPECT_EQ(first_frame_to_decode(frames, 5, 4), 5u);
    EXPECT_EQ(first_frame_to_decode(frames, 5, 5), 6u);  // held already: nothing to decode
    EXPECT_EQ(first_frame_to_decode(frames, 4, 1), 3u);  // held before the keyframe: start there
    EXPECT_EQ(first_frame_to_decode(frames, 1, 4), 0u);  // held after k: start over
}

TEST(SeriesFraming, PayloadBytesAreTakenInPlaceOrRefusedAsTruncated) {
    const std::vector<uint8_t> payload = {3, 'a', 'b', 'c', 9};
    PayloadReader in(payload.data(), payload.size(), "frame");
    const uint64_t length = in.varint();
    const uint8_t* name = in.bytes(length);
    EXPECT_EQ(std::string(reinterpret_cast<const char*>(name), size_t(length)), "abc");
    EXPECT_EQ(in.remaining(), 1u);
    try {
        in.bytes(2);
        FAIL() << "two bytes taken from one";
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), ErrorCode::truncated);
    }
    EXPECT_EQ(in.u8(), 9);
}

TEST(Series, HeatRunRoundTripsFrameByFrame) {
    const std::vector<Frame> frames = heat_frames(12);
    SeriesOptions options;
    options.keyframe_interval = 5;
    std::vector<SeriesFrameStats> stats;
    const std::vector<uint8_t> bytes = write_series(frames, options, &stats);
    SeriesReader reader(bytes);
    ASSERT_EQ(reader.frame_count(), frames.size());
    EXPECT_TRUE(reader.finished());
    for (size_t k = 0; k < frames.size(); ++k) {
        if (k % 5 == 0) {
            EXPECT_TRUE(stats[k].keyframe) << k;  // and any frame the encoder found smaller alone
        }
        EXPECT_EQ(reader.info(k).keyframe, stats[k].keyframe) << k;
        const SeriesFrame f = reader.frame(k);
        EXPECT_TRUE(identical(f.hierarchy, frames[k].h)) << "frame " << k;
        EXPECT_EQ(f.time, frames[k].time);
        expect_same_fields(f.fields, frames[k].fields, k);
    }
    // Random access from a fresh reader: a middle frame, then an earlier one.
    SeriesReader fresh(bytes);
    for (size_t k : {7u, 3u, 11u, 10u}) {
        const SeriesFrame f = fresh.frame(k);
        EXPECT_TRUE(identical(f.hierarchy, frames[k].h)) << "frame " << k;
        expect_same_fields(f.fields, frames[k].fields, k);
    }
}

TEST(Series, FrontModelWithCoarseningRoundTrips) {
    std::vector<Frame> frames;
    for (Hierarchy& h : make_moving_front_sequence(10, 7)) frames.push_back({std::move(h), 0.0, {}});
    const std::vector<uint8_t> bytes = write_series(frames);
    SeriesReader reader(bytes);
    for (size_t k = 0; k < frames.size(); ++k) EXPECT_TRUE(identical(reader.frame(k).hierarchy, frames[k].h)) << k;
}

TEST(Series, TheEncoderWritesAKeyframeWhenTheFrameAloneIsSmaller) {
    // The front moves by more than the width of its refined band from frame to frame: nothing
    // persists, and a frame coded alone is smaller than against the frame before it.
    std::vector<Frame> frames;
    for (Hierarchy& h : make_moving_front_sequence(12, 7)) frames.push_back({std::move(h), 0.0, {}});
    std::vector<SeriesFrameStats> chosen, fixed;
    const std::vector<uint8_t> with_choice = write_series(frames, {}, &chosen);
    SeriesOptions only_first;
    only_first.choose_keyframes = false;
    const std::vector<uint8_t> without = write_series(frames, only_first, &fixed);
    size_t keyframes = 0;
    for (size_t k = 0; k < frames.size(); ++k) {
        keyframes += chosen[k].keyframe;
        EXPECT_EQ(fixed[k].keyframe, k == 0) << k;
    }
    EXPECT_GT(keyframes, 1u);
    EXPECT_LT(with_choice.size(), without.size());
    // Random access starts at the chosen keyframes; every frame decodes in any order.
    SeriesReader reader(with_choice);
    for (size_t k : {11u, 4u, 7u, 0u, 8u}) {
        EXPECT_EQ(reader.info(k).keyframe, chosen[k].keyframe) << k;
        EXPECT_TRUE(identical(reader.frame(k).hierarchy, frames[k].h)) << k;
    }
}

TEST(Series, TheErrorIndicatorOfTheFrameBeforePredictsTheForest) {
    // Version 2 takes a refinement indicator from a cell field of the frame before (FORMAT.md
    // 7.6): with the solver's error indicator the forests cost much less than without it.
    const std::vector<Frame> frames = heat_frames(12);
    std::vector<Frame> without = frames;
    for (Frame& f : without) f.fields.clear();
    std::vector<SeriesFrameStats> with_stats, without_stats;
    write_series(frames, {}, &with_stats);
    const std::vector<uint8_t> bytes = write_series(without, {}, &without_stats);
    uint64_t with_indicator = 0, no_indicator = 0;
    for (size_t k = 1; k < frames.size(); ++k) {
        with_indicator += with_stats[k].connectivity_bytes;
        no_indicator += without_stats[k].connectivity_bytes;
    }
    EXPECT_LT(with_indicator * 3, no_indicator * 2) << with_indicator << " vs " << no_indicator;
    SeriesReader reader(bytes);
    for (size_t k = 0; k < frames.size(); ++k) EXPECT_TRUE(identical(reader.frame(k).hierarchy, frames[k].h)) << k;
}

TEST(Series, IndicatorLevelsAreExactEighthsOfAnOctave) {
    // floor(8 log2(x^2 / mean square)) per cell, computed without libm (FORMAT.md 7.6): known
    // answers, the special values, and libm's answer wherever it is not within 1e-9 of a step.
    const Hierarchy h(make_square(1));  // two roots, one cell each
    const std::vector<uint32_t> first_cell = {0, 1};
    auto levels = [&](double a, double b) { return indicator_levels(h, first_cell, {a, b}).levels; };
    EXPECT_EQ(levels(1, 1), (std::vector<int32_t>{0, 0}));
    EXPECT_EQ(levels(2, 0), (std::vector<int32_t>{8, kZeroIndicator}));        // q = 4 / 2, 0
    EXPECT_EQ(levels(1, 3), (std::vector<int32_t>{-19, 6}));                   // 8 log2 0.2 = -18.6, 8 log2 1.8 = 6.8
    EXPECT_EQ(levels(-3, 1), (std::vector<int32_t>{6, -19}));
    EXPECT_EQ(levels(std::nan(""), 1), (std::vector<int32_t>{kZeroIndicator, kZeroIndicator}));  // the mean is NaN
    EXPECT_EQ(levels(1e200, 1e-200), (std::vector<int32_t>{kZeroIndicator, kZeroIndicator}));  // inf / inf, 0 / inf
    std::mt19937_64 rng(8);
    int compared = 0;
    for (int i = 0; i < 2000; ++i) {
        const double a = std::ldexp(double(rng() % 1000000 + 1), int(rng() % 40) - 20), b = double(rng() % 1000 + 1);
        const double q = a * a / ((a * a + b * b) / 2);
        const double exact = 8 * std::log2(q);
        if (std::fabs(exact - std::round(exact)) < 1e-9) continue;
        EXPECT_EQ(levels(a, b)[0], int32_t(std::floor(exact))) << a << " " << b;
        ++compared;
    }
    EXPECT_GT(compared, 1000);
}

TEST(Series, UnchangedFramesCostNextToNothing) {
    const std::vector<Frame> frames = heat_frames(1);
    std::vector<Frame> same = {frames[0], frames[0], frames[0]};
    std::vector<SeriesFrameStats> stats;
    write_series(same, {}, &stats);
    EXPECT_LE(stats[1].connectivity_bytes, 4u);  // the indicator byte and a few bytes of certain symbols
    EXPECT_LE(stats[2].connectivity_bytes, 4u);
    EXPECT_EQ(stats[1].changed_nodes, 0u);
    EXPECT_FALSE(stats[1].moving);
    EXPECT_EQ(stats[1].geometry_bytes, 1u);  // mode 2: the byte of the mode
    // Fields repeated exactly: temporal prediction leaves zeros.
    EXPECT_LT(stats[1].field_bytes * 10, stats[0].field_bytes);
}

TEST(Series, MovingMeshAndEveryFieldType) {
    std::vector<Frame> frames = heat_frames(5, HeatScenario::rotating, 800);
    std::mt19937_64 rng(3);
    for (size_t k = 0; k < frames.size(); ++k) {
        Hierarchy& h = frames[k].h;
        // Move every vertex a little, differently in each frame (a moving mesh).
        for (NodeId n : h.breadth_first_order())
            for (int i = 0; i < 3; ++i) {
                const VertexId v = h.vertex(n, i);
                const Vec3 p = h.position(v);
                h.set_position(v, {p.x + 1e-3 * std::sin(7 * p.y + double(k)), p.y, 0.01 * double(k) * p.x});
            }
        const size_t points = h.vertex_count(), cells = extract_leaf_mesh(h).mesh.triangles.size();
        Field f32{"velocity", FieldAssociation::point, FieldType::float32, 3, {}, {}};
        for (size_t i = 0; i < 3 * points; ++i) f32.values.push_back(double(float(std::cos(0.001 * double(i * (k + 1))))));
        f32.values[0] = std::numeric_limits<double>::quiet_NaN();
        f32.values[1] = -0.0;
        f32.values[2] = std::numeric_limits<double>::infinity();
        Field labels{"material", FieldAssociation::cell, FieldType::int32, 1, {}, {}};
        for (size_t i = 0; i < cells; ++i) labels.integers.push_back(int64_t(rng() % 5) - 2);
        labels.integers[0] = INT32_MIN;
        Field wide{"id", FieldAssociation::point, FieldType::uint64, 1, {}, {}};
        for (size_t i = 0; i < points; ++i) wide.integers.push_back(int64_t(rng()));
        frames[k].fields.push_back(f32);
        frames[k].fields.push_back(labels);
        frames[k].fields.push_back(wide);
    }
    std::vector<SeriesFrameStats> stats;
    const std::vector<uint8_t> bytes = write_series(frames, {}, &stats);
    EXPECT_TRUE(stats[1].moving);
    SeriesReader reader(bytes);
    for (size_t k = 0; k < frames.size(); ++k) {
        const SeriesFrame f = reader.frame(k);
        EXPECT_TRUE(identical(f.hierarchy, frames[k].h)) << k;
        expect_same_fields(f.fields, frames[k].fields, k);
    }
}

TEST(Series, ErrorBoundedFieldsStayWithinTheBound) {
    const std::vector<Frame> frames = heat_frames(6);
    for (double bound : {1e-2, 1e-5}) {
        SeriesOptions options;
        options.error_bound = bound;
        options.field_bounds = {{"error_indicator", 0.0}};  // this one bit-exact
        std::vector<SeriesFrameStats> stats;
        const std::vector<uint8_t> bytes = write_series(frames, options, &stats);
        SeriesReader reader(bytes);
        for (size_t k = 0; k < frames.size(); ++k) {
            const SeriesFrame f = reader.frame(k);
            EXPECT_TRUE(identical(f.hierarchy, frames[k].h));
            ASSERT_EQ(f.fields.size(), frames[k].fields.size());
            double worst = 0;
            for (size_t i = 0; i < f.fields.size(); ++i) {
                const double e = max_abs_difference(f.fields[i], frames[k].fields[i]);
                EXPECT_LE(e, bound) << f.fields[i].name;
                worst = std::max(worst, e);
                if (f.fields[i].name == "error_indicator" || f.fields[i].name == "level") {
                    EXPECT_TRUE(identical(f.fields[i], frames[k].fields[i]));
                }
            }
            EXPECT_EQ(worst, stats[k].max_error);
            EXPECT_GT(worst, 0);
        }
    }
}

TEST(Series, RefusesFramesOverAnotherBaseAndBadFields) {
    const std::vector<Frame> frames = heat_frames(1);
    SeriesWriter writer(frames[0].h.base());
    Hierarchy other(make_square(3));
    EXPECT_THROW(writer.add_frame(other, 0), Error);
    Field short_field{"t", FieldAssociation::point, FieldType::float64, 1, {1.0, 2.0}, {}};
    EXPECT_THROW(writer.add_frame(frames[0].h, 0, {short_field}), Error);
    Field out_of_range{"l", FieldAssociation::cell, FieldType::uint8, 1, {}, {}};
    out_of_range.integers.assign(extract_leaf_mesh(frames[0].h).mesh.triangles.size(), 300);
    EXPECT_THROW(writer.add_frame(frames[0].h, 0, {out_of_range}), Error);
    EXPECT_EQ(writer.frame_count(), 0u);
    writer.add_frame(frames[0].h, 0, frames[0].fields);  // and the writer still works
    EXPECT_EQ(writer.frame_count(), 1u);
}

std::vector<uint8_t> small_series(size_t* frame_end = nullptr) {
    std::vector<Frame> frames = heat_frames(4, HeatScenario::lshape, 300);
    SeriesOptions options;
    options.keyframe_interval = 3;
    SeriesWriter writer(frames[0].h.base(), options);
    for (const Frame& f : frames) writer.add_frame(f.h, f.time, f.fields);
    if (frame_end) *frame_end = writer.bytes().size();
    writer.close();
    return writer.bytes();
}

TEST(Series, EveryTruncationIsRefusedOrReadsTheCompleteFrames) {
    size_t frames_end = 0;
    const std::vector<uint8_t> bytes = small_series(&frames_end);
    SeriesReader whole(bytes);
    const size_t frames = whole.frame_count();
    for (size_t cut = 0; cut < bytes.size(); ++cut) {
        std::vector<uint8_t> part(bytes.begin(), bytes.begin() + long(cut));
        try {
            SeriesReader r(part);
            ADD_FAILURE() << "a file cut at " << cut << " was accepted";
        } catch (const Error& e) {
            EXPECT_TRUE(e.code() == ErrorCode::truncated || e.code() == ErrorCode::bad_magic) << cut << ": " << e.what();
        }
        SeriesReadOptions partial;
        partial.allow_unfinished = true;
        if (cut % 23 != 0 && cut != frames_end) continue;  // decoding every cut would take long
        try {
            SeriesReader r(part, "series", partial);
            for (size_t k = 0; k < r.frame_count(); ++k)
                EXPECT_TRUE(identical(r.frame(k).hierarchy, whole.frame(k).hierarchy)) << cut;
            EXPECT_LE(r.frame_count(), frames);
            if (cut == frames_end) {
                EXPECT_EQ(r.frame_count(), frames);
            }
        } catch (const Error& e) {
            EXPECT_EQ(e.code() == ErrorCode::truncated || e.code() == ErrorCode::bad_magic, true) << e.what();
        }
    }
}

TEST(Series, CorruptedFilesAreRefusedWithClearErrors) {
    const std::vector<uint8_t> bytes = small_series();
    std::mt19937 rng(9);
    int refused = 0;
    for (int trial = 0; trial < 400; ++trial) {
        std::vector<uint8_t> bad = bytes;
        bad[rng() % bad.size()] ^= uint8_t(1u << (rng() % 8));
        try {
            SeriesReader r(bad);
            for (size_t k = 0; k < r.frame_count(); ++k) r.frame(k);
        } catch (const Error& e) {
            ++refused;
            EXPECT_NE(std::string(e.what()).find("series"), std::string::npos) << e.what();
        }
    }
    EXPECT_EQ(refused, 400);  // every flip breaks a checksum
    std::vector<uint8_t> newer = bytes;
    newer[4] = kNewestSeriesVersion + 1;
    try {
        SeriesReader r(newer);
        FAIL();
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), ErrorCode::unsupported_version);
    }
}

// The header's and every block's XXH32 recomputed, as far as the framing can be walked: lets a
// mutated file past the checksums into the payload decoders.
void fix_checksums(std::vector<uint8_t>& b) {
    auto get32 = [&](size_t at) { return uint32_t(b[at]) | uint32_t(b[at + 1]) << 8 | uint32_t(b[at + 2]) << 16 | uint32_t(b[at + 3]) << 24; };
    auto put32 = [&](size_t at, uint32_t v) {
        for (int i = 0; i < 4; ++i) b[at + size_t(i)] = uint8_t(v >> (8 * i));
    };
    if (b.size() < 16) return;
    put32(12, XXH32(b.data(), 12, 0));
    for (size_t pos = 16; b.size() - pos >= 9;) {
        const uint32_t length = get32(pos + 1);
        if (length > b.size() - pos - 9) return;
        put32(pos + 5 + length, XXH32(b.data() + pos, 5 + size_t(length), 0));
        pos += 9 + size_t(length);
    }
}

// Fuzz-style robustness of every payload decoder (base mesh, frame header, inter-frame forest,
// positions, fields): mutations behind valid checksums either decode or are refused with an
// amc::Error naming the series; never a crash, another exception or a huge allocation (ASan, in CI).
TEST(Series, MutatedPayloadsBehindValidChecksumsAreRefusedOrDecode) {
    const std::vector<uint8_t> bytes = small_series();
    std::mt19937 rng(26);
    int refused = 0, decoded = 0;
    SeriesReadOptions options;
    options.max_nodes = 1u << 20;
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
            SeriesReader r(bad, "series", options);
            for (size_t k = 0; k < r.frame_count(); ++k) r.frame(k);
            ++decoded;
        } catch (const Error& e) {
            ++refused;
            EXPECT_NE(std::string(e.what()).find("series"), std::string::npos) << e.what();
        }
    }
    EXPECT_GT(refused, 1000);  // most mutations break the structure the payloads must have
    std::printf("mutated payloads: %d refused, %d decoded\n", refused, decoded);
}

std::string temp_path(const std::string& name) {
    return (std::filesystem::temp_directory_path() / (name + "_" + std::to_string(getpid()))).string();
}

TEST(Series, WriterKilledMidFrameLeavesEveryCompleteFrame) {
    const std::vector<Frame> frames = heat_frames(12, HeatScenario::rotating, 1500);
    const std::string path = temp_path("amc_series_kill.amcs");
    const std::string progress = path + ".count";
    std::filesystem::remove(path);
    std::filesystem::remove(progress);
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
        // The simulation's writer: appends frames for ever (frame k again and again) until killed.
        SeriesWriter writer(path, frames[0].h.base());
        for (size_t k = 0;; ++k) {
            writer.add_frame(frames[k % frames.size()].h, double(k), frames[k % frames.size()].fields);
            std::ofstream(progress) << k + 1;
        }
    }
    // Kill it once it has written some frames, at whatever point of a frame it is.
    for (int i = 0; i < 2000; ++i) {
        std::ifstream in(progress);
        size_t written = 0;
        if (in >> written && written >= 20) break;
        usleep(5000);
    }
    kill(child, SIGKILL);
    int status = 0;
    waitpid(child, &status, 0);
    EXPECT_THROW(SeriesReader::open(path), Error);  // unfinished: refused by default
    SeriesReadOptions partial;
    partial.allow_unfinished = true;
    SeriesReader reader = SeriesReader::open(path, partial);
    EXPECT_GE(reader.frame_count(), 20u);
    EXPECT_FALSE(reader.finished());
    for (size_t k = 0; k < reader.frame_count(); ++k) {
        const SeriesFrame f = reader.frame(k);
        const Frame& expected = frames[k % frames.size()];
        ASSERT_TRUE(identical(f.hierarchy, expected.h)) << k;
        expect_same_fields(f.fields, expected.fields, k);
    }
    // A cut inside the last frame, exactly: the frames before it read back.
    std::vector<uint8_t> bytes;
    {
        std::ifstream in(path, std::ios::binary);
        bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    }
    const SeriesFrameInfo last = reader.info(reader.frame_count() - 1);
    bytes.resize(size_t(last.offset + last.size / 2));
    SeriesReader cut(bytes, "cut", partial);
    EXPECT_EQ(cut.frame_count(), reader.frame_count() - 1);
    EXPECT_GT(cut.ignored_bytes(), 0u);
    std::filesystem::remove(path);
    std::filesystem::remove(progress);
}

}  // namespace
}  // namespace amc
