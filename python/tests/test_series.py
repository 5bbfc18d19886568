"""Series (.amcs) from Python: frames with fields written and read back exactly, random access with
keyframes, meshes in their own numbering, error bounds, unfinished files, errors as exceptions."""
import threading

import numpy as np
import pytest

import amcodec


def base_mesh():
    points = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0.5, 0.5, 0]], dtype=np.float64)
    triangles = np.array([[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]], dtype=np.int64)
    return points, triangles


def frames(count=8, seed=5):
    """Hierarchies refined and coarsened at random from frame to frame, with fields computed on them."""
    points, triangles = base_mesh()
    h = amcodec.Hierarchy(points, triangles)
    rng = np.random.default_rng(seed)
    out = []
    for k in range(count):
        for _ in range(12):
            leaves = h.leaves()
            h.refine(leaves[rng.integers(len(leaves))])
        mesh = h.leaf_mesh()
        x = mesh["points"]
        point_data = {"u": np.sin(3 * x[:, 0] + 0.1 * k) * np.cos(2 * x[:, 1]),
                      "velocity": np.stack([x[:, 1], -x[:, 0], np.zeros(len(x))], axis=1).astype(np.float32)}
        cell_data = {"material": (mesh["level"] % 3).astype(np.int32)}
        out.append((amcodec.decode_hierarchy(h.encode()), 0.25 * k, point_data, cell_data))
    return out


def series_base(seq):
    """The base of the frames as they came out of .amc files (whose encoder puts the base in its order)."""
    base = seq[0][0].leaf_mesh(0)
    return base["points"], base["triangles"]


def test_frames_come_back_bit_exact_and_by_random_access():
    seq = frames()
    points, triangles = series_base(seq)
    writer = amcodec.SeriesWriter(points, triangles, keyframe_interval=3)
    for h, time, point_data, cell_data in seq:
        stats = writer.add_frame(h, time, point_data, cell_data)
        assert stats["bytes"] > 0
    writer.close()
    data = writer.bytes()
    reader = amcodec.SeriesReader(data)
    assert len(reader) == len(seq) and reader.finished and reader.keyframe_interval == 3
    # Frames 0, 3, 6, ... and any frame the encoder found smaller coded alone.
    assert all(reader.info(k)["keyframe"] for k in range(0, len(seq), 3))
    for k in [5, 0, 7, 6, 1]:  # random access, backwards too
        h, time, point_data, cell_data = seq[k]
        frame = reader.frame(k)
        assert frame["time"] == time
        assert np.array_equal(frame["triangles"], h.leaf_mesh()["triangles"])
        assert np.array_equal(frame["points"], h.leaf_mesh()["points"])
        for name, values in point_data.items():
            assert frame["point_data"][name].dtype == values.dtype
            assert np.array_equal(frame["point_data"][name], values)
        assert np.array_equal(frame["cell_data"]["material"], cell_data["material"])
        assert reader.hierarchy(k).identical(h)
    with pytest.raises(IndexError):
        reader.frame(len(seq))


def test_meshes_in_their_own_numbering_come_back_canonical_with_their_data():
    seq = frames(1)
    points, triangles = series_base(seq)
    h, _, point_data, _ = seq[0]
    mesh = h.leaf_mesh()
    rng = np.random.default_rng(1)
    order = rng.permutation(len(mesh["points"]))
    inverse = np.empty_like(order)
    inverse[order] = np.arange(len(order))
    writer = amcodec.SeriesWriter(points, triangles)
    writer.add_mesh(mesh["points"][order], inverse[mesh["triangles"]], 1.5, {"u": point_data["u"][order]})
    writer.close()
    frame = amcodec.SeriesReader(writer.bytes()).frame(0)
    assert np.array_equal(frame["points"], mesh["points"])
    assert np.array_equal(frame["point_data"]["u"], point_data["u"])


def test_error_bound_holds_and_files_on_disk_read_while_unfinished(tmp_path):
    seq = frames(4)
    points, triangles = series_base(seq)
    path = str(tmp_path / "run.amcs")
    writer = amcodec.SeriesWriter(points, triangles, path=path, error_bound=1e-3)
    for h, time, point_data, cell_data in seq:
        stats = writer.add_frame(h, time, point_data, cell_data)
        assert stats["max_error"] <= 1e-3
    with pytest.raises(amcodec.Error, match="unfinished"):
        amcodec.SeriesReader.open(path)
    reader = amcodec.SeriesReader.open(path, partial=True)
    assert len(reader) == 4 and not reader.finished
    assert np.max(np.abs(reader.frame(3)["point_data"]["u"] - seq[3][2]["u"])) <= 1e-3
    writer.close()
    assert amcodec.SeriesReader.open(path).finished


def test_bad_series_raise_amcodec_error():
    with pytest.raises(amcodec.Error, match="not an amcodec series"):
        amcodec.SeriesReader(b"AMCF not a series")
    seq = frames(1)
    points, triangles = series_base(seq)
    writer = amcodec.SeriesWriter(points, triangles)
    h, time, point_data, _ = seq[0]
    with pytest.raises(amcodec.Error, match="u"):
        writer.add_frame(h, time, {"u": point_data["u"][:-1]})
    writer.add_frame(h, time, point_data)
    writer.close()
    data = bytearray(writer.bytes())
    data[len(data) // 2] ^= 0x10
    with pytest.raises(amcodec.Error, match="checksum"):
        amcodec.SeriesReader(bytes(data))


def test_one_reader_from_many_threads():
    # SeriesReader.frame released the GIL until 2026-12-07 while it changed the reader's state (the
    # frame decoded last), so threads reading one reader crashed the interpreter.
    seq = frames(count=12, seed=8)
    points, triangles = series_base(seq)
    writer = amcodec.SeriesWriter(points, triangles, keyframe_interval=4)
    for h, time, point_data, cell_data in seq:
        writer.add_frame(h, time, point_data, cell_data)
    writer.close()
    reader = amcodec.SeriesReader(writer.bytes())
    errors = []

    def read(seed):
        rng = np.random.default_rng(seed)
        try:
            for _ in range(40):
                k = int(rng.integers(len(seq)))
                frame = reader.frame(k)
                assert np.array_equal(frame["points"], seq[k][0].leaf_mesh()["points"])
                assert np.array_equal(frame["point_data"]["u"], seq[k][2]["u"])
        except Exception as e:  # noqa: BLE001 - reported by the assertion below
            errors.append(e)

    threads = [threading.Thread(target=read, args=(seed,)) for seed in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert errors == []
