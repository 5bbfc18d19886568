// The series file against its peers on an adaptive run (docs/SERIES.md, scripts/series_report.sh):
// sizes (series file, independent .amc files, zstd -19 and xz -9 of each frame's binary VTU
// arrays), the inter-frame connectivity against the same frame coded alone, fields against zstd
// of the raw arrays and zfp (reversible, and at the same absolute bound), round trips frame by
// frame, random access, and speeds.
//
//   series_bench [--scenario lshape|rotating|front|front-cfl] [--frames N] [--target ELEMENTS]
//                [--end-time T] [--cfl C] [--max-level L] [--keyframe K] [--bound B] [--repeat R]
//                [--speed-only 1] [--peers 0] [--per-frame 1]
// Times are CPU seconds; --speed-only leaves out the peers and the bounded file (for large frames);
// --peers 0 leaves out zstd, xz and zfp (the costly part), keeping the .amc files. --end-time
// shortens the heat runs' time span (dt = T / frames: smaller output intervals). front-cfl is the
// front advancing C finest-element sizes a step (a CFL-bounded solver's front), front the model's
// own step. Every frame's connectivity is compared with the same frame coded alone, binned by the
// share of nodes that changed (--per-frame 1 lists them one by one).
#include <amc/codec.h>
#include <amc/hierarchy_coder.h>
#include <amc/refinement.h>
#include <amc/series.h>
#include <amc/simulation.h>

#include <lzma.h>
#include <zstd.h>
#ifdef AMC_HAVE_ZFP
#include <zfp.h>
#endif

#include <algorithm>
#include <ctime>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

using namespace amc;

namespace {

struct Frame {
    Hierarchy h;
    double time;
    std::vector<Field> fields;
};

// CPU seconds of this (single-threaded) process: the machine is shared, wall time says more about the
// neighbours than about the codec.
double now() {
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

template <class T>
void append(std::vector<uint8_t>& out, const std::vector<T>& v) {
    const uint8_t* p = reinterpret_cast<const uint8_t*>(v.data());
    out.insert(out.end(), p, p + v.size() * sizeof(T));
}

// The arrays of a binary VTU file of the frame (appended raw data as VTK writes it, without its
// XML header): points (Float64), connectivity, offsets (Int64), types (UInt8), then the fields.
std::vector<uint8_t> vtu_arrays(const Frame& f, bool with_mesh, bool with_fields) {
    std::vector<uint8_t> out;
    if (with_mesh) {
        const LeafMesh leaf = extract_leaf_mesh(f.h);
        std::vector<double> points;
        for (const Vec3& p : leaf.mesh.positions) points.insert(points.end(), {p.x, p.y, p.z});
        std::vector<int64_t> connectivity, offsets;
        for (const Triangle& t : leaf.mesh.triangles) {
            connectivity.insert(connectivity.end(), {t[0], t[1], t[2]});
            offsets.push_back(int64_t(connectivity.size()));
        }
        std::vector<uint8_t> types(leaf.mesh.triangles.size(), 5);
        append(out, points);
        append(out, connectivity);
        append(out, offsets);
        append(out, types);
    }
    if (with_fields) {
        for (const Field& field : f.fields) {
            if (is_float_type(field.type)) {
                if (field.type == FieldType::float32) {
                    std::vector<float> v(field.values.begin(), field.values.end());
                    append(out, v);
                } else {
                    append(out, field.values);
                }
            } else {
                std::vector<uint8_t> v(field.integers.begin(), field.integers.end());  // the run's labels are UInt8
                append(out, v);
            }
        }
    }
    return out;
}

size_t zstd_size(const std::vector<uint8_t>& in, int level) {
    std::vector<uint8_t> out(ZSTD_compressBound(in.size()));
    return ZSTD_compress(out.data(), out.size(), in.data(), in.size(), level);
}

size_t xz_size(const std::vector<uint8_t>& in) {
    std::vector<uint8_t> out(lzma_stream_buffer_bound(in.size()));
    size_t pos = 0;
    lzma_easy_buffer_encode(9, LZMA_CHECK_CRC64, nullptr, in.data(), in.size(), out.data(), &pos, out.size());
    return pos;
}

#ifdef AMC_HAVE_ZFP
// zfp of one 1-D double array (a field's values): reversible when tolerance is 0, else fixed accuracy.
size_t zfp_size(const std::vector<double>& values, double tolerance, double* max_error) {
    if (values.empty()) return 0;
    std::vector<double> data = values;
    zfp_field* field = zfp_field_1d(data.data(), zfp_type_double, data.size());
    zfp_stream* zfp = zfp_stream_open(nullptr);
    if (tolerance > 0) zfp_stream_set_accuracy(zfp, tolerance);
    else zfp_stream_set_reversible(zfp);
    std::vector<uint8_t> buffer(zfp_stream_maximum_size(zfp, field));
    bitstream* stream = stream_open(buffer.data(), buffer.size());
    zfp_stream_set_bit_stream(zfp, stream);
    zfp_stream_rewind(zfp);
    const size_t size = zfp_compress(zfp, field);
    if (max_error) {
        std::vector<double> back(values.size());
        zfp_field* out = zfp_field_1d(back.data(), zfp_type_double, back.size());
        zfp_stream_rewind(zfp);
        zfp_decompress(zfp, out);
        for (size_t i = 0; i < values.size(); ++i) *max_error = std::max(*max_error, std::fabs(back[i] - values[i]));
        zfp_field_free(out);
    }
    zfp_field_free(field);
    stream_close(stream);
    zfp_stream_close(zfp);
    return size;
}
#endif

// make_moving_front_sequence's front (a circle around (-0.3, -0.2), element size 1.2 times the
// distance to it, coarsened behind and refined ahead) advancing `advance` a step from radius 0.5.
Vec3 centroid(const Hierarchy& h, NodeId n) {
    return (1.0 / 3.0) * (h.position(h.vertex(n, 0)) + h.position(h.vertex(n, 1)) + h.position(h.vertex(n, 2)));
}
double diameter(const Hierarchy& h, NodeId n) {
    double longest = 0;
    for (int e = 0; e < 3; ++e) {
        const Vec3 d = h.position(h.vertex(n, e)) - h.position(h.vertex(n, (e + 1) % 3));
        longest = std::max(longest, dot(d, d));
    }
    return std::sqrt(longest);
}
std::vector<Hierarchy> front_sequence(int steps, int max_level, double advance) {
    std::vector<Hierarchy> sequence;
    Hierarchy h(make_square(8));
    for (int step = 0; step < steps; ++step) {
        const double radius = 0.5 + advance * step;
        auto size_at = [radius](Vec3 x) { return 1.2 * std::fabs(std::hypot(x.x + 0.3, x.y + 0.2) - radius); };
        for (bool changed = true; changed;) {
            changed = false;
            const std::vector<NodeId> order = h.breadth_first_order();
            for (auto it = order.rbegin(); it != order.rend(); ++it)
                if (h.is_alive(*it) && !h.is_leaf(*it) && diameter(h, *it) <= size_at(centroid(h, *it)) && h.coarsen(*it))
                    changed = true;
        }
        refine_to_size(h, size_at, max_level);
        sequence.push_back(h);
    }
    return sequence;
}

double median(std::vector<double> v) {
    if (v.empty()) return 0;
    std::sort(v.begin(), v.end());
    return v.size() % 2 ? v[v.size() / 2] : (v[v.size() / 2 - 1] + v[v.size() / 2]) / 2;
}

}  // namespace

int main(int argc, char** argv) {
    std::string scenario = "lshape";
    int frames = 100, max_level = 10, repeat = 3;
    uint32_t target = 20000, keyframe = 0;
    double bound = 1e-6, end_time = 1.0, cfl = 0.5;
    bool speed_only = false, peers = true, per_frame = false;
    for (int i = 1; i + 1 < argc; i += 2) {
        const std::string a = argv[i];
        if (a == "--scenario") scenario = argv[i + 1];
        else if (a == "--frames") frames = std::atoi(argv[i + 1]);
        else if (a == "--target") target = uint32_t(std::atoi(argv[i + 1]));
        else if (a == "--max-level") max_level = std::atoi(argv[i + 1]);
        else if (a == "--keyframe") keyframe = uint32_t(std::atoi(argv[i + 1]));
        else if (a == "--bound") bound = std::atof(argv[i + 1]);
        else if (a == "--repeat") repeat = std::atoi(argv[i + 1]);
        else if (a == "--speed-only") speed_only = std::atoi(argv[i + 1]) != 0;
        else if (a == "--peers") peers = std::atoi(argv[i + 1]) != 0;
        else if (a == "--per-frame") per_frame = std::atoi(argv[i + 1]) != 0;
        else if (a == "--end-time") end_time = std::atof(argv[i + 1]);
        else if (a == "--cfl") cfl = std::atof(argv[i + 1]);
        else {
            std::fprintf(stderr, "unknown option %s\n", argv[i]);
            return 2;
        }
    }

    // ---- the data ------------------------------------------------------------------------------
    std::vector<Frame> seq;
    double simulate = now();
    if (scenario == "front") {
        for (Hierarchy& h : make_moving_front_sequence(frames, max_level)) seq.push_back({std::move(h), 0.0, {}});
    } else if (scenario == "front-cfl") {
        // The finest element's longest edge: the base square's cells are 1/8 wide.
        const double finest = std::sqrt(2.0) / 8 / double(1 << max_level);
        std::printf("front-cfl: the front advances %g a step (%g finest elements of %g); the front model's step is %g\n", cfl * finest,
                    cfl, finest, 1.0 / std::max(1, frames - 1));
        for (Hierarchy& h : front_sequence(frames, max_level, cfl * finest)) seq.push_back({std::move(h), 0.0, {}});
    } else {
        HeatRunOptions options;
        options.scenario = scenario == "rotating" ? HeatScenario::rotating : HeatScenario::lshape;
        options.frames = frames;
        options.max_level = max_level;
        options.target_elements = target;
        options.end_time = end_time;
        run_heat_simulation(options, [&](const SimulationFrame& f) { seq.push_back({*f.hierarchy, f.time, f.fields}); });
    }
    simulate = now() - simulate;
    uint64_t faces = 0, min_faces = UINT64_MAX, max_faces = 0;
    for (const Frame& f : seq) {
        const uint64_t n = extract_leaf_mesh(f.h).mesh.triangles.size();
        faces += n;
        min_faces = std::min(min_faces, n);
        max_faces = std::max(max_faces, n);
    }
    std::printf("# series_bench --scenario %s --frames %d --target %u --end-time %g --cfl %g --max-level %d --keyframe %u --bound %g\n\n",
                scenario.c_str(), frames, target, end_time, cfl, max_level, keyframe, bound);
    std::printf("data: %zu frames, %llu-%llu faces a frame (%.0f on average), %zu fields; simulated in %.2f s\n\n",
                seq.size(), (unsigned long long)min_faces, (unsigned long long)max_faces, double(faces) / seq.size(),
                seq.front().fields.size(), simulate);

    // ---- the series file, exact and bounded, with timings -----------------------------------------
    SeriesOptions exact_options;
    exact_options.keyframe_interval = keyframe;
    std::vector<SeriesFrameStats> stats;
    std::vector<uint8_t> series;
    std::vector<double> encode_times, decode_times;
    for (int r = 0; r < repeat; ++r) {
        stats.clear();
        const double t0 = now();
        SeriesWriter writer(seq.front().h.base(), exact_options);
        for (const Frame& f : seq) stats.push_back(writer.add_frame(f.h, f.time, f.fields));
        writer.close();
        encode_times.push_back(now() - t0);
        series = writer.bytes();
        const double t1 = now();
        SeriesReader reader(series);
        for (size_t k = 0; k < reader.frame_count(); ++k) reader.frame(k);
        decode_times.push_back(now() - t1);
    }
    // Round trip, frame by frame.
    size_t exact_ok = 0;
    {
        SeriesReader reader(series);
        for (size_t k = 0; k < seq.size(); ++k) {
            const SeriesFrame f = reader.frame(k);
            bool ok = identical(f.hierarchy, seq[k].h) && f.fields.size() == seq[k].fields.size() && f.time == seq[k].time;
            for (size_t i = 0; ok && i < f.fields.size(); ++i) ok = identical(f.fields[i], seq[k].fields[i]);
            exact_ok += ok;
        }
    }
    // Random access to the middle frame from a fresh reader.
    double random_access = 0;
    {
        const double t0 = now();
        SeriesReader reader(series);
        const SeriesFrame f = reader.frame(seq.size() / 2);
        random_access = now() - t0;
        if (!identical(f.hierarchy, seq[seq.size() / 2].h)) std::printf("RANDOM ACCESS MISMATCH\n");
    }
    auto print_speed = [&] {
        const double n = double(seq.size());
        std::printf("speed (%d runs, CPU s): encode %.1f-%.1f frames/s, decode %.1f-%.1f frames/s (%.0f faces a frame)\n",
                    repeat, n / *std::max_element(encode_times.begin(), encode_times.end()),
                    n / *std::min_element(encode_times.begin(), encode_times.end()),
                    n / *std::max_element(decode_times.begin(), decode_times.end()),
                    n / *std::min_element(decode_times.begin(), decode_times.end()), double(faces) / n);
    };
    if (speed_only) {
        std::printf("series file: %zu bytes; round trips: %zu/%zu frames bit-exact\n", series.size(), exact_ok, seq.size());
        std::printf("random access to frame %zu from a fresh reader: %.1f ms\n", seq.size() / 2, 1e3 * random_access);
        print_speed();
        return exact_ok == seq.size() ? 0 : 1;
    }
    SeriesOptions bounded_options = exact_options;
    bounded_options.error_bound = bound;
    std::vector<SeriesFrameStats> bounded_stats;
    size_t bounded_ok = 0;
    double bounded_error = 0;
    std::vector<uint8_t> bounded;
    if (!seq.front().fields.empty()) {
        SeriesWriter writer(seq.front().h.base(), bounded_options);
        for (const Frame& f : seq) bounded_stats.push_back(writer.add_frame(f.h, f.time, f.fields));
        writer.close();
        bounded = writer.bytes();
        SeriesReader reader(bounded);
        for (size_t k = 0; k < seq.size(); ++k) {
            const SeriesFrame f = reader.frame(k);
            bool ok = identical(f.hierarchy, seq[k].h) && f.fields.size() == seq[k].fields.size();
            for (size_t i = 0; ok && i < f.fields.size(); ++i) {
                const double e = max_abs_difference(f.fields[i], seq[k].fields[i]);
                bounded_error = std::max(bounded_error, e);
                ok = e <= bound;
            }
            bounded_ok += ok;
        }
    }

    // ---- peers ---------------------------------------------------------------------------------
    uint64_t amc_total = 0, vtu_raw = 0, vtu_zstd = 0, vtu_xz = 0, field_raw = 0, field_zstd = 0, field_zfp = 0,
             field_zfp_bounded = 0;
    uint64_t series_conn = 0, series_geom = 0, series_fields = 0, series_bounded_fields = 0;
    double zfp_error = 0;
    std::vector<double> small_change_ratio, changed_share;
    struct FrameRatio {
        double share, ratio;
        bool keyframe;
    };
    std::vector<FrameRatio> frame_ratio;
    for (size_t k = 0; k < seq.size(); ++k) {
        const Frame& f = seq[k];
        amc_total += encode(f.h).size();
        if (!peers) goto ours;
        {
        const std::vector<uint8_t> vtu = vtu_arrays(f, true, true);
        vtu_raw += vtu.size();
        vtu_zstd += zstd_size(vtu, 19);
        vtu_xz += xz_size(vtu);
        const std::vector<uint8_t> raw_fields = vtu_arrays(f, false, true);
        field_raw += raw_fields.size();
        field_zstd += zstd_size(raw_fields, 19);
#ifdef AMC_HAVE_ZFP
        for (const Field& field : f.fields) {
            if (!is_float_type(field.type)) {
                field_zfp += field.integers.size();  // UInt8 labels: zfp codes floats; counted raw
                field_zfp_bounded += field.integers.size();
                continue;
            }
            field_zfp += zfp_size(field.values, 0, nullptr);
            field_zfp_bounded += zfp_size(field.values, bound, &zfp_error);
        }
#endif
        }
    ours:
        series_conn += stats[k].connectivity_bytes;
        series_geom += stats[k].geometry_bytes;
        series_fields += stats[k].field_bytes;
        if (!bounded_stats.empty()) series_bounded_fields += bounded_stats[k].field_bytes;
        const double share = double(stats[k].changed_nodes) / double(stats[k].nodes);
        if (k > 0) changed_share.push_back(share);  // frame 0 against the unrefined base is no change
        if (k > 0) {
            // Every frame after the first against the same frame coded alone (what a keyframe's
            // forest costs), whether the encoder coded it against the frame before or alone.
            const uint64_t intra = encode_hierarchy(f.h).size();
            const double ratio = double(stats[k].connectivity_bytes) / double(intra);
            frame_ratio.push_back({share, ratio, stats[k].keyframe});
            if (share <= 0.05) small_change_ratio.push_back(ratio);
            if (per_frame)
                std::printf("frame %zu: %.2f%% of the nodes changed, connectivity %llu bytes%s, alone %llu bytes (%.1f%%)\n", k,
                            100 * share, (unsigned long long)stats[k].connectivity_bytes, stats[k].keyframe ? " (keyframe)" : "",
                            (unsigned long long)intra, 100 * ratio);
        }
    }
    const double n = double(seq.size());
    std::printf("| what | bytes | bytes/frame | vs series |\n|---|---:|---:|---:|\n");
    auto row = [&](const char* what, uint64_t bytes) {
        std::printf("| %s | %llu | %.0f | %.2f |\n", what, (unsigned long long)bytes, double(bytes) / n,
                    double(bytes) / double(series.size()));
    };
    row("series file (.amcs, bit-exact)", series.size());
    row("  connectivity", series_conn);
    row("  positions", series_geom);
    row("  fields", series_fields);
    row("independent .amc files (mesh only, no fields)", amc_total);
    if (peers) {
    row("binary VTU arrays, raw", vtu_raw);
    row("binary VTU arrays, zstd -19 per frame", vtu_zstd);
    row("binary VTU arrays, xz -9 per frame", vtu_xz);
    }
    if (!bounded.empty()) {
        std::printf("\nFields alone (all frames):\n\n| what | bytes | vs ours |\n|---|---:|---:|\n");
        auto frow = [&](const char* what, uint64_t bytes, uint64_t ours) {
            std::printf("| %s | %llu | %.2f |\n", what, (unsigned long long)bytes, double(bytes) / double(ours));
        };
        frow("series fields, bit-exact", series_fields, series_fields);
        if (peers) {
            frow("raw arrays", field_raw, series_fields);
            frow("zstd -19 of the raw arrays, per frame", field_zstd, series_fields);
#ifdef AMC_HAVE_ZFP
            frow("zfp reversible, per array and frame", field_zfp, series_fields);
#endif
        }
        char label[128];
        std::snprintf(label, sizeof label, "series fields, bound %g (max error %.3g)", bound, bounded_error);
        frow(label, series_bounded_fields, series_bounded_fields);
#ifdef AMC_HAVE_ZFP
        std::snprintf(label, sizeof label, "zfp accuracy %g, per array and frame (max error %.3g)", bound, zfp_error);
        if (peers) frow(label, field_zfp_bounded, series_bounded_fields);
#endif
    }
    // Per field: ours against zstd -19 of that array alone.
    if (!seq.front().fields.empty()) {
        std::printf("\nPer field (all frames, bit-exact; bits per value, a value being one component of a "
                    "vertex's or cell's tuple):\n\n| field | ours | bits/value | zstd -19 | bits/value | raw |\n"
                    "|---|---:|---:|---:|---:|---:|\n");
        for (size_t i = 0; i < seq.front().fields.size(); ++i) {
            uint64_t ours = 0, z = 0, raw = 0, values = 0;
            for (size_t k = 0; k < seq.size(); ++k) {
                ours += stats[k].fields[i].bytes;
                values += seq[k].fields[i].value_count();
                Frame one{Hierarchy(), 0, {seq[k].fields[i]}};
                const std::vector<uint8_t> a = vtu_arrays(one, false, true);
                raw += a.size();
                if (peers) z += zstd_size(a, 19);
            }
            const double v = double(values);
            if (peers)
                std::printf("| %s | %llu | %.2f | %llu | %.2f | %llu |\n", seq.front().fields[i].name.c_str(),
                            (unsigned long long)ours, 8.0 * double(ours) / v, (unsigned long long)z, 8.0 * double(z) / v,
                            (unsigned long long)raw);
            else
                std::printf("| %s | %llu | %.2f | - | - | %llu |\n", seq.front().fields[i].name.c_str(),
                            (unsigned long long)ours, 8.0 * double(ours) / v, (unsigned long long)raw);
        }
    }
    std::vector<double> sorted_share = changed_share;
    std::sort(sorted_share.begin(), sorted_share.end());
    std::printf("\nchanged nodes per frame: median %.2f%%, max %.2f%%\n", 100 * median(changed_share),
                100 * sorted_share.back());
    // The distribution over every frame: connectivity in the series against the frame alone, by the
    // share of nodes changed since the frame before.
    std::printf("\nconnectivity against the same frame coded alone (encode_hierarchy), frames 1..%zu by share of nodes "
                "changed:\n\n| changed | frames | keyframes | median | max | above 15%% |\n|---|---:|---:|---:|---:|---:|\n",
                seq.size() - 1);
    const double edges[] = {0, 0.01, 0.025, 0.05, 0.10, 0.20, 0.50, 1e300};
    const char* labels[] = {"<= 1%", "1-2.5%", "2.5-5%", "5-10%", "10-20%", "20-50%", "> 50%"};
    for (int b = 0; b < 7; ++b) {
        std::vector<double> r;
        int keyframes = 0, above = 0;
        for (const FrameRatio& f : frame_ratio)
            if (f.share > (b == 0 ? -1.0 : edges[b]) && f.share <= edges[b + 1]) {
                r.push_back(f.ratio);
                keyframes += f.keyframe;
                above += f.ratio > 0.15;
            }
        if (r.empty()) continue;
        std::printf("| %s | %zu | %d | %.1f%% | %.1f%% | %d |\n", labels[b], r.size(), keyframes, 100 * median(r),
                    100 * *std::max_element(r.begin(), r.end()), above);
    }
    if (!small_change_ratio.empty()) {
        std::sort(small_change_ratio.begin(), small_change_ratio.end());
        std::printf("frames with <= 5%% of the nodes changed: %zu; their connectivity against the same frame coded alone "
                    "(encode_hierarchy): median %.1f%%, max %.1f%%, %zu above 15%%\n",
                    small_change_ratio.size(), 100 * median(small_change_ratio), 100 * small_change_ratio.back(),
                    size_t(std::count_if(small_change_ratio.begin(), small_change_ratio.end(), [](double r) { return r > 0.15; })));
    }
    std::printf("independent .amc files / series file: %.2fx (mesh alone: .amc / (connectivity + positions) = %.2fx)\n",
                double(amc_total) / double(series.size()), double(amc_total) / double(series_conn + series_geom));
    std::printf("round trips: %zu/%zu frames bit-exact; bounded: %zu/%zu frames within %g (max error %.3g)\n",
                exact_ok, seq.size(), bounded_ok, bounded.empty() ? 0 : seq.size(), bound, bounded_error);
    std::printf("random access to frame %zu from a fresh reader: %.1f ms\n", seq.size() / 2, 1e3 * random_access);
    print_speed();
    return exact_ok == seq.size() && bounded_ok == (bounded.empty() ? 0 : seq.size()) ? 0 : 1;
}
