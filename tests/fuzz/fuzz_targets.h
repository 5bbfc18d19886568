// The fuzz targets: one per decoder entry point, each a plain function of the input bytes, so that
// the libFuzzer binaries (fuzz_entry.cpp, built with -DAMC_FUZZ=ON) and the regression test over
// tests/data/fuzz-regressions/ (tests/fuzz_regression_test.cpp, in amc_tests) run the same code.
// A target refuses bad input through amc::Error as the library does; anything else that escapes
// (std::bad_alloc, a crash, a sanitizer report, a hang) is a finding, and so is a property a
// target checks (FUZZ_CHECK: round trips, invariants of what was decoded), which aborts.
#pragma once

#include <amc/hierarchy.h>
#include <amc/mesh.h>

#include "../random_hierarchies.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace amc::fuzz {

using TargetFunction = void (*)(const uint8_t* data, size_t size);

struct Target {
    const char* name;  // the binary is fuzz_<name>; its regression inputs tests/data/fuzz-regressions/<name>/
    TargetFunction run;
};

void amc_decode(const uint8_t* data, size_t size);         // .amc decode: whole, progressive, re-encoded
void amc_inspect(const uint8_t* data, size_t size);        // .amc inspect
void amh_read(const uint8_t* data, size_t size);           // .amh reader
void hierarchy_stream(const uint8_t* data, size_t size);   // decode_hierarchy, HierarchyDecoder
void base_connectivity(const uint8_t* data, size_t size);  // the base mesh connectivity decoder
void geometry(const uint8_t* data, size_t size);           // the coordinate (float and grid) decoder
void obj_read(const uint8_t* data, size_t size);           // mesh readers and writers
void off_read(const uint8_t* data, size_t size);
void ply_read(const uint8_t* data, size_t size);
void vtu_read(const uint8_t* data, size_t size);
void round_trip(const uint8_t* data, size_t size);         // random hierarchy -> encode -> decode
void series_read(const uint8_t* data, size_t size);        // .amcs reader, every frame, written again
void forest_series_read(const uint8_t* data, size_t size); // .amcs forest series reader, every frame, written again
void octree_decode(const uint8_t* data, size_t size);      // .amq decode: whole, progressive, encoded again
void leaf_import(const uint8_t* data, size_t size);        // leaf mesh (damaged or not) -> hierarchy, with the base or alone
void closest_point(const uint8_t* data, size_t size);      // ClosestPointQuery against a brute-force loop
void nearest_vertex(const uint8_t* data, size_t size);     // NearestVertex against a brute-force scan and the k-d tree

// Input layouts of the stream targets, which fuzz_seeds writes too.
//   hierarchy_stream: u8 base (index into stream_bases()), u8 max_level + 1 (0: all levels), the stream.
//   geometry: u8 mode (mode % 3: 0 float32, 1 float64, 2 quantized with 1 + mode / 3 % 30 bits),
//             u8 n (1 + n % 16 predictions), n u64 predictions (the IEEE bits of a double, or a
//             grid coordinate in the low 32 bits), the payload.
const std::vector<TriangleMesh>& stream_bases();
//   closest_point: a mesh and its queries (closest_point_fuzzer.cpp); its seeds, which fuzz_seeds
//             writes and amc_tests runs: a fan, a far component, a translated lattice and more.
std::vector<std::vector<uint8_t>> closest_point_seeds();
//   nearest_vertex: a point set and its queries (nearest_vertex_fuzzer.cpp); its seeds, which
//             fuzz_seeds writes and amc_tests runs: a lattice, many copies of a point, a cluster
//             beside an outlier, tiny and huge scales, a graded box, ties across
//             the side of a query's cell, one point.
std::vector<std::vector<uint8_t>> nearest_vertex_seeds();
//   base_connectivity: u16 vertex count (little endian), the stream; decoder vertex v is at
//             base_position(v).
Vec3 base_position(uint32_t v);
constexpr int kGeometryContexts = 51;           // as many as an .amc file has
constexpr size_t kMaxGeometryCoordinates = 512;  // decoded a run at most

// The tests' generator, whose output is the same on every platform.
using Random = amc::testing::Random;

// Reads fixed-size values front to back; past the end they read as 0.
class ByteReader {
public:
    ByteReader(const uint8_t* data, size_t size) : data_(data), size_(size) {}
    uint8_t u8() { return pos_ < size_ ? data_[pos_++] : 0; }
    uint32_t u32() { return uint32_t(u64_of(4)); }
    uint64_t u64() { return u64_of(8); }
    const uint8_t* rest() const { return data_ + pos_; }
    size_t remaining() const { return size_ - pos_; }

private:
    uint64_t u64_of(int bytes) {
        uint64_t v = 0;
        for (int i = 0; i < bytes; ++i) v |= uint64_t(u8()) << (8 * i);
        return v;
    }
    const uint8_t* data_;
    size_t size_;
    size_t pos_ = 0;
};

// Every target, in the order scripts/fuzz.sh and .ci/run take them.
const std::vector<Target>& targets();

// A property does not hold: prints `what` and aborts (libFuzzer saves the input).
[[noreturn]] void violated(const char* what, const char* file, int line);

// A copy of an .amc file (or an .amq, .amcs file: same framing, their header is `header_size` bytes
// long) with the header's and every block's XXH32 recomputed, as far as the framing can be walked:
// lets mutated files past the checksums into the payload decoders.
constexpr size_t kAmcHeaderSize = 12;    // also .amq's
constexpr size_t kSeriesHeaderSize = 16;
std::vector<uint8_t> with_valid_checksums(const uint8_t* data, size_t size, size_t header_size = kAmcHeaderSize);

// Grows a random red-green hierarchy from the input: up to 63 refinements and coarsenings of nodes
// it picks (no refinement past max_level, none once the hierarchy has max_nodes), then, with
// flip_diagonals, the flipped diagonal of the two-hanging-node leaves it picks.
void refine_at_random(Hierarchy& h, ByteReader& in, uint32_t max_nodes, int max_level, bool flip_diagonals);

}  // namespace amc::fuzz

#define FUZZ_CHECK(condition)                                                        \
    do {                                                                             \
        if (!(condition)) ::amc::fuzz::violated(#condition, __FILE__, __LINE__);     \
    } while (0)
