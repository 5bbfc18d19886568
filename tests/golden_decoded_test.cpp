// What the golden files decode to, pinned by hash (tests/data/golden-decoded.sha256): the hierarchy
// of every .amc file as an .amh byte string, and every frame of the series file with its fields
// (a forest series: its leaves and leaf fields).
// The hashes were made by the reference build (GCC, no floating-point flags); a build with other
// flags (CI: -ffp-contract=fast -O3 -march=native) that decodes one bit differently fails here,
// whatever its procedural models compute. AMC_UPDATE_GOLDEN=1 writes the list when it is missing.
#include "sha256.h"

#include <amc/codec.h>
#include <amc/hierarchy.h>
#include <amc/series.h>

#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace amc {
namespace {

const std::string kGoldenDir = std::string(AMC_TEST_DATA_DIR) + "/golden";
const std::string kManifest = std::string(AMC_TEST_DATA_DIR) + "/golden-decoded.sha256";

std::string read_bytes(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void append_raw(std::string& out, const void* data, size_t size) { out.append(static_cast<const char*>(data), size); }

// Every frame: its hierarchy (.amh bytes), its time and its fields, values bit for bit.
// A forest series: every frame's trees and leaves, its time and its leaf fields.
std::string decoded_forest_series(const std::string& bytes, const std::string& what) {
    ForestSeriesReader reader(std::vector<uint8_t>(bytes.begin(), bytes.end()), what);
    std::string out;
    for (size_t k = 0; k < reader.frame_count(); ++k) {
        const ForestSeriesFrame frame = reader.frame(k);
        append_raw(out, frame.forest.tree_offsets.data(), frame.forest.tree_offsets.size() * sizeof(uint64_t));
        for (const Octant& o : frame.forest.leaves) {
            const int32_t leaf[4] = {o.x, o.y, o.z, o.level};
            append_raw(out, leaf, sizeof leaf);
        }
        append_raw(out, &frame.time, sizeof frame.time);
        for (const Field& f : frame.forest.leaf_data) {
            out += f.name;
            append_raw(out, f.values.data(), f.values.size() * sizeof(double));
            append_raw(out, f.integers.data(), f.integers.size() * sizeof(int64_t));
        }
    }
    return out;
}

std::string decoded_series(const std::string& bytes, const std::string& what) {
    if (is_forest_series(std::vector<uint8_t>(bytes.begin(), bytes.end()))) return decoded_forest_series(bytes, what);
    SeriesReader reader(std::vector<uint8_t>(bytes.begin(), bytes.end()), what);
    std::string out;
    for (size_t k = 0; k < reader.frame_count(); ++k) {
        const SeriesFrame frame = reader.frame(k);
        out += serialize_hierarchy(frame.hierarchy);
        append_raw(out, &frame.time, sizeof frame.time);
        for (const Field& f : frame.fields) {
            out += f.name;
            append_raw(out, f.values.data(), f.values.size() * sizeof(double));
            append_raw(out, f.integers.data(), f.integers.size() * sizeof(int64_t));
        }
    }
    return out;
}

// The golden files whose decoding involves positions, by path relative to tests/data/golden.
std::map<std::string, std::string> decoded_hashes() {
    std::map<std::string, std::string> hashes;
    for (const auto& entry : std::filesystem::recursive_directory_iterator(kGoldenDir)) {
        const std::string ext = entry.path().extension().string();
        if (!entry.is_regular_file() || (ext != ".amc" && ext != ".amcs")) continue;
        const std::string path = entry.path().string();
        const std::string name = std::filesystem::relative(entry.path(), kGoldenDir).generic_string();
        const std::string bytes = read_bytes(path);
        if (ext == ".amc") {
            const Hierarchy h = decode(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
            hashes[name] = test::sha256_hex(serialize_hierarchy(h));
        } else {
            hashes[name] = test::sha256_hex(decoded_series(bytes, path));
        }
    }
    return hashes;
}

TEST(GoldenDecoded, EveryFileDecodesToItsCommittedHash) {
    const std::map<std::string, std::string> hashes = decoded_hashes();
    ASSERT_GE(hashes.size(), 17u) << "the .amc and .amcs files of tests/data/golden";
    if (std::getenv("AMC_UPDATE_GOLDEN") != nullptr && !std::filesystem::exists(kManifest)) {
        std::ofstream out(kManifest);
        for (const auto& [name, hash] : hashes) out << hash << "  " << name << "\n";
    }
    std::map<std::string, std::string> committed;
    std::istringstream manifest(read_bytes(kManifest));
    std::string hash, name;
    while (manifest >> hash >> name) committed[name] = hash;
    ASSERT_FALSE(committed.empty()) << kManifest << " is missing";
    for (const auto& [file, decoded] : hashes) {
        const auto it = committed.find(file);
        ASSERT_TRUE(it != committed.end()) << file << " has no line in " << kManifest;
        EXPECT_EQ(decoded, it->second) << file << " decodes differently from the reference build";
    }
    EXPECT_EQ(committed.size(), hashes.size()) << kManifest << " lists files that are gone";
}

}  // namespace
}  // namespace amc
