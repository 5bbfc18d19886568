// Series of quadtree/octree forests (include/amc/series.h, docs/FORMAT.md 7.10-7.12): the series
// file's framing with a coarse mesh of trees as the base; each frame's forest coded against the
// previous frame's (forest_connectivity.h), its leaf fields against the previous frame's or the
// leaf before (forest_fields.h).
#include <amc/series.h>

#include "common/check.h"
#include "common/file_io.h"
#include "octree/octree_file.h"
#include "octree/octree_leaf_data.h"
#include "series/forest_connectivity.h"
#include "series/forest_fields.h"
#include "series/series_format.h"
#include "series/series_framing.h"

#include <cerrno>
#include <cmath>
#include <cstring>
#include <iterator>

namespace amc {

namespace {

constexpr uint64_t kMaxLeafValues = uint64_t{1} << 28;  // per frame, as OctreeDecodeOptions

std::vector<uint8_t> forest_base_payload(const TreeConnectivity& conn) {
    std::vector<uint8_t> out;
    out.push_back(uint8_t(conn.dim));
    put_varint(out, conn.tree_count());
    const std::vector<uint8_t> block = write_octree_connectivity(conn);
    out.insert(out.end(), block.begin(), block.end());
    return out;
}

// `file_bytes`: the file's blocks after its header (the complete ones).
TreeConnectivity read_forest_base(const uint8_t* data, size_t size, const SeriesReadOptions& options, uint64_t file_bytes) {
    PayloadReader in(data, size, "forest base block");
    const int dim = in.u8();
    AMC_REQUIRE(dim == 2 || dim == 3, corrupt, "forest base block: dimension " + std::to_string(dim));
    const uint64_t trees = in.varint();
    AMC_REQUIRE(trees >= 1, corrupt, "forest base block: no trees");
    AMC_REQUIRE(trees <= options.max_nodes, limit_exceeded,
                "forest base block: " + std::to_string(trees) + " trees, more than the octant limit (" +
                    std::to_string(options.max_nodes) + ")");
    // A brick's trees cost no bits: bounded by the file's bytes, as octants are (FORMAT.md 7.10).
    check_nodes_per_byte(trees, file_bytes, options.max_nodes_per_byte, "trees");
    // The .amq connectivity block (FORMAT.md 8.3) as version 2 reads it.
    return read_octree_connectivity(in.rest(), in.remaining(), dim, trees, kOctreeLeafDataVersion);
}

bool same_connectivity(const TreeConnectivity& x, const TreeConnectivity& y) {
    return x.dim == y.dim && x.vertices == y.vertices && x.tree_to_vertex == y.tree_to_vertex && x.tree_to_tree == y.tree_to_tree &&
           x.tree_to_face == y.tree_to_face;
}

struct ForestFrameHeader {
    double time = 0;
    uint64_t octants = 0, leaves = 0, levels = 0;
};

ForestFrameHeader read_forest_frame_header(PayloadReader& in, const TreeConnectivity& conn) {
    ForestFrameHeader h;
    h.time = in.f64();
    h.octants = in.varint();
    h.leaves = in.varint();
    h.levels = in.varint();
    const uint64_t trees = conn.tree_count(), children = uint64_t(1) << conn.dim;
    // Every refinement adds 2^dim octants and 2^dim - 1 leaves.
    const bool counts = h.octants >= trees && (h.octants - trees) % children == 0 &&
                        h.leaves == trees + (h.octants - trees) / children * (children - 1);
    AMC_REQUIRE(counts && h.levels >= 1 && h.levels <= uint64_t(octree_max_level(conn.dim)) + 1 &&
                    (h.levels == 1) == (h.octants == trees),
                corrupt, "inconsistent counts in the frame header");
    return h;
}

// What both sides keep of the frame before.
struct ForestState {
    OctreeForest forest;  // with its fields
    std::unique_ptr<OctreeLevels> levels;
    ForestConnectivityModels models;
};

struct CodedForestFrame {
    std::vector<uint8_t> block;
    ForestSeriesFrameStats stats;
    std::unique_ptr<OctreeLevels> levels;
    ForestConnectivityModels models;
};

CodedForestFrame code_forest_frame(const ForestState* ref, const OctreeForest& forest, double time) {
    CodedForestFrame coded;
    ForestSeriesFrameStats& stats = coded.stats;
    stats.keyframe = ref == nullptr;
    if (ref) coded.models = ref->models;
    std::vector<uint8_t> connectivity;
    coded.levels.reset(new OctreeLevels(encode_forest_connectivity(ref ? ref->levels.get() : nullptr, forest, coded.models, connectivity)));
    std::vector<uint8_t> head;
    put_f64(head, time);
    stats.octants = coded.levels->octant_count();
    stats.leaves = forest.leaves.size();
    put_varint(head, stats.octants);
    put_varint(head, stats.leaves);
    put_varint(head, uint64_t(coded.levels->depth() + 1));
    std::vector<uint8_t> payload;  // after the connectivity section
    put_varint(payload, forest.leaf_data.size());
    const size_t fields_start = payload.size();
    const ForestFieldFrame frame(ref ? &ref->forest : nullptr, forest);
    for (const Field& field : forest.leaf_data) {
        const size_t before = payload.size();
        encode_forest_field(field, frame, payload);
        stats.fields.push_back({field.name, payload.size() - before, false, 0});
    }
    stats.field_bytes = payload.size() - fields_start;
    payload = padded_frame_payload(head, connectivity, payload, stats.octants);
    stats.connectivity_bytes = connectivity.size();
    coded.block = series_block(uint8_t(ref ? SeriesBlock::forest_frame : SeriesBlock::forest_keyframe), payload);
    stats.bytes = coded.block.size();
    return coded;
}

}  // namespace

// ---- writer ----------------------------------------------------------------------------------

struct ForestSeriesWriter::State {
    TreeConnectivity conn;
    ForestState prev;
};

ForestSeriesWriter::ForestSeriesWriter(const TreeConnectivity& conn, const SeriesOptions& options)
    : state_(new State), options_(options) {
    validate_connectivity(conn, "forest series connectivity");
    AMC_REQUIRE(options.error_bound == 0 && options.field_bounds.empty(), invalid_input,
                "forest series: leaf fields are coded bit-exact (no error bounds)");
    state_->conn = conn;
    bytes_ = series_header(kForestSeriesVersion, 0, options.keyframe_interval);
    const std::vector<uint8_t> b = series_block(uint8_t(SeriesBlock::forest_base), forest_base_payload(conn));
    bytes_.insert(bytes_.end(), b.begin(), b.end());
}

ForestSeriesWriter::ForestSeriesWriter(const std::string& path, const TreeConnectivity& conn, const SeriesOptions& options)
    : ForestSeriesWriter(conn, options) {
    path_ = path;
    file_ = std::fopen(path.c_str(), "wb");
    AMC_REQUIRE(file_ != nullptr, io, path + ": can not open for writing: " + std::strerror(errno));
    std::vector<uint8_t> start;
    start.swap(bytes_);
    write(start);
}

ForestSeriesWriter::~ForestSeriesWriter() {
    if (file_) std::fclose(file_);
}

void ForestSeriesWriter::write(const std::vector<uint8_t>& data) {
    if (!file_) {
        bytes_.insert(bytes_.end(), data.begin(), data.end());
        return;
    }
    const bool ok = std::fwrite(data.data(), 1, data.size(), file_) == data.size() && std::fflush(file_) == 0;
    AMC_REQUIRE(ok, io, path_ + ": write failed: " + std::strerror(errno));
}

ForestSeriesFrameStats ForestSeriesWriter::add_frame(const OctreeForest& forest, double time) {
    AMC_REQUIRE(!closed_, invalid_input, "forest series: add_frame after close");
    const std::string what = "forest series frame " + std::to_string(frames_);
    validate_octree_forest(forest, what);
    AMC_REQUIRE(same_connectivity(forest.connectivity, state_->conn), invalid_input, what + ": not over the series' connectivity");
    validate_leaf_fields(forest.leaf_data, forest.leaves.size(), what);
    AMC_REQUIRE(forest.leaf_data.size() <= kMaxSeriesFields, invalid_input, what + ": more than 4096 fields");
    const bool keyframe = frames_ == 0 || (options_.keyframe_interval && frames_ % options_.keyframe_interval == 0);
    CodedForestFrame coded = code_forest_frame(keyframe ? nullptr : &state_->prev, forest, time);
    // An encoder-chosen keyframe when the frame is smaller alone (FORMAT.md 7.12).
    if (!keyframe && options_.choose_keyframes) {
        CodedForestFrame alone = code_forest_frame(nullptr, forest, time);
        if (alone.block.size() < coded.block.size()) coded = std::move(alone);
    }
    coded.stats.changed_octants =
        frames_ == 0 ? coded.levels->octant_count() - forest.tree_count() : changed_octants(*state_->prev.levels, *coded.levels);
    write(coded.block);
    state_->prev.forest = forest;
    state_->prev.levels = std::move(coded.levels);
    state_->prev.models = std::move(coded.models);
    ++frames_;
    return coded.stats;
}

void ForestSeriesWriter::close() {
    if (closed_) return;
    write(series_block(uint8_t(SeriesBlock::end), {}));
    closed_ = true;
    if (file_) {
        const bool ok = std::fclose(file_) == 0;
        file_ = nullptr;
        AMC_REQUIRE(ok, io, path_ + ": close failed: " + std::strerror(errno));
    }
}

// ---- reader ----------------------------------------------------------------------------------

struct ForestSeriesReader::State {
    TreeConnectivity conn;
    ForestState current;
    long long current_index = -1;
};

bool is_forest_series(const std::vector<uint8_t>& bytes) {
    return bytes.size() > kSeriesHeaderSize && std::memcmp(bytes.data(), kSeriesMagic, 4) == 0 &&
           bytes[kSeriesHeaderSize] == uint8_t(SeriesBlock::forest_base);
}

ForestSeriesReader::ForestSeriesReader(std::vector<uint8_t> bytes, const std::string& what, const SeriesReadOptions& options)
    : bytes_(std::move(bytes)), what_(what), options_(options), state_(new State) {
    const SeriesScan scan = scan_series_file(bytes_, what, options.allow_unfinished, 0, uint8_t(SeriesBlock::forest_frame));
    version_ = scan.version;
    keyframe_interval_ = scan.keyframe_interval;
    finished_ = scan.finished;
    ignored_ = scan.ignored;
    for (const SeriesBlockView& b : scan.blocks) {
        const SeriesBlock kind = SeriesBlock(b.type);
        if (&b == &scan.blocks.front()) {
            AMC_REQUIRE(kind != SeriesBlock::base, corrupt, what + ": a series of triangle meshes (read it with SeriesReader)");
            AMC_REQUIRE(kind == SeriesBlock::forest_base, corrupt, what + ": the first block is not the forest base block");
            AMC_REQUIRE(version_ >= kForestSeriesVersion, corrupt,
                        what + ": forest blocks in a file of version " + std::to_string(version_) + " (they came with version 3)");
            try {
                state_->conn = read_forest_base(b.payload, b.length, options, bytes_.size() - kSeriesHeaderSize - scan.ignored);
            } catch (const Error& e) {
                throw e.prefixed(what);
            }
            continue;
        }
        AMC_REQUIRE(kind == SeriesBlock::forest_keyframe || kind == SeriesBlock::forest_frame, corrupt,
                    what + ": a block of type " + std::to_string(b.type) + " at byte " + std::to_string(b.offset) +
                        " in a forest series");
        AMC_REQUIRE(kind == SeriesBlock::forest_keyframe || !frames_.empty(), corrupt, what + ": frame 0 is not a keyframe");
        const std::string frame_what = what + ": frame " + std::to_string(frames_.size());
        ForestFrameHeader fh;
        try {
            PayloadReader in(b.payload, b.length, "frame header");
            fh = read_forest_frame_header(in, state_->conn);
        } catch (const Error& e) {
            throw e.prefixed(frame_what);
        }
        ForestSeriesFrameInfo info;
        info.offset = b.offset;
        info.size = b.length + kSeriesBlockOverhead;
        info.keyframe = kind == SeriesBlock::forest_keyframe;
        info.time = fh.time;
        info.octants = fh.octants;
        info.leaves = fh.leaves;
        info.levels = int(fh.levels);
        frames_.push_back(info);
    }
}

ForestSeriesReader ForestSeriesReader::open(const std::string& path, const SeriesReadOptions& options) {
    const std::string text = read_whole_file(path, [&](const std::string& first) {  // a file of something else: at once
        check_series_header(reinterpret_cast<const uint8_t*>(first.data()), first.size(), path, 0);
    });
    return ForestSeriesReader(std::vector<uint8_t>(text.begin(), text.end()), path, options);
}

ForestSeriesReader::~ForestSeriesReader() = default;
ForestSeriesReader::ForestSeriesReader(ForestSeriesReader&&) noexcept = default;

const TreeConnectivity& ForestSeriesReader::connectivity() const { return state_->conn; }

void ForestSeriesReader::decode_next(size_t k) {
    const ForestSeriesFrameInfo& info = frames_[k];
    const std::string what = what_ + ": frame " + std::to_string(k);
    const ForestState* ref = info.keyframe ? nullptr : &state_->current;
    try {
        PayloadReader in(bytes_.data() + info.offset + 5, info.size - kSeriesBlockOverhead, "frame");
        const ForestFrameHeader fh = read_forest_frame_header(in, state_->conn);
        check_frame_nodes(fh.octants, info.size, options_.max_nodes, options_.max_nodes_per_byte, "octants");
        const uint64_t length = in.varint();
        AMC_REQUIRE(length <= in.remaining(), truncated, "connectivity longer than the frame");
        const uint8_t* connectivity = in.bytes(length);
        ForestState next;
        if (ref) next.models = ref->models;
        next.levels.reset(new OctreeLevels(decode_forest_connectivity(state_->conn, ref ? ref->levels.get() : nullptr, next.models,
                                                                       connectivity, size_t(length), fh.octants)));
        AMC_REQUIRE(uint64_t(next.levels->depth() + 1) == fh.levels, corrupt, "the forest does not match the frame header's levels");
        next.forest = next.levels->leaves(state_->conn);
        const uint64_t field_count = in.varint();
        AMC_REQUIRE(field_count <= kMaxSeriesFields, corrupt, std::to_string(field_count) + " fields (at most 4096)");
        const ForestFieldFrame frame(ref ? &ref->forest : nullptr, next.forest);
        uint64_t values = 0;
        std::vector<Field> fields;
        for (uint64_t i = 0; i < field_count; ++i) {
            Field f = decode_forest_field(in, frame, kMaxLeafValues - values);
            values += f.value_count();
            for (const Field& g : fields)
                AMC_REQUIRE(g.name != f.name, corrupt, "two fields named \"" + f.name + "\"");
            fields.push_back(std::move(f));
        }
        AMC_REQUIRE(in.remaining() == 0, corrupt, "bytes after the last field");
        next.forest.leaf_data = std::move(fields);
        state_->current = std::move(next);
        state_->current_index = (long long)k;
    } catch (const Error& e) {
        state_->current_index = -1;
        throw e.prefixed(what);
    }
}

ForestSeriesFrame ForestSeriesReader::frame(size_t k) {
    if (k >= frames_.size())
        throw std::out_of_range("forest series frame " + std::to_string(k) + " of " + std::to_string(frames_.size()));
    for (size_t i = first_frame_to_decode(frames_, k, state_->current_index); i <= k; ++i) decode_next(i);
    return {state_->current.forest, frames_[k].time};
}

}  // namespace amc
