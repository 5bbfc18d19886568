// The leaves of a forest as VTU cells: VTK_QUAD in 2D, VTK_HEXAHEDRON in 3D, hanging nodes left
// as they are (ParaView draws them as they come), or the triangles / tetrahedra of
// conforming_leaf_mesh; with the cell arrays "level" and "tree" and the forest's leaf fields.
#include <amc/mesh_io.h>

#include "common/check.h"
#include "common/keyed_hash.h"
#include "mesh/vtu_writer.h"

#include <amc/series.h>

#include <cmath>
#include <type_traits>
#include <unordered_map>

namespace amc {

namespace {

constexpr uint8_t kVtkTriangle = 5, kVtkTetra = 10, kVtkQuad = 9, kVtkHexahedron = 12;
// VTK's corner order from z-order: around the bottom face, then around the top one.
constexpr int kVtkCorner[8] = {0, 1, 3, 2, 4, 5, 7, 6};

// The leaves' corners, shared within a tree, as VTK cells.
void leaf_cells(const OctreeForest& forest, std::vector<Vec3>& points, std::vector<uint32_t>& connectivity) {
    const TreeConnectivity& conn = forest.connectivity;
    const int d = forest.dim(), root = octree_root_log2(d), corners = 1 << d;
    connectivity.reserve(forest.leaves.size() * corners);
    // Corners shared within a tree, by their integer coordinates (up to 2^root on each axis);
    // keyed: a forest can put many corners in one residue of the identity hash's bucket count.
    std::unordered_map<uint64_t, uint32_t, KeyedWordHash> index;
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
        }
    }
}

// The array's tuples in the order `index` names them (each cell gets its leaf's values).
DataArray gathered(DataArray array, const std::vector<uint32_t>& index) {
    std::visit(
        [&](auto& values) {
            std::remove_reference_t<decltype(values)> out;
            out.reserve(index.size() * array.components);
            for (uint32_t i : index)
                out.insert(out.end(), values.begin() + size_t(i) * array.components, values.begin() + size_t(i + 1) * array.components);
            values = std::move(out);
        },
        array.values);
    return array;
}

}  // namespace

void write_octree_vtu(const std::string& path, const OctreeForest& forest, VtuEncoding encoding, OctreeVtuCells cells) {
    validate_octree_forest(forest, path);
    const int d = forest.dim();
    std::vector<Vec3> points;
    std::vector<uint32_t> connectivity;
    std::vector<uint32_t> leaf_of_cell;  // empty: cell i is leaf i
    std::vector<DataArray> point_data;
    if (cells == OctreeVtuCells::leaves) {
        leaf_cells(forest, points, connectivity);
    } else {
        ConformingLeafMesh mesh = conforming_leaf_mesh(forest);
        std::vector<uint8_t> added(mesh.points.size(), 0);
        std::fill(added.begin() + mesh.corner_points, added.end(), uint8_t(1));
        point_data.push_back({"added_point", 1, std::move(added)});
        points = std::move(mesh.points);
        connectivity = std::move(mesh.cells);
        leaf_of_cell = std::move(mesh.leaf);
    }
    const size_t cell_count = leaf_of_cell.empty() ? forest.leaves.size() : leaf_of_cell.size();
    std::vector<uint32_t> tree_of_leaf(forest.leaves.size());
    for (uint32_t t = 0; t < forest.tree_count(); ++t)
        for (uint64_t i = forest.tree_offsets[t]; i < forest.tree_offsets[t + 1]; ++i) tree_of_leaf[i] = t;
    std::vector<uint8_t> levels(cell_count);
    std::vector<uint32_t> trees(cell_count);
    for (size_t c = 0; c < cell_count; ++c) {
        const size_t leaf = leaf_of_cell.empty() ? c : leaf_of_cell[c];
        levels[c] = uint8_t(forest.leaves[leaf].level);
        trees[c] = tree_of_leaf[leaf];
    }
    // The leaf fields, after "level", "tree" (and "leaf") unless a leaf field takes one of those names.
    std::vector<DataArray> cell_data;
    const auto has_field = [&](const char* name) {
        for (const Field& f : forest.leaf_data)
            if (f.name == name) return true;
        return false;
    };
    if (!has_field("level")) cell_data.push_back({"level", 1, std::move(levels)});
    if (!has_field("tree")) cell_data.push_back({"tree", 1, std::move(trees)});
    if (!leaf_of_cell.empty() && !has_field("leaf")) cell_data.push_back({"leaf", 1, leaf_of_cell});
    for (const Field& f : forest.leaf_data)
        cell_data.push_back(leaf_of_cell.empty() ? array_from_field(f) : gathered(array_from_field(f), leaf_of_cell));
    const bool conforming = cells == OctreeVtuCells::conforming;
    const uint8_t type = conforming ? (d == 2 ? kVtkTriangle : kVtkTetra) : (d == 2 ? kVtkQuad : kVtkHexahedron);
    VtuCells vtu_cells{connectivity.data(), cell_count, conforming ? d + 1 : 1 << d, type};
    write_file_atomically(path, format_vtu_cells(points, false, vtu_cells, point_data, cell_data, encoding));
}

}  // namespace amc
