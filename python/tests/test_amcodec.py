"""The Python module: arrays in and out, round trips exact, numbering kept, errors as exceptions."""
import threading

import numpy as np
import pytest

import amcodec


def icosahedron():
    t = (1 + 5 ** 0.5) / 2
    points = np.array([[-1, t, 0], [1, t, 0], [-1, -t, 0], [1, -t, 0], [0, -1, t], [0, 1, t], [0, -1, -t], [0, 1, -t],
                       [t, 0, -1], [t, 0, 1], [-t, 0, -1], [-t, 0, 1]], dtype=np.float64)
    triangles = np.array([[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4], [11, 10, 2],
                          [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8], [3, 8, 9], [4, 9, 5],
                          [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1]], dtype=np.int64)
    return points, triangles


def adaptive_leaf_mesh(seed=1):
    """A red-green hierarchy refined at random, and its leaf mesh with vertices and faces shuffled."""
    points, triangles = icosahedron()
    h = amcodec.Hierarchy(points, triangles)
    rng = np.random.default_rng(seed)
    for _ in range(40):
        leaves = h.leaves()
        h.refine(leaves[rng.integers(len(leaves))])
    mesh = h.leaf_mesh()
    order = rng.permutation(len(mesh["points"]))
    inverse = np.empty_like(order)
    inverse[order] = np.arange(len(order))
    shuffled_points = mesh["points"][order]
    shuffled_triangles = inverse[mesh["triangles"]][rng.permutation(len(mesh["triangles"]))]
    return h, shuffled_points, shuffled_triangles


def test_hierarchy_round_trip_is_identical():
    h, _, _ = adaptive_leaf_mesh()
    assert h.check() == ""
    data = h.encode()
    back = amcodec.decode_hierarchy(data)
    assert back.node_count == h.node_count
    assert back.leaf_mesh()["triangles"].shape == h.leaf_mesh()["triangles"].shape


def test_mesh_round_trip_keeps_the_numbering():
    _, points, triangles = adaptive_leaf_mesh(2)
    data = amcodec.encode(points, triangles, keep_numbering=True)
    mesh = amcodec.decode(data)
    assert np.array_equal(mesh["points"], points)
    assert np.array_equal(mesh["triangles"], triangles)
    assert mesh["numbering"] is not None
    assert mesh["level"].shape == (len(triangles),)


def test_plain_mesh_gets_its_coarsest_base_detected():
    points, triangles = icosahedron()
    h = amcodec.Hierarchy(points, triangles)
    for _ in range(2):
        for leaf in h.leaves():
            h.refine(leaf)
    mesh = h.leaf_mesh()
    rng = np.random.default_rng(5)
    order = rng.permutation(len(mesh["points"]))
    inverse = np.empty_like(order)
    inverse[order] = np.arange(len(order))
    shuffled = inverse[mesh["triangles"]][rng.permutation(len(mesh["triangles"]))]
    data, stats = amcodec.encode(mesh["points"][order], shuffled, keep_numbering=True, return_stats=True)
    assert stats["base_triangles"] == 20 and stats["levels"] == 3
    back = amcodec.decode(data)
    assert np.array_equal(back["points"], mesh["points"][order]) and np.array_equal(back["triangles"], shuffled)


def test_without_numbering_the_map_ties_input_to_output():
    _, points, triangles = adaptive_leaf_mesh(4)
    data, stats = amcodec.encode(points, triangles, return_stats=True)
    assert stats["numbering_bytes"] == 0
    mesh = amcodec.decode(data)
    vertex = stats["numbering"]["vertex"]
    assert np.array_equal(mesh["points"][vertex], points)


def test_partial_file_decodes_the_levels_that_arrived():
    h, _, _ = adaptive_leaf_mesh(4)
    data = h.encode()
    whole = amcodec.decode(data, partial=True)
    assert whole["complete"] and whole["reached_level"] == whole["levels"] - 1
    assert np.array_equal(whole["triangles"], amcodec.decode(data)["triangles"])
    cut = amcodec.decode(data[:len(data) * 3 // 4], partial=True)
    assert not cut["complete"] and 0 <= cut["reached_level"] < whole["levels"] - 1
    same = amcodec.decode(data, level=cut["reached_level"])
    assert np.array_equal(cut["triangles"], same["triangles"]) and np.array_equal(cut["points"], same["points"])
    with pytest.raises(amcodec.Error, match="truncated|base mesh"):
        amcodec.decode(data[:30], partial=True)
    with pytest.raises(amcodec.Error):
        amcodec.decode(data[:len(data) * 3 // 4])


def test_float32_stays_float32_and_quantized_is_within_the_error():
    _, points, triangles = adaptive_leaf_mesh(5)
    mesh = amcodec.decode(amcodec.encode(points.astype(np.float32), triangles, keep_numbering=True))
    assert mesh["points"].dtype == np.float32
    assert np.array_equal(mesh["points"], points.astype(np.float32))
    data, stats = amcodec.encode(points, triangles, keep_numbering=True, quantize=12, return_stats=True)
    lossy = amcodec.decode(data)
    assert np.max(np.abs(lossy["points"] - points)) <= stats["max_error"]


def test_bad_input_raises_amcodec_error_with_the_message():
    points, triangles = icosahedron()
    bad = triangles.copy()
    bad[0, 0] = 99
    with pytest.raises(amcodec.Error, match="out of range"):
        amcodec.encode(points, bad)
    with pytest.raises(amcodec.Error, match="magic"):
        amcodec.decode(b"not an amc file")
    data = amcodec.encode(points, triangles)
    with pytest.raises(amcodec.Error):
        amcodec.decode(data[: len(data) // 2])


def test_meshio_round_trip():
    meshio = pytest.importorskip("meshio")
    _, points, triangles = adaptive_leaf_mesh(6)
    mesh = meshio.Mesh(points, [("triangle", triangles)])
    back = amcodec.decode_meshio(amcodec.encode_meshio(mesh))
    assert np.array_equal(back.points, points)
    assert np.array_equal(back.cells[0].data, triangles)
    assert "level" in back.cell_data


def test_meshio_file_in_and_out(tmp_path):
    """The README's session: a mesh file read with meshio, compressed, decoded, compared."""
    meshio = pytest.importorskip("meshio")
    _, points, triangles = adaptive_leaf_mesh(7)
    meshio.write(tmp_path / "leaf.vtu", meshio.Mesh(points, [("triangle", triangles)]))
    mesh = meshio.read(tmp_path / "leaf.vtu")
    data = amcodec.encode_meshio(mesh)
    (tmp_path / "leaf.amc").write_bytes(data)
    back = amcodec.decode_meshio((tmp_path / "leaf.amc").read_bytes())
    assert np.array_equal(back.points, mesh.points)
    assert np.array_equal(back.cells[0].data, mesh.cells[0].data)
    meshio.write(tmp_path / "back.vtu", back)


def test_every_effort_decodes_alike_and_others_are_refused():
    h, points, triangles = adaptive_leaf_mesh(3)
    expected = amcodec.decode_hierarchy(h.encode(quantize=12)).leaf_mesh()
    for effort in (0, 1, 2, 3, 4):
        back = amcodec.decode_hierarchy(h.encode(quantize=12, effort=effort)).leaf_mesh()
        if effort <= 2:
            assert np.array_equal(back["points"], expected["points"])
            assert np.array_equal(back["triangles"], expected["triangles"])
        else:  # the base order is the search's: the same mesh, maybe numbered otherwise
            assert np.array_equal(np.unique(back["points"], axis=0), np.unique(expected["points"], axis=0))
            assert len(back["triangles"]) == len(expected["triangles"])
        mesh = amcodec.decode(amcodec.encode(points, triangles, keep_numbering=True, effort=effort))
        assert np.array_equal(mesh["points"], points)
    for effort in (-1, 5):
        with pytest.raises(Exception, match="effort"):
            h.encode(effort=effort)
        with pytest.raises(Exception, match="effort"):
            amcodec.encode(points, triangles, effort=effort)


def test_node_ids_are_checked():
    points, triangles = icosahedron()
    h = amcodec.Hierarchy(points, triangles)
    h.refine(0)
    assert h.level(h.node_count - 1) == 1 and h.is_leaf(h.node_count - 1)
    # Read out of the node array until 2026-12-07 (level(10**8) crashed the interpreter).
    for call in (h.is_leaf, h.level, h.refine, h.coarsen):
        for node in (h.node_count, 10 ** 8, 2 ** 32 - 1):
            with pytest.raises(amcodec.Error, match="no node"):
                call(node)


def test_triangle_indices_must_be_integers():
    _, points, triangles = adaptive_leaf_mesh(4)
    data = amcodec.encode(points, triangles)
    # Whole numbers in a float array (np.loadtxt) are taken; a fraction was truncated to another
    # vertex without a word until 2026-12-07.
    assert amcodec.encode(points, triangles.astype(np.float64)) == data
    assert amcodec.encode(points, triangles.astype(np.uint32)) == data
    fractional = triangles.astype(np.float64)
    fractional[3, 1] += 0.5
    with pytest.raises(amcodec.Error, match=r"triangle 3 has vertex index .*, not an integer"):
        amcodec.encode(points, fractional)
    with pytest.raises(amcodec.Error, match="out of range"):
        amcodec.encode(points, np.array([[0, 1, 2 ** 64 - 1]], dtype=np.uint64))
    for wrong in (triangles.astype(bool), triangles.astype(str), triangles[:, :2]):
        with pytest.raises(amcodec.Error, match=r"triangles must be an \(m, 3\) integer array"):
            amcodec.encode(points, wrong)


def test_a_hierarchy_changed_by_one_thread_while_another_encodes_it():
    # Hierarchy.encode released the GIL until 2026-12-07, so refine and coarsen on another thread
    # changed the hierarchy under it ("invalid hierarchy", or a crash); now each encode sees one state.
    h, _, _ = adaptive_leaf_mesh(5)
    for _ in range(1500):
        leaves = h.leaves()
        h.refine(leaves[len(leaves) // 2])
    errors = []

    def encode_repeatedly():
        try:
            for _ in range(30):
                back = amcodec.decode_hierarchy(h.encode())
                assert back.check() == ""
        except Exception as e:  # noqa: BLE001 - reported by the assertion below
            errors.append(e)

    def change_repeatedly():
        rng = np.random.default_rng(6)
        try:
            for _ in range(6000):
                leaves = h.leaves()
                node = int(leaves[rng.integers(len(leaves))])
                if rng.random() < 0.5:
                    h.refine(node)
                else:
                    try:
                        h.coarsen(max(0, node - 3))
                    except amcodec.Error:  # not a node (any more)
                        pass
        except Exception as e:  # noqa: BLE001 - reported by the assertion below
            errors.append(e)

    threads = [threading.Thread(target=encode_repeatedly), threading.Thread(target=change_repeatedly)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert errors == []
    assert h.check() == ""


def test_planar_points_are_taken_at_z_zero():
    _, points, triangles = adaptive_leaf_mesh(7)
    flat = points.copy()
    flat[:, 2] = 0
    data = amcodec.encode(flat[:, :2], triangles, keep_numbering=True)
    assert data == amcodec.encode(flat, triangles, keep_numbering=True)
    assert np.array_equal(amcodec.decode(data)["points"], flat)
    with pytest.raises(amcodec.Error, match=r"points must be an \(n, 3\) or \(n, 2\) array"):
        amcodec.encode(points[:, :1], triangles)


def test_the_forest_can_be_walked_and_ties_to_the_leaf_mesh():
    h, _, _ = adaptive_leaf_mesh(9)
    points, triangles = h.base
    assert len(triangles) == h.root_count
    alive = [n for n in range(h.node_capacity) if h.is_alive(n)]
    assert len(alive) == h.node_count
    for n in alive:
        parent = h.parent(n)
        assert (parent is None) == (n < h.root_count)
        if parent is not None:
            assert n in h.children(parent) and h.level(n) == h.level(parent) + 1
        kids = h.children(n)
        assert (kids == []) == h.is_leaf(n)
        if kids:  # the center's corners are the parent's edge midpoints, each shared with a corner child
            center = set(h.vertices(kids[3]))
            for k in range(3):
                assert len(center & set(h.vertices(kids[k]))) == 2
                assert h.vertices(n)[k] in h.vertices(kids[k])
        for e, q in enumerate(h.neighbors(n)):
            if q is not None:  # the same edge, the other way round
                a, b = h.vertices(n)[e], h.vertices(n)[(e + 1) % 3]
                assert h.level(q) == h.level(n) and {a, b} <= set(h.vertices(q))
    for level in (-1, 2):
        mesh = h.leaf_mesh(level)
        assert np.array_equal(mesh["points"], np.array([h.position(v) for v in mesh["vertex"]]))
        for t, node, node_level, green in zip(mesh["triangles"], mesh["node"], mesh["level"], mesh["green"]):
            assert h.is_leaf(node) or h.level(node) == level
            assert h.level(node) == node_level
            # A red leaf is its node's triangle; a green one keeps one or two of its corners.
            corners = {int(mesh["vertex"][i]) for i in t}
            assert len(corners & set(h.vertices(node))) == 3 if not green else 1 <= len(corners & set(h.vertices(node))) <= 2
    v = h.vertices(h.leaves()[0])[0]
    h.set_position(v, [0.5, 0.25, 2.0])
    assert np.array_equal(h.position(v), [0.5, 0.25, 2.0])
    back = amcodec.decode_hierarchy(h.encode())
    assert np.array_equal(np.sort(back.leaf_mesh()["points"], axis=0), np.sort(h.leaf_mesh()["points"], axis=0))
    for call in (h.parent, h.children, h.vertices, h.neighbors):
        with pytest.raises(amcodec.Error, match="no node"):
            call(h.node_capacity)
    with pytest.raises(amcodec.Error, match="no vertex"):
        h.position(10 ** 7)
    with pytest.raises(amcodec.Error, match="three coordinates"):
        h.set_position(v, [1.0, 2.0])


def test_info_and_chunks_without_decoding_the_whole_file():
    h, _, _ = adaptive_leaf_mesh(10)
    whole = h.encode()
    info = amcodec.info(whole)
    assert (info["faces"], info["nodes"], info["chunks"]) == (len(h.leaf_mesh()["triangles"]), h.node_count, [])
    assert sum(b["bytes"] for b in info["blocks"]) + 12 == len(whole)  # the 12-byte file header before them
    data = h.encode(chunks=4)
    chunks = amcodec.info(data)["chunks"]
    assert len(chunks) == 4 and sum(c["roots"] for c in chunks) == h.root_count
    back = amcodec.decode_hierarchy(data)
    total_nodes = 0
    for k, chunk in enumerate(chunks):
        part, roots, base_vertices = amcodec.decode_chunks(data, [k])
        assert list(roots) == list(range(chunk["first_root"], chunk["first_root"] + chunk["roots"]))
        assert part.node_count == chunk["nodes"]
        total_nodes += part.node_count
        base_points, _ = back.base
        assert np.array_equal(part.base[0], base_points[base_vertices])
    assert total_nodes == back.node_count
    with pytest.raises(amcodec.Error, match="chunk"):
        amcodec.decode_chunks(data, [4])
    with pytest.raises(amcodec.Error, match="magic"):
        amcodec.info(b"not an amc file")


def test_a_base_elsewhere_is_matched_by_its_map():
    h, points, triangles = adaptive_leaf_mesh(11)
    base_points, base_triangles = h.base
    # Per base vertex its index among the shuffled points (the leaf mesh has them bit for bit).
    where = {tuple(p): i for i, p in enumerate(points)}
    base_map = np.array([where[tuple(p)] for p in base_points])
    by_position = amcodec.encode(points, triangles, base=(base_points, base_triangles))
    moved = base_points + 0.001
    with pytest.raises(amcodec.Error, match="not a vertex of the leaf mesh"):
        amcodec.encode(points, triangles, base=(moved, base_triangles))
    assert amcodec.encode(points, triangles, base=(moved, base_triangles), base_map=base_map) == by_position
    imported, vertex_of_input = amcodec.import_mesh(points, triangles, base=(moved, base_triangles), base_map=base_map)
    assert np.array_equal(imported.base[0], base_points)  # the leaf mesh's positions, not the moved base's
    for wrong, message in ((base_map[:-1], "entries for"), (np.append(base_map[:-1], base_map[0]), "both map to"),
                           (-base_map - 1, "not a vertex"), (base_map.astype(float), r"\(n,\) integer array")):
        with pytest.raises(amcodec.Error, match=message):
            amcodec.encode(points, triangles, base=(moved, base_triangles), base_map=wrong)
    with pytest.raises(amcodec.Error, match="without a base"):
        amcodec.encode(points, triangles, base_map=base_map)
