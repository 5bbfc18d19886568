// The process's pool of helper threads for parallel_for (parallel.h).
#include "common/parallel.h"

#include <system_error>
#include <vector>

#if defined(__unix__)
#include <pthread.h>
#endif

namespace amc::detail {

namespace {

// A helper thread and the work it is handed, guarded by its mutex.
struct PoolThread {
    std::mutex mutex;
    std::condition_variable wake;
    void (*work)(void*) = nullptr;  // set: run it once, then wait again
    void* context = nullptr;
    HelperGroup* group = nullptr;
};

// Helpers waiting for work. Kept between calls because a new thread per call costs more than its
// start: its malloc arena is another one each time, and the working memory a helper allocated
// was trimmed and had to be faulted in again by the next call (docs/BENCHMARKS.md, "Threads and
// memory"); a helper that waits keeps its arena, as the calling thread keeps its own.
struct Pool {
    std::mutex mutex;
    std::vector<PoolThread*> idle;  // the last one to finish at the back, taken first
};

// More idle helpers than this end instead of waiting (a burst of calls from many threads).
constexpr size_t kMaxIdle = 64;

// Never destroyed: helpers wait in it until the process ends. A forked child has none of the
// parent's threads: it starts on a pool of its own.
Pool*& the_pool() {
    static Pool* pool = [] {
#if defined(__unix__)
        pthread_atfork(nullptr, nullptr, [] { the_pool() = new Pool; });
#endif
        return new Pool;
    }();
    return pool;
}

// Back to the idle helpers; false when there are enough of them (the thread then ends).
bool park(PoolThread* self) {
    Pool& pool = *the_pool();
    std::lock_guard<std::mutex> lock(pool.mutex);
    if (pool.idle.size() >= kMaxIdle) return false;
    pool.idle.push_back(self);
    return true;
}

void serve(PoolThread* self) {
    std::unique_lock<std::mutex> lock(self->mutex);
    for (;;) {
        self->wake.wait(lock, [self] { return self->work != nullptr; });
        void (*work)(void*) = self->work;
        void* const context = self->context;
        HelperGroup* const group = self->group;
        self->work = nullptr;
        lock.unlock();
        work(context);
        const bool kept = park(self);  // before helper_done: the group's caller may start the next call at once
        group->helper_done();
        if (!kept) {
            delete self;
            return;
        }
        lock.lock();
    }
}

}  // namespace

void HelperGroup::start(size_t helpers, void (*work)(void*), void* context) {
    for (size_t k = 0; k < helpers; ++k) {
        PoolThread* thread = nullptr;
        {
            Pool& pool = *the_pool();
            std::lock_guard<std::mutex> lock(pool.mutex);
            if (!pool.idle.empty()) {
                thread = pool.idle.back();
                pool.idle.pop_back();
            }
        }
        {
            std::lock_guard<std::mutex> lock(mutex_);
            ++running_;
        }
        if (thread != nullptr) {
            {
                std::lock_guard<std::mutex> lock(thread->mutex);
                thread->work = work;
                thread->context = context;
                thread->group = this;
            }
            thread->wake.notify_one();
            continue;
        }
        thread = new PoolThread;
        thread->work = work;
        thread->context = context;
        thread->group = this;
        try {
            std::thread(serve, thread).detach();
        } catch (const std::system_error&) {  // no more threads to be had: the others do the work
            delete thread;
            helper_done();
            return;
        }
    }
}

void HelperGroup::wait() {
    std::unique_lock<std::mutex> lock(mutex_);
    done_.wait(lock, [this] { return running_ == 0; });
}

void HelperGroup::helper_done() {
    // Notified under the lock: once wait() sees zero the group may go, and this thread no longer
    // touches it.
    std::lock_guard<std::mutex> lock(mutex_);
    if (--running_ == 0) done_.notify_all();
}

}  // namespace amc::detail
