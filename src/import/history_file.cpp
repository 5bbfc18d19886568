// The refinement history file, version 1 (docs/IMPORT.md, "The history file"): a magic line,
// a base mesh (a path or inline), then steps of "refine" / "coarsen" element lists.
#include <amc/import.h>
#include <amc/mesh_io.h>

#include "common/check.h"
#include "common/file_io.h"
#include "mesh/text_number.h"

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace amc {

namespace {

constexpr int kHistoryVersion = 1;
constexpr std::string_view kMagic = "amc-history";

// The text cut into lines, each into whitespace-separated tokens ('#' starts a comment).
struct Line {
    uint32_t number;
    std::vector<std::string_view> tokens;
    std::string_view rest_after_first;  // the line after its first token, trimmed (paths)
};

std::string_view trim(std::string_view s) {
    const auto is_space = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; };
    while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
    while (!s.empty() && is_space(s.back())) s.remove_suffix(1);
    return s;
}

std::vector<Line> split_lines(std::string_view text) {
    std::vector<Line> lines;
    uint32_t number = 0;
    while (!text.empty()) {
        ++number;
        const size_t end = text.find('\n');
        std::string_view line = text.substr(0, end);
        text = end == std::string_view::npos ? std::string_view() : text.substr(end + 1);
        const size_t hash = line.find('#');
        if (hash != std::string_view::npos) line = line.substr(0, hash);
        line = trim(line);
        if (line.empty()) continue;
        Line out{number, {}, {}};
        for (std::string_view rest = line; !rest.empty();) {
            size_t stop = 0;
            while (stop < rest.size() && rest[stop] != ' ' && rest[stop] != '\t') ++stop;
            out.tokens.push_back(rest.substr(0, stop));
            if (out.tokens.size() == 1) out.rest_after_first = trim(rest.substr(stop));
            rest = trim(rest.substr(stop));
        }
        lines.push_back(std::move(out));
    }
    return lines;
}

class Parser {
public:
    Parser(std::string_view text, const std::string& what, const std::string& directory)
        : lines_(split_lines(text)), what_(what), directory_(directory) {}

    RefinementHistory parse() {
        RefinementHistory history;
        history.source = what_;
        AMC_REQUIRE(!lines_.empty() && lines_[0].number == 1 && lines_[0].tokens[0] == kMagic, bad_magic,
                    what_ + ":1: not an amc refinement history (the first line must be \"amc-history 1\")");
        const Line& magic = lines_[0];
        AMC_REQUIRE(magic.tokens.size() == 2, invalid_input, at(magic) + "expected \"amc-history <version>\"");
        const int64_t version = integer(magic, 1);
        AMC_REQUIRE(version <= kHistoryVersion, unsupported_version,
                    at(magic) + "version " + std::to_string(version) + " is newer than this build reads (" +
                        std::to_string(kHistoryVersion) + ")");
        AMC_REQUIRE(version >= 1, invalid_input, at(magic) + "version " + std::to_string(version) + " does not exist");
        bool have_base = false;
        for (size_t i = 1; i < lines_.size(); ++i) {
            const Line& line = lines_[i];
            const std::string_view key = line.tokens[0];
            if (key == "base" || key == "base-inline") {
                AMC_REQUIRE(!have_base, invalid_input, at(line) + "a second base mesh");
                AMC_REQUIRE(history.steps.empty(), invalid_input, at(line) + "the base mesh must come before the steps");
                history.base = key == "base" ? base_from_path(line) : base_inline(line, i);
                have_base = true;
            } else if (key == "step") {
                AMC_REQUIRE(have_base, invalid_input, at(line) + "a step before the base mesh");
                AMC_REQUIRE(line.tokens.size() == 1, invalid_input, at(line) + "\"step\" takes nothing after it");
                history.steps.push_back({});
                history.steps.back().line = line.number;
            } else if (key == "refine" || key == "coarsen") {
                AMC_REQUIRE(!history.steps.empty(), invalid_input,
                            at(line) + "\"" + std::string(key) + "\" before the first \"step\"");
                std::vector<uint32_t>& list = key == "refine" ? history.steps.back().refine : history.steps.back().coarsen;
                for (size_t t = 1; t < line.tokens.size(); ++t) {
                    const int64_t e = integer(line, t);
                    AMC_REQUIRE(e >= 0 && e <= int64_t(UINT32_MAX), invalid_input,
                                at(line) + "element " + std::to_string(e) + " is not an element index");
                    list.push_back(uint32_t(e));
                }
            } else {
                throw_error(ErrorCode::invalid_input, at(line) + "unknown keyword " + text::quote_token(key) +
                                                          " (expected base, base-inline, step, refine or coarsen)");
            }
        }
        AMC_REQUIRE(have_base, invalid_input, what_ + ": no base mesh (a \"base\" or \"base-inline\" line)");
        return history;
    }

private:
    std::string at(const Line& line) const { return what_ + ":" + std::to_string(line.number) + ": "; }

    int64_t integer(const Line& line, size_t t) const {
        int64_t value = 0;
        AMC_REQUIRE(text::parse_int(line.tokens[t], value), invalid_input,
                    at(line) + "expected an integer, not " + text::quote_token(line.tokens[t]));
        return value;
    }

    TriangleMesh base_from_path(const Line& line) const {
        AMC_REQUIRE(!line.rest_after_first.empty(), invalid_input, at(line) + "\"base\" needs the path of a mesh file");
        std::filesystem::path path(std::string(line.rest_after_first));
        if (path.is_relative()) path = std::filesystem::path(directory_) / path;
        try {
            return read_mesh(path.string());
        } catch (const Error& e) {
            throw e.prefixed(at(line) + "base mesh");
        }
    }

    // base-inline V F [float32|float64], then V lines "v x y z" and F lines "f a b c" (0-based).
    TriangleMesh base_inline(const Line& head, size_t& i) const {
        AMC_REQUIRE(head.tokens.size() == 3 || head.tokens.size() == 4, invalid_input,
                    at(head) + "expected \"base-inline <vertices> <triangles> [float32|float64]\"");
        const int64_t v = integer(head, 1), f = integer(head, 2);
        TriangleMesh mesh;
        if (head.tokens.size() == 4) {
            AMC_REQUIRE(head.tokens[3] == "float32" || head.tokens[3] == "float64", invalid_input,
                        at(head) + "expected float32 or float64, not " + text::quote_token(head.tokens[3]));
            mesh.single_precision = head.tokens[3] == "float32";
        }
        // The counts are checked against the lines that are there before anything is allocated.
        const int64_t available = int64_t(lines_.size() - i - 1);
        AMC_REQUIRE(v >= 0 && f >= 1 && v <= available && f <= available - v, invalid_input,
                    at(head) + "the counts " + std::to_string(v) + " and " + std::to_string(f) +
                        " do not fit the lines that follow");
        mesh.positions.reserve(size_t(v));
        mesh.triangles.reserve(size_t(f));
        for (int64_t k = 0; k < v; ++k) {
            const Line& line = lines_[++i];
            AMC_REQUIRE(line.tokens[0] == "v" && line.tokens.size() == 4, invalid_input,
                        at(line) + "expected vertex line \"v x y z\" (" + std::to_string(k) + " of " +
                            std::to_string(v) + ")");
            double c[3];
            for (int j = 0; j < 3; ++j) {
                const bool ok = mesh.single_precision ? [&] {
                    float x = 0;
                    const bool good = text::parse_real(line.tokens[j + 1], x);
                    c[j] = x;
                    return good;
                }()
                                                      : text::parse_real(line.tokens[j + 1], c[j]);
                AMC_REQUIRE(ok, invalid_input, at(line) + "expected a number, not " + text::quote_token(line.tokens[j + 1]));
            }
            mesh.positions.push_back({c[0], c[1], c[2]});
        }
        for (int64_t k = 0; k < f; ++k) {
            const Line& line = lines_[++i];
            AMC_REQUIRE(line.tokens[0] == "f" && line.tokens.size() == 4, invalid_input,
                        at(line) + "expected triangle line \"f a b c\" (" + std::to_string(k) + " of " +
                            std::to_string(f) + ")");
            Triangle t;
            for (int j = 0; j < 3; ++j) {
                const int64_t index = integer(line, size_t(j + 1));
                AMC_REQUIRE(index >= 0 && index < v, invalid_input,
                            at(line) + "vertex index " + std::to_string(index) + " out of range (" + std::to_string(v) +
                                " vertices, counted from 0)");
                t[j] = uint32_t(index);
            }
            mesh.triangles.push_back(t);
        }
        validate_triangle_mesh(mesh, at(head) + "inline base mesh");
        return mesh;
    }

    std::vector<Line> lines_;
    const std::string& what_;
    const std::string& directory_;
};

}  // namespace

RefinementHistory parse_history(const std::string& text, const std::string& what, const std::string& directory) {
    return Parser(text, what, directory).parse();
}

RefinementHistory read_history(const std::string& path) {
    return parse_history(read_whole_file(path), path, std::filesystem::path(path).parent_path().string());
}

std::string format_history(const RefinementHistory& history) {
    const TriangleMesh& base = history.base;
    std::string out = std::string(kMagic) + " " + std::to_string(kHistoryVersion) + "\n";
    out += "base-inline " + std::to_string(base.positions.size()) + " " + std::to_string(base.triangles.size()) +
           (base.single_precision ? " float32\n" : " float64\n");
    for (const Vec3& p : base.positions) {
        out += "v ";
        if (base.single_precision) {
            text::append_line(out, float(p.x), float(p.y), float(p.z));
        } else {
            text::append_line(out, p.x, p.y, p.z);
        }
    }
    for (const Triangle& t : base.triangles) {
        out += "f ";
        text::append_line(out, t[0], t[1], t[2]);
    }
    for (const AdaptationStep& step : history.steps) {
        out += "step\n";
        for (int list = 0; list < 2; ++list) {
            const std::vector<uint32_t>& elements = list == 0 ? step.refine : step.coarsen;
            if (elements.empty()) continue;
            out += list == 0 ? "refine" : "coarsen";
            for (uint32_t e : elements) {
                out += ' ';
                text::append_uint(out, e);
            }
            out += '\n';
        }
    }
    return out;
}

void write_history(const std::string& path, const RefinementHistory& history) {
    write_file_atomically(path, format_history(history));
}

}  // namespace amc
