// The coarse mesh of a forest: bricks, gluing by shared vertices, p4est's orientation rule and the
// checks a connectivity must pass.
#include "octree/tree_faces.h"

#include "common/check.h"

#include <algorithm>
#include <cmath>
#include <map>

namespace amc {

namespace {

// The tangential axes of face f in increasing order: face corner bit k runs along axis tangent[k].
void tangential_axes(int dim, int f, int tangent[2]) {
    int k = 0;
    for (int a = 0; a < dim; ++a)
        if (a != f / 2) tangent[k++] = a;
}

// Handedness of (tangential axes in order, outward normal) for face f: +1 or -1.
int face_handedness(int dim, int f) {
    const int outward = (f & 1) ? 1 : -1;
    const int a = f / 2;
    // det(e_t0, n) in 2D; det(e_t0, e_t1, n) in 3D for n = +e_a.
    const int base = dim == 2 ? (a == 0 ? -1 : 1) : (a == 1 ? -1 : 1);
    return base * outward;
}

// The symmetries of the face square (segment in 2D): corner bits (u, v) -> swapped if `swap`,
// then xor `flips`. Index s = swap * 4 + flips; in 2D only flips 0 and 1.
FaceCornerPerm symmetry_perm(int dim, int s, int& det) {
    FaceCornerPerm perm{0, 0, 0, 0};
    const bool swap = s >= 4;
    const int flips = s & 3;
    const int corners = 1 << (dim - 1);
    for (int i = 0; i < corners; ++i) {
        int u = i & 1, v = (i >> 1) & 1;
        if (swap) std::swap(u, v);
        perm[i] = uint8_t((u | (v << 1)) ^ flips);
    }
    det = (swap ? -1 : 1) * ((flips & 1) ? -1 : 1) * ((flips & 2) ? -1 : 1);
    return perm;
}

int symmetry_count(int dim) { return dim == 2 ? 2 : 8; }

FaceCornerPerm inverse(int dim, const FaceCornerPerm& perm) {
    FaceCornerPerm inv{0, 0, 0, 0};
    for (int i = 0; i < (1 << (dim - 1)); ++i) inv[perm[i]] = uint8_t(i);
    return inv;
}

// p4est: the orientation is the corner of the higher face that face corner 0 of the lower touches.
int orientation_of(int dim, int f, int nf, const FaceCornerPerm& perm) {
    return f <= nf ? perm[0] : inverse(dim, perm)[0];
}

const int kFaceCorners2[4][2] = {{0, 2}, {1, 3}, {0, 1}, {2, 3}};
const int kFaceCorners3[6][4] = {{0, 2, 4, 6}, {1, 3, 5, 7}, {0, 1, 4, 5}, {2, 3, 6, 7}, {0, 1, 2, 3}, {4, 5, 6, 7}};

int face_corner(int dim, int f, int i) { return dim == 2 ? kFaceCorners2[f][i] : kFaceCorners3[f][i]; }

}  // namespace

bool face_corner_perm(int dim, int f, int nf, int orientation, FaceCornerPerm& perm) {
    if (orientation < 0 || orientation >= octree_orientations(dim)) return false;
    if (dim == 2) {  // p4est: the corners in order or reversed; 2D trees may be of either hand (a Moebius strip)
        perm = {uint8_t(orientation), uint8_t(1 - orientation), 0, 0};
        return true;
    }
    // Gluing two right-handed trees reverses the face frame: det = -h(f) h(nf).
    const int wanted = -face_handedness(dim, f) * face_handedness(dim, nf);
    for (int s = 0; s < symmetry_count(dim); ++s) {
        int det = 0;
        const FaceCornerPerm p = symmetry_perm(dim, s, det);
        if (det == wanted && orientation_of(dim, f, nf, p) == orientation) {
            perm = p;
            return true;
        }
    }
    return false;
}

int face_orientation(int dim, int f, int nf, const FaceCornerPerm& perm) {
    if (dim == 2) return perm[0];
    const int wanted = -face_handedness(dim, f) * face_handedness(dim, nf);
    for (int s = 0; s < symmetry_count(dim); ++s) {
        int det = 0;
        const FaceCornerPerm p = symmetry_perm(dim, s, det);
        bool same = true;
        for (int i = 0; i < (1 << (dim - 1)); ++i) same &= p[i] == perm[i];
        if (same) return det == wanted ? orientation_of(dim, f, nf, p) : -1;
    }
    return -1;
}

TreeFaces::TreeFaces(const TreeConnectivity& conn) : dim_(conn.dim) {
    const int faces = 2 * dim_;
    glue_.resize(size_t(conn.tree_count()) * faces);
    for (uint32_t t = 0; t < conn.tree_count(); ++t) {
        for (int f = 0; f < faces; ++f) {
            FaceGlue& g = glue_[size_t(t) * faces + f];
            g.tree = conn.tree_to_tree[size_t(t) * faces + f];
            const int code = conn.tree_to_face[size_t(t) * faces + f];
            g.face = uint8_t(code % faces);
            g.boundary = g.tree == t && g.face == f;
            if (g.boundary) continue;
            FaceCornerPerm perm{};
            face_corner_perm(dim_, f, g.face, code / faces, perm);
            int mine[2] = {0, 0}, theirs[2] = {0, 0};
            tangential_axes(dim_, f, mine);
            tangential_axes(dim_, g.face, theirs);
            g.axis_to[f / 2] = uint8_t(g.face / 2);
            for (int k = 0; k < dim_ - 1; ++k) {
                // Walking my tangential axis k moves the touching corner along one of theirs.
                const int moved = perm[1 << k] ^ perm[0];
                const int j = moved == 1 ? 0 : 1;
                g.axis_to[mine[k]] = uint8_t(theirs[j]);
                g.flip[mine[k]] = (perm[0] >> j) & 1;
            }
        }
    }
}

void validate_connectivity(const TreeConnectivity& conn, const std::string& what) {
    AMC_REQUIRE(conn.dim == 2 || conn.dim == 3, invalid_input, what + ": dimension " + std::to_string(conn.dim) + " is not 2 or 3");
    const int faces = 2 * conn.dim, corners = 1 << conn.dim;
    AMC_REQUIRE(conn.tree_to_tree.size() % faces == 0 && conn.tree_to_face.size() == conn.tree_to_tree.size(), invalid_input,
                what + ": tree_to_tree and tree_to_face do not hold " + std::to_string(faces) + " entries per tree");
    const uint64_t trees = conn.tree_count();
    AMC_REQUIRE(trees >= 1, invalid_input, what + ": no trees");
    AMC_REQUIRE(trees < (uint64_t{1} << 31), limit_exceeded, what + ": too many trees");
    AMC_REQUIRE(conn.vertices.empty() == conn.tree_to_vertex.empty(), invalid_input,
                what + ": vertices and tree_to_vertex must be both empty or both given");
    if (!conn.vertices.empty()) {
        AMC_REQUIRE(conn.tree_to_vertex.size() == trees * corners, invalid_input,
                    what + ": tree_to_vertex does not hold " + std::to_string(corners) + " vertices per tree");
        for (size_t i = 0; i < conn.tree_to_vertex.size(); ++i)
            AMC_REQUIRE(conn.tree_to_vertex[i] < conn.vertices.size(), invalid_input,
                        what + ": tree " + std::to_string(i / corners) + " uses vertex " + std::to_string(conn.tree_to_vertex[i]) +
                            " of " + std::to_string(conn.vertices.size()));
        for (const Vec3& p : conn.vertices)
            AMC_REQUIRE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z), invalid_input, what + ": a vertex is not finite");
    }
    for (uint64_t t = 0; t < trees; ++t) {
        for (int f = 0; f < faces; ++f) {
            const std::string where = what + ": tree " + std::to_string(t) + " face " + std::to_string(f);
            const uint32_t nt = conn.tree_to_tree[t * faces + f];
            const int code = conn.tree_to_face[t * faces + f];
            AMC_REQUIRE(nt < trees, invalid_input, where + " names tree " + std::to_string(nt));
            AMC_REQUIRE(code < faces * octree_orientations(conn.dim), invalid_input, where + ": face code " + std::to_string(code) + " out of range");
            const int nf = code % faces, o = code / faces;
            if (nt == t && nf == f) {
                AMC_REQUIRE(o == 0, invalid_input, where + ": boundary face with orientation " + std::to_string(o));
                continue;
            }
            const uint32_t back_tree = conn.tree_to_tree[size_t(nt) * faces + nf];
            const int back = conn.tree_to_face[size_t(nt) * faces + nf];
            AMC_REQUIRE(back_tree == t && back == f + faces * o, invalid_input,
                        where + " is glued to tree " + std::to_string(nt) + " face " + std::to_string(nf) +
                            ", which is not glued back to it with the same orientation");
            FaceCornerPerm perm{};
            AMC_REQUIRE(face_corner_perm(conn.dim, f, nf, o, perm), invalid_input, where + ": bad orientation");
        }
    }
}

TreeConnectivity brick_connectivity(int dim, int nx, int ny, int nz, bool periodic_x, bool periodic_y, bool periodic_z) {
    AMC_REQUIRE(dim == 2 || dim == 3, invalid_input, "brick: dimension " + std::to_string(dim) + " is not 2 or 3");
    if (dim == 2) nz = 1, periodic_z = false;
    // nx * ny bounded first: three sizes of 2^22 would wrap the product of all three to 0.
    AMC_REQUIRE(nx >= 1 && ny >= 1 && nz >= 1 && uint64_t(nx) * ny < (uint64_t{1} << 24) &&
                    uint64_t(nx) * ny * nz < (uint64_t{1} << 24),
                invalid_input,
                "brick: sizes must be at least 1 and at most 2^24 trees");
    TreeConnectivity conn;
    conn.dim = dim;
    const int n[3] = {nx, ny, nz};
    const bool periodic[3] = {periodic_x, periodic_y, periodic_z};
    const int vx = nx + 1, vy = ny + 1, vz = dim == 3 ? nz + 1 : 1;
    for (int k = 0; k < vz; ++k)
        for (int j = 0; j < vy; ++j)
            for (int i = 0; i < vx; ++i) conn.vertices.push_back({double(i), double(j), double(k)});
    const int faces = 2 * dim;
    for (int k = 0; k < nz; ++k) {
        for (int j = 0; j < ny; ++j) {
            for (int i = 0; i < nx; ++i) {
                const uint32_t t = uint32_t((k * ny + j) * nx + i);
                for (int c = 0; c < (1 << dim); ++c)
                    conn.tree_to_vertex.push_back(uint32_t(((k + ((c >> 2) & 1)) * vy + j + ((c >> 1) & 1)) * vx + i + (c & 1)));
                const int at[3] = {i, j, k};
                for (int f = 0; f < faces; ++f) {
                    const int a = f / 2, step = (f & 1) ? 1 : -1;
                    int q[3] = {at[0], at[1], at[2]};
                    q[a] += step;
                    if (q[a] < 0 || q[a] >= n[a]) {
                        if (!periodic[a]) {
                            conn.tree_to_tree.push_back(t);
                            conn.tree_to_face.push_back(uint8_t(f));
                            continue;
                        }
                        q[a] = (q[a] + n[a]) % n[a];
                    }
                    conn.tree_to_tree.push_back(uint32_t((q[2] * ny + q[1]) * nx + q[0]));
                    conn.tree_to_face.push_back(uint8_t(f ^ 1));
                }
            }
        }
    }
    return conn;
}

TreeConnectivity connectivity_from_vertices(int dim, std::vector<Vec3> vertices, std::vector<uint32_t> tree_to_vertex) {
    AMC_REQUIRE(dim == 2 || dim == 3, invalid_input, "connectivity: dimension " + std::to_string(dim) + " is not 2 or 3");
    const int corners = 1 << dim, faces = 2 * dim, face_corners = corners / 2;
    AMC_REQUIRE(!tree_to_vertex.empty() && tree_to_vertex.size() % corners == 0, invalid_input,
                "connectivity: tree_to_vertex does not hold " + std::to_string(corners) + " vertices per tree");
    const uint32_t trees = uint32_t(tree_to_vertex.size() / corners);
    TreeConnectivity conn;
    conn.dim = dim;
    conn.vertices = std::move(vertices);
    conn.tree_to_vertex = std::move(tree_to_vertex);
    for (uint32_t v : conn.tree_to_vertex)
        AMC_REQUIRE(v < conn.vertices.size(), invalid_input, "connectivity: vertex " + std::to_string(v) + " out of range");
    conn.tree_to_tree.resize(size_t(trees) * faces);
    conn.tree_to_face.resize(size_t(trees) * faces);
    // Faces by their sorted vertices.
    std::map<std::array<uint32_t, 4>, std::vector<uint32_t>> by_vertices;  // -> tree * faces + face
    auto face_vertices = [&](uint32_t t, int f) {
        std::array<uint32_t, 4> v{0, 0, 0, 0};
        for (int i = 0; i < face_corners; ++i) v[i] = conn.tree_to_vertex[size_t(t) * corners + face_corner(dim, f, i)];
        return v;
    };
    for (uint32_t t = 0; t < trees; ++t) {
        const uint32_t* all = conn.tree_to_vertex.data() + size_t(t) * corners;
        for (int c = 1; c < corners; ++c) {
            AMC_REQUIRE(std::find(all, all + c, all[c]) == all + c, invalid_input,
                        "connectivity: tree " + std::to_string(t) + " repeats a vertex");
        }
        for (int f = 0; f < faces; ++f) {
            std::array<uint32_t, 4> key = face_vertices(t, f);
            std::sort(key.begin(), key.begin() + face_corners);
            by_vertices[key].push_back(t * faces + f);
        }
    }
    for (const auto& key_sides : by_vertices) {
        const std::vector<uint32_t>& sides = key_sides.second;  // named: AMC_REQUIRE's lambda cannot capture a structured binding
        AMC_REQUIRE(sides.size() <= 2, invalid_input,
                    "connectivity: " + std::to_string(sides.size()) + " trees share the face of tree " +
                        std::to_string(sides[0] / faces) + " face " + std::to_string(sides[0] % faces));
        if (sides.size() == 1) {
            conn.tree_to_tree[sides[0]] = sides[0] / faces;
            conn.tree_to_face[sides[0]] = uint8_t(sides[0] % faces);
            continue;
        }
        for (int side = 0; side < 2; ++side) {
            const uint32_t me = sides[side], other = sides[1 - side];
            const int f = int(me % faces), nf = int(other % faces);
            const auto mine = face_vertices(me / faces, f), theirs = face_vertices(other / faces, nf);
            FaceCornerPerm perm{0, 0, 0, 0};
            for (int i = 0; i < face_corners; ++i)
                perm[i] = uint8_t(std::find(theirs.begin(), theirs.begin() + face_corners, mine[i]) - theirs.begin());
            const int o = face_orientation(dim, f, nf, perm);
            AMC_REQUIRE(o >= 0, invalid_input,
                        "connectivity: trees " + std::to_string(me / faces) + " and " + std::to_string(other / faces) +
                            " meet against their orientation (a left-handed tree?) at face " + std::to_string(f));
            conn.tree_to_tree[me] = other / faces;
            conn.tree_to_face[me] = uint8_t(nf + faces * o);
        }
    }
    return conn;
}

}  // namespace amc
