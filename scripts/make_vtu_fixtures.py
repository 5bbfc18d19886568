#!/usr/bin/python3
"""Write the VTU test fixtures with the tools users write them with.

  tests/data/vtu/meshio_*.vtu  meshio (Debian's python3-meshio): ascii, binary, binary + zlib
  tests/data/vtu/vtk_*.vtu     VTK's vtkXMLUnstructuredGridWriter (python3-vtk9): ascii, inline
                               binary, appended raw and base64, zlib or none, UInt32 or UInt64
                               headers, little- and big-endian, two pieces, polygons of 3 points
  tests/data/vtu/dune_*.vtu    DUNE's VTKWriter (libdune-grid-dev), from scripts/vtu_fixture_dune.cc
  tests/data/bad/vtu_*.vtu     broken files: truncations, wrong sizes, bad zlib, unknown types,
                               huge declared sizes, non-triangle cells, an unsupported compressor

Every good file but DUNE's holds the same octahedron and arrays, defined here and again in
tests/vtu_reader_test.cpp (same IEEE arithmetic on both sides). Run from the repository root with
Debian's python (`/usr/bin/python3 scripts/make_vtu_fixtures.py`); it rewrites the files.
"""
import base64
import os
import shutil
import struct
import subprocess
import sys
import tempfile
import zlib

import meshio
import numpy as np
import vtk
from vtk.util import numpy_support

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
GOOD = os.path.join(ROOT, "tests", "data", "vtu")
BAD = os.path.join(ROOT, "tests", "data", "bad")

# ----------------------------------------------------------------------------- the known mesh
# Octahedron: vertex i on axis i // 2 (sign + for even i) at distance 1 + i / 7; outward faces.
TRIANGLES = [(0, 2, 4), (2, 1, 4), (1, 3, 4), (3, 0, 4), (2, 0, 5), (1, 2, 5), (3, 1, 5), (0, 3, 5)]


def points():
    p = np.zeros((6, 3))
    for i in range(6):
        p[i, i // 2] = (1.0 if i % 2 == 0 else -1.0) * (1.0 + i / 7.0)
    return p


def point_data():
    temperature = np.array([i / 3.0 + 0.1 for i in range(6)], dtype=np.float64)
    velocity = np.array([[i + k / 10.0 for k in range(3)] for i in range(6)], dtype=np.float32)
    ids = np.array([2**60 + i for i in range(6)], dtype=np.int64)
    return {"temperature": temperature, "velocity": velocity, "id": ids}


def cell_data():
    level = np.array([c % 3 for c in range(8)], dtype=np.uint8)
    material = np.array([-1000 * c for c in range(8)], dtype=np.int32)
    quality = np.array([1.0 / (c + 1) for c in range(8)], dtype=np.float64)
    return {"level": level, "material": material, "quality": quality}


# ----------------------------------------------------------------------------- meshio
def write_meshio():
    mesh = meshio.Mesh(points(), [("triangle", np.array(TRIANGLES, dtype=np.int64))],
                       point_data=point_data(),
                       cell_data={k: [v] for k, v in cell_data().items()})
    out = lambda name: os.path.join(GOOD, name)
    meshio.vtu.write(out("meshio_ascii.vtu"), mesh, binary=False)
    meshio.vtu.write(out("meshio_binary.vtu"), mesh, binary=True, compression=None)
    meshio.vtu.write(out("meshio_binary_zlib.vtu"), mesh, binary=True, compression="zlib")
    meshio.vtu.write(out("meshio_binary_zlib_uint64.vtu"), mesh, binary=True, compression="zlib",
                     header_type="UInt64")
    # An LZMA-compressed file: a valid VTU that we refuse (only zlib).
    meshio.vtu.write(os.path.join(BAD, "vtu_lzma_compressor.vtu"), mesh, binary=True,
                     compression="lzma")


# ----------------------------------------------------------------------------- VTK
def vtk_grid(float32_points=False, polygons=False):
    grid = vtk.vtkUnstructuredGrid()
    pts = vtk.vtkPoints()
    pts.SetDataTypeToFloat() if float32_points else pts.SetDataTypeToDouble()
    for p in points():
        pts.InsertNextPoint(*p)
    grid.SetPoints(pts)
    for t in TRIANGLES:
        ids = vtk.vtkIdList()
        for v in t:
            ids.InsertNextId(v)
        grid.InsertNextCell(vtk.VTK_POLYGON if polygons else vtk.VTK_TRIANGLE, ids)
    for name, values in point_data().items():
        a = numpy_support.numpy_to_vtk(values, deep=True)
        a.SetName(name)
        grid.GetPointData().AddArray(a)
    for name, values in cell_data().items():
        a = numpy_support.numpy_to_vtk(values, deep=True)
        a.SetName(name)
        grid.GetCellData().AddArray(a)
    return grid


def write_vtk(name, mode, compress=False, header64=True, base64_appended=False,
              big_endian=False, float32_points=False, pieces=1, polygons=False):
    w = vtk.vtkXMLUnstructuredGridWriter()
    w.SetInputData(vtk_grid(float32_points, polygons))
    w.SetFileName(os.path.join(GOOD, name))
    {"ascii": w.SetDataModeToAscii, "binary": w.SetDataModeToBinary,
     "appended": w.SetDataModeToAppended}[mode]()
    if compress:
        w.SetCompressorTypeToZLib()
        w.SetBlockSize(64)  # several blocks per array, to test the multi-block header
    else:
        w.SetCompressorTypeToNone()
    w.SetHeaderTypeToUInt64() if header64 else w.SetHeaderTypeToUInt32()
    w.SetEncodeAppendedData(base64_appended)
    w.SetByteOrderToBigEndian() if big_endian else w.SetByteOrderToLittleEndian()
    w.SetNumberOfPieces(pieces)
    if not w.Write():
        sys.exit("VTK could not write " + name)


def write_vtk_all():
    write_vtk("vtk_ascii.vtu", "ascii")
    write_vtk("vtk_binary_uint32.vtu", "binary", header64=False, float32_points=True)
    write_vtk("vtk_binary_zlib.vtu", "binary", compress=True)
    write_vtk("vtk_appended_raw.vtu", "appended")
    write_vtk("vtk_appended_raw_zlib_uint32.vtu", "appended", compress=True, header64=False,
              float32_points=True)
    write_vtk("vtk_appended_base64.vtu", "appended", header64=False, base64_appended=True)
    write_vtk("vtk_appended_base64_zlib.vtu", "appended", compress=True, base64_appended=True)
    write_vtk("vtk_big_endian_zlib.vtu", "appended", compress=True, header64=False, big_endian=True)
    write_vtk("vtk_big_endian_binary.vtu", "binary", big_endian=True, float32_points=True)
    write_vtk("vtk_two_pieces.vtu", "appended", compress=True, pieces=2)
    write_vtk("vtk_polygons.vtu", "ascii", polygons=True)


# ----------------------------------------------------------------------------- DUNE
def write_dune():
    source = os.path.join(ROOT, "scripts", "vtu_fixture_dune.cc")
    if not os.path.isdir("/usr/include/dune/grid"):
        print("skipping DUNE fixtures: libdune-grid-dev is not installed")
        return
    build = tempfile.mkdtemp()
    try:
        # Debian builds dune-uggrid and dune-common with MPI; a config.h says so.
        with open(os.path.join(build, "config.h"), "w") as f:
            f.write("#define HAVE_MPI 1\n#define HAVE_DUNE_UGGRID 1\n#define ENABLE_UG 1\n"
                    "#define UG_USE_NEW_DIMENSION_DEFINES 1\n#define OMPI_SKIP_MPICXX 1\n")
        exe = os.path.join(build, "dune_vtu")
        subprocess.check_call(
            ["g++", "-std=c++17", "-DModelP", "-DENABLE_MPI=1", "-I" + build,
             "-I/usr/lib/x86_64-linux-gnu/openmpi/include", source, "-o", exe, "-ldunegrid",
             "-lduneuggrid", "-ldunegeometry", "-ldunecommon",
             "-L/usr/lib/x86_64-linux-gnu/openmpi/lib", "-lmpi"])
        subprocess.check_call([exe, GOOD])
    finally:
        shutil.rmtree(build)


# ----------------------------------------------------------------------------- bad files
def word(value, header64, big=False):
    return struct.pack((">" if big else "<") + ("Q" if header64 else "I"), value)


def hand_vtu(piece_attrs, arrays_xml, appended=b"", header64=False, compressor=None,
             encoding="raw", file_type="UnstructuredGrid"):
    """A VTU laid out as VTK writes it; arrays_xml sits in the Piece."""
    head = '<VTKFile type="%s" version="1.0" byte_order="LittleEndian" header_type="%s"' % (
        file_type, "UInt64" if header64 else "UInt32")
    if compressor:
        head += ' compressor="%s"' % compressor
    text = ('<?xml version="1.0"?>\n%s>\n  <UnstructuredGrid>\n    <Piece %s>\n%s    </Piece>\n'
            '  </UnstructuredGrid>\n' % (head, piece_attrs, arrays_xml)).encode()
    if appended:
        text += b'  <AppendedData encoding="%s">\n   _' % encoding.encode() + appended + \
            b"\n  </AppendedData>\n"
    return text + b"</VTKFile>\n"


def ascii_arrays(pts, conn, offs, types, point_type="Float64"):
    f = lambda v: " ".join(str(x) for x in v)
    return ('      <Points>\n        <DataArray type="%s" NumberOfComponents="3" format="ascii">'
            '%s</DataArray>\n      </Points>\n      <Cells>\n'
            '        <DataArray type="Int32" Name="connectivity" format="ascii">%s</DataArray>\n'
            '        <DataArray type="Int32" Name="offsets" format="ascii">%s</DataArray>\n'
            '        <DataArray type="UInt8" Name="types" format="ascii">%s</DataArray>\n'
            '      </Cells>\n') % (point_type, f(pts), f(conn), f(offs), f(types))


def zlib_block(data, header64=False, blocks=None):
    """vtkZLibDataCompressor layout of one array: header words, then the compressed block."""
    c = zlib.compress(data)
    n, size, last = blocks if blocks else (1, len(data), len(data))
    return word(n, header64) + word(size, header64) + word(last, header64) + \
        word(len(c), header64) + c


def write_bad():
    def put(name, data):
        with open(os.path.join(BAD, name), "wb") as f:
            f.write(data)

    flat_pts = [v for p in points() for v in p]
    flat_conn = [v for t in TRIANGLES for v in t]
    offs = [3 * (c + 1) for c in range(8)]
    tris = [5] * 8
    good = ascii_arrays(flat_pts, flat_conn, offs, tris)
    attrs = 'NumberOfPoints="6" NumberOfCells="8"'

    # Cells that are not triangles: quads from cell 5 on.
    put("vtu_quad_cells.vtu", hand_vtu(
        'NumberOfPoints="6" NumberOfCells="6"',
        ascii_arrays(flat_pts, flat_conn[:15] + [0, 2, 1, 3], [3, 6, 9, 12, 15, 19],
                     [5, 5, 5, 5, 5, 9])))
    put("vtu_polygon_of_4.vtu", hand_vtu(
        'NumberOfPoints="6" NumberOfCells="2"',
        ascii_arrays(flat_pts, [0, 2, 4, 0, 4, 3, 5], [3, 7], [7, 7])))
    put("vtu_polydata.vtu", hand_vtu(attrs, good, file_type="PolyData"))
    put("vtu_unknown_type.vtu", hand_vtu(attrs, good.replace('type="Float64"', 'type="Float16"')))
    put("vtu_index_out_of_range.vtu", hand_vtu(
        attrs, ascii_arrays(flat_pts, flat_conn[:-1] + [6], offs, tris)))
    put("vtu_wrong_point_count.vtu", hand_vtu('NumberOfPoints="7" NumberOfCells="8"', good))
    put("vtu_missing_types.vtu", hand_vtu(attrs, good[:good.index('        <DataArray type="UInt8"')]
                                          + "      </Cells>\n"))
    put("vtu_huge_point_count.vtu", hand_vtu('NumberOfPoints="4000000000" NumberOfCells="8"', good))
    whole = hand_vtu(attrs, good)
    put("vtu_unclosed.vtu", whole[:whole.rindex(b"</VTKFile>")])
    put("vtu_not_xml.vtu", bytes(range(256)))

    # Binary (inline base64) points: the header claims 144 bytes, the text holds half of them.
    pts64 = struct.pack("<18d", *flat_pts)
    b64 = (base64.b64encode(word(len(pts64), False)) + base64.b64encode(pts64)).decode()
    binary = good.replace('format="ascii">%s</DataArray>' % " ".join(str(x) for x in flat_pts),
                          'format="binary">%s</DataArray>' % b64)
    assert binary != good
    put("vtu_truncated_base64.vtu", hand_vtu(attrs, binary.replace(b64, b64[:len(b64) // 2])))
    put("vtu_bad_base64_character.vtu", hand_vtu(attrs, binary.replace(b64, b64[:20] + "*" + b64[21:])))
    put("vtu_wrong_header_size.vtu", hand_vtu(attrs, binary.replace(
        b64, (base64.b64encode(word(len(pts64) - 8, False)) + base64.b64encode(pts64)).decode())))

    # Appended raw, zlib-compressed points.
    appended_pts = good.replace(
        'format="ascii">%s</DataArray>' % " ".join(str(x) for x in flat_pts),
        'format="appended" offset="0"/>')
    block = zlib_block(pts64)
    put("vtu_truncated_appended.vtu",
        hand_vtu(attrs, appended_pts, block, compressor="vtkZLibDataCompressor")
        .split(b"\n  </AppendedData>")[0][:-20])
    corrupt = bytearray(block)
    corrupt[16 + 6] ^= 0xff
    corrupt[16 + 9] ^= 0x55
    put("vtu_bad_zlib.vtu", hand_vtu(attrs, appended_pts, bytes(corrupt), compressor="vtkZLibDataCompressor"))
    # 2^40 blocks declared in a few bytes.
    put("vtu_huge_block_count.vtu", hand_vtu(
        attrs, appended_pts, word(2**40, True) + word(65536, True) + word(0, True) + block[16:],
        header64=True, compressor="vtkZLibDataCompressor"))
    # 100 million points (2.4 GB) declared by one 300-byte compressed block.
    huge = hand_vtu('NumberOfPoints="100000000" NumberOfCells="8"', appended_pts,
                    zlib_block(pts64, True, (1, 2400000000, 2400000000)), header64=True,
                    compressor="vtkZLibDataCompressor")
    put("vtu_huge_compressed_size.vtu", huge)
    put("vtu_offset_past_end.vtu", hand_vtu(
        attrs, appended_pts.replace('offset="0"', 'offset="99999"'), block,
        compressor="vtkZLibDataCompressor"))


def main():
    os.makedirs(GOOD, exist_ok=True)
    write_meshio()
    write_vtk_all()
    write_dune()
    write_bad()


if __name__ == "__main__":
    main()
