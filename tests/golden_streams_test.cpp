// Golden standalone hierarchy streams and .amh files (tests/data/golden/hierarchy_stream/,
// tests/data/golden/amh/), kept forever like the .amc ones (docs/COMPATIBILITY.md). The untagged
// version-1 streams and the .amh files were written by 31e1487, the last commit that wrote version
// 1, through scripts/compat/write_vectors.cpp (its five random hierarchies of seed 2: about 900
// leaves, at most 4 levels). The tagged version-2 streams are the current writer's; without their
// tag they are the untagged version-2 streams written from 2026-11-24 to 2026-12.
#include "hierarchy_checks.h"

#include "coding/format_version.h"
#include "coding/hierarchy/hierarchy_stream.h"

#include <amc/codec.h>
#include <amc/hierarchy_coder.h>

#include <algorithm>
#include <cstddef>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>

namespace amc {
namespace {

// write_vectors' hierarchies of seed 2 and the coder switches of the kept streams: none, the
// 1-regularity cull (where versions 1 and 2 differ) with either traversal, and all six.
constexpr const char* kNames[] = {"icosahedron_2", "torus_2", "square_2", "lshape_2", "bumpy_2"};
constexpr int kSwitches[] = {0, 1, 33, 63};

std::string golden_dir() { return std::string(AMC_TEST_DATA_DIR) + "/golden/"; }

std::vector<uint8_t> read_bytes(const std::string& path) {
    std::ifstream file(path, std::ios::binary);
    return std::vector<uint8_t>((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
}

std::string stream_path(const std::string& dir, const std::string& name, int switches, const char* extension) {
    return golden_dir() + "hierarchy_stream/" + dir + "/" + name + ".sw" + std::to_string(switches) + extension;
}

// Same base, forest and effective diagonals (a stream holds no positions), as in
// hierarchy_coder_test.cpp.
bool same_connectivity(const Hierarchy& a, const Hierarchy& b) {
    const std::vector<NodeId> oa = a.breadth_first_order(), ob = b.breadth_first_order();
    if (oa.size() != ob.size() || a.base().triangles != b.base().triangles) return false;
    for (size_t i = 0; i < oa.size(); ++i) {
        if (a.is_leaf(oa[i]) != b.is_leaf(ob[i])) return false;
        if (a.is_leaf(oa[i]) && a.hanging_node_count(oa[i]) == 2 && a.diagonal_flipped(oa[i]) != b.diagonal_flipped(ob[i]))
            return false;
    }
    return extract_leaf_mesh(a).mesh.triangles == extract_leaf_mesh(b).mesh.triangles;
}

// The .amh files of version 1 read back, and the current writer writes them byte for byte.
TEST(GoldenStreams, AmhFilesOfVersion1ReadAndAreWhatTheWriterWrites) {
    for (const char* name : kNames) {
        const std::string path = golden_dir() + "amh/v1/" + name + ".amh";
        const std::vector<uint8_t> golden = read_bytes(path);
        ASSERT_FALSE(golden.empty()) << path << " is missing";
        const Hierarchy h = read_hierarchy(path);
        EXPECT_TRUE(testing::hierarchy_is_valid(h)) << path;
        EXPECT_GT(h.leaf_count(), h.root_count()) << path;
        const std::string bytes = serialize_hierarchy(h);
        EXPECT_EQ(std::vector<uint8_t>(bytes.begin(), bytes.end()), golden) << path << ": the .amh writer changed";
    }
}

// Every stream version decodes to the hierarchy of its .amh file: untagged version 1 (as the
// caller declares it), untagged version 2 (the default for untagged streams) and tagged version 2,
// whose files the current writer writes byte for byte (AMC_UPDATE_GOLDEN=1 writes a missing one).
TEST(GoldenStreams, EveryStreamVersionDecodesToItsHierarchy) {
    int versions_differ = 0;
    for (const char* name : kNames) {
        const Hierarchy h = read_hierarchy(golden_dir() + "amh/v1/" + name + ".amh");
        for (const int switches : kSwitches) {
            SCOPED_TRACE(std::string(name) + " switches " + std::to_string(switches));
            const HierarchyCoderOptions options = coder_options_from_switches(switches);
            const std::vector<uint8_t> v1 = read_bytes(stream_path("v1-untagged", name, switches, ".hs"));
            const std::string tagged_path = stream_path("v2", name, switches, ".amhs");
            const std::vector<uint8_t> current = encode_hierarchy(h, options);
            if (std::getenv("AMC_UPDATE_GOLDEN") != nullptr && !std::filesystem::exists(tagged_path)) {
                std::filesystem::create_directories(std::filesystem::path(tagged_path).parent_path());
                std::ofstream(tagged_path, std::ios::binary)
                    .write(reinterpret_cast<const char*>(current.data()), std::streamsize(current.size()));
            }
            const std::vector<uint8_t> tagged = read_bytes(tagged_path);
            ASSERT_FALSE(v1.empty() || tagged.empty()) << "a golden stream is missing";
            const std::vector<uint8_t> tag = hierarchy_stream_tag(kHierarchyStreamVersion);
            ASSERT_TRUE(tagged.size() > tag.size() && std::equal(tag.begin(), tag.end(), tagged.begin()));
            const std::vector<uint8_t> v2(tagged.begin() + std::ptrdiff_t(tag.size()), tagged.end());  // untagged
            HierarchyDecodeOptions as_v1;
            as_v1.untagged_version = 1;
            EXPECT_TRUE(same_connectivity(decode_hierarchy(h.base(), v1.data(), v1.size(), as_v1), h)) << "v1 untagged";
            EXPECT_TRUE(same_connectivity(decode_hierarchy(h.base(), v2.data(), v2.size()), h)) << "v2 untagged";
            EXPECT_TRUE(same_connectivity(decode_hierarchy(h.base(), tagged.data(), tagged.size()), h)) << "v2 tagged";
            EXPECT_EQ(current, tagged) << "the hierarchy stream writer changed: a new stream version";
            versions_differ += v1 != v2;
        }
    }
    EXPECT_GT(versions_differ, 0) << "no version-1 stream differs from its version 2: the old path goes untested";
}

}  // namespace
}  // namespace amc
