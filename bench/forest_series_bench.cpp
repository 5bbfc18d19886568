// Forest series (docs/SERIES.md, scripts/series_report.sh): a p4est-like moving front in 2D or 3D,
// one forest a frame, as a series file against independent .amq files and p4est_save files (with
// AMC_WITH_P4EST: the forests are then made by p4est itself — p4est_refine around the front,
// p4est_balance — and each frame's p4est_save file is measured; without p4est, amcodec's
// front_octree_forest and balance_octree_forest, and p4est_save's per-leaf layout counted).
// Each frame also carries leaf data: "phi" (Float64, the front's level set at the leaf centre)
// and "level" (UInt8), coded in the series, in the .amq files and saved as p4est user data.
//
//   forest_series_bench [--dim 2|3] [--frames N] [--max-level L] [--cfl C] [--balance face|corner]
//
// The front advances C finest-leaf widths a frame (C <= 1: a CFL-bounded solver's front).
// Times are CPU seconds of this process.
#include <amc/octree.h>
#include <amc/series.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <string>
#include <vector>

#include <unistd.h>

using namespace amc;

namespace {

double now() {
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

// The leaf data of a frame: front_octree_forest's level set at each leaf's centre, and its level.
void add_leaf_data(OctreeForest& f, double t) {
    Field phi{"phi", FieldAssociation::cell, FieldType::float64, 1, {}, {}};
    Field level{"level", FieldAssociation::cell, FieldType::uint8, 1, {}, {}};
    const double root = double(int64_t(1) << octree_root_log2(f.dim()));
    for (uint32_t tree = 0; tree < f.tree_count(); ++tree)
        for (uint64_t i = f.tree_offsets[tree]; i < f.tree_offsets[tree + 1]; ++i) {
            const Octant& o = f.leaves[i];
            const double h = std::ldexp(1.0, -o.level) / 2;
            const Vec3 c = tree_point(f.connectivity, tree, o.x / root + h, o.y / root + h, f.dim() == 3 ? o.z / root + h : 0);
            phi.values.push_back(c.x + 0.3 * std::sin(4 * c.y) + 0.2 * std::cos(3 * c.z) - t);
            level.integers.push_back(o.level);
        }
    f.leaf_data = {phi, level};
}

uint64_t p4est_layout_size(const OctreeForest& f) {  // per tree a count, per leaf coordinates and level (int32)
    return 8 * uint64_t(f.tree_count()) + uint64_t(f.leaves.size()) * 4 * uint64_t(f.dim() + 1);
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0 : v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
    int dim = 2, frames = 100, max_level = -1;
    double cfl = 0.5;
    std::string balance_name = "corner";
    for (int i = 1; i + 1 < argc; i += 2) {
        const std::string a = argv[i];
        if (a == "--dim") dim = std::atoi(argv[i + 1]);
        else if (a == "--frames") frames = std::atoi(argv[i + 1]);
        else if (a == "--max-level") max_level = std::atoi(argv[i + 1]);
        else if (a == "--cfl") cfl = std::atof(argv[i + 1]);
        else if (a == "--balance") balance_name = argv[i + 1];
        else {
            std::fprintf(stderr, "unknown option %s\n", argv[i]);
            return 2;
        }
    }
    if (max_level < 0) max_level = dim == 2 ? 9 : 6;
    const OctreeBalance balance = balance_name == "face" ? OctreeBalance::face : OctreeBalance::corner;
    const TreeConnectivity conn = dim == 2 ? brick_connectivity(2, 4, 2) : brick_connectivity(3, 2, 2, 1);
    const double advance = cfl * std::ldexp(1.0, -max_level), t0 = dim == 2 ? 1.5 : 0.25;
    const bool p4est = octree_p4est_available();
    std::printf("# forest_series_bench --dim %d --frames %d --max-level %d --cfl %g --balance %s\n\n", dim, frames, max_level, cfl,
                balance_name.c_str());
    std::printf("front x + 0.3 sin(4y)%s = t over a %s brick, t from %g by %g a frame (%g finest leaves); forests made by %s, "
                "balanced by %s\n\n",
                dim == 3 ? " + 0.2 cos(3z)" : "", dim == 2 ? "4x2" : "2x2x1", t0, advance, cfl,
                p4est ? "p4est (p4est_refine, p4est_balance, p4est_save)" : "amcodec (front_octree_forest, balance_octree_forest)",
                balance_name.c_str());

    const std::string tmp = (std::filesystem::temp_directory_path() / ("forest_series_bench_" + std::to_string(::getpid()))).string();
    std::vector<OctreeForest> seq;
    uint64_t p4est_bytes = 0, p4est_data_bytes = 0, amq_bytes = 0, amq_forest_bytes = 0, leaves = 0, min_leaves = UINT64_MAX,
             max_leaves = 0;
    double amq_encode = 0;
    for (int k = 0; k < frames; ++k) {
        const double t = t0 + advance * k;
        OctreeForest f;
        if (p4est) {
            write_p4est_front_forest(tmp + ".p4est", conn, t, max_level, balance);
            f = read_p4est_file(tmp + ".p4est");
            p4est_bytes += std::filesystem::file_size(tmp + ".p4est");
        } else {
            f = balance_octree_forest(front_octree_forest(conn, t, max_level), balance);
            p4est_bytes += p4est_layout_size(f);
        }
        OctreeEncodeStats s;
        const double e0 = now();
        encode_octree_forest(f, {}, &s);
        amq_encode += now() - e0;
        amq_forest_bytes += s.file_bytes;
        add_leaf_data(f, t);
        amq_bytes += encode_octree_forest(f).size();
        if (p4est) {
            write_p4est_file(tmp + "_data.p4est", f);
            p4est_data_bytes += std::filesystem::file_size(tmp + "_data.p4est");
        } else {
            p4est_data_bytes += p4est_layout_size(f) + f.leaves.size() * octree_leaf_data_bytes(f.leaf_data);
        }
        leaves += f.leaves.size();
        min_leaves = std::min<uint64_t>(min_leaves, f.leaves.size());
        max_leaves = std::max<uint64_t>(max_leaves, f.leaves.size());
        seq.push_back(std::move(f));
    }
    std::filesystem::remove(tmp + ".p4est");
    std::filesystem::remove(tmp + "_data.p4est");

    // The series, with and without the leaf data.
    auto write = [&](bool with_data, std::vector<ForestSeriesFrameStats>& stats, double* seconds) {
        ForestSeriesWriter writer(conn);
        const double e0 = now();
        for (int k = 0; k < frames; ++k) {
            if (with_data) {
                stats.push_back(writer.add_frame(seq[k], double(k)));
            } else {
                OctreeForest bare = seq[k];
                bare.leaf_data.clear();
                stats.push_back(writer.add_frame(bare, double(k)));
            }
        }
        writer.close();
        if (seconds) *seconds = now() - e0;
        return writer.bytes();
    };
    std::vector<ForestSeriesFrameStats> bare_stats, stats;
    const std::vector<uint8_t> bare = write(false, bare_stats, nullptr);
    double encode_seconds = 0;
    const std::vector<uint8_t> series = write(true, stats, &encode_seconds);
    // Round trip and decode time.
    ForestSeriesReader reader(series);
    int exact = 0;
    const double d0 = now();
    std::vector<ForestSeriesFrame> decoded;
    for (int k = 0; k < frames; ++k) decoded.push_back(reader.frame(size_t(k)));
    const double decode_seconds = now() - d0;
    for (int k = 0; k < frames; ++k) exact += decoded[k].forest == seq[k];
    std::vector<double> changed;
    uint64_t keyframes = 0, forest_bytes = 0, field_bytes = 0;
    for (int k = 0; k < frames; ++k) {
        if (k > 0) changed.push_back(double(stats[k].changed_octants) / double(stats[k].octants));
        keyframes += stats[k].keyframe;
        forest_bytes += stats[k].connectivity_bytes;
        field_bytes += stats[k].field_bytes;
    }
    const double n = double(frames);
    std::printf("%d frames of %llu-%llu leaves (%.0f on average); octants changed a frame: median %.2f%%, max %.2f%%; "
                "%llu keyframes\n\n",
                frames, (unsigned long long)min_leaves, (unsigned long long)max_leaves, double(leaves) / n, 100 * median(changed),
                changed.empty() ? 0.0 : 100 * *std::max_element(changed.begin(), changed.end()), (unsigned long long)keyframes);
    std::printf("| what | forests only (bytes) | bits/leaf | vs series | with leaf data (bytes) | vs series |\n|---|---:|---:|---:|---:|---:|\n");
    auto row = [&](const char* what, uint64_t b, uint64_t d) {
        std::printf("| %s | %llu | %.3f | %.1f | %llu | %.2f |\n", what, (unsigned long long)b, 8.0 * double(b) / double(leaves),
                    double(b) / double(bare.size()), (unsigned long long)d, double(d) / double(series.size()));
    };
    row("series file (.amcs)", bare.size(), series.size());
    row("independent .amq files", amq_forest_bytes, amq_bytes);
    row(p4est ? "p4est_save files" : "p4est_save layout (per leaf)", p4est_bytes, p4est_data_bytes);
    std::printf("\nseries with leaf data: forests %llu bytes, leaf data %llu bytes; round trips %d/%d frames bit-exact\n",
                (unsigned long long)forest_bytes, (unsigned long long)field_bytes, exact, frames);
    std::printf("speed (CPU s, one run): series encode %.1f frames/s (%.2f M leaves/s), decode %.1f frames/s (%.2f M leaves/s); "
                ".amq encode of the forests alone %.1f frames/s\n",
                n / encode_seconds, double(leaves) / encode_seconds / 1e6, n / decode_seconds, double(leaves) / decode_seconds / 1e6,
                n / amq_encode);
    return exact == frames ? 0 : 1;
}
