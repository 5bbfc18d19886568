// How `amc` reads its inputs and writes its outputs, the conventions of zstd and xz: `-` is
// stdin or stdout, the kind of an input comes from its first bytes, outputs get default names
// and are never overwritten without -f, and every file is written to a temporary name first.
#pragma once

#include <amc/codec.h>
#include <amc/mesh.h>
#include <amc/mesh_io.h>

#include <string>

namespace amc::cli {

// A mistake in how amc was called (exit code 2), as opposed to a problem with the data (1).
class UsageError : public Error {
public:
    using Error::Error;
};

enum class FileKind { compressed, hierarchy, mesh, series };
const char* file_kind_name(FileKind kind);

struct InputFile {
    std::string name;  // the path, or "stdin"
    std::string bytes;
    FileKind kind = FileKind::mesh;
    MeshFormat mesh_format = MeshFormat::obj;  // when kind is mesh
};

// Reads a file, or standard input for "-". The kind comes from the magic bytes (.amc, .amh, .amcs,
// PLY, OFF, VTU); text without a magic word is read as OBJ when the name or content says so. Throws
// Error naming the file when no kind fits.
InputFile read_input(const std::string& path);

// The bytes of an .amq input (a path, or - for stdin), refused on its first bytes where they are
// no .amq header (check_octree_file_start). Errors do not name the input: callers prefix them.
std::string read_octree_input(const std::string& path);

// The input's name with its extension replaced ("-" stays "-").
std::string default_output(const std::string& input, const std::string& extension);

// The format an output path names: a mesh format, .amh, or .amc.
enum class OutputKind { compressed, hierarchy, mesh, other };
OutputKind output_kind(const std::string& path, MeshFormat* mesh_format = nullptr);

// Writes `bytes` to `path` (stdout for "-"), through a temporary file and a rename. An existing
// file is refused unless `force`.
void write_output(const std::string& path, const std::string& bytes, bool force);
// Throws Error when `path` exists: called before long work whose output would be refused.
void refuse_existing(const std::string& path);

// Data read from an InputFile, with the file named in every error.
Hierarchy decode_input(const InputFile& input, const DecodeOptions& options, LeafNumbering* numbering = nullptr);
PartialDecode decode_partial_input(const InputFile& input, const DecodeOptions& options);
Hierarchy hierarchy_of(const InputFile& input);  // .amh
// Refuses a level asked for on the command line (-1: all) that a hierarchy of levels 0..depth
// does not have: decode and extract say it alike (their options' ranges are checked when parsed).
void check_level(const std::string& name, int level, int depth);
TriangleMesh mesh_of(const InputFile& input);

}  // namespace amc::cli
