// The per-process key of common/keyed_hash.h.
#include "common/keyed_hash.h"

#include <chrono>
#include <random>

namespace amc {

uint64_t process_hash_key() {
    static const uint64_t key = [] {
        uint64_t drawn = 0;
        try {
            std::random_device device;
            drawn = uint64_t(device()) << 32 | device();
        } catch (...) {  // no entropy source: the clock and where this process's stack lies still vary
        }
        int on_stack = 0;
        const uint64_t clock = uint64_t(std::chrono::steady_clock::now().time_since_epoch().count());
        return splitmix64_mix(drawn ^ splitmix64_mix(clock ^ uint64_t(reinterpret_cast<uintptr_t>(&on_stack))));
    }();
    return key;
}

}  // namespace amc
