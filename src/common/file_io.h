// Whole files in and out: the one whole-file read of the library, beside write_file_atomically
// (declared in <amc/mesh.h>).
#pragma once

#include <cstddef>
#include <functional>
#include <istream>
#include <string>

namespace amc {

// What a FirstBytesCheck is given: this many bytes, or all of a shorter input.
inline constexpr size_t kFirstBytes = size_t(1) << 16;
// Throws where an input's first bytes cannot begin a valid one, so that a large or endless input
// of something else is refused before the rest is read.
using FirstBytesCheck = std::function<void(const std::string& first_bytes)>;

// The bytes of the regular file `path`. Throws Error(io) naming the file when it is missing, not
// a regular file, or cannot be read; `check`, when given, sees the first bytes first.
std::string read_whole_file(const std::string& path, const FirstBytesCheck& check = {});

// The bytes of `in` to its end (standard input, a pipe): as read_whole_file, `name` in errors.
std::string read_whole_stream(std::istream& in, const std::string& name, const FirstBytesCheck& check = {});

}  // namespace amc
