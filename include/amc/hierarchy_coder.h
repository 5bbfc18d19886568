// The hierarchy coder (paper, sections II-B to II-E): the refinement forest of a red-green
// hierarchy as one "refined?" symbol per node, level by level, with every symbol the refinement
// rules imply culled, the rest coded by an adaptive binary arithmetic coder in context groups,
// in an order that codes well-informed nodes first. The base mesh is not part of this stream:
// encoder and decoder share it (the container codes it separately).
#pragma once

#include <amc/hierarchy.h>

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace amc {

enum class Traversal : uint8_t {
    naive = 0,     // each level in canonical order (children in child order)
    improved = 1,  // each level by priority: culled nodes first, then nodes with most coded neighbours
};

// Every switch of the coder; the defaults are the paper's complete method. The switches exist for
// ablation (Table 1) and are recorded in the stream, so any combination decodes.
struct HierarchyCoderOptions {
    bool cull_one_regularity = true;  // nodes next to a coarser leaf can not be refined
    bool cull_hanging_nodes = true;   // nodes whose three neighbours are refined must be refined
    bool uniform_levels = true;       // levels refined everywhere are skipped (one byte)
    bool truncate_stream = true;      // trailing zeros (and with them the finest level) are dropped
    bool use_contexts = true;         // nine context groups instead of one adaptive model
    Traversal traversal = Traversal::improved;
};

// Local-index rules by which producers choose the diagonal of a leaf closed with two hanging
// nodes (unrefined edge u): the diagonal joins the midpoint of refined edge r to its opposite
// corner v_{(r+2)%3}. Frozen values: they are written to the stream.
enum class DiagonalRule : uint8_t {
    next_after_unrefined = 0,     // r = u+1 (amcodec's default; Hierarchy's flag = 0)
    previous_before_unrefined = 1,  // r = u+2
    lower_local_index = 2,          // r = the refined edge with the lower local index
    higher_local_index = 3,         // r = the refined edge with the higher local index
};
constexpr int kDiagonalRuleCount = 4;
// The Hierarchy flag (flip relative to the default) that `rule` implies for unrefined edge u.
bool diagonal_flag_by_rule(DiagonalRule rule, int unrefined_edge);
// Over leaves closed by two hanging nodes: how many flags each rule gets wrong. The encoder codes
// the flags relative to best().
struct DiagonalExceptions {
    uint64_t by_rule[kDiagonalRuleCount] = {};
    uint64_t leaves = 0;
    void add(int unrefined_edge, bool flipped);
    DiagonalRule best() const;  // the first rule with the fewest exceptions
    uint64_t fewest() const { return by_rule[size_t(best())]; }
};

// Context group of a symbol: counts of edge neighbours that are refined, not refined, unknown
// (not yet coded). Boundary edges count as not refined. (3,0,0) never carries a symbol when
// hanging-node culling is on.
struct ContextGroupStats {
    int refined = 0, unrefined = 0, unknown = 0;
    uint64_t symbols = 0;
    uint64_t ones = 0;
    double coded_bits = 0;  // adaptive code length spent in this group
};

struct HierarchyCodeStats {
    uint64_t nodes = 0;
    uint64_t faces = 0;
    int levels = 0;  // depth + 1
    int uniform_levels = 0;
    // Where each node's symbol went (they add up to nodes).
    uint64_t culled_uniform = 0;
    uint64_t culled_one_regularity = 0;
    uint64_t culled_hanging_nodes = 0;
    uint64_t truncated = 0;  // trailing zeros dropped, the finest level included
    uint64_t coded = 0;
    uint64_t coded_ones = 0;
    std::array<ContextGroupStats, 10> groups{};  // indexed by context_group_index()
    double conditional_entropy_bits = 0;  // sum over groups of n_g * H(p_g): H(X | context)
    double adaptive_code_bits = 0;        // what the adaptive models spent (symbols and orientation)
    // Orientation (diagonal) bits.
    DiagonalRule diagonal_rule = DiagonalRule::next_after_unrefined;
    uint64_t two_hanging_leaves = 0;
    uint64_t diagonal_exceptions = 0;
    bool orientation_coded = false;
    double orientation_bits = 0;
    // Stream.
    uint64_t header_bytes = 0;
    uint64_t payload_bytes = 0;
    uint64_t total_bytes() const { return header_bytes + payload_bytes; }
};

int context_group_index(int refined, int unrefined, int unknown);

// Encodes the forest and diagonals of `h` (positions are not coded here). The stream starts with
// its magic and version (docs/FORMAT.md, section 2).
std::vector<uint8_t> encode_hierarchy(const Hierarchy& h, const HierarchyCoderOptions& options = {},
                                      HierarchyCodeStats* stats = nullptr);

struct HierarchyDecodeOptions {
    int max_level = -1;               // stop after this level (progressive decoding); -1: all
    uint64_t max_nodes = 1ull << 26;  // refuse streams that would build more nodes than this
    // The version of a stream without magic and version, as encode_hierarchy wrote them before
    // 2026-12: 2, or 1 for streams written before 2026-11-24 (docs/FORMAT.md, section 2).
    uint8_t untagged_version = 2;
};

// Rebuilds the hierarchy over `base` (which must be the encoder's base mesh, same order) from a
// stream made by encode_hierarchy, of any version this build reads (a newer one is refused). New
// vertices sit at edge midpoints. Throws Error on a corrupt, truncated or over-large stream; never
// crashes or hangs. The stream holds no positions, and culled and uniformly refined levels cost no
// bits, so a short stream may describe a large forest: options.max_nodes bounds memory and time.
Hierarchy decode_hierarchy(const TriangleMesh& base, const uint8_t* data, size_t size,
                           const HierarchyDecodeOptions& options = {});

class HierarchyLevelDecoder;

// decode_hierarchy for many streams in a row, such as the time steps of a simulation: the decoder
// keeps its working memory from one stream to the next, and each stream is decoded into the
// memory of the caller's hierarchy. Decoding fresh memory costs page faults and cache misses that
// are a large part of the time (about a third at 10^5 nodes).
class HierarchyDecoder {
public:
    HierarchyDecoder();
    ~HierarchyDecoder();
    HierarchyDecoder(HierarchyDecoder&&) noexcept;
    HierarchyDecoder& operator=(HierarchyDecoder&&) noexcept;

    // As decode_hierarchy, with the result in `out` (whatever it held is replaced; its memory is
    // reused). On error it throws as decode_hierarchy does and leaves `out` a valid hierarchy
    // with unspecified contents.
    void decode(const TriangleMesh& base, const uint8_t* data, size_t size, Hierarchy& out,
                const HierarchyDecodeOptions& options = {});

private:
    void decode_stream(const TriangleMesh& base, const uint8_t* data, size_t size, Hierarchy& out,
                       const HierarchyDecodeOptions& options);
    std::unique_ptr<HierarchyLevelDecoder> coder_;
};

}  // namespace amc
