// The leaves of a forest as VTU cells: VTK_QUAD in 2D, VTK_HEXAHEDRON in 3D, hanging nodes left
// as they are (ParaView draws them as they come), with the cell arrays "level" and "tree" and the
// forest's leaf fields.
#include <amc/mesh_io.h>

#include "common/check.h"
#include "mesh/vtu_writer.h"
#include "octree/octree_levels.h"

#include <amc/series.h>

#include <cmath>
#include <unordered_map>

namespace amc {

namespace {

constexpr uint8_t kVtkQuad = 9, kVtkHexahedron = 12;
// VTK's corner order from z-order: around the bottom face, then around the top one.
constexpr int kVtkCorner[8] = {0, 1, 3, 2, 4, 5, 7, 6};

}  // namespace

void write_octree_vtu(const std::string& path, const OctreeForest& forest, VtuEncoding encoding) {
    validate_octree_forest(forest, path);
    const TreeConnectivity& conn = forest.connectivity;
    const int d = forest.dim(), root = octree_root_log2(d), corners = 1 << d;
    std::vector<Vec3> points;
    std::vector<uint32_t> connectivity;
    connectivity.reserve(forest.leaves.size() * corners);
    std::vector<uint8_t> levels;
    std::vector<uint32_t> trees;
    // Corners shared within a tree, by their integer coordinates (up to 2^root on each axis).
    std::unordered_map<uint64_t, uint32_t> index;
    for (uint32_t t = 0; t < forest.tree_count(); ++t) {
        index.clear();
        for (uint64_t i = forest.tree_offsets[t]; i < forest.tree_offsets[t + 1]; ++i) {
            const Octant& o = forest.leaves[i];
            const int64_t len = int64_t(1) << (root - o.level);
            for (int k = 0; k < corners; ++k) {
                const int c = kVtkCorner[k];
                const uint64_t x = uint64_t(o.x + ((c & 1) ? len : 0)), y = uint64_t(o.y + ((c & 2) ? len : 0)),
                               z = uint64_t(o.z + ((c & 4) ? len : 0));
                const uint64_t key = (x << 42) | (y << 21) | z;  // 2^root + 1 values fit in 21 bits in 3D, z = 0 in 2D
                const uint64_t key2 = d == 2 ? (x << 31) | y : key;
                auto [it, added] = index.try_emplace(key2, uint32_t(points.size()));
                if (added)
                    points.push_back(tree_point(conn, t, std::ldexp(double(x), -root), std::ldexp(double(y), -root),
                                                std::ldexp(double(z), -root)));
                connectivity.push_back(it->second);
            }
            levels.push_back(uint8_t(o.level));
            trees.push_back(t);
        }
    }
    // The leaf fields, after "level" and "tree" unless a leaf field takes one of those names.
    std::vector<DataArray> cell_data;
    const auto has_field = [&](const char* name) {
        for (const Field& f : forest.leaf_data)
            if (f.name == name) return true;
        return false;
    };
    if (!has_field("level")) cell_data.push_back({"level", 1, std::move(levels)});
    if (!has_field("tree")) cell_data.push_back({"tree", 1, std::move(trees)});
    for (const Field& f : forest.leaf_data) cell_data.push_back(array_from_field(f));
    VtuCells cells{connectivity.data(), forest.leaves.size(), corners, d == 2 ? kVtkQuad : kVtkHexahedron};
    write_file_atomically(path, format_vtu_cells(points, false, cells, {}, cell_data, encoding));
}

}  // namespace amc
