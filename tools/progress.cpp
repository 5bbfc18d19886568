// The progress line of `amc` (see progress.h).
#include "progress.h"

#include <cstdio>

#include <unistd.h>

namespace amc::cli {

namespace {

constexpr auto kDelay = std::chrono::seconds(1);             // quiet for work shorter than this
constexpr auto kRedraw = std::chrono::milliseconds(250);

}  // namespace

Progress::Progress(bool enabled) : active_(enabled && ::isatty(STDERR_FILENO)) {
    if (active_) thread_ = std::thread([this] { run(); });
}

Progress::~Progress() { finish(); }

void Progress::finish() {
    if (!active_) return;
    active_ = false;
    {
        std::lock_guard<std::mutex> lock(mutex_);
        stop_ = true;
    }
    wake_.notify_one();
    thread_.join();
    if (drawn_) std::fprintf(stderr, "\r\033[K");
}

void Progress::phase(const std::string& name) {
    if (!active_) return;
    std::lock_guard<std::mutex> lock(mutex_);
    phase_ = name;
    phase_start_ = std::chrono::steady_clock::now();
}

void Progress::run() {
    std::unique_lock<std::mutex> lock(mutex_);
    while (!stop_) {
        wake_.wait_for(lock, kRedraw);
        if (stop_ || phase_.empty()) continue;
        const auto elapsed = std::chrono::steady_clock::now() - phase_start_;
        if (elapsed < kDelay) continue;
        std::fprintf(stderr, "\r\033[Kamc: %s ... %.0f s", phase_.c_str(), std::chrono::duration<double>(elapsed).count());
        std::fflush(stderr);
        drawn_ = true;
    }
}

}  // namespace amc::cli
