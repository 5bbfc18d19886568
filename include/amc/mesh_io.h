// Mesh files in other programs' formats (OBJ, OFF, PLY, VTU) and the files that name them: the
// readers and writers of the library amcodec_extras (zlib), which the CLI, the
// Python module, the tests and the benchmarks link. The codec library amcodec, which installs,
// works on meshes in memory (<amc/mesh.h>) and does not read these formats.
#pragma once

#include <amc/import.h>
#include <amc/mesh.h>
#include <amc/octree.h>

#include <cstddef>
#include <string>
#include <vector>

namespace amc {

enum class MeshFormat { obj, off, ply, vtu };

// Format from the file name's extension (.obj, .off, .ply, .vtu); throws Error otherwise.
MeshFormat mesh_format_from_path(const std::string& path);

// The format a file's first bytes announce (PLY, OFF and VTU have magic words; OBJ has none and
// is taken for text that starts like an OBJ file). Returns false when the bytes name no format.
// Reads no further than the first kMeshFormatContentBytes (a byte-order mark, white space, a word).
bool mesh_format_from_content(const std::string& bytes, MeshFormat& format);
inline constexpr size_t kMeshFormatContentBytes = 4096 + 8;

// Reads an OBJ, OFF, PLY or VTU file (by extension) and validates it with
// validate_triangle_mesh. Throws Error naming the file and the first offending element.
TriangleMesh read_mesh(const std::string& path);
// The same for a file's bytes already in memory; `what` names the source in messages.
TriangleMesh parse_mesh(const std::string& bytes, MeshFormat format, const std::string& what);

// Binary or text for the formats that have both (PLY, VTU); OBJ and OFF are always text.
enum class MeshEncoding { binary, ascii };

// Writes a mesh; format from the extension. Cell data is written where the format can hold it
// and its readers read it (VTU cell arrays; ASCII PLY face properties, see format_ply) and
// ignored otherwise; binary VTU is VtuEncoding::binary_zlib, its zlib blocks compressed on up to
// `threads` threads (0: every core; the bytes do not depend on it). The file is written to a
// temporary name and renamed, so it is never half-written. Throws Error.
void write_mesh(const std::string& path, const TriangleMesh& mesh, const CellData* cells = nullptr,
                MeshEncoding encoding = MeshEncoding::binary, unsigned threads = 0);
// The bytes write_mesh would write, for a format chosen by the caller (output to a stream).
std::string format_mesh(const TriangleMesh& mesh, const CellData* cells, MeshFormat format,
                        MeshEncoding encoding = MeshEncoding::binary, unsigned threads = 0);

// Reads a .vtu file as VTK, ParaView, meshio and DUNE write it: inline ascii or base64
// ("binary"), or appended raw or base64 data; UInt32 or UInt64 headers; zlib-compressed
// (vtkZLibDataCompressor) or not; little- or big-endian. Every cell must be a triangle (VTK
// type 5, or a polygon of 3 points); Points as Float32 set single_precision. A file of several
// Pieces reads as their concatenation (points of later pieces numbered after earlier ones, as
// VTK's reader does); their point and cell arrays must match in name, type and components.
// The mesh is validated with validate_triangle_mesh. zlib blocks inflate on up to `threads`
// threads (0: every core; the result and errors do not depend on it). Throws Error naming the file.
VtuMesh read_vtu(const std::string& path, unsigned threads = 0);

enum class VtuEncoding {
    binary_zlib,  // appended raw data, zlib-compressed blocks, UInt64 headers (VTK's default)
    ascii,        // inline text, for reading by eye
};

// Writes a .vtu file: Points as Float32 when mesh.single_precision, else Float64; cells as
// triangles; every array of point_data and cell_data (sizes must match the vertex and triangle
// counts); zlib blocks on up to `threads` threads (0: every core). Through a temporary file and a
// rename. Throws Error.
void write_vtu(const std::string& path, const VtuMesh& vtu,
               VtuEncoding encoding = VtuEncoding::binary_zlib, unsigned threads = 0);

// ---- files that name or hold meshes ------------------------------------------------------------

// import_leaf_mesh (<amc/import.h>) on files (read_mesh: OBJ, OFF, PLY); errors name the files.
ImportedHierarchy import_leaf_mesh_files(const std::string& base_path, const std::string& leaf_path);

// The history file (docs/IMPORT.md, "The history file"): parse_history validates everything and
// names the line of each problem; `what` names the source, `directory` is where a relative base
// path is looked for. format_history writes the base inline (coordinates exactly).
RefinementHistory parse_history(const std::string& text, const std::string& what, const std::string& directory = ".");
RefinementHistory read_history(const std::string& path);
std::string format_history(const RefinementHistory& history);
void write_history(const std::string& path, const RefinementHistory& history);

// ---- leaf meshes of quadtree and octree forests (docs/OCTREE.md) -------------------------------

// The leaves of a forest as a conforming mesh of triangles (2D) or tetrahedra (3D) on the leaves'
// corners plus added centres: every leaf covered exactly once by its cells, no hanging node left
// (a leaf corner on another leaf's edge is a vertex of that leaf's cells), cells meeting face to
// face across leaves and trees (with the trees' orientation; also across periodic gluing, where
// the two sides get separate points in space with the same forest_point). Per leaf (docs/OCTREE.md,
// "Conforming leaf meshes"): 2D, 2 triangles, or 4 + h fanned from the centre when h leaf corners
// lie on its edges; 3D, the cone of the centre over each face's triangles (2 per face, 4 + h when
// h leaf corners lie on its edges, or those of its quarters where the neighbour is finer): 12
// tetrahedra without hanging nodes. Throws Error on an invalid forest (validate_octree_forest).
struct ConformingLeafMesh {
    int dim = 2;                         // 2: triangles, 3: tetrahedra
    std::vector<Vec3> points;            // corner_points leaf corners first, then the added centres
    uint32_t corner_points = 0;
    std::vector<uint32_t> cells;         // dim + 1 points per cell, oriented alike (docs/OCTREE.md)
    std::vector<uint32_t> leaf;          // per cell: the index of its leaf in forest.leaves
    std::vector<uint32_t> forest_point;  // per point: the point of the forest it stands for

    size_t cell_count() const { return leaf.size(); }
};
ConformingLeafMesh conforming_leaf_mesh(const OctreeForest& forest);

enum class OctreeVtuCells {
    leaves,      // VTK_QUAD / VTK_HEXAHEDRON, hanging nodes left as they are
    conforming,  // VTK_TRIANGLE / VTK_TETRA of conforming_leaf_mesh, point array "added_point"
};

// The leaves as VTU cells with cell data "level" and "tree" (and "leaf", the leaf's index, for
// conforming cells) and the forest's leaf fields (each cell has its leaf's values). Leaves: corners
// placed by tree_point, shared within a tree and repeated on tree boundaries. Through a temporary
// file and a rename. Throws Error.
void write_octree_vtu(const std::string& path, const OctreeForest& forest, VtuEncoding encoding = VtuEncoding::binary_zlib,
                      OctreeVtuCells cells = OctreeVtuCells::leaves);

}  // namespace amc
