// The geometry of a level block (docs/FORMAT.md 3.6, 5.5, 5.6): the predictor byte that opens the
// block, then, after the level's hierarchy part in the same arithmetic code, the positions of the
// vertices the level creates. Modes 1 and 2 (midpoint, butterfly) code them adaptively in that
// arithmetic code (from version 14, in bit-exact files, with their raw bits in a side stream after
// it: [predictor | kRawSideFlag, arithmetic length, arithmetic payload, raw bits]); mode 3 (normal frame) puts its tables there and the positions in a rANS stream
// and raw bits behind it: [predictor, arithmetic length, arithmetic payload, rANS length, rANS
// stream, raw bits].
#pragma once

#include "coding/container.h"
#include "coding/geometry/position_coder.h"
#include "coding/geometry/static_position_coder.h"

#include <amc/codec.h>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace amc {

// Set in the predictor byte of an adaptive level block (predictor 1 or 2) of a bit-exact file, from
// version 14: the coordinates' raw bits follow the arithmetic part, in a side stream (FORMAT.md 3.6).
constexpr uint8_t kRawSideFlag = 0x80;
// Whether a level payload (finish_level_payload's) has its raw bits in a side stream: a version-14 file.
inline bool has_raw_side(const std::vector<uint8_t>& payload) { return !payload.empty() && (payload[0] & kRawSideFlag) != 0; }

// The vertices a level creates, as (node, edge) in canonical order (new_vertices_of_level).
using NewVertices = std::vector<std::pair<NodeId, int>>;

// ---- encoder ------------------------------------------------------------------------------------

// A winning adaptive trial's coding of the level: the level's arithmetic code (its hierarchy part,
// then the positions), the raw bits of its side stream, and the models after them.
struct AdaptiveLevelCode {
    ArithmeticEncoder level;
    RawBitWriter raw;
    PositionCoder positions;
};

// A level's geometry code, chosen before the level block is written.
struct LevelGeometryCode {
    GeometryPredictor predictor = GeometryPredictor::midpoint;
    std::unique_ptr<StaticLevelEncoder> static_code;  // mode 3's, 4's or 5's streams, when chosen
    std::unique_ptr<AdaptiveLevelCode> adaptive_code;  // mode 1's or 2's, when a trial coded it
};

// The predictor of the level that creates `created` (positions set in h as the decoder will have
// them): `choice`, or when it is automatic the one that codes the level in the fewest bytes, each
// adaptive predictor tried on a copy of `positions`' models; mode 4 is a candidate only with
// grid_contexts in a quantized space, mode 5 only with unit_normals in a bit-exact one. Below
// kMaxGeometryEffort an adaptive predictor may be judged from a sample (EncodeOptions::effort). Mode 4's
// tokens go in `grid_order` (grouped: a version-18 file; per_vertex: versions 9-17). The static
// modes' encoders work in `buffers` when given (StaticEncoderBuffers). With `level_code`, the level
// block's arithmetic code after its hierarchy part, a winning adaptive trial that coded the whole
// level leaves that coding in adaptive_code (the same bytes as coding it again).
// Mesh: Hierarchy or HierarchyOnGrid (hierarchy_on_grid.h: the input's nodes with their grid points).
template <class Mesh>
LevelGeometryCode choose_level_geometry(const Mesh& h, const NewVertices& created, const PositionCoder& positions,
                                        CoordinateSpace space, GeometryPredictor choice, bool grid_contexts = false,
                                        bool unit_normals = false, int effort = kMaxGeometryEffort,
                                        StaticOrder grid_order = StaticOrder::grouped, StaticEncoderBuffers* buffers = nullptr,
                                        const ArithmeticEncoder* level_code = nullptr);

// When an adaptive trial of a level of `count` new vertices stops, from the bytes its code has
// committed after each vertex: once they pass `limit` (SIZE_MAX: none) by 8 bytes (exact: a
// finished code is never much shorter), and, with a `sample` of fewer vertices than the level
// (SIZE_MAX: none), when the level's bytes projected at a recent rate pass the limit by a margin
// (a guess): after the sample's first eighth and first quarter at the rate of the sixteenth
// (eighth) before, when that rate rests on 16 committed bytes or more, halfway through the sample
// at the rate of its second quarter, at the sample's end at the rate of its second half, then at
// the end of every further sample's length at the rate of the last one (the surfaces' trials that
// passed the sample all lost, after coding 60-80 % of their level: BENCHMARKS.md, "One-core
// encode, twelfth step"; those that stopped halfway mostly projected past the margin already
// after the first eighth: fourteenth step).
class AdaptiveTrialJudge {
public:
    AdaptiveTrialJudge(size_t count, size_t sample, size_t limit)
        : count_(count), sample_(sample), limit_(limit), next_(sample == SIZE_MAX ? SIZE_MAX : sample / 16) {}
    // After the trial's first `done` vertices, `bytes` committed: whether it stops there.
    bool stops(size_t done, size_t bytes) {
        if (bytes > limit_ + 8) return true;
        return done == next_ && checkpoint(done, bytes);
    }

private:
    bool checkpoint(size_t done, size_t bytes);
    size_t count_, sample_, limit_;
    size_t next_;              // the next vertex count with a test (or a rate's start)
    size_t since_ = 0, since_bytes_ = 0;  // where the rate of the next test starts
};

// Throws invalid_input, naming `what`, unless 0 <= effort <= kMaxEffort: what every encoder of
// levels checks before it starts (encode(), the ranks' writer).
void check_effort(int effort, const std::string& what);

// The payload of a level block whose hierarchy part `encoder` holds: the predictor byte, then the
// arithmetic code finished with the level's geometry (and mode 3's streams). A code's adaptive_code
// (made from `encoder` as it is) is taken instead of coding the positions again.
template <class Mesh>
std::vector<uint8_t> finish_level_payload(const Mesh& h, const NewVertices& created, LevelGeometryCode& code,
                                          PositionCoder& positions, ArithmeticEncoder& encoder);

// ---- decoder ------------------------------------------------------------------------------------

// A level block's payload split at its predictor byte and its arithmetic part.
struct LevelBlockParts {
    GeometryPredictor predictor = GeometryPredictor::midpoint;
    const uint8_t* arithmetic = nullptr;  // hierarchy part, then geometry (or mode 3's tables)
    size_t arithmetic_size = 0;
    const uint8_t* after_arithmetic = nullptr;  // mode 3: rANS length, rANS stream, raw bits; raw_side: raw bits
    size_t after_arithmetic_size = 0;
    bool raw_side = false;  // an adaptive level of a bit-exact file of version 14 or later
    StaticOrder order = StaticOrder::per_vertex;  // mode 4's token order: grouped from version 18
};

// Throws Error on a predictor the file's version does not have (mode 4 also in a file that is not
// quantized) and on a mode-3 or mode-4 arithmetic length beyond the block. `where` names the block in messages.
LevelBlockParts split_level_block(const Block& block, uint8_t file_version, bool quantized, bool mixed,
                                  const std::string& where);

// Decodes the positions of `created` (the level `level` just decoded from `decoder`) and sets them
// in h. Throws Error on a corrupt or truncated block.
void decode_level_geometry(Hierarchy& h, const NewVertices& created, const LevelBlockParts& parts, ArithmeticDecoder& decoder,
                           PositionCoder& positions, CoordinateSpace space, int level, const std::string& where);
// The same for a level in a mode without tables (midpoint, butterfly: not is_static_mode, else
// Error) whose new vertices `edges` walks (HierarchyLevelDecoder::new_vertex_edges).
void decode_walked_level_geometry(Hierarchy& h, const NewVertexEdges& edges, const LevelBlockParts& parts,
                                  ArithmeticDecoder& decoder, PositionCoder& positions, int level, const std::string& where);
// The same for a level in a static mode (is_static_mode(parts.predictor), else Error) whose new
// vertices `corners` lists with their frame corners (HierarchyLevelDecoder::new_vertex_corners).
void decode_listed_level_geometry(Hierarchy& h, NewVertexCorners corners, const LevelBlockParts& parts,
                                  ArithmeticDecoder& decoder, CoordinateSpace space, const std::string& where);

}  // namespace amc
