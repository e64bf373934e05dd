"""A Bouc–Wen oscillator written as Python functions (module level, so it pickles):
m ÿ + c ẏ + k y + z = u,  ż = α ẏ − β_γ |ẏ| sgn(z) |z|^ν − β_δ ẏ |z|^ν  (Noël & Schoukens 2016)."""

import math

import hysid
import numpy as np


def bw_rhs(t, x, u, p):
    y, v, z = x.tolist()  # Python floats: scalar arithmetic is faster on them
    m, c, k, a, bg, bd, nu = p.tolist()
    az = abs(z) ** nu
    s = 1.0 if z > 0 else (-1.0 if z < 0 else 0.0)
    return np.array([v, (u[0] - c * v - k * y - z) / m, a * v - bg * abs(v) * s * az - bd * v * az])


def bw_output(t, x, u, p):
    return x[:1]


def bouc_wen_python(start):
    params = [
        hysid.Parameter(n, v, fixed=(n == "nu"), lower=1e-9 if n == "mL" else -math.inf) for n, v in start.items()
    ]
    return hysid.GreyBoxModel(["y", "v", "z"], params, bw_rhs, bw_output)


def raising_rhs(t, x, u, p):
    if t > 0.05:
        raise ZeroDivisionError("boom at t > 0.05")
    return bw_rhs(t, x, u, p)


def wrong_shape_late(t, x, u, p):
    if t > 0.05:
        return np.zeros(2)
    return bw_rhs(t, x, u, p)


def cascade_fit(record):
    """A fleet fit: the Example-1 cascade structure on an (x, y) pair."""
    x, y = record
    return hysid.identify_cascade(x, y, hysteresis="ch4", na=2, nb=2, delay=1)
