// How many chunks the encoder cuts a forest into when the caller does not say (EncodeOptions::chunks
// 0, no chunk_roots): one per `chunk_faces` leaf faces, then fewer when the chunked code turns out
// to hold less than `min_chunk_bytes` per chunk and coding it again removes a quarter of the chunks
// or more. Each chunk costs bytes that a file of one chunk does not pay (the seam's vertices
// predicted by their segment's midpoint alone, worse predictions next to the seam, fresh adaptive
// models, a header and framing), about the same whatever the rest of the chunk holds; docs/CODEC.md,
// "Chunks", gives the cost per model.
#pragma once

#include <amc/codec.h>

#include <cstdint>

namespace amc {

// The chunk count EncodeOptions ask for a hierarchy of `faces` leaf faces (before its code is known).
uint32_t chunk_count_for(const EncodeOptions& options, uint64_t faces);

// The chunk count once the forest's code in `chunks` chunks (chunk_count_for's) is known to take
// `bytes`: one chunk per min_chunk_bytes of the code (at least one) when that is at most three
// quarters of `chunks`, and the encoder codes the forest again; otherwise `chunks`, whose code
// then holds more than 3/4 of min_chunk_bytes per chunk.
uint32_t chunk_count_for_size(const EncodeOptions& options, uint32_t chunks, uint64_t bytes);

}  // namespace amc
