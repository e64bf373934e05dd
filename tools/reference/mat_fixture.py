#!/usr/bin/env python3
"""MAT-file fixtures for hysid's .mat reader, made with SciPy's writer (MATLAB level 5 format).

Writes crates/hysid-tests/tests/data/piezo_150V_1Hz.mat from data/piezo/piezo_150V_1Hz.csv (the
real piezo record, see data/README.md for its source), compressed as MATLAB's default `save`
(-v7) does, with:
  * t_s, voltage_V, displacement_um  the three columns as N×1 double vectors;
  * record                            the same as one N×3 double matrix [t, V, d];
  * voltage_row                       the voltage as a 1×N row vector;
  * counts                            round(10·voltage) as int16 (integer classes convert);
  * z                                 a complex vector (must be refused).

Run:  python3 tools/reference/mat_fixture.py
"""
import numpy as np
import scipy
from scipy import io

data = np.loadtxt("data/piezo/piezo_150V_1Hz.csv", delimiter=",", skiprows=1)
t, v, d = data[:, 0], data[:, 1], data[:, 2]
io.savemat(
    "crates/hysid-tests/tests/data/piezo_150V_1Hz.mat",
    {
        "t_s": t.reshape(-1, 1),
        "voltage_V": v.reshape(-1, 1),
        "displacement_um": d.reshape(-1, 1),
        "record": data,
        "voltage_row": v.reshape(1, -1),
        "counts": np.round(10 * v).astype(np.int16).reshape(-1, 1),
        "z": (v + 1j * d).reshape(-1, 1),
    },
    format="5",
    do_compression=True,
)
print(f"written with SciPy {scipy.__version__}, NumPy {np.__version__}")
