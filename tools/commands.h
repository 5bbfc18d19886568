// The subcommands of `amc`, each a thin layer over the public API. A command returns normally on
// success and throws Error (exit code 1) or UsageError (exit code 2).
#pragma once

#include <amc/refinement.h>

#include <cstdint>
#include <string>
#include <vector>

namespace amc::cli {

struct GlobalOptions {
    bool force = false;  // overwrite existing outputs
    int verbosity = 1;   // 0 with -q (errors only), 2 with -v
};

struct EncodeCommand {
    std::string input, output;
    std::string base;             // a mesh input's base mesh; empty: detected
    bool keep_numbering = false;  // store the input mesh's own numbering in the file
    std::string map;              // write the numbering map (input -> decoded) here
    int quantize_bits = 0;
    std::string predictor = "auto";
};
void run_encode(const EncodeCommand& command, const GlobalOptions& global);

struct DecodeCommand {
    std::string input, output;
    std::string format;          // output format for stdout (obj, off, ply, vtu, amh)
    int level = -1;              // progressive: stop after this level
    bool canonical = false;      // ignore a stored numbering
    std::string map;             // write the stored numbering map here
    uint64_t max_nodes = 0;      // 0: the library's default limit
};
void run_decode(const DecodeCommand& command, const GlobalOptions& global);

struct ImportCommand {
    std::string input, output;
    std::string base;
    std::string map;
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
    uint32_t faces = 150000, base_faces = 500;
    int max_level = 7, levels = 3, steps = 5;
    uint64_t seed = 1;
};
void run_refine(const RefineCommand& command, const GlobalOptions& global);

// The main job on the embedded default (README, first command).
void run_demo(const std::string& out_dir, const GlobalOptions& global);

}  // namespace amc::cli
