// Level decoders kept between decodes, so that several threads' working memory is reused rather
// than allocated and faulted in again by every decode: a worker thread's decoder, freed after the
// decode, went back to that thread's malloc arena, which glibc trims, so the next decode's worker
// faulted all its working memory in again (about 4,000 page faults per 2-thread decode of 10^6
// faces; docs/BENCHMARKS.md, "Threads and memory").
#pragma once

#include "coding/hierarchy/hierarchy_level_coder.h"

#include <cstdint>
#include <memory>

namespace amc {

// Callers pool the decoders of chunks up to this many nodes (the default chunk policy's have about
// 6·10^5): the pool then holds at most one such chunk's working memory per core, about 15 bytes a
// node.
constexpr uint64_t kPooledChunkNodes = uint64_t(1) << 20;

// A decoder from the pool (its working memory kept from an earlier decode), or a new one when the
// pool is empty. Restart it before use. Thread-safe.
std::unique_ptr<HierarchyLevelDecoder> take_pooled_decoder();

// Gives back a decoder whose decodes finished: kept while the pool has fewer than one a core, freed
// otherwise. A decoder whose decode threw is dropped instead. Thread-safe.
void return_pooled_decoder(std::unique_ptr<HierarchyLevelDecoder> decoder);

}  // namespace amc
