// Progress on stderr for work that takes more than about a second: the current phase and the time
// spent, redrawn in place. Only on a terminal and never with -q, so pipes and logs stay clean.
#pragma once

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <string>
#include <thread>

namespace amc::cli {

class Progress {
public:
    // Shows nothing unless `enabled` and stderr is a terminal.
    explicit Progress(bool enabled);
    ~Progress();  // finish()
    Progress(const Progress&) = delete;
    Progress& operator=(const Progress&) = delete;

    // Starts a phase ("importing leaf.vtu"); its line appears once it has run for a second.
    void phase(const std::string& name);
    // Stops and clears the line: call before printing results.
    void finish();

private:
    void run();

    bool active_ = false;
    std::mutex mutex_;
    std::condition_variable wake_;
    std::string phase_;
    std::chrono::steady_clock::time_point phase_start_;
    bool stop_ = false;
    bool drawn_ = false;
    std::thread thread_;
};

}  // namespace amc::cli
