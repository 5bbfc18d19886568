// The processor's counters of the calling thread in user space (cycles, instructions, branch
// misses), where Linux allows it: unlike time, they hardly move when other virtual machines load
// the host, so two builds or two formats can be compared with few runs.
#pragma once

#include <cstdint>

#if defined(__linux__)
#include <linux/perf_event.h>
#include <sys/syscall.h>
#include <unistd.h>
#endif

constexpr int kCounters = 3;
const char* const kCounterNames[kCounters] = {"cycles", "instructions", "branch misses"};

// The user-space counters of this thread, or none where perf events are not available.
class Counters {
public:
    Counters() {
#if defined(__linux__)
        const uint64_t configs[kCounters] = {PERF_COUNT_HW_CPU_CYCLES, PERF_COUNT_HW_INSTRUCTIONS,
                                             PERF_COUNT_HW_BRANCH_MISSES};
        for (int k = 0; k < kCounters; ++k) {
            perf_event_attr attr{};
            attr.type = PERF_TYPE_HARDWARE;
            attr.size = sizeof(attr);
            attr.config = configs[k];
            attr.exclude_kernel = 1;
            attr.exclude_hv = 1;
            fd_[k] = int(syscall(SYS_perf_event_open, &attr, 0, -1, -1, 0));
        }
#endif
    }
    ~Counters() {
#if defined(__linux__)
        for (int fd : fd_) {
            if (fd >= 0) close(fd);
        }
#endif
    }
    bool available() const { return fd_[0] >= 0; }
    void read_all(double out[kCounters]) const {
        for (int k = 0; k < kCounters; ++k) {
            uint64_t value = 0;
#if defined(__linux__)
            if (fd_[k] < 0 || read(fd_[k], &value, sizeof(value)) != sizeof(value)) value = 0;
#endif
            out[k] = double(value);
        }
    }

private:
    int fd_[kCounters] = {-1, -1, -1};
};
