// Error codes and the out-of-line throw behind AMC_REQUIRE.
#include "common/check.h"

namespace amc {

const char* error_code_name(ErrorCode code) {
    switch (code) {
        case ErrorCode::invalid_input: return "invalid input";
        case ErrorCode::io: return "I/O";
        case ErrorCode::truncated: return "truncated";
        case ErrorCode::bad_magic: return "bad magic";
        case ErrorCode::unsupported_version: return "unsupported version";
        case ErrorCode::checksum: return "checksum";
        case ErrorCode::corrupt: return "corrupt";
        case ErrorCode::limit_exceeded: return "limit exceeded";
    }
    return "unknown";
}

void throw_error(ErrorCode code, const std::string& message) { throw Error(code, message); }

}  // namespace amc
