// `amc series encode | decode | info`: time series of adaptive meshes with their fields (.amcs,
// docs/SERIES.md), from and to ParaView collections (.pvd + one VTU per frame), and series of
// quadtree/octree forests from and to .amq (or p4est) files, one a frame. `amc encode` of a .pvd
// (or with --series), `amc decode` and `amc info` of an .amcs file come here too.
#include "cli_files.h"
#include "commands.h"
#include "progress.h"

#include <amc/import.h>
#include <amc/mesh_io.h>
#include <amc/octree.h>
#include <amc/series.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <set>

namespace amc::cli {

namespace {

namespace fs = std::filesystem;

double seconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

std::string lower_extension(const std::string& path) {
    std::string ext = fs::path(path).extension().string();
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    return ext;
}

// "temperature=1e-6" -> {"temperature", 1e-6}.
std::pair<std::string, double> parse_field_bound(const std::string& text) {
    const size_t eq = text.rfind('=');
    if (eq == std::string::npos || eq == 0)
        throw UsageError("--field-bound: expected NAME=BOUND, got '" + text + "'");
    const std::string value = text.substr(eq + 1);
    char* stop = nullptr;
    const double bound = std::strtod(value.c_str(), &stop);
    if (value.empty() || *stop != '\0' || !std::isfinite(bound) || bound < 0)
        throw UsageError("--field-bound: '" + value + "' is not a bound >= 0 (in " + text + ")");
    return {text.substr(0, eq), bound};
}

// One input frame of `amc series encode`: its file, and its time.
struct FrameSource {
    std::string path;
    double time = 0;
};

std::vector<FrameSource> frame_sources(const std::vector<std::string>& inputs) {
    std::vector<FrameSource> sources;
    for (const std::string& input : inputs) {
        if (is_pvd(input)) {
            const fs::path dir = fs::path(input).parent_path();
            for (const PvdEntry& e : read_pvd(input)) {
                const fs::path file(e.file);
                sources.push_back({file.is_absolute() ? e.file : (dir / file).string(), e.time});
            }
        } else {
            sources.push_back({input, double(sources.size())});
        }
    }
    return sources;
}

// Frame `source` as a SeriesFrame: a VTU mesh (with its point and cell data) or another mesh over
// `base`, a hierarchy (.amh), or a compressed .amc file; `base` is set from the first frame when
// the caller gave none.
SeriesFrame read_frame(const FrameSource& source, std::optional<TriangleMesh>& base) {
    const InputFile input = read_input(source.path);
    SeriesFrame frame;
    frame.time = source.time;
    switch (input.kind) {
        case FileKind::hierarchy: frame.hierarchy = hierarchy_of(input); break;
        case FileKind::compressed: frame.hierarchy = decode_input(input, {}); break;
        case FileKind::series: throw Error(input.name + ": a series file can not be a frame of another series");
        case FileKind::mesh: {
            // Without --base: the coarsest base found in the first frame (import_mesh).
            const VtuMesh vtu = input.mesh_format == MeshFormat::vtu ? read_vtu(source.path) : VtuMesh{mesh_of(input), {}, {}};
            if (!base) base = import_mesh(vtu.mesh, input.name).hierarchy.base();
            return frame_from_vtu(*base, vtu, source.time, input.name);
        }
    }
    if (!base) base = frame.hierarchy.base();
    return frame;
}

template <class Command>
SeriesReadOptions read_options(const Command& command) {
    SeriesReadOptions options;
    options.allow_unfinished = command.allow_unfinished;
    if (command.max_nodes > 0) options.max_nodes = command.max_nodes;
    if (command.max_nodes_per_byte >= 0) options.max_nodes_per_byte = uint64_t(command.max_nodes_per_byte);
    return options;
}

SeriesReader open_series(const InputFile& input, const SeriesReadOptions& options) {
    if (input.kind != FileKind::series)
        throw Error(input.name + ": expected a series file (.amcs), found " + file_kind_name(input.kind));
    return SeriesReader(std::vector<uint8_t>(input.bytes.begin(), input.bytes.end()), input.name, options);
}

SeriesFrame decode_frame(SeriesReader& reader, size_t k, const std::string& name) {
    try {
        return reader.frame(k);
    } catch (const Error& e) {
        throw e.prefixed(name);
    }
}

std::string field_summary(const Field& f) {
    std::string s = f.name + " (" + (f.association == FieldAssociation::point ? "point" : "cell") + ", " +
                    field_type_name(f.type) + (f.components > 1 ? " x" + std::to_string(f.components) : "") + ")";
    return s;
}

// Frame k's file beside the collection: run.pvd -> run_<k>.vtu.
std::string frame_file(const std::string& pvd, size_t k) {
    return fs::path(pvd).stem().string() + "_" + std::to_string(k) + ".vtu";
}

// ---- forest series -----------------------------------------------------------------------------

// A frame file of a forest series: an .amq file or (with AMC_WITH_P4EST) a p4est_save file.
bool is_forest_input(const std::string& path) {
    const std::string ext = lower_extension(path);
    return ext == ".amq" || ext == ".p4est";
}

OctreeForest read_forest_frame(const std::string& path) {
    try {
        if (lower_extension(path) == ".p4est") return read_p4est_file(path);
        const std::string bytes = read_octree_input(path);
        return decode_octree_forest(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
    } catch (const Error& e) {
        throw e.prefixed(path);
    }
}

void encode_forest_series(const std::vector<FrameSource>& sources, const std::string& output, const SeriesOptions& options,
                          const GlobalOptions& global) {
    if (options.error_bound > 0 || !options.field_bounds.empty())
        throw UsageError("series encode: forest leaf data are coded bit-exact (no --error-bound or --field-bound)");
    Progress progress(global.verbosity > 0);
    std::unique_ptr<ForestSeriesWriter> writer;
    std::vector<ForestSeriesFrameStats> stats;
    double encode_seconds = 0;
    for (size_t k = 0; k < sources.size(); ++k) {
        progress.phase("frame " + std::to_string(k) + " of " + std::to_string(sources.size()) + ": " + sources[k].path);
        if (!is_forest_input(sources[k].path))
            throw UsageError("series encode: " + sources[k].path + " is not a forest (.amq, .p4est) like the first frame");
        const OctreeForest forest = read_forest_frame(sources[k].path);
        const auto start = std::chrono::steady_clock::now();
        if (!writer) writer = std::make_unique<ForestSeriesWriter>(forest.connectivity, options);
        try {
            stats.push_back(writer->add_frame(forest, sources[k].time));
        } catch (const Error& e) {
            throw e.prefixed(sources[k].path + " (frame " + std::to_string(k) + ")");
        }
        encode_seconds += seconds_since(start);
    }
    writer->close();
    const std::vector<uint8_t>& bytes = writer->bytes();
    write_output(output, std::string(bytes.begin(), bytes.end()), global.force);
    progress.finish();
    if (global.verbosity == 0) return;
    std::FILE* out = output == "-" ? stderr : stdout;
    uint64_t connectivity = 0, fields = 0, leaves = 0, keyframes = 0;
    for (const ForestSeriesFrameStats& s : stats) {
        connectivity += s.connectivity_bytes;
        fields += s.field_bytes;
        leaves += s.leaves;
        keyframes += s.keyframe;
    }
    std::fprintf(out, "%s: %zu forest frames (%lu keyframe%s), %lu bytes, %.0f bytes a frame (%.0f leaves a frame)\n",
                 output == "-" ? "stdout" : output.c_str(), stats.size(), (unsigned long)keyframes, keyframes == 1 ? "" : "s",
                 (unsigned long)bytes.size(), double(bytes.size()) / double(stats.size()), double(leaves) / double(stats.size()));
    std::fprintf(out, "  forests %lu bytes (%.4f bits/leaf), leaf fields %lu; encode %.3f s (%.1f frames/s)\n",
                 (unsigned long)connectivity, 8.0 * double(connectivity) / double(leaves), (unsigned long)fields, encode_seconds,
                 double(stats.size()) / encode_seconds);
    if (global.verbosity > 1)
        for (size_t k = 0; k < stats.size(); ++k)
            std::fprintf(out, "  frame %5zu %4s %10lu bytes, forest %8lu, fields %10lu, %9lu leaves, %9lu changed octants\n", k,
                         stats[k].keyframe ? "key" : "", (unsigned long)stats[k].bytes, (unsigned long)stats[k].connectivity_bytes,
                         (unsigned long)stats[k].field_bytes, (unsigned long)stats[k].leaves, (unsigned long)stats[k].changed_octants);
}

ForestSeriesReader open_forest_series(const InputFile& input, const SeriesReadOptions& options) {
    return ForestSeriesReader(std::vector<uint8_t>(input.bytes.begin(), input.bytes.end()), input.name, options);
}

ForestSeriesFrame decode_forest_frame(ForestSeriesReader& reader, size_t k, const std::string& name) {
    try {
        return reader.frame(k);
    } catch (const Error& e) {
        throw e.prefixed(name);
    }
}

// Frame k's forest beside the collection: run.pvd -> run_<k>.vtu.
void write_forest_frame(const std::string& path, const OctreeForest& forest, bool force) {
    const std::string ext = lower_extension(path);
    if (ext == ".vtu") write_octree_vtu(path, forest);
    else if (ext == ".p4est") write_p4est_file(path, forest);
    else {
        const std::vector<uint8_t> bytes = encode_octree_forest(forest);
        write_output(path, std::string(bytes.begin(), bytes.end()), force);
    }
}

void decode_forest_series(const InputFile& input, const SeriesDecodeCommand& command, const GlobalOptions& global) {
    if (command.level >= 0) throw UsageError("series decode: --level is for triangle series (decode a frame to .amq, then amc octree decode --level)");
    const bool one_frame = command.frame >= 0;
    std::string output = command.output;
    if (output.empty())
        output = one_frame ? default_output(command.input, "") + "_" + std::to_string(command.frame) + ".amq"
                           : default_output(command.input, ".pvd");
    const std::string ext = lower_extension(output);
    if (output == "-" || !(is_pvd(output) || (one_frame && (ext == ".amq" || ext == ".vtu" || ext == ".p4est"))))
        throw UsageError(std::string("series decode of forests writes a collection (.pvd + one VTU a frame)") +
                         (one_frame ? " or the frame's forest (.amq .vtu .p4est)" : "") + ", not " + output);
    ForestSeriesReader reader = open_forest_series(input, read_options(command));
    if (one_frame && uint64_t(command.frame) >= reader.frame_count())
        throw Error(input.name + ": frame " + std::to_string(command.frame) + " requested but the file has frames 0.." +
                    std::to_string(int64_t(reader.frame_count()) - 1));
    const fs::path dir = fs::path(output).parent_path();
    if (!global.force) {
        refuse_existing(output);
        if (is_pvd(output))
            for (size_t k = 0; k < reader.frame_count(); ++k) refuse_existing((dir / frame_file(output, k)).string());
    }
    if (one_frame) {
        write_forest_frame(output, decode_forest_frame(reader, size_t(command.frame), input.name).forest, global.force);
    } else {
        std::vector<PvdEntry> entries;
        for (size_t k = 0; k < reader.frame_count(); ++k) {
            const ForestSeriesFrame frame = decode_forest_frame(reader, k, input.name);
            write_octree_vtu((dir / frame_file(output, k)).string(), frame.forest);
            entries.push_back({frame.time, frame_file(output, k)});
        }
        write_pvd(output, entries);
    }
    if (global.verbosity > 0)
        std::printf("%s: %s -> %s\n", input.name.c_str(), one_frame ? ("frame " + std::to_string(command.frame)).c_str() : "every frame",
                    output.c_str());
}

void forest_series_info(const InputFile& input, const SeriesInfoCommand& command) {
    ForestSeriesReader reader = open_forest_series(input, read_options(command));
    const TreeConnectivity& conn = reader.connectivity();
    size_t keyframes = 0;
    for (size_t k = 0; k < reader.frame_count(); ++k) keyframes += reader.info(k).keyframe;
    std::printf("%s: amc series version %d, %dD forests of %u trees, %zu frames, %lu bytes; %zu keyframes (interval %s, and the "
                "encoder's choices); %s\n",
                input.name.c_str(), reader.version(), conn.dim, conn.tree_count(), reader.frame_count(), (unsigned long)input.bytes.size(),
                keyframes, reader.keyframe_interval() ? std::to_string(reader.keyframe_interval()).c_str() : "none",
                reader.finished() ? "finished"
                                  : ("unfinished (" + std::to_string(reader.ignored_bytes()) + " bytes of an incomplete frame ignored)").c_str());
    if (command.frame >= 0 && uint64_t(command.frame) >= reader.frame_count())
        throw Error(input.name + ": frame " + std::to_string(command.frame) + " requested but the file has frames 0.." +
                    std::to_string(int64_t(reader.frame_count()) - 1));
    const size_t described = command.frame >= 0 ? size_t(command.frame) : 0;
    ForestSeriesFrame shown;
    for (size_t k = 0; k < reader.frame_count(); ++k) {
        ForestSeriesFrame frame = decode_forest_frame(reader, k, input.name);
        if (k == described) shown = std::move(frame);
    }
    std::printf("  decodes: yes\n  %5s %12s %4s %10s %10s %10s %10s %6s\n", "frame", "time", "key", "offset", "bytes", "octants",
                "leaves", "levels");
    for (size_t k = 0; k < reader.frame_count(); ++k) {
        const ForestSeriesFrameInfo& f = reader.info(k);
        std::printf("  %5zu %12.6g %4s %10lu %10lu %10lu %10lu %6d\n", k, f.time, f.keyframe ? "yes" : "", (unsigned long)f.offset,
                    (unsigned long)f.size, (unsigned long)f.octants, (unsigned long)f.leaves, f.levels);
    }
    if (reader.frame_count() == 0) return;
    std::printf("  leaf fields of frame %zu:%s\n", described, shown.forest.leaf_data.empty() ? " none" : "");
    for (const Field& f : shown.forest.leaf_data) std::printf("    %s\n", field_summary(f).c_str());
}

}  // namespace

bool is_pvd(const std::string& path) { return lower_extension(path) == ".pvd"; }

void run_series_encode(const SeriesEncodeCommand& command, const GlobalOptions& global) {
    if (command.inputs.empty()) throw UsageError("series encode: no input (a .pvd, or frame files)");
    const std::string output =
        command.output.empty() ? default_output(command.inputs.front(), ".amcs") : command.output;
    if (output != "-" && lower_extension(output) != ".amcs")
        throw UsageError("series encode writes a series file (.amcs), not " + output);
    if (!global.force) refuse_existing(output);
    SeriesOptions options;
    options.keyframe_interval = command.keyframe_interval;
    options.choose_keyframes = !command.fixed_keyframes;
    options.error_bound = command.error_bound;
    for (const std::string& b : command.field_bounds) options.field_bounds.push_back(parse_field_bound(b));

    const std::vector<FrameSource> sources = frame_sources(command.inputs);
    if (!sources.empty() && is_forest_input(sources.front().path)) {
        if (!command.base.empty()) throw UsageError("series encode: --base is for triangle frames; forests carry their trees");
        encode_forest_series(sources, output, options, global);
        return;
    }
    Progress progress(global.verbosity > 0);
    progress.phase("reading " + command.inputs.front());
    std::optional<TriangleMesh> base;
    if (!command.base.empty()) base = mesh_of(read_input(command.base));
    std::unique_ptr<SeriesWriter> writer;
    std::vector<SeriesFrameStats> stats;
    double read_seconds = 0, encode_seconds = 0;
    for (size_t k = 0; k < sources.size(); ++k) {
        progress.phase("frame " + std::to_string(k) + " of " + std::to_string(sources.size()) + ": " + sources[k].path);
        auto start = std::chrono::steady_clock::now();
        const bool base_given = base.has_value();
        SeriesFrame frame;
        try {
            frame = read_frame(sources[k], base);
        } catch (const Error& e) {
            const bool off_base = std::string(e.what()).find("wrong base") != std::string::npos;
            if (k == 0 || !command.base.empty() || !base_given || !off_base) throw;
            throw Error(e.code(), std::string(e.what()) + " (frame " + std::to_string(k) +
                                  "; without --base the base is the coarsest one found in the first frame)");
        }
        read_seconds += seconds_since(start);
        start = std::chrono::steady_clock::now();
        if (!writer) writer = std::make_unique<SeriesWriter>(*base, options);
        try {
            stats.push_back(writer->add_frame(frame.hierarchy, frame.time, frame.fields));
        } catch (const Error& e) {
            throw e.prefixed(sources[k].path + " (frame " + std::to_string(k) + ")");
        }
        encode_seconds += seconds_since(start);
    }
    // A bound naming no field (a typo, or NAME=B,NAME2=B2 in one option) would leave it bit-exact unsaid.
    std::set<std::string> field_names;
    for (const SeriesFrameStats& s : stats)
        for (const auto& f : s.fields) field_names.insert(f.name);
    for (const auto& bound : options.field_bounds)
        if (field_names.count(bound.first) == 0)
            throw UsageError("--field-bound " + bound.first + "=...: no frame has a field of that name");
    writer->close();
    const std::vector<uint8_t>& bytes = writer->bytes();
    write_output(output, std::string(bytes.begin(), bytes.end()), global.force);
    progress.finish();
    if (global.verbosity == 0) return;
    std::FILE* out = output == "-" ? stderr : stdout;
    uint64_t connectivity = 0, positions = 0, fields = 0, faces = 0, vertices = 0, keyframes = 0;
    double max_error = 0;
    for (const SeriesFrameStats& s : stats) {
        connectivity += s.connectivity_bytes;
        positions += s.geometry_bytes;
        fields += s.field_bytes;
        faces += s.faces;
        vertices += s.vertices;
        keyframes += s.keyframe;
        max_error = std::max(max_error, s.max_error);
    }
    std::fprintf(out, "%s: %zu frames (%lu keyframe%s), %lu bytes, %.0f bytes a frame (%.0f faces, %.0f vertices a frame)\n",
                 output == "-" ? "stdout" : output.c_str(), stats.size(), (unsigned long)keyframes,
                 keyframes == 1 ? "" : "s", (unsigned long)bytes.size(), double(bytes.size()) / double(stats.size()),
                 double(faces) / double(stats.size()), double(vertices) / double(stats.size()));
    std::fprintf(out, "  connectivity %lu bytes (%.3f bits/face), positions %lu (%.2f bits/vertex), fields %lu\n",
                 (unsigned long)connectivity, 8.0 * double(connectivity) / double(faces), (unsigned long)positions,
                 8.0 * double(positions) / double(vertices), (unsigned long)fields);
    if (!stats.empty()) {
        for (size_t i = 0; i < stats.front().fields.size(); ++i) {
            uint64_t field_bytes = 0;
            for (const SeriesFrameStats& s : stats)
                if (i < s.fields.size()) field_bytes += s.fields[i].bytes;
            std::fprintf(out, "  field %-24s %10lu bytes%s\n", stats.front().fields[i].name.c_str(),
                         (unsigned long)field_bytes, stats.front().fields[i].bounded ? " (error-bounded)" : "");
        }
    }
    if (options.error_bound > 0 || !options.field_bounds.empty())
        std::fprintf(out, "  error-bounded fields: max error %.3g\n", max_error);
    std::fprintf(out, "  read %.3f s, encode %.3f s (%.1f frames/s)\n", read_seconds, encode_seconds,
                 double(stats.size()) / encode_seconds);
    if (global.verbosity > 1) {
        std::fprintf(out, "  %5s %4s %10s %10s %10s %10s %9s %9s\n", "frame", "key", "bytes", "connect", "positions",
                     "fields", "faces", "changed");
        for (size_t k = 0; k < stats.size(); ++k) {
            const SeriesFrameStats& s = stats[k];
            std::fprintf(out, "  %5zu %4s %10lu %10lu %10lu %10lu %9lu %9lu\n", k, s.keyframe ? "yes" : "", (unsigned long)s.bytes,
                         (unsigned long)s.connectivity_bytes, (unsigned long)s.geometry_bytes,
                         (unsigned long)s.field_bytes, (unsigned long)s.faces, (unsigned long)s.changed_nodes);
        }
    }
}

void run_series_decode(const InputFile& input, const SeriesDecodeCommand& command, const GlobalOptions& global) {
    if (input.kind == FileKind::series && is_forest_series(std::vector<uint8_t>(input.bytes.begin(), input.bytes.end())))
        return decode_forest_series(input, command, global);
    const bool one_frame = command.frame >= 0;
    std::string output = command.output;
    if (output.empty())
        output = one_frame ? default_output(command.input, "") + "_" + std::to_string(command.frame) + ".vtu"
                           : default_output(command.input, ".pvd");
    if (output == "-") throw UsageError("series decode writes files (a .pvd and its VTU files, or a frame's file), not stdout");
    MeshFormat mesh_format = MeshFormat::vtu;
    const OutputKind kind = output_kind(output, &mesh_format);
    if (!is_pvd(output) && !(one_frame && (kind == OutputKind::mesh || kind == OutputKind::hierarchy)))
        throw UsageError(std::string("series decode writes a collection (.pvd)") +
                         (one_frame ? " or the frame's mesh (.vtu .obj .off .ply) or hierarchy (.amh)" : "") + ", not " +
                         output);
    Progress progress(global.verbosity > 0);
    progress.phase("reading " + input.name);
    SeriesReader reader = open_series(input, read_options(command));
    if (one_frame && uint64_t(command.frame) >= reader.frame_count())
        throw Error(input.name + ": frame " + std::to_string(command.frame) + " requested but the file has frames 0.." +
                    std::to_string(int64_t(reader.frame_count()) - 1));
    std::vector<size_t> frames;
    if (one_frame) frames.push_back(size_t(command.frame));
    else
        for (size_t k = 0; k < reader.frame_count(); ++k) frames.push_back(k);
    // Every output is checked before the work whose result it would refuse.
    const fs::path dir = fs::path(output).parent_path();
    if (!global.force) {
        refuse_existing(output);
        if (is_pvd(output))
            for (size_t k : frames) refuse_existing((dir / frame_file(output, k)).string());
    }
    std::vector<PvdEntry> entries;
    const auto start = std::chrono::steady_clock::now();
    double decode_seconds = 0;
    uint64_t faces = 0;
    for (size_t k : frames) {
        progress.phase("frame " + std::to_string(k) + " of " + std::to_string(reader.frame_count()));
        const auto t = std::chrono::steady_clock::now();
        const SeriesFrame frame = decode_frame(reader, k, input.name);
        decode_seconds += seconds_since(t);
        if (command.level > frame.hierarchy.depth())
            throw Error(input.name + ": level " + std::to_string(command.level) + " requested but frame " +
                        std::to_string(k) + " has levels 0.." + std::to_string(frame.hierarchy.depth()));
        faces += reader.info(k).faces;
        if (is_pvd(output)) {
            const std::string file = frame_file(output, k);
            write_vtu((dir / file).string(), vtu_from_frame(frame, command.level));
            entries.push_back({frame.time, file});
        } else if (kind == OutputKind::hierarchy) {
            write_output(output, serialize_hierarchy(frame.hierarchy), global.force);
        } else if (mesh_format == MeshFormat::vtu) {
            write_vtu(output, vtu_from_frame(frame, command.level));
        } else {
            const LeafMesh leaf = extract_leaf_mesh(frame.hierarchy, command.level);
            write_output(output, format_mesh(leaf.mesh, &leaf.cells, mesh_format), global.force);
        }
    }
    if (is_pvd(output)) write_pvd(output, entries);
    progress.finish();
    if (global.verbosity > 0)
        std::printf("%s: %zu frame%s (%.0f faces a frame) -> %s%s (decode %.3f s, %.1f frames/s; %.3f s in all)\n",
                    input.name.c_str(), frames.size(), frames.size() == 1 ? "" : "s",
                    double(faces) / double(frames.size()), output.c_str(),
                    is_pvd(output) ? (" + " + std::to_string(frames.size()) + " VTU files").c_str() : "", decode_seconds,
                    double(frames.size()) / decode_seconds, seconds_since(start));
}

void run_series_info(const InputFile& input, const SeriesInfoCommand& command, const GlobalOptions&) {
    if (input.kind == FileKind::series && is_forest_series(std::vector<uint8_t>(input.bytes.begin(), input.bytes.end())))
        return forest_series_info(input, command);
    SeriesReader reader = open_series(input, read_options(command));
    const TriangleMesh& base = reader.base();
    size_t keyframes = 0;
    for (size_t k = 0; k < reader.frame_count(); ++k) keyframes += reader.info(k).keyframe;
    std::printf("%s: amc series version %d, %zu frames, %lu bytes; %zu keyframes (interval %s, and the encoder's choices); %s\n",
                input.name.c_str(), reader.version(), reader.frame_count(), (unsigned long)input.bytes.size(), keyframes,
                reader.keyframe_interval() ? std::to_string(reader.keyframe_interval()).c_str() : "none",
                reader.finished() ? "finished"
                                  : ("unfinished (" + std::to_string(reader.ignored_bytes()) + " bytes of an incomplete frame ignored)").c_str());
    std::printf("  base mesh %zu vertices, %zu triangles\n", base.positions.size(), base.triangles.size());
    if (command.frame >= 0 && uint64_t(command.frame) >= reader.frame_count())
        throw Error(input.name + ": frame " + std::to_string(command.frame) + " requested but the file has frames 0.." +
                    std::to_string(int64_t(reader.frame_count()) - 1));
    // Decoding validates what the block checksums can not: the payloads.
    const size_t described = command.frame >= 0 ? size_t(command.frame) : 0;
    SeriesFrame shown;
    for (size_t k = 0; k < reader.frame_count(); ++k) {
        SeriesFrame frame = decode_frame(reader, k, input.name);
        if (k == described) shown = std::move(frame);
    }
    std::printf("  decodes: yes\n  %5s %12s %4s %10s %10s %9s %9s %9s %6s\n", "frame", "time", "key", "offset", "bytes",
                "nodes", "vertices", "faces", "levels");
    for (size_t k = 0; k < reader.frame_count(); ++k) {
        const SeriesFrameInfo& f = reader.info(k);
        std::printf("  %5zu %12.6g %4s %10lu %10lu %9lu %9lu %9lu %6d\n", k, f.time, f.keyframe ? "yes" : "",
                    (unsigned long)f.offset, (unsigned long)f.size, (unsigned long)f.nodes, (unsigned long)f.vertices,
                    (unsigned long)f.faces, f.levels);
    }
    if (reader.frame_count() == 0) return;
    std::printf("  fields of frame %zu:%s\n", described, shown.fields.empty() ? " none" : "");
    for (const Field& f : shown.fields) {
        double lo = std::numeric_limits<double>::infinity(), hi = -lo;
        for (double v : f.values) lo = std::min(lo, v), hi = std::max(hi, v);
        for (int64_t v : f.integers) lo = std::min(lo, double(v)), hi = std::max(hi, double(v));
        std::printf("    %-40s %zu tuples, %g .. %g\n", field_summary(f).c_str(), f.tuple_count(), lo, hi);
    }
}

}  // namespace amc::cli
