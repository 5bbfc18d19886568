// Series whose frames cost next to nothing, which the writers pad to at most kSeriesNodesPerByte
// nodes (octants) per byte (FORMAT.md 7.2, Bounds): shared by the crafted-file suite and the
// series golden files.
#pragma once

#include <amc/octree.h>
#include <amc/refinement.h>
#include <amc/series.h>

#include <vector>

namespace amc::test {

// A single triangle refined uniformly 9 times (349,525 nodes), as a keyframe and again unchanged.
struct PaddedSeries {
    Hierarchy hierarchy;
    std::vector<SeriesFrameStats> stats;
    std::vector<uint8_t> bytes;
};
inline PaddedSeries padded_series() {
    TriangleMesh triangle;
    triangle.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    triangle.triangles = {{0, 1, 2}};
    PaddedSeries out{Hierarchy(triangle), {}, {}};
    refine_uniformly(out.hierarchy, 9);
    SeriesOptions options;
    options.choose_keyframes = false;
    SeriesWriter writer(triangle, options);
    for (int k = 0; k < 2; ++k) out.stats.push_back(writer.add_frame(out.hierarchy, double(k)));
    writer.close();
    out.bytes = writer.bytes();
    return out;
}

// A uniform quadtree of depth 9 (349,525 octants) over one tree of a 2 x 1 brick, twice.
struct PaddedForestSeries {
    OctreeForest forest;
    std::vector<ForestSeriesFrameStats> stats;
    std::vector<uint8_t> bytes;
};
inline PaddedForestSeries padded_forest_series() {
    PaddedForestSeries out{uniform_octree_forest(brick_connectivity(2, 1, 1), 9), {}, {}};
    SeriesOptions options;
    options.choose_keyframes = false;
    ForestSeriesWriter writer(out.forest.connectivity, options);
    for (int k = 0; k < 2; ++k) out.stats.push_back(writer.add_frame(out.forest, double(k)));
    writer.close();
    out.bytes = writer.bytes();
    return out;
}

}  // namespace amc::test
