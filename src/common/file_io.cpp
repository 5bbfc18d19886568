// Whole-file reads and atomic writes (common/file_io.h, write_file_atomically in <amc/mesh.h>).
#include "common/file_io.h"

#include <atomic>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include <fcntl.h>
#include <unistd.h>

#include "amc/mesh.h"

namespace amc {

namespace {

// Reads `in` to its end: the first kFirstBytes (or all of a shorter input) are shown to `check`
// before anything more is read or reserved; `size_hint` (0: unknown) is reserved after it.
std::string read_to_end(std::istream& in, const std::string& name, const FirstBytesCheck& check, size_t size_hint) {
    std::string bytes;
    char buffer[1 << 16];
    static_assert(sizeof buffer >= kFirstBytes, "the first bytes arrive in one buffer");
    size_t first = 0;  // the first bytes gathered (a pipe may deliver them in several reads)
    while (first < kFirstBytes && (in.read(buffer + first, std::streamsize(kFirstBytes - first)) || in.gcount() > 0))
        first += size_t(in.gcount());
    if (in.bad()) throw Error(ErrorCode::io, name + ": read error");
    bytes.assign(buffer, first);
    if (check) check(bytes);
    // Room for the size the file has now, so that a large file is not copied as the string grows.
    if (size_hint > bytes.size()) bytes.reserve(size_hint);
    while (in.read(buffer, sizeof buffer) || in.gcount() > 0) bytes.append(buffer, size_t(in.gcount()));
    if (in.bad()) throw Error(ErrorCode::io, name + ": read error");
    return bytes;
}

}  // namespace

std::string read_whole_file(const std::string& path, const FirstBytesCheck& check) {
    std::error_code ec;
    const std::filesystem::file_status status = std::filesystem::status(path, ec);
    if (ec || !std::filesystem::exists(status)) {
        throw Error(ErrorCode::io, path + ": cannot open file (" +
                    (ec ? ec.message() : std::string("No such file or directory")) + ")");
    }
    if (!std::filesystem::is_regular_file(status)) throw Error(ErrorCode::io, path + ": not a regular file");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(ErrorCode::io, path + ": cannot open file (" + std::strerror(errno) + ")");
    const std::uintmax_t size = std::filesystem::file_size(path, ec);
    return read_to_end(in, path, check, ec ? 0 : size_t(size));
}

std::string read_whole_stream(std::istream& in, const std::string& name, const FirstBytesCheck& check) {
    return read_to_end(in, name, check, 0);
}

void write_file_atomically(const std::string& path, const std::string& bytes) {
    // A name no other call uses, in this process or another, in the directory of `path`, so that
    // the rename stays within one file system.
    static std::atomic<uint64_t> calls{0};
    const std::string temp = path + ".tmp." + std::to_string(static_cast<long>(::getpid())) + "." +
                             std::to_string(calls.fetch_add(1, std::memory_order_relaxed));
    const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd < 0) throw Error(ErrorCode::io, path + ": cannot create " + temp + " (" + std::strerror(errno) + ")");
    auto fail = [&](const std::string& what, int error) {
        if (fd >= 0) ::close(fd);
        ::unlink(temp.c_str());
        throw Error(ErrorCode::io, path + ": " + what + " (" + std::strerror(error) + ")");
    };
    for (size_t done = 0; done < bytes.size();) {
        const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) fail("cannot write file", n < 0 ? errno : EIO);
        done += size_t(n);
    }
    // On the disk before the rename: after a crash of the machine too, the path holds the old file
    // or the whole new one.
    if (::fsync(fd) != 0) fail("cannot write file", errno);
    if (::close(fd) != 0) {
        const int error = errno;
        ::unlink(temp.c_str());
        throw Error(ErrorCode::io, path + ": cannot write file (" + std::strerror(error) + ")");
    }
    if (::rename(temp.c_str(), path.c_str()) != 0) {
        const int error = errno;
        ::unlink(temp.c_str());
        throw Error(ErrorCode::io, path + ": cannot rename " + temp + " to it (" + std::strerror(error) + ")");
    }
}

}  // namespace amc
