// Growing the coder's large scratch arrays without paying a page fault per 4 KiB: on Linux the
// fresh part of a large buffer is offered to transparent huge pages (a hint; harmless elsewhere).
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#if defined(__GLIBC__)
#include <malloc.h>
#endif
#if defined(__linux__)
#include <sys/mman.h>
#include <unistd.h>
#endif

namespace amc {

#if defined(__linux__)
namespace detail {
// madvise(advice) on the whole `alignment`-aligned blocks inside [begin, begin + bytes).
inline void advise_aligned(const void* begin, size_t bytes, uintptr_t alignment, int advice) {
    const uintptr_t a = (reinterpret_cast<uintptr_t>(begin) + alignment - 1) & ~(alignment - 1);
    const uintptr_t b = (reinterpret_cast<uintptr_t>(begin) + bytes) & ~(alignment - 1);
    if (b > a) madvise(reinterpret_cast<void*>(a), b - a, advice);
}

// madvise(advice) on the whole system pages inside [begin, begin + bytes).
inline void advise_whole_pages(const void* begin, size_t bytes, int advice) {
    static const uintptr_t page = uintptr_t(sysconf(_SC_PAGESIZE));
    advise_aligned(begin, bytes, page, advice);
}
}  // namespace detail
#endif

// Which buffers are offered to huge pages. Scratch that grows and may be touched in part only
// from 8 MiB on, so that a small array does not make 2 MiB resident for a few pages; an array
// that one pass writes whole as soon as it is made (the encoder's reordered copy and chunks) from
// one huge page on: none of its huge pages stays partly untouched, and on the project's VM a
// 4 KiB page fault costs 15-25 us (docs/BENCHMARKS.md, "Threads and memory").
enum class HugePages { large_scratch, written_whole };

constexpr size_t kHugePage = size_t(2) << 20;

// glibc's header before a block's bytes: a block that malloc maps on its own starts this far into
// its mapping (glibc's mmapped chunks; elsewhere the rounding below only costs some address space).
constexpr size_t kMallocHeader = 16;

// The bytes to ask for an array of at least `bytes` that is written whole: from one huge page on,
// a whole number of huge pages less malloc's header, so that a block malloc maps on its own fills
// its mapping, whose length the kernel then aligns to a huge page (Linux 6.7 on). Its first and
// last huge pages are then whole too, where a block at any offset pays up to 2 x 512 4 KiB faults.
inline size_t written_whole_bytes(size_t bytes) {
    if (bytes < kHugePage) return bytes;
    return (bytes + 2 * kMallocHeader + kHugePage - 1) / kHugePage * kHugePage - 2 * kMallocHeader;  // >= bytes
}

inline void advise_huge_pages(const void* begin, size_t bytes, HugePages kind = HugePages::large_scratch) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    if (bytes < (kind == HugePages::written_whole ? kHugePage : 4 * kHugePage)) return;
    const uintptr_t at = reinterpret_cast<uintptr_t>(begin);
    if (kind == HugePages::written_whole && at % kHugePage == kMallocHeader) {
        // A mapping of its own (written_whole_bytes): all of it, the header's huge page included,
        // which malloc faulted in as a 4 KiB page when it wrote the header (collapsed: Linux 6.1 on).
        void* const mapping = reinterpret_cast<void*>(at - kMallocHeader);
        const size_t length = (bytes + kMallocHeader + kHugePage - 1) / kHugePage * kHugePage;
        madvise(mapping, length, MADV_HUGEPAGE);
#if defined(MADV_COLLAPSE)
        madvise(mapping, kHugePage, MADV_COLLAPSE);
#else
        madvise(mapping, kHugePage, 25);  // MADV_COLLAPSE, where the C library's headers predate it
#endif
        return;
    }
    detail::advise_aligned(begin, bytes, kHugePage, MADV_HUGEPAGE);
#else
    (void)begin;
    (void)bytes;
    (void)kind;
#endif
}

// Gives the whole pages inside [begin, begin + bytes) back to the system (Linux; elsewhere
// nothing): they stop counting as resident until written again, and then read as zeros. For
// working memory whose contents are dead, so that what a decoder writes next does not add to it.
inline void release_pages(void* begin, size_t bytes) {
#if defined(__linux__) && defined(MADV_DONTNEED)
    detail::advise_whole_pages(begin, bytes, MADV_DONTNEED);
#else
    (void)begin;
    (void)bytes;
#endif
}

// Gives the allocator's free memory back to the system (glibc: malloc_trim; elsewhere nothing):
// for a process that decodes once, where no later allocation would have reused it.
inline void release_free_heap() {
#if defined(__GLIBC__)
    malloc_trim(0);
#endif
}

// Faults in the whole pages inside [begin, begin + bytes) as writable, zeroed, without writing
// them (Linux 5.14 on; elsewhere nothing): memory that one thread makes resident before others
// write it, since two threads faulting fresh pages in at once take several times as long on the
// project's VM (docs/BENCHMARKS.md, "Threads and memory"). One huge page a call: each call holds
// the process's memory map lock, and another thread's brk, mprotect or madvise waited for a whole
// array's call (up to 5 ms).
inline void populate_pages(void* begin, size_t bytes) {
#if defined(__linux__) && defined(MADV_POPULATE_WRITE)
    const uintptr_t end = reinterpret_cast<uintptr_t>(begin) + bytes;
    for (uintptr_t at = reinterpret_cast<uintptr_t>(begin); at < end;) {
        // Cut at huge pages (so at whole pages): the same pages as one call.
        const uintptr_t next = std::min<uintptr_t>(end, (at + kHugePage) & ~uintptr_t(kHugePage - 1));
        detail::advise_whole_pages(reinterpret_cast<void*>(at), size_t(next - at), MADV_POPULATE_WRITE);
        at = next;
    }
#else
    (void)begin;
    (void)bytes;
#endif
}

// An array of at least `count` T left unset (no pass of zeros), sized and offered to huge pages as
// written whole: for arrays whose every entry a pass writes before any is read.
template <class T>
std::unique_ptr<T[]> written_whole_array(size_t count) {
    const size_t bytes = written_whole_bytes(count * sizeof(T));
    std::unique_ptr<T[]> array(new T[bytes / sizeof(T)]);
    advise_huge_pages(array.get(), bytes, HugePages::written_whole);
    return array;
}

// v.reserve(capacity), with the whole new buffer offered to huge pages before the old contents
// are copied in, so that the copy itself faults in huge pages rather than 4 KiB ones.
template <class T>
void reserve_huge(std::vector<T>& v, size_t capacity, HugePages kind = HugePages::large_scratch) {
    if (capacity <= v.capacity()) return;
    if (kind == HugePages::written_whole) capacity = written_whole_bytes(capacity * sizeof(T)) / sizeof(T);
    std::vector<T> fresh;
    fresh.reserve(capacity);
    advise_huge_pages(fresh.data(), fresh.capacity() * sizeof(T), kind);
    fresh.insert(fresh.end(), v.begin(), v.end());
    v.swap(fresh);
}

// The capacity scratch storage grows to for n elements: at least double, so a sequence of
// growing levels reallocates a logarithmic number of times.
inline size_t grown_capacity(size_t n, size_t capacity) { return n > 2 * capacity ? n : 2 * capacity; }

// v.resize(n), reallocating (without copying the old contents) when it must, so a sequence of
// growing levels faults in each page once.
template <class T>
void resize_scratch(std::vector<T>& v, size_t n) {
    if (n > v.capacity()) {
        v.clear();
        reserve_huge(v, grown_capacity(n, v.capacity()));
    }
    v.resize(n);
}

// Scratch storage for trivial types that a pass fills before reading: grows (geometrically, without
// keeping the old contents) and is never zero-filled, unlike std::vector::resize.
template <class T>
class ScratchArray {
public:
    // Room for at least n elements, contents unspecified.
    T* reserve(size_t n) {
        if (n > capacity_) {
            const size_t capacity = grown_capacity(n, capacity_);
            data_.reset(new T[capacity]);  // default-initialized: no writes
            capacity_ = capacity;
            advise_huge_pages(data_.get(), capacity * sizeof(T));
        }
        return data_.get();
    }
    T* data() { return data_.get(); }
    size_t capacity() const { return capacity_; }
    const T* data() const { return data_.get(); }
    // Gives the pages past element n back to the system (release_pages); the capacity stays.
    void release_from(size_t n) {
        if (n < capacity_) release_pages(data_.get() + n, (capacity_ - n) * sizeof(T));
    }
    // Gives the storage back to the allocator: capacity 0.
    void deallocate() {
        data_.reset();
        capacity_ = 0;
    }
    // deallocate() when the storage holds more than kShrinkFactor times n elements: scratch for a
    // level much smaller than the largest before keeps no more than it needs resident.
    static constexpr size_t kShrinkFactor = 2;
    void shrink_for(size_t n) {
        if (capacity_ > kShrinkFactor * n) deallocate();
    }

private:
    std::unique_ptr<T[]> data_;
    size_t capacity_ = 0;
};

}  // namespace amc
