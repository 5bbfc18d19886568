// Level decoders kept between decodes, so that their working memory is reused rather than
// allocated and faulted in again by every decode: a worker thread's decoder, freed after the
// decode, went back to that thread's malloc arena, which glibc trims, so the next decode's worker
// faulted all its working memory in again (about 4,000 page faults per 2-thread decode of 10^6
// faces; docs/BENCHMARKS.md, "Threads and memory"). Used by several threads' chunk decoders and by
// files without chunks; one thread's chunks decode lean instead (ChunkPlace::last).
#pragma once

#include "coding/hierarchy/hierarchy_level_coder.h"

#include <cstdint>
#include <exception>
#include <memory>

namespace amc {

// Callers pool the decoders of chunks (or files without chunks) up to this many nodes (the default
// chunk policy's have about 6·10^5): the pool then holds at most one such chunk's working memory
// per core, about 15 bytes a node.
constexpr uint64_t kPooledChunkNodes = uint64_t(1) << 20;

// A decoder from the pool (its working memory kept from an earlier decode), or a new one when the
// pool is empty. Restart it before use. Thread-safe.
std::unique_ptr<HierarchyLevelDecoder> take_pooled_decoder();

// Gives back a decoder whose decodes finished: kept while the pool has fewer than one a core, freed
// otherwise. A decoder whose decode threw is dropped instead. Thread-safe.
void return_pooled_decoder(std::unique_ptr<HierarchyLevelDecoder> decoder);

// A decoder from the pool for one scope, given back at its end when `keep` and no exception is
// leaving the scope.
class PooledDecoder {
public:
    explicit PooledDecoder(bool keep) : decoder_(take_pooled_decoder()), keep_(keep), exceptions_(std::uncaught_exceptions()) {}
    ~PooledDecoder() {
        if (keep_ && std::uncaught_exceptions() == exceptions_) return_pooled_decoder(std::move(decoder_));
    }
    PooledDecoder(const PooledDecoder&) = delete;
    PooledDecoder& operator=(const PooledDecoder&) = delete;
    HierarchyLevelDecoder& operator*() { return *decoder_; }

private:
    std::unique_ptr<HierarchyLevelDecoder> decoder_;
    bool keep_;
    int exceptions_;
};

}  // namespace amc
