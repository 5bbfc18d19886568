// Level decoders kept between decodes (decoder_pool.h).
#include "coding/hierarchy/decoder_pool.h"

#include "common/parallel.h"

#include <mutex>
#include <vector>

namespace amc {

namespace {

struct DecoderPool {
    std::mutex mutex;
    std::vector<std::unique_ptr<HierarchyLevelDecoder>> idle;
};

DecoderPool& pool() {
    static DecoderPool* const instance = new DecoderPool;  // never destroyed: decodes may run during exit
    return *instance;
}

}  // namespace

std::unique_ptr<HierarchyLevelDecoder> take_pooled_decoder() {
    DecoderPool& p = pool();
    {
        std::lock_guard<std::mutex> lock(p.mutex);
        if (!p.idle.empty()) {
            std::unique_ptr<HierarchyLevelDecoder> decoder = std::move(p.idle.back());
            p.idle.pop_back();
            return decoder;
        }
    }
    return std::make_unique<HierarchyLevelDecoder>();
}

void return_pooled_decoder(std::unique_ptr<HierarchyLevelDecoder> decoder) {
    DecoderPool& p = pool();
    std::lock_guard<std::mutex> lock(p.mutex);
    if (p.idle.size() < resolve_thread_count(0)) p.idle.push_back(std::move(decoder));
}

}  // namespace amc
