// The version numbers of amcodec's streams and which hierarchy stream each .amc version holds: the
// one place that knows them (docs/FORMAT.md, "Versions and compatibility"). Writers write the
// newest version; readers read every version from the oldest on and refuse newer ones.
#pragma once

#include <cstdint>

namespace amc {

// The .amc file (FORMAT.md section 3). decode() reads kOldestReadableVersion .. kNewestVersion. A
// writer writes the lowest version that holds what the file holds: version 5 for files whose base
// connectivity is in mode 2 (every base that mode can code), else version 3 for files with a
// numbering block, else version 2. Version 5 holds version 4's streams; its encoder searches the
// start triangle and gate radius of mode 2 (FORMAT.md 4.16), so it writes other bytes. Version 6 for files with a level in geometry
// mode 3 (normal frame, static tables, rANS). Version 8 for files whose hierarchy symbols are in
// the mixing mode (metadata option bit 2; FORMAT.md 2.1). Version 9 for files with a level in
// geometry mode 4 (whether chunked, mixed or neither). Version 10 for files in the mixing mode's
// second model (FORMAT.md 2.2; whatever their geometry modes): versions 8 and 9 hold the first.
// Version 11 for files in its third model (FORMAT.md 2.3), which encoders write since. Version 12
// for files with a level in geometry mode 5 (the unit-normal frame with three tables; whatever else
// they hold). Version 13 for chunked files (whatever else they hold): its chunk table lists each
// chunk's own vertices. Version 14 for bit-exact files with a level (of the file or of a chunk) in
// an adaptive geometry mode (midpoint, butterfly): such a level's raw bits are in a side stream.
// Version 15 for bit-exact files with a level in geometry mode 6 or 7 (the midpoint's or the
// butterfly's predictions under static tables, rANS and raw bits). Version 16 for files in the
// mixing mode's fourth model (FORMAT.md 2.4; whatever their geometry modes). Version 17 for files
// in its fifth model (FORMAT.md 2.5; whatever their geometry modes): versions 11-15 hold the third,
// 16 the fourth. Version 18 for files with a level in geometry mode 4 whose hierarchy symbols are
// not in the mixing mode (chunked or not): mode 4's tokens in the grouped order (FORMAT.md 5.7);
// mixed files keep the per-vertex order (versions 9-17 and 19). Version 19 for files in the mixing
// mode's sixth model (FORMAT.md 2.6); 17 keeps the fifth. Version 20 for files in its seventh model
// (FORMAT.md 2.7: the sixth with trained initial states), which encoders write since. Version 21
// for bit-exact files whose base positions (or seam vertices) have raw bits: they go to a side
// stream after the base geometry block's (the seam block's) arithmetic code; mixed files of
// version 21 are in the seventh model, and an older model keeps its version and the old layout.
// Version 22 for files whose base connectivity is in mode 3 (mode 2 with split tips looked for near
// the gate, FORMAT.md 4.17), written where mode 2's walk passes its budget; everything else as the
// newest version before it holds it: bit-exact files as version 21, quantized ones as version 18
// (mode 4 in the grouped order) or, mixed, as version 20 (the seventh model, the per-vertex order).
constexpr uint8_t kOldestReadableVersion = 1;
constexpr uint8_t kNewestVersion = 22;
constexpr uint8_t kBaseVersion = 2;       // everything but the numbering block and mode 2
constexpr uint8_t kNumberingVersion = 3;  // the first version with a numbering block
constexpr uint8_t kAngleBaseVersion = 4;  // the first version with base connectivity mode 2
constexpr uint8_t kSearchedBaseVersion = 5;  // mode 2 from the searching encoder: what mode-2 files are written as
constexpr uint8_t kStaticGeometryVersion = 6;  // the first version with level geometry mode 3 (normal frame, rANS)
// Files split into independent chunks of roots (chunk table, seam and chunk blocks instead of level
// blocks): written only for files of more than one chunk.
constexpr uint8_t kChunkedVersion = 7;
constexpr uint8_t kMixedContextsVersion = 8;   // the first version with the hierarchy coder's mixing mode
// The first version with level geometry mode 4 (the normal frame's tables split by where the
// prediction falls between grid points; quantized files, level blocks or chunks).
constexpr uint8_t kGridGeometryVersion = 9;
constexpr uint8_t kSecondMixingVersion = 10;  // the first version whose mixing mode is the second model
constexpr uint8_t kThirdMixingVersion = 11;   // the first version whose mixing mode is the third model
constexpr uint8_t kUnitFrameVersion = 12;     // the first version with level geometry mode 5 (unit-normal frame)
// The first version whose chunk table gives each chunk's own vertex count (FORMAT.md 3.12), so that
// chunks decode straight into their places in the whole on several threads.
constexpr uint8_t kChunkVerticesVersion = 13;
// The first version whose adaptive level blocks (predictors 1, 2) in bit-exact files carry the
// coordinates' raw bits in a byte-aligned side stream after the arithmetic code (FORMAT.md 3.6, 5.2).
constexpr uint8_t kRawSideVersion = 14;
// The first version with level geometry modes 6 and 7 (midpoint_static, butterfly_static; bit-exact
// files, FORMAT.md 5.9).
constexpr uint8_t kStencilTablesVersion = 15;
// The first version whose mixing mode is the fourth model (the quadric's curvatures, FORMAT.md 2.4).
constexpr uint8_t kFourthMixingVersion = 16;
// The first version whose mixing mode is the fifth model (the local threshold, FORMAT.md 2.5).
constexpr uint8_t kFifthMixingVersion = 17;
// The first version whose mode-4 levels code their tokens in the grouped order (StaticOrder::grouped,
// FORMAT.md 5.7): a run of 64 vertices' role-0 tokens, then their roles 1 and 2.
constexpr uint8_t kGroupedGridVersion = 18;
// The first version whose mixing mode is the sixth model (the quadric's ring means, FORMAT.md 2.6);
// its level blocks are version 17's (mode 4 in the per-vertex order).
constexpr uint8_t kSixthMixingVersion = 19;
// The first version whose mixing mode is the seventh model (the sixth whose geometric tables start
// at trained states, FORMAT.md 2.7); its level blocks are version 17's too.
constexpr uint8_t kSeventhMixingVersion = 20;
// The first version whose bit-exact files carry the raw bits of the base positions and of the seam
// vertices in a byte-aligned side stream after the arithmetic code of the base geometry block and of
// the seam block (FORMAT.md 3.5, 3.13); bit-exact files only (a quantized version-21 file is an
// error), everything else as in version 20 (mixed files: the seventh model).
constexpr uint8_t kBaseRawSideVersion = 21;
// The first version whose base connectivity may be in mode 3 (FORMAT.md 4.17).
constexpr uint8_t kWindowedTipVersion = 22;

// Whether a file's base geometry and seam blocks have the side stream: bit-exact, version 21 on.
constexpr bool base_raw_side(uint8_t file_version, bool quantized) { return file_version >= kBaseRawSideVersion && !quantized; }

// Whether a file of `file_version` codes mode 4's tokens in the grouped order: version 18, whose
// files are never mixed, and version 22's files that are not mixed; the mixing mode's files keep
// the per-vertex order (versions 9-17, 19, 20, 22; version 21 holds no mode 4: its files are bit-exact).
constexpr bool grouped_grid_order(uint8_t file_version, bool mixed) {
    return file_version >= kGroupedGridVersion && file_version != kSixthMixingVersion && file_version != kSeventhMixingVersion &&
           !(file_version >= kWindowedTipVersion && mixed);
}

// The lowest version a file's newest features need, 0 if it has none of them (older features then
// decide): the one rule for encode()'s files and the chunked file head the MPI ranks write.
// `grouped_grid`: a mode-4 level in the grouped order (only quantized files have one; stencil
// tables and raw side streams only bit-exact ones). `base_side`: the base's (and seam's) raw bits in
// side streams. `windowed_base`: base connectivity in mode 3.
constexpr uint8_t newest_features_version(bool grouped_grid, bool stencil_tables, bool raw_side, bool chunked, bool base_side,
                                          bool windowed_base) {
    return windowed_base    ? kWindowedTipVersion
           : base_side      ? kBaseRawSideVersion
           : grouped_grid   ? kGroupedGridVersion
           : stencil_tables ? kStencilTablesVersion
           : raw_side       ? kRawSideVersion
           : chunked        ? kChunkVerticesVersion
                            : 0;
}

// The hierarchy stream (FORMAT.md section 2).
constexpr uint8_t kHierarchyStreamVersion = 2;
constexpr uint8_t kOldestHierarchyStreamVersion = 1;
// Version 1 decides the nodes 1-regularity culls in their turn, version 2 before the traversal of
// their level starts.
constexpr bool culls_decided_in_turn(uint8_t stream_version) { return stream_version < 2; }

// The hierarchy stream version that a readable .amc version holds (a new .amc version that keeps
// the hierarchy stream adds a case here).
constexpr uint8_t hierarchy_stream_version_of_file(uint8_t file_version) {
    switch (file_version) {
        case 1: return 1;
        case 2: return 2;
        case 3: return 2;
        case 4: return 2;
        case 5: return 2;
        case 6: return 2;
        case 7: return 2;
        case 8: return 2;
        case 9: return 2;
        case 10: return 2;
        case 11: return 2;
        case 12: return 2;
        case 13: return 2;
        case 14: return 2;
        case 15: return 2;
        case 16: return 2;
        case 17: return 2;
        case 18: return 2;
        case 19: return 2;
        case 20: return 2;
        case 21: return 2;
        case 22: return 2;
    }
    return 0;
}
static_assert(hierarchy_stream_version_of_file(kBaseVersion) == kHierarchyStreamVersion &&
                  hierarchy_stream_version_of_file(kNewestVersion) == kHierarchyStreamVersion,
              "encode() writes the newest hierarchy stream");

}  // namespace amc
