// Decodes the test vectors of write_vectors (written by an older amcodec) with this tree and
// checks each against its hierarchy: every hierarchy stream decodes to the same forest
// (untagged streams read as UNTAGGED_VERSION), every .amc file to the hierarchy in decoder order,
// the quantized ones to what this tree's own encoding of it decodes to. Prints the counts; exits 1
// on any difference.
// Usage: check_vectors DIR UNTAGGED_VERSION
#include <amc/codec.h>
#include <amc/hierarchy.h>
#include <amc/hierarchy_coder.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace {

std::vector<uint8_t> read_bytes(const std::string& path) {
    std::ifstream file(path, std::ios::binary);
    return std::vector<uint8_t>((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 3) {
        std::fprintf(stderr, "usage: check_vectors DIR UNTAGGED_VERSION\n");
        return 2;
    }
    const std::string dir = argv[1];
    amc::HierarchyDecodeOptions stream_options;
    stream_options.untagged_version = uint8_t(std::atoi(argv[2]));
    int streams = 0, files = 0, failures = 0, versions[256] = {};
    auto fail = [&](const std::string& what) {
        if (failures++ < 20) std::fprintf(stderr, "check_vectors: %s\n", what.c_str());
    };
    for (const auto& entry : std::filesystem::directory_iterator(dir)) {
        // Hierarchies of the vectors, not what a file decoded to (NAME.KIND.decoded.amh).
        if (entry.path().extension() != ".amh" || entry.path().stem().extension() == ".decoded") continue;
        const std::string name = (entry.path().parent_path() / entry.path().stem()).string();
        const amc::Hierarchy h = amc::read_hierarchy(entry.path().string());
        for (int s = 0; s < 64; ++s) {
            const std::string path = name + ".sw" + std::to_string(s) + ".hs";
            const std::vector<uint8_t> bytes = read_bytes(path);
            ++streams;
            try {
                if (!amc::identical(amc::decode_hierarchy(h.base(), bytes.data(), bytes.size(), stream_options), h))
                    fail(path + ": decodes to another hierarchy");
            } catch (const std::exception& e) {
                fail(path + ": " + e.what());
            }
        }
        for (const char* kind : {"lossless", "naive", "butterfly", "q12"}) {
            const std::string path = name + "." + kind + ".amc";
            const std::vector<uint8_t> bytes = read_bytes(path);
            ++files;
            try {
                ++versions[amc::inspect(bytes.data(), bytes.size()).version];
                const amc::Hierarchy back = amc::decode(bytes.data(), bytes.size());
                // What the writing build decoded its file to (the base order is that build's).
                const amc::Hierarchy expected = amc::read_hierarchy(name + "." + kind + ".decoded.amh");
                if (!amc::identical(back, expected)) fail(path + ": decodes to another hierarchy");
            } catch (const std::exception& e) {
                fail(path + ": " + e.what());
            }
        }
    }
    std::printf("check_vectors: %d hierarchy streams (untagged: version %d), %d .amc files (", streams,
                int(stream_options.untagged_version), files);
    for (int v = 0; v < 256; ++v) {
        if (versions[v] != 0) std::printf(" version %d: %d", v, versions[v]);
    }
    std::printf(" ), %d differences\n", failures);
    return failures == 0 && streams > 0 ? 0 : 1;
}
