#!/usr/bin/env python3
"""Writes scipy_v5.mat, an independent MAT v5 file for matfile_test.cpp.

scipy.io.savemat stores 1-D arrays as 1 x N row vectors; the file holds
  t    1 x 5 double   0, 0.01, ..., 0.04
  u    1 x 5 double   0.61, 82, 82, 82, 82
  y    5 x 1 int32    0, 10, 35, 60, 80
  data 5 x 3 single   [t u y]
  name char           'IPA step'
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
