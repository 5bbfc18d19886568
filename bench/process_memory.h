// What bench/memory_peak and bench/scaling_bench read of their own process (Linux only): the
// resident set now and at its peak, the peak reset, and a file read at its exact size.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

// A field of /proc/self/status in MiB (VmRSS: now, VmHWM: the peak since the last reset); -1 if absent.
inline double status_mib(const char* field) {
    std::ifstream in("/proc/self/status");
    std::string line;
    const size_t length = std::strlen(field);
    while (std::getline(in, line))
        if (line.compare(0, length, field) == 0 && line[length] == ':') return std::atof(line.c_str() + length + 1) / 1024.0;
    return -1;
}

// Sets the peak to what is resident now (Linux 4.0 and later).
inline void reset_peak() {
    std::ofstream clear("/proc/self/clear_refs");
    clear << "5";
}

// The file's bytes in a vector of exactly its size, as amc's read_whole_file reserves them: a
// vector grown by doubling would leave slack and raise glibc's threshold for mapping large
// blocks, and with it the peaks measured after. Exits naming the file if it can not be read.
inline std::vector<char> read_exact(const char* path) {
    std::ifstream in(path, std::ios::binary | std::ios::ate);
    if (!in) {
        std::fprintf(stderr, "can not read %s\n", path);
        std::exit(1);
    }
    std::vector<char> bytes(size_t(in.tellg()));
    in.seekg(0);
    if (!in.read(bytes.data(), std::streamsize(bytes.size()))) {
        std::fprintf(stderr, "can not read %s\n", path);
        std::exit(1);
    }
    return bytes;
}
