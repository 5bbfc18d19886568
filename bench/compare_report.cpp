#include "compare_report.h"

#include "bench_common.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <stdexcept>
#include <tuple>

namespace amc_bench {

namespace {

struct Column {
    const char* coder;
    const char* label;
};

// Connectivity coders, in table order.
const Column kConnectivityColumns[] = {
    {"raw", "raw indices"},
    {"zstd-19", "zstd -19"},
    {"xz-9", "xz -9"},
    {"meshopt", "meshopt"},
    {"meshopt+zstd", "meshopt + zstd"},
    {"draco-default", "Draco default"},
    {"draco-best", "Draco best"},
    {"one-bit-per-node", "1 bit/node"},
    {"naive-hierarchy", "naive coder"},
    {"amc-paper-naive", "paper, naive trav."},
    {"amc-paper-improved", "paper, improved trav."},
    {"amc-best", "amcodec best"},
    {"amc-mixed", "amcodec mixed"},
    {"amc-imported", "amcodec, leaf mesh only"},
};

const char* const kMeshPayloads[] = {"mesh-lossless", "mesh-16", "mesh-12"};
const Column kMeshCoders[] = {{"amc-best", "amcodec"}, {"draco-best", "Draco best"}, {"draco-default", "Draco default"}};

// The paper's Table 3 (bytes) and the corpus model made as its analogue (same source model where
// ../shared/data has it, same curvature criterion).
struct PaperRow {
    const char* model;
    uint64_t faces;
    uint64_t optimized_edgebreaker;
    uint64_t ours;
    const char* analogue;  // "" when the corpus has none
};
const PaperRow kPaperTable3[] = {
    {"bones", 5622, 853, 638, ""},
    {"bunny", 90771, 8740, 3656, "bunny-hr_mean"},
    {"fandisk", 86092, 8041, 3164, "fandisk_mean"},
    {"feline_gauss", 199008, 16499, 6111, "feline_gauss"},
    {"feline_mean", 254044, 19347, 7853, "feline_mean"},
    {"femur", 8944, 784, 400, "femur_mean"},
    {"heat_transfer", 96412, 7612, 3823, ""},
    {"horse", 96368, 7811, 3266, "horse_mean"},
    {"rabbit", 68506, 6325, 2735, "bunny-hr_gauss"},
    {"venus", 138672, 10505, 4601, "venus_gauss"},
};

// The procedural models, and the plain meshes (named "NAME (mesh)"); every other model is
// remeshed from a real surface.
bool is_procedural(const std::string& model) {
    return model == "lshape" || model == "uniform" || model == "random" || model.rfind("front_", 0) == 0;
}
bool is_remeshed_surface(const std::string& model) {
    return !is_procedural(model) && model.find(" (mesh)") == std::string::npos;
}

class Index {
public:
    explicit Index(const std::vector<Result>& results) {
        for (const Result& r : results) {
            if (by_key_.emplace(std::make_tuple(r.model, r.coder, r.payload), &r).second &&
                std::find(models_.begin(), models_.end(), r.model) == models_.end())
                models_.push_back(r.model);
        }
    }
    const Result* find(const std::string& model, const std::string& coder, const std::string& payload) const {
        const auto it = by_key_.find(std::make_tuple(model, coder, payload));
        return it == by_key_.end() ? nullptr : it->second;
    }
    const std::vector<std::string>& models() const { return models_; }
    // Any result of the model, for its counts.
    const Result& any(const std::string& model) const {
        for (const auto& [key, r] : by_key_)
            if (std::get<0>(key) == model) return *r;
        throw std::logic_error("no result for " + model);
    }

private:
    std::map<std::tuple<std::string, std::string, std::string>, const Result*> by_key_;
    std::vector<std::string> models_;
};

std::string format(const char* pattern, double value) {
    char text[64];
    std::snprintf(text, sizeof text, pattern, value);
    return text;
}

double bits_per_face(const Result& r) { return 8.0 * double(r.bytes) / double(r.faces); }

// Marks a figure whose decoded result did not match its input.
std::string flagged(const Result& r, const std::string& text) { return passed(r) ? text : text + " (FAILED)"; }

// Million faces per second; 0 when not timed.
double mfaces_per_second(uint64_t faces, double seconds) { return seconds > 0 ? double(faces) / seconds / 1e6 : 0.0; }

// A rate in million faces per second as the speed tables write it: two decimals below 10, one
// below 100, none from 100.
std::string rate_text(double mfaces) { return format(mfaces >= 100 ? "%.0f" : mfaces >= 10 ? "%.1f" : "%.2f", mfaces); }

std::string speed(uint64_t faces, double seconds) { return seconds <= 0 ? "–" : rate_text(mfaces_per_second(faces, seconds)); }

// How the tables name a complete-mesh payload: "lossless" for mesh-lossless, "16 bits" for mesh-16.
std::string payload_label(const std::string& payload) {
    return payload == "mesh-lossless" ? "lossless" : payload.substr(std::string("mesh-").size()) + " bits";
}

std::string speed_pair(const Result* r) {
    if (r == nullptr) return "–";
    return flagged(*r, speed(r->faces, r->encode_seconds) + " / " + speed(r->faces, r->decode_seconds));
}

double mean(const std::vector<double>& v) {
    double sum = 0;
    for (double x : v) sum += x;
    return v.empty() ? 0 : sum / double(v.size());
}

double geometric_mean(const std::vector<double>& v) {
    double sum = 0;
    for (double x : v) sum += std::log(x);
    return v.empty() ? 0 : std::exp(sum / double(v.size()));
}

void print_header(FILE* f, const std::string& first, const std::vector<std::string>& columns, const std::string& align) {
    std::fprintf(f, "| %s |", first.c_str());
    for (const std::string& c : columns) std::fprintf(f, " %s |", c.c_str());
    std::fprintf(f, "\n|---|");
    for (size_t i = 0; i < columns.size(); ++i) std::fprintf(f, "%s|", align.c_str());
    std::fprintf(f, "\n");
}

void print_row(FILE* f, const std::string& first, const std::vector<std::string>& cells) {
    std::fprintf(f, "| %s |", first.c_str());
    for (const std::string& c : cells) std::fprintf(f, " %s |", c.c_str());
    std::fprintf(f, "\n");
}

void connectivity_bytes_table(FILE* f, const Index& index) {
    std::fprintf(f, "### Connectivity: bytes (the paper's Table 3)\n\n");
    std::vector<std::string> columns{"faces", "nodes"};
    for (const Column& c : kConnectivityColumns) columns.push_back(c.label);
    print_header(f, "model", columns, "---:");
    for (const std::string& model : index.models()) {
        const Result& any = index.any(model);
        std::vector<std::string> cells{std::to_string(any.faces), std::to_string(any.nodes)};
        for (const Column& c : kConnectivityColumns) {
            const Result* r = index.find(model, c.coder, "connectivity");
            cells.push_back(r ? flagged(*r, std::to_string(r->bytes)) : "–");
        }
        print_row(f, model, cells);
    }
    std::fprintf(f, "\n");
}

void connectivity_bits_table(FILE* f, const Index& index) {
    std::fprintf(f, "### Connectivity: bits per face\n\n");
    std::vector<std::string> columns;
    for (const Column& c : kConnectivityColumns) columns.push_back(c.label);
    print_header(f, "model", columns, "---:");
    std::vector<std::vector<double>> per_column(std::size(kConnectivityColumns));
    for (const std::string& model : index.models()) {
        std::vector<std::string> cells;
        for (size_t i = 0; i < std::size(kConnectivityColumns); ++i) {
            const Result* r = index.find(model, kConnectivityColumns[i].coder, "connectivity");
            if (r == nullptr) {
                cells.push_back("–");
                continue;
            }
            cells.push_back(flagged(*r, format("%.3f", bits_per_face(*r))));
            per_column[i].push_back(bits_per_face(*r));
        }
        print_row(f, model, cells);
    }
    std::vector<std::string> means;
    for (const std::vector<double>& v : per_column) means.push_back("**" + format("%.3f", mean(v)) + "**");
    print_row(f, "**mean**", means);
    std::fprintf(f, "\n");
}

// Ratios of a peer's connectivity size to amcodec's: how many times smaller amcodec's code is.
void ratio_table(FILE* f, const Index& index) {
    struct Ratio {
        const char* label;
        const char* peer;
        const char* ours;
    };
    const Ratio ratios[] = {
        {"Draco best / amcodec best", "draco-best", "amc-best"},
        {"Draco default / amcodec best", "draco-default", "amc-best"},
        {"Draco best / amcodec mixed", "draco-best", "amc-mixed"},
        {"paper improved / amcodec mixed", "amc-paper-improved", "amc-mixed"},
        {"Draco best / paper improved", "draco-best", "amc-paper-improved"},
        {"Draco best / paper naive", "draco-best", "amc-paper-naive"},
        {"meshopt + zstd / amcodec best", "meshopt+zstd", "amc-best"},
        {"xz -9 / amcodec best", "xz-9", "amc-best"},
    };
    std::fprintf(f, "### Connectivity: how many times smaller amcodec's code is\n\n");
    std::vector<std::string> columns;
    for (const Ratio& r : ratios) columns.push_back(r.label);
    print_header(f, "model", columns, "---:");
    std::vector<std::vector<double>> all(std::size(ratios)), surfaces(std::size(ratios)), all_but_uniform(std::size(ratios));
    for (const std::string& model : index.models()) {
        std::vector<std::string> cells;
        for (size_t i = 0; i < std::size(ratios); ++i) {
            const Result* peer = index.find(model, ratios[i].peer, "connectivity");
            const Result* ours = index.find(model, ratios[i].ours, "connectivity");
            if (peer == nullptr || ours == nullptr || peer->bytes == 0 || ours->bytes == 0 || !passed(*peer) || !passed(*ours)) {
                cells.push_back("–");
                continue;
            }
            const double ratio = double(peer->bytes) / double(ours->bytes);
            cells.push_back(format("%.2f", ratio));
            all[i].push_back(ratio);
            if (is_remeshed_surface(model)) surfaces[i].push_back(ratio);
            if (model != "uniform") all_but_uniform[i].push_back(ratio);
        }
        print_row(f, model, cells);
    }
    auto summary = [&](const char* label, const std::vector<std::vector<double>>& values, double (*average)(const std::vector<double>&)) {
        std::vector<std::string> cells;
        for (const std::vector<double>& v : values) cells.push_back("**" + format("%.2f", average(v)) + "**");
        print_row(f, label, cells);
    };
    // The uniform model is coded in a few bytes by the hierarchy coder: its ratios are in the
    // thousands and would make an arithmetic mean over all models meaningless.
    summary("**mean, remeshed surfaces**", surfaces, mean);
    summary("**mean, all models but uniform**", all_but_uniform, mean);
    summary("**geometric mean, all models**", all, geometric_mean);
    std::fprintf(f, "\n");
}

void paper_table(FILE* f, const Index& index) {
    std::fprintf(f, "### Beside the paper's Table 3\n\n");
    std::fprintf(f, "The paper's models are not ours (see above); bits per face make them comparable.\n\n");
    print_header(f, "paper model",
                 {"f", "optEB bytes", "paper bytes", "optEB / paper", "optEB b/f", "paper b/f", "our analogue", "f",
                  "Draco best bytes", "amcodec bytes", "Draco best / amcodec", "Draco best b/f", "amcodec b/f"},
                 "---:");
    std::vector<double> paper_ratios, our_ratios;
    for (const PaperRow& p : kPaperTable3) {
        const double paper_ratio = double(p.optimized_edgebreaker) / double(p.ours);
        paper_ratios.push_back(paper_ratio);
        std::vector<std::string> cells{std::to_string(p.faces), std::to_string(p.optimized_edgebreaker), std::to_string(p.ours),
                                       format("%.2f", paper_ratio), format("%.3f", 8.0 * double(p.optimized_edgebreaker) / double(p.faces)),
                                       format("%.3f", 8.0 * double(p.ours) / double(p.faces))};
        const Result* draco = *p.analogue ? index.find(p.analogue, "draco-best", "connectivity") : nullptr;
        const Result* ours = *p.analogue ? index.find(p.analogue, "amc-best", "connectivity") : nullptr;
        if (draco && ours && passed(*draco) && passed(*ours)) {
            const double ratio = double(draco->bytes) / double(ours->bytes);
            our_ratios.push_back(ratio);
            cells.insert(cells.end(), {p.analogue, std::to_string(ours->faces), std::to_string(draco->bytes), std::to_string(ours->bytes),
                                       format("%.2f", ratio), format("%.3f", bits_per_face(*draco)), format("%.3f", bits_per_face(*ours))});
        } else {
            cells.insert(cells.end(), {"–", "", "", "", "", "", ""});
        }
        print_row(f, p.model, cells);
    }
    print_row(f, "**mean**", {"", "", "", "**" + format("%.2f", mean(paper_ratios)) + "**", "", "", "", "", "", "",
                              "**" + format("%.2f", mean(our_ratios)) + "**", "", ""});
    std::fprintf(f, "\n");
}

void mesh_table(FILE* f, const Index& index) {
    std::fprintf(f, "### Complete meshes (connectivity and positions)\n\n");
    std::vector<std::string> columns{"coordinates"};
    for (const Column& c : kMeshCoders) {
        columns.push_back(std::string(c.label) + " bytes");
        columns.push_back("b/f");
        columns.push_back("max error");
    }
    columns.push_back("Draco best / amcodec");
    print_header(f, "model", columns, "---:");
    for (const std::string& model : index.models()) {
        for (const char* payload : kMeshPayloads) {
            std::vector<std::string> cells{payload_label(payload)};
            const Result* ours = index.find(model, "amc-best", payload);
            const Result* draco = index.find(model, "draco-best", payload);
            for (const Column& c : kMeshCoders) {
                const Result* r = index.find(model, c.coder, payload);
                if (r == nullptr || r->bytes == 0) {
                    cells.insert(cells.end(), {r ? flagged(*r, "–") : "–", "", ""});
                    continue;
                }
                cells.push_back(flagged(*r, std::to_string(r->bytes)));
                cells.push_back(format("%.2f", bits_per_face(*r)));
                cells.push_back(r->max_error == 0 ? "0" : format("%.2e", r->max_error));
            }
            cells.push_back(ours && draco && ours->bytes && draco->bytes ? format("%.2f", double(draco->bytes) / double(ours->bytes)) : "–");
            print_row(f, model, cells);
        }
    }
    std::fprintf(f, "\n");
}

// The per-model rates of a speed table's columns, for its closing row of medians.
struct SpeedColumns {
    std::vector<std::vector<double>> encode, decode;  // million faces per second
    explicit SpeedColumns(size_t columns) : encode(columns), decode(columns) {}
    void add(size_t column, const Result* r) {
        if (!r || r->encode_seconds <= 0 || r->decode_seconds <= 0) return;
        encode[column].push_back(mfaces_per_second(r->faces, r->encode_seconds));
        decode[column].push_back(mfaces_per_second(r->faces, r->decode_seconds));
    }
    void print_medians(FILE* f) const {
        std::vector<std::string> medians;
        for (size_t i = 0; i < encode.size(); ++i)
            medians.push_back("**" + rate_text(median(encode[i])) + " / " + rate_text(median(decode[i])) + "**");
        print_row(f, "**median over models**", medians);
        std::fprintf(f, "\n");
    }
};

void connectivity_speed_table(FILE* f, const Index& index) {
    std::fprintf(f, "### Speed, connectivity: encode / decode, million faces per second\n\n");
    std::vector<std::string> columns;
    std::vector<const Column*> timed;
    for (const Column& c : kConnectivityColumns) {
        if (std::string(c.coder) == "raw" || std::string(c.coder) == "one-bit-per-node" || std::string(c.coder) == "amc-mixed") continue;
        timed.push_back(&c);
        columns.push_back(c.label);
    }
    print_header(f, "model", columns, "---:");
    SpeedColumns speeds(timed.size());
    for (const std::string& model : index.models()) {
        std::vector<std::string> cells;
        for (size_t i = 0; i < timed.size(); ++i) {
            const Result* r = index.find(model, timed[i]->coder, "connectivity");
            cells.push_back(speed_pair(r));
            speeds.add(i, r);
        }
        print_row(f, model, cells);
    }
    speeds.print_medians(f);
}

// The leaf mesh as users have it, without its hierarchy: what import_mesh finds and what that costs.
void imported_table(FILE* f, const Index& index) {
    std::fprintf(f, "### From the leaf mesh alone (as users have it): connectivity bytes\n\n");
    std::fprintf(f, "The hierarchy coded by *amcodec best* is the corpus hierarchy (for a mesh file: the one found\n"
                    "in it); *leaf mesh only* imports the conforming leaf mesh over the coarsest base found in its\n"
                    "connectivity (`import_mesh`) and codes that; its speed includes the import.\n\n");
    print_header(f, "model",
                 {"faces", "base triangles", "base found", "amcodec best", "leaf mesh only", "only / best", "Draco best",
                  "Draco best / leaf mesh only", "import + encode M faces/s"},
                 "---:");
    for (const std::string& model : index.models()) {
        const Result* best = index.find(model, "amc-best", "connectivity");
        const Result* imported = index.find(model, "amc-imported", "connectivity");
        const Result* draco = index.find(model, "draco-best", "connectivity");
        if (best == nullptr || imported == nullptr) continue;
        print_row(f, model,
                  {std::to_string(best->faces), std::to_string(best->base_triangles), std::to_string(imported->base_triangles),
                   flagged(*best, std::to_string(best->bytes)), flagged(*imported, std::to_string(imported->bytes)),
                   format("%.3f", double(imported->bytes) / double(best->bytes)),
                   draco ? flagged(*draco, std::to_string(draco->bytes)) : "–",
                   draco ? format("%.2f", double(draco->bytes) / double(imported->bytes)) : "–",
                   rate_text(mfaces_per_second(imported->faces, imported->encode_seconds))});
    }
    std::fprintf(f, "\n");
}

void mesh_speed_table(FILE* f, const Index& index) {
    std::fprintf(f, "### Speed, complete meshes: encode / decode, million faces per second\n\n");
    std::vector<std::string> columns;
    for (const Column& c : kMeshCoders)
        for (const char* payload : kMeshPayloads)
            columns.push_back(std::string(c.label) + " " + payload_label(payload));
    print_header(f, "model", columns, "---:");
    SpeedColumns speeds(columns.size());
    for (const std::string& model : index.models()) {
        std::vector<std::string> cells;
        size_t i = 0;
        for (const Column& c : kMeshCoders)
            for (const char* payload : kMeshPayloads) {
                const Result* r = index.find(model, c.coder, payload);
                cells.push_back(speed_pair(r));
                speeds.add(i++, r);
            }
        print_row(f, model, cells);
    }
    speeds.print_medians(f);
}

void check_summary(FILE* f, const std::vector<Result>& results, int runs) {
    size_t checked = 0;
    std::vector<const Result*> failed;
    for (const Result& r : results) {
        if (r.check == "computed") continue;
        ++checked;
        if (!passed(r)) failed.push_back(&r);
    }
    std::fprintf(f, "### Checks\n\n");
    if (failed.empty()) {
        std::fprintf(f, "All %zu decoded results (every coder, model and mode, last of %d runs) matched their input.\n\n", checked,
                     runs);
    } else {
        std::fprintf(f, "%zu of %zu decoded results did **not** match their input:\n\n", failed.size(), checked);
        print_header(f, "model", {"coder", "payload", "problem"}, "---");
        for (const Result* r : failed) print_row(f, r->model, {r->coder, r->payload, r->check});
        std::fprintf(f, "\n");
    }
    bool any_note = false;
    for (const Result& r : results) {
        if (r.note.empty() || r.payload != "connectivity") continue;
        if (!any_note) std::fprintf(f, "Tolerated by the checks (the same in every mode of the coder):\n\n");
        any_note = true;
        std::fprintf(f, "- %s, %s: %s\n", r.model.c_str(), r.coder.c_str(), r.note.c_str());
    }
    if (any_note) std::fprintf(f, "\n");
}

}  // namespace

bool passed(const Result& r) { return r.check == "ok" || r.check == "computed"; }

void write_csv(const std::string& path, const std::vector<Result>& results) {
    FILE* f = std::fopen(path.c_str(), "w");
    if (f == nullptr) throw std::runtime_error(path + ": cannot write");
    std::fprintf(f, "model,faces,vertices,nodes,coder,payload,bytes,bits_per_face,connectivity_bytes,max_error,"
                    "encode_seconds,decode_seconds,encode_mfaces_per_s,decode_mfaces_per_s,check,note\n");
    for (const Result& r : results) {
        std::string check = r.check, note = r.note;
        for (std::string* text : {&check, &note}) {
            std::replace(text->begin(), text->end(), ',', ';');
            std::replace(text->begin(), text->end(), '"', '\'');
        }
        std::fprintf(f, "%s,%llu,%llu,%llu,%s,%s,%llu,%.6f,%llu,%.9g,%.6f,%.6f,%.4f,%.4f,%s,%s\n", r.model.c_str(),
                     (unsigned long long)r.faces, (unsigned long long)r.vertices, (unsigned long long)r.nodes, r.coder.c_str(),
                     r.payload.c_str(), (unsigned long long)r.bytes, r.faces ? bits_per_face(r) : 0.0,
                     (unsigned long long)r.connectivity_bytes, r.max_error, r.encode_seconds, r.decode_seconds,
                     mfaces_per_second(r.faces, r.encode_seconds), mfaces_per_second(r.faces, r.decode_seconds), check.c_str(),
                     note.c_str());
    }
    if (std::fclose(f) != 0) throw std::runtime_error(path + ": write error");
}

void write_markdown(const std::string& path, const std::vector<Result>& results, int runs) {
    FILE* f = std::fopen(path.c_str(), "w");
    if (f == nullptr) throw std::runtime_error(path + ": cannot write");
    const Index index(results);
    connectivity_bytes_table(f, index);
    connectivity_bits_table(f, index);
    ratio_table(f, index);
    imported_table(f, index);
    paper_table(f, index);
    mesh_table(f, index);
    connectivity_speed_table(f, index);
    mesh_speed_table(f, index);
    check_summary(f, results, runs);
    if (std::fclose(f) != 0) throw std::runtime_error(path + ": write error");
}

}  // namespace amc_bench
