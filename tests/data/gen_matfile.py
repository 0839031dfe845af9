#!/usr/bin/env python3
"""Writes scipy_v5.mat and scipy_struct_cell.mat, independent MAT v5 files for
matfile_test.cpp.

scipy.io.savemat stores 1-D arrays as 1 x N row vectors; the file holds
  t    1 x 5 double   0, 0.01, ..., 0.04
  u    1 x 5 double   0.61, 82, 82, 82, 82
  y    5 x 1 int32    0, 10, 35, 60, 80
  data 5 x 3 single   [t u y]
  name char           'IPA step'
scipy_struct_cell.mat (uncompressed) holds t, u, y (1 x 5 double: 0..0.4,
sin t, cos t) beside what a pneumid reader skips but must not call corrupt:
a struct s (fields a, bb, ccc), a cell c, an int8 vector i8 = [1 2 3] and a
single scalar f = 2.5 (both stored as small data elements, the last element
of their arrays) and an empty 0 x 3 double e.
Run with /usr/bin/python3 from this directory.
"""
import numpy as np
from scipy.io import savemat

t = np.arange(5) * 0.01
u = np.array([0.61, 82, 82, 82, 82])
y = np.array([[0], [10], [35], [60], [80]], dtype=np.int32)
data = np.column_stack([t, u, y[:, 0]]).astype(np.float32)
savemat("scipy_v5.mat", {"t": t, "u": u, "y": y, "data": data, "name": "IPA step"},
        format="5", do_compression=True)

t = np.arange(5) * 0.1
cell = np.empty((1, 2), dtype=object)
cell[0, 0] = np.ones(2)
cell[0, 1] = "x"
savemat("scipy_struct_cell.mat",
        {"t": t, "u": np.sin(t), "y": np.cos(t),
         "s": {"a": np.ones(3), "bb": "text", "ccc": np.eye(2)}, "c": cell,
         "i8": np.int8([1, 2, 3]), "f": np.float32(2.5), "e": np.zeros((0, 3))},
        format="5", do_compression=False)
