#!/usr/bin/env python3
"""MINPACK's correct digits on NIST's StRD nonlinear regression problems (docs/numerics.md).

For each of the 27 problems in `data/nist-strd/` and both starts, fits the model with
SciPy's `scipy.optimize.least_squares(method='lm')` (MINPACK's lmdif: Levenberg-Marquardt
with a forward-difference Jacobian), default options, and prints the log relative error
LRE = -log10(|b - b_cert| / |b_cert|), worst over the parameters, capped at 11 (the
certified values' digits); 0 when the fit fails or is worse than one digit.

Written for hysid (not part of the build). Run in a throwaway virtual environment:
    python3 -m venv /tmp/nistvenv && /tmp/nistvenv/bin/pip install scipy numpy
    /tmp/nistvenv/bin/python tools/nist/minpack_table.py
The figures in docs/numerics.md came from SciPy 1.x as printed in the first line.
"""

import math
import pathlib
import sys

import numpy as np
import scipy
from scipy.optimize import least_squares

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from make_files import DIR, MODELS  # noqa: E402


def certified(path):
    """Start 1, start 2 and the certified values and standard deviations of a .dat file."""
    import re

    lines = path.read_text().splitlines()
    header = "\n".join(lines[:10])
    m = re.search(r"Certified Values\s*\(lines\s+(\d+)\s+to\s+(\d+)\)", header, re.I)
    s = re.search(r"Starting Values\s*\(lines\s+(\d+)\s+to\s+(\d+)\)", header, re.I)
    d = re.search(r"Data\s*\(lines\s+(\d+)\s+to\s+(\d+)\)", header, re.I)
    rows = []
    for line in lines[int(s.group(1)) - 1 : int(s.group(2))]:
        f = line.split("=")[1].split()
        rows.append([float(v) for v in f[:4]])
    data = np.array(
        [[float(v) for v in line.split()] for line in lines[int(d.group(1)) - 1 : int(d.group(2))] if line.strip()]
    )
    return np.array(rows), data


def lre(est, cert):
    worst = 11.0
    for e, c in zip(est, cert):
        if not math.isfinite(e):
            return 0.0
        rel = abs(e - c) / abs(c)
        v = 11.0 if rel == 0 else -math.log10(rel)
        worst = min(worst, v)
    return max(0.0, min(11.0, worst))


def main():
    print(f"# scipy {scipy.__version__}, numpy {np.__version__}: least_squares(method='lm'), defaults")
    print("problem,start,lre")
    for name, expr in MODELS.items():
        table, data = certified(DIR / f"{name}.dat")
        y = data[:, 0]
        if name == "Nelson":
            y = np.log(y)
            cols = {"x1": data[:, 1], "x2": data[:, 2]}
        else:
            cols = {"x": data[:, 1]}
        code = compile(expr.replace("^", "**"), name, "eval")
        p = table.shape[0]

        def residual(b):
            env = {"exp": np.exp, "cos": np.cos, "sin": np.sin, "atan": np.arctan, "pi": np.pi}
            env.update(cols)
            env.update({f"b{i + 1}": b[i] for i in range(p)})
            with np.errstate(all="ignore"):
                return eval(code, env) - y

        for k in (1, 2):
            try:
                fit = least_squares(residual, table[:, k - 1], method="lm")
                score = lre(fit.x, table[:, 2])
            except Exception:  # a failed fit scores 0
                score = 0.0
            print(f"{name},{k},{score:.1f}")


if __name__ == "__main__":
    main()
