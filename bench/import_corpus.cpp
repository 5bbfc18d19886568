// The corpus check of issue 23 (docs/IMPORT.md, "The corpus check"): for every hierarchy given,
// its leaf mesh as a user holds it (vertices and faces shuffled, every non-base vertex moved off
// its midpoint by up to 0.3 of its shortest edge per coordinate):
//   * import_leaf_mesh with the base (matched by position) must give the identical hierarchy;
//   * import_mesh without it: the base it finds and the connectivity code of its hierarchy
//     (base connectivity + hierarchy stream of the .amc file) against the true hierarchy's.
// Prints a Markdown table. Exit status 1 if any import with the base is not identical.
//
// Usage: import_corpus [--move X] [--seed N] [--with-base-only | --without-base-only] [--hash]
//                      [--full-messages] corpus/*.amh
// (scripts/import_corpus.sh makes the corpus; --with-base-only skips import_mesh and leaves its
// columns empty, --without-base-only skips import_leaf_mesh likewise; --hash prints,
// to stderr, a hash of each detected hierarchy's .amc file, to tell a changed search's output apart;
// --seed N shuffles and moves with another seed than 23, to see how the results depend on the order;
// --full-messages prints refusals whole instead of their first 67 characters, to tell a changed
// import's answers apart)
#include "user_leaf_mesh.h"

#include <amc/codec.h>
#include <amc/import.h>

#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <string>
#include <vector>

namespace {

double thread_seconds() {
    timespec t;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

// FNV-1a of a byte string.
uint64_t fnv1a(const std::vector<uint8_t>& bytes) {
    uint64_t hash = 14695981039346656037ull;
    for (uint8_t byte : bytes) hash = (hash ^ byte) * 1099511628211ull;
    return hash;
}

uint64_t connectivity_bytes(const amc::Hierarchy& h) {
    amc::EncodeStats stats;
    amc::encode(h, {}, &stats);
    return stats.base_connectivity_bytes + stats.hierarchy_bytes;
}

}  // namespace

constexpr const char* kUsage =
    "usage: import_corpus [--move X] [--seed N] [--with-base-only | --without-base-only] [--hash] [--full-messages] "
    "hierarchy.amh...\n";

int run(int argc, char** argv) {
    double move = 0.3;
    uint64_t seed = 23;
    bool detect = true, with_base_import = true, hash = false, full_messages = false;
    std::vector<std::string> files;
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        if (arg == "--move" && i + 1 < argc) {
            move = std::atof(argv[++i]);
        } else if (arg == "--seed" && i + 1 < argc) {
            seed = std::strtoull(argv[++i], nullptr, 10);
        } else if (arg == "--with-base-only") {
            detect = false;
        } else if (arg == "--without-base-only") {
            with_base_import = false;
        } else if (arg == "--hash") {
            hash = true;
        } else if (arg == "--full-messages") {
            full_messages = true;
        } else if (arg == "--help" || arg == "-h") {
            std::printf("%s", kUsage);
            return 0;
        } else if (!arg.empty() && arg[0] == '-') {
            std::fprintf(stderr, "import_corpus: unknown option %s\n%s", arg.c_str(), kUsage);
            return 2;
        } else {
            files.push_back(arg);
        }
    }
    if (files.empty()) {
        std::fprintf(stderr, "%s", kUsage);
        return 2;
    }
    std::printf("| model | leaf faces | base triangles | with base | s | M faces/s | base found (triangles) | connectivity bytes, true | found | found / true | s |\n");
    std::printf("|---|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|\n");
    int not_identical = 0;
    for (const std::string& file : files) {
        const amc::Hierarchy h = amc::read_hierarchy(file);
        const amc::LeafMesh leaf = amc::extract_leaf_mesh(h);
        std::vector<uint32_t> user_of_leaf;
        const amc::TriangleMesh user =
            bench::user_leaf_mesh(leaf.mesh, uint32_t(h.base().positions.size()), move, seed, &user_of_leaf);
        // The hierarchy the import must give: h with the user's positions.
        amc::Hierarchy expected = h;
        const std::vector<uint32_t> canonical = amc::canonical_vertex_order(h);
        for (amc::VertexId v = 0; v < canonical.size(); ++v) {
            if (canonical[v] != amc::kNoVertex) expected.set_position(v, user.positions[user_of_leaf[canonical[v]]]);
        }
        std::string with_base;
        double start = thread_seconds();
        if (with_base_import) {
            try {
                const amc::ImportedHierarchy imported = amc::import_leaf_mesh(h.base(), user);
                with_base = amc::identical(imported.hierarchy, expected) ? "identical" : "DIFFERENT";
            } catch (const amc::Error& e) {
                with_base = std::string("refused: ") + e.what();
                if (!full_messages && with_base.size() > 70) with_base = with_base.substr(0, 67) + "...";
            }
        }
        const double with_base_seconds = thread_seconds() - start;
        if (with_base_import && with_base != "identical") ++not_identical;

        const std::string name = std::filesystem::path(file).stem().string();
        // Import speed only where the import succeeded: a refusal's time says when it gave up.
        char rate[32] = "";
        if (with_base == "identical") {
            std::snprintf(rate, sizeof rate, "%.2f", 1e-6 * double(user.triangles.size()) / with_base_seconds);
        }
        if (!detect) {
            std::printf("| %s | %zu | %zu | %s | %.2f | %s | | | | | |\n", name.c_str(), leaf.mesh.triangles.size(),
                        h.base().triangles.size(), with_base.c_str(), with_base_seconds, rate);
            std::fflush(stdout);
            continue;
        }
        start = thread_seconds();
        const amc::ImportedHierarchy detected = amc::import_mesh(user);
        const double detect_seconds = thread_seconds() - start;
        const uint64_t truth = connectivity_bytes(h), found = connectivity_bytes(detected.hierarchy);
        if (hash) std::fprintf(stderr, "%s %016llx\n", name.c_str(), (unsigned long long)fnv1a(amc::encode(detected.hierarchy)));
        std::printf("| %s | %zu | %zu | %s | %.2f | %s | %u | %llu | %llu | %.3f | %.2f |\n", name.c_str(),
                    leaf.mesh.triangles.size(), h.base().triangles.size(), with_base.c_str(), with_base_seconds, rate,
                    detected.hierarchy.root_count(), (unsigned long long)truth, (unsigned long long)found,
                    double(found) / double(truth), detect_seconds);
        std::fflush(stdout);
    }
    return not_identical == 0 ? 0 : 1;
}

int main(int argc, char** argv) {
    try {
        return run(argc, argv);
    } catch (const amc::Error& e) {  // an unreadable input file
        std::fprintf(stderr, "import_corpus: %s\n", e.what());
        return 1;
    }
}
