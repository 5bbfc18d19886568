// A program of a user of the installed library: a small adaptive hierarchy over an octahedron,
// encoded and decoded, and the decoded hierarchy compared with the input (and encoded again to
// the same bytes); with a library built with p4est, an octree forest balanced by p4est and coded
// (which links p4est, sc and MPI into the program). Built by CI against the installed amcodec
// through find_package (cmake/) and pkg-config (pkgconfig/); exit status 0 when all is exact.
#include <amc/codec.h>
#include <amc/hierarchy.h>
#include <amc/import.h>
#include <amc/octree.h>

#include <cstdio>
#include <cstdlib>
#include <vector>

namespace {

amc::TriangleMesh octahedron() {
    amc::TriangleMesh m;
    m.positions = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    m.triangles = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
    return m;
}

bool check(bool ok, const char* what) {
    std::printf("%s: %s\n", what, ok ? "ok" : "FAILED");
    return ok;
}

}  // namespace

int main() {
    try {
        amc::Hierarchy h(octahedron());
        // Adaptive: refine the finest leaf three times over, with balance and closure.
        for (int round = 0; round < 3; ++round) {
            const std::vector<amc::NodeId> leaves = h.leaves();
            h.refine(leaves.back());  // the finest leaf: levels 1, 2, 3
        }
        // Move every vertex off its midpoint, so the geometry coder has residuals to code.
        for (amc::VertexId v = 0; v < h.positions().size(); ++v) {
            const amc::Vec3 p = h.position(v);
            h.set_position(v, {p.x * 1.25 + 0.001 * v, p.y - 0.002 * v, p.z + 0.0005 * v * v});
        }
        const std::vector<uint8_t> file = amc::encode(h);
        const amc::Hierarchy decoded = amc::decode(file.data(), file.size());
        const std::vector<uint8_t> again = amc::encode(decoded);
        std::printf("%u nodes, %u vertices, %zu bytes\n", h.node_count(), h.vertex_count(), file.size());

        // A leaf mesh alone, as a user would have it: imported, encoded, decoded.
        const amc::LeafMesh leaf = amc::extract_leaf_mesh(h);
        const amc::ImportedHierarchy imported = amc::import_mesh(leaf.mesh);
        const std::vector<uint8_t> leaf_file = amc::encode(imported.hierarchy);
        const amc::Hierarchy leaf_decoded = amc::decode(leaf_file.data(), leaf_file.size());

        bool ok = check(amc::check_invariants(decoded).empty(), "decoded hierarchy is valid");
        ok &= check(amc::identical(decoded, amc::in_decoder_order(h)), "decode(encode(h)) is h");
        ok &= check(again == file, "encoded again to the same bytes");
        ok &= check(amc::identical(leaf_decoded, amc::in_decoder_order(imported.hierarchy)),
                    "imported leaf mesh round trip");
        ok &= check(amc::extract_leaf_mesh(leaf_decoded).mesh.triangles.size() == leaf.mesh.triangles.size(),
                    "same leaf triangle count");

        if (amc::octree_p4est_available()) {
            const amc::TreeConnectivity brick = amc::brick_connectivity(2, 2, 1);
            const amc::OctreeForest sphere = amc::sphere_octree_forest(brick, {0.7, 0.4, 0}, 0.3, 5);
            const amc::OctreeForest by_p4est = amc::balanced_by_p4est(sphere, amc::OctreeBalance::corner);
            const std::vector<uint8_t> octree_file = amc::encode_octree_forest(by_p4est);
            const amc::OctreeForest octree_decoded = amc::decode_octree_forest(octree_file.data(), octree_file.size());
            ok &= check(amc::balance_octree_forest(sphere, amc::OctreeBalance::corner) == by_p4est,
                        "amcodec's balance is p4est's");
            ok &= check(octree_decoded == by_p4est, "decode(encode(forest)) is the forest");
            ok &= check(amc::octree_p4est_checksum(octree_decoded) == amc::octree_p4est_checksum(by_p4est),
                        "p4est-balanced forest round trip (p4est checksum)");
            ok &= check(amc::is_balanced_in_p4est(octree_decoded, amc::OctreeBalance::corner),
                        "decoded forest balanced in p4est");
        }
        return ok ? EXIT_SUCCESS : EXIT_FAILURE;
    } catch (const amc::Error& e) {
        std::fprintf(stderr, "error: %s\n", e.what());
        return EXIT_FAILURE;
    }
}
