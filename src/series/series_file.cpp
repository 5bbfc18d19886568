// The series file: framing, SeriesWriter and SeriesReader (include/amc/series.h, docs/FORMAT.md
// section 7). A frame is coded by code_frame / decode_frame against the state of the frame before
// it (or the unrefined base for a keyframe).
#include <amc/hierarchy_coder.h>
#include <amc/series.h>

#include "coding/container.h"
#include "common/check.h"
#include "common/file_io.h"
#include "common/little_endian.h"
#include "series/field_coder.h"
#include "series/frame_connectivity.h"
#include "series/frame_geometry.h"
#include "series/frame_state.h"
#include "series/series_format.h"
#include "series/series_framing.h"

#include <cmath>
#include <iterator>

namespace amc {

namespace {


std::vector<uint8_t> block(SeriesBlock type, const std::vector<uint8_t>& payload) {
    return series_block(uint8_t(type), payload);
}

std::vector<uint8_t> base_payload(const TriangleMesh& base) {
    std::vector<uint8_t> out;
    put_varint(out, base.positions.size());
    put_varint(out, base.triangles.size());
    for (const Triangle& t : base.triangles)
        for (uint32_t v : t) put_varint(out, v);
    for (const Vec3& p : base.positions)
        for (double x : {p.x, p.y, p.z}) {
            if (base.single_precision) {
                append_le32(out, bit_cast<uint32_t>(float(x)));
            } else {
                put_f64(out, x);
            }
        }
    return out;
}

TriangleMesh read_base(const uint8_t* data, size_t size, bool single_precision, const std::string& what) {
    PayloadReader in(data, size, "base mesh block");
    TriangleMesh base;
    base.single_precision = single_precision;
    const uint64_t vertices = in.varint(), triangles = in.varint();
    const size_t coordinate = single_precision ? 4 : 8;
    AMC_REQUIRE(triangles >= 1 && triangles <= in.remaining() / 3 && vertices <= in.remaining() / (3 * coordinate),
                corrupt, what + ": base mesh block: " + std::to_string(vertices) + " vertices and " +
                             std::to_string(triangles) + " triangles can not fit in the block");
    base.triangles.resize(size_t(triangles));
    for (Triangle& t : base.triangles)
        for (uint32_t& v : t) {
            const uint64_t index = in.varint();
            AMC_REQUIRE(index < vertices, corrupt, what + ": base mesh block: vertex index out of range");
            v = uint32_t(index);
        }
    AMC_REQUIRE(in.remaining() == vertices * 3 * coordinate, corrupt,
                what + ": base mesh block: its size does not match its counts");
    base.positions.resize(size_t(vertices));
    const uint8_t* p = in.rest();
    for (Vec3& v : base.positions) {
        double xyz[3];
        for (double& x : xyz) {
            if (single_precision) {
                x = bit_cast<float>(load_le32(p));
                p += 4;
            } else {
                x = bit_cast<double>(load_le64(p));
                p += 8;
            }
        }
        v = {xyz[0], xyz[1], xyz[2]};
    }
    try {
        validate_triangle_mesh(base, what + ": base mesh");
    } catch (const Error& e) {
        throw Error(ErrorCode::corrupt, e.what());
    }
    return base;
}

uint64_t zigzag(int32_t v) { return v < 0 ? 2 * uint64_t(-int64_t(v)) - 1 : 2 * uint64_t(v); }
int32_t unzigzag(uint64_t z) { return z & 1 ? int32_t(-int64_t((z + 1) / 2)) : int32_t(z / 2); }

// A field of the reference that may serve as the refinement indicator (FORMAT.md 7.6).
bool is_indicator_candidate(const Field& f) {
    return f.association == FieldAssociation::cell && is_float_type(f.type) && f.components == 1;
}

uint64_t face_count(const Hierarchy& h) {
    uint64_t faces = 0;
    for (NodeId n : h.leaves()) faces += 1 + uint64_t(h.hanging_node_count(n));
    return faces;
}

// Frame header fields (FORMAT.md 7.4).
struct FrameHeader {
    double time = 0;
    uint64_t nodes = 0, vertices = 0, faces = 0, levels = 0;
};

FrameHeader read_frame_header(PayloadReader& in, uint64_t base_vertices, uint64_t base_triangles,
                              const std::string& what) {
    FrameHeader f;
    f.time = in.f64();
    f.nodes = in.varint();
    f.vertices = in.varint();
    f.faces = in.varint();
    f.levels = in.varint();
    AMC_REQUIRE(f.nodes >= base_triangles && (f.nodes - base_triangles) % 4 == 0 && f.vertices >= base_vertices &&
                    f.vertices <= 3 * f.nodes + base_vertices && f.faces >= base_triangles && f.faces <= 3 * f.nodes &&
                    f.levels >= 1 && f.levels <= uint64_t(kMaxLevel) + 1,
                corrupt, what + ": inconsistent counts in the frame header");
    return f;
}

}  // namespace

// ---- writer ----------------------------------------------------------------------------------

struct SeriesWriter::State {
    TriangleMesh base;
    FrameState prev;
};

SeriesWriter::SeriesWriter(const TriangleMesh& base, const SeriesOptions& options)
    : state_(new State), options_(options) {
    validate_triangle_mesh(base, "series base mesh");
    state_->base = base;
    AMC_REQUIRE(options.error_bound >= 0 && std::isfinite(options.error_bound), invalid_input,
                "series: the error bound must be finite and >= 0");
    for (const auto& field_bound : options.field_bounds) {
        const std::string& name = field_bound.first;  // not a structured binding: lambdas cannot capture one in C++17
        AMC_REQUIRE(field_bound.second >= 0 && std::isfinite(field_bound.second), invalid_input,
                    "series: the error bound of field \"" + name + "\" must be finite and >= 0");
    }
    std::vector<uint8_t> start = series_header(kSeriesVersion, base.single_precision ? kSeriesFlagSinglePrecision : 0, options.keyframe_interval);
    const std::vector<uint8_t> b = block(SeriesBlock::base, base_payload(base));
    start.insert(start.end(), b.begin(), b.end());
    bytes_ = std::move(start);
}

SeriesWriter::SeriesWriter(const std::string& path, const TriangleMesh& base, const SeriesOptions& options)
    : SeriesWriter(base, options) {
    path_ = path;
    file_ = std::fopen(path.c_str(), "wb");
    AMC_REQUIRE(file_ != nullptr, io, path + ": can not open for writing: " + std::strerror(errno));
    std::vector<uint8_t> start;
    start.swap(bytes_);
    write(start);
}

SeriesWriter::~SeriesWriter() {
    if (file_) std::fclose(file_);
}

void SeriesWriter::write(const std::vector<uint8_t>& data) {
    if (!file_) {
        bytes_.insert(bytes_.end(), data.begin(), data.end());
        return;
    }
    const bool ok = std::fwrite(data.data(), 1, data.size(), file_) == data.size() && std::fflush(file_) == 0;
    AMC_REQUIRE(ok, io, path_ + ": write failed: " + std::strerror(errno));
}

namespace {

// One frame coded against `ref` (the unrefined base for a keyframe): its block and the state the
// decoder will hold after it.
struct CodedFrame {
    std::vector<uint8_t> block;
    FrameState next;
    SeriesFrameStats stats;
};

CodedFrame code_frame(const TriangleMesh& base, const SeriesOptions& options, const FrameState& ref, bool keyframe,
                      const Hierarchy& h, double time, const std::vector<Field>& fields) {
    CodedFrame coded;
    SeriesFrameStats& stats = coded.stats;
    FrameState& next = coded.next;
    stats.keyframe = keyframe;
    Counterparts cp;
    std::vector<uint8_t> connectivity;
    if (keyframe) {
        connectivity = encode_hierarchy(h);
        next.h = decode_hierarchy(base, connectivity.data(), connectivity.size());
        cp = match_nodes(ref.h, next.h);
    } else {
        // The indicator: none, or the reference's scalar float cell field that codes the forest
        // in the fewest bytes, with the thresholds that mispredict fewest nodes (FORMAT.md 7.9).
        const Counterparts matched = match_nodes(ref.h, h);
        for (size_t choice = 0; choice <= ref.fields.size(); ++choice) {
            if (choice > 0 && !is_indicator_candidate(ref.fields[choice - 1])) continue;
            Indicator indicator;
            std::vector<uint8_t> bytes;
            put_varint(bytes, choice);
            if (choice > 0) {
                indicator = indicator_levels(ref.h, ref.first_cell, ref.fields[choice - 1].values);
                fit_indicator_thresholds(ref.h, h, matched, indicator);
                for (int32_t t : indicator.threshold) put_varint(bytes, zigzag(t));
            }
            ArithmeticEncoder encoder;
            ConnectivityMemory memory = ref.memory;
            Hierarchy out;
            Counterparts out_cp;
            encode_frame_connectivity(ref.h, h, kSeriesVersion, memory, choice > 0 ? &indicator : nullptr, encoder, out,
                                      out_cp);
            const std::vector<uint8_t> payload = encoder.finish();
            bytes.insert(bytes.end(), payload.begin(), payload.end());
            if (choice == 0 || bytes.size() < connectivity.size()) {
                connectivity = std::move(bytes);
                next.h = std::move(out);
                next.memory = memory;
                cp = std::move(out_cp);
            }
        }
    }
    const std::vector<FrameVertex> order = frame_vertex_order(next.h, ref.h, cp);
    std::vector<Vec3> positions(order.size());
    {
        const std::vector<uint32_t> canonical = canonical_vertex_order(h);
        for (size_t v = 0; v < canonical.size(); ++v)
            if (canonical[v] != kNoVertex) positions[canonical[v]] = h.position(VertexId(v));
    }
    FrameGeometryMode mode;
    const std::vector<uint8_t> geometry = encode_frame_geometry(ref.h, order, positions, kSeriesVersion, next.h, &mode);
    stats.moving = mode == FrameGeometryMode::moving;
    index_frame(next);

    std::vector<uint8_t> head;
    put_f64(head, time);
    stats.nodes = next.h.node_count();
    stats.vertices = next.h.vertex_count();
    stats.faces = face_count(next.h);
    const FieldFrame field_frame(ref, next, cp, order);
    put_varint(head, stats.nodes);
    put_varint(head, stats.vertices);
    put_varint(head, stats.faces);
    put_varint(head, uint64_t(field_frame.levels));
    std::vector<uint8_t> payload;  // after the connectivity section
    put_varint(payload, geometry.size());
    payload.insert(payload.end(), geometry.begin(), geometry.end());
    AMC_REQUIRE(fields.size() <= kMaxSeriesFields, invalid_input, "series frame: more than 4096 fields");
    put_varint(payload, fields.size());
    const size_t fields_start = payload.size();
    for (size_t i = 0; i < fields.size(); ++i) {
        for (size_t j = 0; j < i; ++j)
            AMC_REQUIRE(fields[j].name != fields[i].name || fields[j].association != fields[i].association,
                        invalid_input, "series frame: two fields named \"" + fields[i].name + "\"");
        double bound = options.error_bound;
        for (const auto& field_bound : options.field_bounds)
            if (field_bound.first == fields[i].name) bound = field_bound.second;
        const size_t before = payload.size();
        Field decoded;
        FieldCodeStats fs;
        encode_field(fields[i], bound, field_frame, payload, decoded, &fs);
        stats.fields.push_back({fields[i].name, payload.size() - before, fs.bounded, fs.max_error});
        stats.max_error = std::max(stats.max_error, fs.max_error);
        next.fields.push_back(std::move(decoded));
    }
    stats.field_bytes = payload.size() - fields_start;
    payload = padded_frame_payload(head, connectivity, payload, stats.nodes);
    stats.connectivity_bytes = connectivity.size();
    stats.geometry_bytes = geometry.size();
    coded.block = block(keyframe ? SeriesBlock::keyframe : SeriesBlock::frame, payload);
    stats.bytes = coded.block.size();
    return coded;
}

}  // namespace

SeriesFrameStats SeriesWriter::add_frame(const Hierarchy& h, double time, const std::vector<Field>& fields) {
    AMC_REQUIRE(!closed_, invalid_input, "series: add_frame after close");
    const TriangleMesh& base = state_->base;
    AMC_REQUIRE(h.base().triangles == base.triangles, invalid_input,
                "series frame " + std::to_string(frames_) + ": not over the series' base mesh (other base triangles)");
    AMC_REQUIRE(h.single_precision() == base.single_precision, invalid_input,
                "series frame " + std::to_string(frames_) + ": coordinate precision differs from the base mesh's");
    const bool keyframe = frames_ == 0 || (options_.keyframe_interval && frames_ % options_.keyframe_interval == 0);
    CodedFrame coded = code_frame(base, options_, keyframe ? initial_state(base) : state_->prev, keyframe, h, time, fields);
    // An encoder-chosen keyframe when the frame coded alone is smaller (FORMAT.md 7.9): tried in
    // full only when the forest alone says it may be.
    if (!keyframe && options_.choose_keyframes &&
        encode_hierarchy(h).size() < coded.stats.connectivity_bytes + coded.stats.geometry_bytes) {
        CodedFrame alone = code_frame(base, options_, initial_state(base), true, h, time, fields);
        if (alone.block.size() < coded.block.size()) coded = std::move(alone);
    }
    // Nodes added or removed since the previous frame (whatever the frame was coded against).
    const FrameState first = frames_ == 0 ? initial_state(base) : FrameState{};
    const Hierarchy& before = frames_ == 0 ? first.h : state_->prev.h;
    const Counterparts cp = match_nodes(before, coded.next.h);
    uint64_t kept = 0;
    for (NodeId n = 0; n < cp.size(); ++n) kept += coded.next.h.is_alive(n) && cp[n] != kNoNode;
    coded.stats.changed_nodes = (coded.next.h.node_count() - kept) + (before.node_count() - kept);
    write(coded.block);
    state_->prev = std::move(coded.next);
    ++frames_;
    return coded.stats;
}

void SeriesWriter::close() {
    if (closed_) return;
    write(block(SeriesBlock::end, {}));
    closed_ = true;
    if (file_) {
        const bool ok = std::fclose(file_) == 0;
        file_ = nullptr;
        AMC_REQUIRE(ok, io, path_ + ": close failed: " + std::strerror(errno));
    }
}

// ---- reader ----------------------------------------------------------------------------------

struct SeriesReader::State {
    TriangleMesh base;
    FrameState current;
    long long current_index = -1;  // the frame `current` holds, -1 none
};

SeriesReader::SeriesReader(std::vector<uint8_t> bytes, const std::string& what, const SeriesReadOptions& options)
    : bytes_(std::move(bytes)), what_(what), options_(options), state_(new State) {
    const SeriesScan scan = scan_series_file(bytes_, what, options.allow_unfinished, kSeriesFlagSinglePrecision,
                                             uint8_t(SeriesBlock::forest_frame));
    version_ = scan.version;
    keyframe_interval_ = scan.keyframe_interval;
    finished_ = scan.finished;
    ignored_ = scan.ignored;
    const bool single = scan.flags & kSeriesFlagSinglePrecision;
    for (const SeriesBlockView& b : scan.blocks) {
        const SeriesBlock kind = SeriesBlock(b.type);
        AMC_REQUIRE(!is_forest_block(kind), corrupt,
                    what + ": a series of quadtree/octree forests (read it with ForestSeriesReader, or amc series decode)");
        if (&b == &scan.blocks.front()) {
            AMC_REQUIRE(kind == SeriesBlock::base, corrupt, what + ": the first block is not the base mesh");
            try {
                state_->base = read_base(b.payload, b.length, single, what);
            } catch (const Error& e) {
                if (std::string(e.what()).rfind(what, 0) == 0) throw;
                throw e.prefixed(what);
            }
            continue;
        }
        AMC_REQUIRE(kind != SeriesBlock::base, corrupt, what + ": a second base mesh block");
        AMC_REQUIRE(kind == SeriesBlock::keyframe || !frames_.empty(), corrupt, what + ": frame 0 is not a keyframe");
        PayloadReader in(b.payload, b.length, "frame header");
        const std::string frame_what = what + ": frame " + std::to_string(frames_.size());
        const FrameHeader fh = read_frame_header(in, state_->base.positions.size(), state_->base.triangles.size(), frame_what);
        SeriesFrameInfo info;
        info.offset = b.offset;
        info.size = b.length + kSeriesBlockOverhead;
        info.keyframe = kind == SeriesBlock::keyframe;
        info.time = fh.time;
        info.nodes = fh.nodes;
        info.vertices = fh.vertices;
        info.faces = fh.faces;
        info.levels = int(fh.levels);
        frames_.push_back(info);
    }
}

SeriesReader SeriesReader::open(const std::string& path, const SeriesReadOptions& options) {
    const std::string text = read_whole_file(path, [&](const std::string& first) {  // a file of something else: at once
        check_series_header(reinterpret_cast<const uint8_t*>(first.data()), first.size(), path, kSeriesFlagSinglePrecision);
    });
    return SeriesReader(std::vector<uint8_t>(text.begin(), text.end()), path, options);
}

SeriesReader::~SeriesReader() = default;
SeriesReader::SeriesReader(SeriesReader&&) noexcept = default;

const TriangleMesh& SeriesReader::base() const { return state_->base; }

void SeriesReader::decode_next(size_t k) {
    const SeriesFrameInfo& info = frames_[k];
    const std::string what = what_ + ": frame " + std::to_string(k);
    const uint8_t* payload = bytes_.data() + info.offset + 5;
    const size_t length = info.size - kSeriesBlockOverhead;
    const TriangleMesh& base = state_->base;
    const FrameState initial = info.keyframe ? initial_state(base) : FrameState{};
    const FrameState& ref = info.keyframe ? initial : state_->current;
    try {
        PayloadReader in(payload, length, "frame");
        const FrameHeader fh = read_frame_header(in, base.positions.size(), base.triangles.size(), what);
        check_frame_nodes(fh.nodes, info.size, options_.max_nodes, options_.max_nodes_per_byte, "nodes");
        uint64_t connectivity_length = in.varint();
        AMC_REQUIRE(connectivity_length <= in.remaining(), truncated, "connectivity longer than the frame");
        const uint8_t* connectivity = in.bytes(connectivity_length);
        FrameState next;
        Counterparts cp;
        if (info.keyframe) {
            HierarchyDecodeOptions options;
            options.max_nodes = fh.nodes;
            next.h = decode_hierarchy(base, connectivity, size_t(connectivity_length), options);
            cp = match_nodes(ref.h, next.h);
        } else {
            Indicator indicator;
            uint64_t choice = 0;
            if (version_ >= 2) {
                PayloadReader section(connectivity, size_t(connectivity_length), "connectivity");
                choice = section.varint();
                AMC_REQUIRE(choice <= ref.fields.size() && (choice == 0 || is_indicator_candidate(ref.fields[choice - 1])),
                            corrupt, "connectivity: indicator " + std::to_string(choice) + " is not a scalar float cell field of the frame before");
                if (choice > 0) {
                    indicator = indicator_levels(ref.h, ref.first_cell, ref.fields[choice - 1].values);
                    for (int32_t& t : indicator.threshold) {
                        const uint64_t z = section.varint();
                        AMC_REQUIRE(z <= 2 * uint64_t(kMaxIndicatorThreshold), corrupt,
                                    "connectivity: an indicator threshold out of range");
                        t = unzigzag(z);
                    }
                }
                const size_t skip = size_t(connectivity_length) - section.remaining();
                connectivity += skip;
                connectivity_length -= skip;
            }
            ArithmeticDecoder decoder(connectivity, size_t(connectivity_length));
            next.memory = ref.memory;
            decode_frame_connectivity(ref.h, version_, next.memory, choice > 0 ? &indicator : nullptr, decoder, fh.nodes,
                                      next.h, cp);
            AMC_REQUIRE(!decoder.overran(), truncated, "connectivity: the payload ends early");
        }
        AMC_REQUIRE(next.h.node_count() == fh.nodes && next.h.vertex_count() == fh.vertices, corrupt,
                    "the forest does not match the counts of the frame header");
        const uint64_t geometry_length = in.varint();
        AMC_REQUIRE(geometry_length <= in.remaining(), truncated, "geometry longer than the frame");
        const uint8_t* geometry = in.bytes(geometry_length);
        const std::vector<FrameVertex> order = frame_vertex_order(next.h, ref.h, cp);
        decode_frame_geometry(ref.h, order, geometry, size_t(geometry_length), version_, next.h);
        index_frame(next);
        const FieldFrame field_frame(ref, next, cp, order);
        AMC_REQUIRE(uint64_t(field_frame.levels) == fh.levels && field_frame.cell_node.size() == fh.faces, corrupt,
                    "the forest does not match the counts of the frame header");
        const uint64_t field_count = in.varint();
        AMC_REQUIRE(field_count <= kMaxSeriesFields, corrupt, std::to_string(field_count) + " fields (at most 4096)");
        for (uint64_t i = 0; i < field_count; ++i) {
            Field f = decode_field(in, field_frame);
            for (const Field& g : next.fields)
                AMC_REQUIRE(g.name != f.name || g.association != f.association, corrupt,
                            "two fields named \"" + f.name + "\"");
            next.fields.push_back(std::move(f));
        }
        AMC_REQUIRE(in.remaining() == 0, corrupt, "bytes after the last field");
        next.h.set_single_precision(base.single_precision);
        state_->current = std::move(next);
        state_->current_index = (long long)k;
    } catch (const Error& e) {
        state_->current_index = -1;
        if (std::string(e.what()).rfind(what, 0) == 0) throw;
        throw e.prefixed(what);
    }
}

SeriesFrame SeriesReader::frame(size_t k) {
    if (k >= frames_.size()) throw std::out_of_range("series frame " + std::to_string(k) + " of " + std::to_string(frames_.size()));
    for (size_t i = first_frame_to_decode(frames_, k, state_->current_index); i <= k; ++i) decode_next(i);
    SeriesFrame out;
    out.hierarchy = state_->current.h;
    out.time = frames_[k].time;
    out.fields = state_->current.fields;
    return out;
}

}  // namespace amc
