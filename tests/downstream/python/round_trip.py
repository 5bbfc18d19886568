"""The installed Python module as a user imports it: from the install prefix (PYTHONPATH names its
folder), not the build tree; a mesh encoded and decoded back exactly, in the input's numbering."""
import os
import sys

import numpy as np

import amcodec

prefix = sys.argv[1]
assert os.path.realpath(amcodec.__file__).startswith(os.path.realpath(prefix)), amcodec.__file__
points = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], dtype=np.float64)
triangles = np.array([[0, 1, 2], [1, 3, 2]])
h = amcodec.Hierarchy(points, triangles)
for _ in range(3):
    h.refine(h.leaves()[-1])
leaf = h.leaf_mesh()
data = amcodec.encode(leaf["points"], leaf["triangles"][::-1], keep_numbering=True)
back = amcodec.decode(data)
assert np.array_equal(back["points"], leaf["points"]) and np.array_equal(back["triangles"], leaf["triangles"][::-1])
print("installed amcodec", amcodec.__version__, "from", os.path.dirname(amcodec.__file__), "round trip ok")
