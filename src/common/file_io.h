// Whole files in and out: the one whole-file read of the library, beside write_file_atomically
// (declared in <amc/mesh.h>).
#pragma once

#include <string>

namespace amc {

// The bytes of the regular file `path`. Throws Error(io) naming the file when it is missing, not
// a regular file, or cannot be read.
std::string read_whole_file(const std::string& path);

}  // namespace amc
