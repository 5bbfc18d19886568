"""VTU and PLY files that amcodec writes, opened by meshio and by VTK (Debian's python3-meshio and
python3-vtk9) with their points, triangles and every point and cell array intact.

Run by .ci/run after the build:  AMC_BUILD_DIR=build /usr/bin/python3 -m pytest tests/vtu_interop_test.py
The files come from tests/vtu_write_sample.cpp (every value type, binary and ASCII, single and
double precision) and from `amc demo` (a leaf mesh with level and green cell arrays).
"""
import os
import subprocess

import meshio
import numpy as np
import pytest
import vtk
from vtk.util import numpy_support

BUILD = os.path.abspath(os.environ.get("AMC_BUILD_DIR", "build"))
SAMPLES = ["binary_double.vtu", "binary_single.vtu", "ascii_double.vtu", "ascii_single.vtu"]


def expected(single):
    """The sample of tests/vtu_write_sample.cpp, computed the same way."""
    w, h = 40, 30
    pts = np.array([[i / 3.0, j * 0.1, (i * j % 7) / 7.0] for j in range(h + 1) for i in range(w + 1)])
    if single:
        pts = pts.astype(np.float32)
    tris = []
    for j in range(h):
        for i in range(w):
            a = j * (w + 1) + i
            b, c = a + 1, a + w + 1
            tris += [(a, b, c + 1), (a, c + 1, c)]
    n, m = len(pts), len(tris)
    point = {
        "temperature": np.array([i / 3.0 + 0.1 for i in range(n)], dtype=np.float64),
        "velocity": np.array([[i + k / 10.0 for k in range(3)] for i in range(n)], dtype=np.float32),
        "id": np.array([2**60 + i for i in range(n)], dtype=np.int64),
        "u16": np.array([i * 7919 % 65536 for i in range(n)], dtype=np.uint16),
    }
    cell = {
        "level": np.array([t % 5 for t in range(m)], dtype=np.uint8),
        "green": np.array([t % 2 for t in range(m)], dtype=np.uint8),
        "material": np.array([-1000 * t for t in range(m)], dtype=np.int32),
        "big": np.array([2**63 + t for t in range(m)], dtype=np.uint64),
        "i8": np.array([t % 256 - 128 for t in range(m)], dtype=np.int8),
        "i16": np.array([-t for t in range(m)], dtype=np.int16),
        "u32": np.array([4000000000 - t for t in range(m)], dtype=np.uint32),
    }
    return pts, np.array(tris), point, cell


@pytest.fixture(scope="module")
def sample_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("vtu")
    subprocess.run([os.path.join(BUILD, "tests", "vtu_write_sample"), str(out)], check=True)
    return out


def same(got, want):
    """Same dtype and the same bits."""
    got = np.asarray(got)
    assert got.dtype == want.dtype, (got.dtype, want.dtype)
    assert got.shape == want.shape, (got.shape, want.shape)
    assert got.tobytes() == want.tobytes()


@pytest.mark.parametrize("name", SAMPLES)
def test_meshio_reads_our_files(sample_dir, name):
    pts, tris, point, cell = expected("single" in name)
    mesh = meshio.read(str(sample_dir / name))
    same(mesh.points, pts)
    assert len(mesh.cells) == 1 and mesh.cells[0].type == "triangle"
    assert np.array_equal(mesh.cells[0].data, tris)
    assert list(mesh.point_data) == list(point)
    for key, values in point.items():
        same(mesh.point_data[key], values)
    assert list(mesh.cell_data) == list(cell)
    for key, values in cell.items():
        same(mesh.cell_data[key][0], values)


def vtk_read(path):
    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(str(path))
    reader.Update()
    assert reader.GetErrorCode() == 0
    return reader.GetOutput()


@pytest.mark.parametrize("name", SAMPLES)
def test_vtk_reads_our_files(sample_dir, name):
    pts, tris, point, cell = expected("single" in name)
    grid = vtk_read(sample_dir / name)
    same(numpy_support.vtk_to_numpy(grid.GetPoints().GetData()), pts)
    assert grid.GetNumberOfCells() == len(tris)
    types = numpy_support.vtk_to_numpy(grid.GetCellTypesArray())
    assert (types == vtk.VTK_TRIANGLE).all()
    conn = numpy_support.vtk_to_numpy(grid.GetCells().GetConnectivityArray())
    assert np.array_equal(conn.reshape(-1, 3), tris)
    for data, arrays in ((grid.GetPointData(), point), (grid.GetCellData(), cell)):
        assert [data.GetArrayName(i) for i in range(data.GetNumberOfArrays())] == list(arrays)
        for key, values in arrays.items():
            same(numpy_support.vtk_to_numpy(data.GetArray(key)), values)


def test_amc_demo_vtu_opens_in_meshio_and_vtk(tmp_path):
    subprocess.run([os.path.join(BUILD, "amc"), "demo", "--out-dir", str(tmp_path)], check=True,
                   stdout=subprocess.DEVNULL)
    path = tmp_path / "demo.vtu"
    head = path.read_bytes()[:400]
    assert b'compressor="vtkZLibDataCompressor"' in head and b'header_type="UInt64"' in head
    mesh = meshio.read(str(path))
    grid = vtk_read(path)
    assert grid.GetNumberOfPoints() == len(mesh.points) > 0
    assert grid.GetNumberOfCells() == len(mesh.cells[0].data) > 0
    for key in ("level", "green"):
        from_meshio = mesh.cell_data[key][0]
        from_vtk = numpy_support.vtk_to_numpy(grid.GetCellData().GetArray(key))
        assert from_meshio.dtype == np.uint8 and from_vtk.dtype == np.uint8
        assert np.array_equal(from_meshio, from_vtk)
    assert set(np.unique(mesh.cell_data["green"][0])) == {0, 1}
    assert mesh.cell_data["level"][0].max() > 0


def vtk_read_ply(path):
    reader = vtk.vtkPLYReader()
    reader.SetFileName(str(path))
    reader.Update()
    return reader.GetOutput()


@pytest.mark.parametrize("ascii", [False, True])
def test_amc_decoded_ply_opens_in_meshio_and_vtk(tmp_path, ascii):
    """Binary PLY (the default) holds vertices and faces; --ascii adds level and green per face,
    which meshio reads (VTK's PLY reader keeps only its own property names)."""
    amc = os.path.join(BUILD, "amc")
    subprocess.run([amc, "-q", "demo", "--out-dir", str(tmp_path)], check=True)
    ply = tmp_path / "leaf.ply"
    subprocess.run([amc, "-q", "decode", str(tmp_path / "demo.amc"), "-o", str(ply)] +
                   (["--ascii"] if ascii else []), check=True)
    subprocess.run([amc, "-q", "decode", str(tmp_path / "demo.amc"), "-o", str(tmp_path / "leaf.vtu")], check=True)
    reference = meshio.read(str(tmp_path / "leaf.vtu"))
    mesh = meshio.read(str(ply))
    assert np.array_equal(mesh.points, reference.points)
    assert np.array_equal(mesh.cells[0].data, reference.cells[0].data)
    if ascii:
        for key in ("level", "green"):
            assert np.array_equal(mesh.cell_data[key][0], reference.cell_data[key][0])
    else:
        assert "level" not in mesh.cell_data
    poly = vtk_read_ply(ply)
    assert poly.GetNumberOfPoints() == len(reference.points)
    assert poly.GetNumberOfCells() == len(reference.cells[0].data)
    triangles = numpy_support.vtk_to_numpy(poly.GetPolys().GetData()).reshape(-1, 4)
    assert np.array_equal(triangles[:, 1:], reference.cells[0].data)
    assert np.array_equal(numpy_support.vtk_to_numpy(poly.GetPoints().GetData()), reference.points)


@pytest.mark.parametrize("dim", [2, 3])
def test_conforming_octree_vtu_opens_in_meshio_and_vtk(tmp_path, dim):
    """`amc octree make --conforming`: triangles / tetrahedra without hanging nodes, positively
    oriented, covering the unit square / cube, with the leaves' level, tree and index per cell."""
    path = tmp_path / "forest.vtu"
    subprocess.run([os.path.join(BUILD, "amc"), "-q", "octree", "make", "--dim", str(dim), "--model", "sphere",
                    "--level", "5" if dim == 2 else "3", "--conforming", "-o", str(path)], check=True)
    mesh = meshio.read(str(path))
    grid = vtk_read(path)
    kind = "triangle" if dim == 2 else "tetra"
    assert len(mesh.cells) == 1 and mesh.cells[0].type == kind
    cells = mesh.cells[0].data
    assert grid.GetNumberOfCells() == len(cells) and grid.GetNumberOfPoints() == len(mesh.points)
    types = numpy_support.vtk_to_numpy(grid.GetCellTypesArray())
    assert (types == (vtk.VTK_TRIANGLE if dim == 2 else vtk.VTK_TETRA)).all()
    p = mesh.points[cells]
    edges = p[:, 1:, :dim] - p[:, :1, :dim]
    measure = np.linalg.det(edges) / (2 if dim == 2 else 6)
    assert (measure > 0).all()
    assert abs(measure.sum() - 1.0) < 1e-12
    for key in ("level", "tree", "leaf"):
        from_vtk = numpy_support.vtk_to_numpy(grid.GetCellData().GetArray(key))
        assert np.array_equal(mesh.cell_data[key][0], from_vtk)
    assert mesh.cell_data["level"][0].max() == (5 if dim == 2 else 3)
    added = mesh.point_data["added_point"]
    assert set(np.unique(added)) == {0, 1}
