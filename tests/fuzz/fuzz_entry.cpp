// The libFuzzer entry point of one target, chosen at compile time (AMC_FUZZ_TARGET, see
// tests/fuzz/CMakeLists.txt).
#include "fuzz_targets.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    AMC_FUZZ_TARGET(data, size);
    return 0;
}
