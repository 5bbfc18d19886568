// Position-guided picks against the true hierarchy (docs/IMPORT.md, "Undo steps decide between
// the nearest" and "The children repair the picks"): for every corpus hierarchy, its leaf mesh as
// a user holds it (as import_corpus makes it), the top-down reconstruction with the base run with
// each guide (or those --guide names) four times: picking the nearest candidate (way 3 of
// import_leaf_mesh), judged when the pick is made and again after the level's repair, then way 5's
// choice (undo steps and, at the fine levels, the shortest chains), judged the same two ways (as
// import_leaf_mesh runs them). Every pick is compared
// with the true hierarchy's vertex and the reconstruction goes on with the true one, so each pick
// is judged on a correct past. Prints a Markdown table: guided picks, wrong ones of each rule, per
// level, and how many wrong picks the repair fixed and right ones it broke.
//
// With --classify, every wrong pick of way 5's choice (when made, and after the repair) with the leaf-midpoint guide is listed: the
// true vertex's rank among the candidates, the undo steps of both, whether the pick is a leaf-mesh
// neighbour of the true vertex, whether it lies on the true chain of the edge, how much finer it
// is, and how many levels below the pick the reconstruction fails when that pick alone is wrong.
//
// Usage: import_picks [--move X] [--classify] [--guide leaf|subdivision|surface|ray]... corpus/*.amh
#include "user_leaf_mesh.h"

#include "import/anchored_reconstruction.h"
#include "import/leaf_halfedges.h"
#include "import/leaf_reconstruction.h"
#include "import/position_index.h"
#include "common/no_index.h"

#include <amc/hierarchy.h>

#include <cstdio>
#include <cstdlib>
#include <algorithm>
#include <filesystem>
#include <functional>
#include <string>
#include <unordered_map>
#include <vector>

namespace {

struct WrongPick {
    int level;
    uint32_t a, b, picked, truth;
    int truth_rank;  // 1 for the nearest; 0: not among the candidates
    bool adjacent, on_chain;
    int finer_by;  // the pick's level of creation minus the true vertex's
    bool after_repair = false;     // judged after the level's repair (else when made)
    bool right_when_made = false;  // after_repair: the repair broke it
};

struct Count {
    long picks = 0, wrong = 0;
    long fixed = 0, broken = 0;  // by the repair
    std::vector<long> wrong_per_level;
    bool failed = false;  // a misfit no pick explains (the reconstruction threw)
};

}  // namespace

int main(int argc, char** argv) {
    double move = 0.3;
    bool classify = false;
    std::vector<int> only;  // --guide: the guides to run (all when none given)
    std::vector<std::string> files;
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        if (arg == "--move" && i + 1 < argc) {
            move = std::atof(argv[++i]);
        } else if (arg == "--classify") {
            classify = true;
        } else if (arg == "--guide" && i + 1 < argc) {
            const std::string name = argv[++i];
            const char* names[] = {"leaf", "subdivision", "surface", "ray"};
            int g = 0;
            while (g < 4 && name != names[g]) ++g;
            if (g == 4) {
                std::fprintf(stderr, "unknown guide %s (leaf, subdivision, surface, ray)\n", name.c_str());
                return 2;
            }
            only.push_back(g);
        } else {
            files.push_back(arg);
        }
    }
    if (files.empty()) {
        std::fprintf(stderr, "usage: import_picks [--move X] [--classify] [--guide leaf|subdivision|surface|ray]... hierarchy.amh...\n");
        return 2;
    }
    const amc::MidpointGuide guides[] = {amc::MidpointGuide::leaf_midpoint, amc::MidpointGuide::subdivision,
                                         amc::MidpointGuide::surface, amc::MidpointGuide::normal_ray};
    const char* guide_names[] = {"leaf midpoint", "subdivision", "surface", "normal ray"};
    std::printf("| model | guide | guided picks | wrong: the nearest (per level 0, 1, ...) | the nearest, after the children's "
                "repair | wrong: undo steps and chains | of them per level | the same after the children's repair | of "
                "them per level | repair: fixed / broken |\n");
    std::printf("|---|---|---:|---|---|---:|---|---:|---|---|\n");
    for (const std::string& file : files) {
        const amc::Hierarchy h = amc::read_hierarchy(file);
        const amc::LeafMesh leaf = amc::extract_leaf_mesh(h);
        const uint32_t base_vertices = uint32_t(h.base().positions.size());
        std::vector<uint32_t> user_of_leaf;
        const amc::TriangleMesh user = bench::user_leaf_mesh(leaf.mesh, base_vertices, move, 23, &user_of_leaf);
        const std::vector<uint32_t> canonical = amc::canonical_vertex_order(h);
        auto user_vertex = [&](amc::VertexId v) { return user_of_leaf[canonical[v]]; };
        // The true vertex of every split edge, both directions.
        std::unordered_map<uint64_t, uint32_t> truth;
        for (amc::NodeId n = 0; n < h.node_capacity(); ++n) {
            if (!h.is_alive(n) || h.is_leaf(n)) continue;
            for (int e = 0; e < 3; ++e) {
                const uint32_t a = user_vertex(h.vertex(n, e)), b = user_vertex(h.vertex(n, (e + 1) % 3));
                const uint32_t m = user_vertex(h.midpoint(n, e));
                truth[(uint64_t(a) << 32) | b] = m;
                truth[(uint64_t(b) << 32) | a] = m;
            }
        }
        // The level at which each vertex was created (0: base).
        std::vector<int> created(user.positions.size(), 0);
        for (amc::NodeId n = 0; n < h.node_capacity(); ++n) {
            if (!h.is_alive(n) || h.is_leaf(n)) continue;
            for (int e = 0; e < 3; ++e) {
                int& c = created[user_vertex(h.midpoint(n, e))];
                c = c == 0 ? h.level(n) + 1 : std::min(c, h.level(n) + 1);
            }
        }
        std::function<bool(uint32_t, uint32_t, uint32_t)> on_chain = [&](uint32_t a, uint32_t b, uint32_t x) {
            const auto it = truth.find((uint64_t(a) << 32) | b);
            if (it == truth.end()) return false;
            return it->second == x || on_chain(a, it->second, x) || on_chain(it->second, b, x);
        };
        std::vector<WrongPick> wrong_picks;
        std::vector<uint32_t> leaf_of_base(base_vertices);
        amc::TriangleMesh base;
        base.triangles = h.base().triangles;
        base.single_precision = user.single_precision;
        for (uint32_t b = 0; b < base_vertices; ++b) {
            leaf_of_base[b] = user_vertex(b);
            base.positions.push_back(user.positions[leaf_of_base[b]]);
        }
        const amc::LeafHalfedges halfedges(user);
        amc::LeafSearch search(user);
        const amc::PositionIndex positions(user.positions);
        auto fresh = [&] {
            amc::Hierarchy out(base);
            out.reserve(user.triangles.size() * 4 / 3 + base.triangles.size() + 4, user.positions.size());
            return out;
        };
        auto classify_pick = [&](const amc::GuidedPick& pick, uint32_t truth_vertex) {
            WrongPick w{pick.level, pick.a, pick.b, pick.picked, truth_vertex, 0, false, false, 0};
            for (uint32_t i = 0; i < pick.candidate_count; ++i) {
                if (pick.candidates[i] == truth_vertex) w.truth_rank = int(i) + 1;
            }
            w.adjacent = halfedges.face(pick.picked, truth_vertex) != amc::kNoIndex ||
                         halfedges.face(truth_vertex, pick.picked) != amc::kNoIndex;
            w.on_chain = on_chain(pick.a, pick.b, pick.picked);
            w.finer_by = created[pick.picked] - created[truth_vertex];
            return w;
        };
        amc::UndoSteps steps;
        {
            amc::Hierarchy anchored = fresh();
            amc::reconstruct_anchored(anchored, leaf_of_base, user, file, &steps);
        }
        const std::string name = std::filesystem::path(file).stem().string();
        for (int g = 0; g < 4; ++g) {
            if (!only.empty() && std::find(only.begin(), only.end(), g) == only.end()) continue;
            Count counts[4];
            std::unordered_map<uint64_t, uint32_t> first_pick;
            for (int rule = 0; rule < 4; ++rule) {
                Count& c = counts[rule];
                // Rule 3: the nearest candidate (ways 3 and 4), judged after the level's repair.
                const bool after_repair = rule >= 2;
                const amc::PickReferee referee = [&](const amc::GuidedPick& pick) {
                    // Rules 2 and 3 judge the picks after the level's repair, the others when made.
                    const auto it = truth.find((uint64_t(pick.a) << 32) | pick.b);
                    if (after_repair && !pick.repaired && it != truth.end()) first_pick[it->first] = pick.picked;
                    if (after_repair && pick.repaired && it != truth.end()) {
                        const bool was_right = first_pick[it->first] == it->second;
                        c.fixed += !was_right && pick.picked == it->second;
                        c.broken += was_right && pick.picked != it->second;
                    }
                    if (pick.repaired != after_repair) return pick.picked;
                    if (it == truth.end()) return pick.picked;  // an edge the true hierarchy does not split
                    ++c.picks;
                    if (pick.picked != it->second) {
                        ++c.wrong;
                        const size_t level = size_t(pick.level);
                        if (c.wrong_per_level.size() <= level) c.wrong_per_level.resize(level + 1, 0);
                        ++c.wrong_per_level[level];
                        if (classify && g == 0 && (rule == 1 || rule == 2)) {
                            WrongPick w = classify_pick(pick, it->second);
                            w.after_repair = rule == 2;
                            w.right_when_made = rule == 2 && first_pick[it->first] == it->second;
                            wrong_picks.push_back(w);
                        }
                    }
                    return it->second;
                };
                amc::Hierarchy reconstructed = fresh();
                try {
                    amc::reconstruct_hierarchy(reconstructed, leaf_of_base, user, halfedges, guides[g], positions, search, file,
                                               rule == 1 || rule == 2 ? &steps : nullptr, &referee);
                } catch (const amc::Error&) {
                    c.failed = true;
                }
            }
            auto levels = [](const Count& c) {
                std::string text;
                for (size_t l = 0; l < c.wrong_per_level.size(); ++l)
                    text += (l ? ", " : "") + std::to_string(c.wrong_per_level[l]);
                return text;
            };
            std::printf("| %s | %s | %ld | %ld%s (%s) | %ld%s (%s) | %ld%s | %s | %ld%s | %s | %ld / %ld |\n", name.c_str(),
                        guide_names[g], counts[0].picks, counts[0].wrong, counts[0].failed ? " (stopped)" : "",
                        levels(counts[0]).c_str(), counts[3].wrong, counts[3].failed ? " (stopped)" : "",
                        levels(counts[3]).c_str(), counts[1].wrong, counts[1].failed ? " (stopped)" : "",
                        levels(counts[1]).c_str(), counts[2].wrong, counts[2].failed ? " (stopped)" : "",
                        levels(counts[2]).c_str(), counts[2].fixed, counts[2].broken);
            std::fflush(stdout);
        }
        if (!classify) continue;
        std::printf("\n| %s: judged | level | truth's rank | undo step: pick, truth | adjacent | on the chain | finer by | "
                    "fails at level (pick alone wrong, then repaired) |\n|---|---:|---:|---|---|---|---:|---|\n",
                    name.c_str());
        for (const WrongPick& w : wrong_picks) {
            int last_level = -1;
            const amc::PickReferee inject = [&](const amc::GuidedPick& pick) {
                last_level = std::max(last_level, pick.level);
                if (pick.repaired) return pick.picked;  // the repair may take the wrong pick back
                if (pick.a == w.a && pick.b == w.b) return w.picked;
                const auto it = truth.find((uint64_t(pick.a) << 32) | pick.b);
                return it == truth.end() ? pick.picked : it->second;
            };
            amc::Hierarchy reconstructed = fresh();
            std::string outcome = "completes";
            try {
                amc::reconstruct_hierarchy(reconstructed, leaf_of_base, user, halfedges, guides[0], positions, search, file,
                                           &steps, &inject);
            } catch (const amc::Error& e) {
                const std::string message = e.what();
                outcome = "+" + std::to_string(last_level + 1 - w.level) + ": " +
                          message.substr(file.size() + 2, 60);
            }
            auto step_text = [](int s) { return s == amc::kNeverUndone ? std::string("never") : std::to_string(s); };
            const char* judged = !w.after_repair ? "when made" : w.right_when_made ? "after repair (broken)" : "after repair";
            std::printf("| %s | %d | %s | %s, %s | %s | %s | %d | %s |\n", judged, w.level,
                        w.after_repair ? "-" : std::to_string(w.truth_rank).c_str(),
                        step_text(steps.step[w.picked]).c_str(), step_text(steps.step[w.truth]).c_str(),
                        w.adjacent ? "yes" : "no", w.on_chain ? "yes" : "no", w.finer_by, outcome.c_str());
        }
        std::fflush(stdout);
    }
    return 0;
}
