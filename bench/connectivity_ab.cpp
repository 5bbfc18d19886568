// connectivity_ab: two builds of the library decoding the same hierarchy streams in one process,
// decode by decode in turn, with Draco's standard Edgebreaker decoding the same leaf mesh's
// connectivity in the same rounds: the "Speed, connectivity" comparison of compare_bench
// (decode_hierarchy of the stream encode_hierarchy writes with the default options, against
// Draco's DecodeConnectivity() at speed 5), timed as this thread's CPU time.
//
//   connectivity_ab A.so B.so ROUNDS model.amh ...   timed in turn; B / A and Draco / A per model
//   connectivity_ab --hash LIB.so file ...           a hash of every decoded hierarchy
//   connectivity_ab --run LIB.so RUNS model.amh      LIB's decodes alone (for callgrind)
//
// A.so and B.so are shared objects of two builds' libamcodec.a (decode_ab.cpp says how). The
// streams come from this program's own encoder, the same for both. --hash decodes a .amh's stream
// (improved and naive traversal) and a .amc file (amc::decode, 1 and 2 threads) and prints an
// FNV-1a hash of every node's fields, ids and every position: equal hashes, equal hierarchies.
// Set MALLOC_MMAP_THRESHOLD_ and MALLOC_TRIM_THRESHOLD_ high (4000000000) to keep the heap between
// decodes, as compare_bench's timed decodes, which give the previous result back first.
#include "bench_common.h"
#include "compare_draco.h"

#include <amc/codec.h>
#include <amc/hierarchy.h>
#include <amc/hierarchy_coder.h>

#include <dlfcn.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace {

using DecodeHierarchy = amc::Hierarchy (*)(const amc::TriangleMesh&, const uint8_t*, size_t,
                                           const amc::HierarchyDecodeOptions&);
using DecodeFile = amc::Hierarchy (*)(const uint8_t*, size_t, const amc::DecodeOptions&, amc::LeafNumbering*);

struct Library {
    DecodeHierarchy decode_hierarchy = nullptr;
    DecodeFile decode = nullptr;
};

Library open_library(const char* path) {
    void* library = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (library == nullptr) throw std::runtime_error(dlerror());
    Library l;
    l.decode_hierarchy = reinterpret_cast<DecodeHierarchy>(
        dlsym(library, "_ZN3amc16decode_hierarchyERKNS_12TriangleMeshEPKhmRKNS_22HierarchyDecodeOptionsE"));
    l.decode = reinterpret_cast<DecodeFile>(dlsym(library, "_ZN3amc6decodeEPKhmRKNS_13DecodeOptionsEPNS_13LeafNumberingE"));
    if (l.decode_hierarchy == nullptr || l.decode == nullptr) throw std::runtime_error(std::string("no decoders in ") + path);
    return l;
}

struct Fnv {
    uint64_t h = 1469598103934665603ull;
    void bytes(const void* data, size_t n) {
        const unsigned char* p = static_cast<const unsigned char*>(data);
        for (size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 1099511628211ull;
    }
    void word(uint64_t w) { bytes(&w, sizeof w); }
};

// Every node's fields as the interface shows them (dead ones as dead), ids included, and every
// position.
uint64_t hash_of(const amc::Hierarchy& h) {
    Fnv f;
    f.word(h.root_count());
    f.word(h.node_capacity());
    f.word(h.node_count());
    f.word(h.vertex_count());
    for (amc::NodeId n = 0; n < h.node_capacity(); ++n) {
        if (!h.is_alive(n)) {
            f.word(~0ull);
            continue;
        }
        uint32_t w[12] = {h.vertex(n, 0), h.vertex(n, 1), h.vertex(n, 2), h.is_leaf(n) ? amc::kNoNode : h.child(n, 0),
                          h.neighbor(n, 0), h.neighbor(n, 1), h.neighbor(n, 2), h.parent(n), uint32_t(h.level(n)),
                          uint32_t(h.neighbor_edge(n, 0) | h.neighbor_edge(n, 1) << 2 | h.neighbor_edge(n, 2) << 4),
                          uint32_t(h.is_boundary_edge(n, 0) | h.is_boundary_edge(n, 1) << 1 | h.is_boundary_edge(n, 2) << 2 |
                                   h.diagonal_flipped(n) << 3),
                          uint32_t(h.child_index(n))};
        f.bytes(w, sizeof w);
    }
    f.word(h.positions().size());
    f.bytes(h.positions().data(), h.positions().size() * sizeof(amc::Vec3));
    f.word(h.base().positions.size());
    f.bytes(h.base().positions.data(), h.base().positions.size() * sizeof(amc::Vec3));
    f.bytes(h.base().triangles.data(), h.base().triangles.size() * sizeof(amc::Triangle));
    return f.h;
}

std::vector<uint8_t> read_file(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (!in && !in.eof()) throw std::runtime_error("can not read " + path);
    return bytes;
}

bool ends_with(const std::string& s, const char* tail) {
    const size_t n = std::strlen(tail);
    return s.size() >= n && s.compare(s.size() - n, n, tail) == 0;
}

// A model as compare_bench codes it: the hierarchy in the decoder's order and its stream.
struct Model {
    std::string name;
    amc::Hierarchy expected;
    std::vector<uint8_t> stream;
    size_t faces = 0;
};

Model load(const std::string& path, amc::Traversal traversal = amc::Traversal::improved) {
    Model m;
    m.name = model_name(path);
    m.expected = amc::in_decoder_order(amc::read_hierarchy(path));
    amc::HierarchyCoderOptions options;
    options.traversal = traversal;
    m.stream = amc::encode_hierarchy(m.expected, options);
    m.faces = amc::extract_leaf_mesh(m.expected).mesh.triangles.size();
    return m;
}

int hash_files(const Library& lib, int argc, char** argv) {
    for (int a = 0; a < argc; ++a) {
        const std::string path = argv[a];
        if (ends_with(path, ".amh")) {
            for (const amc::Traversal t : {amc::Traversal::improved, amc::Traversal::naive}) {
                const Model m = load(path, t);
                const amc::Hierarchy back = lib.decode_hierarchy(m.expected.base(), m.stream.data(), m.stream.size(), {});
                std::printf("%s %s %016llx\n", m.name.c_str(), t == amc::Traversal::naive ? "stream-naive" : "stream-improved",
                            (unsigned long long)hash_of(back));
            }
        } else {
            const std::vector<uint8_t> file = read_file(path);
            for (const unsigned threads : {1u, 2u}) {
                amc::DecodeOptions options;
                options.threads = threads;
                const amc::Hierarchy back = lib.decode(file.data(), file.size(), options, nullptr);
                std::printf("%s file-%ut %016llx\n", path.substr(path.find_last_of('/') + 1).c_str(), threads,
                            (unsigned long long)hash_of(back));
            }
        }
    }
    return 0;
}

int run_alone(const Library& lib, int runs, const std::string& path) {
    const Model m = load(path);
    uint64_t nodes = 0;
    for (int r = 0; r < runs; ++r) {
        const amc::Hierarchy back = lib.decode_hierarchy(m.expected.base(), m.stream.data(), m.stream.size(), {});
        nodes += back.node_count();
    }
    std::printf("%s: %d decodes, %llu nodes\n", m.name.c_str(), runs, (unsigned long long)nodes);
    return 0;
}

int compare(const Library lib[2], int rounds, int argc, char** argv) {
    std::printf("model faces | A ms | B ms | B/A (median of rounds) | Draco ms | A/Draco speed | B/Draco speed | B M faces/s | same\n");
    for (int a = 0; a < argc; ++a) {
        const Model m = load(argv[a]);
        const auto draco_mesh = amc_bench::make_draco_mesh(amc::extract_leaf_mesh(m.expected).mesh, false);
        const std::vector<char> draco_file = amc_bench::draco_encode(*draco_mesh, {5, 12}).bytes;
        amc::Hierarchy back;
        uint64_t hashes[2];
        for (int k = 0; k < 2; ++k) {  // one unmeasured decode each
            back = lib[k].decode_hierarchy(m.expected.base(), m.stream.data(), m.stream.size(), {});
            hashes[k] = hash_of(back);
        }
        std::vector<double> t[3], ratio;
        for (int r = 0; r < rounds; ++r) {
            double s[2];
            for (int j = 0; j < 2; ++j) {
                const int k = (r + j) % 2;  // A first in even rounds
                back = {};
                const double start = thread_seconds();
                back = lib[k].decode_hierarchy(m.expected.base(), m.stream.data(), m.stream.size(), {});
                s[k] = thread_seconds() - start;
                t[k].push_back(s[k]);
            }
            ratio.push_back(s[1] / s[0]);
            amc_bench::DracoDecoded d = amc_bench::draco_decode(draco_file);
            t[2].push_back(d.connectivity_cpu_seconds);
        }
        const double ma = median(t[0]), mb = median(t[1]), md = median(t[2]);
        std::printf("%s %zu | %.3f | %.3f | %.4f | %.3f | %.3f | %.3f | %.1f | %s\n", m.name.c_str(), m.faces, 1e3 * ma, 1e3 * mb,
                    median(ratio), 1e3 * md, md / ma, md / mb, double(m.faces) / mb / 1e6,
                    hashes[0] == hashes[1] ? "same" : "DIFFERENT");
        std::fflush(stdout);
    }
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    try {
        if (argc >= 3 && std::string(argv[1]) == "--hash") return hash_files(open_library(argv[2]), argc - 3, argv + 3);
        if (argc == 5 && std::string(argv[1]) == "--run") return run_alone(open_library(argv[2]), std::atoi(argv[3]), argv[4]);
        if (argc >= 5 && argv[1][0] != '-') {
            const Library lib[2] = {open_library(argv[1]), open_library(argv[2])};
            return compare(lib, std::max(1, std::atoi(argv[3])), argc - 4, argv + 4);
        }
    } catch (const std::exception& e) {
        std::fprintf(stderr, "connectivity_ab: %s\n", e.what());
        return 1;
    }
    std::fprintf(stderr,
                 "usage: connectivity_ab A.so B.so ROUNDS model.amh ... | --hash LIB.so file.amh|file.amc ... | --run LIB.so RUNS model.amh\n");
    return 2;
}
