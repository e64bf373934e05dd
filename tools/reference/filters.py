#!/usr/bin/env python3
"""Reference values for hysid's MATLAB-compatible preprocessing (butter, filtfilt, gradient).

Generated with SciPy/NumPy, which implement MATLAB's definitions:
  * scipy.signal.butter(N, Wn)            == MATLAB butter(N, Wn)
  * scipy.signal.filtfilt(b, a, x, padtype='odd', padlen=3*(max(len(a), len(b))-1))
                                          == MATLAB filtfilt(b, a, x)
  * numpy.gradient(x, h)                  == MATLAB gradient(x, h)

Run:  python3 tools/reference/filters.py > crates/hysid-tests/tests/data/filter_reference.json
Versions used for the committed file are written into it.
"""
import json

import numpy as np
import scipy
from scipy import signal


def test_signal(n):
    t = np.arange(n) * 1e-3
    # A slow sine, a fast component the low-pass removes, a step, a ramp: exercises the
    # passband, the stopband and the end extensions.
    x = np.sin(2 * np.pi * 3 * t) + 0.3 * np.sin(2 * np.pi * 180 * t) + 0.5 * (t > 0.15) + 2.0 * t
    return x


cases = []
for order, wn in [(4, 0.2), (2, 0.05), (6, 0.45)]:
    b, a = signal.butter(order, wn)
    x = test_signal(400)
    y = signal.filtfilt(b, a, x, padtype="odd", padlen=3 * (max(len(a), len(b)) - 1))
    cases.append({"order": order, "wn": wn, "b": b.tolist(), "a": a.tolist(), "x": x.tolist(), "filtfilt": y.tolist()})

cheby = []
for order, rp, wn in [(8, 0.05, 0.08), (8, 0.05, 0.4), (5, 0.5, 0.3)]:
    b, a = signal.cheby1(order, rp, wn)
    cheby.append({"order": order, "ripple_db": rp, "wn": wn, "b": b.tolist(), "a": a.tolist()})


def matlab_decimate(x, r):
    """MATLAB decimate(x, r): cheby1(8, 0.05, 0.8/r), filtfilt with MATLAB's padding, and
    every r-th sample aligned so that the last one is kept (nbeg = r - (r*nout - nd))."""
    b, a = signal.cheby1(8, 0.05, 0.8 / r)
    y = signal.filtfilt(b, a, x, padtype="odd", padlen=3 * (max(len(a), len(b)) - 1))
    nd = len(x)
    nout = -(-nd // r)
    nbeg = r - (r * nout - nd)
    return y[nbeg - 1 :: r]


xd = test_signal(1003)
x = test_signal(50)
out = {
    "cheby1": cheby,
    "decimate": {"r": 10, "x": xd.tolist(), "y": matlab_decimate(xd, 10).tolist()},
    "generator": "tools/reference/filters.py",
    "numpy": np.__version__,
    "scipy": scipy.__version__,
    "butter_filtfilt": cases,
    "gradient": {"h": 1e-3, "x": x.tolist(), "g": np.gradient(x, 1e-3).tolist()},
}
print(json.dumps(out, indent=1))
