// Writes a hierarchy's leaf mesh with the true reference angles of its faces (units of 30 degrees,
// every base triangle equilateral) and the length level of each face, for the SAT experiment of
// docs/IMPORT.md, "Reference angles by a SAT solver, measured" (scripts/angle_sat.py reads it).
#include <amc/hierarchy.h>
#include <amc/refinement.h>

#include "hierarchy/leaf_triangles.h"
#include "random_hierarchies.h"

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

using namespace amc;

namespace {

struct Face {
    VertexId v[3];
    int angle[3];
    int level;
    NodeId root;  // the base triangle the face lies in
};

}  // namespace

int main(int argc, char** argv) {
    if (argc != 3 && !(argc == 4 && std::string(argv[1]) == "--random")) {
        std::fprintf(stderr, "usage: angle_labels IN.amh OUT | angle_labels --random SEED OUT (seed SEED of the import tests' random hierarchies)\n");
        return 2;
    }
    const Hierarchy h = argc == 4 ? testing::varied_random_hierarchy(std::strtoull(argv[2], nullptr, 10)) : read_hierarchy(argv[1]);
    std::vector<Face> faces;
    // The angles follow for_each_leaf_triangle's corner order for each pattern (docs/HIERARCHY.md).
    for_each_leaf_triangle(h, h.breadth_first_order(), -1, [&](NodeId n, VertexId a, VertexId b, VertexId c, bool green) {
        const int k = h.level(n);
        NodeId root = n;
        while (h.parent(root) != kNoNode) root = h.parent(root);
        Face f{{a, b, c}, {2, 2, 2}, k, root};
        if (green) {
            int count = h.hanging_node_count(n);
            if (count == 1) {
                // (a, m, c) or (m, b, c): the midpoint m is the vertex that is not a node corner.
                for (int i = 0; i < 3; ++i) {
                    const VertexId v = f.v[i];
                    const bool corner = v == h.vertex(n, 0) || v == h.vertex(n, 1) || v == h.vertex(n, 2);
                    f.angle[i] = !corner ? 3 : i == 2 ? 1 : 2;
                }
            } else {
                // Two hanging nodes: the corner triangle (m2, m1, c) is a red triangle one level finer;
                // the trapezoid halves are (a, b, m) with 1 at the diagonal's corner end and (x, m1, m2).
                const int u = !h.has_hanging_node(n, 0) ? 0 : !h.has_hanging_node(n, 1) ? 1 : 2;
                const VertexId va = h.vertex(n, u), vb = h.vertex(n, (u + 1) % 3);
                const bool flipped = h.diagonal_flipped(n);
                if (a != va && a != vb) {
                    f.level = k + 1;  // corner triangle
                } else if (b == vb) {
                    // (a, b, m1) default: 1 2 3; (a, b, m2) flipped: 2 1 3
                    f.angle[0] = flipped ? 2 : 1;
                    f.angle[1] = flipped ? 1 : 2;
                    f.angle[2] = 3;
                } else {
                    // (a, m1, m2) default: 1 1 4; (b, m1, m2) flipped: 1 4 1
                    f.angle[0] = 1;
                    f.angle[1] = flipped ? 4 : 1;
                    f.angle[2] = flipped ? 1 : 4;
                }
            }
        }
        faces.push_back(f);
    });
    // Compact vertex ids (a coarsened hierarchy reuses dead ids); base vertices keep theirs.
    const uint32_t base_vertices = uint32_t(h.base().positions.size());
    std::vector<uint32_t> id(h.positions().size(), UINT32_MAX);
    uint32_t next = base_vertices;
    for (uint32_t v = 0; v < base_vertices; ++v) id[v] = v;
    for (Face& f : faces) {
        for (VertexId& v : f.v) {
            if (id[v] == UINT32_MAX) id[v] = next++;
            v = id[v];
        }
    }
    std::vector<int> base_valence(base_vertices, 0);
    for (const Triangle& t : h.base().triangles) {
        for (uint32_t v : t) ++base_valence[v];
    }
    FILE* out = std::fopen(argv[argc - 1], "w");
    if (!out) {
        std::perror(argv[argc - 1]);
        return 1;
    }
    std::fprintf(out, "angle-labels 1\n%u %zu %u %d\n", next, faces.size(), base_vertices, h.depth());
    for (int valence : base_valence) std::fprintf(out, "%d\n", valence);
    for (const Face& f : faces) {
        std::fprintf(out, "%u %u %u %d %d %d %d %u\n", f.v[0], f.v[1], f.v[2], f.angle[0], f.angle[1], f.angle[2], f.level,
                     f.root);
    }
    std::fclose(out);
    return 0;
}
