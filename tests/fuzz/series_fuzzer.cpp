// Fuzz targets of the series file (.amcs): the triangle series reader (framing, base mesh, every
// frame: forest against the previous frame, positions, fields) and the forest series reader
// (coarse mesh of trees, every frame's octree forest against the previous one, leaf fields), on the
// input as it is and with its checksums made valid; what they decode is written again and reads
// back the same.
#include "fuzz_targets.h"

#include <amc/octree.h>
#include <amc/series.h>

#include <algorithm>
#include <cstring>
#include <memory>

namespace amc::fuzz {
namespace {

constexpr uint64_t kMaxNodes = uint64_t(1) << 16;  // per frame: keeps runs short
constexpr size_t kMaxFrames = 16;                  // decoded per input

void read_series(const uint8_t* data, size_t size) {
    SeriesReadOptions options;
    options.allow_unfinished = size % 2 == 0;
    options.max_nodes = kMaxNodes;
    std::vector<SeriesFrame> frames;
    std::unique_ptr<SeriesReader> reader;
    try {
        reader = std::make_unique<SeriesReader>(std::vector<uint8_t>(data, data + size), "input", options);
        const size_t count = std::min(reader->frame_count(), kMaxFrames);
        for (size_t k = 0; k < count; ++k) frames.push_back(reader->frame(k));
        // Random access: the last frame read again, from its keyframe.
        if (count > 1) FUZZ_CHECK(identical(reader->frame(count - 1).hierarchy, frames.back().hierarchy));
    } catch (const Error&) {
        return;
    }
    for (const SeriesFrame& f : frames) FUZZ_CHECK(check_invariants(f.hierarchy).empty());
    // What the reader accepts the writer accepts, and the file it writes (lossless) reads back the same.
    SeriesWriter writer(reader->base());
    for (const SeriesFrame& f : frames) writer.add_frame(f.hierarchy, f.time, f.fields);  // throws: a finding
    writer.close();
    SeriesReader again(writer.bytes(), "written");
    FUZZ_CHECK(again.frame_count() == frames.size());
    for (size_t k = 0; k < frames.size(); ++k) {
        const SeriesFrame f = again.frame(k);
        FUZZ_CHECK(identical(f.hierarchy, frames[k].hierarchy));
        FUZZ_CHECK(std::memcmp(&f.time, &frames[k].time, sizeof f.time) == 0);
        FUZZ_CHECK(f.fields.size() == frames[k].fields.size());
        for (size_t i = 0; i < f.fields.size(); ++i) FUZZ_CHECK(identical(f.fields[i], frames[k].fields[i]));
    }
}

void read_forest_series(const uint8_t* data, size_t size) {
    SeriesReadOptions options;
    options.allow_unfinished = size % 2 == 0;
    options.max_nodes = kMaxNodes;
    std::vector<ForestSeriesFrame> frames;
    std::unique_ptr<ForestSeriesReader> reader;
    try {
        reader = std::make_unique<ForestSeriesReader>(std::vector<uint8_t>(data, data + size), "input", options);
        const size_t count = std::min(reader->frame_count(), kMaxFrames);
        for (size_t k = 0; k < count; ++k) frames.push_back(reader->frame(k));
        // Random access: the last frame read again, from its keyframe.
        if (count > 1) FUZZ_CHECK(reader->frame(count - 1).forest == frames.back().forest);
    } catch (const Error&) {
        return;
    }
    for (const ForestSeriesFrame& f : frames) {
        validate_octree_forest(f.forest, "decoded frame");  // throws: a finding
        const TreeConnectivity &a = f.forest.connectivity, &b = reader->connectivity();
        FUZZ_CHECK(a.dim == b.dim && a.vertices == b.vertices && a.tree_to_vertex == b.tree_to_vertex &&
                   a.tree_to_tree == b.tree_to_tree && a.tree_to_face == b.tree_to_face);
    }
    // What the reader accepts the writer accepts, and the file it writes reads back the same.
    ForestSeriesWriter writer(reader->connectivity());
    for (const ForestSeriesFrame& f : frames) writer.add_frame(f.forest, f.time);  // throws: a finding
    writer.close();
    ForestSeriesReader again(writer.bytes(), "written");
    FUZZ_CHECK(again.frame_count() == frames.size());
    for (size_t k = 0; k < frames.size(); ++k) {
        const ForestSeriesFrame f = again.frame(k);
        FUZZ_CHECK(f.forest == frames[k].forest);
        FUZZ_CHECK(std::memcmp(&f.time, &frames[k].time, sizeof f.time) == 0);
    }
}

}  // namespace

void forest_series_read(const uint8_t* data, size_t size) {
    read_forest_series(data, size);
    const std::vector<uint8_t> repaired = with_valid_checksums(data, size, kSeriesHeaderSize);
    if (!std::equal(repaired.begin(), repaired.end(), data)) read_forest_series(repaired.data(), repaired.size());
}

void series_read(const uint8_t* data, size_t size) {
    read_series(data, size);
    const std::vector<uint8_t> repaired = with_valid_checksums(data, size, kSeriesHeaderSize);
    if (!std::equal(repaired.begin(), repaired.end(), data)) read_series(repaired.data(), repaired.size());
}

}  // namespace amc::fuzz
