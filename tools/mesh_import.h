// Meshes as users have them, turned into hierarchies for `amc encode` and `amc import`, and the
// numbering map that ties the user's vertex and face numbers to the decoded leaf mesh.
#pragma once

#include "cli_files.h"
#include "commands.h"

#include <amc/numbering.h>

#include <string>
#include <vector>

namespace amc::cli {

struct ImportedMesh {
    Hierarchy hierarchy;
    LeafNumbering numbering;  // with_numbering: the input mesh's numbering against extract_leaf_mesh(hierarchy)
};

// A mesh input over the base mesh in `base_path` (its vertices matched to the input's by the map
// in `base_map_path`, or by position when that is empty), or over the coarsest base found in it.
// The input's bytes are let go once read: a large text mesh's file is larger than the mesh. The
// numbering only `with_numbering` (an encoder given one keeps the input's order, a slower path).
ImportedMesh import_input(InputFile& input, const std::string& base_path, const std::string& base_map_path, unsigned threads,
                          const GlobalOptions& global, bool with_numbering);

// A base vertex map file (docs/IMPORT.md, "The base vertex map"): for each base vertex, in order,
// the 0-based index of its leaf vertex, as decimal integers separated by white space; lines
// starting with # are comments. Throws Error naming the file and line of anything else.
std::vector<uint32_t> parse_base_map(const std::string& text, const std::string& name);

// The map as text (docs/IMPORT.md, "The numbering map"): for every input vertex its leaf vertex,
// for every input face its leaf triangle and rotation.
std::string format_numbering_map(const LeafNumbering& numbering);

}  // namespace amc::cli
