// The caller's numbering of a leaf mesh, found by matching faces, and the leaf mesh renumbered by it.
#include <amc/numbering.h>

#include <algorithm>
#include <string>

namespace amc {

namespace {

// Leaf triangles grouped by their smallest vertex (a CSR table), each group sorted by the two
// vertices that follow it: a face is found by binary search (a pass over the group was quadratic
// where one vertex is the smallest of many faces).
struct TrianglesByLowestVertex {
    struct Entry {
        uint32_t next, after, triangle;  // the vertices after the lowest, in order; the leaf triangle
        bool operator<(const Entry& o) const {
            return next != o.next ? next < o.next : after != o.after ? after < o.after : triangle < o.triangle;
        }
    };
    std::vector<uint32_t> start;
    std::vector<Entry> entries;
    TrianglesByLowestVertex(const std::vector<Triangle>& mesh, size_t vertices) : start(vertices + 1, 0) {
        for (const Triangle& t : mesh) ++start[t[lowest_corner(t)] + 1];
        for (size_t v = 0; v < vertices; ++v) start[v + 1] += start[v];
        entries.resize(mesh.size());
        std::vector<uint32_t> fill(start.begin(), start.end() - 1);
        for (uint32_t i = 0; i < mesh.size(); ++i) {
            const int r = lowest_corner(mesh[i]);
            entries[fill[mesh[i][r]]++] = {mesh[i][(r + 1) % 3], mesh[i][(r + 2) % 3], i};
        }
        for (size_t v = 0; v < vertices; ++v) std::sort(entries.begin() + start[v], entries.begin() + start[v + 1]);
    }
    static int lowest_corner(const Triangle& t) { return t[0] < t[1] ? (t[0] < t[2] ? 0 : 2) : (t[1] < t[2] ? 1 : 2); }
};

}  // namespace

std::string check_numbering(const LeafNumbering& numbering, uint64_t vertices, uint64_t faces) {
    if (numbering.vertex.size() != vertices)
        return "the numbering has " + std::to_string(numbering.vertex.size()) + " vertices, the leaf mesh " +
               std::to_string(vertices);
    if (numbering.face.size() != faces || numbering.rotation.size() != faces)
        return "the numbering has " + std::to_string(numbering.face.size()) + " faces, the leaf mesh " + std::to_string(faces);
    std::vector<bool> seen(vertices, false);
    for (size_t i = 0; i < vertices; ++i) {
        const uint32_t v = numbering.vertex[i];
        if (v >= vertices || seen[v]) return "vertex " + std::to_string(i) + " of the numbering is out of range or repeated";
        seen[v] = true;
    }
    seen.assign(faces, false);
    for (size_t j = 0; j < faces; ++j) {
        const uint32_t f = numbering.face[j];
        if (f >= faces || seen[f]) return "face " + std::to_string(j) + " of the numbering is out of range or repeated";
        if (numbering.rotation[j] > 2) return "face " + std::to_string(j) + " of the numbering has a rotation above 2";
        seen[f] = true;
    }
    return "";
}

LeafNumbering leaf_numbering(const Hierarchy& h, const TriangleMesh& mesh, const std::vector<VertexId>& vertex_of_input) {
    const std::vector<uint32_t> canonical = canonical_vertex_order(h);
    const uint32_t vertices = h.vertex_count();
    if (mesh.positions.size() != vertices || vertex_of_input.size() != vertices)
        throw Error("numbering: the mesh has " + std::to_string(mesh.positions.size()) + " vertices (map: " +
                    std::to_string(vertex_of_input.size()) + "), its hierarchy " + std::to_string(vertices));
    LeafNumbering numbering;
    numbering.vertex.resize(vertices);
    std::vector<bool> taken(vertices, false);
    for (uint32_t i = 0; i < vertices; ++i) {
        const VertexId v = vertex_of_input[i];
        const uint32_t leaf_vertex = v < canonical.size() ? canonical[v] : kNoVertex;
        if (leaf_vertex >= vertices || taken[leaf_vertex])
            throw Error("numbering: vertex " + std::to_string(i) + " maps to no vertex of the hierarchy, or to one already taken");
        taken[leaf_vertex] = true;
        numbering.vertex[i] = leaf_vertex;
    }

    const std::vector<Triangle> leaf = extract_leaf_mesh(h).mesh.triangles;
    if (mesh.triangles.size() != leaf.size())
        throw Error("numbering: the mesh has " + std::to_string(mesh.triangles.size()) + " faces, the leaf mesh " +
                    std::to_string(leaf.size()));
    const TrianglesByLowestVertex index(leaf, vertices);
    numbering.face.resize(leaf.size());
    numbering.rotation.resize(leaf.size());
    std::vector<bool> matched(leaf.size(), false);
    for (uint32_t j = 0; j < mesh.triangles.size(); ++j) {
        Triangle face;
        for (int c = 0; c < 3; ++c) {
            if (mesh.triangles[j][c] >= vertices) throw Error("numbering: face " + std::to_string(j) + " has a vertex out of range");
            face[c] = numbering.vertex[mesh.triangles[j][c]];
        }
        // The first unmatched leaf triangle with the same corners in the same cyclic order.
        const int r = TrianglesByLowestVertex::lowest_corner(face);
        const uint32_t low = face[r], next = face[(r + 1) % 3], after = face[(r + 2) % 3];
        const auto end = index.entries.begin() + index.start[low + 1];
        auto k = std::lower_bound(index.entries.begin() + index.start[low], end, TrianglesByLowestVertex::Entry{next, after, 0});
        while (k != end && k->next == next && k->after == after && matched[k->triangle]) ++k;
        const bool found = k != end && k->next == next && k->after == after;
        if (found) {
            matched[k->triangle] = true;
            numbering.face[j] = k->triangle;
            numbering.rotation[j] = uint8_t((TrianglesByLowestVertex::lowest_corner(leaf[k->triangle]) + 3 - r) % 3);
        }
        if (!found) throw Error("numbering: face " + std::to_string(j) + " is not a triangle of the leaf mesh (or is listed twice)");
    }
    return numbering;
}

TriangleMesh renumber_leaf_mesh(const LeafMesh& leaf, const LeafNumbering& numbering, CellData* cells) {
    const std::string problem = check_numbering(numbering, leaf.mesh.positions.size(), leaf.mesh.triangles.size());
    if (!problem.empty()) throw Error("numbering does not fit the leaf mesh: " + problem);
    TriangleMesh out;
    out.single_precision = leaf.mesh.single_precision;
    out.positions.resize(numbering.vertex.size());
    std::vector<uint32_t> input_of_leaf(numbering.vertex.size());
    for (uint32_t i = 0; i < numbering.vertex.size(); ++i) {
        out.positions[i] = leaf.mesh.positions[numbering.vertex[i]];
        input_of_leaf[numbering.vertex[i]] = i;
    }
    out.triangles.resize(numbering.face.size());
    if (cells != nullptr) {
        cells->level.resize(numbering.face.size());
        cells->is_green.resize(numbering.face.size());
    }
    for (uint32_t j = 0; j < numbering.face.size(); ++j) {
        const Triangle& t = leaf.mesh.triangles[numbering.face[j]];
        const int r = numbering.rotation[j];
        for (int c = 0; c < 3; ++c) out.triangles[j][c] = input_of_leaf[t[(c + r) % 3]];
        if (cells != nullptr) {
            cells->level[j] = leaf.cells.level[numbering.face[j]];
            cells->is_green[j] = leaf.cells.is_green[numbering.face[j]];
        }
    }
    return out;
}

}  // namespace amc
