// The subcommands of `amc`, each a thin layer over the public API. A command returns normally on
// success and throws Error (exit code 1) or UsageError (exit code 2).
#pragma once

#include <amc/codec.h>
#include <amc/mesh.h>
#include <amc/mesh_io.h>
#include <amc/octree.h>
#include <amc/refinement.h>

#include <cstdint>
#include <string>
#include <vector>

namespace amc::cli {

struct InputFile;

struct GlobalOptions {
    bool force = false;  // overwrite existing outputs
    int verbosity = 1;   // 0 with -q (errors only), 2 with -v
    MeshEncoding mesh_encoding = MeshEncoding::binary;  // PLY and VTU outputs; ascii with --ascii
};

struct EncodeCommand {
    std::string input, output;
    std::string base;             // a mesh input's base mesh; empty: detected
    std::string base_map;         // with base: the leaf vertex of each base vertex (text); empty: by position
    bool keep_numbering = false;  // store the input mesh's own numbering in the file
    std::string map;              // write the numbering map (input -> decoded) here
    int quantize_bits = 0;
    std::string predictor = "auto";
    uint32_t chunks = 0;          // 0: one per chunk_faces faces, fewer for a small code (EncodeOptions)
    uint64_t chunk_faces = EncodeOptions{}.chunk_faces;
    unsigned threads = 0;         // 0: every core
    std::string hierarchy_contexts = "paper";
    std::string geometry_contexts = "grid";  // grid (mode 4 where smaller in quantized files, mode 5 in bit-exact ones) | roles (mode 3 only)
    std::string traversal = "auto";  // the hierarchy coder's order within a level (HierarchyCoderOptions)
    int effort = kDefaultEffort;  // EncodeOptions::effort
    bool series = false;          // the input is a series (.pvd, or a list of VTU files): run_series_encode
};
void run_encode(const EncodeCommand& command, const GlobalOptions& global);

struct DecodeCommand {
    std::string input, output;
    std::string format;          // output format for stdout (obj, off, ply, vtu, amh)
    int level = -1;              // progressive: stop after this level
    bool canonical = false;      // ignore a stored numbering
    bool partial = false;        // a file still arriving: decode the levels whose blocks are complete
    std::string map;             // write the stored numbering map here
    uint64_t max_nodes = 0;      // 0: the library's default limit
    int64_t frame = -1;          // a series: only this frame
    unsigned threads = 0;        // 0: every core
    std::string chunks;          // only these chunks: "0,3-5"
    std::vector<uint32_t> triangles;  // only the chunks holding these base triangles (decoder order)
};
void run_decode(const DecodeCommand& command, const GlobalOptions& global);

struct ImportCommand {
    std::string input, output;
    std::string base;
    std::string base_map;  // as EncodeCommand's
    std::string map;
    unsigned threads = 0;  // 0: every core
};
void run_import(const ImportCommand& command, const GlobalOptions& global);

struct ExtractCommand {
    std::string input, output;
    int level = -1;
    uint64_t max_nodes = 0;
};
void run_extract(const ExtractCommand& command, const GlobalOptions& global);

struct InfoCommand {
    std::string input;
    uint64_t max_nodes = 0;
};
void run_info(const InfoCommand& command, const GlobalOptions& global);

struct RefineCommand {
    std::string input, model = "surface", criterion = "mean", output, leaf_output;
    std::string precision = "input";  // surface models: input | float32 | float64
    bool no_measure = false;          // surface models: skip the remesh report
    uint32_t faces = 150000, base_faces = 500;
    int max_level = 7, levels = 3, steps = 5;
    uint64_t seed = 1;
    uint64_t max_nodes = DecodeOptions{}.max_nodes;  // refused beyond (uniform and random counted before; front: its steps together)
};
void run_refine(const RefineCommand& command, const GlobalOptions& global);

// Series of frames with fields (.amcs), from and to ParaView collections (series_commands.cpp).
struct SeriesEncodeCommand {
    std::vector<std::string> inputs;  // one .pvd, or frame files (VTU with point and cell data, meshes, .amh, .amc)
    std::string output;
    std::string base;                 // base mesh of mesh frames; empty: detected in the first frame
    uint32_t keyframe_interval = 0;
    bool fixed_keyframes = false;     // no encoder-chosen keyframes
    double error_bound = 0;           // absolute, for every float field; 0: bit-exact
    std::vector<std::string> field_bounds;  // NAME=BOUND
};
void run_series_encode(const SeriesEncodeCommand& command, const GlobalOptions& global);

struct SeriesDecodeCommand {
    std::string input, output;
    int64_t frame = -1;     // only this frame (random access)
    int level = -1;         // the mesh of this level
    bool allow_unfinished = false;
    uint64_t max_nodes = 0;
    int64_t max_nodes_per_byte = -1;  // -1: the reader's default; 0: no bound (unpadded files)
};
void run_series_decode(const InputFile& input, const SeriesDecodeCommand& command, const GlobalOptions& global);

struct SeriesInfoCommand {
    std::string input;
    int64_t frame = -1;     // describe this frame's fields (default: frame 0's)
    bool allow_unfinished = false;
    uint64_t max_nodes = 0;
    int64_t max_nodes_per_byte = -1;
};
void run_series_info(const InputFile& input, const SeriesInfoCommand& command, const GlobalOptions& global);

bool is_pvd(const std::string& path);  // a ParaView collection, by its name

// Quadtree and octree forests (.amq, octree_commands.cpp).
struct OctreeMakeCommand {
    int dim = 2, level = 8;
    std::string model = "sphere", trees = "1x1x1", balance = "face", output;
    uint64_t seed = 1;
    bool conforming = false;  // VTU output as triangles / tetrahedra without hanging nodes
    uint64_t max_leaves = OctreeDecodeOptions{}.max_nodes;  // the makers stop with an error beyond
};
void run_octree_make(const OctreeMakeCommand& command, const GlobalOptions& global);
struct OctreeEncodeCommand {
    std::string input, output;  // input: a p4est file (with AMC_WITH_P4EST) or an .amq file
    std::string data;           // p4est user data as fields: NAME:TYPE[:COMPONENTS],... (empty: UInt8 bytes)
    double vertex_step = 0;     // > 0: coarse-mesh vertices on a grid of this step
};
void run_octree_encode(const OctreeEncodeCommand& command, const GlobalOptions& global);
struct OctreeDecodeCommand {
    std::string input, output;  // output: .vtu or .p4est
    int level = -1;
    uint64_t max_nodes = 0;
    int64_t max_octants_per_byte = -1;  // -1: the reader's default; 0: no bound (unpadded files)
    bool conforming = false;  // VTU output as triangles / tetrahedra without hanging nodes
};
void run_octree_decode(const OctreeDecodeCommand& command, const GlobalOptions& global);
struct OctreeInfoCommand {
    std::string input;
    uint64_t max_nodes = 0;
    int64_t max_octants_per_byte = -1;
};
void run_octree_info(const OctreeInfoCommand& command, const GlobalOptions& global);

// The main job on the embedded default (README, first command).
void run_demo(const std::string& out_dir, const GlobalOptions& global);

}  // namespace amc::cli
