// Time series of adaptive meshes with their fields: every step of an adaptive run in one file
// (.amcs, docs/FORMAT.md section 7, docs/SERIES.md). One base mesh, then frames; each frame is a
// hierarchy over that base (refined and coarsened freely from the previous frame), its vertex
// positions and its fields. A frame is coded against the previous one (connectivity, positions
// and fields predicted from it), except keyframes, which decode on their own.
#pragma once

#include <amc/field.h>
#include <amc/hierarchy.h>
#include <amc/octree.h>

#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace amc {

struct SeriesOptions {
    // Frames 0, K, 2K, ... are keyframes (decodable without the frames before them); 0: only
    // frame 0. Random access to frame k decodes from the last keyframe at or before k.
    uint32_t keyframe_interval = 0;
    // An absolute error bound for every float field (0: bit-exact), and bounds by field name
    // that override it. The decoder guarantees |decoded - input| <= bound for every value.
    double error_bound = 0;
    std::vector<std::pair<std::string, double>> field_bounds;
    // Write a frame as a keyframe also when it is smaller coded alone than against the frame
    // before it (a sequence that changes faster than it persists).
    bool choose_keyframes = true;
};

struct FieldStats {
    std::string name;
    uint64_t bytes = 0;
    bool bounded = false;
    double max_error = 0;
};

struct SeriesFrameStats {
    bool keyframe = false;
    uint64_t bytes = 0;               // the whole frame block
    uint64_t connectivity_bytes = 0;  // forest and diagonals
    uint64_t geometry_bytes = 0;      // positions
    uint64_t field_bytes = 0;         // all fields
    uint64_t nodes = 0, vertices = 0, faces = 0;
    uint64_t changed_nodes = 0;       // nodes added, removed or whose refinement changed since the previous frame
    bool moving = false;              // persisting vertices moved
    std::vector<FieldStats> fields;
    double max_error = 0;             // over the bounded fields
};

// Writes a series frame by frame, to memory or straight to a file (each frame is appended and
// flushed as it is added, so a reader sees every complete frame even if the writer dies).
class SeriesWriter {
public:
    // In memory: bytes() holds the file so far.
    explicit SeriesWriter(const TriangleMesh& base, const SeriesOptions& options = {});
    // To a file (created or truncated). Throws Error (io) when it can not be written.
    SeriesWriter(const std::string& path, const TriangleMesh& base, const SeriesOptions& options = {});
    ~SeriesWriter();  // closes the file without the END block if close() was not called
    SeriesWriter(const SeriesWriter&) = delete;
    SeriesWriter& operator=(const SeriesWriter&) = delete;

    // Adds a frame: a hierarchy over the base mesh (same triangles in the same order; positions,
    // base vertices included, may change from frame to frame), its time and fields. Point fields
    // have one tuple per vertex in canonical order (extract_leaf_mesh's vertices), cell fields
    // one per triangle of extract_leaf_mesh. Throws Error (invalid_input) naming the problem; the
    // series is unchanged then.
    SeriesFrameStats add_frame(const Hierarchy& h, double time, const std::vector<Field>& fields = {});
    // Writes the END block (and closes the file). No frame can be added afterwards.
    void close();

    uint64_t frame_count() const { return frames_; }
    const std::vector<uint8_t>& bytes() const { return bytes_; }  // in memory only

private:
    struct State;
    void write(const std::vector<uint8_t>& data);
    std::unique_ptr<State> state_;
    SeriesOptions options_;
    std::vector<uint8_t> bytes_;
    std::FILE* file_ = nullptr;
    std::string path_;
    uint64_t frames_ = 0;
    bool closed_ = false;
};

// A frame block holds at most this many nodes (octants) per byte, framing included, and a forest
// series at most this many trees per byte of the file after its header (docs/FORMAT.md 7.2,
// Bounds): uniform levels and unchanged forests cost next to nothing, so the writer pads such
// frames, and the reader's memory and time grow at most linearly with the file. The .amq bound.
constexpr uint64_t kSeriesNodesPerByte = kOctreeOctantsPerByte;

struct SeriesReadOptions {
    // Read a file whose writer has not finished (no END block) or died in the middle of a frame:
    // every complete frame is read, the incomplete rest ignored. Otherwise such a file is refused
    // (ErrorCode::truncated).
    bool allow_unfinished = false;
    uint64_t max_nodes = 1ull << 26;  // per frame
    // More is refused as ErrorCode::limit_exceeded. 0 lifts the bound, for files written before
    // it (2026-12-02), whose writer did not pad.
    uint64_t max_nodes_per_byte = kSeriesNodesPerByte;
};

struct SeriesFrame {
    Hierarchy hierarchy;  // over the series' base mesh
    double time = 0;
    std::vector<Field> fields;
};

struct SeriesFrameInfo {
    uint64_t offset = 0, size = 0;  // of the frame block
    bool keyframe = false;
    double time = 0;
    uint64_t nodes = 0, vertices = 0, faces = 0;
    int levels = 0;
};

// Reads a series: the constructor checks the framing of the whole file (every block's length and
// checksum) without decoding frames; frame(k) decodes from the last keyframe at or before k (or
// from the frame decoded last, when k follows it).
class SeriesReader {
public:
    // `what` names the file in messages. Throws Error (bad magic, unsupported version, checksum,
    // truncated, corrupt) naming the problem.
    SeriesReader(std::vector<uint8_t> bytes, const std::string& what = "series", const SeriesReadOptions& options = {});
    static SeriesReader open(const std::string& path, const SeriesReadOptions& options = {});
    ~SeriesReader();
    SeriesReader(SeriesReader&&) noexcept;

    const TriangleMesh& base() const;
    size_t frame_count() const { return frames_.size(); }
    const SeriesFrameInfo& info(size_t k) const { return frames_.at(k); }
    bool finished() const { return finished_; }       // the END block is there
    uint64_t ignored_bytes() const { return ignored_; }  // an incomplete frame at the end (allow_unfinished)
    uint32_t keyframe_interval() const { return keyframe_interval_; }
    int version() const { return version_; }  // of the file's format (FORMAT.md 7.1)

    // Throws Error naming the frame on a corrupt frame; std::out_of_range for k >= frame_count().
    SeriesFrame frame(size_t k);

private:
    struct State;
    void decode_next(size_t k);
    std::vector<uint8_t> bytes_;
    std::string what_;
    SeriesReadOptions options_;
    std::vector<SeriesFrameInfo> frames_;
    std::unique_ptr<State> state_;
    bool finished_ = false;
    uint64_t ignored_ = 0;
    uint32_t keyframe_interval_ = 0;
    int version_ = 0;
};

}  // namespace amc

namespace amc {

// ---- series as ParaView collections of VTU files (src/series/series_vtu.cpp) -------------------

// One dataset of a ParaView collection (.pvd): its time step and its file, as written in the .pvd
// (relative to the .pvd's directory unless absolute).
struct PvdEntry {
    double time = 0;
    std::string file;
};
// Reads the <DataSet timestep=... file=...> entries of a .pvd file, in file order (part and group
// attributes are ignored). Throws Error naming the file and line.
std::vector<PvdEntry> read_pvd(const std::string& path);
// Writes a .pvd collection (through a temporary file and a rename).
void write_pvd(const std::string& path, const std::vector<PvdEntry>& entries);

// A field as a VTK DataArray of the same name, type and values, and back.
Field field_from_array(const DataArray& array, FieldAssociation association);
DataArray array_from_field(const Field& field);

// A VTU leaf mesh with point and cell data, read as a frame over `base` (import_leaf_mesh): the
// point and cell arrays become fields, reordered to canonical vertex order and leaf-mesh order.
SeriesFrame frame_from_vtu(const TriangleMesh& base, const VtuMesh& vtu, double time = 0,
                           const std::string& what = "vtu");
// The frame's leaf mesh (or the mesh of `max_level`, which keeps only the point fields: cell
// fields belong to the leaf mesh) with its fields as point and cell data, plus the cell arrays
// "level" and "green" unless the frame has fields of those names.
VtuMesh vtu_from_frame(const SeriesFrame& frame, int max_level = -1);

}  // namespace amc

namespace amc {

// ---- series of quadtree/octree forests (src/series/forest_series.cpp, FORMAT.md 7.10-7.12) -----
// The same file (.amcs, version 3) with a coarse mesh of trees instead of a base mesh: each frame
// a forest over it (OctreeForest) with its leaf data as fields, coded against the previous
// frame's forest and fields, keyframes as in SeriesOptions (error bounds are for triangle series
// only: forest fields are bit-exact).

struct ForestSeriesFrameStats {
    bool keyframe = false;
    uint64_t bytes = 0, connectivity_bytes = 0, field_bytes = 0;
    uint64_t octants = 0, leaves = 0;
    uint64_t changed_octants = 0;  // octants added or removed since the previous frame
    std::vector<FieldStats> fields;
};

class ForestSeriesWriter {
public:
    explicit ForestSeriesWriter(const TreeConnectivity& conn, const SeriesOptions& options = {});
    // Appends to a file (created or truncated), each frame flushed as it is added.
    ForestSeriesWriter(const std::string& path, const TreeConnectivity& conn, const SeriesOptions& options = {});
    ~ForestSeriesWriter();
    ForestSeriesWriter(const ForestSeriesWriter&) = delete;
    ForestSeriesWriter& operator=(const ForestSeriesWriter&) = delete;

    // A forest over the series' connectivity (validate_octree_forest), its leaf data the frame's
    // fields. Throws Error (invalid_input) naming the problem; the series is unchanged then.
    ForestSeriesFrameStats add_frame(const OctreeForest& forest, double time);
    void close();  // the END block
    uint64_t frame_count() const { return frames_; }
    const std::vector<uint8_t>& bytes() const { return bytes_; }  // in memory only

private:
    struct State;
    void write(const std::vector<uint8_t>& data);
    std::unique_ptr<State> state_;
    SeriesOptions options_;
    std::vector<uint8_t> bytes_;
    std::FILE* file_ = nullptr;
    std::string path_;
    uint64_t frames_ = 0;
    bool closed_ = false;
};

struct ForestSeriesFrame {
    OctreeForest forest;  // leaf_data: the frame's fields
    double time = 0;
};

struct ForestSeriesFrameInfo {
    uint64_t offset = 0, size = 0;
    bool keyframe = false;
    double time = 0;
    uint64_t octants = 0, leaves = 0;
    int levels = 0;
};

class ForestSeriesReader {
public:
    // Checks the framing of the whole file, as SeriesReader. max_nodes limits octants per frame.
    ForestSeriesReader(std::vector<uint8_t> bytes, const std::string& what = "series", const SeriesReadOptions& options = {});
    static ForestSeriesReader open(const std::string& path, const SeriesReadOptions& options = {});
    ~ForestSeriesReader();
    ForestSeriesReader(ForestSeriesReader&&) noexcept;

    const TreeConnectivity& connectivity() const;
    size_t frame_count() const { return frames_.size(); }
    const ForestSeriesFrameInfo& info(size_t k) const { return frames_.at(k); }
    bool finished() const { return finished_; }
    uint64_t ignored_bytes() const { return ignored_; }
    uint32_t keyframe_interval() const { return keyframe_interval_; }
    int version() const { return version_; }
    // Decodes from the last keyframe at or before k (or the frame decoded last). Throws Error
    // naming the frame; std::out_of_range for k >= frame_count().
    ForestSeriesFrame frame(size_t k);

private:
    struct State;
    void decode_next(size_t k);
    std::vector<uint8_t> bytes_;
    std::string what_;
    SeriesReadOptions options_;
    std::vector<ForestSeriesFrameInfo> frames_;
    std::unique_ptr<State> state_;
    bool finished_ = false;
    uint64_t ignored_ = 0;
    uint32_t keyframe_interval_ = 0;
    int version_ = 0;
};

// Whether a series file holds forests (its first block is a forest base block); false for
// anything else, a triangle series or not a series at all.
bool is_forest_series(const std::vector<uint8_t>& bytes);

}  // namespace amc
