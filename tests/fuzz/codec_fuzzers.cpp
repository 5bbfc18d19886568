// Fuzz targets of the .amc file: decode (whole, through a kept DecodeContext, every prefix of
// levels, and encoded again) and inspect, each on the input as it is and with its checksums made valid, so that mutations reach
// the payload decoders behind the checksums.
#include "fuzz_targets.h"

#include "coding/chunks/chunk_layout.h"

#include <amc/codec.h>
#include <amc/refinement.h>

#include <algorithm>

namespace amc::fuzz {
namespace {

// Keeps a run short and its memory small (a node takes about 40 bytes): most of the time goes to
// the decoders' checks, not to building large hierarchies.
constexpr uint64_t kMaxNodes = uint64_t(1) << 16;

// One chunk of a file that decodes whole decodes alone, to the same trees as the whole's.
void check_one_chunk(const uint8_t* data, size_t size, const Hierarchy& whole, const DecodeOptions& options) {
    const FileInfo info = inspect(data, size);  // throws: a finding
    if (info.chunks.size() < 2) return;
    const uint32_t c = uint32_t(size % info.chunks.size());
    const ChunkDecode part = decode_chunks(data, size, {c}, options);  // throws: a finding
    const std::vector<RootRange> roots{{info.chunks[c].first_root, info.chunks[c].roots}};
    FUZZ_CHECK(check_invariants(part.hierarchy).empty());
    FUZZ_CHECK(identical(part.hierarchy, extract_roots(whole, roots)));
}

// A DecodeContext kept from input to input (as a caller decoding many files keeps one): what it
// carries from one decode to the next must change no result and no refusal.
void check_through_context(const uint8_t* data, size_t size, const DecodeOptions& options, const Hierarchy* whole,
                           const LeafNumbering& numbering, ErrorCode refused) {
    static DecodeContext context;
    LeafNumbering kept_numbering;
    try {
        const Hierarchy h = decode(context, data, size, options, &kept_numbering);
        FUZZ_CHECK(whole != nullptr && identical(h, *whole));
        FUZZ_CHECK(kept_numbering.vertex == numbering.vertex && kept_numbering.face == numbering.face &&
                   kept_numbering.rotation == numbering.rotation);
    } catch (const Error& e) {
        FUZZ_CHECK(whole == nullptr && e.code() == refused);
    }
}

void decode_file(const uint8_t* data, size_t size) {
    DecodeOptions options;
    options.max_nodes = kMaxNodes;
    options.threads = 1;  // one thread: steadier runs; ThreadSanitizer covers the threads in CI
    LeafNumbering numbering;
    Hierarchy h;
    try {
        h = decode(data, size, options, &numbering);
    } catch (const Error& e) {
        check_through_context(data, size, options, nullptr, numbering, e.code());
        // Refused whole, its first levels may still decode (or be refused as well).
        options.max_level = int(size % 5);
        try {
            decode(data, size, options);
        } catch (const Error&) {
        }
        return;
    }
    check_through_context(data, size, options, &h, numbering, ErrorCode{});
    FUZZ_CHECK(check_invariants(h).empty());
    check_one_chunk(data, size, h, options);
    if (!numbering.empty()) {
        FUZZ_CHECK(check_numbering(numbering, h.vertex_count(), extract_leaf_mesh(h).mesh.triangles.size()).empty());
    }
    // A prefix of levels decodes, to the first levels of the whole (one cut a run, chosen by the
    // input, keeps valid files as quick as broken ones).
    const std::vector<uint32_t> levels = compute_stats(h).nodes_per_level;
    {
        const int cut = int(size % size_t(h.depth() + 2));
        options.max_level = cut;
        const Hierarchy prefix = decode(data, size, options);  // throws: a finding
        const std::vector<uint32_t> prefix_levels = compute_stats(prefix).nodes_per_level;
        FUZZ_CHECK(prefix_levels.size() == std::min(levels.size(), size_t(cut) + 1));
        FUZZ_CHECK(std::equal(prefix_levels.begin(), prefix_levels.end(), levels.begin()));
    }
    // What the decoder accepts the encoder accepts, and the file it writes decodes to it.
    EncodeOptions fixed;
    fixed.predictor = GeometryPredictor::midpoint;  // no trial encodings
    fixed.threads = 1;
    const std::vector<uint8_t> again = encode(h, fixed);
    DecodeOptions whole;
    whole.threads = 1;
    FUZZ_CHECK(identical(decode(again.data(), again.size(), whole), in_decoder_order(h)));
}

void inspect_file(const uint8_t* data, size_t size) {
    FileInfo info;
    try {
        info = inspect(data, size);
    } catch (const Error&) {
        return;
    }
    uint64_t total = 12;
    for (const FileBlock& block : info.blocks) total += block.size;
    FUZZ_CHECK(total == size);
    FUZZ_CHECK(!info.blocks.empty() && info.blocks.back().name == "end");
}

}  // namespace

void amc_decode(const uint8_t* data, size_t size) {
    decode_file(data, size);
    const std::vector<uint8_t> repaired = with_valid_checksums(data, size);
    if (!std::equal(repaired.begin(), repaired.end(), data)) decode_file(repaired.data(), repaired.size());
}

void amc_inspect(const uint8_t* data, size_t size) {
    inspect_file(data, size);
    const std::vector<uint8_t> repaired = with_valid_checksums(data, size);
    if (!std::equal(repaired.begin(), repaired.end(), data)) inspect_file(repaired.data(), repaired.size());
}

}  // namespace amc::fuzz
