// What the anchored inverse refinement learnt before it stopped, used to tell apart the nearest
// candidates for a hidden midpoint (docs/IMPORT.md, "Undo steps decide between the nearest").
#pragma once

#include <amc/mesh.h>

#include <cstdint>
#include <vector>

namespace amc {

constexpr uint8_t kNeverUndone = 0xff;

struct UndoSteps {
    std::vector<uint8_t> step;        // per leaf vertex: the step (1 for the first) whose splits
                                      // removed it, kNeverUndone if none did
    std::vector<Triangle> remaining;  // the mesh the steps left, over leaf vertex ids
};

// Picks the leaf vertex that splits an edge among candidates near where a guide expects it.
class UndoStepChoice {
public:
    explicit UndoStepChoice(const UndoSteps& steps);

    // Of `candidates` (nearest first), the one undone last; of several never undone, the first
    // two are compared by how far they lie off the shortest path from a to b in the remaining
    // mesh (through vertices not yet matched: vertex_of_leaf[v] == 0xffffffff), the nearer
    // winning ties.
    uint32_t choose(const uint32_t* candidates, uint32_t count, uint32_t a, uint32_t b,
                    const std::vector<uint32_t>& vertex_of_leaf);
    // The vertices and neighbour entries the comparisons so far walked (a caller's budget).
    uint64_t walked() const { return walked_; }

private:
    void measure_from(uint32_t source, const uint32_t targets[2], std::vector<int>& hops,
                      const std::vector<uint32_t>& vertex_of_leaf);

    const UndoSteps& steps_;
    std::vector<uint32_t> first_neighbor_, neighbors_;  // the remaining mesh's vertex neighbours
    std::vector<int> hops_from_a_, hops_from_b_;        // -1: not reached
    std::vector<uint32_t> reached_, queue_;
    uint64_t walked_ = 0;
};

}  // namespace amc
