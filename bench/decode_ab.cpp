// decode_ab: two builds of the library decoding the same files in one process, decode by decode in
// turn, timed as this thread's CPU time: on a shared machine the other processes and the host's
// minutes weigh on both builds alike, where whole processes run one after the other differ by tens
// of percent (docs/BENCHMARKS.md, "One-core complete decode, tenth step").
//
//   decode_ab A.so B.so ROUNDS file.amc ...
//   decode_ab A.so B.so ROUNDS a.amc=b.amc ...   (a format change: A decodes a.amc, B b.amc)
//
// A.so and B.so are the two builds' libraries as shared objects: a build configured with
// -DBUILD_SHARED_LIBS=ON, or a static build's libamcodec.a made one by
//   c++ -shared -Wl,-Bsymbolic -o A.so -Wl,--whole-archive libamcodec.a -Wl,--no-whole-archive -lxxhash -lpthread
// Each round decodes every file once with each build (one thread; A first in even rounds, B first
// in odd ones), after one unmeasured decode each. Per file it prints the median time of each build
// and the median over the rounds of B's time over A's. Set MALLOC_MMAP_THRESHOLD_ and
// MALLOC_TRIM_THRESHOLD_ high (4000000000) to keep the heap between decodes, as a long-running
// process does.
#include <amc/codec.h>
#include <amc/hierarchy.h>

#include <dlfcn.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace {

using Decode = amc::Hierarchy (*)(const uint8_t*, size_t, const amc::DecodeOptions&, amc::LeafNumbering*);

double thread_seconds() {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    const size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 5) {
        std::fprintf(stderr, "usage: decode_ab A.so B.so ROUNDS file.amc ...\n");
        return 2;
    }
    Decode decode[2];
    for (int k = 0; k < 2; ++k) {
        void* library = dlopen(argv[1 + k], RTLD_NOW | RTLD_LOCAL);
        if (library == nullptr) {
            std::fprintf(stderr, "decode_ab: %s\n", dlerror());
            return 1;
        }
        // amc::decode(const uint8_t*, size_t, const DecodeOptions&, LeafNumbering*)
        decode[k] = reinterpret_cast<Decode>(dlsym(library, "_ZN3amc6decodeEPKhmRKNS_13DecodeOptionsEPNS_13LeafNumberingE"));
        if (decode[k] == nullptr) {
            std::fprintf(stderr, "decode_ab: no amc::decode in %s\n", argv[1 + k]);
            return 1;
        }
    }
    const int rounds = std::max(1, std::atoi(argv[3]));
    amc::DecodeOptions options;
    options.threads = 1;
    for (int a = 4; a < argc; ++a) {
        const std::string arg = argv[a];
        const size_t split = arg.find('=');
        const std::string path[2] = {arg.substr(0, split), split == std::string::npos ? arg : arg.substr(split + 1)};
        std::vector<uint8_t> file[2];
        for (int k = 0; k < 2; ++k) {
            std::ifstream in(path[k], std::ios::binary);
            file[k].assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
            if (!in && !in.eof()) {
                std::fprintf(stderr, "decode_ab: can not read %s\n", path[k].c_str());
                return 1;
            }
        }
        for (int k = 0; k < 2; ++k) decode[k](file[k].data(), file[k].size(), options, nullptr);
        std::vector<double> ms[2], ratio;
        for (int r = 0; r < rounds; ++r) {
            double seconds[2];
            for (int j = 0; j < 2; ++j) {
                const int k = (r + j) % 2;
                const double start = thread_seconds();
                { const amc::Hierarchy h = decode[k](file[k].data(), file[k].size(), options, nullptr); }
                seconds[k] = thread_seconds() - start;
                ms[k].push_back(1e3 * seconds[k]);
            }
            ratio.push_back(seconds[1] / seconds[0]);
        }
        std::printf("%s: A %.3f ms, B %.3f ms (medians of %d); B / A %.4f (median of the rounds' ratios)\n", argv[a],
                    median(ms[0]), median(ms[1]), rounds, median(ratio));
    }
    return 0;
}
