"""amcodec: lossless compression of adaptive red-green multiresolution meshes.

Arrays in, arrays out::

    import amcodec
    data = amcodec.encode(points, triangles, keep_numbering=True)   # bytes of an .amc file
    mesh = amcodec.decode(data)                                    # dict: points, triangles, level, green, numbering

``points`` is an (n, 3) float array (float32 stays float32, bit-exact), or (n, 2) for a planar
mesh (z = 0; decoding returns (n, 3)); ``triangles`` an (m, 3) integer array. The mesh may be any edge-manifold, consistently oriented triangle mesh: the
coarsest red-green base is found in it (adaptive and semi-regular meshes), or given as
``base=(base_points, base_triangles)``. Errors raise :class:`amcodec.Error` (a ValueError) with the
library's message.

With meshio (when installed): :func:`encode_meshio` and :func:`decode_meshio`.

Series (.amcs, one file for every output step of an adaptive run, with its fields)::

    writer = amcodec.SeriesWriter(base_points, base_triangles, path="run.amcs", keyframe_interval=10)
    writer.add_mesh(points, triangles, time, point_data={"u": u}, cell_data={"error": eta})  # any numbering
    writer.close()
    reader = amcodec.SeriesReader.open("run.amcs")
    frame = reader.frame(40)  # dict: points, triangles, level, green, time, point_data, cell_data
"""

from ._amcodec import (Error, Hierarchy, SeriesReader, SeriesWriter, __version__, decode, decode_chunks, decode_hierarchy,
                       encode, import_mesh, info)

__all__ = ["Error", "Hierarchy", "SeriesReader", "SeriesWriter", "__version__", "decode", "decode_chunks",
           "decode_hierarchy", "encode", "import_mesh", "info", "encode_meshio", "decode_meshio"]


def encode_meshio(mesh, keep_numbering=True, quantize=0, base=None):
    """Compresses a ``meshio.Mesh`` of triangles to .amc bytes (its numbering kept by default)."""
    triangles = [block.data for block in mesh.cells if block.type == "triangle"]
    others = sorted({block.type for block in mesh.cells if block.type != "triangle"})
    if others or len(triangles) != 1:
        raise Error("encode_meshio: expected one block of triangles, found " +
                    ", ".join(others or [f"{len(triangles)} triangle blocks"]))
    return encode(mesh.points, triangles[0], base=base, keep_numbering=keep_numbering, quantize=quantize)


def decode_meshio(data, level=-1, canonical=False):
    """Decodes .amc bytes to a ``meshio.Mesh`` with cell data ``level`` and ``green``."""
    import meshio

    decoded = decode(data, level=level, canonical=canonical)
    return meshio.Mesh(decoded["points"], [("triangle", decoded["triangles"])],
                       cell_data={"level": [decoded["level"]], "green": [decoded["green"]]})
