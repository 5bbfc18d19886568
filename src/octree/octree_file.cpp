// Metadata and connectivity blocks of the .amq file.
#include "octree/octree_file.h"

#include "common/check.h"
#include "octree/octree_traversal.h"

#include <algorithm>
#include <cmath>

namespace amc {

namespace {

uint8_t octree_last_block_type(uint8_t version) {
    return uint8_t(version >= kOctreeLeafDataVersion ? OctreeBlock::leaf_field : OctreeBlock::level);
}

const char* octree_block_name(uint8_t type) {
    switch (OctreeBlock(type)) {
        case OctreeBlock::end: return "end";
        case OctreeBlock::metadata: return "metadata";
        case OctreeBlock::connectivity: return "connectivity";
        case OctreeBlock::level: return "level";
        case OctreeBlock::leaf_field: return "leaf field";
    }
    return "unknown";
}

}  // namespace

const FileFraming kOctreeFraming = {{'A', 'M', 'Q', 'T'}, ".amq", kOctreeBaseVersion, kOctreeNewestVersion, 0, octree_last_block_type,
                                    octree_block_name};

std::vector<uint8_t> write_octree_metadata(const OctreeMetadata& m) {
    std::vector<uint8_t> out;
    out.push_back(uint8_t(m.dim));
    put_varint(out, m.trees);
    put_varint(out, m.octants);
    put_varint(out, m.leaves);
    put_varint(out, m.levels);
    out.push_back(m.switches);
    out.push_back(uint8_t(m.uniform_levels));
    if (m.switches & kOctreeTruncate) put_varint(out, m.count);
    return out;
}

OctreeMetadata read_octree_metadata(const uint8_t* data, size_t size, uint64_t max_octants) {
    PayloadReader in(data, size, "metadata block");
    OctreeMetadata m;
    m.dim = in.u8();
    AMC_REQUIRE(m.dim == 2 || m.dim == 3, corrupt, "metadata block: dimension " + std::to_string(m.dim));
    m.trees = in.varint();
    m.octants = in.varint();
    m.leaves = in.varint();
    m.levels = in.varint();
    m.switches = in.u8();
    m.uniform_levels = in.u8();
    if (m.switches & kOctreeTruncate) m.count = in.varint();
    AMC_REQUIRE(in.remaining() == 0, corrupt, "metadata block: " + std::to_string(in.remaining()) + " bytes too many");
    AMC_REQUIRE(!(m.switches & ~kOctreeKnownSwitches), corrupt, "metadata block: unknown switches");
    AMC_REQUIRE(m.trees >= 1 && m.trees < (uint64_t{1} << 31), corrupt, "metadata block: " + std::to_string(m.trees) + " trees");
    AMC_REQUIRE(m.levels >= 1 && m.levels <= uint64_t(octree_max_level(m.dim)) + 1, corrupt,
                "metadata block: " + std::to_string(m.levels) + " levels");
    AMC_REQUIRE(m.uniform_levels < int(m.levels) && (m.uniform_levels == 0 || (m.switches & kOctreeUniformLevels)), corrupt,
                "metadata block: " + std::to_string(m.uniform_levels) + " uniform levels");
    AMC_REQUIRE(m.octants <= max_octants, limit_exceeded,
                "metadata block: " + std::to_string(m.octants) + " octants, more than the limit " + std::to_string(max_octants));
    // Every level below the last has an octant refined: at least trees + (levels - 1) 2^dim octants.
    AMC_REQUIRE(m.octants >= m.trees + (m.levels - 1) * (uint64_t{1} << m.dim), corrupt,
                "metadata block: " + std::to_string(m.octants) + " octants can not fill " + std::to_string(m.levels) + " levels");
    AMC_REQUIRE((m.octants - m.trees) % (uint64_t{1} << m.dim) == 0, corrupt,
                "metadata block: " + std::to_string(m.octants) + " octants over " + std::to_string(m.trees) + " trees");
    AMC_REQUIRE(m.leaves == m.octants - (m.octants - m.trees) / (uint64_t{1} << m.dim), corrupt,
                "metadata block: " + std::to_string(m.leaves) + " leaves do not match " + std::to_string(m.octants) + " octants");
    AMC_REQUIRE(m.count <= m.octants, corrupt, "metadata block: more symbols than octants");
    return m;
}

namespace {

// The brick `conn` is, if it is one: sizes from the largest vertex coordinates, periodicity tried.
bool find_brick(const TreeConnectivity& conn, int n[3], uint8_t& periodic) {
    if (conn.vertices.empty()) return false;
    double hi[3] = {0, 0, 0};
    for (const Vec3& p : conn.vertices) hi[0] = std::max(hi[0], p.x), hi[1] = std::max(hi[1], p.y), hi[2] = std::max(hi[2], p.z);
    for (int a = 0; a < 3; ++a) {
        if (!(hi[a] >= 1 && hi[a] <= (1 << 24) && hi[a] == std::floor(hi[a]))) hi[a] = a == 2 && conn.dim == 2 ? 1 : -1;
        if (hi[a] < 1) return false;
        n[a] = int(hi[a]);
    }
    if (uint64_t(n[0]) * n[1] * n[2] != conn.tree_count()) return false;
    for (int bits = 0; bits < (1 << conn.dim); ++bits) {
        const TreeConnectivity brick = brick_connectivity(conn.dim, n[0], n[1], n[2], bits & 1, bits & 2, bits & 4);
        if (brick.vertices == conn.vertices && brick.tree_to_vertex == conn.tree_to_vertex &&
            brick.tree_to_tree == conn.tree_to_tree && brick.tree_to_face == conn.tree_to_face) {
            periodic = uint8_t(bits);
            return true;
        }
    }
    return false;
}

// Grid indices of quantized positions stay within 2^52, where doubles hold every integer.
constexpr double kMaxGridIndex = 4503599627370496.0;

uint64_t zigzag(int64_t v) { return (uint64_t(v) << 1) ^ uint64_t(v >> 63); }
int64_t unzigzag(uint64_t u) { return int64_t(u >> 1) ^ -int64_t(u & 1); }

void put_quantized_positions(std::vector<uint8_t>& out, const std::vector<Vec3>& vertices, double step) {
    put_f64(out, step);
    int64_t previous[3] = {0, 0, 0};
    for (const Vec3& p : vertices) {
        const double xyz[3] = {p.x, p.y, p.z};
        for (int a = 0; a < 3; ++a) {
            const double q = std::nearbyint(xyz[a] / step);
            AMC_REQUIRE(std::fabs(q) <= kMaxGridIndex, invalid_input,
                        "encode_octree_forest: vertex_step " + std::to_string(step) + " is too small for a coordinate " +
                            std::to_string(xyz[a]) + " (grid indices beyond 2^52)");
            put_varint(out, zigzag(int64_t(q) - previous[a]));
            previous[a] = int64_t(q);
        }
    }
}

void read_quantized_positions(PayloadReader& in, std::vector<Vec3>& vertices) {
    const double step = in.f64();
    AMC_REQUIRE(std::isfinite(step) && step > 0, corrupt, "connectivity block: a grid step that is not finite and positive");
    int64_t q[3] = {0, 0, 0};
    for (Vec3& p : vertices) {
        double xyz[3];
        for (int a = 0; a < 3; ++a) {
            const uint64_t delta = in.varint();
            const double next = double(q[a]) + double(unzigzag(delta));
            AMC_REQUIRE(std::fabs(next) <= kMaxGridIndex, corrupt, "connectivity block: a grid index beyond 2^52");
            q[a] = int64_t(next);
            xyz[a] = double(q[a]) * step;
            AMC_REQUIRE(std::isfinite(xyz[a]), corrupt, "connectivity block: a vertex is not finite");
        }
        p = {xyz[0], xyz[1], xyz[2]};
    }
}

}  // namespace

bool is_quantized_connectivity(const std::vector<uint8_t>& payload) {
    return !payload.empty() && (payload[0] == uint8_t(OctreeConnectivityMode::glued_by_quantized_vertices) ||
                                payload[0] == uint8_t(OctreeConnectivityMode::explicit_with_quantized_vertices));
}

std::vector<uint8_t> write_octree_connectivity(const TreeConnectivity& conn, double vertex_step) {
    AMC_REQUIRE(vertex_step == 0 || (std::isfinite(vertex_step) && vertex_step > 0), invalid_input,
                "encode_octree_forest: vertex_step must be 0 (exact) or finite and positive");
    std::vector<uint8_t> out;
    int n[3] = {1, 1, 1};
    uint8_t periodic = 0;
    if (find_brick(conn, n, periodic)) {
        out.push_back(uint8_t(OctreeConnectivityMode::brick));
        out.push_back(periodic);
        for (int a = 0; a < conn.dim; ++a) put_varint(out, uint64_t(n[a]));
        return out;
    }
    const bool has_vertices = !conn.vertices.empty();
    OctreeConnectivityMode mode = has_vertices ? OctreeConnectivityMode::explicit_with_vertices
                                               : OctreeConnectivityMode::explicit_without_vertices;
    if (has_vertices) {
        try {
            const TreeConnectivity glued = connectivity_from_vertices(conn.dim, conn.vertices, conn.tree_to_vertex);
            if (glued.tree_to_tree == conn.tree_to_tree && glued.tree_to_face == conn.tree_to_face)
                mode = OctreeConnectivityMode::glued_by_vertices;
        } catch (const Error&) {
            // Not gluable by vertices (periodic, say): stored explicitly.
        }
    }
    const bool quantized = has_vertices && vertex_step > 0;
    if (quantized)
        mode = mode == OctreeConnectivityMode::glued_by_vertices ? OctreeConnectivityMode::glued_by_quantized_vertices
                                                                 : OctreeConnectivityMode::explicit_with_quantized_vertices;
    out.push_back(uint8_t(mode));
    if (has_vertices) {
        put_varint(out, conn.vertices.size());
        if (quantized) put_quantized_positions(out, conn.vertices, vertex_step);
        else
            for (const Vec3& p : conn.vertices) put_f64(out, p.x), put_f64(out, p.y), put_f64(out, p.z);
        for (uint32_t v : conn.tree_to_vertex) put_varint(out, v);
    }
    if (mode != OctreeConnectivityMode::glued_by_vertices && mode != OctreeConnectivityMode::glued_by_quantized_vertices) {
        for (size_t i = 0; i < conn.tree_to_tree.size(); ++i) {
            put_varint(out, conn.tree_to_tree[i]);
            out.push_back(conn.tree_to_face[i]);
        }
    }
    return out;
}

TreeConnectivity read_octree_connectivity(const uint8_t* data, size_t size, int dim, uint64_t trees, uint8_t version) {
    PayloadReader in(data, size, "connectivity block");
    uint8_t mode = in.u8();
    const uint8_t last_mode = uint8_t(version >= kOctreeLeafDataVersion ? OctreeConnectivityMode::explicit_with_quantized_vertices
                                                                        : OctreeConnectivityMode::brick);
    AMC_REQUIRE(mode <= last_mode, corrupt, "connectivity block: unknown mode " + std::to_string(mode));
    const bool quantized = mode == uint8_t(OctreeConnectivityMode::glued_by_quantized_vertices) ||
                           mode == uint8_t(OctreeConnectivityMode::explicit_with_quantized_vertices);
    if (quantized)  // the same as modes 0 and 1 but for the positions
        mode = uint8_t(mode == uint8_t(OctreeConnectivityMode::glued_by_quantized_vertices) ? OctreeConnectivityMode::glued_by_vertices
                                                                                             : OctreeConnectivityMode::explicit_with_vertices);
    const int corners = 1 << dim, faces = 2 * dim;
    TreeConnectivity conn;
    conn.dim = dim;
    if (mode == uint8_t(OctreeConnectivityMode::brick)) {
        AMC_REQUIRE(trees < (uint64_t{1} << 24), corrupt, "connectivity block: a brick of " + std::to_string(trees) + " trees");
        const uint8_t periodic = in.u8();
        AMC_REQUIRE(periodic < (1 << dim), corrupt, "connectivity block: unknown periodicity bits");
        uint64_t n[3] = {1, 1, 1};
        for (int a = 0; a < dim; ++a) {
            n[a] = in.varint();
            AMC_REQUIRE(n[a] >= 1 && n[a] <= trees, corrupt, "connectivity block: brick size " + std::to_string(n[a]));
        }
        AMC_REQUIRE(n[0] * n[1] * n[2] == trees, corrupt, "connectivity block: the brick does not have " + std::to_string(trees) + " trees");
        AMC_REQUIRE(in.remaining() == 0, corrupt, "connectivity block: " + std::to_string(in.remaining()) + " bytes too many");
        return brick_connectivity(dim, int(n[0]), int(n[1]), int(n[2]), periodic & 1, periodic & 2, periodic & 4);
    }
    if (mode != uint8_t(OctreeConnectivityMode::explicit_without_vertices)) {
        const uint64_t vertices = in.varint();
        const uint64_t vertex_bytes = quantized ? 3 : 24;  // three varints of at least a byte, or three f64
        AMC_REQUIRE(vertices >= 1 && vertices <= in.remaining() / vertex_bytes, corrupt,
                    "connectivity block: " + std::to_string(vertices) + " vertices do not fit in it");
        AMC_REQUIRE(trees * corners <= in.remaining() - vertices * vertex_bytes, corrupt,
                    "connectivity block: " + std::to_string(trees) + " trees do not fit in it");
        conn.vertices.resize(vertices);
        if (quantized) {
            read_quantized_positions(in, conn.vertices);
            AMC_REQUIRE(trees * corners <= in.remaining(), corrupt, "connectivity block: " + std::to_string(trees) + " trees do not fit in it");
        } else {
            for (Vec3& p : conn.vertices) {
                p.x = in.f64(), p.y = in.f64(), p.z = in.f64();
                AMC_REQUIRE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z), corrupt, "connectivity block: a vertex is not finite");
            }
        }
        conn.tree_to_vertex.resize(trees * corners);
        for (uint32_t& v : conn.tree_to_vertex) {
            const uint64_t value = in.varint();
            AMC_REQUIRE(value < vertices, corrupt, "connectivity block: vertex " + std::to_string(value) + " out of range");
            v = uint32_t(value);
        }
    }
    if (mode == uint8_t(OctreeConnectivityMode::glued_by_vertices)) {
        try {
            conn = connectivity_from_vertices(dim, std::move(conn.vertices), std::move(conn.tree_to_vertex));
        } catch (const Error& e) {
            throw_error(ErrorCode::corrupt, std::string("connectivity block: ") + e.what());
        }
    } else {
        AMC_REQUIRE(trees * faces <= in.remaining() / 2, corrupt, "connectivity block: " + std::to_string(trees) + " trees do not fit in it");
        conn.tree_to_tree.resize(trees * faces);
        conn.tree_to_face.resize(trees * faces);
        for (size_t i = 0; i < conn.tree_to_tree.size(); ++i) {
            const uint64_t t = in.varint();
            AMC_REQUIRE(t < trees, corrupt, "connectivity block: tree " + std::to_string(t) + " out of range");
            conn.tree_to_tree[i] = uint32_t(t);
            conn.tree_to_face[i] = in.u8();
        }
    }
    AMC_REQUIRE(in.remaining() == 0, corrupt, "connectivity block: " + std::to_string(in.remaining()) + " bytes too many");
    try {
        validate_connectivity(conn, "connectivity block");
    } catch (const Error& e) {
        throw_error(ErrorCode::corrupt, e.what());
    }
    return conn;
}

}  // namespace amc
