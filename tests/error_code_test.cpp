// Errors as values: every bad input of tests/data/bad/ is refused with its kind of problem, and
// try_decode reports the same kind as decode throws.
#include <amc/codec.h>
#include <amc/hierarchy.h>
#include <amc/mesh_io.h>
#include <amc/refinement.h>

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <string>

namespace amc {
namespace {

std::vector<uint8_t> read_bytes(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::vector<uint8_t>((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

bool has_suffix(const std::string& s, const std::string& suffix) {
    return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// Reads a bad file the way `amc info` does and returns the error it raises.
Error refusal_of(const std::string& path) {
    try {
        if (has_suffix(path, ".amc")) {
            const std::vector<uint8_t> bytes = read_bytes(path);
            decode(bytes.data(), bytes.size());
        } else if (has_suffix(path, ".amh")) {
            read_hierarchy(path);
        } else {
            read_mesh(path);
        }
    } catch (const Error& e) {
        return e;
    }
    return Error(ErrorCode::invalid_input, "accepted");
}

TEST(ErrorCodes, BadFilesAreRefusedWithTheirKindOfProblem) {
    using C = ErrorCode;
    // Files not listed here must be refused too, with any code.
    const std::map<std::string, ErrorCode> expected = {
        {"amc_bad_checksum.amc", C::checksum},
        {"amc_empty.amc", C::bad_magic},
        {"amc_garbage.amc", C::bad_magic},
        {"amc_newer_version.amc", C::unsupported_version},
        {"amc_truncated.amc", C::truncated},
        {"amh_bad_magic.amh", C::bad_magic},
        {"amh_corrupt_bits.amh", C::corrupt},
        {"amh_newer_version.amh", C::unsupported_version},
        {"amh_truncated.amh", C::truncated},
        {"off_bad_magic.off", C::bad_magic},
        {"off_truncated.off", C::truncated},
        {"off_huge_count.off", C::corrupt},
        {"off_polygon.off", C::invalid_input},
        {"off_nonmanifold_edge.off", C::invalid_input},
        {"obj_quad.obj", C::invalid_input},
        {"obj_index_out_of_range.obj", C::corrupt},
        {"ply_not_ply.ply", C::bad_magic},
        {"ply_truncated_binary.ply", C::truncated},
        {"ply_huge_count.ply", C::corrupt},
        {"unknown_extension.stl", C::invalid_input},
    };
    size_t checked = 0;
    for (const auto& entry : std::filesystem::directory_iterator(std::string(AMC_TEST_DATA_DIR) + "/bad")) {
        const std::string name = entry.path().filename().string();
        const Error e = refusal_of(entry.path().string());
        ASSERT_NE(std::string(e.what()), "accepted") << name;
        const auto it = expected.find(name);
        if (it == expected.end()) continue;
        EXPECT_EQ(error_code_name(e.code()), std::string(error_code_name(it->second))) << name << ": " << e.what();
        ++checked;
    }
    EXPECT_EQ(checked, expected.size()) << "a listed file is missing from tests/data/bad";
}

TEST(ErrorCodes, TryDecodeReportsTheCodeDecodeThrows) {
    Hierarchy h(make_icosahedron());
    refine_randomly(h, 200, 3, 5);
    const std::vector<uint8_t> good = encode(h);
    const DecodeResult ok = try_decode(good.data(), good.size());
    EXPECT_TRUE(ok.ok);
    EXPECT_TRUE(ok.error.empty());

    struct Case {
        std::vector<uint8_t> bytes;
        ErrorCode code;
    };
    std::vector<Case> cases;
    cases.push_back({std::vector<uint8_t>(good.begin(), good.begin() + 3), ErrorCode::bad_magic});
    cases.push_back({std::vector<uint8_t>(good.begin(), good.end() - 1), ErrorCode::truncated});
    cases.push_back({good, ErrorCode::unsupported_version});
    cases.back().bytes[4] = 99;
    cases.push_back({good, ErrorCode::checksum});
    cases.back().bytes[good.size() / 2] ^= 0x10;
    cases.push_back({good, ErrorCode::checksum});
    cases.back().bytes[9] ^= 1;  // the header's own checksum
    for (const Case& c : cases) {
        const DecodeResult r = try_decode(c.bytes.data(), c.bytes.size());
        EXPECT_FALSE(r.ok);
        EXPECT_EQ(error_code_name(r.code), std::string(error_code_name(c.code))) << r.error;
        try {
            decode(c.bytes.data(), c.bytes.size());
            ADD_FAILURE() << "decode accepted what try_decode refused";
        } catch (const Error& e) {
            EXPECT_EQ(e.code(), r.code);
            EXPECT_EQ(std::string(e.what()), r.error);
        }
    }
    DecodeOptions small;
    small.max_nodes = h.node_count() - 1;
    const DecodeResult limited = try_decode(good.data(), good.size(), small);
    EXPECT_FALSE(limited.ok);
    EXPECT_EQ(limited.code, ErrorCode::limit_exceeded) << limited.error;
}

TEST(ErrorCodes, PrefixedKeepsTheCode) {
    const Error e(ErrorCode::checksum, "checksum mismatch");
    const Error p = e.prefixed("file.amc");
    EXPECT_EQ(p.code(), ErrorCode::checksum);
    EXPECT_EQ(std::string(p.what()), "file.amc: checksum mismatch");
    EXPECT_EQ(Error("plain").code(), ErrorCode::invalid_input);
}

}  // namespace
}  // namespace amc
