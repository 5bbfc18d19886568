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

std::string read_whole_file(const std::string& path) {
    std::error_code ec;
    const std::filesystem::file_status status = std::filesystem::status(path, ec);
    if (ec || !std::filesystem::exists(status)) {
        throw Error(ErrorCode::io, path + ": cannot open file (" +
                    (ec ? ec.message() : std::string("No such file or directory")) + ")");
    }
    if (!std::filesystem::is_regular_file(status)) throw Error(ErrorCode::io, path + ": not a regular file");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(ErrorCode::io, path + ": cannot open file (" + std::strerror(errno) + ")");
    std::string bytes;
    // Room for the size the file has now, so that a large file is not copied as the string grows.
    const std::uintmax_t size = std::filesystem::file_size(path, ec);
    if (!ec) bytes.reserve(size_t(size));
    char buffer[1 << 16];
    while (in.read(buffer, sizeof buffer) || in.gcount() > 0) bytes.append(buffer, in.gcount());
    if (in.bad()) throw Error(ErrorCode::io, path + ": read error");
    return bytes;
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
