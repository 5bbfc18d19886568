// Runs independent tasks on several threads (std::thread, nothing else): the chunks of an .amc
// file are coded this way. Tasks are handed out one at a time from a shared counter, so threads
// that finish early take the next task and chunks of unequal cost still balance.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <mutex>
#include <system_error>
#include <thread>
#include <vector>

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
    std::vector<std::thread> pool;
    pool.reserve(workers - 1);
    for (size_t t = 1; t < workers; ++t) {
        try {
            pool.emplace_back([&] { work(next++); });
        } catch (const std::system_error&) {  // no more threads to be had: the others do the work
            break;
        }
    }
    work(first);
    for (std::thread& thread : pool) thread.join();
    if (error) std::rethrow_exception(error);
}

}  // namespace amc
