// The one way the library refuses bad input (zstd's RETURN_ERROR_IF): AMC_REQUIRE(condition,
// code, message) throws Error(ErrorCode::code, message) when the condition is false. The message,
// any expression that gives a std::string, is built only then and out of line, so a check in a
// hot loop costs a compare, a branch and nothing else.
#pragma once

#include <amc/mesh.h>

#include <new>
#include <stdexcept>
#include <string>

namespace amc {

[[noreturn]] __attribute__((cold, noinline)) void throw_error(ErrorCode code, const std::string& message);

// AMC_REQUIRE's failure: the message is built here, out of line, so that the code that builds it
// stays out of the caller (a hot loop keeps its registers).
template <class MakeMessage>
[[noreturn]] __attribute__((cold, noinline)) void throw_error_with(ErrorCode code, MakeMessage make_message) {
    throw_error(code, make_message());
}

// Runs f(); an allocation that fails inside becomes Error(limit_exceeded) naming `what`, so that
// std::bad_alloc never reaches a caller as such (decoders bound their allocations by the input
// and the caller's limits, so this is a last resort: a machine short of memory).
template <class F>
auto with_allocation_errors_as_limits(const char* what, F&& f) -> decltype(f()) {
    try {
        return f();
    } catch (const std::bad_alloc&) {
        throw_error(ErrorCode::limit_exceeded, std::string(what) + ": out of memory");
    } catch (const std::length_error&) {
        throw_error(ErrorCode::limit_exceeded, std::string(what) + ": out of memory");
    }
}

}  // namespace amc

#define AMC_REQUIRE(condition, code, message)                                                          \
    do {                                                                                               \
        if (__builtin_expect(!(condition), 0))                                                         \
            ::amc::throw_error_with(::amc::ErrorCode::code, [&]() -> std::string { return message; }); \
    } while (0)
