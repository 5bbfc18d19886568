// Designs of the hierarchy coder's mixing mode measured on its own features (issue 30;
// docs/HIERARCHY_CODER.md, "The second model"): each model's coded symbols with the features the
// mixing mode computes for them (HierarchyLevelEncoder::mixed_symbols), coded again by variants of
// the first model (.amc version 8); exact adaptive code lengths, so one run gives the table. The
// first rows are the coder's own second model (version 10) and the first model. The features of
// each model are kept in CACHE_DIR (default /tmp/mixing_study) after the first run; ONLY=text runs
// only the designs whose name holds it.
//   [CACHE_DIR=dir] [ONLY=text] mixing_study model.amh ...
#include "mixed_symbols.h"

#include "coding/hierarchy/context_mixing.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace {

using namespace amc;
using mixed_study::ModelData;
using mixed_study::Symbol;

// A mixer with chosen initial weights (context_mixing.h's Mixer starts every weight at 1/n).
class Mixer2 {
public:
    Mixer2(int inputs, int sets, int rate, std::vector<int32_t> init) : n_(inputs), rate_(rate) {
        for (int s = 0; s < sets; ++s) w_.insert(w_.end(), init.begin(), init.end());
    }
    int mix(const int* st, int set) {
        set_ = set;
        const int32_t* w = &w_[size_t(set) * size_t(n_)];
        int64_t dot = 0;
        for (int i = 0; i < n_; ++i) dot += int64_t(w[i]) * st[i];
        x_ = int(std::clamp<int64_t>(dot >> 16, -mixing::kStretchLimit, mixing::kStretchLimit));
        p_ = mixing::squash(x_);
        return p_;
    }
    int stretched() const { return x_; }
    void update(const int* st, bool bit) {
        const int err = ((int(bit) << 12) - p_) * rate_;
        int32_t* w = &w_[size_t(set_) * size_t(n_)];
        for (int i = 0; i < n_; ++i) w[i] += (st[i] * err + (1 << 15)) >> 16;
    }

private:
    int n_, rate_, set_ = 0, p_ = 2048, x_ = 0;
    std::vector<int32_t> w_;
};

struct Options {
    bool final_mixer = false;     // a second-layer mixer over the three mixers instead of their mean
    int final_rate = 8;
    int apms = 0;                 // bit mask of extra APMs: 1 mean_curv, 2 disp x level, 4 history, 8 ring2 x parent nbrs
    int apm_share = 2;            // of 4: the APMs' share of the final probability
    bool history_inputs = false;  // inputs from the last coded bits
    int fast_inputs = 0;          // bit mask of inputs that also get a fast model (window 2^fast_log2)
    int fast_log2 = 5;
    int indirect = 0;             // bit mask of inputs that also get a bit-history (indirect) model
    int third_set = 0;            // 0: by disp; 1: by mean_curv / 4; 2: by group x level; 3: by history x group
    bool confidence = false;      // mixer weight set 1 also by the model count of input 11
    int extra_inputs = 0;         // bit mask of extra feature combinations
    int linear = 0;               // bit mask of the features given to the mixer as numbers: 1 mean_curv, 2 disp, 4 bend_sum
    int linear_scale = 16;
    bool second_set = false;  // mixer B by ring_mean / 4 instead of level x center
};

// An indirect model: each context keeps the last bits seen in it (up to 7, with a leading 1),
// and an adaptive probability per such history.
struct Indirect {
    std::vector<uint8_t> hist;
    std::vector<BitModel> map;
    size_t slot = 0;
    explicit Indirect(size_t contexts) : hist(contexts, 1), map(256 * 10, BitModel(6)) {}
};

class Study {
public:
    static constexpr int kBase = MixedHierarchyModel::kInputs;
    explicit Study(const Options& o) : o_(o) {
        static constexpr uint32_t kSizes[kBase] = {10, 40, 40, 80, 50, 120, 240, 960, 1920, 2560, 640, 10240, 3840, 200, 400, 480};
        for (int j = 0; j < kBase; ++j) models_.push_back(std::vector<BitModel>(kSizes[j], BitModel(8)));
        for (int j = 0; j < kBase; ++j)
            if (o.fast_inputs >> j & 1) fast_.push_back({j, std::vector<BitModel>(kSizes[j], BitModel(o.fast_log2))});
        for (int j = 0; j < kBase; ++j)
            if (o.indirect >> j & 1) indirect_.push_back({j, Indirect(kSizes[j])});
        n_ = kBase + int(fast_.size()) + int(indirect_.size()) + (o.history_inputs ? 3 : 0) + extra_count() + __builtin_popcount(unsigned(o.linear)) + 1;
        st_.resize(size_t(n_));
        extra_.resize(size_t(extra_count()));
        for (int e = 0; e < extra_count(); ++e) extra_models_.push_back(std::vector<BitModel>(1 << 16, BitModel(8)));
        if (o.history_inputs) hist_models_.assign(3, std::vector<BitModel>(4096, BitModel(8)));
        const std::vector<int32_t> flat(size_t(n_), (1 << 16) / n_);
        m1_ = std::make_unique<Mixer2>(n_, 10 * (o.confidence ? 4 : 1), 24, flat);
        m2_ = std::make_unique<Mixer2>(n_, 16, 24, flat);
        m3_ = std::make_unique<Mixer2>(n_, 256, 24, flat);
        final_ = std::make_unique<Mixer2>(4, 10, o.final_rate, std::vector<int32_t>{21845, 21845, 21845, 0});
        apm_.emplace_back(40, 7);
        apm_.emplace_back(640, 7);
        apm_.emplace_back(24 * 8, 7);
        apm_.emplace_back(10 * 256, 7);
        apm_.emplace_back(10 * 5 * 4, 7);
        apm_.emplace_back(64 * 8, 7);
    }
    int extra_count() const { return __builtin_popcount(unsigned(o_.extra_inputs)); }

    double code(const std::vector<Symbol>& symbols) {
        double bits = 0;
        for (const Symbol& s : symbols) {
            cur_ = &s;
            const int p = p12(s.f);
            bits -= std::log2(s.bit ? p / 4096.0 : 1 - p / 4096.0);
            update(s.bit);
        }
        return bits;
    }

private:
    int p12(const MixedFeatures& f) {
        const uint32_t g = f.group;
        slot_ = MixedHierarchyModel::direct_slots(f);
        int k = 0;
        for (int j = 0; j < kBase; ++j) st_[size_t(k++)] = mixing::stretch(mixing::p12_of(models_[size_t(j)][slot_[size_t(j)]]));
        for (auto& [j, m] : fast_) st_[size_t(k++)] = mixing::stretch(mixing::p12_of(m[slot_[size_t(j)]]));
        for (auto& [j, ind] : indirect_) {
            ind.slot = slot_[size_t(j)];
            st_[size_t(k++)] = mixing::stretch(mixing::p12_of(ind.map[g * 256 + ind.hist[ind.slot]]));
        }
        if (o_.history_inputs) {
            hslot_ = {(g * 16 + (hist_ & 15)), ((g * 4 + f.inner) * 16 + (hist_ & 15)), (g * 64 + f.mean_curv) * 4 + (hist_ & 3)};
            for (int j = 0; j < 3; ++j) st_[size_t(k++)] = mixing::stretch(mixing::p12_of(hist_models_[size_t(j)][hslot_[size_t(j)]]));
        }
        {
            int e = 0;
            const uint32_t combos[] = {
                ((g * 64 + f.mean_curv) * 5 + f.ring2),
                ((g * 32 + f.bend_sum) * 24 + f.disp),
                ((g * 64 + f.mean_curv) * 4 + f.parent_nbrs),
                ((g * 24 + f.disp_parent) * 24 + f.disp),
                ((g * 4 + f.inner) * 64 + f.mean_curv) * 2 + f.center,
                ((g * 8 + f.level) * 5 + f.ring2) * 4 + f.parent_sibs,
                g * 64 + cur_->ring_max,
                (g * 64 + cur_->ring_mean) * 8 + f.level,
                (g * 64 + cur_->parent_curv) * 8 + f.level,  // now: two-ring mean
                ((g * 64 + cur_->ring_max) * 8 + f.level) * 4 + f.inner,
            };
            for (int c = 0; c < 10; ++c) {
                if (!(o_.extra_inputs >> c & 1)) continue;
                extra_[size_t(e)] = combos[c] & 0xffff;
                st_[size_t(k++)] = mixing::stretch(mixing::p12_of(extra_models_[size_t(e)][extra_[size_t(e)]]));
                ++e;
            }
        }
        if (o_.linear & 1) st_[size_t(k++)] = f.mean_curv == 0 ? 0 : (int(f.mean_curv) - 32) * o_.linear_scale;
        if (o_.linear & 2) st_[size_t(k++)] = f.disp == 0 ? 0 : (int(f.disp) - 12) * o_.linear_scale;
        if (o_.linear & 4) st_[size_t(k++)] = f.bend_sum == 0 ? 0 : (int(f.bend_sum) - 16) * o_.linear_scale;
        st_[size_t(k)] = 256;
        int set1 = int(g);
        if (o_.confidence) {
            const int n = models_[11][slot_[11]].n;
            set1 = set1 * 4 + (n < 2 ? 0 : n < 8 ? 1 : n < 32 ? 2 : 3);
        }
        const int s1 = mixing::stretch(m1_->mix(st_.data(), set1));
        const int s2 = mixing::stretch(m2_->mix(st_.data(), o_.second_set ? int(f.ring_mean / 4) : f.level * 2 + f.center));
        const int set3 = o_.third_set == 0   ? f.disp
                         : o_.third_set == 1 ? f.mean_curv / 4
                         : o_.third_set == 2 ? int(g * 8 + f.level)
                         : o_.third_set == 4 ? int(g * 16 + f.ring_max / 4)
                                             : int(g * 16 + (hist_ & 15));
        const int s3 = mixing::stretch(m3_->mix(st_.data(), set3));
        if (o_.final_mixer) {
            fin_ = {s1, s2, s3, 256};
            p_mix_ = final_->mix(fin_.data(), int(g));
        } else {
            p_mix_ = mixing::squash((s1 + s2 + s3) / 3);
        }
        int sum = apm_[0].refine(p_mix_, int(g * 4 + f.inner));
        int count = 1;
        apm_used_ = {true, false, false, false, false, false};
        if (o_.apms & 1) sum += apm_[1].refine(p_mix_, int(g * 64 + f.mean_curv)), ++count, apm_used_[1] = true;
        if (o_.apms & 2) sum += apm_[2].refine(p_mix_, int(f.disp * 8 + f.level)), ++count, apm_used_[2] = true;
        if (o_.apms & 4) sum += apm_[3].refine(p_mix_, int(g * 256 + (hist_ & 255))), ++count, apm_used_[3] = true;
        if (o_.apms & 16) sum += apm_[5].refine(p_mix_, int(f.ring_max * 8 + f.level)), ++count, apm_used_[5] = true;
        if (o_.apms & 8) sum += apm_[4].refine(p_mix_, int((g * 5 + f.ring2) * 4 + f.parent_nbrs)), ++count, apm_used_[4] = true;
        const int refined = sum / count;
        return std::clamp((p_mix_ * (4 - o_.apm_share) + refined * o_.apm_share + 2) >> 2, 1, 4095);
    }

    void update(bool bit) {
        m1_->update(st_.data(), bit);
        m2_->update(st_.data(), bit);
        m3_->update(st_.data(), bit);
        if (o_.final_mixer) final_->update(fin_.data(), bit);
        for (size_t a = 0; a < apm_.size(); ++a)
            if (apm_used_[a]) apm_[a].update(bit);
        for (int j = 0; j < kBase; ++j) models_[size_t(j)][slot_[size_t(j)]].update(bit);
        for (auto& [j, m] : fast_) m[slot_[size_t(j)]].update(bit);
        for (auto& [j, ind] : indirect_) {
            uint8_t& hb = ind.hist[ind.slot];
            ind.map[size_t(slot_[0]) * 256 + hb].update(bit);
            hb = uint8_t(hb < 128 ? hb * 2 + bit : 128 + ((hb * 2 + bit) & 127));  // as the coder's
        }
        if (o_.history_inputs)
            for (int j = 0; j < 3; ++j) hist_models_[size_t(j)][hslot_[size_t(j)]].update(bit);
        for (size_t e = 0; e < extra_.size(); ++e) extra_models_[e][extra_[e]].update(bit);
        hist_ = (hist_ << 1) | uint32_t(bit);
    }

    const Symbol* cur_ = nullptr;
    Options o_;
    int n_;
    std::vector<std::vector<BitModel>> models_;
    std::vector<std::pair<int, std::vector<BitModel>>> fast_;
    std::vector<std::pair<int, Indirect>> indirect_;
    std::vector<std::vector<BitModel>> hist_models_, extra_models_;
    std::array<uint32_t, 3> hslot_{};
    std::vector<uint32_t> extra_;
    std::array<uint32_t, kBase> slot_{};
    std::vector<int> st_;
    std::array<int, 4> fin_{};
    std::unique_ptr<Mixer2> m1_, m2_, m3_, final_;
    std::vector<mixing::ProbabilityMap> apm_;
    std::array<bool, 6> apm_used_{};
    uint32_t hist_ = 0;
    int p_mix_ = 2048;
};

}  // namespace

int main(int argc, char** argv) {
    const std::filesystem::path cache = std::getenv("CACHE_DIR") ? std::getenv("CACHE_DIR") : "/tmp/mixing_study";
    std::vector<ModelData> data;
    for (int a = 1; a < argc; ++a) data.push_back(mixed_study::load(argv[a], cache));
    struct Design {
        std::string name;
        Options o;
    };
    std::vector<Design> designs;
    designs.push_back({"mixing mode (v8)", {}});
    auto add = [&](const std::string& name, auto change) {
        Options o;
        change(o);
        designs.push_back({name, o});
    };
    const char* only = std::getenv("ONLY");
    add("linear mean curv", [](Options& o) { o.linear = 1; });
    add("linear mean curv, scale 32", [](Options& o) { o.linear = 1, o.linear_scale = 32; });
    add("linear all three", [](Options& o) { o.linear = 7; });
    auto best = [](Options& o) {
        o.history_inputs = true;
        o.indirect = 2 | 16 | 2048;
        o.apms = 15;
        o.apm_share = 3;
        o.third_set = 3;
    };
    add("combo: history, indirect 3, APMs share 3, set by history", best);
    add("combo without set by history", [&](Options& o) { best(o), o.third_set = 0; });
    add("combo + fast 2^4", [&](Options& o) { best(o), o.fast_inputs = 1 | 16 | 1024, o.fast_log2 = 4; });
    add("combo + extra 0, 5", [&](Options& o) { best(o), o.extra_inputs = 1 | 32; });
    add("combo + ring curv (6..9)", [&](Options& o) { best(o), o.extra_inputs = 0x3c0; });
    add("combo + ring curv (6, 7, 9)", [&](Options& o) { best(o), o.extra_inputs = 0x2c0; });
    add("combo + ring curv (6, 7)", [&](Options& o) { best(o), o.extra_inputs = 0xc0; });
 add("R: + APM ring max x level", [&](Options& o) { best(o), o.extra_inputs = 0xc0, o.apms = 31; });
    add("R: set C by group x ring max", [&](Options& o) { best(o), o.extra_inputs = 0xc0, o.third_set = 4; });
    add("R: set B by ring mean", [&](Options& o) { best(o), o.extra_inputs = 0xc0, o.second_set = true; });
    add("R: + extra 0, 5", [&](Options& o) { best(o), o.extra_inputs = 0xc0 | 1 | 32; });
    add("R: + fast 2^4 for ring max", [&](Options& o) { best(o), o.extra_inputs = 0xc0, o.fast_inputs = 1024, o.fast_log2 = 4; });
    add("combo + ring curv (7)", [&](Options& o) { best(o), o.extra_inputs = 0x80; });
    add("final mixer", [](Options& o) { o.final_mixer = true; });
    add("final mixer rate 4", [](Options& o) { o.final_mixer = true, o.final_rate = 4; });
    add("final mixer rate 16", [](Options& o) { o.final_mixer = true, o.final_rate = 16; });
    add("APM + mean curv", [](Options& o) { o.apms = 1; });
    add("APM + disp x level", [](Options& o) { o.apms = 2; });
    add("APM + history", [](Options& o) { o.apms = 4; });
    add("APM + ring2 x parent nbrs", [](Options& o) { o.apms = 8; });
    add("APM all four", [](Options& o) { o.apms = 15; });
    add("APM all four, share 3", [](Options& o) { o.apms = 15, o.apm_share = 3; });
    add("history inputs", [](Options& o) { o.history_inputs = true; });
    add("fast models (2^5) for group, ring2, mean curv", [](Options& o) { o.fast_inputs = 1 | 16 | 1024; });
    add("fast models (2^4) for group, ring2, mean curv", [](Options& o) { o.fast_inputs = 1 | 16 | 1024, o.fast_log2 = 4; });
    add("indirect for inner, ring2, mean curv x level", [](Options& o) { o.indirect = 2 | 16 | 2048; });
    add("indirect for all 16", [](Options& o) { o.indirect = 0xffff; });
    add("third set by mean curv", [](Options& o) { o.third_set = 1; });
    add("third set by group x level", [](Options& o) { o.third_set = 2; });
    add("third set by group x history", [](Options& o) { o.third_set = 3; });
    add("set 1 by confidence", [](Options& o) { o.confidence = true; });
    for (int c = 0; c < 10; ++c) add("extra input " + std::to_string(c), [c](Options& o) { o.extra_inputs = 1 << c; });
    const double paper_total = mixed_study::print_design_table_head(data);
    {
        double total = 0, mean = 0;
        std::vector<double> change;
        for (const ModelData& d : data) {
            total += d.library_bits;
            change.push_back(100.0 * (d.library_bits - d.paper_bits) / d.paper_bits);
            mean += change.back() / double(data.size());
        }
        std::printf("| the coder's mixing mode (newest model) | %+.2f%% | %+.2f%% |", 100.0 * (total - paper_total) / paper_total, mean);
        for (double c : change) std::printf(" %+.1f%% |", c);
        std::printf("\n");
    }
    for (const Design& design : designs) {
        if (only && design.name.find(only) == std::string::npos && &design != &designs[0]) continue;
        double total = 0, mean = 0;
        std::vector<double> change;
        for (const ModelData& d : data) {
            Study s(design.o);
            const double bits = s.code(d.symbols);
            total += bits;
            change.push_back(100.0 * (bits - d.paper_bits) / d.paper_bits);
            mean += change.back() / double(data.size());
        }
        std::printf("| %s | %+.2f%% | %+.2f%% |", design.name.c_str(), 100.0 * (total - paper_total) / paper_total, mean);
        for (double c : change) std::printf(" %+.1f%% |", c);
        std::printf("\n");
        std::fflush(stdout);
    }
    return 0;
}
