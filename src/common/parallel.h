// Runs independent tasks on several threads: the chunks of an .amc file are coded this way. Tasks
// are handed out one at a time from a shared counter, so threads that finish early take the next
// task and chunks of unequal cost still balance. The threads besides the caller's come from the
// process's pool (parallel.cpp): they wait for the next call instead of ending.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <condition_variable>
#include <mutex>
#include <thread>

namespace amc {

// The threads a caller's `threads` option asks for: 0 means every core the machine reports.
inline unsigned resolve_thread_count(unsigned threads) {
    if (threads != 0) return threads;
    const unsigned cores = std::thread::hardware_concurrency();
    return cores == 0 ? 1 : cores;
}

// Calls task(i), never inlined: every task is a frame of its own in a profile (the lambda's type
// names it), also on one thread (scripts/serial_fraction.sh counts what runs outside tasks).
template <class Task>
[[gnu::noinline]] void run_task(Task& task, size_t i) {
    task(i);
}

namespace detail {
// Calls work(context) on up to `helpers` threads of the process's pool at once, woken from their
// wait or started when none waits, and returns at once: wait_for_helpers(group) returns once every
// one of them has returned from it. A thread that can not be had is left out (work() must not
// need it). A group is one call's; any thread may start groups, also from inside work().
class HelperGroup {
public:
    HelperGroup() = default;
    HelperGroup(const HelperGroup&) = delete;
    HelperGroup& operator=(const HelperGroup&) = delete;
    ~HelperGroup() { wait(); }
    void start(size_t helpers, void (*work)(void*), void* context);
    void wait();
    // Called by a helper once its work has returned: the last thing it touches of the group.
    void helper_done();

private:
    std::mutex mutex_;
    std::condition_variable done_;
    size_t running_ = 0;
};
}  // namespace detail

// Calls task(i) for i in [0, count) on up to `threads` threads (the caller's thread is one of
// them, and takes task 0 first). The first exception a task throws is rethrown here once every
// thread has stopped; the tasks not started by then are skipped.
template <class Task>
void parallel_for(size_t count, unsigned threads, Task&& task) {
    const size_t workers = std::min<size_t>(count, std::max(1u, threads));
    if (workers <= 1) {
        for (size_t i = 0; i < count; ++i) run_task(task, i);
        return;
    }
    std::atomic<size_t> next{0};
    std::atomic<bool> failed{false};
    std::exception_ptr error;
    std::mutex error_mutex;
    auto work = [&](size_t i) {
        for (; i < count && !failed; i = next++) {
            try {
                run_task(task, i);
            } catch (...) {
                std::lock_guard<std::mutex> lock(error_mutex);
                if (!error) error = std::current_exception();
                failed = true;
            }
        }
    };
    const size_t first = next++;  // this thread's first task is task 0, however fast the others start
    auto helper_work = [&] { work(next++); };
    {
        detail::HelperGroup helpers;
        helpers.start(workers - 1, [](void* context) { (*static_cast<decltype(helper_work)*>(context))(); }, &helper_work);
        work(first);
    }  // the helpers have returned
    if (error) std::rethrow_exception(error);
}

}  // namespace amc
